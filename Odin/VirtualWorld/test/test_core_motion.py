"""The Core's motion checker (virtual_world.core.motion over odin_motion.c), a geometric
planner's whole motion check in one C call, on tiny robots whose tables are built by hand:
a motion through an obstacle is invalid and one clear of it valid, for a turning link (the
clearance walk), a translating base (the sweep walk) and two robots' links passing each other
(the capsule pair distance); a long free motion needs few exact checks; and every hostile
table or input is refused with InvalidArgument, never shown to ODE, leaving the Core usable.
"""
import math

import numpy as np
import pytest

from virtual_world.core import ObjectSpec
from virtual_world.core.motion import RobotKinematics
from virtual_world.errors import InvalidArgument, UnknownName

TIERS = 0.001 * 2.0 ** np.arange(9, -1, -1)      # 0.512 ... 0.001 m
RESOLUTION = 0.01
SWEEP_GAP = 0.01


def _skew_z() -> np.ndarray:
    """Rodrigues' B of a turn about z: the skew matrix of the axis, in a 4 x 4 block."""
    k = np.zeros((4, 4))
    k[0, 1], k[1, 0] = -1.0, 1.0
    return k


def _translation(x, y=0.0, z=0.0) -> np.ndarray:
    pose = np.eye(4)
    pose[:3, 3] = (x, y, z)
    return pose


def _bounds(half):
    """(capsule (7), box (15)) holding a box of half sides ``half`` centred at its object
    frame: the capsule along its longest side, its radius the cross-section's half diagonal."""
    half = np.asarray(half, dtype=float)
    k = int(np.argmax(half))
    a = np.zeros(3)
    a[k] = -half[k]
    capsule = np.r_[a, -a, np.linalg.norm(np.delete(half, k))]
    box = np.r_[np.zeros(3), np.eye(3).ravel(), half]
    return capsule, box


# -- a one-link arm turning about the world z axis at the origin ---------------------------

ARM_SIDES = (1.0, 0.1, 0.1)
ARM_OFFSET = 0.55           # the box's centre from the axis: it spans x in [0.05, 1.05]


def _arm(**changes) -> RobotKinematics:
    """The arm's table: control 0 in [0, 1] turns it over [-pi, pi] (0.5: along +x)."""
    half = np.asarray(ARM_SIDES) / 2
    offsets = _translation(ARM_OFFSET)[None]
    reach = float(np.linalg.norm(offsets[0, :3, 3] + half))
    capsule, box = _bounds(half)
    k = _skew_z()
    table = RobotKinematics(
        links=("arm",), part=(0, 1), offset=np.array([0.5]), matrix=np.array([[1.0]]),
        dof_of_joint=np.array([0]), joint_low=np.array([-math.pi]),
        joint_span=np.array([2 * math.pi]), joint_link=np.array([0]), base_pose=np.eye(4),
        base_box=None, base_rotation=None, base_turns=False, fixed_part=np.eye(4)[None],
        first_part=k[None], second_part=(k @ k)[None], rotational=np.array([True]),
        parent=np.array([-1]), offsets=offsets, arms=np.array([[reach]]),
        reaches=np.array([reach]), capsules=capsule[None], boxes=box[None],
        boxed=np.array([True]), moved=np.array([0]))
    return table._replace(**changes)


def _c(degrees: float) -> float:
    """The arm's control for its angle (degrees from +x, counter-clockwise)."""
    return (math.radians(degrees) + math.pi) / (2 * math.pi)


def _arm_scene(core):
    """The arm (a body, along +x) and a static 0.2 m post 0.85 m out at 45 degrees."""
    core.build_object(ObjectSpec("arm", list(ARM_SIDES), position=(ARM_OFFSET, 0.0, 0.0)))
    core.build_object(ObjectSpec("post", [0.2, 0.2, 0.2], geometry_only=True,
                                 position=(0.6, 0.6, 0.0)))


def _arm_checker(core, **changes):
    return core.motion_checker([_arm(**changes)], 1, TIERS, SWEEP_GAP, RESOLUTION)


def test_a_turn_through_the_post_is_invalid_and_one_away_from_it_valid(core):
    _arm_scene(core)
    checker = _arm_checker(core)
    assert core.motion_valid(checker, [_c(0.0)], [_c(90.0)])[0] is False
    assert core.motion_valid(checker, [_c(90.0)], [_c(0.0)])[0] is False
    assert core.motion_valid(checker, [_c(0.0)], [_c(-90.0)])[0] is True
    assert core.motion_valid(checker, [_c(0.0)], [_c(30.0)])[0] is True   # stops short of it
    assert core.motion_valid(checker, [_c(80.0)], [_c(170.0)])[0] is True  # starts past it


