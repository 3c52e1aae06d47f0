"""Kautham 5.1.1 as the peer of Odin's geometric planning (issue 43): where its driver is built,
how it is built, and one seeded solve of a problem by Kautham's own library.

The peer's folder (Kautham's source, its ``build.sh`` and ``kautham_peer_solve.cpp``, the
driver) is ``$ODIN_KAUTHAM_PEER_DIR``, default ``../shared/peers/kautham`` beside the clone.
``make bench-kautham`` (``python3 tools/bench/kautham_peer.py build``) runs its ``build.sh``
once into ``build/kautham/`` (git-ignored); a second run finds the binaries and does nothing.

The driver, ``kautham-peer-solve PROBLEM --seed S [--time T] --task FILE``, loads the problem
as ``kautham-console`` does (models from the problem's folder and its ``../../models``), seeds
OMPL, solves the first query with the problem's planner and prints, among OMPL's own lines:

    PEER seed S
    PEER family F planner NAME
    PEER solved 0|1 wall T      T: wall seconds of Planner::solveAndInherit (OMPL's setup,
                                solve, and the simplification the problem asks for)
    PEER states N               a solved OMPL planner's path: its states

It writes the path to FILE as Kautham's GUI "Save Data" does (a ``<Task>`` file, which
``gui.core.kautham.solutions.read_solution`` reads) and exits 0 solved, 1 not solved, 3 when
the problem did not load, 4 on an error (Kautham's exception, printed as ``Error: ...``).
"""
from __future__ import annotations

import os
import pathlib
import subprocess
import sys
import xml.etree.ElementTree as ElementTree
from dataclasses import dataclass
from typing import Optional, Sequence

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent.parent
BUILD_DIR = ROOT / "build" / "kautham"
"""Where ``make bench-kautham`` builds the peer (the workspace's build/ is git-ignored)."""
PEER_ENVIRONMENT = "ODIN_KAUTHAM_PEER_DIR"
"""The variable naming the peer's folder (default: ../shared/peers/kautham beside the clone)."""
DRIVER = "kautham-peer-solve"
BUILT = (DRIVER, "apps/console/kautham-console", "libodecount.so")
"""What build.sh leaves in the build folder: all three there means the peer is built."""
MARGIN_S = 60.0
"""Seconds a run may take beyond its time limit before it is killed: loading the problem's
meshes and OMPL's setup come before the search, and simplification after it."""
KAUTHAM_TIME_PARAMETER = "_Max Planning Time"
KAUTHAM_DEFAULT_TIME_S = 10.0
"""Kautham 5.1.1's omplPlanner reads only ``_Max Planning Time`` (s), 10 unless the problem
sets it (src/planner/omplg/omplplanner.cpp)."""
FAILURES = {3: "Kautham could not load the problem", 4: "Kautham raised an error"}
"""The driver's exit statuses that are not an answer (0 solved, 1 not solved)."""
TAIL_LINES = 8
NOT_SOLVED_LINES = ("No exact solution found", "No solution found")
"""What Kautham prints when its planner found no exact solution, whatever the driver's exit
status (5.1.1's omplPlanner::trySolve reports an approximate solution this way, and the
driver's solveAndInherit still answered true: seen on UR3e, the path 5 cm short of the
goal)."""


def peer_dir() -> pathlib.Path:
    """The peer's folder: $ODIN_KAUTHAM_PEER_DIR, else ../shared/peers/kautham beside the
    clone."""
    value = os.environ.get(PEER_ENVIRONMENT)
    return pathlib.Path(value) if value else ROOT.parent / "shared" / "peers" / "kautham"


def peer_binary(build_dir: pathlib.Path = BUILD_DIR) -> Optional[pathlib.Path]:
    """The built driver, or None when it is not there."""
    path = pathlib.Path(build_dir) / DRIVER
    return path if path.is_file() and os.access(path, os.X_OK) else None


def why_not(build_dir: pathlib.Path = BUILD_DIR) -> str:
    """One line: where the driver is expected and how it is built."""
    return (f"Kautham is not built: no {pathlib.Path(build_dir) / DRIVER}; `make bench-kautham` "
            f"builds it (from {peer_dir()}, ${PEER_ENVIRONMENT}; about 7 CPU minutes)")


def own_time_limit(problem_file: pathlib.Path) -> float:
    """The problem's own time limit as Kautham reads it (s): its planner's
    ``_Max Planning Time``, else Kautham's default."""
    root = ElementTree.parse(problem_file).getroot()
    for parameter in root.iterfind("./Planner/Parameters/Parameter"):
        if (parameter.get("name") or "").strip() == KAUTHAM_TIME_PARAMETER:
            return float((parameter.text or "").strip())
    return KAUTHAM_DEFAULT_TIME_S


