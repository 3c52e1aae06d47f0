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
        previous one, thesis 6.4.2).
    ``<~world>/markers`` (visualization_msgs/MarkerArray): geometries the Viewer does not hold
        are added from the world's markers, so a rosbag played back drives the Viewer with no
        world running (viewer.portal.markers).

Published topics
    ``~image`` (sensor_msgs/Image): every rendered frame, rgb8, ``~width`` x ``~height``,
        at ``~rate``; header.stamp = wall time of rendering, frame_id ``odin_camera``.

Services
    ``~view_object`` (Services/ViewObject): add an object, or replace the one with that ID (the
        world may re-send its scene to a Viewer that started late). Refused: empty ID, a
        parameter count that is no shape, sizes <= 0, empty mesh, index out of range, NaN
        position, a quaternion that is not finite or whose norm is off 1 by more than 1e-3
        (odin_common.rotations.QUATERNION_TOLERANCE),
        colour outside [0, 1].
    ``~remove_object`` (Services/ViewerRemoveObject): refused for an unknown ID.
    ``~new_scene`` (Services/ViewerNewScene): empty the scene (the camera stays).
    ``~save_snapshot`` (Services/SaveSnapshot): render now and write ``<~snapshot_dir>/<name>``
        (".png" added); names with '/', "..", absolute paths and symbolic links are refused.
    ``~set_camera`` (Services/SetCamera): pose (fixes the camera), re-fit, image size, field of
        view; answers the camera now in use.

