"""The Core's collision probe (virtual_world.core.probe), a geometric planner's queries: it
answers as Check Collision does, its clearances never exceed a true distance (and come within
a tier of it), and it refuses what would give ODE bad state, changing nothing."""
import numpy as np
import pytest

from odin_common.interface import Shape
from virtual_world.core import ObjectSpec
from virtual_world.core.probe import BOUND_BOX, BOUND_CAPSULE, BOUND_VALUES
from virtual_world.errors import InvalidArgument, UnknownName

TIERS = 0.001 * 2.0 ** np.arange(9, -1, -1)      # 0.512 ... 0.001 m


def _scene(core):
    """A 1 m static box at the origin, a cylinder (r 0.2, 1 m along z) at x = -3, and a ball of
    radius 0.1 that the probe moves."""
    core.build_object(ObjectSpec("block", [1.0, 1.0, 1.0], geometry_only=True))
    core.build_object(ObjectSpec("drum", [0.2, 1.0], geometry_only=True,
                                 position=(-3.0, 0.0, 0.0)))
    core.build_object(ObjectSpec("ball", [0.1], position=(5.0, 0.0, 0.0)))
    return core.collision_probe(["ball"], apart=["ball"], tiers=TIERS)


def _at(x, y=0.0, z=0.0):
    pose = np.eye(4)
    pose[:3, 3] = (x, y, z)
    return pose[None]


def _capsule(a, b, radius):
    bound = np.zeros(BOUND_VALUES)
    bound[0] = BOUND_CAPSULE
    bound[1:4], bound[4:7], bound[7] = a, b, radius
    return bound


def _box(centre, half, rotation=np.eye(3)):
    bound = np.zeros(BOUND_VALUES)
    bound[0] = BOUND_BOX
    bound[1:4], bound[4:13], bound[13:16] = centre, np.asarray(rotation).ravel(), half
    return bound


def test_touching_answers_as_check_collision_does(core):
    probe = _scene(core)
    rng = np.random.default_rng(5)
    answers = set()
    for x, y in rng.uniform(-4.0, 1.5, size=(300, 2)):
        pair = core.probe_touching(probe, _at(x, y))
        expected = {frozenset((c.first, c.second)) for c in core.check_collision(
            [("ball", (x, y, 0.0), (1.0, 0.0, 0.0, 0.0))])}
        assert (set() if pair is None else {frozenset(pair)}) <= expected
        assert (pair is None) == (not expected)
        answers.add(pair is None)
    assert answers == {True, False}                     # both kinds were met


@pytest.mark.parametrize("gap", [0.003, 0.02, 0.1, 0.3])
def test_a_clearance_is_within_a_tier_below_the_true_distance(core, gap):
    """A capsule and a box each ``gap`` from the block's face at x = 0.5."""
    probe = _scene(core)
    capsule = _capsule((0.5 + gap + 0.05, 0.0, -0.2), (0.5 + gap + 0.05, 0.0, 0.2), 0.05)
    box = _box((0.5 + gap + 0.05, 0.0, 0.0), (0.05, 0.3, 0.3))
    for clearance in core.probe_clearances(probe, np.array([capsule, box])):
        assert gap / 2 <= clearance <= gap


def test_a_shape_no_probe_collider_takes_counts_as_touching_near_it(core):
    """ODE collides neither probe with a cylinder: near its bounding box the clearance is 0,
    never the distance's overestimate; far from it, the growth is clear."""
    probe = _scene(core)
    near = _capsule((-3.0, 0.3, -0.2), (-3.0, 0.3, 0.2), 0.05)   # 0.05 m from the drum
    far = _capsule((-3.0, 2.0, -0.2), (-3.0, 2.0, 0.2), 0.05)
    clear_near, clear_far = core.probe_clearances(probe, np.array([near, far]))
    assert clear_near <= 0.05 and clear_far == TIERS[0]


