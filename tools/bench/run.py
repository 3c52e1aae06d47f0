"""Runs every benchmark module ``bench_*.py`` beside this file, writes the figures and checks
them against tools/bench/goals.json.

Each module defines ``run(out_dir: pathlib.Path) -> dict[str, float]`` (figure name -> number)
and may write details of its own under ``out_dir``. A figure's value may instead be a
``report.Refused(reason)``: the module could not measure it honestly (e.g. native C and Odin did
not do the same work); it is left out of the results and the run fails.

Every run starts a fresh ``out/bench/results.json`` (figure -> number; a module that fails
leaves its figures out and makes the run fail) and ``out/bench/run.json`` (what ran, what
failed, what was refused and why, the host probes). The host's speed is probed before every
module and at the end (the native C program's steps per second on the 100-sphere scene, one
2,000-step run, ~1 s): ``host_native_ode_steps_per_s`` is their median, and the README's table
prints beside each absolute figure the mean of the two probes around its module, so that a
slow host (other work on this shared machine) can be told from a slow Odin. At the end of a
whole run, report.py prints every missed
goal, rewrites the README's figure table and the exit status is 1 if a goal was missed, a goal's
figure is missing, a figure was refused or a module failed.

``python run.py core viewer`` runs only ``bench_core``/``bench_viewer`` (a partial run: the
README is left alone and only the figures measured are checked). ``ODIN_BENCH_ROUNDS=3`` runs
fewer rounds in the modules that repeat rounds (for development on a shared machine).
"""
import datetime
import importlib.util
import json
import pathlib
import statistics
import sys
import time
import traceback

from odin_common.blas import use_reference_blas

use_reference_blas()  # before the benchmarks import numpy (odin_common.blas)

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent.parent
sys.path.insert(0, str(HERE))

import bench_core  # noqa: E402
import report  # noqa: E402


def _load(path: pathlib.Path):
    spec = importlib.util.spec_from_file_location(path.stem, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _write(path: pathlib.Path, data: dict) -> None:
    path.write_text(json.dumps(data, indent=2, sort_keys=path.name == "results.json") + "\n")


def _probe(exe, probes: list, before: str) -> None:
    """Appends the host's steps per second now (None if the probe fails) to ``probes``."""
    try:
        value = round(bench_core.host_steps_per_s(exe)) if exe else None
    except Exception as error:  # the figures matter more than the probe
        print(f"host probe failed: {error}", file=sys.stderr)
        value = None
    probes.append({"before": before, "steps_per_s": value})
    print(f"host: {value} native steps/s", flush=True)


def main(argv: list) -> int:
    started = time.monotonic()
    out_dir = ROOT / "out" / "bench"
    out_dir.mkdir(parents=True, exist_ok=True)
    goals = report.load_goals()     # a malformed goals.json fails before minutes of benchmarks
    modules = {path.stem[len("bench_"):]: path for path in sorted(HERE.glob("bench_*.py"))}
    unknown = [name for name in argv if name not in modules]
    if unknown:
        print(f"no benchmark module {unknown}; there are {sorted(modules)}", file=sys.stderr)
        return 2
    wanted = [name for name in modules if not argv or name in argv]
    results: dict = {}
    run = {"modules": wanted, "partial": bool(argv), "failed_modules": [], "refused": {},
           "figure_modules": {}, "host_probes": [], "host_by_module": {}}
    _write(out_dir / "results.json", results)
    _write(out_dir / "run.json", run)
    try:
        probe_exe = bench_core._compile(out_dir, "host_probe")
    except Exception as error:
        print(f"host probe not compiled: {error}", file=sys.stderr)
        probe_exe = None
    for name in wanted:
        _probe(probe_exe, run["host_probes"], name)
        module_started = time.monotonic()
        print(f"bench {name} ...", flush=True)
        try:
            figures = _load(modules[name]).run(out_dir)
        except Exception:  # one broken benchmark must not hide the others' figures
            traceback.print_exc()
            run["failed_modules"].append(name)
            print(f"bench {name}: FAILED after {time.monotonic() - module_started:.1f} s",
                  flush=True)
            _write(out_dir / "run.json", run)
            continue
        for key, value in figures.items():
            if isinstance(value, report.Refused):
                run["refused"][key] = value.reason
                print(f"  {key} REFUSED: {value.reason}")
            else:
                print(f"  {key} = {value}")
                results[key] = value
            run["figure_modules"][key] = name
        _write(out_dir / "results.json", results)
        _write(out_dir / "run.json", run)
        print(f"bench {name}: {time.monotonic() - module_started:.1f} s", flush=True)
    _probe(probe_exe, run["host_probes"], "end")
    probes = [p["steps_per_s"] for p in run["host_probes"]]
    for k, name in enumerate(wanted):
        around = [v for v in probes[k:k + 2] if v is not None]
        if around:
            run["host_by_module"][name] = round(sum(around) / len(around))
    if any(v is not None for v in probes):
        results[report.HOST_FIGURE] = round(statistics.median(v for v in probes if v is not None))
        run["figure_modules"][report.HOST_FIGURE] = "run.py"
        _write(out_dir / "results.json", results)
    run["seconds"] = round(time.monotonic() - started, 1)
    run["finished"] = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    _write(out_dir / "run.json", run)
    print(f"figures in {out_dir / 'results.json'} ({run['seconds']:.0f} s)")
    status = report.report(results, goals, run, None if argv else report.README_PATH,
                           only_present=bool(argv))
    for figure, reason in run["refused"].items():
        print(f"REFUSED {figure}: {reason}", file=sys.stderr)
    if run["failed_modules"]:
        print(f"failed benchmark modules: {', '.join(run['failed_modules'])}", file=sys.stderr)
    return 1 if (status or run["refused"] or run["failed_modules"]) else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
