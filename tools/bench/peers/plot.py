"""Draws per-body step cost against body count (the rest<N> scenes) for Odin, MuJoCo,
PyBullet and native ODE from bench_peers.py's rounds (median of the rounds), log-log.

    python plot.py PEERS_JSON OUT_PNG      (.venv-bench's python: it has matplotlib)
"""
from __future__ import annotations

import json
import statistics
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.ticker import NullFormatter, ScalarFormatter  # noqa: E402

import scenes  # noqa: E402

STYLE = {"odin": ("Odin (Core, ODE 0.16)", "o-"), "native": ("native C over libode", "s--"),
         "mujoco": ("MuJoCo 4.0.0", "^-"), "pybullet": ("PyBullet 3.2.7", "v-")}


def main(argv) -> int:
    if len(argv) != 2:
        print("usage: plot.py PEERS_JSON OUT_PNG", file=sys.stderr)
        return 2
    rounds = json.loads(open(argv[0]).read())
    figure, axes = plt.subplots(figsize=(6.4, 4.2), dpi=100)
    counts = sorted(scenes.REST_COUNTS)
    for engine, (label, style) in STYLE.items():
        costs = [statistics.median(1e6 * r[engine]["seconds"] /
                                   (r[engine]["steps"] * r[engine]["bodies"])
                                   for r in rounds[scenes.REST_COUNTS[n]]) for n in counts]
        axes.plot(counts, costs, style, label=label)
    axes.set_xscale("log")
    axes.set_yscale("log")
    axes.yaxis.set_major_formatter(ScalarFormatter())     # 2, 3, 6 µs, not 6 x 10^0
    axes.yaxis.set_minor_formatter(ScalarFormatter())
    axes.xaxis.set_minor_formatter(NullFormatter())
    axes.set_xlabel("resting spheres (spread out on a plane)")
    axes.set_ylabel("step cost per body (µs, 1 ms steps)")
    axes.set_title("Per-body step cost against body count (lower is better)")
    axes.grid(True, which="both", alpha=0.3)
    axes.legend()
    figure.tight_layout()
    figure.savefig(argv[1])
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
