"""The Viewer's Core: the scene of objects keyed by ID, without ROS and without OpenGL
(thesis chapter 6.4).

Each object has a pose (world frame, REP 103), a colour and a shape. Its original colour is
remembered: an object that a Collided message lists is drawn in ``COLLIDING_COLOR`` at once, and
stays so until the second scene update after that message, i.e. after every update an object is
grey exactly when some Collided message listed it since the previous update (thesis 6.4.2: the
colliding status is cleared each cycle). With stamps (simulated time), "since" is the world's
order, not the order of arrival: the two topics reach the Viewer on threads of their own, and
after a burst of cycles one runs ahead of the other. After an update stamped u, following one
stamped p, an object is grey exactly when a Collided message stamped p or later lists it; a
message whose stamp is before p comes too late to colour anything. An update with the stamp of
the one before is the same cycle told again (a paused world repeats its last cycle at its
rate): it moves objects but starts no new colouring cycle. An update whose stamp goes back (a
bag played in a loop) starts the colouring afresh. Unstamped updates and messages keep the
order of arrival. The scene remembers the stamps of the last update and Collided message it
applied: which simulated time a frame shows. New Scene replaces the whole scene. Adding an
object re-fits the camera to the whole scene unless the user fixed the camera.

The scene is not thread-safe: one thread (the Portal's render thread) owns it.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Iterable, Optional, Sequence

import numpy as np

# DEFAULT_COLOR: an object sent with an all-zero colour; COLLIDING_COLOR: while reported as
# colliding (thesis 6.4.1: "dark gray"); shared with the world's RViz markers
from odin_common.errors import InvalidArgument
from odin_common.defaults import COLLIDING_COLOR, DEFAULT_COLOR
from odin_common.limits import check_name, shown
from viewer.core.camera import Camera
from viewer.errors import ViewerError
from viewer.core.geometry import (Geometry, GeometryCache, geometry_from_parameters,
                                  pose_matrices, pose_matrix)

#: default background (r, g, b)
DEFAULT_BACKGROUND = (0.93, 0.94, 0.96)


def check_color(color: Sequence[float], where: str = "color") -> tuple:
    """(r, g, b, a) in [0, 1]; all zero means ``DEFAULT_COLOR``; 3 numbers mean a = 1."""
    c = np.asarray(color, dtype=float).reshape(-1)
    if c.size == 3:
        c = np.r_[c, 1.0]
    if c.shape != (4,) or not np.all((c >= 0) & (c <= 1)):        # False for NaN too
        raise ViewerError(f"{where}: expected r, g, b, a in [0, 1], got {shown(c)}")
    if not np.any(c):
        return DEFAULT_COLOR
    return tuple(float(v) for v in c)


def check_id(object_id: str) -> str:
    """``object_id`` if it is a valid name (odin_common.limits.check_name: non-empty, at
    most MAX_NAME_BYTES, printable: no NUL, no newline), else :class:`ViewerError`."""
    try:
        return check_name("object ID", object_id)
    except InvalidArgument as error:
        raise ViewerError(str(error)) from None


@dataclass(frozen=True)
class ViewRequest:
    """A checked View Object request: id, shape, pose T_WB (4, 4) and colour (r, g, b, a)."""
    id: str
    geometry: Geometry
    pose_W: np.ndarray
    color: tuple


def prepare_view(object_id: str, parameters: Sequence[float], indices: Sequence[int],
                 position_W: Sequence[float], orientation_wxyz: Sequence[float],
                 color: Sequence[float], shape: int = 0,
                 cache: Optional[GeometryCache] = None) -> ViewRequest:
    """Checks a View Object request and builds its geometry (no scene needed, so a service
    callback can do it on its own thread), or takes it from ``cache`` when that content was
    built before. Everything is checked here (ID, sizes, mesh, pose, colour: geometry's
    MIN_SIZE, MAX_SIZE and MAX_EXTENT), so that a request the scene takes can change nothing
    it cannot hold. Raises :class:`ViewerError` if anything is wrong."""
    object_id = check_id(object_id)
    where = f"object {shown(object_id)}"
    build = geometry_from_parameters if cache is None else cache.geometry
    try:
        geometry = build(parameters, indices, shape)
    except ViewerError as error:
        raise ViewerError(f"{where}: {error}") from None
    return ViewRequest(object_id, geometry, pose_matrix(position_W, orientation_wxyz, where),
                       check_color(color, f"{where} color"))


@dataclass
class SceneObject:
    id: str
    geometry: Geometry
    pose_W: np.ndarray          # T_WB (4, 4)
    color: tuple                # original colour (r, g, b, a)


@dataclass(frozen=True)
class DrawItem:
    """One object to draw: geometry, model matrix (4, 4) body->world including the primitive's
    scale, and the colour to draw it in now."""
    id: str
    geometry: Geometry
    model_W: np.ndarray
    color: tuple


@dataclass(frozen=True)
class Grid:
    """A floor grid on the world's z = 0 plane: centre (x, y) m, half size m, line spacing m."""
    centre_xy: tuple
    half_size: float
    spacing: float


