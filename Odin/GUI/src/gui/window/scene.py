"""What the window knows of the scene: the objects, joints, motors, forces and robots.

The world is the authority: objects come from ``world_update`` (a composite counts as present
while its parts are reported) and joints from ``joint_data``, so a scene changed by another
client shows up too; motors, forces and robots are what this window built (the world has no
topic listing them). ``SceneModel`` emits ``changed(str what)`` with ``what`` one of
"objects", "joints", "motors", "forces", "robots" only when the set really changes, so the
25 Hz topics cost the GUI thread a set comparison, not a list rebuild.
"""
from __future__ import annotations

from typing import Optional

from PyQt5.QtCore import QObject, pyqtSignal

from odin_common.interface import JointType, motor_joint

JOINT_TYPE_NAMES = {
    JointType.BALL: "Ball", JointType.HINGE: "Hinge", JointType.SLIDER: "Slider",
    JointType.PISTON: "Piston", JointType.UNIVERSAL: "Universal", JointType.HINGE2: "Hinge2",
    JointType.PR: "PR (prismatic-rotoide)", JointType.PU: "PU (prismatic-universal)",
    JointType.FIXED: "Fixed", JointType.PLANE2D: "Plane 2D",
}
"""How the window names each joint type (what each one uses and takes:
odin_common.interface's joint tables)."""


class SceneModel(QObject):
    changed = pyqtSignal(str)

    def __init__(self, parent=None):
        super().__init__(parent)
        self.composites: dict = {}      # composite ID -> tuple of part names
        self.geometries: set = set()    # geometry names of the last world_update
        self.poses: dict = {}           # geometry name -> (position, quaternion wxyz)
        self.objects: list = []         # object IDs in the world, sorted
        self.joints: dict = {}          # joint ID -> JointType value (from joint_data)
        self.motors: dict = {}          # motor ID -> number of axes
        self.forces: list = []          # external force / torque IDs
        self.joint_forces: list = []    # joint force IDs
        self.robots: dict = {}          # robot name -> gui.core.build.RobotHandle
        self.problem_format: Optional[str] = None
        self.plan = None                # the last opened problem's gui.core.build.BuildPlan

    # -- from the world's topics -------------------------------------------------------------
    def on_world_update(self, msg) -> None:
        names = set()
        poses = {}
        for s in msg.situations:
            names.add(s.name)
            poses[s.name] = (tuple(s.position), tuple(s.orientation))
        self.poses = poses
        if names == self.geometries:
            return
        self.geometries = names
        parts = set()
        objects = []
        for cid, members in self.composites.items():
            if members and all(m in names for m in members):
                objects.append(cid)
                parts.update(members)
        objects.extend(n for n in names if n not in parts)
        objects.sort()
        if objects != self.objects:
            self.objects = objects
            present = set(objects)
            self._prune_forces(present)
            self.changed.emit("objects")

    def on_joint_data(self, msg) -> None:
        joints = {j.id: int(j.type) for j in msg.joints}
        if joints != self.joints:
            self.joints = joints
            motors = {m: n for m, n in self.motors.items() if motor_joint(m) in joints
                      or not motor_joint(m)}
            stale = [f for f in self.joint_forces if f.split(":", 1)[1].rsplit(":", 1)[0]
                     not in joints]
            self.changed.emit("joints")
            if motors != self.motors:
                self.motors = motors
                self.changed.emit("motors")
            if stale:
                self.joint_forces = [f for f in self.joint_forces if f not in stale]
                self.changed.emit("forces")

    def _prune_forces(self, present: set) -> None:
        kept = [f for f in self.forces if f.split(":", 1)[1].rsplit(":", 1)[0] in present]
        if kept != self.forces:
            self.forces = kept
            self.changed.emit("forces")

    # -- what this window built ---------------------------------------------------------------
    def add_composite(self, cid: str, parts) -> None:
        self.composites[cid] = tuple(parts)

    def add_motor(self, motor_id: str, axes: int = 1) -> None:
        self.motors[motor_id] = axes
        self.changed.emit("motors")

    def add_force(self, force_id: str) -> None:
        self.forces.append(force_id)
        self.changed.emit("forces")

    def remove_force(self, force_id: str) -> None:
        if force_id in self.forces:
            self.forces.remove(force_id)
        if force_id in self.joint_forces:
            self.joint_forces.remove(force_id)
        self.changed.emit("forces")

    def add_joint_force(self, force_id: str) -> None:
        self.joint_forces.append(force_id)
        self.changed.emit("forces")

    def add_robot(self, handle, problem_format: str) -> None:
        self.robots[handle.name] = handle
        self.problem_format = problem_format
        self.changed.emit("robots")

    def clear(self) -> None:
        """New Scene: forget everything (the world's topics refill objects and joints)."""
        self.composites.clear()
        self.motors.clear()
        self.forces.clear()
        self.joint_forces.clear()
        self.robots.clear()
        self.problem_format = None
        self.plan = None
        for what in ("motors", "forces", "robots"):
            self.changed.emit(what)

    def forget_world(self) -> None:
        """The world went away: a world that comes back starts empty."""
        self.geometries, self.poses, self.objects, self.joints = set(), {}, [], {}
        self.changed.emit("objects")
        self.changed.emit("joints")
        self.clear()

    def pose_of(self, object_id: str) -> Optional[tuple]:
        """(position, quaternion) of an object as last reported (None for composites)."""
        return self.poses.get(object_id)
