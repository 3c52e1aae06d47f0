"""What the three experiments share: starting the nodes, driving the world cycle by cycle,
recording what it publishes, saving Viewer frames and writing the summary.

Every experiment runs against a roscore of its own (``tests/ros_harness.RosMaster``) with the
three parts of Odin as separate processes started by rosrun or acting as the GUI:

    VirtualWorld  (``rosrun VirtualWorld virtualWorld`` with the experiment's parameters)
    Viewer        (``rosrun Viewer viewer``, fixed camera, frames into ``<out>/frames``)
    GUI           this process: ``gui.core.kautham`` loads the problem, ``gui.core.translate``
                  plans it and ``gui.ros.client.WorldClient`` sends it, exactly as
                  ``rosrun GUI load_problem``

and they talk only through the world's and the Viewer's services and topics.

The world is paused and advanced with Step Once, one Portal cycle per call, so a command the
GUI sends "every cycle" (Set Position along a path, Set Velocity) lands on the cycle it was
meant for, and every run is repeatable. Cycles still run back to back, as under
``~free_run``: the real-time factor reported is simulated time over the wall-clock time spent
advancing (``rtf_stepping``) and over the whole run, frames included (``rtf_overall``), plus
the world's own ``~real_time_factor`` topic.

Recorded per cycle from the world's topics: the poses of ``track``-ed geometries
(``~world_update``), the pairs of ``~collided`` (contact-less policy) or ``~contacts`` (contact
policy). Every message is stamped with simulated time; lost messages are counted, not guessed.
"""
from __future__ import annotations

import json
import math
import os
import pathlib
import shutil
import threading
import time
from dataclasses import dataclass, field
from typing import Iterable, Optional, Sequence

from odin_common.blas import use_reference_blas

use_reference_blas()  # before numpy (odin_common.blas)

import numpy as np  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parent.parent.parent

from gui.core.kautham.corpus import ENVIRONMENT  # noqa: E402
from odin_common.ros_master import RosMaster  # noqa: E402

OUT_ROOT = ROOT / "out" / "experiments"
KAUTHAM_DIR = pathlib.Path(os.environ.get(ENVIRONMENT, ROOT.parent / "shared" / "kautham"))
EXAMPLES = KAUTHAM_DIR / "legacy_2012" / "examples"
PATHS_DIR = ROOT / "Odin" / "GUI" / "paths"

#: The Viewer's colour for a colliding object (odin_common.defaults.COLLIDING_COLOR), 0..255.
COLLIDING_RGB = (89, 89, 89)

#: The ICRA09 scene of the TX90 problems (pile, grasp): the table is a 0.5 m cube on the floor,
#: the floor a 10 mm slab centred at z = -0.011 m (its top at -0.006 m).
TABLE_TOP = 0.5
FLOOR_TOP = -0.006


class ExperimentError(RuntimeError):
    """An experiment could not run (a node died, a service refused, a message never came)."""


@dataclass(frozen=True)
class Camera:
    """The Viewer's fixed camera: eye and target in m, world frame; image size in px."""
    eye: tuple
    target: tuple
    width: int = 640
    height: int = 480


@dataclass
class Record:
    """What the world published, keyed by simulated time (s, rounded to the microsecond)."""
    poses: dict = field(default_factory=dict)        # t -> {name: (position (3,), quat (4,))}
    collided: dict = field(default_factory=dict)     # t -> [(first, second, depth m)]
    contacts: dict = field(default_factory=dict)     # t -> (pairs, contact points)
    contact_pairs: dict = field(default_factory=dict)  # t -> [(first, second)]
    contact_depths: dict = field(default_factory=dict)  # t -> [(first, second, depth m)]
    rtf: list = field(default_factory=list)          # the world's ~real_time_factor values
    lock: threading.Lock = field(default_factory=threading.Lock)


def _t(stamp) -> float:
    return round(stamp.to_sec(), 6)


def world_args(parameters: dict) -> list:
    """rosrun private-parameter arguments (``_name:=value``) for the world node."""
    out = []
    for name, value in parameters.items():
        if isinstance(value, bool):
            text = "true" if value else "false"
        elif isinstance(value, (list, tuple)):
            text = "[" + ",".join(repr(float(v)) for v in value) + "]"
        else:
            text = repr(value)
        out.append(f"_{name}:={text}")
    return out


