"""A benchmark's figures as PNG (matplotlib, off-screen): what a user looks at first.

- ``success_rate.png``: per problem (experiment), one bar per planner: the fraction of runs
  that reached the goal region within the time limit;
- ``time_to_solution.png``: per problem, a box per planner of the solved runs' times (s);
- ``propagations_per_s.png``: per physics problem, a box per planner of each run's propagation
  steps per second (Odin's physics rate under that planner);
- ``collision_checks_per_s.png``: per problem planned geometrically, a box per planner of each
  run's collision checks per second (Odin's geometry's rate under that planner).

A rate's figure is drawn when some experiment is of its kind.
"""
from __future__ import annotations

import os
from typing import Callable, Dict, List, Optional

from gui.errors import GuiError
from gui.planning.benchmark_run import RunResult

FILES = ("success_rate.png", "time_to_solution.png", "propagations_per_s.png",
         "collision_checks_per_s.png")


def _pyplot():
    try:
        import matplotlib
        matplotlib.use("Agg")
        from matplotlib import pyplot
    except ImportError as error:
        raise GuiError(f"matplotlib is missing ({error}): tools/install.sh installs Debian's "
                       "python3-matplotlib (tools/apt-packages.txt)") from None
    return pyplot


def check_plotting() -> None:
    """GuiError when the plots could not be drawn (before any run starts)."""
    _pyplot()


def write_plots(folder: str, summary: dict, results: Dict[tuple, RunResult]) -> List[str]:
    """Writes the figures into ``folder`` from ``summary`` (``benchmark.summary``) and the
    runs; answers their paths."""
    pyplot = _pyplot()
    experiments = summary["experiments"]
    paths = [_success_rates(pyplot, folder, experiments)]
    control = [e for e in experiments if not e.get("geometric")]
    geometric = [e for e in experiments if e.get("geometric")]
    for file, label, chosen, value in (
            (FILES[1], "time to solution (s)", experiments,
             lambda r: r.time_s if r.solved else None),
            (FILES[2], "propagations per second", control, lambda r: r.propagations_per_s),
            (FILES[3], "collision checks per second", geometric,
             lambda r: r.collision_checks_per_s)):
        if chosen:
            paths.append(_boxes(pyplot, folder, file, label, chosen, results, value))
    return paths


def _width(experiments: list) -> float:
    return max(6.0, 3.2 * len(experiments))


def _success_rates(pyplot, folder: str, experiments: list) -> str:
    """One bar per planner of each experiment: its success rate, its solved/runs above."""
    figure, axes = pyplot.subplots(1, len(experiments), figsize=(_width(experiments), 3.6),
                                   squeeze=False)
    for ax, experiment in zip(axes[0], experiments):
        names = [p["name"] for p in experiment["planners"]]
        rates = [p["success_rate"] or 0.0 for p in experiment["planners"]]
        bars = ax.bar(names, rates, color="#4c72b0")
        for bar, planner in zip(bars, experiment["planners"]):
            ax.annotate(f"{planner['solved']}/{planner['runs']}",
                        (bar.get_x() + bar.get_width() / 2, bar.get_height()),
                        ha="center", va="bottom", fontsize=8)
        ax.set_ylim(0, 1.1)
        ax.set_title(experiment["name"], fontsize=10)
        ax.tick_params(axis="x", labelrotation=30, labelsize=8)
    axes[0][0].set_ylabel("success rate")
    return _save(pyplot, figure, folder, FILES[0])


def _boxes(pyplot, folder: str, file: str, label: str, experiments: list,
           results: Dict[tuple, RunResult], value: Callable[[RunResult], Optional[float]]
           ) -> str:
    """A box per planner of each experiment: ``value`` of its runs (None: left out)."""
    figure, axes = pyplot.subplots(1, len(experiments), figsize=(_width(experiments), 3.6),
                                   squeeze=False)
    for ax, experiment in zip(axes[0], experiments):
        names = [p["name"] for p in experiment["planners"]]
        data = [[v for r in results.values()
                 if r.experiment == experiment["name"] and r.entry == name
                 and (v := value(r)) is not None] for name in names]
        ax.boxplot([d or [float("nan")] for d in data], labels=names)
        ax.set_title(experiment["name"], fontsize=10)
        ax.tick_params(axis="x", labelrotation=30, labelsize=8)
    axes[0][0].set_ylabel(label)
    return _save(pyplot, figure, folder, file)


def _save(pyplot, figure, folder: str, name: str) -> str:
    figure.tight_layout()
    path = os.path.join(folder, name)
    figure.savefig(path, dpi=90)
    pyplot.close(figure)
    return path


__all__ = ["FILES", "check_plotting", "write_plots"]
