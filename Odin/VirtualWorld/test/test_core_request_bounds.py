"""What a request may set and how a refusal reads: masses, colours and names are checked
before anything is stored, and every refusal quotes a client's value cut short
(odin_common.limits.shown), so a refusal is one short line however large the value."""
import math

import pytest

from odin_common.limits import MAX_NAME_BYTES, MAX_SHOWN_CHARS
from odin_common.specs import CompositeSpec, EntitySpec, JointSpec, MotorSpec, PartSpec
from virtual_world.core import Core, ObjectSpec, step_values
from virtual_world.errors import CoreError, InvalidArgument

LONG = "w" * (MAX_NAME_BYTES + 1)


@pytest.fixture
def core():
    c = Core()
    c.build_object(ObjectSpec("base", [0.2], mass=1.0))
    yield c
    c.close()


@pytest.mark.parametrize("mass", [-2.5, -0.0001, math.nan, -math.inf, math.inf, 1e300])
def test_a_geometry_only_object_with_a_mass_no_body_has_is_refused(core, mass):
    """Geometry only has no body, but its mass is 0 or one a body could have: a negative or
    non-finite one is refused, never ignored; nothing is built."""
    with pytest.raises(InvalidArgument, match="mass"):
        core.build_object(ObjectSpec("wall", [1.0, 1.0, 0.1], mass=mass, geometry_only=True))
    assert core.object_ids() == ["base"]


@pytest.mark.parametrize("mass", [0.0, 2.0])
def test_a_geometry_only_object_takes_no_mass_or_a_valid_one(core, mass):
    core.build_object(ObjectSpec("wall", [1.0, 1.0, 0.1], mass=mass, geometry_only=True))
    assert "wall" in core.object_ids()


def test_a_mass_given_as_text_is_refused(core):
    with pytest.raises(InvalidArgument, match="mass='3' is not a number"):
        core.build_object(ObjectSpec("text", [0.1], mass="3"))


@pytest.mark.parametrize("color", [(1.5, 0.0, 0.0, 1.0), (0.2, -0.1, 0.0, 1.0),
                                   (0.2, 0.2, 0.2, 2.0), (math.nan, 0.0, 0.0, 1.0)])
def test_a_colour_component_out_of_0_1_is_refused_for_objects_and_parts(core, color):
    """The Viewer refuses such colours (the object would never be drawn): the world refuses
    them first, for an object and for a composite's part alike."""
    with pytest.raises(InvalidArgument, match="color"):
        core.build_object(ObjectSpec("red", [0.1], color=color))
    with pytest.raises(InvalidArgument, match="color"):
        core.build_composite(CompositeSpec([PartSpec("p1", [0.1], color=color)]))
    assert core.object_ids() == ["base"]


NAMED = {
    "object": lambda c, n: c.build_object(ObjectSpec(n, [0.1])),
    "part": lambda c, n: c.build_composite(CompositeSpec([PartSpec(n, [0.1])])),
    "entity": lambda c, n: c.build_entity(EntitySpec(n, [ObjectSpec("member", [0.1])])),
    "joint": lambda c, n: c.add_joint(JointSpec(1, "base", "", id=n)),
    "motor": lambda c, n: c.add_motor(MotorSpec(body1="base", axes=(0, 0, 1.0), id=n)),
    "snapshot": lambda c, n: c.save_state(n),
}


@pytest.mark.parametrize("kind", sorted(NAMED))
@pytest.mark.parametrize("name", [LONG, "tab\there", "line\nbreak", "nul\0"])
def test_every_name_a_request_stores_follows_the_name_rule(core, kind, name):
    """Objects, parts, entities, joints, motors and snapshots: longer than MAX_NAME_BYTES or
    holding a control character is refused, with the name quoted short; nothing stored."""
    before = (core.object_ids(), core.joint_ids(), core.motor_ids(), core.snapshot_names(),
              core.entities())
    with pytest.raises(InvalidArgument) as refused:
        NAMED[kind](core, name)
    assert len(str(refused.value)) < 300
    assert (core.object_ids(), core.joint_ids(), core.motor_ids(), core.snapshot_names(),
            core.entities()) == before


