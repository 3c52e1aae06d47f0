"""Determinism, snapshots, reset, propagation and collision queries: the physics a planner
builds on. "The same" means bit-identical here: poses and velocities are compared as raw
float64 bytes, never with a tolerance."""
import hashlib
import math
import subprocess
import sys

import numpy as np
import pytest

from virtual_world.core import (FORCE, HINGE, LO_STOP, MAX_FORCE, Core, JointSpec, MotorSpec,
                                ObjectSpec, WorldParameters)
from odin_common import OdinError
from virtual_world.errors import InvalidArgument, UnknownName

H = 0.001


def pile(core, n=60):
    """Spheres dropped into a box of four walls: a chaotic scene, where one bit's difference
    in one contact spreads to every body within a second."""
    core.build_object(ObjectSpec("ground", [4, 4, 1], position=(0, 0, -0.5), geometry_only=True))
    for name, pos, size in (("w1", (0.45, 0, 1), (0.2, 1.1, 2)),
                            ("w2", (-0.45, 0, 1), (0.2, 1.1, 2)),
                            ("w3", (0, 0.45, 1), (1.1, 0.2, 2)),
                            ("w4", (0, -0.45, 1), (1.1, 0.2, 2))):
        core.build_object(ObjectSpec(name, list(size), position=pos, geometry_only=True))
    for i in range(n):
        layer = i // 9
        core.build_object(ObjectSpec(f"s{i}", [0.1], position=(
            (i % 3) * 0.21 - 0.21 + 0.01 * (layer % 2), ((i // 3) % 3) * 0.21 - 0.21,
            0.12 + layer * 0.21)))


def state_bytes(core) -> bytes:
    """Every geometry's pose and every body's velocities, as raw bytes."""
    names, positions, quaternions = core.poses()
    velocities = [np.concatenate(core.body_state(i)[2:]) for i in core.object_ids()
                  if not core.object_spec(i).geometry_only]
    return positions.tobytes() + quaternions.tobytes() + np.array(velocities).tobytes()


def digest(core) -> str:
    return hashlib.sha256(state_bytes(core)).hexdigest()


@pytest.fixture
def core():
    c = Core()
    yield c
    c.close()


# ------------------------------------------------------------------ determinism

def test_the_same_pile_is_bit_identical_after_new_scene_cycles(core):
    pile(core)
    core.step(H, 1500)
    first = state_bytes(core)
    for k in range(3):   # other scenes in between: other memory, other broad-phase order
        core.new_scene()
        core.build_object(ObjectSpec(f"junk{k}", [0.3], position=(5, 5, 5)))
        pile(core, n=20 + k)
        core.step(H, 7)
    core.new_scene()
    pile(core)
    core.step(H, 1500)
    assert state_bytes(core) == first


def test_the_same_pile_is_bit_identical_in_a_fresh_process(core):
    script = (f"import sys; sys.path.insert(0, {str(__file__.rsplit('/', 1)[0])!r})\n"
              "import test_core_snapshots as t\nfrom virtual_world.core import Core\n"
              "c = Core(); t.pile(c); c.step(t.H, 800); print(t.digest(c))")
    fresh = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                           check=True).stdout.strip()
    core.build_object(ObjectSpec("elsewhere", [0.2], position=(9, 9, 9)))   # a history
    core.new_scene()
    pile(core)
    core.step(H, 800)
    assert digest(core) == fresh


def hub(core):
    """A sphere 'a' (the lowest serial) touching 'b' and 'c' (mirror images across x, so the
    broad phase sorts them by list order alone) and hinged to 'd', built last: ODE's island
    walk starts at 'd' and reaches a's contacts from a's own joint list, whose order is the
    order the contacts were made in (the order of a's pairs sorted by the lower byte of the
    other geom's serial)."""
    core.set_world_parameters(gravity=(0.0, 0.0, 0.0))
    core.build_object(ObjectSpec("a", [0.1], position=(0, 0, 1)))
    core.build_object(ObjectSpec("b", [0.1], position=(0.05, 0.19, 1)))
    core.build_object(ObjectSpec("c", [0.1], position=(0.05, -0.19, 1)))
    core.build_object(ObjectSpec("d", [0.1, 0.1, 0.1], position=(-0.3, 0, 1)))
    core.add_joint(JointSpec(HINGE, "a", "d", anchor=(-0.15, 0, 1), axis1=(0, 0, 1)))
    core.set_velocity("d", angular=(0, 0, 3.0))


def reversed_space(core):
    """Re-adds every geom to the world's space in reverse order: the broad phase then meets
    (and reports) pairs in another order."""
    from virtual_world.ode.bindings import lib
    space = core._scene.c.space.ptr
    for obj in reversed(list(core._scene.objects.values())):
        for geometry in obj.geometries:
            lib.dSpaceRemove(space, geometry.owner.ptr)
            lib.dSpaceAdd(space, geometry.owner.ptr)


@pytest.mark.parametrize("scene", [pile, hub])
def test_the_broad_phase_order_changes_nothing(scene, monkeypatch):
    """The same scene in a world whose broad phase is ODE's hash space instead of sweep and
    prune, its geoms re-added in reverse order: the pairs are found in another order, but the
    contacts are still made in one order (by the geoms' serials, which do not change), and the
    scene comes out bit-identical."""
    from virtual_world.ode import handles
    one = Core()
    sweep_and_prune = handles.new_space
    monkeypatch.setattr(handles, "new_space", lambda: sweep_and_prune("hash"))
    other = Core()
    monkeypatch.undo()
    try:
        for c in (one, other):
            scene(c)
        reversed_space(other)
        one.step(H, 400)
        other.step(H, 400)
        assert state_bytes(other) == state_bytes(one)
    finally:
        one.close()
        other.close()


def test_another_world_stepping_in_between_changes_nothing():
    alone, shared, other = Core(), Core(), Core()
    for c in (alone, shared, other):
        pile(c)
    for _ in range(10):
        alone.step(H, 60)
        shared.step(H, 60)
        other.step(H, 13)   # QuickStep's random constraint order is each world's own
    assert state_bytes(alone) == state_bytes(shared)
    for c in (alone, shared, other):
        c.close()


# ------------------------------------------------------------------ snapshots

def arm(core):
    """A three-link arm on hinges with motors, stops, a joint force and a body force, over a
    ground it can hit."""
    core.set_world_parameters(solver=1)
    core.build_object(ObjectSpec("ground", [4, 4, 1], position=(0, 0, -0.5), geometry_only=True))
    previous = ""
    for k in range(3):
        core.build_object(ObjectSpec(f"l{k}", [0.3, 0.05, 0.05], mass=1.0,
                                     position=(0.15 + 0.3 * k, 0, 0.5)))
        joint = core.add_joint(JointSpec(HINGE, previous, f"l{k}", anchor=(0.3 * k, 0, 0.5),
                                         axis1=(0, 1, 0)))
        core.add_motor(MotorSpec(joint=joint, max_forces=[8.0]))
        previous = f"l{k}"
    core.set_joint_parameters("1:&l0", [(LO_STOP, 1, -0.5)])
    core.add_joint_force("1:l0&l1", [0.3])
    core.add_body_force("l2", FORCE, (0, 0, -2.0))
    core.set_velocity(motors=["motor:1:&l0", "motor:1:l0&l1"], velocities=[0.4, -0.2])


@pytest.mark.parametrize("build", [pile, arm], ids=["pile", "arm"])
def test_restoring_a_snapshot_replays_bit_for_bit(core, build):
    build(core)
    core.step(H, 300)
    core.save_state("s")
    core.step(H, 700)
    continued = state_bytes(core)
    time_then = core.sim_time
    core.restore_state("s")
    assert core.sim_time == pytest.approx(0.3)
    core.step(H, 700)
    assert state_bytes(core) == continued and core.sim_time == time_then


def test_a_snapshot_brings_back_goals_parameters_and_forces(core):
    arm(core)
    core.step(H, 200)
    core.save_state("before changes")
    core.step(H, 500)
    expected = state_bytes(core)
    core.restore_state("before changes")
    # change every kind of state a snapshot holds ...
    core.set_velocity(motors=["motor:1:&l0", "motor:1:l1&l2"], velocities=[-1.0, 2.0])
    core.set_joint_parameters("1:&l0", [(LO_STOP, 1, -0.1)])
    core.set_joint_parameters("motor:1:l0&l1", [(MAX_FORCE, 1, 1.0)])
    core.add_body_force("l0", FORCE, (5, 0, 0))
    core.remove_joint_force("jointforce:1:l0&l1:0")
    core.set_velocity("l1", linear=(0, 0, 3))
    core.step(H, 50)
    assert state_bytes(core) != expected
    # ... and put it back
    core.restore_state("before changes")
    assert core.body_force_ids() == ["force:l2:0"]
    assert core.joint_force_ids() == ["jointforce:1:l0&l1:0"]
    assert core.motor_goals()["motor:1:&l0"] == [0.4]
    core.step(H, 500)
    assert state_bytes(core) == expected


def test_snapshots_are_listed_replaced_removed_and_forgotten_by_new_scene(core):
    pile(core, n=5)
    core.save_state("a")
    core.save_state("b")
    core.save_state("a")
    assert core.snapshot_names() == ["a", "b"]
    core.remove_state("b")
    assert core.snapshot_names() == ["a"]
    core.new_scene()
    assert core.snapshot_names() == []


def test_an_unknown_snapshot_or_a_changed_scene_is_refused_and_changes_nothing(core):
    pile(core, n=5)
    core.save_state("s")
    core.step(H, 100)
    before = state_bytes(core)
    with pytest.raises(UnknownName, match="no snapshot 'nope'"):
        core.restore_state("nope")
    assert state_bytes(core) == before
    core.build_object(ObjectSpec("newcomer", [0.1], position=(2, 2, 1)))
    grown = state_bytes(core)
    with pytest.raises(InvalidArgument, match="newcomer"):
        core.restore_state("s")
    assert state_bytes(core) == grown
    core.remove_object("newcomer")
    core.remove_object("s0")
    shrunk = state_bytes(core)
    with pytest.raises(InvalidArgument, match="s0"):
        core.restore_state("s")
    assert state_bytes(core) == shrunk and core.sim_time == pytest.approx(0.1)


# ------------------------------------------------------------------ reset

def test_reset_goes_back_to_the_state_right_after_the_last_build(core):
    pile(core, n=10)
    built = state_bytes(core)
    core.set_poses([("s0", (0, 0, 2.0), (1, 0, 0, 0))])
    core.step(H, 400)
    core.reset()
    assert state_bytes(core) == built and core.sim_time == 0.0
    core.step(H, 400)
    once = state_bytes(core)
    core.reset()
    core.step(H, 400)
    assert state_bytes(core) == once
    core.build_object(ObjectSpec("late", [0.1], position=(1, 1, 1)))   # a new last build
    core.step(H, 100)
    after_late = core.body_state("s1")[0].tobytes()
    core.step(H, 100)
    core.reset()
    assert core.body_state("s1")[0].tobytes() != after_late   # the state when "late" came
    assert core.sim_time == pytest.approx(0.4)


# ------------------------------------------------------------------ propagation

def test_propagation_leaves_the_world_as_it_was_and_matches_stepping(core):
    arm(core)
    core.step(H, 100)
    core.save_state("here")
    before = state_bytes(core)
    result = core.propagate(0.25, H)
    assert state_bytes(core) == before and core.sim_time == pytest.approx(0.1)
    assert result.steps == 250 and result.start_time == pytest.approx(0.1)
    assert not result.kept and result.wall_time > 0
    core.step(H, 250)
    stepped = {s: core.body_state(s) for s in ("l0", "l1", "l2")}
    for state in result.states:
        position, orientation, linear, angular = stepped[state.id]
        assert np.array(state.position).tobytes() == position.tobytes()
        assert np.array(state.linear).tobytes() == linear.tobytes()
    assert {s.id for s in result.states} == {"l0", "l1", "l2"}


def test_propagation_from_a_snapshot_under_controls_then_kept(core):
    arm(core)
    core.save_state("start")
    core.step(H, 300)
    goals = {"motor:1:&l0": [-0.8]}
    push = [dict(object_id="l2", kind=FORCE, vector=(0.0, 0.0, 20.0))]
    kept = core.propagate(0.2, H, motor_goals=goals, body_forces=push, start="start", keep=True)
    assert kept.kept and core.sim_time == pytest.approx(0.2)
    assert core.body_force_ids() == ["force:l2:0"]          # the push acted during it only
    assert core.motor_goals()["motor:1:&l0"] == [-0.8]      # goals are state: kept
    after = state_bytes(core)
    # the same by hand
    core.restore_state("start")
    core.set_velocity(motors=["motor:1:&l0"], velocities=[-0.8])
    pushed = core.add_body_force("l2", FORCE, (0.0, 0.0, 20.0))
    core.step(H, 200)
    core.remove_body_force(pushed)
    assert state_bytes(core) == after


def test_propagation_from_a_state_vector_matches_stepping_on_from_it(core):
    pile(core, 18)
    core.step(H, 200)
    vector = core.body_state_vector()
    core.step(H, 150)                                       # elsewhere now
    before = state_bytes(core)
    result = core.propagate(0.3, H, start_state=vector)
    assert state_bytes(core) == before                      # not kept: as it was
    chained = core.propagate(0.2, H, start_state=result.state)
    core.set_body_state_vector(vector)
    core.step(H, 500)                                       # the same by stepping
    assert chained.state.tobytes() == core.body_state_vector().tobytes()
    for state in chained.states:
        position, _, linear, _ = core.body_state(state.id)
        assert np.array(state.position).tobytes() == position.tobytes()
        assert np.array(state.linear).tobytes() == linear.tobytes()


def test_a_state_vector_record_is_what_body_state_reads():
    from odin_common.interface import BODY_STATE_SIZE, body_record
    core = Core()
    try:
        pile(core, 3)
        core.step(H, 120)
        vector = core.body_state_vector()
        assert vector.size == 1 + 3 * BODY_STATE_SIZE
        for index, name in enumerate(("s0", "s1", "s2")):
            position, quaternion, linear, angular = core.body_state(name)
            record = body_record(vector, index)
            for field, value in (("position", position), ("quaternion", quaternion),
                                 ("linear", linear), ("angular", angular)):
                assert np.asarray(record[field]).tobytes() == np.asarray(value).tobytes()
            assert record["enabled"][0] in (0.0, 1.0)
        with pytest.raises(OdinError, match="no body 3"):
            body_record(vector, 3)
    finally:
        core.close()


def test_a_bad_start_state_is_refused_and_changes_nothing(core):
    pile(core, 3)
    core.save_state("start")
    before = state_bytes(core)
    good = core.body_state_vector()
    for kwargs in (dict(start_state=good[:-1]), dict(start_state=np.full(good.size, np.nan)),
                   dict(start_state=good, start="start")):
        with pytest.raises(InvalidArgument):
            core.propagate(0.1, H, **kwargs)
        assert state_bytes(core) == before, kwargs


def test_propagation_reports_each_collision_once_with_its_first_time(core):
    core.build_object(ObjectSpec("ground", [4, 4, 1], position=(0, 0, -0.5), geometry_only=True))
    core.build_object(ObjectSpec("ball", [0.1], position=(0, 0, 0.6)))
    result = core.propagate(0.6, H)
    (hit,) = result.collisions
    assert (hit.first, hit.second) == ("ball", "ground")
    fall = math.sqrt(2 * 0.5 / 9.81)   # the ball's bottom falls 0.5 m
    assert abs(hit.first_time - fall) < 0.003 and hit.depth > 0
    assert core.read_collisions() == [] and core.sim_time == 0.0


def test_a_bad_propagation_is_refused_and_changes_nothing(core):
    arm(core)
    core.step(H, 50)
    before = state_bytes(core)
    for kwargs in (dict(duration=-1.0), dict(step_size=0.0), dict(start="unknown"),
                   dict(motor_goals={"motor:nope": [1.0]}),
                   dict(motor_goals={"motor:1:&l0": [1.0, 2.0]}),
                   dict(body_forces=[dict(object_id="ground", kind=FORCE, vector=(1, 0, 0))]),
                   dict(body_forces=[dict(object_id="l1", kind=FORCE, vector=(math.nan, 0, 0))])):
        with pytest.raises(OdinError):
            core.propagate(**{"duration": 0.1, "step_size": H, **kwargs})
        assert state_bytes(core) == before, kwargs
        assert core.body_force_ids() == ["force:l2:0"]
        assert core.motor_goals()["motor:1:&l0"] == [0.4]


@pytest.mark.parametrize("build,pushed", [(pile, "s4"), (arm, "l2")], ids=["pile", "arm"])
def test_a_state_propagation_is_bit_for_bit_a_kept_propagation_from_the_state(core, build,
                                                                              pushed):
    """propagate_state (a planner's propagation in one C call) against propagate from the
    same vectors under the same forces, kept: the same states, pairs and world after. The
    pushed body holds persistent forces too: ODE must sum them in the same order."""
    build(core)
    for persistent in ((0.31, -1.37, 0.93), (-0.57, 0.11, 0.29)):  # sums that the order
        core.add_body_force(pushed, FORCE, persistent)              # of summands changes
    rng = np.random.default_rng(3)
    vectors = []
    for _ in range(4):
        core.step(H, 70)
        vectors.append(core.body_state_vector())
    for k in range(12):
        vector = vectors[rng.integers(len(vectors))]
        push = tuple(float(v) for v in rng.normal(0.0, 30.0, 3))
        duration = (1, 7, 40)[k % 3] * H
        general = core.propagate(duration, H, start_state=vector, keep=True, body_forces=[
            dict(object_id=pushed, kind=FORCE, vector=push)])
        world_after = state_bytes(core)
        fast = core.propagate_state(vector, duration, H, [(pushed, push)])
        assert fast.state.tobytes() == general.state.tobytes(), k
        assert fast.pairs == tuple((c.first, c.second) for c in general.collisions), k
        assert fast.steps == general.steps
        assert state_bytes(core) == world_after
        vectors.append(fast.state)
    assert core.read_collisions() == []                      # nothing left over to report
    assert len(core.body_force_ids()) == (2 if build is pile else 3)   # the pushes are gone


def test_a_state_propagation_reports_every_pair_met_on_the_way(core):
    core.build_object(ObjectSpec("ground", [4, 4, 1], position=(0, 0, -0.5), geometry_only=True))
    core.build_object(ObjectSpec("ball", [0.1], position=(0, 0, 0.6)))
    start = core.body_state_vector()
    assert core.propagate_state(start, 0.2, H).pairs == ()            # still falling
    landed = core.propagate_state(start, 0.6, H)
    assert landed.pairs == (("ball", "ground"),) and landed.steps == 600
    # the world stays where the propagation ended, and time went on
    assert core.body_state_vector().tobytes() == landed.state.tobytes()
    assert core.sim_time == pytest.approx(0.8)


def test_a_bad_state_propagation_is_refused_and_changes_nothing(core):
    from odin_common.limits import MAX_FORCE as FORCE_LIMIT
    arm(core)
    core.build_object(ObjectSpec("ball", [0.1], position=(2, 0, 0.1)))   # on the ground
    core.step(H, 50)
    good = core.body_state_vector()
    core.step(H, 20)
    before, time_before, touching = state_bytes(core), core.sim_time, core.read_collisions()
    assert [(c.first, c.second) for c in touching] == [("ball", "ground")]
    seed_broken, nan_inside = good.copy(), good.copy()
    seed_broken[0] = 0.5
    nan_inside[30] = np.nan
    for args, message in (
            ((good[:-1], 0.01, H), "values"), ((nan_inside, 0.01, H), "value 30 is nan"),
            ((np.full(good.size, np.inf), 0.01, H), "32-bit"),
            ((["a"] * good.size, 0.01, H), "numbers"), ((seed_broken, 0.01, H), "32-bit"),
            ((good, -1.0, H), "duration"), ((good, 0.01, 0.0), "step_size"),
            ((good, 1e9, H), "steps"),
            ((good, 0.01, H, [("ground", (1, 0, 0))]), "geometry only"),
            ((good, 0.01, H, [("nope", (1, 0, 0))]), "no object"),
            ((good, 0.01, H, [("l1", (math.nan, 0, 0))]), "finite"),
            ((good, 0.01, H, [("l1", (0, 0, 2 * FORCE_LIMIT))]), "beyond the limit"),
            ((good, 0.01, H, [("l1",)]), "object id, force vector"),
            ((good, 0.01, H, [("l1", (1, 0))]), "vector of 3 numbers")):
        with pytest.raises(OdinError, match=message):
            core.propagate_state(*args)
        assert state_bytes(core) == before and core.sim_time == time_before, message
        assert core.read_collisions() == touching, message
    assert core.body_force_ids() == ["force:l2:0"]


# ------------------------------------------------------------------ collision queries

@pytest.mark.parametrize("contact_less", [False, True])
def test_a_collision_query_answers_at_once_and_leaves_the_world_as_it_was(contact_less):
    core = Core(WorldParameters(contact_less=contact_less, gravity=(0, 0, 0)))
    core.build_object(ObjectSpec("table", [1, 1, 0.1], position=(0, 0, 0.5), geometry_only=True))
    core.build_object(ObjectSpec("can", [0.05, 0.2], position=(2, 0, 0.7)))
    core.build_object(ObjectSpec("a", [0.1], position=(5, 0, 0)))
    core.build_object(ObjectSpec("b", [0.1], position=(5.15, 0, 0)))   # touching already
    core.step(H)
    before = state_bytes(core)
    hits = core.check_collision([("can", (0, 0, 0.62), (1, 0, 0, 0))])
    assert [(c.first, c.second) for c in hits] == [("a", "b"), ("can", "table")]
    depth = {(c.first, c.second): c.depth for c in hits}
    assert depth[("can", "table")] == pytest.approx(0.03, abs=1e-6)   # 0.62 - 0.1 - 0.55
    assert core.check_collision([("can", (0, 0, 1.0), (1, 0, 0, 0))]) == \
        [c for c in hits if c.first == "a"]
    assert core.check_collision([("table", (2, 0, 0.6), (1, 0, 0, 0))])[1][:2] == \
        ("can", "table")   # a static object moved for the question only
    assert state_bytes(core) == before
    reported = [(c.first, c.second) for c in core.read_collisions()]
    assert reported == [("a", "b")]   # the query added nothing to what the world reports
    with pytest.raises(UnknownName):
        core.check_collision([("ghost", (0, 0, 0), (1, 0, 0, 0))])
    core.close()


def test_a_row_is_bit_for_bit_its_propagations_one_by_one(core):
    """propagate_row (a planner's control held over several propagations, one call: what the
    pool back end asks a world for, issue 42) against propagate_state called as many times,
    each from the state the last reached: the same states and pairs; without keep the world
    goes back; a bad row is refused and changes nothing."""
    arm(core)
    core.build_object(ObjectSpec("ball", [0.1], position=(2, 0, 0.1)))
    core.step(H, 50)
    start, before = core.body_state_vector(), state_bytes(core)
    row = core.propagate_row(start, 6, 7 * H, H, [("l2", (3.0, -1.0, 0.5))])
    assert state_bytes(core) == before                       # not kept: put back
    vector = start
    for one in row:
        alone = core.propagate_state(vector, 7 * H, H, [("l2", (3.0, -1.0, 0.5))])
        assert one.state.tobytes() == alone.state.tobytes()
        assert one.pairs == alone.pairs and one.steps == alone.steps == 7
        vector = alone.state
    kept = core.propagate_row(start, 2, 7 * H, H, keep=True)
    assert core.body_state_vector().tobytes() == kept[-1].state.tobytes()
    core.set_body_state_vector(start)
    before = state_bytes(core)
    for args, message in (((start, 0, 7 * H, H), "row=0"), ((start[:-1], 3, 7 * H, H), "values"),
                          ((start, 10 ** 9, 7 * H, H), "body-steps")):
        with pytest.raises(InvalidArgument, match=message):
            core.propagate_row(*args)
        assert state_bytes(core) == before
