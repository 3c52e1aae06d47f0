"""The Core back end's propagation (gui.planning.backend.CoreBackend: Core.propagate_state,
one C call per propagation step) against the Core's general path as run_path drives a control
row (put the state vector back, read the base, set the servos, one kept Propagate with the
row's forces, read the tracked link and the state vector): for random (state, control) pairs
on Kautham's Sphere demo and on the car, the same states, tracked positions and velocities,
pairs and forbidden-contact verdicts, bit for bit."""
import numpy as np
import pytest

from gui.planning.backend import CoreBackend, Outcome, step_actuation
from gui.planning.core_world import CoreWorld
from gui.planning.problem import planning_problem
from gui_core_world import quiet_plan

SPHERE = ("current_2025", "demos", "OMPL_ode_demos", "Sphere", "Sphere.xml")
CAR = ("demos", "OMPL_ode_demos", "Car", "k-PMPCar.xml")


class GeneralPathBackend:
    """The problem's world in a Core of its own, each propagation step made of the Core's
    general requests, as run_path runs a control row on a world."""

    def __init__(self, built, problem):
        self.problem = problem
        self.world = CoreWorld()
        self.world.execute(built)

    def propagate_one(self, state, control) -> Outcome:
        core, problem = self.world.core, self.problem
        core.set_body_state_vector(state)
        act = step_actuation(problem, control, self.world.body_state(problem.base_body))
        if act.servo is not None:
            self.world.set_servo(act.servo)
        collisions = self.world.advance(problem.step, act.forces)
        position, quaternion, linear, _ = core.body_state(problem.tracked_body)
        return Outcome(core.body_state_vector(), problem.tracked_origin(position, quaternion),
                       np.asarray(linear), tuple((c.first, c.second) for c in collisions))

    def close(self) -> None:
        self.world.close()


@pytest.fixture(params=["sphere", "car"])
def built(request, kautham_dir, ode_demos_dir):
    if request.param == "sphere":
        return quiet_plan(kautham_dir.joinpath(*SPHERE))
    return quiet_plan(ode_demos_dir.joinpath(*CAR))


def test_the_one_call_propagation_is_bit_for_bit_the_general_path(built):
    fast = CoreBackend(built, planning_problem(built))
    general = GeneralPathBackend(built, planning_problem(built))
    problem = fast.problem
    rng = np.random.default_rng(11)
    try:
        states = [fast.start_state()]
        verdicts = set()
        for k in range(120):
            state = states[rng.integers(len(states))]
            control = tuple(float(v) for v in rng.random(problem.control_size))
            # a planner holds a control for several steps: the fast path then sends its
            # servos once; the general path sends them every step
            for _ in range(1 + k % 3):
                mine = fast.propagate([(state, control)])[0]
                theirs = general.propagate_one(state, control)
                assert mine.state.tobytes() == theirs.state.tobytes(), (k, control)
                assert mine.position.tobytes() == theirs.position.tobytes(), k
                assert mine.velocity.tobytes() == theirs.velocity.tobytes(), k
                assert mine.collisions == theirs.collisions, k
                forbidden = problem.forbidden_contacts(mine.collisions)
                assert forbidden == problem.forbidden_contacts(theirs.collisions)
                verdicts.add(bool(forbidden))
                state = mine.state
            states.append(state)
            tracked = fast.tracked_state(state)
            assert tracked[0].tobytes() == mine.position.tobytes()
            assert tracked[1].tobytes() == mine.velocity.tobytes()
        assert len({s.tobytes() for s in states}) > 100     # the pairs went places
        assert False in verdicts
    finally:
        fast.close()
        general.close()


def test_a_bad_state_is_refused_before_the_servos_change(ode_demos_dir):
    from virtual_world.errors import InvalidArgument
    built = quiet_plan(ode_demos_dir.joinpath(*CAR))
    backend = CoreBackend(built, planning_problem(built))
    try:
        core = backend.world.core
        servos = core.servo_states()
        before = core.body_state_vector()
        for bad in (np.zeros(5), np.full(before.size, np.inf)):
            with pytest.raises(InvalidArgument):
                backend.propagate([(bad, (0.9, 0.9))])
            assert core.servo_states() == servos
            assert core.body_state_vector().tobytes() == before.tobytes()
    finally:
        backend.close()


CHAIN = ("demos", "OMPL_ode_demos", "Chain", "k-PMPChain.xml")


@pytest.fixture(params=["sphere", "car", "chain"])
def any_built(request, kautham_dir, ode_demos_dir):
    if request.param == "sphere":
        return request.param, quiet_plan(kautham_dir.joinpath(*SPHERE))
    return request.param, quiet_plan(ode_demos_dir.joinpath(
        *(CAR if request.param == "car" else CHAIN)))


def test_a_step_judged_in_c_is_the_step_and_the_rule_judged_in_python(any_built):
    """CoreBackend.propagate_into (the search's step: one C call that also judges the state,
    issue 42) against propagate and the problem's rule in Python (forbidden_contacts,
    in_bounds), on the Sphere, the car and the held chain (its tool may push boxes, its
    other links may not; its tracked link is off its body's origin): the same state and
    tracked link bit for bit, and the same verdict."""
    name, built = any_built
    backend = CoreBackend(built, planning_problem(built))
    problem = backend.problem
    rng = np.random.default_rng(5)
    size = backend.start_state().size
    try:
        states, verdicts = [backend.start_state()], []
        for k in range(100):
            state = states[rng.integers(len(states))]
            control = tuple(float(v) for v in rng.random(problem.control_size))
            for _ in range(1 + k % 20):
                into, tracked = np.full((1, size + 1), np.nan), np.full((1, 6), np.nan)
                backend.propagate_into(state, control, into, tracked)
                mine = backend.propagate([(state, control)])[0]
                assert into[0, :-1].tobytes() == mine.state.tobytes(), k
                assert tracked[0].tobytes() == np.concatenate(
                    [mine.position, mine.velocity]).tobytes(), k
                invalid = bool(problem.forbidden_contacts(mine.collisions)) or \
                    not problem.in_bounds(mine.position, mine.velocity)
                assert into[0, -1] == float(invalid), (k, mine.collisions)
                verdicts.append(invalid)
                if invalid:
                    break                       # as OMPL's propagateWhileValid
                state = mine.state
            states.append(state)
        assert False in verdicts
        if name != "car":                       # the ball and the chain's links hit walls
            assert True in verdicts             # (the car's are further than it goes)
    finally:
        backend.close()
