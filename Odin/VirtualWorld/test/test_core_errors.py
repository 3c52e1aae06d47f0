"""Every bad input raises the right error and changes nothing."""
import math

import numpy as np
import pytest

from odin_common import OdinError
from virtual_world import core as vc
from virtual_world.core import (CompositeSpec, Core, EntitySpec, JointSpec, MotorSpec, ObjectSpec,
                                PartSpec)
from virtual_world.errors import (Closed, CoreError, DuplicateName, InvalidArgument,
                                  Unsupported, UnknownName)

NAN, INF = float("nan"), float("inf")


@pytest.fixture
def core():
    c = Core()
    c.build_object(ObjectSpec("a", [0.1], position=(0, 0, 1)))
    c.build_object(ObjectSpec("b", [0.1, 0.2, 0.3], position=(1, 0, 1)))
    c.build_object(ObjectSpec("wall", [1, 1, 1], position=(5, 0, 0), geometry_only=True))
    c.add_joint(JointSpec(vc.HINGE, "a", "b", anchor=(0.5, 0, 1)))
    c.add_motor(MotorSpec(joint="1:a&b"))
    c.add_body_force("a", vc.FORCE, (1, 0, 0))
    c.add_joint_force("1:a&b", [0.1])
    yield c
    c.close()


def snapshot(c):
    names, positions, quaternions = c.poses()
    return (names, positions.tolist(), quaternions.tolist(), c.object_ids(), c.joint_ids(),
            c.motor_ids(), c.body_force_ids(), sorted(c.joint_force_ids()), c.world_parameters,
            c.entities(), c.body_state("a")[2].tolist())


def test_error_hierarchy():
    assert issubclass(CoreError, OdinError)
    for cls in (InvalidArgument, UnknownName, DuplicateName, Unsupported, Closed):
        assert issubclass(cls, CoreError)


MESH = [0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1]
BAD_OBJECTS = [
    (ObjectSpec("", [0.1]), InvalidArgument, "name"),
    (ObjectSpec("x>y", [0.1]), InvalidArgument, "'>'"),
    (ObjectSpec("a", [0.1]), DuplicateName, "'a'"),
    (ObjectSpec("x", [0.1], orientation=(0, 0, 0, 0)), InvalidArgument, "zero quaternion"),
    (ObjectSpec("x", [0.1], orientation=(1, 0, 0, 0.5)), InvalidArgument, "unit quaternion"),
    (ObjectSpec("x", [0.1], orientation=(NAN, 0, 0, 0)), InvalidArgument, "finite"),
    (ObjectSpec("x", [0.1], orientation=(1, 0, 0)), InvalidArgument, "expected 4"),
    (ObjectSpec("x", [0.1], mass=0.0), InvalidArgument, "mass"),
    (ObjectSpec("x", [0.1], mass=-1.0), InvalidArgument, "mass"),
    (ObjectSpec("x", [0.1], mass=INF), InvalidArgument, "finite"),
    (ObjectSpec("x", [0.1], position=(0, INF, 0)), InvalidArgument, "finite"),
    (ObjectSpec("x", [0.0]), InvalidArgument, "positive"),
    (ObjectSpec("x", [0.1, -1]), InvalidArgument, "positive"),
    (ObjectSpec("x", [1, 1, NAN]), InvalidArgument, "finite"),
    (ObjectSpec("x", [1, 1, 1, 1]), InvalidArgument, "fit no shape"),
    (ObjectSpec("x", [1] * 10), InvalidArgument, "fit no shape"),
    (ObjectSpec("x", [0.1], indices=[0, 1, 2]), InvalidArgument, "primitive"),
    (ObjectSpec("x", MESH, indices=[0, 1]), InvalidArgument, "3 per triangle"),
    (ObjectSpec("x", MESH, indices=[]), InvalidArgument, "3 per triangle"),
    (ObjectSpec("x", MESH, indices=[0, 1, 4]), InvalidArgument, "out of range"),
    (ObjectSpec("x", MESH, indices=[0, 1, -1]), InvalidArgument, "out of range"),
    (ObjectSpec("x", MESH, indices=[0, 1, 1.5]), InvalidArgument, "integers"),
    (ObjectSpec("x", MESH, indices=[0, 0, 0]), InvalidArgument, "degenerate"),
    (ObjectSpec("x", [0.1], inertia=[1, 1]), InvalidArgument, "expected 6"),
    (ObjectSpec("x", [0.1], inertia=[1, 1, -1, 0, 0, 0]), InvalidArgument, "positive definite"),
    (ObjectSpec("x", [0.1], inertia=[1, 1, 5, 0, 0, 0]), InvalidArgument, "triangle"),
    (ObjectSpec("x", [0.1], color=(1, 1)), InvalidArgument, "color"),
    (ObjectSpec("x", [0.1], fixed="yes"), InvalidArgument, "fixed"),
    ("not a spec", InvalidArgument, "ObjectSpec"),
]


