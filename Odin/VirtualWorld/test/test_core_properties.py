"""Property-based tests of the Core's requests (hypothesis): any sequence of requests, valid,
extreme or malformed, either works or raises one of the Core's own errors; it never ends the
process, never leaves a non-finite pose behind, and never leaves the world in a state that a
later valid call cannot use.

The machine runs in a forked child (pytest.mark.forked): should ODE ever abort, the test fails
with the child's status instead of taking the whole run down. Numbers are drawn from ranges that
straddle odin_common.limits, plus the values that break naive code (0, -0, inf, nan, 1e300).
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, settings, strategies as st
from hypothesis.stateful import RuleBasedStateMachine, invariant, precondition, rule

from odin_common.interface import JointType, MotorKind, Shape
from odin_common.specs import Surface
from virtual_world.core import (CompositeSpec, Core, JointSpec, MotorSpec, ObjectSpec,
                                PartSpec)
from virtual_world.errors import CoreError

pytestmark = pytest.mark.forked

NASTY = st.sampled_from([0.0, -0.0, 1e-12, -1.0, 1e300, -1e300, math.inf, -math.inf, math.nan])
SIZE = st.one_of(st.floats(0.01, 2.0), NASTY)
COORD = st.one_of(st.floats(-20.0, 20.0), NASTY)
VECTOR = st.lists(COORD, min_size=0, max_size=4)
UNIT_QUATERNION = st.sampled_from([(1, 0, 0, 0), (0, 1, 0, 0), (0.5, 0.5, 0.5, 0.5)])
QUATERNION = st.one_of(UNIT_QUATERNION, st.lists(COORD, min_size=3, max_size=5))
MAGNITUDE = st.one_of(st.floats(-100.0, 100.0), NASTY)
NAMES = st.sampled_from(["a", "b", "c", "d", "", "a/b", "x" * 300])
SHAPE = st.sampled_from([Shape.BY_COUNT, Shape.CAPSULE, Shape.PLANE, 99])
TETRAHEDRON = ([0, 0, 0, 0.3, 0, 0, 0, 0.3, 0, 0, 0, 0.3], [0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3])


@st.composite
def surfaces(draw):
    if draw(st.booleans()):
        return Surface()
    return Surface(friction=draw(st.one_of(st.none(), MAGNITUDE)),
                   friction2=draw(st.one_of(st.none(), MAGNITUDE)),
                   friction_direction=tuple(draw(st.lists(COORD, min_size=3, max_size=3))),
                   bounce=draw(st.one_of(st.none(), st.floats(-1, 2), NASTY)),
                   stiffness=draw(st.one_of(st.none(), MAGNITUDE)),
                   damping=draw(MAGNITUDE))


@st.composite
def object_specs(draw, name):
    kind = draw(st.sampled_from(["sphere", "box", "cylinder", "mesh", "odd"]))
    parameters = {"sphere": [draw(SIZE)], "box": [draw(SIZE) for _ in range(3)],
                  "cylinder": [draw(SIZE), draw(SIZE)], "mesh": TETRAHEDRON[0],
                  "odd": draw(st.lists(SIZE, max_size=7))}[kind]
    indices = TETRAHEDRON[1] if kind == "mesh" else draw(st.sampled_from([(), (0, 1, 2)]))
    return ObjectSpec(name, parameters, indices=indices,
                      mass=draw(st.one_of(st.floats(0.01, 100.0), NASTY)),
                      position=tuple(draw(st.one_of(st.lists(st.floats(-5, 5), min_size=3,
                                                             max_size=3), VECTOR))),
                      orientation=tuple(draw(QUATERNION)),
                      fixed=draw(st.booleans()), geometry_only=draw(st.booleans()),
                      no_collisions=draw(st.booleans()), shape=draw(SHAPE),
                      surface=draw(surfaces()))


class CoreRequests(RuleBasedStateMachine):
    """Requests in any order; each either works or raises a CoreError."""

    def __init__(self):
        super().__init__()
        self.core = Core()

    def attempt(self, call, *args, **kwargs):
        try:
            return call(*args, **kwargs)
        except CoreError as error:
            assert str(error), "an error must say what went wrong"
            return None

    # ------------------------------------------------------------ building

    @rule(name=NAMES, data=st.data())
    def build_object(self, name, data):
        self.attempt(self.core.build_object, data.draw(object_specs(name)))

    @rule(name=NAMES, sizes=st.lists(SIZE, min_size=1, max_size=3),
          offset=st.lists(COORD, min_size=3, max_size=3), position=VECTOR)
    def build_composite(self, name, sizes, offset, position):
        parts = [PartSpec(f"{name}{i}", [size], position=tuple(offset) if i else (0, 0, 0))
                 for i, size in enumerate(sizes)]
        self.attempt(self.core.build_composite, CompositeSpec(parts, position=tuple(position)))

    @rule(name=NAMES)
    def remove_object(self, name):
        self.attempt(self.core.remove_object, name)

    @rule(joint_type=st.sampled_from(list(JointType) + [0, 42]), body1=NAMES, body2=NAMES,
          anchor=VECTOR, axis1=VECTOR, axis2=VECTOR)
    def create_joint(self, joint_type, body1, body2, anchor, axis1, axis2):
        self.attempt(self.core.add_joint, JointSpec(joint_type, body1, body2, tuple(anchor),
                                                    tuple(axis1), tuple(axis2)))

    @precondition(lambda self: self.core.joint_ids())
    @rule(data=st.data(), kind=st.sampled_from(list(MotorKind) + [7]),
          forces=st.lists(MAGNITUDE, max_size=3))
    def create_motor(self, data, kind, forces):
        joint = data.draw(st.sampled_from(self.core.joint_ids()))
        self.attempt(self.core.add_motor, MotorSpec(joint=joint, kind=kind, max_forces=forces))

    @precondition(lambda self: self.core.motor_ids())
    @rule(data=st.data(), values=st.lists(MAGNITUDE, max_size=3))
    def drive_motor(self, data, values):
        motor = data.draw(st.sampled_from(self.core.motor_ids()))
        if data.draw(st.booleans()):
            self.attempt(self.core.set_velocity, motors=[motor], velocities=values)
        else:
            self.attempt(self.core.set_servo, [motor], values)

    @precondition(lambda self: self.core.joint_ids())
    @rule(data=st.data(), values=st.lists(MAGNITUDE, max_size=3))
    def joint_force(self, data, values):
        joint = data.draw(st.sampled_from(self.core.joint_ids()))
        self.attempt(self.core.add_joint_force, joint, values)

    # ------------------------------------------------------------ moving things

    @rule(name=NAMES, kind=st.integers(-1, 3), vector=VECTOR, point=VECTOR)
    def body_force(self, name, kind, vector, point):
        self.attempt(self.core.add_body_force, name, kind, vector, at_point=bool(point),
                     point=point or (0.0, 0.0, 0.0))

    @rule(name=NAMES, linear=VECTOR, angular=VECTOR)
    def set_velocity(self, name, linear, angular):
        self.attempt(self.core.set_velocity, name, linear=linear, angular=angular)

    @rule(name=NAMES, position=VECTOR, orientation=QUATERNION)
    def set_pose(self, name, position, orientation):
        self.attempt(self.core.set_poses, [(name, position, orientation)])

    @rule(name=NAMES, surface=surfaces())
    def set_surface(self, name, surface):
        self.attempt(self.core.set_surface, name, surface)

    @rule(gravity=st.lists(MAGNITUDE, min_size=3, max_size=3), erp=MAGNITUDE, cfm=MAGNITUDE)
    def set_world(self, gravity, erp, cfm):
        self.attempt(self.core.set_world_parameters, gravity=tuple(gravity))
        self.attempt(self.core.set_world_parameters, erp=erp, cfm=cfm)

    @rule(step=st.one_of(st.floats(1e-4, 0.02), NASTY), count=st.integers(-1, 40))
    def step(self, step, count):
        self.attempt(self.core.step, step, count)

    # ------------------------------------------------------------ planning

    @rule(name=NAMES)
    def save_state(self, name):
        self.attempt(self.core.save_state, name)

    @rule(name=NAMES)
    def restore_state(self, name):
        self.attempt(self.core.restore_state, name)

    @rule(duration=st.one_of(st.floats(0, 0.05), NASTY), step=st.one_of(st.floats(1e-4, 0.01),
                                                                        NASTY))
    def propagate(self, duration, step):
        self.attempt(self.core.propagate, duration, step)

    @rule(data=st.data(), duration=st.one_of(st.floats(0, 0.05), NASTY),
          step=st.one_of(st.floats(1e-4, 0.01), NASTY), name=NAMES, force=VECTOR)
    def propagate_state(self, data, duration, step, name, force):
        """From this world's vector, one with a value broken, or one of another size."""
        vector = self.core.body_state_vector()
        change = data.draw(st.sampled_from(["none", "value", "size"]))
        if change == "value" and vector.size:
            vector[data.draw(st.integers(0, vector.size - 1))] = data.draw(NASTY)
        elif change == "size":
            vector = np.append(vector, 0.0)
        pushes = data.draw(st.sampled_from([(), ((name, force),), ((name,),)]))
        self.attempt(self.core.propagate_state, vector, duration, step, pushes)

    @rule(name=NAMES, position=VECTOR)
    def check_collision(self, name, position):
        self.attempt(self.core.check_collision, [(name, position, (1, 0, 0, 0))])

    @rule()
    def reset(self):
        self.attempt(self.core.reset)

    @rule()
    def new_scene(self):
        self.core.new_scene()

    # ------------------------------------------------------------ what must always hold

    @invariant()
    def poses_are_finite(self):
        _, positions, quaternions = self.core.poses()
        assert np.all(np.isfinite(positions)) and np.all(np.isfinite(quaternions))

    def teardown(self):
        # whatever came before, a valid scene still builds and steps
        core = self.core
        core.new_scene()
        core.set_world_parameters(gravity=(0.0, 0.0, -9.81), erp=0.2, cfm=1e-5)
        core.build_object(ObjectSpec("probe", [0.1], position=(0, 0, 1)))
        core.step(0.001, 10)
        assert core.body_state("probe")[0][2] < 1.0
        core.close()


CoreRequests.TestCase.settings = settings(
    max_examples=150, stateful_step_count=30, deadline=None, derandomize=True,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
test_core_requests_never_break_the_world = CoreRequests.TestCase
