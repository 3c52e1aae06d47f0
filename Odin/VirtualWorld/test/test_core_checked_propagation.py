"""Core.plan_rule and Core.propagate_checked (issue 42): a control planner's steps made and
judged in one C call each. The states are propagate_state's bit for bit; the verdict is the
rule's (roles that may not collide, the tracked link's bounds and speed); the tracked link's
values are a documented arithmetic, checked here value for value; bad input is refused and
changes nothing."""
import numpy as np
import pytest

from odin_common.rotations import quaternion_to_matrix
from virtual_world.core import Core, ObjectSpec, WorldParameters
from virtual_world.core.checked_propagation import TrackedLink
from virtual_world.errors import InvalidArgument, UnknownName

H = 0.01
GROUND, WALL, ROBOT = 1, 2, 3
RULE_PAIRS = [(WALL, WALL), (WALL, ROBOT), (ROBOT, 0)]
WIDE = [(-10, 10), (-10, 10), (-10, 10)]
COM = (0.03, -0.02, 0.01)
OFFSET = (0.2, 0.1, -0.05)


@pytest.fixture
def core():
    c = Core(WorldParameters(gravity=(0, 0, -9.81)))
    c.build_object(ObjectSpec("ground", [6, 6, 1], position=(0, 0, -0.5), geometry_only=True))
    c.build_object(ObjectSpec("wall", [0.1, 2, 0.5], position=(1.0, 0, 0.25), mass=5.0))
    c.build_object(ObjectSpec("block", [0.2, 0.2, 0.2], position=(-1.0, 0, 0.1), mass=1.0))
    # the robot: a box whose centre of mass is off its origin, sliding towards the wall
    c.build_object(ObjectSpec("robot", [0.3, 0.3, 0.2], position=(0.55, 0, 0.1), mass=2.0,
                              inertia=[0.02, 0.02, 0.02, 0, 0, 0], center_of_mass=list(COM)))
    c.step(H, 20)
    yield c
    c.close()


def rule(core, bounds=WIDE, max_speed=50.0, roles=None):
    roles = {"ground": GROUND, "wall": WALL, "robot": ROBOT} if roles is None else roles
    return core.plan_rule(roles, RULE_PAIRS, "robot", OFFSET, bounds, max_speed)


def pushed(speed):
    return [("robot", (speed, 0.0, 0.0))]


def reference_tracked(state, index):
    """The tracked values by the documented arithmetic, in Python floats: the body's origin
    (position - R com) and then the link's origin (+ R offset), each row summed left to
    right."""
    body = state[1 + 26 * index:1 + 26 * (index + 1)]
    r = quaternion_to_matrix(body[3:7]).tolist()
    origin = [body[k] - (r[k][0] * COM[0] + r[k][1] * COM[1] + r[k][2] * COM[2])
              for k in range(3)]
    link = [origin[k] + (r[k][0] * OFFSET[0] + r[k][1] * OFFSET[1] + r[k][2] * OFFSET[2])
            for k in range(3)]
    return np.array(link + list(body[19:22]))


def test_a_row_is_propagate_state_bit_for_bit_with_each_step_judged(core):
    checked = rule(core)
    start = core.body_state_vector()
    row = core.propagate_checked(checked, start, 3 * H, H, pushed(40.0), count=12,
                                 stop_at_invalid=False)
    assert row.made == 12 and row.states.shape == (12, start.size + 1)
    vector = start
    robot = core.object_ids().index("robot") - 1        # the ground has no body
    for states, tracked in zip(row.states, row.tracked):
        alone = core.propagate_state(vector, 3 * H, H, pushed(40.0))
        assert states[:-1].tobytes() == alone.state.tobytes()
        touches_wall = any("wall" in pair and "ground" not in pair for pair in alone.pairs)
        assert states[-1] == (1.0 if touches_wall else 0.0)
        assert tracked.tobytes() == reference_tracked(alone.state, robot).tobytes()
        vector = alone.state
    assert row.states[:, -1].any() and not row.states[0, -1]   # it reaches the wall
    assert core.body_state_vector().tobytes() == vector.tobytes()  # the world stays there


def test_the_row_stops_at_its_first_invalid_step(core):
    checked = rule(core)
    start = core.body_state_vector()
    full = core.propagate_checked(checked, start, 3 * H, H, pushed(40.0), count=12,
                                  stop_at_invalid=False)
    first = int(np.argmax(full.states[:, -1]))
    stopped = core.propagate_checked(checked, start, 3 * H, H, pushed(40.0), count=12)
    assert stopped.made == first + 1
    assert stopped.states[:first + 1].tobytes() == full.states[:first + 1].tobytes()