def test_one_configuration_is_checked_as_the_walk_checks_it(core):
    """Core.configuration_valid: the arm along the post's bearing touches it, elsewhere not;
    a control vector with NaN or of the wrong length is refused."""
    _arm_scene(core)
    checker = _arm_checker(core)
    assert core.configuration_valid(checker, [_c(45.0)]) is False
    assert core.configuration_valid(checker, [_c(0.0)]) is True
    assert core.configuration_valid(checker, [_c(-135.0)]) is True
    for hostile in ([float("nan")], [0.5, 0.5], []):
        with pytest.raises(InvalidArgument):
            core.configuration_valid(checker, hostile)
    assert core.configuration_valid(checker, [_c(45.0)]) is False


def test_the_arm_is_left_at_a_configuration_of_the_motion(core):
    """The walk places the arm's body (Core.motion_valid: it stays where the last exact check
    put it): after a turn from 0 to -90 degrees its object frame is the chain's at some angle
    in between, 0.55 m from the axis, turned by that angle."""
    _arm_scene(core)
    checker = _arm_checker(core)
    assert core.motion_valid(checker, [_c(0.0)], [_c(-90.0)])[0] is True
    position, orientation = core.body_state("arm")[:2]
    assert abs(position[2]) < 1e-9
    assert math.hypot(position[0], position[1]) == pytest.approx(ARM_OFFSET, abs=1e-9)
    angle = math.atan2(position[1], position[0])
    assert -math.pi / 2 - 1e-9 <= angle <= 1e-9
    turn = (math.cos(angle / 2), 0.0, 0.0, math.sin(angle / 2))     # wxyz about z
    assert abs(float(np.dot(orientation, turn))) == pytest.approx(1.0, abs=1e-9)


def test_a_long_free_turn_needs_fewer_exact_checks_than_resolution_steps(core):
    """From -45 to -170 degrees, far from the post: the tip moves about 2.3 m, 230 resolution
    steps; the clearances let the walk take far longer steps, proven free without a check."""
    _arm_scene(core)
    checker = _arm_checker(core)
    valid, checks, clearances = core.motion_valid(checker, [_c(-45.0)], [_c(-170.0)])
    assert valid is True
    assert type(checks) is int and type(clearances) is int
    assert checks >= 1 and clearances >= 1          # its end, at least, and one clearance
    steps = _arm().reaches[0] * math.radians(125.0) / RESOLUTION
    assert checks < steps / 4
    valid, checks, clearances = core.motion_valid(checker, [_c(0.0)], [_c(90.0)])
    assert valid is False and checks >= 1 and clearances >= 0


def test_a_motion_that_does_not_move_is_valid_where_the_arm_is_free(core):
    _arm_scene(core)
    checker = _arm_checker(core)
    assert core.motion_valid(checker, [_c(-20.0)], [_c(-20.0)])[0] is True
    assert core.motion_valid(checker, [_c(-20.0)], [_c(45.0)])[0] is False


# -- a base translating in the plane past a wall -------------------------------------------

SLIDER_HALF = (0.1, 0.1, 0.1)


def _slider(link: str, part, columns: np.ndarray, box_xy, **changes) -> RobotKinematics:
    """A one-link robot whose base the controls slide in the box ``box_xy`` (x, y ranges; z
    0): DOFs 0-5 are offset 0.5 plus ``columns`` (6 x part length) times (controls - 0.5);
    no joints."""
    capsule, box = _bounds(SLIDER_HALF)
    table = RobotKinematics(
        links=(link,), part=part, offset=np.full(6, 0.5), matrix=np.asarray(columns, float),
        dof_of_joint=np.zeros(0, dtype=int), joint_low=np.zeros(0), joint_span=np.zeros(0),
        joint_link=np.zeros(0, dtype=int), base_pose=np.eye(4),
        base_box=np.r_[np.asarray(box_xy, float).reshape(2, 2), [[0.0, 0.0]]],
        base_rotation=np.eye(3), base_turns=False, fixed_part=np.eye(4)[None],
        first_part=np.zeros((1, 4, 4)), second_part=np.zeros((1, 4, 4)),
        rotational=np.array([False]), parent=np.array([-1]), offsets=np.eye(4)[None],
        arms=np.zeros((1, 0)), reaches=np.array([0.2]), capsules=capsule[None],
        boxes=box[None], boxed=np.array([True]), moved=np.array([0]))
    return table._replace(**changes)


