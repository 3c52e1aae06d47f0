"""The scenes Odin is compared on with MuJoCo and PyBullet (bench_peers.py), as plain data
each engine builds in its own way (peers/engines.py). Pure Python: it is imported by Odin's
venv and by the benchmark venv of the peers alike.

SI units, z up, gravity -9.81 m/s^2, 1 ms steps. Spheres: radius 0.1 m, 1 kg.
  spheres100   100 spheres dropped from 0.5 m onto a plane (bench_core's scene)
  pile100      the same piled inside four walls (bench_core's pile)
  rest<N>      N spheres resting on a plane, spread out on a 0.3 m grid
  arm7         a 7-link arm of the KUKA LWR's dimensions (0.95 m reach, 14.4 kg), stretched out
               horizontally and held there by position-controlled joint motors (each engine's
               own: Odin's servos, MuJoCo's position actuators, PyBullet's POSITION_CONTROL)
  grasp        arm7 with a palm and two fingers on sliders squeezing a can (cylinder r 0.03 m,
               0.12 m, 0.35 kg) with 20 N each: the can is held in the air by friction alone
"""
from __future__ import annotations

import math

RADIUS = 0.1
SPHERE_MASS = 1.0
STEP = 0.001
GRAVITY = -9.81
FRICTION = 1.0

#: scene -> (timed steps, warm-up steps before timing)
STEPS = {"spheres100": (2000, 0), "pile100": (2000, 0), "rest100": (2000, 20),
         "rest1000": (400, 20), "rest10000": (60, 20), "arm7": (3000, 0), "grasp": (3000, 0)}
SCENES = tuple(STEPS)
#: the resting scenes, by body count (the scale figure and the plot)
REST_COUNTS = {100: "rest100", 1000: "rest1000", 10000: "rest10000"}

WALLS = (((0.65, 0, 1), (0.2, 1.5, 2)), ((-0.65, 0, 1), (0.2, 1.5, 2)),
         ((0, 0.65, 1), (1.5, 0.2, 2)), ((0, -0.65, 1), (1.5, 0.2, 2)))


def sphere_positions(scene: str):
    """The spheres' start positions (m, world)."""
    if scene == "spheres100":
        return [((i % 10) * 0.25 - 1.125, (i // 10) * 0.25 - 1.125, 0.5) for i in range(100)]
    if scene == "pile100":
        out = []
        for i in range(100):
            layer = i // 25
            o = 0.06 if layer % 2 else 0.0
            out.append(((i % 5) * 0.21 - 0.42 + o + 0.001 * (i % 7),
                        ((i // 5) % 5) * 0.21 - 0.42 + o, 0.15 + layer * 0.21))
        return out
    n = int(scene[len("rest"):])
    side = math.ceil(math.sqrt(n))
    return [((i % side) * 0.3 - side * 0.15, (i // side) * 0.3 - side * 0.15, RADIUS)
            for i in range(n)]


def walls(scene: str):
    """((centre, sides), ...) of the static boxes around the pile (m)."""
    return WALLS if scene == "pile100" else ()


# ------------------------------------------------------------------------------ the arm

#: z of the horizontal part of the arm, m
ARM_Z = 0.31
#: the joints' anchors (world, m) and axes; link k runs from anchor k to anchor k + 1 (the
#: last to the flange); the KUKA LWR's: 0.31 m to the shoulder, 0.4 m to the elbow, 0.39 m
#: to the wrist, 0.078 m to the flange (here stretched out along x)
ANCHORS = ((0, 0, 0.11), (0, 0, ARM_Z), (0.2, 0, ARM_Z), (0.4, 0, ARM_Z), (0.6, 0, ARM_Z),
           (0.79, 0, ARM_Z), (0.868, 0, ARM_Z))
AXES = ((0, 0, 1), (0, 1, 0), (1, 0, 0), (0, 1, 0), (1, 0, 0), (0, 1, 0), (1, 0, 0))
FLANGE = (0.946, 0, ARM_Z)
LINK_MASSES = (2.7, 2.7, 2.7, 2.7, 1.7, 1.6, 0.3)
LINK_RADIUS = 0.04
#: position servo of every arm joint: the stiffest each engine holds stably at 1 ms
MOTOR_MAX_TORQUE = 300.0                         # N m


def links():
    """[(anchor, axis, start, end, mass)] of the 7 arm links: the capsule's segment (radius
    LINK_RADIUS around it) runs from start to end, 1 cm short of both anchors. Link 0 hinges on
    the static world; joined links overlap at their joints, where every engine exempts them
    from collisions, and no other two links touch."""
    out = []
    ends = ANCHORS[1:] + (FLANGE,)
    for anchor, axis, end, mass in zip(ANCHORS, AXES, ends, LINK_MASSES):
        direction = [e - a for a, e in zip(anchor, end)]
        length = math.sqrt(sum(d * d for d in direction))
        unit = [d / length for d in direction]
        start = tuple(a + 0.01 * u for a, u in zip(anchor, unit))
        stop = tuple(e - 0.01 * u for e, u in zip(end, unit))
        out.append((anchor, axis, start, stop, mass))
    return out


# ------------------------------------------------------------------------------ the hand

PALM = ((FLANGE[0] + 0.03, 0, ARM_Z), (0.06, 0.12, 0.06), 0.5)        # centre, sides, kg
CAN_RADIUS, CAN_LENGTH, CAN_MASS = 0.03, 0.12, 0.35
CAN = (FLANGE[0] + 0.06 + 0.045, 0, ARM_Z)                             # centre (m)
FINGER_SIDES = (0.08, 0.02, 0.04)
FINGER_MASS = 0.1
FINGER_FORCE = 20.0          # N, each finger's motor limit
FINGER_SPEED = 0.05          # m/s, the goal speed towards the can


def fingers():
    """[(centre, slide direction towards the can)] of the two fingers, touching the can."""
    y = CAN_RADIUS + FINGER_SIDES[1] / 2
    return [((CAN[0], y, ARM_Z), (0, -1, 0)), ((CAN[0], -y, ARM_Z), (0, 1, 0))]
