"""The geometric planners' side-by-side benchmark (tools/bench/bench_geometric.py): its figures
from each side's runs (success, medians, the comparisons, refusals, a skipped side) and how it
finds its problems. No planning, no Kautham: the runs are given."""
import pathlib
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tools" / "bench"))

import bench_geometric  # noqa: E402
from bench_geometric import Attempt, figures_of  # noqa: E402
from report import Refused  # noqa: E402


def _runs(*times):
    """Solved runs of those times (s); None: a run not solved in the limit."""
    return [Attempt(t is not None, t if t is not None else 1.0) for t in times]


def test_successes_medians_and_comparisons_of_the_two_sides():
    figures = figures_of("p", 1.0, _runs(0.2, 0.4, None), _runs(0.1, 0.1, 0.3))
    assert figures == {"geo_p_kautham_success": 0.667, "geo_p_kautham_median_s": 0.3,
                       "geo_p_success": 1.0, "geo_p_median_s": 0.1, "geo_p_deepest_mm": 0.0,
                       "geo_p_time_over_kautham": 0.333, "geo_p_success_minus_kautham": 0.333}


def test_the_ratio_comes_from_the_medians_before_rounding():
    figures = figures_of("p", 10.0, _runs(0.00004), _runs(0.00006))
    assert figures["geo_p_kautham_median_s"] == 0.0
    assert figures["geo_p_time_over_kautham"] == 1.5


def test_a_side_that_solved_nothing_has_the_time_limit_as_its_median():
    figures = figures_of("p", 2.5, _runs(None, None), _runs(0.5, None))
    assert figures["geo_p_kautham_success"] == 0.0 and figures["geo_p_kautham_median_s"] == 2.5
    assert figures["geo_p_time_over_kautham"] == 0.2
    assert figures["geo_p_success_minus_kautham"] == 0.5


def test_a_run_without_an_answer_refuses_its_side_and_the_comparisons_with_the_reason():
    odin = _runs(0.1) + [Attempt(False, None, "gui.planning.geometric: boom")]
    figures = figures_of("p", 1.0, _runs(0.2, 0.3), odin)
    assert figures["geo_p_kautham_success"] == 1.0
    for name in ("geo_p_success", "geo_p_median_s", "geo_p_time_over_kautham",
                 "geo_p_success_minus_kautham"):
        assert isinstance(figures[name], Refused)
        assert figures[name].reason == "1 of 2 runs gave no answer: gui.planning.geometric: boom"


def test_a_skipped_side_leaves_the_other_sides_figures_and_no_comparison():
    assert figures_of("p", 1.0, None, _runs(0.5)) == {"geo_p_success": 1.0,
                                                      "geo_p_median_s": 0.5,
                                                      "geo_p_deepest_mm": 0.0}
    assert set(figures_of("p", 1.0, _runs(0.5), None)) == {"geo_p_kautham_success",
                                                           "geo_p_kautham_median_s"}


def test_runs_read_as_attempts_whatever_side_wrote_them():
    runs = [{"solved": True, "time_s": 0.2, "planner": "RRTConnect"},
            {"solved": False, "time_s": 1.0, "error": ""},
            {"error": "Kautham could not load the problem"},
            {"solved": True, "time_s": 0.3, "deepest_mm": 0.4, "deepest_pair": "a into b"}]
    assert bench_geometric.attempts(runs) == [
        Attempt(True, 0.2), Attempt(False, 1.0),
        Attempt(False, None, "Kautham could not load the problem"), Attempt(True, 0.3, "", 0.4)]


def test_the_deepest_figure_is_the_deepest_of_odins_solved_runs():
    odin = [Attempt(True, 0.1, "", 0.25), Attempt(True, 0.2, "", 0.0),
            Attempt(True, 0.3, "", 0.61234), Attempt(False, 1.0)]
    figures = figures_of("p", 1.0, _runs(0.2), odin)
    assert figures["geo_p_deepest_mm"] == 0.6123
    assert "geo_p_kautham_deepest_mm" not in figures     # Kautham's paths are not checked


def test_the_deepest_figure_is_zero_when_nothing_touched_or_nothing_was_solved():
    assert figures_of("p", 1.0, None, _runs(0.1, 0.2))["geo_p_deepest_mm"] == 0.0
    assert figures_of("p", 1.0, _runs(0.2), _runs(None, None))["geo_p_deepest_mm"] == 0.0


def test_a_run_without_an_answer_refuses_the_deepest_figure_with_the_reason():
    odin = [Attempt(True, 0.1, "", 0.3), Attempt(False, None, "gui.planning.geometric: boom")]
    deepest = figures_of("p", 1.0, None, odin)["geo_p_deepest_mm"]
    assert isinstance(deepest, Refused)
    assert deepest.reason == "1 of 2 runs gave no answer: gui.planning.geometric: boom"


def test_an_unknown_problem_asked_for_is_refused_naming_the_known_ones(monkeypatch):
    monkeypatch.setenv(bench_geometric.PROBLEMS_ENVIRONMENT, "tx90, nope")
    with pytest.raises(ValueError, match=r"no problem \['nope'\]; there are .*'tx90'"):
        bench_geometric.problems()


def test_a_problem_in_neither_corpus_is_skipped_in_one_line(monkeypatch, tmp_path, capsys):
    (tmp_path / "small").mkdir()
    (tmp_path / "small" / "MANIFEST.md").write_text("")
    monkeypatch.setenv("ODIN_KAUTHAM_DIR", str(tmp_path / "small"))
    monkeypatch.setenv("ODIN_KAUTHAM_ALL_DIR", str(tmp_path / "whole"))
    monkeypatch.setenv(bench_geometric.PROBLEMS_ENVIRONMENT, "ur5,maze")
    ur5 = tmp_path / "small" / bench_geometric.PROBLEMS["ur5"]
    ur5.parent.mkdir(parents=True)
    ur5.write_text("<Problem/>")
    assert bench_geometric.problems() == {"ur5": ur5}
    out = capsys.readouterr().out
    assert out.count("\n") == 1 and "maze skipped" in out


def test_kauthams_checked_paths_give_their_deepest_figure_beside_odins():
    kautham = [Attempt(True, 0.6, "", 0.488), Attempt(True, 0.7, "", 0.0), Attempt(False, 1.0)]
    figures = figures_of("p", 1.0, kautham, _runs(0.1))
    assert figures["geo_p_kautham_deepest_mm"] == 0.488
    assert figures["geo_p_deepest_mm"] == 0.0
