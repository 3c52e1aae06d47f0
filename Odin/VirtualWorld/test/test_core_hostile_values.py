"""No accepted request can make ODE end the process: every physical quantity a request sets is
checked against the others before ODE sees it. A property test over the whole float range
(NaN, infinities, 1e-320 .. 1e308 of either sign) builds bodies, joints, motors and forces
through the Core and steps: each request is either refused (an OdinError: nothing changed) or
accepted, and the world then steps and propagates without dying.

ODE aborts the process on what it cannot integrate (``dxNormalize4``'s assertion), which no
``pytest.raises`` can catch: the whole property test runs in one child process, whose exit
status is the verdict. Each example is written to the child's stderr before it runs, so an
abort names the values that caused it."""
import os
import subprocess
import sys
import textwrap

import pytest

CHILD = textwrap.dedent(r'''
    import math, sys
    from odin_common.blas import use_reference_blas; use_reference_blas()  # before numpy
    from hypothesis import HealthCheck, given, settings, strategies as st
    from odin_common.errors import OdinError
    from odin_common.interface import JointParameter, JointType
    from virtual_world.core import Core, JointSpec, MotorSpec, ObjectSpec, WorldParameters

    def magnitudes():
        """Log-uniform 1e-320 .. 1e308 of either sign, with 0."""
        return st.builds(lambda e, sign: sign * 10.0 ** e, st.floats(-320, 308),
                         st.sampled_from([1.0, -1.0]))

    HOSTILE = st.one_of(st.floats(allow_nan=True, allow_infinity=True), magnitudes())
    FIELDS = ["size", "mass", "inertia", "com", "position", "velocity", "spin", "force",
              "point", "anchor", "axis", "joint value", "max force", "goal", "joint force",
              "gravity", "angular cap", "step", "duration"]

    class Values:
        """Sane values but for 1..3 fields of the example, drawn over the whole range."""
        def __init__(self, draw):
            self.draw = draw
            self.hostile = set(draw(st.lists(st.sampled_from(FIELDS), min_size=1,
                                             max_size=3)))

        def __call__(self, field, sane, n=None):
            values = HOSTILE if field in self.hostile else sane
            if n is None:
                return self.draw(values)
            return [self.draw(values) for _ in range(n)]

    SIZE = st.floats(0.01, 2.0)
    SMALL = st.floats(-1.0, 1.0)
    SHAPES = st.sampled_from([(1, 0), (2, 0), (3, 0), (2, 5)])   # parameter count, shape

    def body(draw, v, name, at):
        count, shape = draw(SHAPES)
        inertia = ()
        if draw(st.booleans()) or "inertia" in v.hostile:
            inertia = v("inertia", st.floats(0.05, 0.2), 3) + v("inertia", SMALL.map(
                lambda x: x / 100), 3)
        com = v("com", SMALL.map(lambda x: x / 10), 3) if inertia and draw(st.booleans()) \
            else ()
        return ObjectSpec(name, v("size", SIZE, count), mass=v("mass", st.floats(0.1, 10.0)),
                          inertia=inertia, center_of_mass=com,
                          position=[p + d for p, d in zip(at, v("position", SMALL, 3))],
                          shape=shape)

    def attempt(label, call, *args, **kwargs):
        print("  ", label, args, kwargs, file=sys.stderr, flush=True)
        try:
            return call(*args, **kwargs)
        except OdinError:
            return None

    CORE = Core()

    @settings(max_examples=int(sys.argv[1]), derandomize=True, deadline=None, database=None,
              suppress_health_check=list(HealthCheck))
    @given(st.data())
    def run(data):
        draw = data.draw
        v = Values(draw)
        core = CORE
        core.new_scene()
        print("example", sorted(v.hostile), file=sys.stderr, flush=True)
        attempt("world", core.set_world_parameters,
                gravity=tuple(v("gravity", st.floats(-20, 20), 3)),
                max_angular_speed=v("angular cap", st.sampled_from([0.0, 100.0])))
        built = [attempt("build", core.build_object, body(draw, v, n, at))
                 for n, at in (("a", (0.0, 0.0, 0.0)), ("b", (0.0, 0.0, 3.0)))]
        names = [b.id for b in built if b is not None]
        if not names:
            return
        a = names[0]
        attempt("velocity", core.set_velocity, a, v("velocity", st.floats(-10, 10), 3),
                v("spin", st.floats(-10, 10), 3))
        attempt("force", core.add_body_force, a, draw(st.sampled_from([0, 1])),
                v("force", st.floats(-100, 100), 3), False, draw(st.booleans()),
                v("point", SMALL, 3))
        joint = attempt("joint", core.add_joint, JointSpec(
            draw(st.sampled_from(list(JointType))), a, names[1] if len(names) > 1 else "",
            v("anchor", SMALL, 3), v("axis", SMALL, 3),
            parameters=[(draw(st.sampled_from(list(JointParameter))), 1,
                         v("joint value", st.floats(-2, 2)))
                        for _ in range(draw(st.integers(0, 3)))]))
        if joint is not None:
            motor = attempt("motor", core.add_motor, MotorSpec(
                joint=joint, max_forces=[v("max force", st.floats(0, 100))]))
            if motor is not None:
                attempt("goal", core.set_velocity, motors=[motor],
                        velocities=[v("goal", SMALL)])
            attempt("joint force", core.add_joint_force, joint, [v("joint force", SMALL)])
        step = v("step", st.sampled_from([1e-3, 1e-2, 1e-4]))
        for _ in range(3):
            attempt("step", core.step, step, 10)
        attempt("propagate", core.propagate, v("duration", st.floats(1e-3, 0.05)), step,
                keep=True)
        attempt("step", core.step, 1e-3, 20)

    run()
    print("survived", file=sys.stderr, flush=True)
''')


