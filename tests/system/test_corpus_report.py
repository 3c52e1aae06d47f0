"""make corpus's bookkeeping (tools/corpus): a refusal is expected only when the file is not a
problem or names a file the repository lacks, each file's outcome joins both passes, and the
README's figures are rewritten between their markers only."""
import pathlib
import sys

import pytest

TOOLS = pathlib.Path(__file__).resolve().parents[2] / "tools" / "corpus"
sys.path.insert(0, str(TOOLS))

import corpus_checks as checks  # noqa: E402
import corpus_report as report  # noqa: E402


@pytest.mark.parametrize("reason,kind", [
    ("/c/x.xml:1: is a Kautham benchmark file (<Benchmark>: ...), not a problem: ...",
     "not a problem"),
    ("/c/x.xml:2: is a Kautham configuration file (<Config>: ...), not a problem",
     "not a problem"),
    ('/c/x.xml:22: file "BRONCO/broncoGrid.wrl" not found (looked in: /c/BRONCO)',
     "missing file"),
    ("/c/models/a.dae: geometry file not found", "missing file"),
    ("/c/x.xml:5: <Home X=\"0.5 1\">: '0.5 1' is not a number", "unexpected"),
    ("/c/r.urdf:9: joint type \"floating\" is not supported", "unexpected"),
])
def test_a_refusal_is_expected_only_for_what_is_not_a_problem_or_absent(reason, kind):
    assert checks.refusal_kind(pathlib.Path("/c"), "x.xml", reason) == kind


def test_counts_join_problem_info_and_the_world():
    results = {
        "a.xml": dict(status="ok", world="ok"),
        "b.xml": dict(status="ok", world="failed", world_reason="1 bodies diverged"),
        "c.xml": dict(status="refused", refusal="missing file", reason="..."),
        "d.xml": dict(status="refused", refusal="unexpected", reason="..."),
        "e.xml": dict(status="failed", traceback=True, reason="exit 1: KeyError: 'Base'"),
    }
    c = report.counts(results)
    assert (c["ok"], c["failed"], c["refused"], c["tracebacks"]) == (1, 2, 2, 1)
    assert (c["refused_missing"], c["refused_unexpected"], c["world_failed"]) == (1, 1, 1)
    assert "2 failed, 1 tracebacks" in report.summary_line(c)


def test_the_readme_block_is_rewritten_between_its_markers_only(tmp_path):
    readme = tmp_path / "README.md"
    readme.write_text(f"before\n{report.BEGIN}\nold figures\n{report.END}\nafter\n")
    report.rewrite_readme("new figures\n", readme)
    assert readme.read_text() == f"before\n{report.BEGIN}\nnew figures\n{report.END}\nafter\n"
    readme.write_text("no markers\n")
    with pytest.raises(ValueError, match="markers"):
        report.rewrite_readme("x\n", readme)


def test_parts_built_inside_each_other_are_counted_shown_and_explain_a_failure():
    """A file's pairs built inside each other (gui.core.overlaps) show in its row, whatever
    its outcome, and join the reason of a failure they explain."""
    from gui.core.model import FIXED_BASE
    overlaps = [["TX90/Arm", "columns#2", 0.0473], ["TX90/Base", "columns#0", 0.04]]
    robot = dict(name="TX90", kind=FIXED_BASE, moved_m=0.0588, outside_limits=[])
    result = dict(diverged=0, fell=[], robots=[robot], overlaps=overlaps)
    faults = checks._faults(result, {})
    assert faults == ["fixed-base robot TX90 moved 58.8 mm",
                      "built with 2 pairs inside each other where the problem places them "
                      "(deepest TX90/Arm in columns#2, 47.3 mm)"]
    assert checks._faults(dict(result, overlaps=[]), {}) == faults[:1]
    results = {"a.xml": dict(status="ok", world="failed", world_reason="; ".join(faults),
                             robots=[robot], overlaps=overlaps),
               "b.xml": dict(status="ok", world="ok", robots=[], overlaps=[])}
    run = dict(corpus="/c", seconds=2.0, simulated=True, only="", started=0.0, tests=None)
    text = report.markdown(run, results, report.counts(results))
    assert "1 files build parts inside each other" in text
    row = next(line for line in text.splitlines() if line.startswith("| a.xml "))
    assert row.endswith("| 2 (TX90/Arm in columns#2, 47.3) |")
    assert next(line for line in text.splitlines()
                if line.startswith("| b.xml ")).endswith("|  |")
