"""The Viewer node's Portal: ROS topics and services wired to the Core (thesis chapter 6.3).

Node ``viewer``. One render thread owns the scene and the OpenGL (OSMesa) context; service and
subscriber callbacks hand their work to it. A service answers after its change has been applied
(or refused) on that thread, so the answer is the truth; nothing a caller sends ends the node.

Subscribed topics
    ``<~world>/world_update`` (Messages/SpaceDistribution): poses of the scene's geometries;
        names the Viewer does not hold (yet) are ignored, entries with a NaN position or a bad
        quaternion are skipped.
    ``<~world>/collided`` (Messages/Collided): geometries drawn dark grey until the second
        world update after the message (grey after an update exactly when listed since the
        previous one, thesis 6.4.2); an update with the previous one's stamp (a paused world
        repeating its cycle) starts no new colouring cycle. Queue of 1,000: a burst of cycles
        loses no collision.
    ``<~world>/markers`` (visualization_msgs/MarkerArray): geometries the Viewer does not hold
        are added from the world's markers, so a rosbag played back drives the Viewer with no
        world running (viewer.portal.markers); taken MARKER_GRACE (1 s) after they arrive, when
        a live world's View Object for the same geometries has come.

Published topics
    ``~image`` (sensor_msgs/Image): every rendered frame, rgb8, ``~width`` x ``~height``,
        at ``~rate``; header.stamp = wall time of rendering, frame_id ``odin_camera``.
    ``~image/compressed`` (sensor_msgs/CompressedImage): the same frames as JPEG (format
        ``rgb8; jpeg compressed bgr8``, as image_transport's compressed plugin names them),
        about 1/20 of the raw bytes: the topic to record (docs/ROS.md, rosbag).
    Frames are rendered only while one of the two topics has a subscriber or ``~snapshot_every``
    writes frames (Save Snapshot always renders): an unwatched Viewer costs no CPU, and each
    topic is encoded only for its own subscribers.

Services (odin_common.interface.VIEWER_SERVICES, each answered by the Portal's method of the
same name)
    ``~view_object`` (Services/ViewObject): add an object, or replace the one with that ID (the
        world may re-send its scene to a Viewer that started late, and does on every problem
        load: meshes are kept by content, viewer.core.geometry.GeometryCache, so the same
        mesh sent again is not built again). Checked whole before the scene or the camera
        changes (a refusal changes nothing): refused are an ID that is no name
        (odin_common.limits.check_name: empty, over 256 bytes, NUL, newline...), a parameter
        count that is no shape, sizes outside [MIN_SIZE, MAX_SIZE], an empty mesh, an index
        out of range, a position or mesh vertex not finite or beyond MAX_EXTENT (the widest
        world_extent; viewer.core.geometry), a quaternion that is not finite or whose norm is
        off 1 by more than 1e-3 (odin_common.rotations.QUATERNION_TOLERANCE), a colour outside
        [0, 1].
    ``~remove_object`` (Services/ViewerRemoveObject): refused for an unknown ID.
    ``~new_scene`` (Services/ViewerNewScene): empty the scene (the camera stays).
    ``~save_snapshot`` (Services/SaveSnapshot): render now and write ``<~snapshot_dir>/<name>``
        (".png" added); names that are no name (check_name), names with '/', "..", a file name
        over 255 bytes with its ".png", and symbolic links are refused. The file is written
        whole or not at all (a temporary file renamed onto the name): a full disk leaves an
        older file of that name as it was and answers one line with the cause.
        Answers the stamps of the last world update and Collided message the frame shows.
    ``~set_camera`` (Services/SetCamera): pose (fixes the camera), re-fit, image size, field of
        view; answers the camera now in use.

``~snapshot_every`` frames are written the same way; while the disk is full no frame file is
left, one warning a minute says so, and frames are written again once there is room.

Parameters: ``viewer.portal.parameters.NODE_PARAMETERS`` (``~world``, ``~rate``, ``~width``,
``~height``, ``~fov_y``, ``~eye``, ``~target``, ``~up``, ``~background``, ``~snapshot_dir``,
``~snapshot_every``), with units and defaults in docs/parameters.md.
"""
from __future__ import annotations