@pytest.mark.parametrize("spec,error,text", BAD_OBJECTS)
def test_bad_objects(core, spec, error, text):
    before = snapshot(core)
    with pytest.raises(error) as info:
        core.build_object(spec)
    assert text in str(info.value)
    assert snapshot(core) == before


def test_unit_quaternion_tolerance(core):
    core.build_object(ObjectSpec("x", [0.1], orientation=(1 + 5e-5, 0, 0, 0)))
    np.testing.assert_allclose(core.poses()[2][-1], (1, 0, 0, 0))


BAD_COMPOSITES = [
    (CompositeSpec([]), InvalidArgument),
    (CompositeSpec([PartSpec("p", [0.1]), PartSpec("p", [0.1])]), DuplicateName),
    (CompositeSpec([PartSpec("a", [0.1])]), DuplicateName),  # geometry name of object a
    (CompositeSpec([PartSpec("p", [0.1]), PartSpec("q", [0.1], mass=0)]), InvalidArgument),
    (CompositeSpec([PartSpec("p", [0.1], orientation=(0, 0, 0, 2))]), InvalidArgument),
    (CompositeSpec([PartSpec("p>", [0.1])]), InvalidArgument),
    (CompositeSpec([PartSpec("p", [0.1])], position=(NAN, 0, 0)), InvalidArgument),
    (CompositeSpec(["nope"]), InvalidArgument),
]


@pytest.mark.parametrize("spec,error", BAD_COMPOSITES)
def test_bad_composites(core, spec, error):
    before = snapshot(core)
    with pytest.raises(error):
        core.build_composite(spec)
    assert snapshot(core) == before


def test_bad_entities_build_nothing(core):
    before = snapshot(core)
    good, bad = ObjectSpec("g1", [0.1]), ObjectSpec("g2", [0.1], mass=-1)
    with pytest.raises(InvalidArgument):
        core.build_entity(EntitySpec("e", [good, bad], [], False))
    with pytest.raises(DuplicateName):
        core.build_entity(EntitySpec("e", [good, ObjectSpec("g1", [0.2])], [], False))
    with pytest.raises(DuplicateName):
        core.build_entity(EntitySpec("e", [good], [CompositeSpec([PartSpec("g1", [0.1])])],
                                     True))
    with pytest.raises(InvalidArgument):
        core.build_entity(EntitySpec("e", [], [], True))
    assert snapshot(core) == before
    core.build_entity(EntitySpec("e", [good], [], True))
    with pytest.raises(DuplicateName):
        core.build_entity(EntitySpec("e", [ObjectSpec("g3", [0.1])], [], True))


@pytest.mark.parametrize("args,error", [
    ((vc.HINGE, "a", "nope"), UnknownName),
    ((vc.HINGE, "", ""), InvalidArgument),
    ((vc.HINGE, "a", "a"), InvalidArgument),
    ((vc.BALL, "a", "b"), DuplicateName),           # one joint per pair
    ((vc.BALL, "b", "a"), DuplicateName),
    ((42, "a", ""), InvalidArgument),
    ((vc.HINGE, "a", "wall"), Unsupported),          # geometry only: no body
    ((vc.PLANE2D, "a", "b"), Unsupported),
])
def test_bad_joints(core, args, error):
    before = snapshot(core)
    with pytest.raises(error):
        core.add_joint(JointSpec(*args))
    assert snapshot(core) == before


@pytest.mark.parametrize("kwargs,error", [
    (dict(axis1=(0, 0, 0)), InvalidArgument),
    (dict(axis1=(0, NAN, 1)), InvalidArgument),
    (dict(anchor=(0, 0)), InvalidArgument),
    (dict(type=vc.UNIVERSAL, axis1=(1, 0, 0), axis2=(2, 0, 0)), InvalidArgument),
    (dict(id="1:a&b"), DuplicateName),
])
def test_bad_joint_arguments(core, kwargs, error):
    core.build_object(ObjectSpec("c", [0.1], position=(2, 0, 1)))
    before = snapshot(core)
    kwargs = dict(kwargs)
    joint_type = kwargs.pop("type", vc.HINGE)
    with pytest.raises(error):
        core.add_joint(JointSpec(joint_type, "c", "", **kwargs))
    assert snapshot(core) == before


