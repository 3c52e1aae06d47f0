"""What the window knows of the world: its objects, joints, motors, forces and robots.

The world is the authority, whoever built what it holds. Get World (``on_inventory``, a
``gui.ros.client.WorldInventory``) gives the IDs of the objects, joints, motors and forces and
the robots declared with Set Robot (their links and their own joint names); ``joint_data`` gives
each joint's type (Get State gives the type of a joint the topic has not yet named: the window
can motor a joint it has just built) and ``world_update`` the poses. The 25 Hz topics also tell
when the world changed under the window (a geometry or a joint came or went: ``stale`` is
emitted, and the window asks Get World again). ``SceneModel`` emits ``changed(str what)`` with
``what`` one of "objects", "joints", "motors", "forces", "robots" only when that set really
changes, so the topics cost the GUI thread a set comparison, not a list rebuild.

``robots`` are the kinematic handles (``gui.core.plan.RobotHandle``) of the robots this window
built (paths need them); ``world_robots`` every robot the world holds.
"""
from __future__ import annotations

from typing import Optional

from PyQt5.QtCore import QObject, pyqtSignal

from odin_common.interface import COMPOSITE_MARK, JointType, is_composite_id, motor_joint

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
    stale = pyqtSignal()            # the topics show a change Get World has not told yet

    def __init__(self, parent=None):
        super().__init__(parent)
        self.geometries: set = set()    # geometry names of the last world_update
        self.poses: dict = {}           # geometry name -> (position, quaternion wxyz)
        self.objects: list = []         # object IDs in the world, sorted
        self.joints: dict = {}          # joint ID -> JointType value (None: type not known yet)
        self.motors: dict = {}          # motor ID -> number of axes
        self.forces: list = []          # external force / torque IDs
        self.joint_forces: list = []    # joint force IDs
        self.world_robots: tuple = ()   # gui.ros.client.WorldRobot of every robot declared
        self.robots: dict = {}          # robot name -> RobotHandle, robots this window built
        self.problem_format: Optional[str] = None
        self.plan = None                # the last opened problem's gui.core.plan.BuildPlan
        self.inventory = None           # the last Get World answer
        self._joint_types: dict = {}    # joint ID -> JointType value, from joint_data

    # -- from Get World ----------------------------------------------------------------------
    def on_inventory(self, inventory, motor_axes: dict, joint_types: dict = None) -> None:
        """Get World's answer; ``motor_axes``: motor ID -> axes of motors not known before;
        ``joint_types``: joint ID -> JointType value of joints whose type was not known (Get
        State's answer: a new joint's type must not wait for the ``joint_data`` topic, whose
        subscription may connect late)."""
        self.inventory = inventory
        self._set("objects", sorted(inventory.objects))
        self._set("joints", {j: self._type_of(j, joint_types or {}) for j in inventory.joints})
        self._set("motors", {m: self.motors.get(m) or motor_axes.get(m, 1)
                             for m in inventory.motors})
        self._set("forces", (list(inventory.body_forces), list(inventory.joint_forces)))
        robots = {r.name for r in inventory.robots}
        handles = {name: h for name, h in self.robots.items() if name in robots}
        if inventory.robots != self.world_robots or handles != self.robots:
            self.world_robots = inventory.robots
            self.robots = handles
            if not handles:       # the robots this window built are gone: so is their plan
                self.problem_format, self.plan = None, None
            self.changed.emit("robots")

    def _type_of(self, joint_id: str, asked: dict):
        """A joint's type: from the topic, else from Get State, else as known before (None:
        not known yet). Ball is 0: hence no ``or`` here."""
        for source in (self._joint_types, asked, self.joints):
            if source.get(joint_id) is not None:
                return source[joint_id]
        return None

    def _set(self, what: str, value) -> None:
        if what == "forces":
            if value != (self.forces, self.joint_forces):
                self.forces, self.joint_forces = value
                self.changed.emit(what)
        elif value != getattr(self, what):
            setattr(self, what, value)
            self.changed.emit(what)

    def new_motors(self, motor_ids) -> list:
        """The motor IDs of ``motor_ids`` whose number of axes the window does not know."""
        return [m for m in motor_ids if m not in self.motors]

    # -- from the world's topics -------------------------------------------------------------
    def on_world_update(self, msg) -> None:
        poses = {s.name: (tuple(s.position), tuple(s.orientation)) for s in msg.situations}
        self.poses = poses
        if poses.keys() != self.geometries:
            self.geometries = set(poses)
            self.stale.emit()

    def on_joint_data(self, msg) -> None:
        types = {j.id: int(j.type) for j in msg.joints}
        if types == self._joint_types:
            return
        self._joint_types = types
        if set(types) != set(self.joints):
            self.stale.emit()
        self._set("joints", {j: self._type_of(j, {}) for j in self.joints})

    # -- what this window built (shown at once; the next Get World confirms it) --------------
    def add_motor(self, motor_id: str, axes: int = 1) -> None:
        self._set("motors", {**self.motors, motor_id: axes})

    def add_force(self, force_id: str) -> None:
        self._set("forces", (self.forces + [force_id], self.joint_forces))

    def add_joint_force(self, force_id: str) -> None:
        self._set("forces", (self.forces, self.joint_forces + [force_id]))

    def remove_force(self, force_id: str) -> None:
        self._set("forces", ([f for f in self.forces if f != force_id],
                             [f for f in self.joint_forces if f != force_id]))

    def add_robot(self, handle, problem_format: str) -> None:
        self.robots[handle.name] = handle
        self.problem_format = problem_format
        self.changed.emit("robots")

    def forget_world(self) -> None:
        """The world went away: a world that comes back starts empty."""
        self.geometries, self.poses, self._joint_types = set(), {}, {}
        self.inventory = None
        for what, empty in [("objects", []), ("joints", {}), ("motors", {}),
                            ("forces", ([], []))]:
            self._set(what, empty)
        self.plan = None
        if self.robots or self.world_robots:
            self.robots, self.world_robots, self.problem_format = {}, (), None
            self.changed.emit("robots")

    # -- names --------------------------------------------------------------------------------
    def pose_of(self, object_id: str) -> Optional[tuple]:
        """(position, quaternion) of an object as last reported (None for composites)."""
        return self.poses.get(object_id)

    def robot_points(self) -> list:
        """Origins (m, world frame) of the robots' links as last reported; of every object
        when the world holds no robot (what "Frame the robot" aims at)."""
        wanted = {o for r in self.world_robots for o in r.objects} or set(self.objects)
        names = {part for o in wanted for part in
                 (o.split(COMPOSITE_MARK)[1:] if is_composite_id(o) else [o])}
        return [self.poses[n][0] for n in sorted(names) if n in self.poses]

    def joint_owner(self, joint_id: str) -> Optional[tuple]:
        """(robot name, the robot's own joint name) of a world joint, or None."""
        for robot in self.world_robots:
            if joint_id in robot.joints:
                return robot.name, robot.joint_names[robot.joints.index(joint_id)]
        return None

    def joint_label(self, joint_id: str) -> str:
        """How menus name a joint: "<robot>: <its joint name>" for a robot's joint, else the
        world ID."""
        owner = self.joint_owner(joint_id)
        return f"{owner[0]}: {owner[1]}" if owner else joint_id

    def motor_label(self, motor_id: str) -> str:
        """How menus name a motor: by its joint's robot name and joint name when it has one."""
        owner = self.joint_owner(motor_joint(motor_id))
        return f"{owner[0]}: {owner[1]} (motor)" if owner else motor_id

    def grouped(self, ids, label) -> list:
        """(label, ID) of ``ids``, robots' first (in robot and joint order), then by ID."""
        order = {j: k for k, j in enumerate(j for r in self.world_robots for j in r.joints)}
        owned = [(label(i), i) for i in ids if _joint_of(i) in order]
        owned.sort(key=lambda pair: order[_joint_of(pair[1])])
        return owned + sorted((i, i) for i in ids if _joint_of(i) not in order)


def _joint_of(element_id: str) -> str:
    """The joint a joint ID or a default motor ID is about."""
    return motor_joint(element_id) or element_id
