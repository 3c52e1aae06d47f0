"""The motion checks of a geometric search (gui.planning.geometric_world): a motion they pass
takes no link deeper than half the resolution into anything, checked four times finer on
random motions of our own arm around its post; far from everything they certify long steps
by clearance and check few configurations exactly; the robots' bounds hold their links."""
from __future__ import annotations

import pathlib
import subprocess
import sys

import numpy as np
import pytest

from gui.planning.geometric import GeometricWorld, query
from gui.planning.geometric_robots import _point_distances, planned_robots
from test_geometric_planning import _plan, _problem


def _deepest(world, a, b, fine):
    deepest = 0.0
    for point in fine.motion_points(a, b):
        deepest = max([deepest] + [depth for _, _, depth in fine.collisions(point)])
    return deepest


def _random_motions_stay_within_the_promise(plan, seed: int) -> None:
    """15 random motions passed at a 4 mm resolution go no deeper than 2 mm into anything,
    checked four times finer; at least 5 others failed (the obstacles were met too: not a
    vacuous test)."""
    world = GeometricWorld(plan, resolution=0.004)
    fine = GeometricWorld(plan, resolution=0.001)
    rng = np.random.default_rng(seed)
    try:
        passed = failed = 0
        while passed < 15:
            a, b = rng.random(2), rng.random(2)
            if not world.valid(a):
                continue
            if world.motion_valid(a, b):
                passed += 1
                assert _deepest(world, a, b, fine) <= 0.002
            else:
                failed += 1
        assert failed >= 5
    finally:
        world.close()
        fine.close()


def test_every_motion_passed_goes_no_deeper_than_half_the_resolution(tmp_path):
    _random_motions_stay_within_the_promise(_plan(_problem(tmp_path)), seed=11)


def test_a_motion_far_from_everything_is_certified_not_walked(tmp_path):
    """The arm swung 3 rad away from the post (start and goal both at x < 0) is certified by
    clearances in a few steps, where the resolution alone would check hundreds of points."""
    plan = _plan(_problem(tmp_path, init="0.2 0.5", goal="0.2 0.9"))
    world = GeometricWorld(plan)
    try:
        start, goal = query(plan)
        walked = len(world.motion_points(start, goal))
        assert walked > 200
        assert world.motion_valid(start, goal)
        assert world.checks + world.clearance_checks < walked / 10
    finally:
        world.close()


def test_a_motion_into_the_post_fails(tmp_path):
    plan = _plan(_problem(tmp_path))
    world = GeometricWorld(plan)
    try:
        start, goal = query(plan)
        assert not world.motion_valid(start, goal)
    finally:
        world.close()


def test_each_link_stays_within_its_capsule_and_box_and_moves_within_its_bound(tmp_path):
    """At random configurations every vertex of a link's box geometry lies in its capsule and
    its box; between two, no link frame corner moves farther than its bound."""
    plan = _plan(_problem(tmp_path))
    robot = planned_robots(plan)[0]
    rng = np.random.default_rng(2)
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)])
    half = {1: np.array([0.25, 0.025, 0.025]), 2: np.array([0.2, 0.02, 0.02])}
    centre = {1: np.array([0.25, 0.0, 0.0]), 2: np.array([0.2, 0.0, 0.0])}
    for _ in range(50):
        a, b = robot.configuration(rng.random(2)), robot.configuration(rng.random(2))
        frames_a, frames_b = robot.object_frames(a), robot.object_frames(b)
        bounds = robot.link_bounds(a, b)
        for k in (1, 2):
            local = corners * half[k] + centre[k] - robot.handle.bodies[k].offset[:3, 3]
            world_a = local @ frames_a[k][:3, :3].T + frames_a[k][:3, 3]
            world_b = local @ frames_b[k][:3, :3].T + frames_b[k][:3, 3]
            assert np.max(np.linalg.norm(world_b - world_a, axis=1)) <= bounds[k] + 1e-12
            capsule, pose = robot.capsules[k], frames_a[k]
            ends = capsule[:6].reshape(2, 3) @ pose[:3, :3].T + pose[:3, 3]
            assert np.all(_point_distances(world_a, *ends) <= capsule[6] + 1e-12)
            box, pose = robot.boxes[k], frames_a[k]
            axes = pose[:3, :3] @ box[3:12].reshape(3, 3)
            inside = (world_a - pose[:3, :3] @ box[:3] - pose[:3, 3]) @ axes
            assert np.all(np.abs(inside) <= box[12:15] + 1e-12)


PLATE = """<?xml version="1.0"?><robot name="plate"><link name="base"><collision><geometry>
 <box size="0.05 0.01 0.05"/></geometry></collision></link></robot>"""
PLATE_CNTR = """<?xml version="1.0"?><ControlSet>
 <Offset><DOF name="plate/X" value="0.5"/><DOF name="plate/Y" value="0.5"/></Offset>
 <Control name="plate/x" eigValue="1.0"><DOF name="plate/X" value="1.0"/></Control>
 <Control name="plate/y" eigValue="1.0"><DOF name="plate/Y" value="1.0"/></Control>
</ControlSet>"""
CORRIDOR = """<?xml version="1.0"?><robot name="corridor">
 <link name="floor"><collision><origin xyz="0.5 0.5 -0.05"/><geometry><box size="1 1 0.1"/>
  </geometry></collision></link>
 <link name="wall"><collision><origin xyz="0.5 0.5 0.05"/><geometry><box size="0.04 0.7 0.1"/>
  </geometry></collision></link>
 <joint name="f" type="fixed"><parent link="floor"/><child link="wall"/></joint></robot>"""
