"""ODE's own levers on the cost of many bodies (issue 14: "measure each and keep what pays"),
each measured natively (native/rest_scene.c: the peers' rest<N> scene stepped as Odin steps it)
against the same program without it, alternately in one run:

  lever_hash_over_sap_rest<N>        steps/s with ODE's hash space ÷ with sweep and prune
                                     (Odin's broad phase)
  lever_quadtree_over_sap_rest<N>    the same for ODE's quadtree space (depth 7 over the grid)
  lever_auto_disable_speedup_rest<N> steps/s with ODE's auto-disabling (its default thresholds)
                                     ÷ without, on a scene where every body rests: its best case
  lever_auto_disable_enabled_rest<N> the share of bodies still enabled after the timed steps
  lever_threads2_speedup_rest<N>     steps/s with ODE's island threading on a pool of 2 threads
                                     (this machine's cores) ÷ on the caller's thread alone
  auto_disable_speedup_rest<N>_odin  the lever Odin keeps, in Odin: the Core's steps/s on the
                                     same scene with the world parameter auto_disable ÷ without

N is 1,000 and 10,000. Each figure is the median over the rounds of the ratio within a round;
ODIN_BENCH_ROUNDS sets the rounds (default 5). Every run also prints the largest drift of a
sphere from its start, so that a lever that moved the bodies would show. docs/PERFORMANCE.md
says what each lever does to Odin and which one Odin keeps.
"""
from __future__ import annotations

import os
import pathlib
import statistics
import subprocess
import sys
import time

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent.parent
ROUNDS = int(os.environ.get("ODIN_BENCH_ROUNDS", "5"))

#: bodies -> (timed steps, untimed steps first); auto-disabling needs 10 resting steps
STEPS = {1000: (400, 50), 10000: (40, 30)}
#: lever -> rest_scene.c's SPACE AUTO_DISABLE THREADS; "base" is Odin's own setting
LEVERS = {"base": ("sap", 0, 1), "hash": ("hash", 0, 1), "quadtree": ("quadtree", 0, 1),
          "auto_disable": ("sap", 1, 1), "threads2": ("sap", 0, 2)}


def _compile(out_dir: pathlib.Path) -> pathlib.Path:
    exe = out_dir / "rest_scene_levers"
    subprocess.run(["gcc", "-O2", "-DdDOUBLE", str(HERE / "native" / "rest_scene.c"), "-lode",
                    "-lm", "-o", str(exe)], check=True)
    return exe


def measure(exe: pathlib.Path, bodies: int, lever: str) -> dict:
    """One run of rest_scene.c with ``lever``: steps/s, bodies enabled at the end, largest
    drift (m)."""
    steps, warm = STEPS[bodies]
    space, auto_disable, threads = LEVERS[lever]
    out = subprocess.run([str(exe), str(bodies), str(steps), str(warm), space,
                          str(auto_disable), str(threads)], check=True, capture_output=True,
                         text=True, timeout=600).stdout.split()
    return {"steps_per_s": steps / float(out[0]), "enabled": int(out[3]) / bodies,
            "drift_m": float(out[4])}


def measure_odin(bodies: int, auto_disable: bool) -> dict:
    """The same scene in Odin's Core (its own process: a fresh heap for every run)."""
    steps, warm = STEPS[bodies]
    out = subprocess.run([sys.executable, __file__, "odin", str(bodies), str(int(auto_disable))],
                         check=True, capture_output=True, text=True, timeout=1200).stdout
    return {"steps_per_s": steps / float(out.split()[-1])}


def _odin_seconds(bodies: int, auto_disable: bool) -> float:
    """The peers' rest scene in Odin's Core (peers/odin_engine.py), the world parameter
    auto_disable as given: seconds of the timed steps."""
    sys.path.insert(0, str(HERE / "peers"))
    import odin_engine
    from virtual_world.core import WorldParameters
    steps, warm = STEPS[bodies]
    sim = odin_engine.Sim(f"rest{bodies}", WorldParameters(auto_disable=auto_disable))
    sim.step(warm)
    started = time.perf_counter()
    sim.step(steps)
    return time.perf_counter() - started


#: the Core's runs, beside the native levers
ODIN = {"odin_base": False, "odin_auto_disable": True}


def rounds_of(exe: pathlib.Path, bodies: int) -> list:
    """[{lever: measure()}], the levers' order rotated from round to round."""
    names = list(LEVERS) + list(ODIN)
    rounds = []
    for k in range(ROUNDS):
        order = names[k % len(names):] + names[:k % len(names)]
        runs = {lever: measure_odin(bodies, ODIN[lever]) if lever in ODIN
                else measure(exe, bodies, lever) for lever in order}
        rounds.append(runs)
        print(f"  rest{bodies} round {k}: " + ", ".join(
            f"{lever} {runs[lever]['steps_per_s']:.1f}/s" for lever in names), flush=True)
    return rounds


def figures_of(bodies: int, rounds: list) -> dict:
    def speedup(lever: str, base: str = "base") -> float:
        return round(statistics.median(r[lever]["steps_per_s"] / r[base]["steps_per_s"]
                                       for r in rounds), 3)
    return {f"lever_hash_over_sap_rest{bodies}": speedup("hash"),
            f"lever_quadtree_over_sap_rest{bodies}": speedup("quadtree"),
            f"lever_auto_disable_speedup_rest{bodies}": speedup("auto_disable"),
            f"lever_auto_disable_enabled_rest{bodies}": round(statistics.median(
                r["auto_disable"]["enabled"] for r in rounds), 4),
            f"lever_threads2_speedup_rest{bodies}": speedup("threads2"),
            f"auto_disable_speedup_rest{bodies}_odin": speedup("odin_auto_disable",
                                                               "odin_base")}


def run(out_dir: pathlib.Path) -> dict:
    out_dir.mkdir(parents=True, exist_ok=True)
    exe = _compile(out_dir)
    figures = {}
    for bodies in STEPS:
        figures.update(figures_of(bodies, rounds_of(exe, bodies)))
    return figures


if __name__ == "__main__":
    if sys.argv[1:2] == ["odin"]:          # one Core run (measure_odin): prints its seconds
        print(_odin_seconds(int(sys.argv[2]), bool(int(sys.argv[3]))))
    else:
        print(run(ROOT / "out" / "bench"))
