"""`make corpus`: every problem file of Kautham's whole public corpus through Odin, as a user
would run it, with a report (issue 31). Not part of `make test` (about an hour here).

    python tools/corpus/run.py [--corpus DIR] [--only TEXT] [--seconds 2] [--no-simulation]
                               [--no-planning] [--plan-seconds S] [--no-readme] [--out DIR]

The corpus is what ``tools/get_kautham.sh --all`` lays out (``$ODIN_KAUTHAM_ALL_DIR``, else
``../shared/kautham_all`` beside the clone: ``gui.core.kautham.corpus``). Its problem files
are the XML files that mention ``<Problem`` (Kautham's benchmark and task-planning configuration
files do too).

1. problem_info on each (``rosrun GUI problem_info FILE``'s main, in a process forked for it
   from one that imported it once: a rosrun each costs seconds of imports): ok (exit 0, JSON),
   refused (exit 2 and one line ``problem_info: error: ...``) or failed (anything else: a traceback,
   another status, more than one error line, a hang of more than ``PROBLEM_INFO_TIMEOUT`` s). A
   refusal is expected when the file is not a problem (``<Benchmark>``, ``<Config>``) or names a
   file the repository does not hold at that commit (absent from the tree, or listed in the corpus's
   SKIPPED.md); any other refusal is unexpected.
2. Each problem problem_info accepts is loaded into a VirtualWorld (with a Viewer beside it,
   both started by rosrun against a roscore of the run's own) as ``rosrun GUI load_problem``
   builds it, in a world set back to its default parameters first (the problem's own settings
   are what its plan sets), and simulated ``--seconds`` s of simulated time. Recorded: the
   load time (reading, planning and building), the bodies, and whether after the simulation
   anything diverged (the world parks such a body and logs it), a body fell through the ground
   (problems with Kautham's physics: its origin more than ``FELL_BELOW`` m under the ground
   plane z = 0 when it started above that), a fixed-base robot's link moved more than
   ``FIXED_BASE_HOLD`` m, or a robot was built outside its joint limits; the pairs built
   inside each other (``gui.core.overlaps``) are recorded and named in a failure's reason,
   where they explain a move. The largest move of
   each robot's links is reported for every robot kind, and the largest drop of any body
   (in a problem without a ground, a dynamic body falls for as long as it is simulated).

3. Each problem problem_info accepts that names a planner other than Kautham's ODE planners is
   planned as ``rosrun GUI plan`` plans it: ``gui.planning.geometric.solve``, the problem's
   own planner and time limit (``--plan-seconds``: at most that), seed 1, in a process of its
   own (tools/corpus/corpus_plan.py): solved | not solved | refused (one line: no query, start
   or goal collides, planner unknown...) | failed (a traceback, a crash, a hang), the search's
   time, states and collision checks (``--no-planning``: not run).

4. The tests over the whole corpus (``WHOLE_CORPUS_TESTS``, skipped by `make test`): the fuzz
   of every file problem_info opens (mutated, truncated, wrong encodings: one clear error or a
   plan, never a traceback or a hang), and the forward kinematics of every URDF robot against
   robot_state_publisher's (KDL) on /tf (``--no-tests``: not run).

Writes ``out/corpus/report.json`` and ``report.md`` (``--out``: elsewhere) and the counts between
the README's corpus markers (``--no-readme``: not; ``--only`` or ``--no-simulation``: a partial
run never rewrites them; a run with ``--plan-seconds`` says there that it was capped). Exit
status 0 when no file failed (a search not solved, or refused with its reason, is no failure)
and every refusal of problem_info is expected, 1 otherwise, 2 when the corpus is missing.
"""
from __future__ import annotations

import argparse
import json
import os
import pathlib
import signal
import subprocess
import sys
import time

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import corpus_checks as checks  # noqa: E402
import corpus_plan as planning  # noqa: E402
import corpus_report as report  # noqa: E402

from gui.core.kautham.corpus import (WHOLE_CORPUS_TESTS, WHOLE_ENVIRONMENT,  # noqa: E402
                                     whole_corpus_dir, whole_missing_message)

ROOT = HERE.parent.parent
OUT = ROOT / "out" / "corpus"


