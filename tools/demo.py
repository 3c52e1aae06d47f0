"""`make demo`: the three-node chain end to end, headless, then the thesis's grasp.

First part, on a scene Odin builds itself: starts a roscore on a free loopback port and the
nodes with rosrun (VirtualWorld, Viewer), builds a scene through the GUI's world client
(gui.ros.client.WorldClient: a sphere above a box on the ground), runs it, and writes Viewer
snapshots to out/demo/. Every process started here is stopped on the way out, also on Ctrl-C,
SIGTERM or failure. Exit status 0 only if the sphere was seen to fall.

Second part, on the Kautham corpus: the grasping experiment (tools/experiments, frames in
out/experiments/grasp/), in a process of its own. Without the corpus (a bare clone) it prints
one line saying where the corpus comes from instead.
"""
from __future__ import annotations

import pathlib
import shutil
import signal
import subprocess
import sys
import time

from gui.core.kautham.corpus import corpus_dir, missing_message
from odin_common.ros_master import RosMaster
from odin_common.specs import ObjectSpec

ROOT = pathlib.Path(__file__).resolve().parent.parent

OUT = ROOT / "out" / "demo"
SNAPSHOTS = 16
SNAPSHOT_PERIOD = 0.12  # s of wall-clock time between snapshots (real-time simulation)


def _raise_keyboard_interrupt(signum, frame):
    raise KeyboardInterrupt(f"signal {signum}")


def build_scene(client) -> None:
    """The walking skeleton's scene: ground, a box on it and a bouncy sphere 2 m above it."""
    client.new_scene()
    client.set_world(gravity=(0.0, 0.0, -9.81), bounce=0.6, bounce_velocity=0.1)
    ground = ObjectSpec(name="ground", parameters=(4.0, 4.0, 0.1), position=(0, 0, -0.05),
                        color=(0.55, 0.6, 0.55, 1), geometry_only=True)
    box = ObjectSpec(name="box", parameters=(0.6, 0.6, 0.4), mass=5.0, position=(0, 0, 0.2),
                     color=(0.2, 0.4, 0.9, 1))
    sphere = ObjectSpec(name="sphere", parameters=(0.15,), mass=1.0, position=(0.05, 0, 2.6),
                        color=(0.9, 0.25, 0.2, 1))
    for body in (ground, box, sphere):
        client.build_object(body)


def main() -> int:
    signal.signal(signal.SIGTERM, _raise_keyboard_interrupt)
    shutil.rmtree(OUT, ignore_errors=True)
    OUT.mkdir(parents=True)
    with RosMaster() as master:
        print(f"demo: master {master.uri}", flush=True)
        master.apply_to_this_process()
        import rospy  # after the environment points at our master
        from Messages import msg
        from Services import srv

        def call(name, service_class, *request):
            rospy.wait_for_service(name, timeout=30)
            response = rospy.ServiceProxy(name, service_class)(*request)
            if not response.success:
                raise RuntimeError(f"{name}: {response.message}")
            return response

        rospy.init_node("odin_demo", disable_signals=True)
        world = master.rosrun("VirtualWorld", "virtualWorld")
        viewer = master.rosrun("Viewer", "viewer", f"_snapshot_dir:={OUT}",
                               "_eye:=[3.2, -3.2, 1.8]", "_target:=[0, 0, 1.3]")
        master.wait_for_service("/virtual_world/start")
        master.wait_for_service("/viewer/save_snapshot")
        from gui.ros.client import WorldClient
        client = WorldClient(timeout=30)
        build_scene(client)
        time.sleep(0.5)  # the Viewer receives the scene from the world's queue
        heights = []
        for index in range(SNAPSHOTS):
            if index == 1:
                client.start()
            time.sleep(SNAPSHOT_PERIOD)
            update = rospy.wait_for_message("/virtual_world/world_update",
                                            msg.SpaceDistribution, timeout=10)
            heights.extend(s.position[2] for s in update.situations if s.name == "sphere")
            call("/viewer/save_snapshot", srv.SaveSnapshot, f"demo_{index:03d}.png")
        client.pause()
        client.close()
        for process in (world, viewer):
            if process.poll() is not None:
                raise RuntimeError(f"{process.args} died:\n{master.log_text(process)[-2000:]}")
    written = sorted(OUT.glob("demo_*.png"))
    print(f"demo: {len(written)} snapshots in {OUT}; sphere height {heights[0]:.2f} m -> "
          f"{heights[-1]:.2f} m")
    if len(written) < 10 or heights[0] - min(heights) < 0.3:
        print("demo: the sphere did not visibly move", file=sys.stderr)
        return 1
    return 0


def kautham_part() -> int:
    """The grasp experiment on the Kautham corpus, or one line saying where it comes from."""
    if corpus_dir() is None:
        print(f"demo: the Kautham part is skipped: {missing_message()}")
        return 0
    return subprocess.run([sys.executable, str(ROOT / "tools" / "experiments" / "run.py"),
                           "grasp"]).returncode


if __name__ == "__main__":
    try:
        sys.exit(main() or kautham_part())
    except KeyboardInterrupt:
        print("demo: interrupted; every process it started was stopped", file=sys.stderr)
        sys.exit(130)
    except Exception as error:  # one line for the user, the processes are already stopped
        print(f"demo: {error}", file=sys.stderr)
        sys.exit(1)
