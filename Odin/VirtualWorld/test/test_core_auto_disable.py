"""ODE's auto-disabling as the world parameter auto_disable (issue 14's scaling lever, off by
default): bodies at rest sleep and cost nothing, and every way the world can change under a
sleeper still reaches it: a request (a velocity, a force, a support removed, new gravity), an
awake body running into it, turning the parameter off. Forces applied to a sleeper do not pile
up, and Save State / Restore State step on alike."""
import numpy as np
import pytest

from odin_common.errors import InvalidArgument
from odin_common.interface import Shape
from virtual_world.core import Core, ObjectSpec, WorldParameters

H = 0.001
RADIUS = 0.1


def spheres(auto_disable: bool, count: int = 16) -> Core:
    """``count`` spheres resting on a plane, 0.3 m apart."""
    core = Core(WorldParameters(auto_disable=auto_disable))
    core.build_object(ObjectSpec("ground", [], shape=Shape.PLANE, geometry_only=True))
    for i in range(count):
        core.build_object(ObjectSpec(f"s{i}", [RADIUS], mass=1.0,
                                     position=((i % 4) * 0.3, (i // 4) * 0.3, RADIUS)))
    return core


def position(core: Core, object_id: str) -> np.ndarray:
    return core.body_state(object_id)[0]


def test_off_by_default_and_nothing_sleeps():
    assert WorldParameters().auto_disable is False
    core = spheres(False)
    core.step(H, 200)
    assert core.sleeping_objects() == []


def test_resting_bodies_fall_asleep_where_they_rest():
    awake, sleepy = spheres(False), spheres(True)
    awake.step(H, 200)
    sleepy.step(H, 200)
    assert sorted(sleepy.sleeping_objects()) == sorted(f"s{i}" for i in range(16))
    # where each sphere rests is the same, within the contact surface layer (1 mm) that an
    # awake sphere keeps sinking into by microns and a sleeping one stops sinking into
    for i in range(16):
        assert np.allclose(position(sleepy, f"s{i}"), position(awake, f"s{i}"), atol=1e-4)


def test_a_velocity_or_a_force_wakes_a_sleeper_and_moves_it():
    core = spheres(True)
    core.step(H, 100)
    core.set_velocity("s0", linear=(1.0, 0.0, 0.0))
    assert core.sleeping_objects() == []
    core.step(H, 100)
    assert position(core, "s0")[0] > 0.05
    core.step(H, 2000)                           # asleep again, then pushed
    assert "s5" in core.sleeping_objects()
    before = position(core, "s5").copy()
    core.add_body_force("s5", 0, (0.0, 0.0, 30.0))      # 30 N up against 9.81 N of weight
    core.step(H, 100)
    assert position(core, "s5")[2] > before[2] + 0.05


def test_removing_the_support_wakes_the_body_resting_on_it():
    core = Core(WorldParameters(auto_disable=True))
    core.build_object(ObjectSpec("floor", [], shape=Shape.PLANE, geometry_only=True))
    core.build_object(ObjectSpec("table", [1.0, 1.0, 0.1], position=(0, 0, 0.5),
                                 geometry_only=True))
    core.build_object(ObjectSpec("box", [0.2, 0.2, 0.2], mass=1.0, position=(0, 0, 0.65)))
    core.step(H, 300)
    assert core.sleeping_objects() == ["box"]
    core.remove_object("table")
    core.step(H, 400)
    assert position(core, "box")[2] < 0.2           # on the floor


def test_new_gravity_wakes_every_sleeper():
    core = spheres(True, count=4)
    core.step(H, 100)
    assert len(core.sleeping_objects()) == 4
    core.set_world_parameters(gravity=(3.0, 0.0, -9.81))
    core.step(H, 200)
    assert all(position(core, f"s{i}")[0] > (i % 4) * 0.3 + 0.01 for i in range(4))


def test_an_awake_body_running_into_a_sleeper_wakes_it():
    core = spheres(True, count=4)
    core.step(H, 100)
    core.build_object(ObjectSpec("ball", [RADIUS], mass=1.0, position=(-0.6, 0.0, RADIUS)))
    core.set_velocity("ball", linear=(3.0, 0.0, 0.0))
    core.step(H, 20)                                # the build woke all; they sleep again
    assert "s0" in core.sleeping_objects() and "ball" not in core.sleeping_objects()
    core.step(H, 300)
    assert position(core, "s0")[0] > 0.05           # ODE woke it on contact; it was pushed


def test_forces_on_a_sleeper_do_not_pile_up():
    """A persistent force friction holds lets the box sleep while it acts every step; when
    the box wakes, only one step's force acts, not thousands."""
    core = Core(WorldParameters(auto_disable=True))
    core.build_object(ObjectSpec("floor", [], shape=Shape.PLANE, geometry_only=True))
    core.build_object(ObjectSpec("box", [0.2, 0.2, 0.2], mass=1.0, position=(0, 0, 0.1)))
    core.add_body_force("box", 0, (2.0, 0.0, 0.0))      # friction can hold 9.81 N
    core.step(H, 300)
    assert core.sleeping_objects() == ["box"]
    core.step(H, 5000)
    core.set_world_parameters(gravity=(0.0, 0.0, -9.81))   # wakes it
    core.step(H, 5)
    assert abs(core.body_state("box")[2][0]) < 0.01     # m/s: 5,000 steps' 2 N would be 10


def test_turning_it_off_wakes_every_body():
    core = spheres(True, count=4)
    core.step(H, 100)
    assert len(core.sleeping_objects()) == 4
    core.set_world_parameters(auto_disable=False)
    assert core.sleeping_objects() == []
    core.step(H, 100)
    assert core.sleeping_objects() == []


def test_a_restored_snapshot_steps_on_as_the_saved_run_did():
    core = spheres(True)
    core.build_object(ObjectSpec("ball", [RADIUS], mass=1.0, position=(-0.6, 0.0, 0.5)))
    core.set_velocity("ball", linear=(2.0, 0.0, 0.0))
    core.step(H, 15)                                # the spheres asleep, the ball flying
    asleep = sorted(core.sleeping_objects())
    assert asleep and "ball" not in asleep
    core.save_state("mid")
    core.step(H, 400)
    first = core.body_state_vector().copy()
    core.restore_state("mid")
    assert sorted(core.sleeping_objects()) == asleep
    core.step(H, 400)
    assert core.body_state_vector().tobytes() == first.tobytes()


def test_a_run_with_auto_disable_is_deterministic():
    def run():
        core = spheres(True)
        core.build_object(ObjectSpec("ball", [RADIUS], mass=1.0, position=(-0.6, 0.0, 0.5)))
        core.set_velocity("ball", linear=(2.0, 0.0, 0.0))
        core.step(H, 600)
        return core.body_state_vector().tobytes()
    assert run() == run()


def test_a_value_that_is_not_a_bool_is_refused():
    core = spheres(False, count=1)
    with pytest.raises(InvalidArgument, match="auto_disable"):
        core.set_world_parameters(auto_disable=1)
    assert core.world_parameters.auto_disable is False