PLATE_PROBLEM = """<?xml version="1.0"?><Problem>
 <Robot robot="plate.urdf"><Limits name="X" min="0" max="1"/><Limits name="Y" min="0" max="1"/>
  <Limits name="Z" min="0.006" max="0.006"/>
  <Home X="0" Y="0" Z="0.006" WX="0" WY="0" WZ="1" TH="0"/></Robot>
 <Obstacle obstacle="corridor.urdf"><Home X="0" Y="0" Z="0" WX="0" WY="0" WZ="1" TH="0"/>
 </Obstacle>
 <Controls robot="plate.cntr"/>
 <Planner><Parameters><Name>omplRRTConnect</Name>
  <Parameter name="_Max Planning Time">10</Parameter></Parameters>
  <Queries><Query><Init>0.2 0.2</Init><Goal>0.8 0.2</Goal></Query></Queries></Planner>
</Problem>"""
# the plate (5 cm square, 1 cm thick: Kautham turns its y up, as it turns its demos' bigcube, by
# the rotation its controls leave at their offsets) slides 1 mm above the floor; a wall x in
# [0.48, 0.52], y in [0.15, 0.85] stands between start and goal


def _plate_plan(folder):
    from kautham_files import write_problem
    return _plan(write_problem(folder, {"plate.urdf": PLATE, "plate.cntr": PLATE_CNTR,
                                        "corridor.urdf": CORRIDOR}, "plate.xml",
                               PLATE_PROBLEM))


def test_a_plate_sliding_1_mm_above_the_floor_is_swept_not_walked(tmp_path):
    """Its clearance is 1 mm everywhere (the floor), so the clearance walk would go at the
    resolution; what it sweeps translating is free of the floor, and a motion along the wall
    takes a few sweeps. Through the wall it fails."""
    plan = _plate_plan(tmp_path)
    world = GeometricWorld(plan)
    try:
        along = (np.array([0.2, 0.1]), np.array([0.8, 0.1]))     # south of the wall's end
        walked = len(world.motion_points(*along))
        assert walked > 200
        assert world.motion_valid(*along)
        assert world.checks + world.clearance_checks < 10
        assert not world.motion_valid(np.array([0.2, 0.5]), np.array([0.8, 0.5]))
    finally:
        world.close()


def test_every_swept_motion_passed_goes_no_deeper_than_half_the_resolution(tmp_path):
    _random_motions_stay_within_the_promise(_plate_plan(tmp_path), seed=4)


PRM_RUN = """
import logging, pathlib, sys
from dataclasses import replace
logging.disable(logging.WARNING)
sys.path.insert(0, {here!r})
from gui.planning.geometric import GeometricSettings, solve
from test_geometric_motions import _plate_plan
plan = _plate_plan(pathlib.Path({folder!r}))
settings = replace(GeometricSettings.of_problem(plan), planner="PRM", time_limit=2.0)
print("solved", solve(plan, settings, seed={seed}).solved)
"""


@pytest.mark.parametrize("seed", [1, 4])
def test_prm_solves_and_ends_in_its_time(tmp_path, seed):
    """PRM looks for a solution on a thread of its own, which asks the termination condition:
    a Python one there waited for the interpreter's lock the planner's thread held (a hang, or
    no solution ever found). In a process of its own, so that a hang fails the test."""
    here = str(pathlib.Path(__file__).resolve().parent)
    code = PRM_RUN.format(here=here, folder=str(tmp_path), seed=seed)
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=30)
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.split()[-2:] == ["solved", "True"]


def test_the_search_measures_controls_as_kautham_measures_configurations(tmp_path):
    """Kautham's OMPL space is the configuration space (joints in rad, a base's position in
    m), where its Range is a distance; Odin's is the control space scaled per control
    (geometric_robots.control_scales), so that a distance there is the same joints' or
    base's distance: checked on random pairs of the arm (two revolute joints) and of the
    plate (a base sliding in a 1 m box)."""
    from gui.planning.geometric_robots import control_scales
    rng = np.random.default_rng(5)
    (tmp_path / "arm").mkdir()
    (tmp_path / "plate").mkdir()
    for plan in (_plan(_problem(tmp_path / "arm")), _plate_plan(tmp_path / "plate")):
        robot = planned_robots(plan)[0]
        scales = control_scales([robot], 2)
        for _ in range(20):
            a, b = rng.random(2), rng.random(2)
            (base_a, q_a), (base_b, q_b) = robot.configuration(a), robot.configuration(b)
            kautham = np.linalg.norm(np.r_[q_b - q_a, base_b[:3, 3] - base_a[:3, 3]])
            assert np.linalg.norm((b - a) * scales) == pytest.approx(kautham, rel=1e-9)