def _planar(**changes) -> RobotKinematics:
    """Controls 0, 1 in [0, 1] put the slider at x, y = -2 + 4 c."""
    columns = np.zeros((6, 2))
    columns[0, 0] = columns[1, 1] = 1.0
    return _slider("slider", (0, 2), columns, [[-2.0, 2.0], [-2.0, 2.0]], **changes)


def _xy(x, y):
    return [(x + 2.0) / 4.0, (y + 2.0) / 4.0]


def _wall_scene(core):
    """A static wall 0.1 m thick across x = 0, from y = -0.5 to 0.5; the slider's 0.2 m
    cube."""
    core.build_object(ObjectSpec("wall", [0.1, 1.0, 1.0], geometry_only=True))
    core.build_object(ObjectSpec("slider", [0.2, 0.2, 0.2], position=(-1.0, 0.0, 0.0)))
    return core.motion_checker([_planar()], 2, TIERS, SWEEP_GAP, RESOLUTION)


def test_a_slide_through_the_wall_is_invalid_and_one_beside_it_valid(core):
    checker = _wall_scene(core)
    assert core.motion_valid(checker, _xy(-1.0, 0.0), _xy(1.0, 0.0))[0] is False
    assert core.motion_valid(checker, _xy(-1.0, 0.4), _xy(1.0, 0.4))[0] is False  # a corner
    valid, checks, clearances = core.motion_valid(checker, _xy(-1.0, 1.0), _xy(1.0, 1.0))
    assert valid is True
    # One sweep shows the whole 2 m free: its end checked exactly, no walk of probes.
    assert checks <= 2 and clearances >= 1


def test_a_slide_grazing_the_wall_is_told_from_one_clipping_it(core):
    """Closer to the wall than the sweep's growth the walk halves the slide; 3 mm clear of
    its end the slide is valid, 3 mm into it (more than half the resolution) invalid."""
    checker = _wall_scene(core)
    clear, clipping = 0.5 + 0.1 + 0.003, 0.5 + 0.1 - 0.003
    valid, checks, _ = core.motion_valid(checker, _xy(-1.0, clear), _xy(1.0, clear))
    assert valid is True and checks > 2
    assert core.motion_valid(checker, _xy(-1.0, clipping), _xy(1.0, clipping))[0] is False
    assert core.motion_valid(checker, _xy(1.0, -clipping), _xy(-1.0, -clipping))[0] is False


def test_a_slide_that_starts_beside_the_wall_and_ends_in_it_is_invalid(core):
    checker = _wall_scene(core)
    assert core.motion_valid(checker, _xy(-1.0, 1.0), _xy(0.0, 0.2))[0] is False
    assert core.motion_valid(checker, _xy(-1.0, 1.0), _xy(-0.5, 0.2))[0] is True


# -- two robots whose links may touch each other -------------------------------------------

PLATE_HALF = (0.025, 0.3, 0.025)


def _plate(link: str, control: int) -> RobotKinematics:
    """A thin plate (0.05 m across x) that control ``control`` of 2 slides along x in
    [-2, 2], at y = 0."""
    capsule, box = _bounds(PLATE_HALF)
    columns = np.zeros((6, 1))
    columns[0, 0] = 1.0
    return _slider(link, (control, 1), columns, [[-2.0, 2.0], [0.0, 0.0]],
                   capsules=capsule[None], boxes=box[None])


def _plates(core):
    for link in ("left", "right"):
        core.build_object(ObjectSpec(link, [0.05, 0.6, 0.05], position=(0.0, 3.0, 0.0)))
    return core.motion_checker([_plate("left", 0), _plate("right", 1)], 2, TIERS, SWEEP_GAP,
                               RESOLUTION)


def _x(left, right):
    return [(left + 2.0) / 4.0, (right + 2.0) / 4.0]


def test_two_robots_links_passing_through_each_other_are_invalid(core):
    """The right plate stands at x = 0.1; the left slides from -1 to 1 through it. They
    overlap only while the left is within 0.05 m of 0.1, between the walk's probes (the
    left at -0.25, 0, 0.25, ...): only the pair's capsule distance brings the walk there."""
    checker = _plates(core)
    assert core.motion_valid(checker, _x(-1.0, 0.1), _x(1.0, 0.1))[0] is False
    assert core.motion_valid(checker, _x(1.0, 0.1), _x(-1.0, 0.1))[0] is False
    assert core.motion_valid(checker, _x(-1.0, 1.0), _x(1.0, -1.0))[0] is False  # both move


