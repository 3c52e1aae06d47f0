"""Odin against the engines a user would pick instead, MuJoCo and PyBullet (pinned in
tools/requirements-bench.txt, in .venv-bench: make bench-setup), on the scenes of
peers/scenes.py, each engine set up as its own documentation recommends (peers/*_engine.py).

Every run of a scene is a process of its own (peers/measure.py: Odin's from Odin's venv, the
peers' from .venv-bench); a round runs every engine once, the order rotated from round to
round, and a round's ratio is Odin's steps/s over the best peer's in that round.
  peer_<scene>_ratio        median of the rounds' ratios (goal >= 1.0). Scenes: spheres100,
                            pile100, rest100, rest1000, rest10000, arm7, grasp
  accuracy_<scene>_<what>_<engine>  each engine's accuracy on the scene (median of the rounds),
                            so that speed is not bought with wrong physics: the pile's deepest
                            penetration (mm), the arm's and the grasp's sag of the flange (mm),
                            the grasp's drop of the can (mm); peers/measure.py says how
  scale_10000_over_100      Odin's step cost per body at 10,000 resting spheres over at 100,
                            (median over rounds; goal <= 1.5): the cost grows linearly
  scale_native_10000_over_100  the same for a native C program over libode doing what Odin
                            does (native/rest_scene.c), run in the same rounds
  per_body_us_rest<N>_<engine>  the per-body step cost (µs) behind the plot
The rounds' numbers go to out_dir/peers.json, and peers/plot.py draws per-body cost against
body count for all four (out_dir/peers_scaling.png; docs/images/peers_scaling.png is a copy).
ODIN_BENCH_ROUNDS sets the rounds (default 5; the 10,000-body scene runs at most 2: MuJoCo
compiles it in over a minute).
"""
from __future__ import annotations

import json
import os
import pathlib
import statistics
import subprocess
import sys

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent.parent
sys.path.insert(0, str(HERE / "peers"))

import scenes  # noqa: E402

BENCH_PYTHON = ROOT / ".venv-bench" / "bin" / "python"
ROUNDS = int(os.environ.get("ODIN_BENCH_ROUNDS", "5"))
BIG_ROUNDS = min(ROUNDS, 2)
PEERS = ("mujoco", "pybullet")
ENGINES = ("odin",) + PEERS
#: accuracy figures: scene -> the measure.py keys reported per engine
ACCURACY = {"pile100": ("penetration_mm",), "rest10000": ("penetration_mm",),
            "arm7": ("sag_mm",), "grasp": ("sag_mm", "can_drop_mm")}


def _measure(engine: str, scene: str) -> dict:
    if engine == "native":
        return _native(scene)
    python = sys.executable if engine == "odin" else str(BENCH_PYTHON)
    done = subprocess.run([python, str(HERE / "peers" / "measure.py"), engine, scene],
                          capture_output=True, text=True, timeout=1800)
    if done.returncode:
        raise RuntimeError(f"{engine} on {scene} failed ({done.returncode}): "
                           f"{done.stderr.strip()[-800:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def _native(scene: str) -> dict:
    n = int(scene[len("rest"):])
    steps, warm = scenes.STEPS[scene]
    out = subprocess.run([str(_native.exe), str(n), str(steps), str(warm)], check=True,
                         capture_output=True, text=True).stdout.split()
    seconds = float(out[0])
    return {"engine": "native", "scene": scene, "steps": steps, "seconds": seconds,
            "steps_per_s": steps / seconds, "bodies": n}


def _compile_native(out_dir: pathlib.Path) -> pathlib.Path:
    exe = out_dir / "rest_scene"
    subprocess.run(["gcc", "-O2", "-DdDOUBLE", str(HERE / "native" / "rest_scene.c"), "-lode",
                    "-lm", "-o", str(exe)], check=True)
    return exe


def per_body_us(run: dict) -> float:
    return 1e6 * run["seconds"] / (run["steps"] * run["bodies"])


def scene_rounds(scene: str) -> list:
    """[{engine: measure.py's answer}] of the scene's rounds, the order rotated each round."""
    engines = ENGINES + (("native",) if scene in scenes.REST_COUNTS.values() else ())
    rounds = []
    for k in range(BIG_ROUNDS if scene == "rest10000" else ROUNDS):
        order = engines[k % len(engines):] + engines[:k % len(engines)]
        runs = {engine: _measure(engine, scene) for engine in order}
        rounds.append(runs)
        print(f"  {scene} round {k}: " + ", ".join(
            f"{e} {runs[e]['steps_per_s']:.0f}/s" for e in engines), flush=True)
    return rounds


def figures_of(all_rounds: dict) -> dict:
    figures = {}
    for scene, rounds in all_rounds.items():
        figures[f"peer_{scene}_ratio"] = round(statistics.median(
            r["odin"]["steps_per_s"] / max(r[p]["steps_per_s"] for p in PEERS)
            for r in rounds), 3)
        for what in ACCURACY.get(scene, ()):
            for engine in ENGINES:
                figures[f"accuracy_{scene}_{what}_{engine}"] = round(
                    statistics.median(r[engine][what] for r in rounds), 3)
    for engine in ENGINES + ("native",):
        for n, scene in scenes.REST_COUNTS.items():
            figures[f"per_body_us_{scene}_{engine}"] = round(statistics.median(
                per_body_us(r[engine]) for r in all_rounds[scene]), 3)
    for name, engine in (("scale_10000_over_100", "odin"),
                         ("scale_native_10000_over_100", "native")):
        figures[name] = round(figures[f"per_body_us_rest10000_{engine}"]
                              / figures[f"per_body_us_rest100_{engine}"], 3)
    return figures


def run(out_dir: pathlib.Path) -> dict:
    if not BENCH_PYTHON.exists():
        raise RuntimeError(f"no {BENCH_PYTHON}: make bench-setup installs the peer engines")
    out_dir.mkdir(parents=True, exist_ok=True)
    _native.exe = _compile_native(out_dir)
    all_rounds = {scene: scene_rounds(scene) for scene in scenes.SCENES}
    (out_dir / "peers.json").write_text(json.dumps(all_rounds, indent=1) + "\n")
    subprocess.run([str(BENCH_PYTHON), str(HERE / "peers" / "plot.py"),
                    str(out_dir / "peers.json"), str(out_dir / "peers_scaling.png")], check=True)
    return figures_of(all_rounds)


if __name__ == "__main__":
    print(run(ROOT / "out" / "bench"))