@pytest.mark.parametrize("joint,params,error", [
    ("1:a&b", [(vc.SUSPENSION_ERP, 1, 0.5)], Unsupported),
    ("1:a&b", [(vc.LO_STOP, 2, 0.5)], InvalidArgument),
    ("1:a&b", [(vc.ERP, 1, 1.5)], InvalidArgument),
    ("1:a&b", [(vc.CFM, 1, -1.0)], InvalidArgument),
    ("1:a&b", [(vc.BOUNCE, 1, NAN)], InvalidArgument),
    ("1:a&b", [(vc.VELOCITY, 1, INF)], InvalidArgument),
    ("1:a&b", [(99, 1, 0.0)], InvalidArgument),
    ("1:a&b", [(vc.LO_STOP, 1, -0.5), (vc.HI_STOP, 1, NAN)], InvalidArgument),
    ("1:a&b", [(vc.LO_STOP, 1)], InvalidArgument),
    ("nope", [(vc.LO_STOP, 1, 0.0)], UnknownName),
])
def test_bad_joint_parameters(core, joint, params, error):
    with pytest.raises(error):
        core.set_joint_parameters(joint, params)


def test_joint_parameters_fit_type(core):
    core.build_object(ObjectSpec("c", [0.1], position=(2, 0, 1)))
    ball = core.add_joint(JointSpec(vc.BALL, "c", ""))
    with pytest.raises(Unsupported):
        core.set_joint_parameters(ball, [(vc.LO_STOP, 1, 0.0)])
    core.set_joint_parameters(ball, [(vc.CFM, 1, 1e-6), (vc.ERP, 1, 0.5)])
    core.set_joint_parameters("1:a&b", [(vc.LO_STOP, 1, -INF), (vc.MAX_FORCE, 1, -1),
                                        (vc.VELOCITY, 1, 0.5), (vc.FUDGE_FACTOR, 1, 0.5)])
    core.set_joint_parameters("motor:1:a&b", [(vc.MAX_FORCE, 1, 2.0), (vc.VELOCITY, 1, 1.0)])
    assert core.motor_goals()["motor:1:a&b"] == [1.0]


def test_bad_motors(core):
    before = snapshot(core)
    with pytest.raises(DuplicateName):
        core.add_motor(MotorSpec(joint="1:a&b"))
    with pytest.raises(UnknownName):
        core.add_motor(MotorSpec(joint="nope"))
    with pytest.raises(InvalidArgument):
        core.add_motor(MotorSpec(body1="a", axes=[0, 0, 1, 1]))
    with pytest.raises(InvalidArgument):
        core.add_motor(MotorSpec(body1="a", axes=[0, 0, 0]))
    with pytest.raises(InvalidArgument):
        core.add_motor(MotorSpec(body1="a", axes=[0, 0, 1], axis_frames=[2]))  # body2 is the world
    with pytest.raises(InvalidArgument):
        core.add_motor(MotorSpec(body1="a", axes=[0, 0, 1] * 4))
    with pytest.raises(InvalidArgument):
        core.add_motor(MotorSpec(body1="a", kind=7, axes=[0, 0, 1]))
    with pytest.raises(InvalidArgument):
        core.add_motor(MotorSpec())
    with pytest.raises(UnknownName):
        core.set_velocity(motors=["motor:1:a&b", "nope"], velocities=[1.0, 1.0])
    with pytest.raises(InvalidArgument):
        core.set_velocity(motors=["motor:1:a&b"], velocities=[1.0, 2.0])
    with pytest.raises(InvalidArgument):
        core.set_velocity(motors=["motor:1:a&b"], velocities=[NAN])
    assert snapshot(core) == before
    assert core.motor_goals()["motor:1:a&b"] == [0.0]
    core.build_object(ObjectSpec("c", [0.1], position=(2, 0, 1)))
    ball = core.add_joint(JointSpec(vc.BALL, "c", ""))
    with pytest.raises(Unsupported):
        core.add_motor(MotorSpec(joint=ball))  # a ball has no axes of its own
    assert core.add_motor(MotorSpec(joint=ball, axes=[1, 0, 0, 0, 1, 0])) == f"motor:{ball}"