def _run_child(examples: int) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", CHILD, str(examples)], capture_output=True,
                          text=True, timeout=300, env=dict(os.environ))


def test_no_accepted_request_over_the_whole_float_range_makes_ode_end_the_process():
    """Bodies (any shape's dimensions, masses, inertias, centres of mass, positions),
    velocities, forces, joints with their parameters, motors, joint forces, gravity, the step
    size and a propagation's duration, drawn over the whole float range: the child process
    that builds and steps them all exits 0 (an ODE abort exits with SIGABRT)."""
    done = _run_child(1500)
    tail = "\n".join(done.stderr.splitlines()[-40:])
    assert done.returncode == 0, f"the child died ({done.returncode}); last requests:\n{tail}"
    assert "survived" in done.stderr


@pytest.mark.parametrize("inertia", [1e200, 1e308, 3e40])
def test_an_inertia_far_too_heavy_for_its_mass_and_size_is_refused(inertia):
    """1 kg of a 0.2 m sphere given principal moments of ``inertia`` kg m^2 (ODE aborted at
    the first step with 1e200): refused naming the bound, and nothing is built."""
    from virtual_world.core import Core, ObjectSpec
    from virtual_world.errors import InvalidArgument
    with Core() as core:
        with pytest.raises(InvalidArgument, match="inertia.*(MAX_INERTIA|MAX_GYRATION_MULTIPLE)"):
            core.build_object(ObjectSpec("heavy", [0.2], mass=1.0,
                                         inertia=[inertia, inertia, inertia, 0.0, 0.0, 0.0]))
        assert core.object_ids() == []


def test_a_heavy_inertia_that_a_body_can_have_is_accepted():
    """A 2 kg, 1 m box given 9 times its uniform inertia (a radius of gyration 3 times the
    uniform one, mass near its corners) is within MAX_GYRATION_MULTIPLE: accepted."""
    from virtual_world.core import Core, ObjectSpec
    with Core() as core:
        uniform = 2.0 * (1.0 + 1.0) / 12.0
        core.build_object(ObjectSpec("box", [1.0, 1.0, 1.0], mass=2.0,
                                     inertia=[9 * uniform] * 3 + [0.0, 0.0, 0.0]))
        core.step(1e-3, 10)


