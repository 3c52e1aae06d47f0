"""Benchmarks of the VirtualWorld node (the Portal) through ROS.

Figures:
  portal_calls_under_load          failures (crashed node + wrong answers) among 10,000 mixed
                                   calls from 4 client processes while the world runs free
                                   (goal 0); also ..._median_ms and ..._p99_ms latencies.
  portal_publish_1000_cpu          share of one core the paused node spends over 10 s with
                                   1,000 objects published at 25 Hz to a subscriber (goal <= 0.1).
  portal_publish_10000_cpu         the same with 10,000 objects (goal <= 0.25); rss_mb_10000 the
                                   node's resident memory meanwhile (reported).
  portal_rtf_spheres100            real-time factor of the 100-sphere scene of bench_core run
                                   back to back (~free_run), divided by the native C program's
                                   steps per second times the step size, measured alternately
                                   (native first in even rounds, the node first in odd ones),
                                   median of the rounds' ratios (goal >= 0.90).
Same work: after each round's window the node is paused and its step count and final poses
read (world_update); one native run at the end steps as far as the longest of them and prints
its poses at each round's step count. The figure is given only if they are bit-identical in
every round (measured so on 2026-11-22), else refused (report.Refused) with the difference.
"""
from __future__ import annotations

import math
import multiprocessing
import os
import pathlib
import statistics
import struct
import subprocess
import sys
import time

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent.parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(ROOT / "tests" / "nodes"))   # world_client: the node tests' raw client

from forked import in_child  # noqa: E402
from report import Refused  # noqa: E402
from odin_common.ros_master import RosMaster  # noqa: E402

CLIENTS = 4
CALLS = 10_000
CPU_WINDOW = 10.0
RTF_WINDOW = 8.0
RTF_ROUNDS = int(os.environ.get("ODIN_BENCH_ROUNDS", "5"))
STEP = 0.001    # the node's default step (s), the native program's
NATIVE_STEPS = 20_000


def _cpu_seconds(pid: int) -> float:
    fields = pathlib.Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def _node_pid(master: RosMaster, process) -> int:
    """The python process of a node started with rosrun (rosrun execs, but be safe)."""
    children = pathlib.Path(f"/proc/{process.pid}/task/{process.pid}/children")
    kids = children.read_text().split() if children.exists() else []
    return int(kids[0]) if kids else process.pid


def _start_world(master: RosMaster, *params: str):
    node = master.rosrun("VirtualWorld", "virtualWorld", *params)
    master.wait_for_service("/virtual_world/set_joint_force")
    time.sleep(0.3)
    return node


# -- calls under load ----------------------------------------------------------------------
def _client(index: int, count: int, results) -> None:
    """One load client: mixed calls, each with the answer it must get."""
    from world_client import WorldClient, sphere
    from Messages.msg import Situation

    client = WorldClient()
    latencies, wrong = [], []
    nan = float("nan")
    for i in range(count):
        name = f"c{index}_{i}"
        kind = i % 8
        started = time.perf_counter()
        try:
            if kind == 0:
                ok = client("build_object", object=sphere(name, 0.05, (index, i % 20 * 0.2, 2)))
                expect = True
            elif kind == 1:
                ok = client("set_position", situations=[Situation(
                    f"c{index}_{i - 1}", [index, 0, 3], [1, 0, 0, 0])])
                expect = True
            elif kind == 2:
                ok = client("set_velocity", object=f"c{index}_{i - 2}", set_linear=True,
                            linear=[0, 0, 1])
                expect = True
            elif kind == 3:
                ok = client("build_object", object=sphere(f"c{index}_{i - 3}"))  # duplicate
                expect = False
            elif kind == 4:
                ok = client("set_external_force", object=f"c{index}_{i - 4}", vector=[0, 0, 1])
                expect = True
            elif kind == 5:
                ok = client("set_world", set_erp=True, erp=nan)                   # bad value
                expect = False
            elif kind == 6:
                ok = client("remove_object", id=f"c{index}_{i - 6}")
                expect = True
            else:
                ok = client("remove_object", id=f"nobody_{index}_{i}")            # unknown
                expect = False
            if ok.success != expect:
                wrong.append(f"{kind}: {ok.message}")
        except Exception as error:  # a transport failure counts as a wrong answer
            wrong.append(f"{kind}: {type(error).__name__}: {error}")
        latencies.append(time.perf_counter() - started)
    client.close()
    results.put((latencies, wrong))


