"""Runs one scene of peers/scenes.py in one engine and prints what bench_peers.py reads: one
JSON line {"engine", "scene", "steps", "seconds" (in the step calls only), "steps_per_s",
"bodies", and the scene's accuracy figures}. Pure Python over the engine modules (each
engine's own venv runs this file: Odin's .venv for "odin", .venv-bench for "mujoco" and
"pybullet").

    python measure.py ENGINE SCENE

Accuracy, from poses read between chunks of steps (outside the timed calls), m -> mm:
  penetration_mm  sphere scenes: the deepest any sphere sinks into the plane, a wall or
                  another sphere at the end of the run
  sag_mm          arm7 and grasp: the largest drop of the arm's flange below its start
  can_drop_mm     grasp: the largest drop of the can below its start (held: a few mm)
"""
from __future__ import annotations

import importlib
import json
import math
import pathlib
import sys
import time

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import scenes  # noqa: E402

ENGINES = ("odin", "mujoco", "pybullet")
#: steps per timed call; poses are read between calls
CHUNK = 100


def penetration_m(scene: str, positions) -> float:
    """The deepest overlap (m) of the spheres with the plane z = 0, the pile's walls and each
    other (0 when none overlaps)."""
    r = scenes.RADIUS
    deepest = max(0.0, max(r - z for _, _, z in positions))
    for centre, sides in scenes.walls(scene):
        half = [s / 2 for s in sides]
        for p in positions:
            outside = [max(abs(p[k] - centre[k]) - half[k], 0.0) for k in range(3)]
            inside = all(abs(p[k] - centre[k]) < half[k] for k in range(3))
            gap = -r if inside else math.sqrt(sum(o * o for o in outside)) - r
            deepest = max(deepest, -gap)
    if scenes.walls(scene):           # only the pile's spheres can meet (the rest stay apart)
        for i, a in enumerate(positions):
            for b in positions[i + 1:]:
                deepest = max(deepest, 2 * r - math.dist(a, b))
    return deepest


def run(engine: str, scene: str) -> dict:
    module = importlib.import_module(f"{engine}_engine")
    sim = module.build(scene)
    steps, warm = scenes.STEPS[scene]
    if warm:
        sim.step(warm)
    arm = scene in ("arm7", "grasp")
    tip0 = sim.tip() if arm else None
    can0 = sim.can() if scene == "grasp" else None
    sag = can_drop = 0.0
    seconds, done = 0.0, 0
    while done < steps:
        n = min(CHUNK, steps - done)
        started = time.perf_counter()
        sim.step(n)
        seconds += time.perf_counter() - started
        done += n
        if arm:
            sag = max(sag, tip0[2] - sim.tip()[2])
        if can0 is not None:
            can_drop = max(can_drop, can0[2] - sim.can()[2])
    out = {"engine": engine, "scene": scene, "steps": steps, "seconds": seconds,
           "steps_per_s": steps / seconds, "bodies": sim.bodies}
    if arm:
        out["sag_mm"] = 1000 * sag
    else:
        out["penetration_mm"] = 1000 * penetration_m(scene, sim.sphere_positions())
    if can0 is not None:
        out["can_drop_mm"] = 1000 * can_drop
    out.update(getattr(sim, "settings", {}))
    return out


def rotate(q_wxyz, v):
    """v rotated by the unit quaternion q (w, x, y, z)."""
    w, x, y, z = q_wxyz
    tx, ty, tz = 2 * (y * v[2] - z * v[1]), 2 * (z * v[0] - x * v[2]), 2 * (x * v[1] - y * v[0])
    return (v[0] + w * tx + y * tz - z * ty, v[1] + w * ty + z * tx - x * tz,
            v[2] + w * tz + x * ty - y * tx)


def main(argv) -> int:
    if len(argv) != 2 or argv[0] not in ENGINES or argv[1] not in scenes.SCENES:
        print(f"usage: measure.py ENGINE SCENE (engines {ENGINES}, scenes {scenes.SCENES})",
              file=sys.stderr)
        return 2
    print(json.dumps(run(*argv)))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
