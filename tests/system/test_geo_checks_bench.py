"""Collision checks per second, Odin over Kautham 5.1.1 (tools/bench/bench_geo_checks.py): OMPL
benchmark logs read as each side writes them, the path checks Kautham's benchmark makes outside
its timed search and simplification, each side's rate and the figure; and the module without
Kautham's build. No planning, no Kautham: the logs are written here."""
import pathlib
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tools" / "bench"))

import bench_geo_checks  # noqa: E402
from bench_geo_checks import Tally, figures_of, path_checks, read_log  # noqa: E402
from report import Refused  # noqa: E402

KAUTHAM_PROPERTIES = ("collision checks INTEGER", "correct solution BOOLEAN",
                      "correct solution strict BOOLEAN", "simplification time REAL",
                      "simplified correct solution BOOLEAN",
                      "simplified correct solution strict BOOLEAN",
                      "simplified solution length REAL", "simplified solution segments INTEGER",
                      "solution length REAL", "solution segments INTEGER", "solved BOOLEAN",
                      "time REAL")


def _kautham_log(rows, leaves=("Real vector state space 'arm_Rn' of dimension 2 with bounds:",),
                 extent=2.0, fraction=0.01):
    """A log as Kautham 5.1.1's console writes it (OMPL 1.5: experiment properties, "enum
    type", the state space in the setup text), one run per row of KAUTHAM_PROPERTIES' values."""
    setup = ["Properties of the state space 'CompoundSpace2'", f"  - extent: {extent}",
             "Compound state space 'CompoundSpace2' of dimension 2 [", *leaves,
             "2 planners", "]"]      # a line of free text that looks like the planners' count
    return "\n".join([
        "OMPL version ", "Experiment p", "0 experiment properties", "Running on vm",
        "Starting at 2026-12-04 04:35:58", "<<<|", *setup, "|>>>", "<<<|", "x86_64", "|>>>",
        "11019730995072601 is the random seed", "1 seconds per run", "4096 MB per run",
        f"{len(rows)} runs per planner", "9.5 seconds spent to collect the data",
        "1 enum type", "status|Unknown status|Timeout|Exact solution", "1 planners",
        "geometric_p", "2 common properties", f"longest_valid_segment_fraction = {fraction}",
        "range = 0.1", f"{len(KAUTHAM_PROPERTIES)} properties for each run",
        *KAUTHAM_PROPERTIES, f"{len(rows)} runs",
        *["".join(f"{v}; " for v in row) for row in rows], "."]) + "\n"


def _odin_log(rows):
    """A log as ``rosrun GUI benchmark`` writes it: (collision checks, time s, simplification
    time s or "") per run, with a progress block after the runs as OMPL may write one."""
    names = ("collision checks INTEGER", "seed INTEGER", "simplification time REAL",
             "time REAL")
    return "\n".join([
        "OMPL version 2.0.1", "Experiment p", "Running on vm", "Starting at 2026-12-04",
        "<<<|", "Odin", "|>>>", "<<<|", "x86_64", "|>>>", "1 is the random seed",
        "1.0 seconds per run", "4096.0 MB per run", f"{len(rows)} runs per planner",
        "2.6 seconds spent to collect the data", "1 enum types", "status|Timeout",
        "1 planners", "geometric_p", "1 common properties", "planner = RRT",
        f"{len(names)} properties for each run", *names, f"{len(rows)} runs",
        *[f"{c}; {k + 1}; {s}; {t}; " for k, (c, t, s) in enumerate(rows)],
        "1 progress properties for each run", "time REAL", "1 runs", "0.1,;", "."]) + "\n"


# a solved run: 1,000 checks, 0.2 s search + 0.3 s simplification; its path 0.5 long in 4
# segments, simplified 0.3 long in 1 (the segment checked every 2.0 x 0.01 = 0.02)
SOLVED = (1000, 1, 1, 0.3, 1, 1, 0.3, 1, 0.5, 4, 1, 0.2)
UNSOLVED = (700, "", "", "", "", "", "", "", "", "", 0, 1.0)


