"""Viewer benchmarks on the TX90 + SAH hand + two cans grasp scene (Kautham legacy_2012,
TX90_RHand_ICRA10_5PMD_TwoCan.xml), loaded with the GUI's Kautham loader (gui.core.kautham.problem,
gui.core.translate: the same requests the GUI sends, ~195k triangles).

viewer_frame_ms_grasp: median wall time (ms) to render one 640x480 frame of the scene and read
    it back as an array, Core + renderer in this process (no ROS), the default camera. Goal <= 15.
viewer_fps_held: frames per second the Viewer node actually publishes on ~image over 10 s while
    a publisher sends SpaceDistribution for the scene at 25 Hz (robot moving). Goal >= 24.
Writes out_dir/viewer_grasp.png (the frame measured) and out_dir/viewer_bench.json.
"""
from __future__ import annotations

import json
import os
import pathlib
import statistics
import sys
import tempfile
import textwrap
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[2]
PROBLEM = "legacy_2012/examples/TX90_RHand_ICRA10_5PMD_TwoCan.xml"


def _kautham_dir() -> pathlib.Path:
    return pathlib.Path(os.environ.get("ODIN_KAUTHAM_DIR", ROOT.parent / "shared" / "kautham"))


def grasp_scene():
    """(view requests [(id, parameters, indices, position, orientation wxyz, color)],
    robot handle) for the grasp problem, composites split into parts as the world does."""
    from gui.core.translate import plan_problem
    from gui.core.kautham.problem import load_problem
    from gui.core.kinematics import pose_to_position_quaternion
    from odin_common.rotations import quaternion_to_matrix
    from odin_common.specs import ObjectSpec

    plan = plan_problem(load_problem(_kautham_dir() / PROBLEM))
    views = []
    for body in plan.bodies():
        if isinstance(body, ObjectSpec):
            views.append((body.name, body.parameters, body.indices, body.position,
                          body.orientation, body.color))
            continue
        T = np.eye(4)
        T[:3, :3] = quaternion_to_matrix(body.orientation)
        T[:3, 3] = body.position
        for part in body.parts:
            P = np.eye(4)
            P[:3, :3] = quaternion_to_matrix(part.orientation)
            P[:3, 3] = part.position
            position, quaternion = pose_to_position_quaternion(T @ P)
            views.append((part.name, part.parameters, part.indices, position,
                          quaternion, part.color))
    return views, (plan.robots[0] if plan.robots else None)


def frame_ms(out_dir: pathlib.Path, frames: int = 40) -> tuple:
    from PIL import Image
    from viewer.core.camera import Camera
    from viewer.core.renderer import Renderer
    from viewer.core.scene import Scene

    views, _ = grasp_scene()
    scene = Scene(Camera(width=640, height=480))
    for view in views:
        scene.view_object(*view)
    triangles = sum(item.geometry.triangle_count for item in scene.draw_list())
    with Renderer(640, 480) as renderer:
        frame = renderer.render(scene)       # uploads the meshes once
        times = []
        for _ in range(frames):
            started = time.perf_counter()
            frame = renderer.render(scene)
            times.append(time.perf_counter() - started)
    Image.fromarray(frame).save(out_dir / "viewer_grasp.png")
    return statistics.median(times) * 1000.0, triangles, len(views)


_PUBLISHER = textwrap.dedent("""
    import sys, time, threading, json
    sys.path.insert(0, {bench_dir!r})
    import rospy
    import bench_viewer
    from Messages.msg import SpaceDistribution, Situation
    from sensor_msgs.msg import Image
    from Services.srv import ViewObject
    rospy.init_node("viewer_bench", disable_signals=True)
    views, robot = bench_viewer.grasp_scene()
    rospy.wait_for_service("/viewer/view_object", 60)
    view = rospy.ServiceProxy("/viewer/view_object", ViewObject, persistent=True)
    for v in views:
        answer = view(id=v[0], parameters=list(v[1]), indices=list(v[2]), position=v[3],
                      orientation=v[4], color=v[5])
        assert answer.success, answer.message
    stamps = []
    rospy.Subscriber("/viewer/image", Image, lambda m: stamps.append(time.monotonic()),
                     queue_size=30, buff_size=2 ** 25)
    pub = rospy.Publisher("/virtual_world/world_update", SpaceDistribution, queue_size=10)
    statics = [(v[0], v[3], v[4]) for v in views]
    time.sleep(2.0)
    rate = rospy.Rate(25)
    started = time.monotonic(); warm = started + 1.0; end = warm + {seconds}
    k = 0
    while time.monotonic() < end:
        values = robot.home + 0.3 * __import__("math").sin(k / 25.0) if robot else None
        moving = robot.situations(values) if robot else []
        moved = {{name for name, _, _ in moving}}
        msg = SpaceDistribution()
        msg.header.stamp = rospy.Time.now()
        msg.situations = [Situation(name=n, position=p, orientation=q)
                          for n, p, q in moving + [s for s in statics if s[0] not in moved]]
        pub.publish(msg)
        k += 1
        rate.sleep()
    held = [t for t in stamps if warm <= t < end]
    print(json.dumps({{"fps": len(held) / {seconds}, "sent": k}}))
""")


def fps_held(seconds: float = 10.0) -> float:
    from odin_common.ros_master import RosMaster

    with tempfile.TemporaryDirectory(prefix="odin_bench_viewer_") as home:
        with RosMaster(ros_home=home) as master:
            master.rosrun("Viewer", "viewer", f"_snapshot_dir:={home}/snaps")
            script = _PUBLISHER.format(bench_dir=str(pathlib.Path(__file__).parent),
                                       seconds=seconds)
            result = master.run([sys.executable, "-c", script], timeout=180)
            return float(json.loads(result.stdout.strip().splitlines()[-1])["fps"])


def run(out_dir: pathlib.Path) -> dict:
    out_dir.mkdir(parents=True, exist_ok=True)
    ms, triangles, objects = frame_ms(out_dir)
    fps = fps_held()
    details = {"viewer_frame_ms_grasp": ms, "viewer_fps_held": fps, "triangles": triangles,
               "objects": objects, "scene": PROBLEM,
               "loader": "gui.core.kautham + gui.core.translate"}
    (out_dir / "viewer_bench.json").write_text(json.dumps(details, indent=2) + "\n")
    return {"viewer_frame_ms_grasp": round(ms, 2), "viewer_fps_held": round(fps, 2)}


if __name__ == "__main__":
    out = ROOT / "out" / "bench"
    print(run(out))