@pytest.mark.parametrize("poses, says", [
    (np.full((1, 4, 4), np.nan), "finite"),
    (np.concatenate([_at(1.0), _at(2.0)]), "2 given for 1"),
    (np.array([[[1.0, 0.1, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]]), "orthonormal"),
    (_at(1e12), "extent"),
    ("ball", "shape"),
])
def test_bad_poses_are_refused_and_nothing_moves(core, poses, says):
    probe = _scene(core)
    before = core.body_state("ball")
    with pytest.raises(InvalidArgument, match=says):
        core.probe_touching(probe, poses)
    np.testing.assert_array_equal(core.body_state("ball")[0], before[0])


@pytest.mark.parametrize("bounds, says", [
    (np.array([_capsule((0, 0, 0), (0, 0, 1), -0.1)]), "negative"),
    (np.array([_box((0, 0, 0), (0.1, 0.1, 0.1), np.diag([1.0, 2.0, 1.0]))]), "orthonormal"),
    (np.array([np.r_[7.0, np.zeros(BOUND_VALUES - 1)]]), "kind"),
    (np.full((1, BOUND_VALUES), np.inf), "finite"),
    (np.zeros((1, 5)), "shape"),
])
def test_bad_bounds_are_refused(core, bounds, says):
    probe = _scene(core)
    with pytest.raises(InvalidArgument, match=says):
        core.probe_clearances(probe, bounds)


def test_a_probe_refuses_static_or_unknown_objects_and_bad_tiers(core):
    _scene(core)
    with pytest.raises(InvalidArgument, match="no body"):
        core.collision_probe(["block"])
    with pytest.raises(UnknownName):
        core.collision_probe(["nothing"])
    with pytest.raises(InvalidArgument, match="at most once"):
        core.collision_probe(["ball", "ball"])
    with pytest.raises(InvalidArgument, match="descending"):
        core.collision_probe(["ball"], tiers=[0.1, 0.2])


def test_a_probe_refuses_every_call_once_the_world_changed(core):
    """C must never see a freed geom: once an object is removed (or the scene is new), the
    probe's arrays may name freed handles, so it answers nothing."""
    probe = _scene(core)
    core.remove_object("drum")
    with pytest.raises(InvalidArgument, match="changed"):
        core.probe_touching(probe, _at(1.0))
    with pytest.raises(InvalidArgument, match="changed"):
        core.probe_clearances(probe, np.array([_capsule((2, 0, 0), (2, 0, 1), 0.1)]))
    core.new_scene()
    core.build_object(ObjectSpec("ball", [0.1]))
    with pytest.raises(InvalidArgument, match="changed"):
        core.probe_touching(probe, _at(1.0))


def test_pairs_that_may_touch_leave_out_bodies_a_joint_joins(core):
    from virtual_world.core import HINGE, JointSpec
    core.build_object(ObjectSpec("a", [0.1]))
    core.build_object(ObjectSpec("b", [0.1], position=(1.0, 0.0, 0.0)))
    core.build_object(ObjectSpec("c", [0.1], position=(2.0, 0.0, 0.0)))
    core.add_joint(JointSpec(HINGE, "a", "b", anchor=(0.5, 0.0, 0.0), axis1=(0.0, 0.0, 1.0)))
    assert core.pairs_that_may_touch(["a", "b", "c"]) == [("a", "c"), ("b", "c")]


def test_a_plane_is_asked_like_any_geometry(core):
    core.build_object(ObjectSpec("ground", [], shape=Shape.PLANE, geometry_only=True))
    core.build_object(ObjectSpec("ball", [0.1], position=(0.0, 0.0, 1.0)))
    probe = core.collision_probe(["ball"], apart=["ball"], tiers=TIERS)
    assert core.probe_touching(probe, _at(0.0, 0.0, 0.05)) == ("ball", "ground")
    clearance = core.probe_clearances(probe, np.array([_capsule((0, 0, 0.3), (0, 0, 0.5),
                                                                0.1)]))[0]
    assert 0.1 <= clearance <= 0.2


def test_a_clearance_is_sought_no_further_than_needed(core):
    """A capsule 0.3 m from the block: asked for up to 0.05 m, it answers the smallest tier
    that reaches 0.05 (0.064 m), still a lower bound; a NaN need is refused."""
    probe = _scene(core)
    capsule = _capsule((0.85, 0.0, -0.2), (0.85, 0.0, 0.2), 0.05)
    assert core.probe_clearances(probe, np.array([capsule]), [0.05])[0] == 0.064
    assert 0.15 <= core.probe_clearances(probe, np.array([capsule]), [np.inf])[0] <= 0.3
    with pytest.raises(InvalidArgument, match="needed"):
        core.probe_clearances(probe, np.array([capsule]), [np.nan])