def test_kautham_and_odin_logs_are_read_by_planner_with_their_runs():
    log = read_log(_kautham_log([SOLVED, UNSOLVED]), "k.log")
    assert list(log.planners) == ["geometric_p"]
    planner = log.planners["geometric_p"]
    assert planner.common["longest_valid_segment_fraction"] == "0.01"
    assert planner.runs[0]["collision checks"] == "1000"
    assert planner.runs[1]["simplification time"] == "" and planner.runs[1]["time"] == "1.0"
    assert "extent: 2.0" in log.setup
    odin = read_log(_odin_log([(250, 0.006, 0.0003), (4000, 1.0, "")]), "o.log")
    assert [r["seed"] for r in odin.planners["geometric_p"].runs] == ["1", "2"]


def test_a_run_line_with_too_few_values_is_refused_naming_the_line():
    text = _odin_log([(250, 0.006, 0.0003)]).replace("250; 1; ", "250; ")
    with pytest.raises(ValueError, match=r"^o\.log:28: 3 values, 4 properties"):
        read_log(text, "o.log")


def test_a_log_cut_short_is_refused():
    text = _odin_log([(250, 0.006, 0.0003)])
    with pytest.raises(ValueError, match=r"^o\.log: ends before"):
        read_log(text[:text.index("4 properties for each run")], "o.log")


def test_kautham_path_checks_outside_the_timed_search_are_counted_from_below():
    segment = 0.02
    run = dict(zip([p.rsplit(" ", 1)[0] for p in KAUTHAM_PROPERTIES], map(str, SOLVED)))
    # each pass: the first state, then per segment ceil(length / 0.02) states at least, and at
    # least one per segment: found path max(4, 25) = 25, simplified max(1, 15) = 15; the strict
    # passes as many (OMPL 1.5's compound spaces ignore their factor of 4)
    assert path_checks(run, segment) == 2 * (1 + 25) + 2 * (1 + 15)
    # a pass that found the path invalid stopped early: nothing of it is counted
    run["simplified correct solution strict"] = "0"
    assert path_checks(run, segment) == 2 * (1 + 25) + (1 + 15)
    # a space of several components: one state per segment and pass at least
    assert path_checks(run, None) == 2 * (1 + 4) + (1 + 1)
    unsolved = dict(zip([p.rsplit(" ", 1)[0] for p in KAUTHAM_PROPERTIES], map(str, UNSOLVED)))
    assert path_checks(unsolved, segment) == 0


def test_kautham_tally_takes_the_path_checks_out_of_its_rate():
    tally = bench_geo_checks.kautham_tally(read_log(_kautham_log([SOLVED, UNSOLVED])))
    assert tally == Tally(runs=2, checks=1700, untimed=84, seconds=pytest.approx(1.5))
    assert tally.rate() == pytest.approx((1700 - 84) / 1.5)


def test_kautham_segment_comes_from_the_space_extent_and_fraction():
    one = read_log(_kautham_log([SOLVED], extent=16.912, fraction=0.00118259))
    assert bench_geo_checks.segment_length(one, "geometric_p") == pytest.approx(0.02, rel=1e-4)
    two = read_log(_kautham_log([SOLVED], leaves=(
        "Real vector state space 'base' of dimension 1 with bounds:",
        "SO(2) state space 'turn' of dimension 1")))
    assert bench_geo_checks.segment_length(two, "geometric_p") is None
    assert bench_geo_checks.kautham_tally(two).untimed == 2 * (1 + 4) + 2 * (1 + 1)


def test_odin_tally_is_every_check_over_search_and_simplification():
    tally = bench_geo_checks.odin_tally(read_log(_odin_log([(250, 0.006, 0.0004),
                                                            (4000, 1.0, "")])))
    assert tally == Tally(runs=2, checks=4250, untimed=0, seconds=pytest.approx(1.0064))
    assert tally.rate() == pytest.approx(4250 / 1.0064)


def test_a_log_without_collision_checks_is_refused():
    with pytest.raises(ValueError, match="run 2 has no collision checks"):
        bench_geo_checks.odin_tally(read_log(_odin_log([(250, 0.006, 0.0004),
                                                        ("", 0.0, "")])))