def test_bounds_and_speed_make_a_step_invalid(core):
    start = core.body_state_vector()
    x = TrackedLink(core.object_ids().index("robot") - 1, COM, OFFSET).values(start)[0]
    behind = [(x - 1.0, x + 0.001), (-10, 10), (-10, 10)]     # left after a few steps
    row = core.propagate_checked(rule(core, behind), start, H, H, pushed(40.0), count=30)
    assert row.states[row.made - 1, -1] == 1.0 and row.tracked[row.made - 1, 0] > x + 0.001
    assert not row.states[:row.made - 1, -1].any()
    slow = core.propagate_checked(rule(core, max_speed=0.05), start, H, H, pushed(40.0),
                                  count=30)
    assert abs(slow.tracked[slow.made - 1, 3]) > 0.05 and slow.states[slow.made - 1, -1]


def test_a_role_pair_not_forbidden_is_valid(core):
    """The block is pushed into nothing forbidden: roles decide, not names."""
    start = core.body_state_vector()
    only_ground = core.propagate_checked(rule(core, roles={"ground": GROUND}), start, 3 * H, H,
                                         pushed(40.0), count=12, stop_at_invalid=False)
    assert not only_ground.states[:, -1].any()     # every object role 0 but the ground


def test_rows_write_into_given_memory(core):
    checked = rule(core)
    start = core.body_state_vector()
    states, tracked = np.full((1, start.size + 1), 7.0), np.full((1, 6), 7.0)
    row = core.propagate_checked(checked, start, H, H, (), 1, states, tracked)
    assert row.states is states and row.tracked is tracked
    assert states[0, :-1].tobytes() == core.propagate_state(start, H, H).state.tobytes()
    assert checked.tracked_values(states[0, :-1]).tobytes() == tracked[0].tobytes()


def test_bad_requests_are_refused_and_change_nothing(core):
    checked = rule(core)
    start = core.body_state_vector()
    before = core.body_state_vector().tobytes()
    broken = start.copy()
    broken[5] = np.nan
    cases = [
        ((checked, broken, H, H), {}, "finite"),
        ((checked, start[:-1], H, H), {}, "values"),
        ((checked, start, H, H), {"count": 0}, "count"),
        ((checked, start, H, H), {"states": np.empty((1, 3))}, "states"),
        ((checked, start, H, H), {"tracked": np.empty((1, 6), dtype=np.float32)}, "tracked"),
        ((checked, start, H, H), {"count": 10 ** 9}, "body-steps"),
    ]
    for args, kwargs, message in cases:
        with pytest.raises(InvalidArgument, match=message):
            core.propagate_checked(*args, **kwargs)
        assert core.body_state_vector().tobytes() == before
    for roles, pairs, message in (({"ghost": 1}, [], None), ({"wall": 16}, [], "at most"),
                                  ({"wall": 0}, [], "role"), ({}, [(1, 99)], "below")):
        error = UnknownName if message is None else InvalidArgument
        with pytest.raises(error, match=message):
            core.plan_rule(roles, pairs, "robot", OFFSET, WIDE, 1.0)
    with pytest.raises(InvalidArgument, match="bounds"):
        rule(core, bounds=[(np.nan, 1), (0, 1), (0, 1)])
    with pytest.raises(InvalidArgument, match="bounds"):
        rule(core, bounds=[(0, 1), (0, 1)])
    with pytest.raises(InvalidArgument, match="max_speed"):
        rule(core, max_speed=0.0)
    with pytest.raises(Exception, match="geometry only"):
        core.plan_rule({}, [], "ground", OFFSET, WIDE, 1.0)


def test_a_rule_is_refused_once_the_world_has_changed(core):
    checked = rule(core)
    core.build_object(ObjectSpec("late", [0.1], position=(3, 3, 0.1)))
    with pytest.raises(InvalidArgument, match="make it again"):
        core.propagate_checked(checked, core.body_state_vector(), H, H)
    other = Core()
    other.build_object(ObjectSpec("robot", [0.1], position=(0, 0, 1)))
    with pytest.raises(InvalidArgument, match="another world"):
        other.propagate_checked(checked, other.body_state_vector(), H, H)
    other.close()


def test_a_rule_follows_the_state_vector_when_exempt_pairs_change_its_size(core):
    """Exempt Overlaps adds values to the state vector without adding an object: the rule
    still holds, and arrays are sized by the world as it is now."""
    checked = rule(core)
    old = core.body_state_vector().size
    core.build_object(ObjectSpec("inside", [0.1, 0.1, 0.1], position=(-1.0, 0, 0.15),
                                 mass=0.5))          # inside the block
    checked = rule(core)                              # a new object: a new rule
    assert core.exempt_overlaps(0.001)
    start = core.body_state_vector()
    assert start.size > old + 26                      # the exempt pair's value
    with pytest.raises(InvalidArgument, match="states"):
        core.propagate_checked(checked, start, H, H, (), 1, np.empty((1, start.size)))
    row = core.propagate_checked(checked, start, H, H, (), 1)
    assert row.states.shape == (1, start.size + 1)
    assert row.states[0, :-1].tobytes() == core.propagate_state(start, H, H).state.tobytes()
