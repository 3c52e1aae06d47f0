"""Benchmarks of physics-based planning (issue 17: OMPL's control planners through Odin).

  plan_sphere_success       fraction of SEEDS seeds (1..SEEDS) for which KPIECE1 solves the
                            Sphere demo's query within TIME_S s of wall clock (Core back end).
                            OMPL seeds its generators once per process: each seed in a
                            process of its own.
  plan_sphere_median_s      median wall-clock seconds of the solved searches.
  propagations_per_s_core   propagation steps (one control path row, 0.03 s simulated) per
                            second of the Core back end: a batch of BATCH (state, control)
                            pairs from states along a path, random controls.
  propagations_per_s_pool   the same batch through a pool of 2 world nodes (fanned out, one
                            ROS round trip per step), and ..._pool1 through a pool of 1:
                            their ratio is plan_pool_speedup_2 (this machine's 2 cores).
  propagations_per_s_native the same batch through a plain ODE propagator written directly
                            against libode (native/plan_scene.c: the same bodies, forces and
                            step, no Odin), served to the planner the same way: the native
                            limit. plan_core_over_native: the Core's rate over it, side by side
                            in one process: the median of ROUNDS paired rounds' ratios (the
                            two batches of a round back to back, native first in even rounds),
                            as bench_core measures against native C; ..._native is the median
                            of the rounds' native rates.
  plan_sphere_native_solved KPIECE1 (seed 1, TIME_S) over the native propagator solves the
                            query too (1) or not (0): the native world is the same problem.
Needs the Kautham data (ODIN_KAUTHAM_DIR). ``ODIN_BENCH_PLAN_SEEDS`` runs fewer seeds,
``ODIN_BENCH_ROUNDS`` fewer paired rounds.
"""
import logging
import os
import pathlib
import statistics
import sys

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent.parent
sys.path.insert(0, str(HERE))

from forked import in_child  # noqa: E402
from odin_common.ros_master import RosMaster  # noqa: E402

SEEDS = int(os.environ.get("ODIN_BENCH_PLAN_SEEDS", 10))
TIME_S = 10.0
BATCH = 200
ROUNDS = int(os.environ.get("ODIN_BENCH_ROUNDS", 7))
SPHERE = ("current_2025", "demos", "OMPL_ode_demos", "Sphere", "Sphere.xml")


def _sphere():
    from gui.core.translate import plan_problem
    from gui.core.kautham.problem import load_problem
    from gui.planning.problem import planning_problem
    logging.disable(logging.WARNING)
    plan = plan_problem(load_problem(pathlib.Path(os.environ["ODIN_KAUTHAM_DIR"]).joinpath(
        *SPHERE)))
    return plan, planning_problem(plan)


def _solve(seed: int) -> dict:
    from gui.planning.backend import CoreBackend
    from gui.planning.bridge import plan
    backend = CoreBackend(*_sphere())
    try:
        result = plan(backend, "KPIECE1", TIME_S, seed)
        return {"solved": result.solved, "time_s": result.time_s}
    finally:
        backend.close()


def _batch(backend) -> list:
    """BATCH (state, control) pairs: states along a straight push, random planar controls."""
    import numpy as np
    rng = np.random.default_rng(1)
    states = [backend.start_state()]
    for _ in range(9):
        states.append(backend.propagate([(states[-1], (0.9, 0.3, 0.4))])[0].state)
    return [(states[k % len(states)], (rng.random(), rng.random(), 0.4)) for k in range(BATCH)]


def _rate(backend) -> float:
    import time
    requests = _batch(backend)
    backend.propagate(requests[:4])          # warm up: connections, caches
    started = time.perf_counter()
    backend.propagate(requests)
    return BATCH / (time.perf_counter() - started)


def _core_rate() -> dict:
    from gui.planning.backend import CoreBackend
    backend = CoreBackend(*_sphere())
    try:
        return {"per_s": _rate(backend)}
    finally:
        backend.close()


