"""make corpus's planning pass (tools/corpus/corpus_plan.py through run.py): over a corpus of
our own, a geometric problem is planned and solved, one whose start collides is refused with
its line, a physics problem is skipped; a search that raises, crashes or hangs is a failure
with its reason (and the run's exit status 1); the README says when the searches were
capped."""
import faulthandler
import json
import os
import pathlib
import signal
import sys
import time

import pytest

TOOLS = pathlib.Path(__file__).resolve().parents[2] / "tools" / "corpus"
sys.path.insert(0, str(TOOLS))

import corpus_plan as planning  # noqa: E402
import corpus_report as report  # noqa: E402
import run  # noqa: E402

ARM = """<?xml version="1.0"?><robot name="arm">
 <link name="base"><inertial><mass value="5"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0"
  ixz="0" iyz="0"/></inertial><collision><geometry><box size="0.2 0.2 0.1"/></geometry>
  </collision></link>
 <link name="upper"><inertial><origin xyz="0.25 0 0"/><mass value="1"/><inertia ixx="0.001"
  iyy="0.021" izz="0.021" ixy="0" ixz="0" iyz="0"/></inertial><collision><origin
  xyz="0.25 0 0"/><geometry><box size="0.5 0.05 0.05"/></geometry></collision></link>
 <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/><origin
  xyz="0 0 0.1"/><axis xyz="0 0 1"/><limit lower="-2" upper="2" effort="30" velocity="1.5"/>
 </joint>
</robot>"""
CNTR = """<?xml version="1.0"?><ControlSet>
 <Offset><DOF name="arm/upper" value="0.5"/></Offset>
 <Control name="arm/shoulder" eigValue="1.0"><DOF name="arm/upper" value="1.0"/></Control>
</ControlSet>"""
POST = """<?xml version="1.0"?><robot name="post"><link name="base"><collision><geometry>
 <box size="0.1 0.1 0.6"/></geometry></collision></link></robot>"""
PROBLEM = """<?xml version="1.0"?><Problem>
 <Robot robot="arm.urdf"><Home X="0" Y="0" Z="0" WX="0" WY="0" WZ="1" TH="0"/></Robot>
 <Obstacle obstacle="post.urdf"><Home X="0.4" Y="0" Z="0.1" WX="0" WY="0" WZ="1" TH="0"/>
 </Obstacle>
 <Controls robot="arm.cntr"/>
 <Planner><Parameters><Name>PLANNER</Name>
  <Parameter name="_Max Planning Time">5</Parameter></Parameters>
  <Queries><Query><Init>INIT</Init><Goal>0.1</Goal></Query></Queries></Planner>
</Problem>"""
# the shoulder at -2 + 4 c rad: c 0.1 points the arm along -1.6 rad, c 0.2 along -1.2 rad, both
# clear of the post on +x; c 0.5 points it along +x, through the post


def _corpus(folder: pathlib.Path) -> pathlib.Path:
    """A corpus of three problems: solvable (straight), its start in the post, physics."""
    folder.mkdir()
    (folder / "ALL.md").write_text("a corpus of our own\n")
    for name, text in (("arm.urdf", ARM), ("arm.cntr", CNTR), ("post.urdf", POST)):
        (folder / name).write_text(text)
    for name, planner, init in (("clear.xml", "omplRRTConnect", "0.2"),
                                ("collides.xml", "omplRRTConnect", "0.5"),
                                ("physics.xml", "KPIECEChainPlanner", "0.2")):
        (folder / name).write_text(PROBLEM.replace("PLANNER", planner).replace("INIT", init))
    return folder


def _run(corpus: pathlib.Path, out: pathlib.Path, *more: str) -> tuple:
    code = run.main(["--corpus", str(corpus), "--no-simulation", "--no-tests", "--no-readme",
                     "--out", str(out), *more])
    return code, json.loads((out / "report.json").read_text())