def test_a_name_of_exactly_the_limit_is_taken(core):
    core.build_object(ObjectSpec("n" * MAX_NAME_BYTES, [0.1]))


@pytest.mark.parametrize("call", [
    lambda c, v: c.remove_object(v), lambda c, v: c.restore_state(v),
    lambda c, v: c.set_velocity(v, (0.0, 0.0, 0.0)),
    lambda c, v: c.set_poses([(v, (0, 0, 0), (1, 0, 0, 0))]),
    lambda c, v: c.add_body_force(v, 0, (0.0, 0.0, 1.0)),
    lambda c, v: c.set_joint_parameters(v, [(0, 1, 0.1)]),
    lambda c, v: c.build_object(ObjectSpec("big", [0.1], color=[0.5] * 200_000)),
    lambda c, v: c.build_object(ObjectSpec("big", [0.1] * 100_001)),
])
def test_a_refusal_quotes_a_huge_value_short(core, call):
    """A 1 MB unknown name, a 200,000-value colour, 100,001 parameters: the refusal names
    them in a line of a few hundred characters, not a copy of the request."""
    with pytest.raises(CoreError) as refused:
        call(core, "x" * 2 ** 20)
    assert len(str(refused.value)) < 4 * MAX_SHOWN_CHARS + 200


def test_restore_states_refusal_lists_a_few_saved_names_and_counts_the_rest(core):
    for k in range(40):
        core.save_state(f"kept-{k:02d}-" + "s" * 200)
    with pytest.raises(CoreError) as refused:
        core.restore_state("never saved")
    message = str(refused.value)
    assert "30 more" in message and len(message) < 2500


@pytest.mark.parametrize("step", [1e-300, 5e-324, 1e-8])
def test_a_step_below_the_shortest_is_refused_in_a_short_line(step):
    """Set Step 1e-300 printed the 298-digit count of steps in a cycle: it is below MIN_STEP
    and is refused naming the range."""
    with pytest.raises(InvalidArgument) as refused:
        step_values.resolve(step_values.StepValues(), step=step)
    assert "1e-07" in str(refused.value) and len(str(refused.value)) < 120


def _strip_mesh(columns: int):
    """A flat strip of 2 x ``columns`` vertices (m) and its 2 (columns - 1) triangles."""
    import numpy as np
    x = np.repeat(np.arange(columns, dtype=float) * 1e-3, 2)
    vertices = np.stack([x, np.tile([0.0, 1e-3], columns), np.zeros(2 * columns)], axis=1)
    k = np.arange(columns - 1) * 2
    triangles = np.concatenate([np.stack([k, k + 2, k + 1], 1), np.stack([k + 1, k + 2, k + 3],
                                                                          1)])
    return vertices.reshape(-1), triangles.reshape(-1).astype(np.uint32)


def test_a_refused_mesh_leaves_the_worlds_memory_where_it_was(core):
    """A 14 MB mesh that passes its own checks but is refused (a vertex beyond the world's
    extent) is not kept by any cache: the memory the world holds afterwards grows by far less
    than the mesh (the mesh cache had kept its bytes as a key and its arrays, twice its size)."""
    import tracemalloc
    vertices, triangles = _strip_mesh(300_000)
    vertices[-3] = 2e4            # beyond world_extent (1e4 m)
    tracemalloc.start()
    try:
        before = tracemalloc.get_traced_memory()[0]
        with pytest.raises(InvalidArgument, match="world_extent"):
            core.build_object(ObjectSpec("far", vertices, triangles, geometry_only=True))
        grown = tracemalloc.get_traced_memory()[0] - before
    finally:
        tracemalloc.stop()
    assert grown < 2 * 2 ** 20, f"{grown / 2 ** 20:.1f} MB kept after a refusal"


def test_a_mesh_of_too_many_triangles_is_refused_before_it_is_checked():
    """max_mesh_triangles is checked first: a refusal of 3 million triangles takes no time
    to check or convert them."""
    import time
    import numpy as np
    from odin_common.limits import ResourceLimits
    with Core(resources=ResourceLimits(max_mesh_triangles=1000)) as small:
        started = time.perf_counter()
        with pytest.raises(InvalidArgument, match="max_mesh_triangles"):
            small.build_object(ObjectSpec("many", np.zeros(9), np.zeros(9_000_000, np.uint32)))
        assert time.perf_counter() - started < 0.5


