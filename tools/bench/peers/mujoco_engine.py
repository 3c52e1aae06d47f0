"""The peers' scenes (scenes.py) in MuJoCo, set up as its documentation recommends: the
implicitfast integrator (recommended for most models, and stable with actuator damping), its
default Newton solver, pyramidal cones and soft contacts; sliding friction mu 1 like Odin's.
The arm's joints are held by position actuators (kp, kv) on hinges with the armature
(reflected motor inertia) the documentation advises for small links; one MJCF string per
scene, stepped with mj_step(nstep=n)."""
from __future__ import annotations

import math

import mujoco

import scenes

#: position actuators: stiffness (N m/rad) and damping (N m s/rad); joint armature (kg m^2)
KP, KV, ARMATURE = 20000.0, 200.0, 0.05


def _v(values) -> str:
    return " ".join(f"{float(v):.6g}" for v in values)


def _spheres(scene: str) -> str:
    walls = "".join(f'<geom type="box" pos="{_v(c)}" size="{_v(s / 2 for s in sides)}"/>'
                    for c, sides in scenes.walls(scene))
    bodies = "".join(f'<body name="s{i}" pos="{_v(p)}"><freejoint/>'
                     f'<geom type="sphere" size="{scenes.RADIUS}" mass="{scenes.SPHERE_MASS}"/>'
                     '</body>' for i, p in enumerate(scenes.sphere_positions(scene)))
    return walls + bodies


def _arm(scene: str) -> str:
    xml, close, previous = "", "", (0.0, 0.0, 0.0)
    for k, (anchor, axis, start, end, mass) in enumerate(scenes.links()):
        local = [a - b for a, b in zip(anchor, previous)]
        xml += (f'<body name="link{k}" pos="{_v(local)}">'
                f'<joint name="j{k}" type="hinge" axis="{_v(axis)}" armature="{ARMATURE}"/>'
                f'<geom type="capsule" size="{scenes.LINK_RADIUS}" mass="{mass}" '
                f'fromto="{_v(s - a for s, a in zip(start, anchor))} '
                f'{_v(e - a for e, a in zip(end, anchor))}"/>')
        close += "</body>"
        previous = anchor
    xml += f'<site name="flange" pos="{_v(f - a for f, a in zip(scenes.FLANGE, previous))}"/>'
    if scene == "grasp":
        centre, sides, mass = scenes.PALM
        xml += (f'<geom type="box" pos="{_v(c - a for c, a in zip(centre, previous))}" '
                f'size="{_v(s / 2 for s in sides)}" mass="{mass}"/>')
        for k, (position, direction) in enumerate(scenes.fingers()):
            xml += (f'<body name="finger{k}" pos="{_v(p - a for p, a in zip(position, previous))}">'
                    f'<joint name="f{k}" type="slide" axis="{_v(direction)}"/>'
                    f'<geom type="box" size="{_v(s / 2 for s in scenes.FINGER_SIDES)}" '
                    f'mass="{scenes.FINGER_MASS}"/></body>')
    xml += close
    if scene == "grasp":
        xml += (f'<body name="can" pos="{_v(scenes.CAN)}"><freejoint/><geom type="cylinder" '
                f'size="{scenes.CAN_RADIUS} {scenes.CAN_LENGTH / 2}" mass="{scenes.CAN_MASS}"/>'
                '</body>')
    return xml


def _actuators(scene: str) -> str:
    if scene not in ("arm7", "grasp"):
        return ""
    xml = "".join(f'<position joint="j{k}" kp="{KP}" kv="{KV}" '
                  f'forcerange="{-scenes.MOTOR_MAX_TORQUE} {scenes.MOTOR_MAX_TORQUE}"/>'
                  for k in range(7))
    if scene == "grasp":   # the fingers: velocity servos at FINGER_SPEED, force-limited
        xml += "".join(f'<velocity joint="f{k}" kv="1000" forcerange="{-scenes.FINGER_FORCE} '
                       f'{scenes.FINGER_FORCE}"/>' for k in range(2))
    return f"<actuator>{xml}</actuator>"


def model_xml(scene: str) -> str:
    arm = scene in ("arm7", "grasp")
    world = _arm(scene) if arm else _spheres(scene)
    plane = "" if arm else '<geom type="plane" size="0 0 1"/>'
    # the arena for contacts and constraints: MuJoCo's default size runs out past ~5,000
    # bodies ("Could not allocate memory"); its documentation says to raise size/memory
    # (its broad phase alone takes 2 n^2 bytes for n bodies)
    n = 0 if arm else len(scenes.sphere_positions(scene))
    memory = 16 + math.ceil(2 * n * n / 2**20) + n // 40
    return (f'<mujoco model="{scene}"><size memory="{memory}M"/>'
            f'<option timestep="{scenes.STEP}" '
            f'gravity="0 0 {scenes.GRAVITY}" integrator="implicitfast"/>'
            f'<default><geom friction="{scenes.FRICTION} 0.005 0.0001"/></default>'
            f'<worldbody>{plane}{world}</worldbody>{_actuators(scene)}</mujoco>')


class Sim:
    def __init__(self, scene: str):
        self.model = mujoco.MjModel.from_xml_string(model_xml(scene))
        self.data = mujoco.MjData(self.model)
        self.bodies = self.model.nbody - 1
        self.settings = {"solver": "Newton", "integrator": "implicitfast"}
        if scene == "grasp":
            self.data.ctrl[7:9] = scenes.FINGER_SPEED
        mujoco.mj_forward(self.model, self.data)
        self._spheres = [self.model.body(f"s{i}").id for i in
                         range(len(scenes.sphere_positions(scene)))] if not \
            scene.startswith(("arm", "grasp")) else []

    def step(self, n: int) -> None:
        mujoco.mj_step(self.model, self.data, nstep=n)

    def sphere_positions(self):
        return [tuple(map(float, self.data.xpos[b])) for b in self._spheres]

    def tip(self):
        return tuple(map(float, self.data.site("flange").xpos))

    def can(self):
        return tuple(map(float, self.data.body("can").xpos))


def build(scene: str) -> Sim:
    return Sim(scene)