class NativeBackend:
    """The planning bridge's Backend over native/plan_scene.c: the Sphere world's bodies (as
    the Core built them: primitives, masses, poses) in a plain libode world; the control's
    force computed as the Core back end computes it (gui.planning.backend.step_actuation).
    A state vector holds STATE_SIZE values per body (plan_scene.c)."""

    STATE_SIZE = 13
    """plan_scene.c's per body: position, quaternion (w, x, y, z), linear, angular velocity."""
    ROLE_OTHER, ROLE_ROBOT, ROLE_FORBIDDEN = 0, 1, 2
    """plan_scene.c's geometry roles: it reports the robot touching a forbidden one."""

    def __init__(self, core_backend, library: pathlib.Path):
        import numpy as np
        from cffi import FFI
        self.problem = core_backend.problem
        core = core_backend.world.core
        self.ffi = FFI()
        self.ffi.cdef("""
            int ps_create(double, double, double, double, double, int, double);
            int ps_add(int, const double *, double, const double *, const double *, int);
            int ps_propagate(const double *, int, const double *, double, double *);
            void ps_read(double *);
            int ps_body_count(void);""")
        self.lib = self.ffi.dlopen(str(library))
        w = core.world_parameters
        self.lib.ps_create(*w.gravity, w.erp, w.cfm, w.max_contacts, w.friction)
        self.index = {}
        for name in core.object_ids():
            self._add(core, name)
        self.size = self.STATE_SIZE * self.lib.ps_body_count()
        self._out = self.ffi.new("double[]", self.size)
        self.lib.ps_read(self._out)
        self._start = np.frombuffer(self.ffi.buffer(self._out), dtype=np.float64).copy()
        self.robot = self.index[self.problem.base_body]
        self.propagations = 0

    def _add(self, core, name: str) -> None:
        from odin_common.interface import Shape
        spec = core.object_spec(name)
        dims = list(spec.parameters) or [0.0]
        shape = Shape.PLANE if spec.shape == Shape.PLANE else (
            Shape.SPHERE if len(dims) == 1 else Shape.BOX)
        if spec.shape not in (Shape.BY_COUNT, Shape.SPHERE, Shape.BOX, Shape.PLANE) \
                or len(dims) not in (1, 3):
            raise RuntimeError(f"{name}: the native propagator takes spheres, boxes, planes")
        dynamic = not (spec.geometry_only or spec.fixed)
        if dynamic:
            position, quaternion, _, _ = core.body_state(name)
        else:
            position, quaternion = spec.position, spec.orientation
        role = self.ROLE_ROBOT if name in self.problem.robot_bodies else (
            self.ROLE_FORBIDDEN if name in self.problem.forbidden else self.ROLE_OTHER)
        index = self.lib.ps_add(int(shape), dims, spec.mass if dynamic else 0.0, list(position),
                                list(quaternion), role)
        if index >= 0:
            self.index[name] = index
        elif index == -2:
            raise RuntimeError("the native propagator holds 64 bodies at most")

    def start_state(self):
        return self._start.copy()

    def _body(self, state, name):
        k = self.STATE_SIZE * self.index[name]
        return state[k:k + 3], state[k + 3:k + 7], state[k + 7:k + 10]

    def tracked_state(self, state):
        position, quaternion, linear = self._body(state, self.problem.tracked_body)
        return self.problem.tracked_origin(position, quaternion), linear.copy()

    def propagate(self, requests):
        import numpy as np
        from gui.planning.backend import Outcome, step_actuation
        outcomes = []
        for state, control in requests:
            act = step_actuation(self.problem, control, self._body(state, self.problem.base_body))
            force = act.forces[0][1] if act.forces else (0.0, 0.0, 0.0)
            state = np.ascontiguousarray(state, dtype=np.float64)
            touched = self.lib.ps_propagate(self.ffi.from_buffer("double[]", state), self.robot,
                                            list(force), self.problem.step, self._out)
            new = np.frombuffer(self.ffi.buffer(self._out), dtype=np.float64).copy()
            self.propagations += 1
            position, linear = self.tracked_state(new)
            # plan_scene.c says only that a forbidden geometry was touched: the pair names
            # one of them, which is all forbidden_contacts needs
            pairs = ((self.problem.base_body, sorted(self.problem.forbidden)[0]),) \
                if touched else ()
            outcomes.append(Outcome(new, position, linear, pairs))
        return outcomes

    def close(self) -> None:
        pass


def _native_library(out_dir: pathlib.Path) -> pathlib.Path:
    import subprocess
    library = out_dir / "plan_scene.so"
    subprocess.run(["gcc", "-O2", "-DdDOUBLE", "-shared", "-fPIC",
                    str(HERE / "native" / "plan_scene.c"), "-lode", "-o", str(library)],
                   check=True)
    return library


def _native(library: pathlib.Path) -> dict:
    """The Core's and the native propagator's batch rates side by side (ROUNDS paired rounds,
    native first in even rounds: the medians of the rates and of the rounds' ratios), and one
    KPIECE1 search over the native propagator."""
    from gui.planning.backend import CoreBackend
    from gui.planning.bridge import plan
    core = CoreBackend(*_sphere())
    native = NativeBackend(core, library)
    try:
        rounds = []
        for k in range(ROUNDS):
            first, second = (native, core) if k % 2 == 0 else (core, native)
            rates = {first: _rate(first), second: _rate(second)}
            rounds.append((rates[core], rates[native]))
        result = plan(native, "KPIECE1", TIME_S, 1)
        return {"core": statistics.median(c for c, _ in rounds),
                "native": statistics.median(n for _, n in rounds),
                "ratio": statistics.median(c / n for c, n in rounds),
                "solved": result.solved}
    finally:
        core.close()


def _pool_rate(size: int) -> dict:
    with RosMaster() as master:
        namespaces = [f"/w{k}/virtual_world" for k in range(size)]
        for k in range(size):
            master.rosrun("VirtualWorld", "virtualWorld", f"__ns:=/w{k}")
        for namespace in namespaces:
            master.wait_for_service(f"{namespace}/propagate")
        master.apply_to_this_process()
        from gui.planning.pool import PoolBackend
        backend = PoolBackend(*_sphere(), namespaces)
        try:
            return {"per_s": _rate(backend)}
        finally:
            backend.close()


def run(out_dir: pathlib.Path) -> dict:
    searches = [in_child(_solve, seed) for seed in range(1, SEEDS + 1)]
    solved = [s["time_s"] for s in searches if s["solved"]]
    core = in_child(_core_rate)["per_s"]
    pool2 = in_child(_pool_rate, 2)["per_s"]
    pool1 = in_child(_pool_rate, 1)["per_s"]
    native = in_child(_native, _native_library(out_dir))
    return {"plan_sphere_success": round(len(solved) / len(searches), 3),
            "plan_sphere_median_s": round(statistics.median(solved), 2) if solved else TIME_S,
            "propagations_per_s_core": round(core, 1),
            "propagations_per_s_pool": round(pool2, 1),
            "propagations_per_s_pool1": round(pool1, 1),
            "plan_pool_speedup_2": round(pool2 / pool1, 3),
            "propagations_per_s_native": round(native["native"], 1),
            "plan_core_over_native": round(native["ratio"], 4),
            "plan_sphere_native_solved": int(native["solved"])}


if __name__ == "__main__":
    print(run(ROOT / "out" / "bench"))
