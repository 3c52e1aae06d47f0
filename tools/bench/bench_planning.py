"""Benchmarks of the world as a planner uses it.

  determinism_cost_ratio    what ordering contacts costs (deterministic stepping): steps per
                            second of a 100-sphere pile in four walls with contacts made in
                            the geoms' creation order, over the same without the ordering
                            (the broad phase's order, as before; a benchmark-only switch of the
                            C world). Paired rounds, the order alternated, median of the
                            ratios; each side in a process of its own. Goal >= 0.95.
  pool_propagate_speedup_2  throughput of a pool of 2 world nodes over a pool of 1 (this
                            machine's 2 cores): the same PROPAGATIONS propagations of a
                            60-sphere pile (0.25 s each) from one snapshot, fanned out.
(``propagate_rtf_grasp`` comes with the grasp experiment: bench_experiments.)
"""
import os
import pathlib
import statistics
import subprocess
import sys
import time

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent.parent
sys.path.insert(0, str(HERE))

from forked import in_child  # noqa: E402
from odin_common.ros_master import RosMaster  # noqa: E402

ROUNDS = int(os.environ.get("ODIN_BENCH_ROUNDS", 5))
STEPS = 2000
PROPAGATIONS = 24

PILE_SCRIPT = (
    "import sys, time; sys.path.insert(0, {here!r}); import bench_core\n"
    "from virtual_world.core import Core\n"
    "core = Core(); bench_core.build_scene(core, 1, 0, 0)\n"
    "core._scene.c.struct.unordered = {unordered}   # benchmark-only switch (odin_step.h)\n"
    "core.step(0.001, 100)\n"
    "started = time.perf_counter(); core.step(0.001, {steps})\n"
    "print({steps} / (time.perf_counter() - started))\n")


def _steps_per_s(unordered: int) -> float:
    script = PILE_SCRIPT.format(here=str(HERE), unordered=unordered, steps=STEPS)
    out = subprocess.run([sys.executable, "-c", script], check=True, capture_output=True,
                         text=True).stdout
    return float(out.split()[-1])


def determinism_cost() -> float:
    ratios = []
    for k in range(ROUNDS):
        if k % 2:
            unordered = _steps_per_s(1)
            ordered = _steps_per_s(0)
        else:
            ordered = _steps_per_s(0)
            unordered = _steps_per_s(1)
        ratios.append(ordered / unordered)
    return round(statistics.median(ratios), 3)


def _pool_throughput(size: int) -> dict:
    """Propagations per second of a pool of ``size`` world nodes (in a child: rospy)."""
    with RosMaster() as master:
        namespaces = [f"/w{k}/virtual_world" for k in range(size)]
        for k in range(size):
            master.rosrun("VirtualWorld", "virtualWorld", f"__ns:=/w{k}")
        for namespace in namespaces:
            master.wait_for_service(f"{namespace}/propagate")
        master.apply_to_this_process()
        sys.path.insert(0, str(ROOT / "tests" / "nodes"))
        from world_client import box, sphere
        from gui.ros.pool import WorldPool
        with WorldPool(namespaces) as pool:
            pool.broadcast("build_object", object=box("ground", (4, 4, 0.2), (0, 0, -0.1),
                                                      geometry_only=True))
            for i in range(60):
                pool.broadcast("build_object", object=sphere(
                    f"s{i}", 0.1, ((i % 4) * 0.21, ((i // 4) % 4) * 0.21, 0.12 + (i // 16) * 0.21)))
            pool.broadcast("save_state", name="start")
            requests = [dict(start="start", duration=0.25) for _ in range(PROPAGATIONS)]
            pool.propagate(requests[:size])          # warm up: connections, caches
            started = time.perf_counter()
            pool.propagate(requests)
            return {"per_s": PROPAGATIONS / (time.perf_counter() - started)}


def pool_speedup() -> float:
    ratios = []
    for k in range(max(1, ROUNDS // 2)):
        sizes = (1, 2) if k % 2 == 0 else (2, 1)
        rates = {size: in_child(_pool_throughput, size)["per_s"] for size in sizes}
        ratios.append(rates[2] / rates[1])
    return round(statistics.median(ratios), 3)


def run(out_dir: pathlib.Path) -> dict:
    return {"determinism_cost_ratio": determinism_cost(),
            "pool_propagate_speedup_2": pool_speedup()}


if __name__ == "__main__":
    print(run(ROOT / "out" / "bench"))