class Scene:
    """Objects keyed by ID, the collision colouring and the camera."""

    def __init__(self, camera: Optional[Camera] = None, camera_fixed: bool = False,
                 background: Sequence[float] = DEFAULT_BACKGROUND) -> None:
        self._objects: dict = {}
        self._grey: set = set()
        self._forget_collisions()
        self.collided_stamp: Optional[float] = None   # s, the last Collided message's
        self._camera = camera or Camera()
        self.camera_fixed = camera_fixed
        bg = np.asarray(background, dtype=float).reshape(-1)
        if bg.shape != (3,) or not np.all((bg >= 0) & (bg <= 1)):
            raise ViewerError(f"background: expected r, g, b in [0, 1], got {list(bg)}")
        self.background = tuple(float(v) for v in bg)

    # -- objects ---------------------------------------------------------------------------
    def __len__(self) -> int:
        return len(self._objects)

    def __contains__(self, object_id: str) -> bool:
        return object_id in self._objects

    @property
    def ids(self) -> list:
        return list(self._objects)

    def view(self, request: ViewRequest) -> bool:
        """Adds the object, or replaces the one with the same ID (the world may re-send its scene
        to a Viewer that started late). Returns True if it replaced one. Re-fits the camera.
        All or nothing: the camera is fitted to the scene with the object before either
        changes, so a refusal leaves the scene and the camera as they were."""
        added = SceneObject(request.id, request.geometry, np.array(request.pose_W, dtype=float),
                            request.color)
        camera = self._camera
        if not self.camera_fixed:
            others = (o for o in self._objects.values() if o.id != request.id)
            camera = self._fitted(camera, [*others, added])
        replaced = request.id in self._objects
        self._objects[request.id] = added
        self._camera = camera
        return replaced

    def view_object(self, object_id: str, parameters: Sequence[float], indices: Sequence[int] = (),
                    position_W: Sequence[float] = (0, 0, 0),
                    orientation_wxyz: Sequence[float] = (1, 0, 0, 0),
                    color: Sequence[float] = (0, 0, 0, 0), shape: int = 0) -> bool:
        """:func:`prepare_view` and :meth:`view` in one call."""
        return self.view(prepare_view(object_id, parameters, indices, position_W,
                                      orientation_wxyz, color, shape))

    def remove_object(self, object_id: str) -> None:
        if object_id not in self._objects:
            raise ViewerError(f"no object {shown(object_id)} in the Viewer's scene "
                              f"({len(self._objects)} objects)")
        del self._objects[object_id]
        self._grey.discard(object_id)
        for names in self._listed.values():
            names.discard(object_id)

    def new_scene(self) -> None:
        """Replaces the scene by an empty one (the camera stays where it is)."""
        self._objects = {}
        self._grey = set()
        self._forget_collisions()
        self.collided_stamp = None

    def _forget_collisions(self) -> None:
        # names listed by Collided messages whose colouring cycles are not over, by stamp (s;
        # None for unstamped messages): those stamped at or after the current update's
        self._listed: dict = {}
        self.update_stamp: Optional[float] = None     # s, the last update's; None: none yet
        self._previous_stamp: Optional[float] = None  # s, the update's before it

    # -- the world's topics ----------------------------------------------------------------
    def update(self, situations: Iterable, stamp: Optional[float] = None) -> int:
        """Applies poses ``(name, position (3,) m, orientation (w, x, y, z))``; names the scene
        does not hold and entries with a non-finite or bad pose are skipped. Ends a colouring
        cycle (see the module doc) unless ``stamp`` (s, simulated time) is the last update's.
        Returns the number of poses applied."""
        applied = self._apply_poses([s for s in situations if s[0] in self._objects])
        if stamp is not None and self.update_stamp is not None:
            if stamp == self.update_stamp:
                return applied                  # the same cycle told again
            if stamp < self.update_stamp:
                self._forget_collisions()       # time went back: nothing listed still counts
        self._grey = set().union(*self._listed.values()) & self._objects.keys()
        self._listed = {listed_at: names for listed_at, names in self._listed.items()
                        if None not in (listed_at, stamp) and listed_at >= stamp}
        self._previous_stamp, self.update_stamp = self.update_stamp, stamp
        return applied

    def _apply_poses(self, held: list) -> int:
        """Poses of objects the scene holds, all at once (the world's 25 Hz updates of every
        geometry were a quarter of the Viewer's CPU one at a time); one by one when they do
        not make arrays (sizes that differ: bad entries, skipped)."""
        try:
            positions = np.array([position for _, position, _ in held], dtype=float)
            quaternions = np.array([orientation for _, _, orientation in held], dtype=float)
            poses, valid = pose_matrices(positions.reshape(len(held), 3),
                                         quaternions.reshape(len(held), 4))
        except (TypeError, ValueError):
            return sum(self._apply_pose(*situation) for situation in held)
        for (name, _, _), pose, ok in zip(held, poses, valid):
            if ok:
                self._objects[name].pose_W = pose
        return int(valid.sum())

    def _apply_pose(self, name: str, position, orientation) -> bool:
        try:
            self._objects[name].pose_W = pose_matrix(position, orientation, name)
        except ViewerError:
            return False
        return True

    def collided(self, names: Iterable[str], stamp: Optional[float] = None) -> None:
        """Objects a Collided message (stamped ``stamp`` s) lists: grey now and through the
        next update of another stamp."""
        self.collided_stamp = stamp
        names = set(names) & self._objects.keys()
        if None not in (stamp, self._previous_stamp) and stamp < self._previous_stamp:
            return                              # its colouring cycles are over
        self._grey |= names
        if None in (stamp, self.update_stamp) or stamp >= self.update_stamp:
            self._listed.setdefault(stamp, set()).update(names)

    def color_of(self, object_id: str) -> tuple:
        """The colour the object is drawn in now."""
        if object_id not in self._objects:
            raise ViewerError(f"no object {shown(object_id)} in the Viewer's scene")
        return COLLIDING_COLOR if object_id in self._grey else self._objects[object_id].color

    def pose_of(self, object_id: str) -> np.ndarray:
        return self._objects[object_id].pose_W.copy()

    def draw_list(self) -> list:
        items = []
        for obj in self._objects.values():
            model = obj.pose_W @ np.diag([*obj.geometry.scale_B, 1.0])
            items.append(DrawItem(obj.id, obj.geometry, model, self.color_of(obj.id)))
        return items

    # -- bounds and camera -----------------------------------------------------------------
    def bounds(self) -> Optional[tuple]:
        """(centre (3,) m, radius m) of a sphere holding every bounded object (planes are
        infinite), or None if there is none."""
        return _bounds(self._objects.values())

    @property
    def camera(self) -> Camera:
        return self._camera

    @property
    def fitting(self) -> bool:
        return not self.camera_fixed

    def fit_camera(self) -> None:
        """Moves the camera to show the whole scene (nothing to do for an empty scene)."""
        self._camera = self._fitted(self._camera, self._objects.values())

    @staticmethod
    def _fitted(camera: Camera, objects) -> Camera:
        """``camera`` fitted to ``objects`` (as it is when none is bounded); raises
        ViewerError, changing nothing, when the fit is no camera."""
        bounds = _bounds(objects)
        return camera if bounds is None else camera.fitted(*bounds)

    def set_camera(self, camera: Camera, fixed: Optional[bool] = None) -> None:
        """Uses ``camera``; ``fixed`` True stops re-fitting, False re-fits now and on adds.
        All or nothing: a camera whose fit fails changes nothing."""
        fixed = self.camera_fixed if fixed is None else fixed
        if not fixed:
            camera = self._fitted(camera, self._objects.values())
        self._camera, self.camera_fixed = camera, fixed

    def grid(self) -> Grid:
        """The floor grid under the scene: about 3 scene radii across, 10-25 lines a side."""
        bounds = self.bounds()
        centre, radius = bounds if bounds is not None else (np.zeros(3), 1.0)
        half = max(1.5 * radius, 0.5)
        raw = half / 8
        exponent = math.floor(math.log10(raw))
        spacing = min((m * 10 ** exponent for m in (1, 2, 5, 10)), key=lambda s: abs(s - raw))
        cx, cy = (round(c / spacing) * spacing for c in centre[:2])
        half = math.ceil(half / spacing) * spacing
        return Grid((cx, cy), half, spacing)

    def clip_planes(self) -> tuple:
        """(near, far) m for the current camera, holding the scene and its grid."""
        bounds = self.bounds()
        centre, radius = bounds if bounds is not None else (np.zeros(3), 1.0)
        grid = self.grid()
        grid_corner = np.array([grid.centre_xy[0] + grid.half_size,
                                grid.centre_xy[1] + grid.half_size, 0.0])
        radius = max(radius, float(np.linalg.norm(grid_corner - centre)))
        distance = float(np.linalg.norm(np.subtract(self._camera.eye_W, centre)))
        far = distance + radius
        near = max(distance - radius, far / 2000.0)
        return near, far


def _bounds(objects) -> Optional[tuple]:
    """(centre (3,) m, radius m) of a sphere holding every bounded one of ``objects``
    (SceneObject; planes are infinite), or None if there is none."""
    bounded = [o for o in objects if o.geometry.bounded]
    if not bounded:
        return None
    centres = np.array([o.pose_W[:3, 3] for o in bounded])
    radii = np.array([o.geometry.radius for o in bounded])
    low = (centres - radii[:, None]).min(axis=0)
    high = (centres + radii[:, None]).max(axis=0)
    centre = (low + high) / 2
    radius = float(np.max(np.linalg.norm(centres - centre, axis=1) + radii))
    return centre, radius