def calls_under_load() -> dict:
    with RosMaster() as master:
        master.apply_to_this_process()
        node = _start_world(master, "_simulate:=true", "_free_run:=true")
        from world_client import WorldClient, box
        setup = WorldClient()
        setup.ok("build_object", object=box("ground", (20, 20, 1), (0, 0, -0.5),
                                            geometry_only=True))
        setup.close()
        context = multiprocessing.get_context("fork")
        results = context.Queue()
        clients = [context.Process(target=_client, args=(i, CALLS // CLIENTS, results))
                   for i in range(CLIENTS)]
        for process in clients:
            process.start()
        collected = [results.get(timeout=900) for _ in clients]
        for process in clients:
            process.join(30)
        crashed = node.poll() is not None
    latencies = sorted(t for chunk, _ in collected for t in chunk)
    wrong = [w for _, chunk in collected for w in chunk]
    if wrong:
        print(f"  wrong answers (first 5): {wrong[:5]}")
    return {"portal_calls_under_load": float(int(crashed) + len(wrong)),
            "portal_calls_under_load_wrong": float(len(wrong)),
            "portal_calls_under_load_crashes": float(int(crashed)),
            "portal_calls_under_load_median_ms": 1000 * statistics.median(latencies),
            "portal_calls_under_load_p99_ms": 1000 * latencies[int(0.99 * len(latencies))]}


# -- publication cost ------------------------------------------------------------------------
def _rss_mb(pid: int) -> float:
    for line in pathlib.Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024.0
    raise RuntimeError(f"no VmRSS for process {pid}")


def _situations(buff: bytes) -> int:
    """The number of situations of a serialised SpaceDistribution (after its Header)."""
    frame_length = struct.unpack_from("<I", buff, 12)[0]
    return struct.unpack_from("<I", buff, 16 + frame_length)[0]


def publish_cpu(count: int) -> dict:
    """The paused node publishing ``count`` static boxes (a grid 0.2 m apart) at 25 Hz to one
    subscriber: its share of a core over CPU_WINDOW, the updates received per second, and its
    resident memory (MB) with them built."""
    with RosMaster() as master:
        master.apply_to_this_process()
        node = _start_world(master)
        import rospy
        from world_client import WorldClient, box
        rospy.init_node("bench_portal", anonymous=True, disable_signals=True)
        client = WorldClient()
        side = math.ceil(math.sqrt(count))
        client.ok("build_entity", name="crowd", objects=[
            box(f"b{i}", (0.1, 0.1, 0.1), (i % side * 0.2, i // side * 0.2, 0.05),
                geometry_only=True) for i in range(count)])
        # raw bytes (AnyMsg): deserialising 10,000 situations in Python would make the
        # subscriber, not the node, set the rate
        received = []
        subscriber = rospy.Subscriber("/virtual_world/world_update", rospy.AnyMsg,
                                      lambda m: received.append(_situations(m._buff)))
        time.sleep(2.0)
        pid = _node_pid(master, node)
        cpu0, wall0, count0 = _cpu_seconds(pid), time.monotonic(), len(received)
        time.sleep(CPU_WINDOW)
        cpu1, wall1, count1 = _cpu_seconds(pid), time.monotonic(), len(received)
        rss = _rss_mb(pid)
        subscriber.unregister()
        client.close()
    rate = (count1 - count0) / (wall1 - wall0)
    print(f"  received {rate:.1f} updates/s of {received[-1]} situations, node {rss:.0f} MB")
    figures = {f"portal_publish_{count}_cpu": (cpu1 - cpu0) / (wall1 - wall0),
               f"portal_publish_{count}_rate_hz": rate}
    if count == 10_000:
        figures["rss_mb_10000"] = rss
    return figures


# -- real-time factor against native C ----------------------------------------------------------
def world_rtf_spheres100() -> dict:
    """Simulated seconds per wall-clock second of the 100-sphere scene, free running; then,
    paused, the steps taken and the final poses (x y z qw qx qy qz of s0..s99)."""
    with RosMaster() as master:
        master.apply_to_this_process()
        _start_world(master, "_free_run:=true")
        import rospy
        from rosgraph_msgs.msg import Clock
        from Messages.msg import SpaceDistribution
        from world_client import WorldClient, sphere, box
        rospy.init_node("bench_portal_rtf", anonymous=True, disable_signals=True)
        client = WorldClient()
        client.ok("build_object", object=box("ground", (20, 20, 1), (0, 0, -0.5),
                                            geometry_only=True))
        client.ok("build_entity", name="spheres", internal_collisions=True, objects=[
            sphere(f"s{i}", 0.1, ((i % 10) * 0.25 - 1.125, (i // 10) * 0.25 - 1.125, 0.5))
            for i in range(100)])
        client.ok("start", simulate=True)
        time.sleep(0.5)
        sim0 = rospy.wait_for_message("/clock", Clock, timeout=5).clock.to_sec()
        wall0 = time.monotonic()
        time.sleep(RTF_WINDOW)
        sim1 = rospy.wait_for_message("/clock", Clock, timeout=5).clock.to_sec()
        wall1 = time.monotonic()
        client.ok("start", simulate=False)
        time.sleep(0.2)         # a cycle under way when the pause came is published by now
        update = rospy.wait_for_message("/virtual_world/world_update", SpaceDistribution,
                                        timeout=5)
        client.close()
    poses = {s.name: tuple(s.position) + tuple(s.orientation) for s in update.situations}
    return {"rtf": (sim1 - sim0) / (wall1 - wall0),
            "steps": round(update.header.stamp.to_sec() / STEP),
            "poses": [poses.get(f"s{i}") for i in range(100)]}


def _native_rtf(exe: pathlib.Path) -> float:
    # long enough that, like the node's window, it is mostly spheres at rest on the plane
    output = subprocess.run([str(exe), "0", str(NATIVE_STEPS), "0", "0"], check=True,
                            capture_output=True, text=True).stdout.split()
    return NATIVE_STEPS * STEP / float(output[0])   # simulated s per wall s


def native_poses_at(exe: pathlib.Path, steps: list) -> dict:
    """{step count: the 100 poses} of one native run of the 100-sphere scene."""
    import bench_core
    output = subprocess.run([str(exe), "0", str(max(steps)), "0", "0", *map(str, steps)],
                            check=True, capture_output=True, text=True).stdout
    return {count: run.poses for count, run in bench_core.parse_checkpoints(output).items()}


def pose_difference(native: list, node: list) -> str | None:
    """None if the node's poses are the native ones to the bit, else the largest difference."""
    if any(pose is None or len(pose) != 7 for pose in node):
        return "the node's world_update lacks some of s0..s99"
    import bench_core
    return bench_core.pose_difference(native, node)


def rtf_spheres100(out_dir: pathlib.Path) -> dict:
    """Alternates the node and the native program; the median of the rounds' ratios; refused
    unless the node's final poses are the native program's after as many steps."""
    import bench_core
    exe = bench_core._compile(out_dir)
    world, native = [], []
    for k in range(RTF_ROUNDS):
        if k % 2 == 0:
            native.append(_native_rtf(exe))
            world.append(in_child(world_rtf_spheres100))
        else:
            world.append(in_child(world_rtf_spheres100))
            native.append(_native_rtf(exe))
    steps = [w["steps"] for w in world]
    reference = native_poses_at(exe, steps)
    differences = [(k, d) for k, d in enumerate(
        pose_difference(reference[w["steps"]], w["poses"]) for w in world) if d]
    # the median of the rounds' ratios: a round's two runs share the load of a shared machine
    ratio = statistics.median(w["rtf"] / n for w, n in zip(world, native))
    print(f"  world rtf {[w['rtf'] for w in world]}, native {native}, node steps {steps}, "
          f"same poses as native: {differences[0][1] if differences else 'yes'}")
    if differences:
        k, difference = differences[0]
        return {"portal_rtf_spheres100": Refused(
            f"the node's poses differ from native C's after as many steps in "
            f"{len(differences)} of {len(world)} rounds (round {k}, {steps[k]} steps: "
            f"{difference})")}
    return {"portal_rtf_spheres100": ratio}


def run(out_dir: pathlib.Path) -> dict:
    figures = {}
    figures.update(in_child(publish_cpu, 1000))
    figures.update(in_child(publish_cpu, 10_000))
    figures.update(in_child(rtf_spheres100, out_dir))
    figures.update(in_child(calls_under_load))
    return figures


if __name__ == "__main__":
    out = ROOT / "out" / "bench"
    out.mkdir(parents=True, exist_ok=True)
    print(run(out))
