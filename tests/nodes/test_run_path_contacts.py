"""run_path reports the collisions a path makes, apart from the contacts the scene rests on,
in position mode and in tracked mode under the kinematic drive (issue 41, findings 3 and 6):
two cranes of our own, the second turned a quarter turn so that slewing it 1.5 rad lays its
boom across the first's. Before, a position path drove the booms through each other without
a word, and under --kinematic the tracked run said "0 colliding pairs"."""
from __future__ import annotations

import re

import pytest
from crane import CRANE_URDF

pytestmark = pytest.mark.forked

PROBLEM = """<?xml version="1.0"?><Problem>
 <Robot robot="crane.urdf"><Home X="0" Y="0" Z="0.5" WX="0" WY="0" WZ="1" TH="0"/></Robot>
 <Robot robot="crane.urdf"><Home X="1.2" Y="0" Z="0.5" WX="0" WY="0" WZ="1" TH="1.5708"/>
 </Robot>
</Problem>"""
BOOMS = re.compile(r"crane/boom \| crane_2/boom (\d+\.\d) mm at (\d+\.\d\d) s")


def _problem(folder):
    (folder / "crane.urdf").write_text(CRANE_URDF)
    problem = folder / "cranes.xml"
    problem.write_text(PROBLEM)
    return problem


def test_a_position_path_driving_one_crane_into_the_other_says_so(world, tmp_path):
    problem = _problem(tmp_path)
    path = tmp_path / "slew.path"
    path.write_text("0\n0.3\n0.6\n0.9\n1.2\n1.5\n")
    world.run(["rosrun", "GUI", "load_problem", str(problem)], timeout=60)
    run = world.run(["rosrun", "GUI", "run_path", str(problem), "--position", str(path),
                     "--robot", "crane_2", "--rate", "50"], timeout=60)
    lines = run.stdout.splitlines()
    last = lines[-1]
    assert last.startswith("crane_2: 6 rows at 50 Hz done, 1 colliding pair made by the path ")
    assert last.endswith(", 0 resting contacts"), last
    depth, when = BOOMS.search(last).groups()
    assert float(depth) > 20.0                  # 25 mm: the booms lie across each other
    assert 0.0 < float(when) <= 6 / 50
    # and a line the moment it happens
    assert any(line.startswith("[") and "crane/boom | crane_2/boom collide" in line
               for line in lines[:-1]), lines


@pytest.mark.parametrize("kinematic", [False, True])
def test_a_tracked_run_reports_the_booms_met_under_either_drive(world, tmp_path, kinematic):
    problem = _problem(tmp_path)
    path = tmp_path / "slew.path"
    path.write_text("0\n1.5\n")
    world.run(["rosrun", "GUI", "load_problem", str(problem)], timeout=60)
    run = world.run(["rosrun", "GUI", "run_path", str(problem), "--tracked", str(path),
                     "--robot", "crane_2", "--fast"] + (["--kinematic"] if kinematic else []),
                    timeout=120)
    last = run.stdout.splitlines()[-1]
    assert "1 colliding pair made by the path (crane/boom | crane_2/boom" in last, last
    assert ", 0 resting contacts, solver " in last, last


def test_an_initial_position_inside_the_other_crane_says_so(world, tmp_path):
    problem = _problem(tmp_path)
    path = tmp_path / "across.path"
    path.write_text("1.5\n")
    world.run(["rosrun", "GUI", "load_problem", str(problem)], timeout=60)
    run = world.run(["rosrun", "GUI", "run_path", str(problem), "--initial", str(path),
                     "--robot", "crane_2"], timeout=60)
    last = run.stdout.splitlines()[-1]
    assert last.startswith("crane_2: initial position set (2 bodies), 1 colliding pair made by "
                           "the path (crane/boom | crane_2/boom "), last
