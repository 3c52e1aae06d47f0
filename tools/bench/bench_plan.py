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
Needs the Kautham data (ODIN_KAUTHAM_DIR). ``ODIN_BENCH_PLAN_SEEDS`` runs fewer seeds.
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
SPHERE = ("current_2025", "demos", "OMPL_ode_demos", "Sphere", "Sphere.xml")


def _sphere():
    from gui.core.build import plan_problem
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


def _pool_rate(size: int) -> dict:
    with RosMaster() as master:
        namespaces = [f"/w{k}/virtual_world" for k in range(size)]
        for k in range(size):
            master.rosrun("VirtualWorld", "virtualWorld", f"__ns:=/w{k}")
        for namespace in namespaces:
            master.wait_for_service(f"{namespace}/propagate")
        master.apply_to_this_process()
        from gui.planning_pool import PoolBackend
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
    return {"plan_sphere_success": round(len(solved) / len(searches), 3),
            "plan_sphere_median_s": round(statistics.median(solved), 2) if solved else TIME_S,
            "propagations_per_s_core": round(core, 1),
            "propagations_per_s_pool": round(pool2, 1),
            "propagations_per_s_pool1": round(pool1, 1),
            "plan_pool_speedup_2": round(pool2 / pool1, 3)}


if __name__ == "__main__":
    print(run(ROOT / "out" / "bench"))