def test_a_problem_is_solved_one_refused_with_its_line_and_physics_skipped(tmp_path):
    code, written = _run(_corpus(tmp_path / "corpus"), tmp_path / "out")
    files = written["files"]
    assert code == 0 and written["run"]["planned"] and written["run"]["plan_seconds"] is None
    solved = files["clear.xml"]
    assert (solved["plan"], solved["ompl_planner"], solved["time_limit"]) == \
        ("solved", "RRTConnect", 5.0)
    assert solved["states"] >= 2 and solved["checks"] > 0 and 0 < solved["plan_s"] < 5
    refused = files["collides.xml"]
    assert (refused["plan"], refused["refusal"]) == ("refused", "start collides")
    assert "the query's start collides: arm/upper is" in refused["plan_reason"]
    assert (files["physics.xml"]["plan"], files["physics.xml"]["skip"]) == \
        ("skipped", "physics")
    text = (tmp_path / "out" / "report.md").read_text()
    assert "| clear.xml | omplRRTConnect | RRTConnect | 5.0 | solved |" in text
    assert "| collides.xml | omplRRTConnect | RRTConnect | 5.0 | refused | start collides: " \
        "the query's start collides: arm/upper is" in text
    assert "| physics.xml | omplRRT" not in text and "1 physics problems" in text


def test_plan_seconds_caps_the_problems_time_limit(tmp_path):
    corpus = _corpus(tmp_path / "corpus")
    code, written = _run(corpus, tmp_path / "out", "--plan-seconds", "0.5", "--only", "clear")
    assert code == 0 and written["files"]["clear.xml"]["time_limit"] == 0.5
    assert written["run"]["plan_seconds"] == 0.5


def _raises():
    raise KeyError("Base")


def _crashes():
    faulthandler.disable()              # pytest's: it would print the crash on the terminal
    os.kill(os.getpid(), signal.SIGSEGV)


def _hangs_loading():
    time.sleep(60)


def _hangs():
    print(json.dumps(dict(ompl_planner="RRT", time_limit=0.1)), flush=True)
    time.sleep(60)


@pytest.mark.parametrize("child,reason", [
    (_raises, "exit 1: KeyError: 'Base'"),
    (_crashes, "crashed: SIGSEGV"),
    (_hangs, "hung: still searching 0.5 s past its 0.1 s time limit"),
    (_hangs_loading, "hung loading the problem (no search after 1 s)"),
])
def test_a_search_that_raises_crashes_or_hangs_is_a_failure_with_its_reason(
        monkeypatch, child, reason):
    monkeypatch.setattr(planning, "PLAN_MARGIN", 0.5)
    monkeypatch.setattr(planning, "LOAD_TIMEOUT", 1.0)
    started = time.monotonic()
    result = planning.plan_one("unused.xml", child=child)
    assert (result["plan"], result["plan_reason"]) == ("failed", reason)
    assert result["plan_traceback"] == (child is _raises)
    assert time.monotonic() - started < 10


def test_a_failed_search_fails_the_run(tmp_path, monkeypatch):
    monkeypatch.setattr(planning, "plan_child", lambda path, cap: _crashes())
    code, written = _run(_corpus(tmp_path / "corpus"), tmp_path / "out", "--only", "clear")
    assert code == 1 and written["files"]["clear.xml"]["plan"] == "failed"


def test_the_readme_says_when_the_searches_were_capped_or_not_run():
    results = {"a.xml": dict(status="ok", plan="solved"),
               "b.xml": dict(status="ok", plan="refused", refusal="no query"),
               "c.xml": dict(status="ok", plan="refused", refusal="planner unknown"),
               "d.xml": dict(status="ok", plan="refused", refusal="planner unknown"),
               "e.xml": dict(status="ok", plan="skipped", skip="physics")}
    c = report.counts(results)
    run_ = dict(started=0.0, minutes=1.0, seconds=2.0, tests=None, planned=True,
                plan_seconds=None)
    own = report.readme_block(run_, c)
    assert "| 4 | 1 | 0 | 3 (2 planner unknown, 1 no query) | 0 | 1 | 0 |" in own
    assert "capped" not in own
    assert "capped at 5 s" in report.readme_block(dict(run_, plan_seconds=5.0), c)
    assert "Planning (the geometric problems searched): not run." in \
        report.readme_block(dict(run_, planned=False), c)