def test_rates_per_problem_and_the_smaller_ratio_over_both():
    measured = {"tx90": (Tally(10, 30000, 10000, 4.0), Tally(10, 3000, 0, 0.06)),
                "ur5": (Tally(10, 50000, 10000, 8.0), Tally(10, 150000, 0, 3.0))}
    figures = figures_of(measured, ("tx90", "ur5"))
    assert figures == {"geo_checks_per_s_tx90_kautham": 5000.0, "geo_checks_per_s_tx90": 50000.0,
                       "geo_checks_per_s_ur5_kautham": 5000.0, "geo_checks_per_s_ur5": 50000.0,
                       "geo_checks_over_kautham": 10.0}
    measured["ur5"] = (Tally(10, 50000, 10000, 8.0), Tally(10, 7500, 0, 3.0))
    assert figures_of(measured, ("tx90", "ur5"))["geo_checks_over_kautham"] == 0.5


def test_a_side_without_an_answer_refuses_its_rate_and_the_ratio():
    measured = {"tx90": (Refused("Kautham wrote no log"), Tally(10, 3000, 0, 0.06)),
                "ur5": (Tally(10, 50000, 10000, 8.0), Tally(10, 150000, 0, 3.0))}
    figures = figures_of(measured, ("tx90", "ur5"))
    assert figures["geo_checks_per_s_tx90_kautham"].reason == "Kautham wrote no log"
    assert figures["geo_checks_over_kautham"].reason == "tx90: Kautham wrote no log"
    assert figures["geo_checks_per_s_ur5"] == 50000.0


def test_without_kautham_odins_rates_come_and_no_ratio():
    figures = figures_of({"tx90": (None, Tally(10, 3000, 0, 0.06))}, ("tx90", "ur5"))
    assert figures == {"geo_checks_per_s_tx90": 50000.0}


def test_a_problem_not_measured_refuses_the_ratio_naming_it():
    measured = {"tx90": (Tally(10, 30000, 10000, 4.0), Tally(10, 3000, 0, 0.06))}
    ratio = figures_of(measured, ("tx90", "ur5"))["geo_checks_over_kautham"]
    assert isinstance(ratio, Refused) and ratio.reason.startswith("ur5 not measured")


def test_the_benchmark_file_is_kauthams_format_with_the_problem_relative_to_it(tmp_path):
    problem = tmp_path / "corpus" / "demos" / "p.xml"
    folder = tmp_path / "work"
    text = bench_geo_checks.benchmark_text("p", problem, folder, 2.5, 4)
    assert '<Problem File="../corpus/demos/p.xml" PlannerAlias="p" />' in text
    for name, value in (("maxTime", "2.5"), ("runCount", "4"), ("filename", "p.log"),
                        ("saveConsoleOutput", "false")):
        assert f'<Parameter Name="{name}" Value="{value}" />' in text


def test_without_kauthams_build_the_module_says_so_in_one_line_and_odin_still_runs(
        monkeypatch, tmp_path, capsys):
    problem = tmp_path / "p.xml"
    problem.write_text('<Problem><Planner><Parameters><Parameter name="_Max Planning Time">'
                       '1.5</Parameter></Parameters></Planner></Problem>')
    monkeypatch.setattr(bench_geo_checks, "CONSOLE", tmp_path / "no_build" / "kautham-console")
    monkeypatch.setattr(bench_geo_checks, "problems", lambda: {"tx90": problem})
    asked = []

    def odin_round(file, work, seed, limit_s):
        asked.append((file.read_text(), seed))
        return _odin_log([(250, 0.006, 0.0004), (4000, 1.0, "")])

    monkeypatch.setattr(bench_geo_checks, "_odin_round", odin_round)
    figures = bench_geo_checks.run(tmp_path / "out")
    assert set(figures) == {"geo_checks_per_s_tx90"}
    assert figures["geo_checks_per_s_tx90"] == round(4250 / 1.0064)
    skipped = [line for line in capsys.readouterr().out.splitlines() if "skipped" in line]
    assert len(skipped) == 1 and "make bench-kautham" in skipped[0]
    assert len(asked) == bench_geo_checks.ROUNDS
    assert all('Value="1.5"' in text for text, _ in asked)     # the problem's own limit
    assert [seed for _, seed in asked] == [1 + r * bench_geo_checks.RUNS
                                           for r in range(bench_geo_checks.ROUNDS)]
