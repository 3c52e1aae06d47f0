"""Runs every benchmark module ``bench_*.py`` beside this file and writes the figures.

Each module defines ``run(out_dir: pathlib.Path) -> dict[str, float]`` (figure name -> number)
and may write details of its own under ``out_dir``. The figures of all modules are merged into
``out/bench/results.json``. ``python run.py core viewer`` runs only ``bench_core``/``bench_viewer``.
Figures are ratios measured side by side in one run wherever a baseline exists, because this
machine is shared and noisy.
"""
import importlib.util
import json
import pathlib
import sys
import time
import traceback

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent.parent


def _load(path: pathlib.Path):
    spec = importlib.util.spec_from_file_location(path.stem, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def main(argv: list) -> int:
    out_dir = ROOT / "out" / "bench"
    out_dir.mkdir(parents=True, exist_ok=True)
    results_path = out_dir / "results.json"
    results = json.loads(results_path.read_text()) if results_path.exists() else {}
    wanted = set(argv)
    failed = []
    for path in sorted(HERE.glob("bench_*.py")):
        name = path.stem[len("bench_"):]
        if wanted and name not in wanted:
            continue
        started = time.monotonic()
        print(f"bench {name} ...", flush=True)
        try:
            figures = _load(path).run(out_dir)
        except Exception:  # one broken benchmark must not hide the others' figures
            traceback.print_exc()
            failed.append(name)
            continue
        for key, value in figures.items():
            print(f"  {key} = {value}")
        results.update(figures)
        results_path.write_text(json.dumps(results, indent=2, sort_keys=True) + "\n")
        print(f"bench {name}: {time.monotonic() - started:.1f} s", flush=True)
    print(f"figures in {results_path}")
    if failed:
        print(f"failed benchmarks: {', '.join(failed)}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
