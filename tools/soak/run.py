"""``make soak``: Odin under load for a while (10 minutes by default), figures in
out/soak/results.json.

A private roscore, the world simulating in real time, the Viewer rendering, a recorder (this
process) subscribed to the world's updates, and four clients (tools/soak/client.py, each its
own process) issuing mixed calls: builds, removals, New Scenes, forces, joints and motors,
velocities, snapshots. Figures: calls, errors (goal 0: a failed call, or a refusal no other
client's action explains), p50/p99 latency, resident-memory growth of each node after a
warm-up (goal <= 10 MB), world updates received against those the publication rate promises
(dropped), and whether every node is still alive. Exits 1 when a goal is missed.

    python tools/soak/run.py [--duration S] [--clients N] [--out DIR]
"""
from __future__ import annotations

import argparse
import json
import pathlib
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parents[2]
WARM_UP = 30.0            # s: memory is measured from here (caches, first meshes, imports)
GOALS = {"errors": 0, "rss_growth_mb": 10.0}


def rss_mb(pid: int) -> float:
    """Resident memory of ``pid`` in MB (VmRSS); 0 when it is gone."""
    try:
        for line in pathlib.Path(f"/proc/{pid}/status").read_text().splitlines():
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
    except OSError:
        pass
    return 0.0


def percentile(values, q: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(q * len(ordered)))] if ordered else 0.0


class Recorder:
    """Subscribes to the world's updates and counts them (the soak's recording client)."""

    def __init__(self):
        import rospy
        from Messages.msg import SpaceDistribution
        from odin_common.interface import WORLD_NAMESPACE
        self.received = 0
        self.largest = 0
        self._sub = rospy.Subscriber(f"{WORLD_NAMESPACE}/world_update", SpaceDistribution,
                                     self._on_update, queue_size=50)

    def _on_update(self, update) -> None:
        self.received += 1
        self.largest = max(self.largest, len(update.situations))


def soak(duration: float, clients: int, out: pathlib.Path) -> dict:
    from odin_common.ros_master import RosMaster
    out.mkdir(parents=True, exist_ok=True)
    with RosMaster(ros_home=out / "ros_home") as master:
        master.apply_to_this_process()
        world = master.rosrun("VirtualWorld", "virtualWorld", "_simulate:=true")
        viewer = master.rosrun("Viewer", "viewer", f"_snapshot_dir:={out}")
        master.wait_for_service("/virtual_world/get_world")
        master.wait_for_service("/viewer/save_snapshot")
        import rospy
        rospy.init_node("soak_recorder", disable_signals=True)
        rate = rospy.get_param("/virtual_world/rate", 25.0)
        recorder = Recorder()
        started = time.monotonic()
        workers = [master.popen([sys.executable, str(ROOT / "tools/soak/client.py"),
                                 "--number", str(k), "--duration", str(duration),
                                 "--out", str(out / f"client{k}.json")],
                                log_name=f"client{k}") for k in range(clients)]
        time.sleep(min(WARM_UP, duration / 3))
        received_at_warm_up = recorder.received
        warm_at = time.monotonic()
        rss_start = {"world": rss_mb(world.pid), "viewer": rss_mb(viewer.pid)}
        for worker in workers:
            worker.wait(timeout=duration + 300)
        measured = time.monotonic() - warm_at
        rss_end = {"world": rss_mb(world.pid), "viewer": rss_mb(viewer.pid)}
        received = recorder.received - received_at_warm_up
        alive = {"world": world.poll() is None, "viewer": viewer.poll() is None}
        elapsed = time.monotonic() - started
    summaries = [json.loads((out / f"client{k}.json").read_text()) for k in range(clients)]
    latencies = [t for s in summaries for t in s["latencies_s"]]
    expected_updates = int(measured * rate)
    return {
        "soak_duration_s": round(elapsed, 1),
        "soak_clients": clients,
        "soak_calls": sum(s["calls"] for s in summaries),
        "soak_errors": sum(s["errors"] for s in summaries) + sum(not a for a in alive.values()),
        "soak_expected_refusals": sum(s["expected_refusals"] for s in summaries),
        "soak_latency_p50_ms": round(1000 * percentile(latencies, 0.50), 2),
        "soak_latency_p99_ms": round(1000 * percentile(latencies, 0.99), 2),
        "soak_rss_growth_world_mb": round(rss_end["world"] - rss_start["world"], 1),
        "soak_rss_growth_viewer_mb": round(rss_end["viewer"] - rss_start["viewer"], 1),
        "soak_rss_world_mb": round(rss_end["world"], 1),
        "soak_rss_viewer_mb": round(rss_end["viewer"], 1),
        "soak_world_updates_received": received,
        "soak_world_updates_dropped": max(0, expected_updates - received),
        "soak_largest_update_situations": recorder.largest,
        "soak_world_alive": int(alive["world"]),
        "soak_viewer_alive": int(alive["viewer"]),
        "soak_error_examples": [e for s in summaries for e in s["error_examples"]][:10],
    }


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--duration", type=float, default=600.0, help="s (default 600)")
    parser.add_argument("--clients", type=int, default=4)
    parser.add_argument("--out", type=pathlib.Path, default=ROOT / "out" / "soak")
    args = parser.parse_args()
    results = soak(args.duration, args.clients, args.out)
    (args.out / "results.json").write_text(json.dumps(results, indent=1) + "\n")
    for name, value in results.items():
        print(f"{name:34s} {value}")
    growth = max(results["soak_rss_growth_world_mb"], results["soak_rss_growth_viewer_mb"])
    missed = (results["soak_errors"] > GOALS["errors"] or growth > GOALS["rss_growth_mb"])
    print(f"soak: {'GOAL MISSED' if missed else 'goals met'} (errors 0, memory growth "
          f"<= {GOALS['rss_growth_mb']} MB); {args.out / 'results.json'}")
    return 1 if missed else 0


if __name__ == "__main__":
    raise SystemExit(main())
