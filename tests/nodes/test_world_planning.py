"""The world node's services for planners, through ROS: Get World, Save/Restore State, Reset,
Propagate and Check Collision. Poses cross ROS as float64, so "the same" is exact here too.

Each test has its own roscore and runs in a forked process (rospy.init_node once per process).
"""
from __future__ import annotations

import pytest

pytestmark = pytest.mark.forked


@pytest.fixture
def world(ros_master):
    """A paused virtualWorld node and a raw client of it."""
    import rospy
    from world_client import WorldClient

    node = ros_master.rosrun("VirtualWorld", "virtualWorld")
    ros_master.wait_for_service("/virtual_world/check_collision")
    rospy.init_node("odin_test_client", anonymous=True, disable_signals=True)
    client = WorldClient()
    yield client
    client.close()
    assert node.poll() is None, "virtualWorld died:\n" + ros_master.log_text(node)[-3000:]


def _scene(world):
    """Ground, a pile of five spheres and a pendulum on a motor."""
    from world_client import box, sphere
    world.ok("build_object", object=box("ground", (4, 4, 0.2), (0, 0, -0.1), geometry_only=True))
    for i in range(5):
        world.ok("build_object", object=sphere(f"s{i}", 0.1, (0.05 * i, 0, 0.3 + 0.21 * i)))
    world.ok("build_object", object=sphere("bob", 0.1, (2, 0, 1)))
    world.ok("set_joint", action=0, type=1, body1="bob", body2="", anchor=[2, 0, 1.5],
             axis1=[0, 1, 0])
    world.ok("set_motor", joint="1:bob&", max_forces=[2.0])


def _states(response) -> dict:
    return {s.id: (tuple(s.position), tuple(s.orientation), tuple(s.linear), tuple(s.angular))
            for s in response.states}


def test_get_world_says_what_the_world_holds_and_the_values_in_force(world):
    _scene(world)
    world.ok("set_world", set_erp=True, erp=0.3)
    world.ok("save_state", name="built")
    world.ok("set_external_force", object="s0", kind=0, vector=[0, 0, 1])
    got = world.ok("get_world")
    assert got.objects == ["ground", "s0", "s1", "s2", "s3", "s4", "bob"]
    assert got.joints == ["1:bob&"] and got.motors == ["motor:1:bob&"]
    assert got.body_forces == ["force:s0:0"] and got.snapshots == ["built"]
    assert got.parameters.erp == pytest.approx(0.3) and got.parameters.max_contacts == 3
    assert (got.step, got.steps_per_cycle, got.rate) == (0.001, 40, 25.0)
    assert not got.simulating and got.sim_time == 0.0


def test_restore_and_propagate_repeat_exactly(world):
    _scene(world)
    world.ok("step_once", cycles=5)
    world.ok("save_state", name="s")
    first = world.ok("propagate", duration=0.5, motors=["motor:1:bob&"], velocities=[1.5])
    again = world.ok("propagate", duration=0.5, motors=["motor:1:bob&"], velocities=[1.5])
    assert first.steps == 500 and first.start_time == pytest.approx(0.2)
    assert _states(first) == _states(again)          # the world went back in between
    kept = world.ok("propagate", duration=0.5, motors=["motor:1:bob&"], velocities=[1.5],
                    keep=True)
    assert _states(kept) == _states(first)
    restored = world.ok("restore_state", name="s")
    assert restored.sim_time == pytest.approx(0.2)
    from_snapshot = world.ok("propagate", start="s", duration=0.5, motors=["motor:1:bob&"],
                             velocities=[1.5])
    assert _states(from_snapshot) == _states(first)
    collided = {(c.first, c.second) for c in first.collisions}
    assert ("ground", "s0") in collided and len(first.first_times) == len(first.collisions)


def test_reset_returns_to_the_state_after_the_build(world):
    _scene(world)
    start = world.ok("propagate", duration=0.001)      # one step from the start, not kept
    world.ok("step_once", cycles=10)
    assert world.ok("reset").sim_time == 0.0
    assert _states(world.ok("propagate", duration=0.001)) == _states(start)


def test_a_collision_query_answers_without_changing_the_world(world):
    _scene(world)
    before = world.ok("propagate", duration=0.001)
    hit = world.ok("check_collision", situations=[_situation("bob", (0, 0, 0.05))])
    assert ("bob", "ground") in {(p.first, p.second) for p in hit.pairs}
    # no situation: the scene as it stands (the spheres 1 cm apart, bob 0.9 m up)
    assert world.ok("check_collision", situations=[]).pairs == []
    world.ok("build_object", object=__import__("world_client").sphere("inside", 0.1, (2, 0, 0.95)))
    inside = world.ok("check_collision", situations=[]).pairs
    assert [(p.first, p.second) for p in inside] == [("bob", "inside")]
    assert inside[0].depth > 0.1
    world.ok("remove_object", id="inside")
    assert _states(world.ok("propagate", duration=0.001)) == _states(before)


def _situation(name, position):
    from Messages.msg import Situation
    return Situation(name=name, position=list(position), orientation=[1, 0, 0, 0])