Parameters: ``viewer.portal.parameters.NODE_PARAMETERS`` (``~world``, ``~rate``, ``~width``,
``~height``, ``~fov_y``, ``~eye``, ``~target``, ``~up``, ``~background``, ``~snapshot_dir``,
``~snapshot_every``), with units and defaults in docs/parameters.md.
"""
from __future__ import annotations

import math
import os
import pathlib
from typing import Optional

import rospy
import rospkg
from sensor_msgs.msg import Image
from visualization_msgs.msg import MarkerArray

from Messages.msg import Collided, SpaceDistribution
from Services.srv import (SaveSnapshot, SaveSnapshotResponse, SetCamera, SetCameraResponse,
                          ViewerNewScene, ViewerNewSceneResponse, ViewerRemoveObject,
                          ViewerRemoveObjectResponse, ViewObject, ViewObjectResponse)
from odin_common import OdinError
from odin_common.node import MasterWatch, init_ros_node
from viewer.core.camera import Camera
from viewer.errors import ViewerError
from viewer.core.loop import RenderLoop
from viewer.core.scene import Scene, prepare_view
from viewer.portal.markers import IDENTITY, MarkerIntake
from viewer.portal.parameters import DEFAULTS
from viewer.core.snapshots import FrameWriter, snapshot_path, write_png

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
        self.snapshot_dir.mkdir(parents=True, exist_ok=True)
        self.snapshot_every = int(rospy.get_param("~snapshot_every", DEFAULTS["snapshot_every"]))
        self.frame_writer = FrameWriter(self.snapshot_dir) if self.snapshot_every > 0 else None

        self.image_pub = rospy.Publisher("~image", Image, queue_size=2)
        from viewer.core.renderer import Renderer  # GL only in the render thread's process
        self.loop = RenderLoop(Scene(camera, camera_fixed=fixed, background=background),
                               lambda: Renderer(camera.width, camera.height), rate,
                               on_frame=self._on_frame)
        self.loop.start()

        rospy.Service("~view_object", ViewObject, self._view_object)
        rospy.Service("~remove_object", ViewerRemoveObject, self._remove_object)
        rospy.Service("~new_scene", ViewerNewScene, self._new_scene)
        rospy.Service("~save_snapshot", SaveSnapshot, self._save_snapshot)
        rospy.Service("~set_camera", SetCamera, self._set_camera)
        rospy.Subscriber(f"{world}/world_update", SpaceDistribution, self._world_update,
                         queue_size=10)
        rospy.Subscriber(f"{world}/collided", Collided, self._collided, queue_size=10)
        self._marker_intake = MarkerIntake()
        rospy.Subscriber(f"{world}/markers", MarkerArray, self._markers, queue_size=10)
        rospy.loginfo("viewer: rendering %dx%d at %.1f Hz, world %s, snapshots in %s",
                      camera.width, camera.height, rate, world, self.snapshot_dir)

    def close(self) -> None:
        self.loop.stop()
        if self.frame_writer is not None:
            self.frame_writer.close()

    # -- frames ----------------------------------------------------------------------------
    def _on_frame(self, frame, number: int) -> None:
        height, width = frame.shape[:2]
        msg = Image(height=height, width=width, encoding="rgb8", is_bigendian=0,
                    step=width * 3, data=frame.tobytes())
        msg.header.stamp = rospy.Time.now()
        msg.header.frame_id = FRAME_ID
        msg.header.seq = number
        self.image_pub.publish(msg)
        if self.frame_writer is not None and number % self.snapshot_every == 0:
            self.frame_writer.put(frame)

    # -- topics ----------------------------------------------------------------------------
    def _world_update(self, msg: SpaceDistribution) -> None:
        situations = [(s.name, tuple(s.position), tuple(s.orientation)) for s in msg.situations]
        self.loop.post(lambda scene, _: scene.update(situations))

    def _markers(self, msg: MarkerArray) -> None:
        def apply(scene: Scene, _) -> None:
            views, removals = self._marker_intake.changes(msg.markers, scene.__contains__)
            for object_id in removals:
                if object_id in scene:
                    scene.remove_object(object_id)
            for object_id, parameters, indices, shape, color in views:
                try:
                    scene.view(prepare_view(object_id, parameters, indices, *IDENTITY, color,
                                            shape))
                except OdinError as error:   # a marker that is no geometry the Viewer takes
                    rospy.logwarn("viewer: marker %r not drawn: %s", object_id, error)
        self.loop.post(apply)

    def _collided(self, msg: Collided) -> None:
        names = list(msg.names)
        self.loop.post(lambda scene, _: scene.collided(names))

    # -- services --------------------------------------------------------------------------
    def _answer(self, response_type, fn, **extra):
        """Runs fn() and turns an OdinError (or anything unexpected) into success: false."""
        try:
            message = fn() or ""
            return response_type(success=True, message=message, **extra)
        except OdinError as error:
            return response_type(success=False, message=str(error), **extra)
        except Exception as error:  # a bug must not take the node down; say what happened
            rospy.logerr("viewer: %s failed: %r", response_type.__name__, error)
            return response_type(success=False, message=f"internal error: {error!r}", **extra)

    def _view_object(self, req) -> ViewObjectResponse:
        def work():
            request = prepare_view(req.id, req.parameters, req.indices, req.position,
                                   req.orientation, req.color, req.shape)   # on this thread
            replaced = self.loop.call(lambda scene, _: scene.view(request))
            return f"replaced {req.id!r}" if replaced else f"added {req.id!r}"
        return self._answer(ViewObjectResponse, work)

    def _remove_object(self, req) -> ViewerRemoveObjectResponse:
        def work():
            self.loop.call(lambda scene, _: scene.remove_object(req.id))
            return f"removed {req.id!r}"
        return self._answer(ViewerRemoveObjectResponse, work)

    def _new_scene(self, req) -> ViewerNewSceneResponse:
        return self._answer(ViewerNewSceneResponse,
                            lambda: self.loop.call(lambda scene, _: scene.new_scene()))

    def _save_snapshot(self, req) -> SaveSnapshotResponse:
        written = []

        def work():
            path = snapshot_path(self.snapshot_dir, req.name)
            frame = self.loop.call(lambda scene, renderer: renderer.render(scene))
            written.append(str(write_png(path, frame)))
            return f"wrote {written[0]}"
        response = self._answer(SaveSnapshotResponse, work)
        response.path = written[0] if written else ""
        return response

    def _set_camera(self, req) -> SetCameraResponse:
        def apply(scene: Scene, _) -> Camera:
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

        state = []

        def work():
            state.extend(self.loop.call(apply))
        response = self._answer(SetCameraResponse, work)
        camera, fitting = state if state else self.loop.call(
            lambda scene, _: (scene.camera, scene.fitting))
        response.eye, response.target, response.up = camera.eye_W, camera.target_W, camera.up_W
        response.width, response.height, response.fov_y = camera.width, camera.height, camera.fov_y
        response.fitting = fitting
        return response


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
