"""Requests as the Portal passes them: ROS messages leave unused fields at zero."""
import pytest

from virtual_world.core import HINGE, UNIVERSAL, Core, JointSpec, MotorSpec, ObjectSpec
from virtual_world.errors import InvalidArgument, UnknownName


@pytest.fixture
def core():
    with Core() as world:
        yield world


def test_geometry_only_objects_need_no_mass(core):
    core.build_object(ObjectSpec("ground", [1, 1, 0.1], mass=0.0, geometry_only=True))
    assert "ground" in core.poses()[0]
    with pytest.raises(InvalidArgument):
        core.build_object(ObjectSpec("body", [1, 1, 0.1], mass=0.0))


def test_only_the_axes_a_joint_type_uses_are_checked(core):
    core.build_object(ObjectSpec("a", [0.1]))
    core.build_object(ObjectSpec("b", [0.1], position=(0.5, 0, 0)))
    core.build_object(ObjectSpec("c", [0.1], position=(1.0, 0, 0)))
    zero = (0.0, 0.0, 0.0)
    core.add_joint(JointSpec(HINGE, "a", "b", axis1=(0, 0, 1), axis2=zero, axis3=zero))
    with pytest.raises(InvalidArgument):
        core.add_joint(JointSpec(HINGE, "b", "c", axis1=zero))
    with pytest.raises(InvalidArgument):
        core.add_joint(JointSpec(UNIVERSAL, "b", "c", axis1=(0, 0, 1), axis2=zero))
    assert core.joint_ids() == ["1:a&b"]


def test_motor_axis_counts(core):
    core.build_object(ObjectSpec("a", [0.1]))
    joint = core.add_joint(JointSpec(HINGE, "a", "", axis1=(0, 0, 1)))
    motor = core.add_motor(MotorSpec(joint=joint))
    assert core.motor_axis_counts([motor]) == [1]
    with pytest.raises(UnknownName):
        core.motor_axis_counts(["motor:none"])


def test_detect_collisions_reports_what_touches_now_without_stepping(core):
    core.set_world_parameters(contact_less=True)
    core.build_object(ObjectSpec("wall", [0.2, 2, 2], geometry_only=True))
    core.build_object(ObjectSpec("ball", [0.1], position=(1, 0, 0)))
    core.detect_collisions()
    assert core.read_collisions() == []
    core.set_poses([("ball", (0.15, 0, 0), (1, 0, 0, 0))])
    core.detect_collisions()
    (pair,) = core.read_collisions()
    assert {pair.first, pair.second} == {"wall", "ball"}
    assert pair.depth == pytest.approx(0.05, abs=1e-6)
    assert core.sim_time == 0.0


def test_detect_collisions_does_nothing_under_the_contact_policy(core):
    core.build_object(ObjectSpec("wall", [0.2, 2, 2], geometry_only=True))
    core.build_object(ObjectSpec("ball", [0.1], position=(0.15, 0, 0)))
    core.detect_collisions()
    assert core.read_collisions() == [] and core.sim_time == 0.0


def test_an_object_without_collisions_passes_through_everything(core):
    core.set_world_parameters(gravity=(0, 0, -9.81))
    core.build_object(ObjectSpec("floor", [2, 2, 0.1], position=(0, 0, -0.05),
                                 geometry_only=True))
    core.build_object(ObjectSpec("ghost", [0.1], position=(0, 0, 0.5), no_collisions=True))
    core.build_object(ObjectSpec("ball", [0.1], position=(1, 0, 0.5)))
    core.step(0.001, 1000)
    names, positions, _ = core.poses()
    z = dict(zip(names, positions[:, 2]))
    assert z["ball"] == pytest.approx(0.1, abs=0.01)      # rests on the floor
    assert z["ghost"] < -3.0                              # fell through it
    with pytest.raises(InvalidArgument):
        core.build_object(ObjectSpec("bad", [0.1], no_collisions="yes"))