def test_bad_planning_requests_are_refused_and_change_nothing(world):
    _scene(world)
    world.ok("save_state", name="s")
    before = world.ok("propagate", duration=0.001)
    for service, fields in [
            ("restore_state", dict(name="nope")),
            ("save_state", dict(name="")),
            ("propagate", dict(duration=-1.0)),
            ("propagate", dict(duration=0.1, start="nope")),
            ("propagate", dict(duration=0.1, motors=["motor:1:bob&"], velocities=[1.0, 2.0])),
            ("propagate", dict(duration=0.1, motors=["motor:x"], velocities=[1.0])),
            ("check_collision", dict(situations=[_situation("ghost", (0, 0, 0))]))]:
        response = world(service, **fields)
        assert not response.success and response.message, (service, fields)
    assert _states(world.ok("propagate", duration=0.001)) == _states(before)
    world.ok("build_object", object=__import__("world_client").sphere("late", 0.1, (3, 3, 1)))
    refused = world("restore_state", name="s")
    assert not refused.success and "late" in refused.message


def test_get_state_gives_masses_joint_reactions_and_motor_goals(world):
    _scene(world)
    world.ok("set_velocity", motors=["motor:1:bob&"], velocities=[0.5])
    world.ok("step_once", cycles=2)
    state = world.ok("get_state", objects=["bob"], joints=["1:bob&"])
    (bob,) = state.bodies
    assert bob.id == "bob" and list(state.masses) == [1.0]
    assert state.inertias[0] == pytest.approx(0.4 * 1.0 * 0.1 ** 2)
    (joint,) = state.joints
    assert joint.rates[0] == pytest.approx(0.5, abs=1e-3)     # QuickStep, the default
    # the hinge holds the bob's weight: its force on the bob is up, m g
    assert state.reactions1[0].force.z == pytest.approx(9.81, rel=0.02)
    everything = world.ok("get_state")
    assert everything.motors == ["motor:1:bob&"] and list(everything.motor_goals) == [0.5]
    assert list(everything.motor_max_forces) == [2.0] and list(everything.motor_axes) == [1]
    assert [b.id for b in everything.bodies] == ["s0", "s1", "s2", "s3", "s4", "bob"]
    refused = world("get_state", objects=["ground"])
    assert not refused.success and "geometry only" in refused.message


def test_a_servo_holds_a_joint_at_its_target_and_reports_it(world):
    """The pendulum's hinge servoed to 0.3 rad: the joint gets there and ~servo_states says so;
    released, the motor holds at speed zero; a servo on no motor is refused."""
    import rospy
    from Messages.msg import ServoStates

    _scene(world)
    world.ok("set_servo", motors=["motor:1:bob&"], targets=[0.3], max_forces=[20.0])
    world.ok("step_once", cycles=50)                     # 2 s
    state = world.ok("get_state", joints=["1:bob&"])
    assert state.joints[0].positions[0] == pytest.approx(0.3, abs=0.01)
    world.ok("start", simulate=True)
    report = rospy.wait_for_message("/virtual_world/servo_states", ServoStates, timeout=10)
    world.ok("start", simulate=False)
    assert report.motors == ["motor:1:bob&"] and list(report.axes) == [1]
    assert report.targets[0] == 0.3 and abs(report.errors[0]) < 0.01
    refused = world("set_servo", motors=["nothing"], targets=[0.0])
    assert not refused.success and "nothing" in refused.message
    refused = world("set_servo", motors=["motor:1:bob&"], targets=[0.0, 1.0])
    assert not refused.success
    world.ok("set_servo", motors=["motor:1:bob&"], release=True)
    got = world.ok("get_state")
    assert list(got.motor_goals) == [0.0]


def test_set_servos_kinematic_drive_moves_the_joint_at_exactly_its_speed(world):
    """The pendulum's hinge under the kinematic drive (Set Servo ``drive`` alone): at 0.5 rad/s
    for 2 s it is at 1 rad exactly, though its motor (2 N m) could not lift the bob that far;
    a bad drive is refused; DYNAMIC gives the joint back to the motor."""
    from Services.srv import SetServoRequest
    _scene(world)
    refused = world("set_servo", motors=["motor:1:bob&"], drive=7)
    assert not refused.success and "drive 7" in refused.message
    world.ok("set_servo", motors=["motor:1:bob&"], drive=SetServoRequest.KINEMATIC)
    world.ok("set_velocity", motors=["motor:1:bob&"], velocities=[0.5])
    world.ok("step_once", cycles=50)                     # 2 s
    state = world.ok("get_state", joints=["1:bob&"])
    assert state.joints[0].positions[0] == pytest.approx(1.0, abs=1e-9)
    world.ok("set_servo", motors=["motor:1:bob&"], drive=SetServoRequest.DYNAMIC)
    world.ok("set_velocity", motors=["motor:1:bob&"], velocities=[0.0])
    world.ok("step_once", cycles=25)
    state = world.ok("get_state", joints=["1:bob&"])
    assert state.joints[0].positions[0] < 0.99          # the weak motor gives way
