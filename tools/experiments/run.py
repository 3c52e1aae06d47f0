"""Runs the thesis's three experiments (chapter 10), Kautham's ODE sphere demo and the plans
OMPL's KPIECE1 makes for both public sphere demos and Kautham's chain and car demos end to
end, headless.

    python tools/experiments/run.py                   # all eight
    python tools/experiments/run.py grasp             # one (contactless ... plan_car)
    python tools/experiments/run.py --no-frames pile  # no Viewer frames (the same simulation)

Each experiment starts its own roscore, ``rosrun VirtualWorld virtualWorld`` and ``rosrun
Viewer viewer``, acts as the GUI, and writes ``out/experiments/<name>/``: numbered Viewer frames
(``frames/frame_NNNN.png``), ``contact_sheet.png``, ``animation.gif`` and ``summary.json``. The
exit status is 0 only if every experiment ran and its outcome held.
"""
from __future__ import annotations

import argparse
import importlib
import os
import pathlib
import signal
import sys
import time

from gui.core.kautham.corpus import corpus_dir, missing_message

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

NAMES = ("contactless", "pile", "grasp", "sphere", "plan_sphere", "plan_sphere_walls",
         "plan_chain", "plan_car")


def _raise_keyboard_interrupt(signum, frame):
    raise KeyboardInterrupt(f"signal {signum}")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("names", nargs="*", metavar="name",
                        help=", ".join(NAMES) + " (default: all)")
    parser.add_argument("--no-frames", action="store_true", help="no Viewer frames")
    args = parser.parse_args(argv)
    unknown = [n for n in args.names if n not in NAMES]
    if unknown:
        parser.error(f"unknown experiment(s) {', '.join(unknown)}: choose from {', '.join(NAMES)}")
    if corpus_dir() is None:
        print(f"experiments: {missing_message()}", file=sys.stderr)
        return 2
    signal.signal(signal.SIGTERM, _raise_keyboard_interrupt)
    failed = []
    for name in args.names or NAMES:
        started = time.monotonic()
        print(f"experiment {name} ...", flush=True)
        try:
            code = _run_in_child(name, frames=not args.no_frames)
        except KeyboardInterrupt:
            print("interrupted; every process started was stopped", file=sys.stderr)
            return 130
        if code == 130:
            print("interrupted; every process started was stopped", file=sys.stderr)
            return 130
        if code == 0 or code == 1:
            print(f"experiment {name}: {'outcome held' if code == 0 else 'OUTCOME FAILED'} "
                  f"({time.monotonic() - started:.1f} s); out/experiments/{name}/summary.json",
                  flush=True)
        if code != 0:
            failed.append(name)
    if failed:
        print(f"failed: {', '.join(failed)}", file=sys.stderr)
        return 1
    return 0


def _run_in_child(name: str, frames: bool) -> int:
    """Runs one experiment in a child process and returns its exit code: 0 the outcome held,
    1 it did not, 2 the run failed, 130 interrupted. Each experiment has a roscore of its own,
    and rospy binds a process to the first master it registers with (init_node works once per
    process): a second experiment in the same process would register with a stopped master
    and hang."""
    pid = os.fork()
    if pid == 0:
        code = 2
        try:
            module = importlib.import_module(name)
            facts = module.run(frames=frames)
            ok, lines = module.verdict(facts)
            for line in lines:
                print(f"  {line}")
            code = 0 if ok else 1
        except KeyboardInterrupt:
            code = 130
        except Exception as error:
            print(f"experiment {name}: {type(error).__name__}: {error}", file=sys.stderr)
        finally:
            sys.stdout.flush()
            sys.stderr.flush()
            os._exit(code)
    try:
        _, status = os.waitpid(pid, 0)
    except KeyboardInterrupt:   # the child's Session stops its own processes on SIGTERM
        os.kill(pid, signal.SIGTERM)
        os.waitpid(pid, 0)
        raise
    return os.waitstatus_to_exitcode(status)


if __name__ == "__main__":
    sys.exit(main())