def test_two_robots_links_kept_apart_are_valid(core):
    checker = _plates(core)
    assert core.motion_valid(checker, _x(-1.0, 0.1), _x(-0.3, 0.1))[0] is True
    assert core.motion_valid(checker, _x(-1.0, 0.1), _x(0.0, 0.1))[0] is True  # 0.05 m apart
    assert core.motion_valid(checker, _x(-1.0, 1.0), _x(-0.5, 0.5))[0] is True  # side by side
    assert core.motion_valid(checker, _x(-1.0, 1.0), _x(-1.5, 1.5))[0] is True  # moving apart


# -- hostile tables and inputs -------------------------------------------------------------

def _nan_offset():
    return _arm(offsets=np.where(np.eye(4) == 1, np.nan, 0.0)[None])


def _bad_parent():
    return _arm(parent=np.array([0]))


def _far_base():
    return _arm(base_pose=_translation(2e4))


@pytest.mark.parametrize("robot", [
    _nan_offset,
    lambda: _arm(joint_span=np.array([np.inf])),
    lambda: _arm(capsules=np.array([[0, 0, 0, 1, 0, 0, np.nan]])),
    _bad_parent,
    lambda: _arm(moved=np.array([1])),
    lambda: _arm(moved=np.array([-1])),
    lambda: _arm(joint_link=np.array([3])),
    lambda: _arm(dof_of_joint=np.array([1])),
    lambda: _arm(matrix=np.ones((2, 2))),
    lambda: _arm(boxes=np.zeros((1, 14))),
    lambda: _arm(part=(1, 1)),
    lambda: _arm(capsules=np.array([[0, 0, 0, 1, 0, 0, -0.1]])),
    _far_base,
    lambda: _arm(base_box=np.zeros((3, 2))),          # a base box but 1 DOF
    lambda: "arm",
], ids=["nan", "infinite span", "nan capsule", "parent after child", "moved beyond",
        "moved negative", "joint link beyond", "dof beyond", "matrix shape", "boxes shape",
        "part beyond", "negative radius", "base beyond extent", "base box without dofs",
        "not a table"])
def test_a_hostile_table_is_refused_and_the_core_answers_on(core, robot):
    _arm_scene(core)
    with pytest.raises(InvalidArgument):
        core.motion_checker([robot()], 1, TIERS, SWEEP_GAP, RESOLUTION)
    checker = _arm_checker(core)
    assert core.motion_valid(checker, [_c(0.0)], [_c(90.0)])[0] is False
    assert core.motion_valid(checker, [_c(0.0)], [_c(-90.0)])[0] is True


def test_a_checker_refuses_bad_arguments_and_a_link_without_a_body(core):
    _arm_scene(core)
    for size, tiers, gap, resolution in [(0, TIERS, SWEEP_GAP, RESOLUTION),
                                         (1, [0.1, 0.2], SWEEP_GAP, RESOLUTION),
                                         (1, TIERS, -1.0, RESOLUTION),
                                         (1, TIERS, SWEEP_GAP, np.nan)]:
        with pytest.raises(InvalidArgument):
            core.motion_checker([_arm()], size, tiers, gap, resolution)
    with pytest.raises(InvalidArgument):
        core.motion_checker([], 1, TIERS, SWEEP_GAP, RESOLUTION)
    with pytest.raises(InvalidArgument, match="no body"):
        core.motion_checker([_arm(links=("post",))], 1, TIERS, SWEEP_GAP, RESOLUTION)
    with pytest.raises(UnknownName):
        core.motion_checker([_arm(links=("nothing",))], 1, TIERS, SWEEP_GAP, RESOLUTION)


@pytest.mark.parametrize("a, b", [
    ([np.nan], [0.5]),
    ([0.5], [np.inf]),
    ([0.5, 0.5], [0.5]),
    ([0.5], []),
    ("arm", [0.5]),
], ids=["nan start", "infinite end", "long start", "empty end", "not numbers"])
def test_a_bad_control_vector_is_refused_and_the_core_answers_on(core, a, b):
    _arm_scene(core)
    checker = _arm_checker(core)
    with pytest.raises(InvalidArgument):
        core.motion_valid(checker, a, b)
    assert core.motion_valid(checker, [_c(0.0)], [_c(90.0)])[0] is False
    assert core.motion_valid(checker, [_c(0.0)], [_c(-90.0)])[0] is True


