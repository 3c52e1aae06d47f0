"""Checks the benchmark figures against their goals and writes the README's figure table.

The goals live in goals.json beside this file, one figure a line:
    "figure": {"min": 0.95, "unit": "ratio", "what": "what it measures"},
"min" (at least) and/or "max" (at most) are the goal, both inclusive; a figure without either is
reported, not checked. Keys starting with "_" are notes. Units other than RELATIVE_UNITS depend
on the host's speed: the table prints the host's speed beside them (the probes run.py took
around the figure's module, else HOST_FIGURE, the run's median), so a reader can tell a slow
host from a slow Odin.

``python report.py`` reads out/bench/results.json (figure -> number) and out/bench/run.json
(written by run.py: why figures are missing), prints every missed goal and missing figure,
rewrites the table between the two markers in README.md (``--no-readme``: not) and exits 1 if a
goal was missed or a goal's figure is missing.
"""
from __future__ import annotations

import argparse
import json
import math
import pathlib
import sys
from typing import Dict, List, Mapping, Optional

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent.parent
GOALS_PATH = HERE / "goals.json"
RESULTS_PATH = ROOT / "out" / "bench" / "results.json"
RUN_PATH = ROOT / "out" / "bench" / "run.json"
README_PATH = ROOT / "README.md"
BEGIN = ("<!-- bench table begin: written by tools/bench/report.py from out/bench/results.json "
         "and tools/bench/goals.json; do not edit -->")
END = "<!-- bench table end -->"
HOST_FIGURE = "host_native_ode_steps_per_s"
RELATIVE_UNITS = ("ratio", "count", "kB", "mm", "rad")
SPEC_KEYS = {"min", "max", "unit", "what"}


class Refused:
    """A benchmark's answer instead of a number: the figure could not be measured honestly
    (e.g. native C and Odin did not do the same work). run.py leaves the figure out of
    results.json, records the reason in run.json, and the run fails."""

    def __init__(self, reason: str):
        self.reason = reason

    def __repr__(self) -> str:
        return f"Refused({self.reason!r})"


def load_goals(path: pathlib.Path = GOALS_PATH) -> Dict[str, dict]:
    """figure -> spec, in the file's order; raises ValueError on a malformed entry."""
    raw = json.loads(pathlib.Path(path).read_text())
    goals = {}
    for figure, spec in raw.items():
        if figure.startswith("_"):
            continue
        if not isinstance(spec, dict):
            raise ValueError(f"{path}: {figure}: not an object")
        unknown = set(spec) - SPEC_KEYS
        if unknown:
            raise ValueError(f"{path}: {figure}: unknown keys {sorted(unknown)} "
                             f"(allowed: {sorted(SPEC_KEYS)})")
        for key in ("unit", "what"):
            if not isinstance(spec.get(key), str):
                raise ValueError(f"{path}: {figure}: {key!r} must be a string")
        for key in ("min", "max"):
            if key in spec and (isinstance(spec[key], bool)
                                or not isinstance(spec[key], (int, float))):
                raise ValueError(f"{path}: {figure}: {key!r} must be a number")
        goals[figure] = spec
    return goals


def goal_text(spec: Mapping) -> str:
    unit = _unit_suffix(spec)
    parts = []
    if "min" in spec:
        parts.append(f"≥ {_number(spec['min'])}{unit}")
    if "max" in spec:
        parts.append(f"≤ {_number(spec['max'])}{unit}")
    return " and ".join(parts) if parts else "-"


def missed(value: float, spec: Mapping) -> bool:
    """Whether ``value`` misses the goal of ``spec`` (a NaN misses any goal)."""
    if "min" not in spec and "max" not in spec:
        return False
    if not isinstance(value, (int, float)) or isinstance(value, bool) or math.isnan(value):
        return True
    return ("min" in spec and value < spec["min"]) or ("max" in spec and value > spec["max"])


def check(results: Mapping[str, float], goals: Mapping[str, dict],
          reasons: Optional[Mapping[str, str]] = None,
          only_present: bool = False) -> List[str]:
    """One line per missed goal and per goal whose figure is missing (with the reason, if
    known); empty when every goal is met. ``only_present`` (a partial run) skips the figures
    missing without a reason (their module did not run)."""
    reasons = reasons or {}
    problems = []
    for figure, spec in goals.items():
        if "min" not in spec and "max" not in spec:
            continue
        if figure not in results:
            if not only_present or figure in reasons:
                why = reasons.get(figure, "not in results.json")
                problems.append(f"MISSING {figure}: goal {goal_text(spec)}; {why}")
        elif missed(results[figure], spec):
            problems.append(f"MISSED  {figure} = {_number(results[figure])}"
                            f"{_unit_suffix(spec)}, goal {goal_text(spec)}")
    return problems


def _number(value) -> str:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return str(value)
    if math.isnan(value) or math.isinf(value):
        return str(value)
    if abs(value) >= 1000:
        return f"{value:,.0f}"
    text = f"{value:.3g}"
    return text if "e" not in text else f"{value:.2g}"


