"""The benchmark report (tools/bench/report.py): goals checked, README table generated from the
figures; and bench_core's same-work check. No ROS, no benchmark run."""
import io
import json
import math
import pathlib
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tools" / "bench"))

import bench_core  # noqa: E402
import report  # noqa: E402

GOALS = {
    "host_native_ode_steps_per_s": {"unit": "steps/s", "what": "the host"},
    "speed_ratio": {"min": 0.95, "unit": "ratio", "what": "native / odin"},
    "frame_ms": {"max": 40, "unit": "ms", "what": "one frame"},
    "crashes": {"max": 0, "unit": "count", "what": "crashes"},
    "band": {"min": 1, "max": 2, "unit": "x real time", "what": "a range"},
    "latency_p99_ms": {"unit": "ms", "what": "no goal"},
}
README = "# Odin\n\n## Performance\n\nprose\n\n" + report.BEGIN + "\nold table\n" + report.END + \
    "\n\nmore prose\n"


def _results(**changes):
    results = {"host_native_ode_steps_per_s": 2978, "speed_ratio": 0.985, "frame_ms": 17.8,
               "crashes": 0.0, "band": 1.5, "latency_p99_ms": 5.54}
    results.update(changes)
    return {k: v for k, v in results.items() if v is not None}


def _report(results, tmp_path, run=None):
    readme = tmp_path / "README.md"
    readme.write_text(README)
    out = io.StringIO()
    status = report.report(results, GOALS, run or {}, readme, out=out)
    return status, out.getvalue(), readme.read_text()


def test_all_goals_met_exits_zero_and_writes_the_table(tmp_path):
    status, printed, readme = _report(_results(), tmp_path)
    assert status == 0, printed
    assert "all 4 goals met" in printed
    assert "old table" not in readme
    assert readme.startswith("# Odin\n\n## Performance\n\nprose\n\n" + report.BEGIN + "\n")
    assert readme.endswith(report.END + "\n\nmore prose\n")
    rows = [line for line in readme.splitlines() if line.startswith("| `")]
    assert [row.split("`")[1] for row in rows] == list(GOALS)      # goals.json's order
    assert "| `speed_ratio` | ≥ 0.95 | 0.985 | native / odin |" in readme
    assert "| `crashes` | ≤ 0 | 0 | crashes |" in readme
    # absolute figures carry the host figure; ratios and counts do not
    assert "| `frame_ms` | ≤ 40 ms | 17.8 ms (host 2,978 steps/s) | one frame |" in readme
    assert "| `band` | ≥ 1 x real time and ≤ 2 x real time | 1.5 x real time (host 2,978" \
        in readme
    assert "| `host_native_ode_steps_per_s` | - | 2,978 steps/s | the host |" in readme


def test_a_missed_goal_is_printed_and_fails(tmp_path):
    status, printed, readme = _report(_results(frame_ms=55.25, speed_ratio=0.9), tmp_path)
    assert status == 1
    assert "MISSED  frame_ms = 55.2 ms, goal ≤ 40 ms" in printed
    assert "MISSED  speed_ratio = 0.9, goal ≥ 0.95" in printed
    assert "2 of 4 goals not met" in printed
    assert "**55.2 ms (missed)** (host 2,978 steps/s)" in readme


def test_a_missing_figure_fails_with_its_reason(tmp_path):
    run = {"refused": {"speed_ratio": "final poses differ"}, "failed_modules": ["viewer"]}
    status, printed, readme = _report(_results(speed_ratio=None, frame_ms=None), tmp_path, run)
    assert status == 1
    assert "MISSING speed_ratio: goal ≥ 0.95; refused: final poses differ" in printed
    assert "MISSING frame_ms: goal ≤ 40 ms; failed benchmark modules: viewer" in printed
    assert "| `speed_ratio` | ≥ 0.95 | **missing**: refused: final poses differ |" in readme


def test_a_missing_figure_without_goal_does_not_fail(tmp_path):
    status, printed, readme = _report(_results(latency_p99_ms=None), tmp_path)
    assert status == 0, printed
    assert "| `latency_p99_ms` | - | **missing** | no goal |" in readme