class Session:
    """Own roscore, the world and Viewer nodes, and this process as the GUI.

    ``with Session("pile", world_parameters, camera, track={"can"}) as s:`` then
    ``s.client`` (gui.ros.client.WorldClient), ``s.cycle()``, ``s.frame()``, ``s.record``.
    ``viewer=False`` runs no Viewer (no frames then): the benchmarks time the world with and
    without one rendering beside it.
    """

    def __init__(self, name: str, world_parameters: dict, camera: Camera,
                 track: Iterable[str] = (), frames: bool = True, contacts: bool = False,
                 out_root: pathlib.Path = OUT_ROOT, viewer: bool = True):
        if frames and not viewer:
            raise ExperimentError(f"{name}: frames come from the Viewer: run it (viewer=True)")
        self.name = name
        self.out = pathlib.Path(out_root) / name
        self.frames_dir = self.out / "frames"
        self.world_parameters = dict(world_parameters)
        self.camera = camera
        self.track = set(track)
        self.save_frames = frames
        self.want_contacts = contacts
        self.with_viewer = viewer
        self.viewer = None
        self.record = Record()
        self.frame_paths: list = []
        self.frame_times: list = []
        self._viewer_scene_complete = False
        self.sim_time = 0.0
        self.cycles = 0
        self.stepping_wall = 0.0
        self._master: Optional[RosMaster] = None
        self.client = None
        self._started = 0.0

    # -- lifecycle ------------------------------------------------------------------------
    def __enter__(self) -> "Session":
        shutil.rmtree(self.out, ignore_errors=True)
        self.frames_dir.mkdir(parents=True)
        self._master = RosMaster()
        self._master.start()
        try:
            self._start_nodes()
        except BaseException:
            self._master.stop()
            raise
        return self

    def __exit__(self, *exc_info) -> None:
        try:
            if self.client is not None:
                self.client.close()
        finally:
            self._master.stop()

    def _start_nodes(self) -> None:
        master = self._master
        master.apply_to_this_process()
        import rospy
        from Messages import msg
        from std_msgs.msg import Float64
        self._rospy = rospy
        if not rospy.core.is_initialized():
            rospy.init_node("gui", anonymous=True, disable_signals=True)
        self.world = master.rosrun("VirtualWorld", "virtualWorld",
                                   *world_args(self.world_parameters))
        cam = self.camera
        if self.with_viewer:
            self.viewer = master.rosrun(
                "Viewer", "viewer", f"_snapshot_dir:={self.frames_dir}",
                "_eye:=[%s]" % ",".join(repr(float(v)) for v in cam.eye),
                "_target:=[%s]" % ",".join(repr(float(v)) for v in cam.target),
                f"_width:={cam.width}", f"_height:={cam.height}")
        master.wait_for_service("/virtual_world/step_once")
        if self.with_viewer:
            master.wait_for_service("/viewer/save_snapshot")
        from gui.ros.client import WorldClient
        self.client = WorldClient(timeout=30.0)
        self._subscribers = [
            rospy.Subscriber("/virtual_world/world_update", msg.SpaceDistribution,
                             self._on_world, queue_size=10000),
            rospy.Subscriber("/virtual_world/collided", msg.Collided, self._on_collided,
                             queue_size=10000),
            rospy.Subscriber("/virtual_world/real_time_factor", Float64, self._on_rtf,
                             queue_size=100)]
        if self.want_contacts:
            self._subscribers.append(rospy.Subscriber(
                "/virtual_world/contacts", msg.Collided, self._on_contacts, queue_size=10000))
        from Services import srv
        self._snapshot = rospy.ServiceProxy("/viewer/save_snapshot", srv.SaveSnapshot)
        # wait until the world sees our subscriptions (contacts are published only then)
        deadline = time.monotonic() + 10
        while time.monotonic() < deadline:
            if all(s.get_num_connections() > 0 for s in self._subscribers):
                break
            time.sleep(0.05)
        self._started = time.monotonic()

    def check_nodes(self) -> None:
        for process in (self.world, self.viewer):
            if process is not None and process.poll() is not None:
                raise ExperimentError(f"{' '.join(process.args)} died:\n"
                                      + self._master.log_text(process)[-3000:])

    # -- topics -----------------------------------------------------------------------------
    def _on_world(self, message) -> None:
        t = _t(message.header.stamp)
        poses = {s.name: (tuple(s.position), tuple(s.orientation))
                 for s in message.situations if s.name in self.track}
        with self.record.lock:
            # the first message of a stamp is the cycle's own; a paused world repeats the
            # stamp of its last cycle with the poses of the moment, which the Set Position
            # calls between cycles may already have changed (keeping the last one made
            # repeated runs record different trajectories of one identical simulation)
            self.record.poses.setdefault(t, poses)

    def _on_collided(self, message) -> None:
        t = _t(message.header.stamp)
        pairs = [(p.first, p.second, float(p.depth)) for p in message.pairs]
        with self.record.lock:
            # a paused world still publishes at its rate, with the stamp of the last cycle
            # and nothing collided since: merge, never overwrite
            merged = {(a, b): d for a, b, d in self.record.collided.get(t, [])}
            for a, b, d in pairs:
                merged[(a, b)] = max(d, merged.get((a, b), 0.0))
            self.record.collided[t] = [(a, b, d) for (a, b), d in sorted(merged.items())]

    def _on_contacts(self, message) -> None:
        t = _t(message.header.stamp)
        points = sum(len(p.points) for p in message.pairs)
        with self.record.lock:
            if t in self.record.contacts and not message.pairs:
                return  # a paused world's repeat publication of the same cycle
            self.record.contacts[t] = (len(message.pairs), points)
            self.record.contact_pairs[t] = [(p.first, p.second) for p in message.pairs]
            self.record.contact_depths[t] = [(p.first, p.second, float(p.depth))
                                             for p in message.pairs]

    def _on_rtf(self, message) -> None:
        with self.record.lock:
            self.record.rtf.append(float(message.data))

    # -- driving ----------------------------------------------------------------------------
    def cycle(self, count: int = 1) -> float:
        """Advances ``count`` Portal cycles, one Step Once each; returns the simulated time."""
        for _ in range(count):
            started = time.perf_counter()
            sim_time = self.client.step_once(1)
            self.stepping_wall += time.perf_counter() - started
            self.sim_time = sim_time
            self.cycles += 1
        return self.sim_time

    def wait_for_update(self, timeout: float = 10.0) -> None:
        """Until the world_update of the current simulated time has arrived here."""
        self._wait_for_stamp("poses", "world_update", timeout)

    def _wait_for_stamp(self, kept: str, message: str, timeout: float) -> None:
        """Until ``record.<kept>`` holds the current simulated time's ``message``."""
        wanted = round(self.sim_time, 6)
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            with self.record.lock:
                if wanted in getattr(self.record, kept):
                    return
            time.sleep(0.001)
        self.check_nodes()
        raise ExperimentError(f"no {message} stamped {wanted} s after {timeout} s")

    def cycle_and_frame(self) -> Optional[pathlib.Path]:
        """One cycle, then its Viewer frame. The Viewer first catches up with the cycle before
        (drawn into the frame's file, overwritten after the cycle): after a burst of cycles it
        may have dropped world updates (it keeps the newest), and a collision stays grey from
        the update before it (viewer.core.scene), which must be the cycle before."""
        if self.save_frames:
            self._wait_for_viewer_scene_once()
            self.snapshot_of_now(self._next_frame_name())
        self.cycle(1)
        return self.frame()

    def frame(self) -> Optional[pathlib.Path]:
        """Saves the Viewer's picture of the current state as the next numbered frame."""
        if not self.save_frames:
            return None
        self._wait_for_viewer_scene_once()
        self.frame_paths.append(self.snapshot_of_now(self._next_frame_name()))
        self.frame_times.append(self.sim_time)
        return self.frame_paths[-1]

    def snapshot_of_now(self, name: str, timeout: float = 10.0) -> pathlib.Path:
        """The Viewer's snapshot ``name`` of the current simulated time: asked again until the
        Viewer answers that it drew this cycle's world update and (contact-less policy, where
        the world publishes one each cycle) its Collided message. The Viewer hears the world
        on topics of its own, a little after this process does, and more after a burst of
        cycles; its colours depend on both messages (viewer.core.scene)."""
        wanted = round(self.sim_time, 6)
        contact_less = self.world_parameters.get("contact_less", False)
        deadline = time.monotonic() + timeout
        while True:
            response = self._snapshot(name=name)
            if not response.success:
                raise ExperimentError(f"/viewer/save_snapshot refused: {response.message}")
            drawn = _t(response.world_update_stamp)
            colours = _t(response.collided_stamp) if contact_less else wanted
            if drawn == wanted and colours == wanted:
                return pathlib.Path(response.path)
            if time.monotonic() > deadline:
                self.check_nodes()
                raise ExperimentError(
                    f"the Viewer still draws the world update of {drawn} s and the Collided "
                    f"message of {colours} s after {timeout} s, not {wanted} s")
            time.sleep(0.005)

    def _next_frame_name(self) -> str:
        return f"frame_{len(self.frame_paths) + 1:04d}.png"

    def _wait_for_viewer_scene_once(self) -> None:
        if not self._viewer_scene_complete:
            self.wait_for_viewer_scene()
            self._viewer_scene_complete = True

    def wait_for_viewer_scene(self, timeout: float = 30.0) -> None:
        """Until the Viewer shows the whole scene: the world hands geometries to the Viewer
        from a queue of its own, so a large scene arrives over a second or two. The world is
        paused between cycles, so the picture stops changing once everything has arrived."""
        import numpy as np
        from sensor_msgs.msg import Image
        deadline = time.monotonic() + timeout
        previous = None
        while time.monotonic() < deadline:
            image = self._rospy.wait_for_message("/viewer/image", Image, timeout=10)
            pixels = np.frombuffer(image.data, np.uint8)
            if previous is not None and np.array_equal(previous, pixels):
                return
            previous = pixels
            time.sleep(0.5)
        raise ExperimentError(f"the Viewer's picture did not settle in {timeout} s")

    def wait_for_contacts(self, timeout: float = 10.0) -> None:
        """Until the Contacts message of the current simulated time has arrived here."""
        self._wait_for_stamp("contacts", "Contacts", timeout)

    def wait_for_collided(self, timeout: float = 10.0) -> None:
        """Until the Collided message of the current simulated time has arrived here."""
        self._wait_for_stamp("collided", "Collided", timeout)

    def finish(self) -> None:
        """Waits for the last cycle's messages; call before reading ``record``."""
        self.wait_for_update()
        if self.world_parameters.get("contact_less", False):
            self.wait_for_collided()
        elif self.want_contacts:
            self.wait_for_contacts()
        self.check_nodes()

    # -- measures ---------------------------------------------------------------------------
    def timing(self) -> dict:
        wall = time.monotonic() - self._started
        rtf = sorted(self.record.rtf)
        return {
            "sim_time_s": round(self.sim_time, 6),
            "cycles": self.cycles,
            "wall_time_s": round(wall, 3),
            "stepping_wall_time_s": round(self.stepping_wall, 3),
            "rtf_stepping": round(self.sim_time / self.stepping_wall, 4)
            if self.stepping_wall > 0 else 0.0,
            "rtf_overall": round(self.sim_time / wall, 4) if wall > 0 else 0.0,
            "world_rtf_median": round(rtf[len(rtf) // 2], 4) if rtf else None,
        }

    def contact_rates(self) -> dict:
        """Contact policy: pairs and contact points reported per cycle, per simulated second."""
        with self.record.lock:
            items = sorted(self.record.contacts.items())
        if not items or self.sim_time <= 0:
            return {"contact_messages": len(items)}
        pairs = sum(p for _, (p, _) in items)
        points = sum(n for _, (_, n) in items)
        return {
            "contact_messages": len(items),
            "contact_pair_reports_per_sim_s": round(pairs / self.sim_time, 3),
            "contact_point_reports_per_sim_s": round(points / self.sim_time, 3),
            "max_pairs_in_a_step": max(p for _, (p, _) in items),
            "cycles_with_contacts": sum(1 for _, (p, _) in items if p > 0),
        }

    def trajectory(self, name: str) -> tuple:
        """(times (n,), positions (n, 3), quaternions (n, 4)) of a tracked geometry."""
        times, poses = self.trajectories(name)
        return (times, *poses[name])

    def trajectories(self, *names: str) -> tuple:
        """(times (n,), {name: (positions (n, 3), quaternions (n, 4))}) of tracked geometries
        at the times every one of them was published: a world update sent between two Build
        Object calls (a paused world publishes at its rate) holds the first geometry and not
        the second, so their own trajectories can differ by a sample, and pairing them index
        by index would compare poses from different cycles."""
        with self.record.lock:
            rows = [(t, poses) for t, poses in sorted(self.record.poses.items())
                    if all(name in poses for name in names)]
        times = np.array([t for t, _ in rows])
        poses = {name: (np.array([p[name][0] for _, p in rows]).reshape(-1, 3),
                        np.array([p[name][1] for _, p in rows]).reshape(-1, 4))
                 for name in names}
        return times, poses


# -- tracked execution, cycle by cycle ---------------------------------------------------------
def session_tracking_port(session: Session, frame_every: int = 0):
    """A ``gui.core.world_port.WorldPort`` (the world node's, gui.ros.world_port) that advances
    ``session`` one Step Once per Portal cycle (so the world publishes every cycle and the
    Viewer's frames keep their numbering: one every ``frame_every`` cycles, none at 0): a
    tracked run's servos are updated once per cycle, its step being the cycle's simulated time.
    Collisions are the pairs of ``~contacts`` (contact policy: ``Session(contacts=True)``),
    first time and deepest depth per cycle."""
    from gui.core.world_port import Collision
    from gui.ros.world_port import ClientWorldPort
    from odin_common.step_values import StepValues

    class SessionPort(ClientWorldPort):
        def step_values(self) -> StepValues:
            if self._step_values is None:
                values = session.client.step_values()
                self._step_values = StepValues(values.cycle_time, 1, values.rate)
            return self._step_values

        def advance(self, duration: float, forces=()) -> list:
            if forces:
                raise ExperimentError("a session's tracked run drives no free-flying base")
            started = session.sim_time
            cycles = max(1, int(round(duration / self.step_values().step)))
            stamps = []
            for _ in range(cycles):
                if frame_every and (session.cycles + 1) % frame_every == 0:
                    session.cycle_and_frame()
                else:
                    session.cycle(1)
                stamps.append(round(session.sim_time, 6))
            self._states.clear()
            if not session.want_contacts:
                return []
            session.wait_for_contacts()
            with session.record.lock:
                return [Collision(a, b, depth, t - started) for t in stamps
                        for a, b, depth in session.record.contact_depths.get(t, [])]

    return SessionPort(session.client)


# -- the problem, as the GUI builds it --------------------------------------------------------
def load_plan(problem_file: pathlib.Path, world: Optional[dict] = None,
              hold_start: bool = True):
    """(problem, BuildPlan) of a Kautham problem file, as ``rosrun GUI load_problem`` plans it.
    ``world``: the experiment's own world (its node's ~parameters): the plan sets these values
    over the problem's, as a load sets every world parameter (docs/INTERFACE.md).
    ``hold_start`` False: the robot's motors left at zero speed, without the servos that hold
    a loaded robot (``BuildDefaults.hold_start``)."""
    from gui.core.translate import BuildDefaults, plan_problem
    from gui.core.kautham.problem import load_problem
    from gui.core.world_settings import with_values
    problem = load_problem(problem_file)
    plan = plan_problem(problem, BuildDefaults(hold_start=hold_start))
    if world:
        plan.set_world(with_values(plan.world, world))
    return problem, plan


def replace_step(plan, name: str, spec) -> None:
    """Replaces the plan's Build Object step named ``name`` by one building ``spec`` (an
    ObjectSpec: the GUI's Objects tab would build the object differently; the rest of the plan
    is sent as loaded)."""
    from gui.core.plan import ObjectStep
    for k, step in enumerate(plan.steps):
        if isinstance(step, ObjectStep) and step.spec.name == name:
            plan.steps[k] = ObjectStep(spec)
            return
    raise ExperimentError(f"the plan has no object named {name!r}")


def cylinder_can(name: str, position, mass: float, color, radius: float, length: float):
    """A can as a cylinder primitive (axis along world z), a movable body (ObjectSpec)."""
    from odin_common.specs import ObjectSpec
    return ObjectSpec(name=name, parameters=(float(radius), float(length)), mass=float(mass),
                      position=tuple(float(v) for v in position),
                      orientation=(1.0, 0.0, 0.0, 0.0), color=tuple(color))


# -- geometry, computed from the meshes the GUI sends (not from the collision engine) ------------
def mesh_bodies(plan) -> dict:
    """{object ID: (vertices (n, 3) in the object's frame, triangles (m, 3))} of every mesh the
    plan builds as a single object (robot links are the objects of a Build Entity)."""
    from odin_common.specs import ObjectSpec
    return {o.id: (np.asarray(o.parameters, float).reshape(-1, 3),
                   np.asarray(o.indices, np.int64).reshape(-1, 3))
            for o in plan.bodies() if isinstance(o, ObjectSpec) and len(o.indices)}


def in_world(vertices: np.ndarray, position, quaternion) -> np.ndarray:
    """Vertices (n, 3) of an object's frame placed at ``position``, ``quaternion`` (wxyz)."""
    from odin_common.rotations import quaternion_to_matrix
    return vertices @ quaternion_to_matrix(quaternion).T + np.asarray(position, float)


def surface_points(vertices: np.ndarray, triangles: np.ndarray, spacing: float) -> np.ndarray:
    """Points on a triangle mesh's surface no further than about ``spacing`` apart along every
    edge: each triangle's barycentric grid of n x n cells, n = its longest edge / spacing."""
    corners = vertices[triangles]                                   # (m, 3, 3)
    edges = np.linalg.norm(corners - np.roll(corners, 1, axis=1), axis=2).max(axis=1)
    counts = np.maximum(1, np.ceil(edges / spacing).astype(int))
    out = [vertices]
    for n in np.unique(counts):
        i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
        keep = i + j <= n
        weights = np.stack([i[keep], j[keep], n - i[keep] - j[keep]], axis=1) / n   # (k, 3)
        out.append(np.einsum("kb,tbc->tkc", weights, corners[counts == n]).reshape(-1, 3))
    return np.concatenate(out)


# -- pictures ---------------------------------------------------------------------------------
def contact_sheet(frames: Sequence[pathlib.Path], times: Sequence[float], out: pathlib.Path,
                  columns: int = 4, rows: int = 3, thumb_width: int = 320) -> pathlib.Path:
    """A ``columns`` x ``rows`` sheet of frames picked evenly, each labelled with its time."""
    from PIL import Image, ImageDraw
    count = min(len(frames), columns * rows)
    if count == 0:
        raise ExperimentError("no frames to put on a contact sheet")
    picks = np.unique(np.linspace(0, len(frames) - 1, count).round().astype(int))
    first = Image.open(frames[0])
    scale = thumb_width / first.width
    tw, th = thumb_width, int(round(first.height * scale))
    sheet = Image.new("RGB", (columns * tw, rows * th), (255, 255, 255))
    draw = ImageDraw.Draw(sheet)
    for k, index in enumerate(picks):
        image = Image.open(frames[index]).convert("RGB").resize((tw, th), Image.LANCZOS)
        x, y = (k % columns) * tw, (k // columns) * th
        sheet.paste(image, (x, y))
        label = f"#{index + 1}  t = {times[index]:.3f} s"
        draw.rectangle([x, y, x + 8 + 7 * len(label), y + 16], fill=(255, 255, 255))
        draw.text((x + 4, y + 2), label, fill=(0, 0, 0))
    sheet.save(out)
    return out


def animation(frames: Sequence[pathlib.Path], out: pathlib.Path, frame_ms: int = 120,
              width: int = 400) -> pathlib.Path:
    """An animated GIF of every frame (scaled to ``width`` px)."""
    from PIL import Image
    images = []
    for path in frames:
        image = Image.open(path).convert("RGB")
        height = int(round(image.height * width / image.width))
        images.append(image.resize((width, height), Image.LANCZOS).quantize(colors=128))
    images[0].save(out, save_all=True, append_images=images[1:], duration=frame_ms, loop=0)
    return out


def write_summary(session: Session, facts: dict, parameters: dict) -> pathlib.Path:
    """``summary.json``: measured facts, the world's parameters, timing and the pictures."""
    pictures = {}
    if session.frame_paths:
        pictures["frames"] = len(session.frame_paths)
        pictures["contact_sheet"] = str(contact_sheet(
            session.frame_paths, session.frame_times, session.out / "contact_sheet.png")
            .relative_to(ROOT))
        pictures["animation"] = str(animation(session.frame_paths, session.out / "animation.gif")
                                    .relative_to(ROOT))
    summary = {"experiment": session.name, **facts, "timing": session.timing(),
               "parameters": parameters, "world_node_parameters": session.world_parameters,
               "pictures": pictures}
    path = session.out / "summary.json"
    path.write_text(json.dumps(_plain(summary), indent=2) + "\n")
    return path


def _plain(value):
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, (np.floating, float)):
        return None if not math.isfinite(float(value)) else float(value)
    if isinstance(value, (np.integer,)):
        return int(value)
    if isinstance(value, np.bool_):
        return bool(value)
    return value