@dataclass(frozen=True)
class PeerRun:
    """One run of the driver. ``wall_s`` (s) and ``states`` are None when it printed none;
    ``task_file`` is the path it wrote when solved; ``returncode`` is None when it was killed
    after its time limit and MARGIN_S. ``error`` is empty when the driver answered (solved or
    not), else why not, with the tail of its output."""
    solved: bool
    wall_s: Optional[float]
    states: Optional[int]
    planner: str
    family: str
    seed: Optional[int]
    task_file: Optional[pathlib.Path]
    returncode: Optional[int]
    error: str = ""

    @property
    def failed(self) -> bool:
        """Whether the run gave no answer (did not load, raised, crashed, was killed)."""
        return bool(self.error)

    @staticmethod
    def from_output(stdout: str, stderr: str, returncode: Optional[int],
                    task_file: Optional[pathlib.Path] = None) -> "PeerRun":
        """The run the driver's output and exit status describe; ``task_file``: where it was
        asked to write the path (kept only when solved and written)."""
        fields = _peer_lines(stdout)
        # an answer: exit 0 with "PEER solved 1", or exit 1 with "PEER solved 0"
        answered = returncode in (0, 1) and fields.get("solved") == str(1 - returncode)
        # Kautham's library returns true after an approximate solution too (its console
        # says "APPROXIMATE_SOLUTION - No exact solution found"): not a solution
        solved = answered and returncode == 0 and not any(
            words in stdout for words in NOT_SOLVED_LINES)
        error = "" if answered else _failure(stdout, stderr, returncode)
        written = task_file if solved and task_file is not None and task_file.is_file() else None
        return PeerRun(solved=solved, wall_s=_number(fields.get("wall"), float),
                       states=_number(fields.get("states"), int),
                       planner=fields.get("planner", ""), family=fields.get("family", ""),
                       seed=_number(fields.get("seed"), int), task_file=written,
                       returncode=returncode, error=error)


def _peer_lines(stdout: str) -> dict:
    """The values of the driver's ``PEER key value [key value]`` lines, by key."""
    fields = {}
    for line in stdout.splitlines():
        words = line.split()
        if len(words) < 3 or words[0] != "PEER":
            continue
        for key, value in zip(words[1::2], words[2::2]):
            fields[key] = value
    return fields


def _number(text: Optional[str], kind: type):
    try:
        return kind(text) if text is not None else None
    except ValueError:
        return None


def _failure(stdout: str, stderr: str, returncode: Optional[int]) -> str:
    """Why a run gave no answer, with Kautham's error lines and the tail of its stderr."""
    if returncode is None:
        why = "no answer within its time limit and the margin: killed"
    else:
        why = FAILURES.get(returncode, f"the driver ended with status {returncode} without "
                                       "a PEER solved line that agrees with it")
    said = [line.strip() for line in stdout.splitlines()
            if line.startswith(("Error", "PEER load failed"))]
    tail = [line.strip() for line in stderr.splitlines() if line.strip()][-TAIL_LINES:]
    return " | ".join([why] + said + tail)


def solve(problem_file: pathlib.Path, seed: int, time_limit: Optional[float],
          out_dir: pathlib.Path, build_dir: pathlib.Path = BUILD_DIR) -> PeerRun:
    """Kautham solves ``problem_file``'s query with its planner, OMPL seeded with ``seed``,
    within ``time_limit`` s (None: the problem's own), in a process of its own, writing the
    path to ``out_dir``. A run that fails is a PeerRun saying how; raises FileNotFoundError
    only when the driver is not built."""
    driver = peer_binary(build_dir)
    if driver is None:
        raise FileNotFoundError(why_not(build_dir))
    problem_file = pathlib.Path(problem_file).resolve()
    out_dir = pathlib.Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    task = out_dir.resolve() / f"{problem_file.stem}_kautham_seed{seed}.xml"
    task.unlink(missing_ok=True)          # a path from an earlier run is not this run's
    command = [str(driver), str(problem_file), "--seed", str(seed), "--task", str(task)]
    if time_limit is not None:
        command += ["--time", repr(float(time_limit))]
    limit = time_limit if time_limit is not None else own_time_limit(problem_file)
    try:
        # in out_dir: whatever Kautham writes beside itself stays out of the clone
        done = subprocess.run(command, capture_output=True, text=True, cwd=out_dir,
                              timeout=limit + MARGIN_S)
    except subprocess.TimeoutExpired as expired:
        return PeerRun.from_output(_text(expired.stdout), _text(expired.stderr), None)
    return PeerRun.from_output(done.stdout, done.stderr, done.returncode, task)


def _text(output) -> str:
    return output.decode(errors="replace") if isinstance(output, bytes) else (output or "")


def build(build_dir: pathlib.Path = BUILD_DIR, peer: Optional[pathlib.Path] = None) -> int:
    """Builds the peer into ``build_dir`` with the peer folder's build.sh unless it is built
    already; the exit status (2, in one line, when the peer's folder is missing)."""
    build_dir = pathlib.Path(build_dir)
    peer = pathlib.Path(peer) if peer is not None else peer_dir()
    if all((build_dir / name).is_file() for name in BUILT):
        print(f"bench-kautham: Kautham is already built in {build_dir}: nothing to do")
        return 0
    script = peer / "build.sh"
    if not script.is_file():
        print(f"bench-kautham: no Kautham peer at {peer} (no build.sh there); set "
              f"{PEER_ENVIRONMENT} to its folder", file=sys.stderr)
        return 2
    print(f"bench-kautham: building Kautham 5.1.1 from {peer} into {build_dir} (apt installs "
          "its Debian dependencies; about 7 CPU minutes, JOBS=N sets make's jobs)", flush=True)
    return subprocess.run(["bash", str(script), str(build_dir)]).returncode


def main(argv: Sequence[str]) -> int:
    if list(argv) != ["build"]:
        print("usage: kautham_peer.py build   (make bench-kautham)", file=sys.stderr)
        return 2
    return build()


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
