"""odin_common's interface facts are pinned to the .msg/.srv files they describe: every
constant to the generated message classes, the service tables to the .srv files, the world
parameters to Set World's fields. (Needs the generated classes, not a master.)"""
import pathlib

import pytest

from Messages import msg
from Services import srv
from odin_common import interface, world_parameters
from odin_common.interface import (AxisFrame, ForceKind, JointParameter, JointType, MotorKind,
                                   ServoDrive, SetJointAction, Shape, Solver)

SRV_DIR = pathlib.Path(__file__).resolve().parents[2] / "Services" / "srv"

PINS = [
    (JointType, msg.Joint),
    (JointParameter, msg.JointParameter),
    (SetJointAction, srv.SetJointRequest),
    (MotorKind, srv.SetMotorRequest),
    (AxisFrame, srv.SetMotorRequest),
    (ForceKind, srv.SetExternalForceRequest),
    (ForceKind, msg.BodyForce),
    (Shape, msg.Object),
    (Solver, srv.SetWorldRequest),
    (ServoDrive, srv.SetServoRequest),
]


@pytest.mark.parametrize("enum,generated", PINS, ids=lambda x: getattr(x, "__name__", x))
def test_every_enum_member_is_the_constant_of_its_message(enum, generated):
    for member in enum:
        assert getattr(generated, member.name) == member.value, (enum.__name__, member.name)


def test_the_message_defines_no_constant_the_enum_lacks():
    for enum, generated in [(JointType, msg.Joint), (JointParameter, msg.JointParameter),
                            (SetJointAction, srv.SetJointRequest),
                            (ServoDrive, srv.SetServoRequest)]:
        constants = {name for name in dir(generated) if name.isupper() and
                     isinstance(getattr(generated, name), int)}
        assert constants == {m.name for m in enum}, enum.__name__


def test_the_service_tables_name_every_srv_file_once():
    world = set(interface.WORLD_SERVICES.values())
    viewer = set(interface.VIEWER_SERVICES.values())
    files = {p.stem for p in SRV_DIR.glob("*.srv")}
    assert world.isdisjoint(viewer)
    assert world | viewer == files
    for type_name in world | viewer:
        assert hasattr(srv, type_name)


def test_world_parameters_are_set_worlds_fields_in_order():
    fields = srv.SetWorldRequest.__slots__
    values = [name for name in fields if not name.startswith("set_")]
    assert values == [p.name for p in world_parameters.PARAMETERS]
    flags = [name for name in fields if name.startswith("set_")]
    assert flags == list(world_parameters.set_world_flags())
    assert list(srv.SetWorldResponse.__slots__[2:]) == values


def test_the_world_parameters_message_holds_every_parameter_in_order():
    assert list(msg.WorldParameters.__slots__) == [p.name for p in world_parameters.PARAMETERS]


def test_the_spec_message_conversions_round_trip():
    from odin_common import messages
    parameters = world_parameters.WorldParameters(gravity=(0, 0, -1.0), erp=0.3, solver=1)
    assert messages.world_parameters_of(messages.world_parameters_message(parameters)) == \
        parameters


def test_a_surface_survives_the_round_trip_through_its_message():
    import math
    from odin_common import messages
    from odin_common.specs import Surface
    for surface in (Surface(), Surface(friction=math.inf, bounce=0.4, bounce_velocity=0.2),
                    Surface(friction=0.3, friction2=0.1, friction_direction=(0.0, 1.0, 0.0),
                            stiffness=1e5, damping=30.0)):
        assert messages.surface_of(messages.surface_message(surface)) == surface


def test_every_parameter_has_a_default_and_the_defaults_are_valid():
    defaults = world_parameters.WorldParameters()
    defaults.validate()
    for info in world_parameters.PARAMETERS:
        assert hasattr(defaults, info.name)
        world_parameters.check_value(info, world_parameters.default(info.name))


def test_joint_tables_cover_every_joint_type():
    assert set(interface.JOINT_AXES_USED) == set(JointType)
    assert set(interface.JOINT_PARAMETERS) == set(JointType) - {JointType.PLANE2D}
    assert set(interface.JOINT_PARAMETER_AXES) == set(interface.JOINT_PARAMETERS)
    assert set(interface.JOINT_FORCE_MAGNITUDES) == set(JointType) - {JointType.FIXED,
                                                                     JointType.PLANE2D}