def problem_files(corpus: pathlib.Path, only: str = "") -> list:
    """Every .xml file under ``corpus`` that mentions <Problem, sorted, relative paths."""
    found = []
    for path in sorted(corpus.rglob("*.xml")):
        relative = str(path.relative_to(corpus))
        if only in relative and b"<Problem" in path.read_bytes():
            found.append(relative)
    return found


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--corpus", type=pathlib.Path, default=whole_corpus_dir(),
                        help=f"the whole corpus [${WHOLE_ENVIRONMENT}, else "
                        "../shared/kautham_all]")
    parser.add_argument("--only", default="", help="only files whose path holds this text")
    parser.add_argument("--seconds", type=float, default=2.0,
                        help="simulated seconds per problem [2]")
    parser.add_argument("--no-simulation", action="store_true",
                        help="problem_info only, no world")
    parser.add_argument("--no-planning", action="store_true",
                        help="not the planning of the geometric problems")
    parser.add_argument("--plan-seconds", type=_positive, default=None, metavar="S",
                        help="each search's time limit at most S s [the problem's own]")
    parser.add_argument("--no-tests", action="store_true",
                        help="not the tests over the whole corpus")
    parser.add_argument("--no-readme", action="store_true")
    parser.add_argument("--out", type=pathlib.Path, default=OUT,
                        help="the report's folder [out/corpus]")
    args = parser.parse_args(argv)
    if args.corpus is None or not (args.corpus / "ALL.md").is_file():
        print(f"corpus: {whole_missing_message()}", file=sys.stderr)
        return 2
    started = time.time()
    files = problem_files(args.corpus, args.only)
    print(f"corpus: {len(files)} problem files under {args.corpus}", flush=True)
    checks.preload()
    results = {f: checks.problem_info(args.corpus, f) for f in _progress(files, "problem_info")}
    if not args.no_simulation:
        accepted = [f for f in files if results[f]["status"] == "ok"]
        for f, simulated in checks.simulate_all(args.corpus, accepted, args.seconds).items():
            results[f].update(simulated)
    if not args.no_planning:
        planning.preload()
        accepted = {f: r for f, r in results.items() if r["status"] == "ok"}
        for f, planned in planning.plan_all(args.corpus, accepted, args.plan_seconds).items():
            results[f].update(planned)
    tests = None if args.no_tests or args.only else whole_corpus_tests(args.corpus, args.out)
    run = dict(corpus=str(args.corpus), started=started, minutes=(time.time() - started) / 60,
               seconds=args.seconds, simulated=not args.no_simulation, only=args.only,
               tests=tests, planned=not args.no_planning, plan_seconds=args.plan_seconds)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "report.json").write_text(json.dumps(dict(run=run, files=results), indent=1)
                                          + "\n")
    counts = report.counts(results)
    (args.out / "report.md").write_text(report.markdown(run, results, counts))
    if not (args.no_readme or args.only or args.no_simulation):
        report.rewrite_readme(report.readme_block(run, counts))
    print(report.summary_line(counts) + f"; {args.out / 'report.md'}", flush=True)
    if run["planned"]:
        print(report.plan_summary_line(counts), flush=True)
    if tests is not None:
        print(f"corpus: tests over the whole corpus: {tests['summary']}", flush=True)
    ok = counts["failed"] == 0 and counts["refused_unexpected"] == 0
    return 0 if ok and (tests is None or tests["status"] == 0) else 1


WHOLE_CORPUS_TEST_FILES = ("Odin/GUI/test/test_hostile_files.py",
                           "tests/nodes/test_urdf_kinematics.py")


def _positive(text: str) -> float:
    value = float(text)
    if not (value > 0 and value < float("inf")):
        raise argparse.ArgumentTypeError(f"{text!r} s: must be a positive number")
    return value


def whole_corpus_tests(corpus: pathlib.Path, out: pathlib.Path) -> dict:
    """Runs the tests over the whole corpus; {"status": pytest's exit status, "summary": its
    last line}."""
    env = dict(os.environ, **{WHOLE_CORPUS_TESTS: "1", WHOLE_ENVIRONMENT: str(corpus)})
    print("corpus: the tests over the whole corpus (fuzz, kinematics against KDL)", flush=True)
    done = subprocess.run([sys.executable, "-m", "pytest", "-p", "no:cacheprovider", "-q",
                           "-k", "whole_corpus", *WHOLE_CORPUS_TEST_FILES], cwd=ROOT, env=env,
                          capture_output=True, text=True)
    out.mkdir(parents=True, exist_ok=True)
    (out / "tests.log").write_text(done.stdout + done.stderr)
    lines = done.stdout.strip().splitlines()
    return dict(status=done.returncode, summary=lines[-1] if lines else "no output")


def _progress(files, what):
    for k, f in enumerate(files, start=1):
        print(f"[{what} {k}/{len(files)}] {f}", flush=True)
        yield f


def _raise_keyboard_interrupt(signum, frame):
    raise KeyboardInterrupt(f"signal {signum}")


if __name__ == "__main__":
    signal.signal(signal.SIGTERM, _raise_keyboard_interrupt)
    try:
        sys.exit(main())
    except KeyboardInterrupt:
        print("corpus: interrupted; every process started was stopped", file=sys.stderr)
        sys.exit(130)