import math
import os
import pathlib
from typing import Optional, Tuple

import rospy
import rospkg
from sensor_msgs.msg import CompressedImage, Image

from Messages.msg import Collided, SpaceDistribution
from Services import srv
from odin_common import OdinError, replies
from odin_common.interface import VIEWER_SERVICES
from odin_common.node import MasterWatch, init_ros_node, numpy_requests
from viewer.core.camera import Camera
from viewer.core.geometry import GeometryCache
from viewer.errors import ViewerError
from viewer.core.loop import RenderLoop
from viewer.core.scene import Scene, prepare_view
from viewer.portal.markers import (IDENTITY, MARKER_GRACE, MarkerIntake, RawMarkerArray,
                                   read_markers)
from viewer.portal.parameters import DEFAULTS
from viewer.core.snapshots import (COMPRESSED_FORMAT, FrameWriter, encode_jpeg, snapshot_path,
                                   write_png)

FRAME_ID = "odin_camera"


def _vector(name: str, value, size: int = 3) -> Optional[tuple]:
    if value is None:
        return None
    try:
        out = tuple(float(v) for v in value)
    except (TypeError, ValueError):
        raise ViewerError(f"parameter {name}: expected {size} numbers, got {value!r}") from None
    if len(out) != size or not all(math.isfinite(v) for v in out):
        raise ViewerError(f"parameter {name}: expected {size} finite numbers, got {value!r}")
    return out


def _stamp_seconds(header) -> Optional[float]:
    """The header's stamp (s), None for a zero stamp: ROS's "no time" (a message a user's tool
    publishes without one), which the scene orders by arrival."""
    return header.stamp.to_sec() if not header.stamp.is_zero() else None


def default_snapshot_dir() -> pathlib.Path:
    return pathlib.Path(rospkg.get_ros_home()) / "odin_snapshots"