def test_absolute_figures_carry_the_host_probed_around_their_module(tmp_path):
    run = {"figure_modules": {"frame_ms": "viewer", "band": "experiments"},
           "host_by_module": {"viewer": 1234, "experiments": 987}}
    status, printed, readme = _report(_results(), tmp_path, run)
    assert status == 0, printed
    assert "| 17.8 ms (host 1,234 steps/s) |" in readme
    assert "| 1.5 x real time (host 987 steps/s) |" in readme
    assert "| 5.54 ms (host 2,978 steps/s) |" in readme     # no probe: the run's figure


def test_caption_says_when_how_long_and_how_fast_the_host_was():
    run = {"finished": "2026-11-23 00:21 UTC", "seconds": 861.5, "failed_modules": ["gui"],
           "host_probes": [{"before": "core", "steps_per_s": 2696},
                           {"before": "gui", "steps_per_s": None},
                           {"before": "end", "steps_per_s": 4685}]}
    assert report.caption(run) == ("Last run: 2026-11-23 00:21 UTC; `make bench` took 14.4 min; "
                                   "host probes 2,696-4,685 native steps/s over the run; "
                                   "failed modules: gui.\n\n")


def test_boundaries_nan_and_undescribed_figures():
    goals = {"a": {"min": 1.0, "unit": "ratio", "what": "a"}}
    assert report.check({"a": 1.0}, goals) == []                # goals are inclusive
    assert report.check({"a": math.nan}, goals)                  # NaN misses
    assert report.check({}, goals, only_present=True) == []      # partial run: not measured
    table = report.table({"a": 1.0, "new_figure": 3.0}, goals)
    assert "| `new_figure` | - | 3 (host ?) | (not described in goals.json) |" in table


def test_the_repository_goals_file_is_valid_and_has_todays_goals():
    goals = report.load_goals()
    assert goals["core_spheres100_ratio"]["min"] == 0.95
    assert goals["rtf_grasp"]["min"] == 2.0                 # issue 14's goals
    assert goals["rtf_grasp_viewer_ratio"]["min"] == 0.8
    assert goals["viewer_frame_ms_grasp"]["max"] == 15
    assert goals["portal_calls_under_load"]["max"] == 0
    assert goals["flagship_hold_drift_mm"]["max"] == 1.0      # issue 28: defaults hold robots
    assert report.HOST_FIGURE in goals
    text = (ROOT / "README.md").read_text()
    assert text.count(report.BEGIN) == 1 and text.count(report.END) == 1


def test_a_malformed_goal_is_rejected(tmp_path):
    path = tmp_path / "goals.json"
    path.write_text(json.dumps({"x": {"mni": 1, "unit": "s", "what": "typo"}}))
    with pytest.raises(ValueError, match="unknown keys"):
        report.load_goals(path)
    path.write_text(json.dumps({"x": {"min": "1", "unit": "s", "what": "a string"}}))
    with pytest.raises(ValueError, match="must be a number"):
        report.load_goals(path)


def _run(contacts=100, poses=None):
    return bench_core.Run(1.0, contacts, poses or tuple((0.1 * i, 0, 0.1, 1, 0, 0, 0)
                                                        for i in range(100)))


def test_same_work_is_exact_contacts_and_poses():
    assert bench_core.work_difference(_run(), _run()) is None
    assert "contacts differ: native 100, Odin 99" in bench_core.work_difference(_run(), _run(99))
    poses = list(_run().poses)
    poses[7] = (0.7, 0, 0.1 + 1e-15, 1, 0, 0, 0)
    assert "s7.z" in bench_core.work_difference(_run(), _run(poses=tuple(poses)))
    poses[7] = (0.7, 0, math.nan, 1, 0, 0, 0)
    assert "s7.z" in bench_core.work_difference(_run(), _run(poses=tuple(poses)))


def test_native_output_parses_with_checkpoints():
    pose = "0.5 0.25 0.10000000000000001 1 0 0 0\n"
    out = "after 3 7\n" + pose * 100 + "0.125 9\n" + pose * 100
    run = bench_core.parse_run(out)
    assert (run.seconds, run.contacts, run.poses[0][2]) == (0.125, 9, 0.1)
    assert list(bench_core.parse_checkpoints(out)) == [3]
    assert bench_core.parse_checkpoints(out)[3].contacts == 7