STOP_AND_UNLIMITED_FORCE = textwrap.dedent(r'''
    from odin_common.blas import use_reference_blas; use_reference_blas()
    from odin_common.interface import JointParameter as P, JointType as J
    from virtual_world.core import Core, JointSpec, MotorSpec, ObjectSpec
    core = Core()
    core.build_object(ObjectSpec("arm", [0.2, 0.3], mass=0.5, position=(0.3, 0.0, 0.0)))
    core.build_object(ObjectSpec("hub", [0.3], mass=4.0, position=(-0.3, 0.0, 0.0)))
    core.set_velocity("arm", (0.0, 2.0, 0.0), (0.0, 0.0, 5.0))
    if "joint" in __import__("sys").argv:    # the joint's own motor, unlimited, past a stop
        core.add_joint(JointSpec(J.HINGE, "arm", "hub", axis1=(0.0, 0.0, 1.0),
                                 parameters=[(P.LO_STOP, 1, 0.3), (P.MAX_FORCE, 1, -2.0)]))
    else:                                     # a motor of unlimited force given a stop
        motor = core.add_motor(MotorSpec(body1="arm", body2="hub", axes=[0.0, 0.0, 1.0]))
        core.set_joint_parameters(motor, [(P.HI_STOP, 1, -0.2)])
    core.step(0.002, 50)
    print("stepped", core.state()[2])
''')


@pytest.mark.parametrize("where", ["joint", "motor"])
def test_an_unlimited_motor_force_on_an_axis_past_its_stop_steps(where):
    """A joint's own motor whose MAX_FORCE is negative (unlimited), or a motor of unlimited
    force (its default), on an axis beyond a stop: ODE applies the whole maximum force to the
    bodies there, and ODE's infinity made them NaN and ended the process. An unlimited force
    is given to ODE as MAX_FORCE: the world steps, and still reads it as infinite."""
    done = subprocess.run([sys.executable, "-c", STOP_AND_UNLIMITED_FORCE, where],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr[-2000:]
    assert "stepped" in done.stdout
    if where == "motor":
        assert "max_forces=(inf,)" in done.stdout


def test_an_unlimited_force_is_odes_infinity_until_its_axis_has_a_stop():
    """Where no stop can be met, ODE keeps its own infinity (the unbounded solver row every
    scene without stops has always stepped: the thesis's grasp and pile experiments moved
    when it was replaced by a finite force everywhere); a finite stop, set before or after,
    makes it UNLIMITED_FORCE, and the stop taken away makes it ODE's infinity again. A client
    reads infinity throughout."""
    import math
    from odin_common.interface import JointParameter as P
    from virtual_world.core import Core, MotorSpec, ObjectSpec
    from virtual_world.ode import joints as ode_joints
    with Core() as core:
        core.build_object(ObjectSpec("arm", [0.2, 0.3], mass=0.5, position=(0.3, 0.0, 0.0)))
        core.build_object(ObjectSpec("hub", [0.3], mass=4.0, position=(-0.3, 0.0, 0.0)))
        motor = core.add_motor(MotorSpec(body1="arm", body2="hub", axes=[0.0, 0.0, 1.0]))
        record = core._scene.motors[motor]

        def held() -> float:
            return ode_joints.motor_parameter(record.owner.ptr, record.kind, P.MAX_FORCE, 1)
        assert held() == math.inf
        core.set_joint_parameters(motor, [(P.HI_STOP, 1, 0.5)])
        assert held() == ode_joints.UNLIMITED_FORCE
        assert math.isfinite(held()) and held() > 1e7
        core.set_joint_parameters(motor, [(P.HI_STOP, 1, math.inf)])
        assert held() == math.inf
        core.set_joint_parameters(motor, [(P.MAX_FORCE, 1, 1e7)])
        core.set_joint_parameters(motor, [(P.LO_STOP, 1, -0.5)])
        assert held() == 1e7        # a limited force is what was asked, stop or none
        core.set_joint_parameters(motor, [(P.MAX_FORCE, 1, -1.0)])
        assert held() == ode_joints.UNLIMITED_FORCE
        assert core.state()[2][0].max_forces == (math.inf,)