class Portal:
    """Reads the node's parameters, starts the render loop and serves the topics/services."""

    def __init__(self) -> None:
        world = rospy.get_param("~world", DEFAULTS["world"]).rstrip("/")
        rate = float(rospy.get_param("~rate", DEFAULTS["rate"]))
        eye = _vector("~eye", rospy.get_param("~eye", DEFAULTS["eye"]))
        target = _vector("~target", rospy.get_param("~target", DEFAULTS["target"]))
        up = _vector("~up", rospy.get_param("~up", DEFAULTS["up"]))
        camera = Camera(width=int(rospy.get_param("~width", DEFAULTS["width"])),
                        height=int(rospy.get_param("~height", DEFAULTS["height"])),
                        fov_y=float(rospy.get_param("~fov_y", DEFAULTS["fov_y"])), up_W=up)
        fixed = eye is not None and target is not None
        if fixed:
            camera = camera.with_(eye_W=eye, target_W=target)
        background = _vector("~background", rospy.get_param("~background",
                                                            DEFAULTS["background"]))
        self.snapshot_dir = pathlib.Path(os.path.expanduser(
            rospy.get_param("~snapshot_dir", str(default_snapshot_dir())))).resolve()
        try:
            self.snapshot_dir.mkdir(parents=True, exist_ok=True)
        except OSError as error:      # a file in the way, no permission, a full disk
            raise ViewerError(f"~snapshot_dir {self.snapshot_dir}: cannot make the folder: "
                              f"{error.strerror or error}") from None
        self.snapshot_every = int(rospy.get_param("~snapshot_every", DEFAULTS["snapshot_every"]))
        self.frame_writer = FrameWriter(self.snapshot_dir) if self.snapshot_every > 0 else None
        self.geometries = GeometryCache()   # a world re-sends the same meshes on every load

        self.image_pub = rospy.Publisher("~image", Image, queue_size=2)
        self.compressed_pub = rospy.Publisher("~image/compressed", CompressedImage, queue_size=2)
        from viewer.core.renderer import Renderer  # GL only in the render thread's process
        self.loop = RenderLoop(Scene(camera, camera_fixed=fixed, background=background),
                               lambda: Renderer(camera.width, camera.height), rate,
                               on_frame=self._on_frame, wanted=self._frames_wanted)
        self.loop.start()

        self._marker_intake = MarkerIntake()
        self._serve()
        rospy.Subscriber(f"{world}/world_update", SpaceDistribution, self._world_update,
                         queue_size=10)
        rospy.Subscriber(f"{world}/collided", Collided, self._collided, queue_size=1000)
        rospy.Subscriber(f"{world}/markers", RawMarkerArray, self._markers, queue_size=10)
        rospy.loginfo("viewer: rendering %dx%d at %.1f Hz, world %s, snapshots in %s",
                      camera.width, camera.height, rate, world, self.snapshot_dir)

    def close(self) -> None:
        self.loop.stop()
        if self.frame_writer is not None:
            self.frame_writer.close()

    # -- frames ----------------------------------------------------------------------------
    def _frames_wanted(self) -> bool:
        return (self.frame_writer is not None or self.image_pub.get_num_connections() > 0
                or self.compressed_pub.get_num_connections() > 0)

    def _on_frame(self, frame, number: int) -> None:
        height, width = frame.shape[:2]
        stamp = rospy.Time.now()
        if self.image_pub.get_num_connections() > 0:
            msg = Image(height=height, width=width, encoding="rgb8", is_bigendian=0,
                        step=width * 3, data=frame.tobytes())
            self._stamp(msg.header, stamp, number)
            self.image_pub.publish(msg)
        if self.compressed_pub.get_num_connections() > 0:
            msg = CompressedImage(format=COMPRESSED_FORMAT, data=encode_jpeg(frame))
            self._stamp(msg.header, stamp, number)
            self.compressed_pub.publish(msg)
        if self.frame_writer is not None and number % self.snapshot_every == 0:
            self.frame_writer.put(frame)

    @staticmethod
    def _stamp(header, stamp, number: int) -> None:
        header.stamp = stamp
        header.frame_id = FRAME_ID
        header.seq = number

    # -- topics ----------------------------------------------------------------------------
    def _world_update(self, msg: SpaceDistribution) -> None:
        situations = [(s.name, tuple(s.position), tuple(s.orientation)) for s in msg.situations]
        stamp = _stamp_seconds(msg.header)
        self.loop.post(lambda scene, _: scene.update(situations, stamp))

    def _markers(self, msg: RawMarkerArray) -> None:
        try:
            markers = read_markers(msg.raw)
        except ViewerError as error:
            rospy.logwarn("viewer: markers not read: %s", error)
            return

        def apply(scene: Scene, _) -> None:
            views, removals = self._marker_intake.changes(markers, scene.__contains__)
            for object_id in removals:
                if object_id in scene:
                    scene.remove_object(object_id)
            for object_id, parameters, indices, shape, color in views:
                try:
                    scene.view(prepare_view(object_id, parameters, indices, *IDENTITY, color,
                                            shape, self.geometries))
                except OdinError as error:   # a marker that is no geometry the Viewer takes
                    rospy.logwarn("viewer: marker %r not drawn: %s", object_id, error)
        self.loop.post_later(MARKER_GRACE, apply)

    def _collided(self, msg: Collided) -> None:
        names = list(msg.names)
        stamp = _stamp_seconds(msg.header)
        self.loop.post(lambda scene, _: scene.collided(names, stamp))

    # -- services --------------------------------------------------------------------------
    def _serve(self) -> None:
        """One server per Viewer service (VIEWER_SERVICES), each answered by the method of the
        same name (odin_common.replies.guarded: a refusal answers ``success: false``); Set
        Camera also answers the camera in use when it refuses."""
        in_force = {"set_camera": self._camera_in_use}
        self.servers = []
        for name, type_name in VIEWER_SERVICES.items():
            service_class = getattr(srv, type_name)
            served = numpy_requests(service_class) if name in NUMPY_REQUESTS else service_class
            self.servers.append(rospy.Service(
                f"~{name}", served,
                replies.guarded(service_class, getattr(self, name), in_force.get(name, dict))))

    def view_object(self, req) -> dict:
        """Adds the object, or replaces the one with its ID (checked on the server's thread)."""
        request = prepare_view(req.id, req.parameters, req.indices, req.position,
                               req.orientation, req.color, req.shape,
                               self.geometries)   # on this thread
        replaced = self.loop.call(lambda scene, _: self._owned(scene.view(request), [req.id]))
        return {"message": f"replaced {req.id!r}" if replaced else f"added {req.id!r}"}

    def remove_object(self, req) -> dict:
        """Removes the object; an unknown ID is refused."""
        self.loop.call(lambda scene, _: self._owned(scene.remove_object(req.id), [req.id]))
        return {"message": f"removed {req.id!r}"}

    def new_scene(self, req) -> dict:
        """Empties the scene (the camera stays)."""
        self.loop.call(lambda scene, _: self._owned(scene.new_scene(),
                                                    list(self._marker_intake.added)))
        return {}

    def _owned(self, result, object_ids):
        """``result``, once the markers' intake has forgotten ``object_ids`` (on the render
        thread, which alone touches it): what the services changed, markers no longer do."""
        self._marker_intake.forget(object_ids)
        return result

    def save_snapshot(self, req) -> dict:
        """Renders now and writes ``<~snapshot_dir>/<name>.png``; answers the path written and
        the stamps of the last world update and Collided message the frame shows."""
        path = snapshot_path(self.snapshot_dir, req.name)
        frame, update_stamp, collided_stamp = self.loop.call(
            lambda scene, renderer: (renderer.render(scene), scene.update_stamp,
                                     scene.collided_stamp))
        written = str(write_png(path, frame))
        return {"message": f"wrote {written}", "path": written,
                "world_update_stamp": rospy.Time.from_sec(update_stamp or 0.0),
                "collided_stamp": rospy.Time.from_sec(collided_stamp or 0.0)}

    def set_camera(self, req) -> dict:
        """Sets the camera's size, field of view, pose or fitting; answers the camera in use."""
        def apply(scene: Scene, _) -> Tuple[Camera, bool]:
            camera = scene.camera
            if req.set_size:
                camera = camera.with_(width=req.width, height=req.height)
            if req.set_fov:
                camera = camera.with_(fov_y=req.fov_y)
            if req.set_pose and req.fit_scene:
                raise ViewerError("set_pose and fit_scene both set: fix the camera or release it")
            if req.set_pose:
                camera = camera.with_(eye_W=tuple(req.eye), target_W=tuple(req.target),
                                      up_W=tuple(req.up))
            fixed = True if req.set_pose else (False if req.fit_scene else None)
            scene.set_camera(camera, fixed)
            return scene.camera, scene.fitting
        return _camera_fields(*self.loop.call(apply))

    def _camera_in_use(self) -> dict:
        """Set Camera's fields as the camera is now (what a refusal answers)."""
        return _camera_fields(*self.loop.call(lambda scene, _: (scene.camera, scene.fitting)))


#: services whose requests arrive with their arrays as numpy views of the received bytes:
#: a View Object of a mesh is hundreds of thousands of numbers, a Python float each otherwise
#: (0.06 s for the TX90 grasp scene's meshes, on every load)
NUMPY_REQUESTS = frozenset({"view_object"})


def _camera_fields(camera: Camera, fitting: bool) -> dict:
    """Set Camera's answer: the camera in use (m, world frame; pixels; rad)."""
    return {"eye": camera.eye_W, "target": camera.target_W, "up": camera.up_W,
            "width": camera.width, "height": camera.height, "fov_y": camera.fov_y,
            "fitting": fitting}


def main() -> None:
    init_ros_node("viewer")
    MasterWatch()
    try:
        portal = Portal()
    except OdinError as error:
        rospy.logfatal("viewer: %s", error)
        raise SystemExit(1)
    rospy.on_shutdown(portal.close)
    rospy.spin()