def _unit_suffix(spec: Mapping) -> str:
    unit = spec.get("unit", "")
    return "" if unit in ("ratio", "count", "") else f" {unit}"


def host_bound(spec: Mapping) -> bool:
    return spec.get("unit", "") not in RELATIVE_UNITS


def table(results: Mapping[str, float], goals: Mapping[str, dict],
          reasons: Optional[Mapping[str, str]] = None, run: Optional[Mapping] = None) -> str:
    """The markdown table: every figure of goals.json in its order, then any figure of the
    results that goals.json does not describe yet."""
    reasons = reasons or {}
    run = run or {}
    by_module = run.get("host_by_module") or {}
    modules = run.get("figure_modules") or {}
    rows = ["| figure | goal | last run | what |", "|---|---|---|---|"]
    figures = list(goals) + sorted(f for f in results if f not in goals)
    for figure in figures:
        spec = goals.get(figure, {"unit": "", "what": "(not described in goals.json)"})
        if figure in results:
            value = results[figure]
            cell = f"{_number(value)}{_unit_suffix(spec)}"
            if missed(value, spec):
                cell = f"**{cell} (missed)**"
            if host_bound(spec) and figure != HOST_FIGURE:
                host = by_module.get(modules.get(figure), results.get(HOST_FIGURE))
                cell += f" (host {_number(host)} steps/s)" if host is not None else " (host ?)"
        else:
            why = reasons.get(figure)
            cell = "**missing**" + (f": {why}" if why else "")
        what = spec["what"].replace("|", "\\|")
        rows.append(f"| `{figure}` | {goal_text(spec)} | {cell.replace('|', '/')} | {what} |")
    return "\n".join(rows) + "\n"


def caption(run: Mapping) -> str:
    """One line over the table: when and how long the run was."""
    parts = []
    if run.get("finished"):
        parts.append(f"Last run: {run['finished']}")
    if run.get("seconds") is not None:
        parts.append(f"`make bench` took {run['seconds'] / 60:.1f} min")
    probes = [p["steps_per_s"] for p in run.get("host_probes") or [] if p.get("steps_per_s")]
    if probes:
        parts.append(f"host probes {_number(min(probes))}-{_number(max(probes))} native "
                     f"steps/s over the run")
    if run.get("failed_modules"):
        parts.append("failed modules: " + ", ".join(run["failed_modules"]))
    return ("; ".join(parts) + ".\n\n") if parts else ""


def rewrite_readme(text: str, block: str) -> str:
    """``text`` with everything between BEGIN and END replaced by ``block``."""
    start, end = text.find(BEGIN), text.find(END)
    if start < 0 or end < start:
        raise ValueError(f"README has no {BEGIN!r} ... {END!r} markers")
    return text[:start + len(BEGIN)] + "\n" + block + text[end:]


def missing_reasons(results: Mapping[str, float], goals: Mapping[str, dict],
                    run: Mapping) -> Dict[str, str]:
    """figure -> why it is not in the results, from run.json's record of the run."""
    reasons = {}
    failed = run.get("failed_modules") or []
    for figure in goals:
        if figure not in results and failed:
            reasons[figure] = f"failed benchmark modules: {', '.join(failed)}"
    for figure, why in (run.get("refused") or {}).items():
        reasons[figure] = f"refused: {why}"
    return reasons


def report(results: Mapping[str, float], goals: Mapping[str, dict], run: Mapping,
           readme: Optional[pathlib.Path], only_present: bool = False,
           out=sys.stdout) -> int:
    """Prints the missed goals, rewrites ``readme``'s table (unless None); 1 if a goal was
    missed or a goal's figure is missing, else 0."""
    reasons = missing_reasons(results, goals, run)
    problems = check(results, goals, reasons, only_present)
    if readme is not None:
        path = pathlib.Path(readme)
        block = caption(run) + table(results, goals, reasons, run)
        path.write_text(rewrite_readme(path.read_text(), block))
        print(f"figure table written to {path}", file=out)
    checked = sum(1 for s in goals.values() if "min" in s or "max" in s)
    if problems:
        print(f"{len(problems)} of {checked} goals not met:", file=out)
        for line in problems:
            print(f"  {line}", file=out)
        return 1
    print(f"all {checked} goals met" + (" (partial run: missing figures not checked)"
                                        if only_present else ""), file=out)
    return 0


def main(argv: List[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--results", type=pathlib.Path, default=RESULTS_PATH)
    parser.add_argument("--run", type=pathlib.Path, default=RUN_PATH)
    parser.add_argument("--goals", type=pathlib.Path, default=GOALS_PATH)
    parser.add_argument("--readme", type=pathlib.Path, default=README_PATH)
    parser.add_argument("--no-readme", action="store_true")
    args = parser.parse_args(argv)
    results = json.loads(args.results.read_text()) if args.results.exists() else {}
    run = json.loads(args.run.read_text()) if args.run.exists() else {}
    partial = bool(run.get("partial"))
    if partial and not args.no_readme:
        print(f"partial run ({', '.join(run.get('modules', []))}): README not rewritten")
    return report(results, load_goals(args.goals), run,
                  None if (args.no_readme or partial) else args.readme, only_present=partial)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