def test_bad_forces(core):
    before = snapshot(core)
    with pytest.raises(UnknownName):
        core.add_body_force("nope", vc.FORCE, (1, 0, 0))
    with pytest.raises(Unsupported):
        core.add_body_force("wall", vc.FORCE, (1, 0, 0))
    with pytest.raises(InvalidArgument):
        core.add_body_force("a", 5, (1, 0, 0))
    with pytest.raises(InvalidArgument):
        core.add_body_force("a", vc.FORCE, (1, NAN, 0))
    with pytest.raises(InvalidArgument):
        core.add_body_force("a", vc.TORQUE, (1, 0, 0), at_point=True)
    with pytest.raises(InvalidArgument):
        core.add_joint_force("1:a&b", [1.0, 2.0])
    with pytest.raises(UnknownName):
        core.add_joint_force("nope", [1.0])
    with pytest.raises(UnknownName):
        core.remove_body_force("force:a:7")
    with pytest.raises(UnknownName):
        core.remove_joint_force("jointforce:x:0")
    assert snapshot(core) == before
    core.build_object(ObjectSpec("c", [0.1], position=(2, 0, 1)))
    fixed = core.add_joint(JointSpec(vc.FIXED, "c", ""))
    with pytest.raises(Unsupported):
        core.add_joint_force(fixed, [1.0])


def test_force_ids_take_the_first_free_number(core):
    assert core.add_body_force("a", vc.FORCE, (0, 0, 1)) == "force:a:1"
    core.remove_body_force("force:a:0")
    assert core.add_body_force("a", vc.FORCE, (0, 0, 1)) == "force:a:0"
    assert core.add_joint_force("1:a&b", [0.2]) == "jointforce:1:a&b:1"


def test_bad_poses_and_velocities_change_nothing(core):
    before = snapshot(core)
    good = ("a", (0, 0, 3), (1, 0, 0, 0))
    for bad in [("nope", (0, 0, 0), (1, 0, 0, 0)), ("b", (0, 0, NAN), (1, 0, 0, 0)),
                ("b", (0, 0, 0), (0, 0, 0, 0)), ("b", (0, 0, 0), (2, 0, 0, 0)), ("b",)]:
        with pytest.raises(CoreError):
            core.set_poses([good, bad])
    with pytest.raises(InvalidArgument):
        core.set_velocity("a", linear=(INF, 0, 0))
    with pytest.raises(Unsupported):
        core.set_velocity("wall", linear=(1, 0, 0))
    assert snapshot(core) == before


def test_bad_steps_and_removals(core):
    before = snapshot(core)
    for args in [(0.0,), (-1e-3,), (NAN,), (1e-3, 0), (1e-3, 1.5), (1e-3, True)]:
        with pytest.raises(InvalidArgument):
            core.step(*args)
    for call in (core.remove_object, core.remove_joint, core.remove_motor, core.geometry_names):
        with pytest.raises(UnknownName):
            call("nope")
    assert snapshot(core) == before
    assert core.sim_time == 0.0


@pytest.mark.parametrize("changes", [
    dict(erp=1.5), dict(cfm=-1), dict(gravity=(0, 0)), dict(gravity=(0, 0, NAN)),
    dict(max_contacts=0), dict(max_contacts=65), dict(max_contacts=2.5), dict(solver=3),
    dict(quickstep_iterations=0), dict(bounce=2), dict(contact_less="no"), dict(nope=1),
    dict(linear_damping=-0.1), dict(friction=NAN), dict(erp=0.5, cfm=-1),
    dict(collision_mesh_tolerance=-0.001), dict(collision_mesh_tolerance=4.0),
])
def test_bad_world_parameters(core, changes):
    before = core.world_parameters
    with pytest.raises(InvalidArgument):
        core.set_world_parameters(**changes)
    assert core.world_parameters == before


def test_world_parameters_apply(core):
    p = core.set_world_parameters(gravity=(0, 0, -1), erp=0.5, friction=-1,
                                  max_angular_speed=0, contact_less=True)
    assert p.gravity == (0.0, 0.0, -1.0) and p.contact_less and p.erp == 0.5
    assert core._scene.c.struct.mu == math.inf and core._scene.c.struct.contact_less == 1


def test_closed_core_refuses_calls():
    c = Core()
    c.close()
    c.close()
    with pytest.raises(Closed):
        c.build_object(ObjectSpec("x", [0.1]))
    with pytest.raises(Closed):
        c.step(0.001)