def test_a_refused_name_of_a_megabyte_costs_no_memory(core):
    import tracemalloc
    name = "n" * 2 ** 20
    tracemalloc.start()
    try:
        with pytest.raises(InvalidArgument, match="MAX_NAME_BYTES"):
            core.build_object(ObjectSpec(name, [0.1]))
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 3 * 2 ** 20


def test_more_poses_than_objects_are_refused_before_any_is_read(core):
    """Set Position of 100,000 unknown names had cost 65 MB: a request naming more entries
    than the world has objects is refused before any is read (the items here would raise if
    read), and one naming an unknown object at that object."""
    class Unreadable:
        def __len__(self):
            return 100_000

        def __iter__(self):
            raise AssertionError("read")

        def __getitem__(self, index):
            raise AssertionError("read")

    with pytest.raises(InvalidArgument, match="100,000 poses given; the world holds 1"):
        core.set_poses(Unreadable())
    with pytest.raises(InvalidArgument, match="100,000 poses"):
        core.check_collision(Unreadable())


def test_a_body_or_joint_holds_at_most_max_forces_per_owner(core):
    """Each persistent force is applied at every step and adding one walks those held: the
    17th on one body (or joint) is refused, and a Propagate's forces count too."""
    from odin_common.limits import MAX_FORCES_PER_OWNER
    for _ in range(MAX_FORCES_PER_OWNER):
        core.add_body_force("base", 0, (0.0, 0.0, 1.0))
    with pytest.raises(InvalidArgument, match="MAX_FORCES_PER_OWNER"):
        core.add_body_force("base", 1, (0.0, 0.0, 1.0))
    assert len(core.body_force_ids()) == MAX_FORCES_PER_OWNER
    core.build_object(ObjectSpec("free", [0.1], position=(1.0, 0.0, 0.0)))
    push = {"object_id": "free", "kind": 0, "vector": (1.0, 0.0, 0.0)}
    with pytest.raises(InvalidArgument, match="MAX_FORCES_PER_OWNER"):
        core.propagate(0.01, 0.001, body_forces=[push] * (MAX_FORCES_PER_OWNER + 1))
    assert len(core.body_force_ids()) == MAX_FORCES_PER_OWNER
    joint = core.add_joint(JointSpec(1, "free", "", axis1=(0.0, 0.0, 1.0)))
    for _ in range(MAX_FORCES_PER_OWNER):
        core.add_joint_force(joint, [0.1])
    with pytest.raises(InvalidArgument, match="MAX_FORCES_PER_OWNER"):
        core.add_joint_force(joint, [0.1])


def test_get_state_of_more_names_than_the_world_holds_is_refused_before_reading(core):
    """One name repeated 100,000 times would answer 100,000 states: refused at once."""
    for kwargs in ({"objects": ["base"] * 100_000}, {"joints": ["j"] * 2},
                   {"motors": ["m"] * 3}):
        with pytest.raises(InvalidArgument, match="asked for; the world holds"):
            core.state(**kwargs)


def test_saved_states_are_bounded_in_memory_not_only_in_count(core, monkeypatch):
    """A snapshot grows with the scene: with MAX_SNAPSHOT_MB made small, Save State beyond it
    is refused naming the bound (max_snapshots alone would allow 10,000 of any size), and
    saving again under a name held replaces it within the bound."""
    from odin_common import limits
    from virtual_world.core import snapshots
    for k in range(200):
        core.build_object(ObjectSpec(f"b{k}", [0.05], position=(0.2 * k, 2.0, 0.0)))
    core.save_state("first")
    one = snapshots.size_bytes(core._scene.snapshots["first"])
    assert one > 200 * 200
    monkeypatch.setattr(limits, "MAX_SNAPSHOT_MB", 2.5 * one / 2 ** 20)
    core.save_state("second")
    with pytest.raises(InvalidArgument, match="MAX_SNAPSHOT_MB"):
        core.save_state("third")
    core.save_state("second")
    assert core.snapshot_names() == ["first", "second"]