@pytest.mark.parametrize("changes, a, b", [
    # each value within the extent (a coordinate's bound, 1e4 m), their sum beyond it
    ({"base_pose": _translation(6000.0), "offsets": _translation(6000.0)[None]},
     [_c(-90.0)], [_c(-10.0)]),
    # Rodrigues' B scaled: every frame but the home one is no rigid transform
    ({"first_part": 10 * _skew_z()[None]}, [_c(0.0)], [_c(-90.0)]),
    ({"first_part": 10 * _skew_z()[None]}, [_c(-10.0)], [_c(-90.0)]),
], ids=["frame beyond extent", "scaled rotation", "scaled rotation off home"])
def test_a_frame_unfit_for_ode_is_refused_by_the_walk_and_the_core_answers_on(core, changes,
                                                                              a, b):
    _arm_scene(core)
    before = core.body_state("arm")[0]
    hostile = _arm_checker(core, **changes)
    with pytest.raises(InvalidArgument, match="rigid transform"):
        core.motion_valid(hostile, a, b)
    np.testing.assert_array_equal(core.body_state("arm")[0], before)   # nothing placed
    checker = _arm_checker(core)
    assert core.motion_valid(checker, [_c(0.0)], [_c(90.0)])[0] is False
    assert core.motion_valid(checker, [_c(0.0)], [_c(-90.0)])[0] is True


def test_a_base_rotation_unfit_for_ode_is_refused_by_the_sweep(core):
    """A base rotation within [-1, 1] but not orthonormal: the sweep walk's frames are no
    rigid transforms."""
    checker = _wall_scene(core)
    hostile = core.motion_checker([_planar(base_rotation=np.diag([1.0, 1.0, 0.5]))], 2, TIERS,
                                  SWEEP_GAP, RESOLUTION)
    with pytest.raises(InvalidArgument, match="rigid transform"):
        core.motion_valid(hostile, _xy(-1.0, 1.0), _xy(1.0, 1.0))
    assert core.motion_valid(checker, _xy(-1.0, 0.0), _xy(1.0, 0.0))[0] is False
    assert core.motion_valid(checker, _xy(-1.0, 1.0), _xy(1.0, 1.0))[0] is True


def test_a_box_bound_whose_rotation_is_not_orthonormal_is_refused(core):
    _wall_scene(core)
    capsule, box = _bounds(SLIDER_HALF)
    box[3:12] = 0.0
    with pytest.raises(InvalidArgument):
        hostile = core.motion_checker([_planar(boxes=box[None])], 2, TIERS, SWEEP_GAP,
                                      RESOLUTION)
        core.motion_valid(hostile, _xy(-1.0, 0.0), _xy(1.0, 0.0))


def test_a_checker_refuses_every_call_once_the_world_changed(core):
    """C must never see a freed geom: once an object is removed or added, the checker's arrays
    may name freed handles, so it answers nothing; a new checker answers for the new world."""
    _arm_scene(core)
    checker = _arm_checker(core)
    core.remove_object("post")
    with pytest.raises(InvalidArgument, match="changed"):
        core.motion_valid(checker, [_c(0.0)], [_c(-90.0)])
    assert core.motion_valid(_arm_checker(core), [_c(0.0)], [_c(90.0)])[0] is True
    checker = _arm_checker(core)
    core.build_object(ObjectSpec("post", [0.2, 0.2, 0.2], geometry_only=True,
                                 position=(0.6, 0.6, 0.0)))
    with pytest.raises(InvalidArgument, match="changed"):
        core.motion_valid(checker, [_c(0.0)], [_c(90.0)])
    assert core.motion_valid(_arm_checker(core), [_c(0.0)], [_c(90.0)])[0] is False


def test_a_walk_past_its_deadline_stops_and_takes_no_motion(core):
    """A search's time limit holds inside a motion (one near heavy meshes took 5 s): past the
    deadline the walk asks nothing more and answers False; without one, the same free turn
    is valid."""
    import time
    _arm_scene(core)
    checker = _arm_checker(core)
    free = ([_c(0.0)], [_c(-90.0)])
    assert core.motion_valid(checker, *free)[0] is True
    assert core.motion_valid(checker, *free, deadline=time.monotonic() + 60.0)[0] is True
    valid, checks, clearances = core.motion_valid(checker, *free,
                                                  deadline=time.monotonic() - 1.0)
    assert (valid, checks, clearances) == (False, 0, 0)
