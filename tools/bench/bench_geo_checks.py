"""Collision checks per second of geometric planning, Odin over Kautham 5.1.1 (issue 42), from
the two sides' OMPL benchmark logs of the same Kautham benchmark files.

For TX90_IOC (``OMPL_RRTConnect_TX90_TwoCan.xml``) and UR5 (``ur5_table.xml``) the module writes
a Kautham ``<Benchmark>`` file in a temporary folder (the problem's own planner, RUNS runs, the
problem's own ``_Max Planning Time`` as maxTime: ``benchmark_text``), and runs it with both:
Kautham's ``kautham-console -b FILE`` (its apps/console/benchmark.cpp, over OMPL 1.5's
Benchmark) and Odin's ``rosrun GUI benchmark FILE`` (gui.planning.geometric_benchmark), in
ROUNDS rounds, who goes first alternating. Odin's runs take seeds (round r: 1 + r x RUNS on);
Kautham's console takes none (OMPL draws one per process; its log records it). Both logs are
kept in out_dir/geo_checks/<problem>/, every round's tallies in out_dir/geo_checks/runs.json.

What one "collision check" is, on each side (the same unit: one configuration of every robot
checked against everything it may touch, stopping at the first contact):

* Kautham: ``collision checks`` is WorkSpace::getCollCheckCounter(), one a call of
  WorkSpace::collisionCheck(sample): every robot's links against the obstacles, the other
  robots, themselves and attached objects, with FCL (src/problem/workspace.cpp). OMPL's state
  validity callback (omplValidityChecker.cpp: out-of-bounds states are refused uncounted) makes
  them: sampled states and OMPL's discrete motion checks, one a state every
  ``longest_valid_segment_fraction`` of the space's extent. The counter is reset before a run
  and read after it, so it also counts the four checks of the path that OMPL's Benchmark makes
  outside the timed search and simplification (``correct solution`` and its ``strict`` form,
  before and after simplifying). ``path_checks`` counts those from below from the logged path
  (its first state, then per segment at least one state and at least its length over the
  resolution), and they are taken out (on TX90 about a fifth of the count). The strict
  form asks for 4 times the states, which OMPL 1.5's compound spaces (Kautham's) ignore:
  counted as the plain form.
* Odin: ``collision checks`` is GeometricResult.checks: configurations checked exactly, each
  one C call placing every link a control moves and asking ODE whether any touches anything
  (virtual_world odin_motion.c ``valid``, stopping at the first pair): OMPL's state checks and
  the exact checks of Odin's motion walk. Not counted: the walk's clearance and sweep queries
  (GeometricResult.clearance_checks), which prove stretches of a motion free without checking
  configurations there; their time is in Odin's seconds.

Seconds, both sides: the log's ``time`` (the planner's search) plus ``simplification time``
(OMPL's Benchmark simplifies every solution; Odin's benchmark too). A side's rate is the sum of
its checks (Kautham's path checks taken out) over the sum of those seconds, over every run of
every round.

  geo_checks_per_s_P_kautham   Kautham's rate on problem P (P: tx90, ur5)
  geo_checks_per_s_P           Odin's
  geo_checks_over_kautham      the smaller of the two problems' Odin / Kautham (from unrounded
                               rates): the goal (>= 1) holds for each

Without Kautham's build (``make bench-kautham``) its side is skipped in one line and Odin's
rates still come, with no ratio. A problem in neither corpus is skipped in one line and the
ratio is refused naming it; a side whose log is missing or malformed refuses its rate and the
ratio (report.Refused). ``ODIN_BENCH_ROUNDS`` below ROUNDS runs fewer rounds.
"""
from __future__ import annotations

import json
import math
import os
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile
from typing import Dict, Iterable, NamedTuple, Optional, Sequence, Tuple

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent.parent
sys.path.insert(0, str(HERE))

import kautham_peer  # noqa: E402
from bench_geometric import PROBLEMS as GEOMETRIC_PROBLEMS  # noqa: E402
from report import Refused  # noqa: E402

SLUGS = ("tx90", "ur5")
"""The problems of issue 42's figure (bench_geometric.PROBLEMS' files)."""
ROUNDS = min(2, int(os.environ.get("ODIN_BENCH_ROUNDS", 2)))
RUNS = 5
"""Runs per round and side: ROUNDS x RUNS = 10 runs a side on each problem (40 to 75 s in all on
this 2-core host under load, most of it Kautham's console outside its timed runs: loading,
OMPL's sanity checks of the space, the measures of each path)."""
CONSOLE = kautham_peer.BUILD_DIR / "apps" / "console" / "kautham-console"
"""Kautham's console, which runs benchmark files (built with the driver by make bench-kautham)."""
ODIN_TOOL = ROOT / "Odin" / "GUI" / "scripts" / "benchmark"
MARGIN_S = 120.0
"""Seconds a round may take beyond its runs' time limits: loading, OMPL's sanity checks of the
space, the path measures."""
LOGGED_DIGITS = 1e-4
"""Relative: what the logged lengths, extent and fraction (5 or 6 digits) may be off by."""
PATH_PASSES = (("correct solution", "solution length", "solution segments"),
               ("correct solution strict", "solution length", "solution segments"),
               ("simplified correct solution", "simplified solution length",
                "simplified solution segments"),
               ("simplified correct solution strict", "simplified solution length",
                "simplified solution segments"))
"""OMPL's Benchmark's checks of a solved run's path (flag, path length, its segments), each
PathGeometric::check(): the first state, then each segment's discrete motion check. The strict
passes set the space's valid segment count factor to 4, which OMPL 1.5's CompoundStateSpace
(Kautham's space) does not pass on to its components, whose counts it takes: counted as the
others (a lower bound on any space)."""


# -- OMPL's benchmark log ------------------------------------------------------------------------
class LoggedPlanner(NamedTuple):
    """One planner of a log: its common properties and its runs (property name without its
    type -> the value as written, "" when not measured)."""
    common: Dict[str, str]
    runs: Tuple[Dict[str, str], ...]


class OmplLog(NamedTuple):
    """An OMPL benchmark log: the setup text (the first <<<| ... |>>> block) and its planners
    by name."""
    setup: str
    planners: Dict[str, LoggedPlanner]


def read_log(text: str, source: str = "log") -> OmplLog:
    """The planners and runs of an OMPL benchmark log (OMPL 1.5 as Kautham's console writes it,
    OMPL 2 as gui.planning.benchmark_log writes it). ValueError naming ``source`` and the line
    when it is not one."""
    lines = text.splitlines()
    blocks, body, k = [], [], 0
    while k < len(lines):           # free text between <<<| and |>>> is not the log's structure
        if lines[k] == "<<<|":
            end = lines.index("|>>>", k + 1) if "|>>>" in lines[k + 1:] else len(lines)
            blocks.append("\n".join(lines[k + 1:end]))
            k = end + 1
            continue
        body.append((k + 1, lines[k]))
        k += 1
    cursor = _Cursor(body, source)
    count = cursor.find(r"(\d+) planners", "its planners' count")
    planners = {}
    for _ in range(count):
        name = cursor.next("a planner's name")
        common = {}
        for _ in range(cursor.count(r"(\d+) common properties")):
            key, _, value = cursor.next("a common property").partition(" = ")
            common[key.strip()] = value.strip()
        names = [cursor.next("a property's name").rsplit(" ", 1)[0]
                 for _ in range(cursor.count(r"(\d+) properties for each run"))]
        runs = []
        for _ in range(cursor.count(r"(\d+) runs")):
            line, values = cursor.line, cursor.next("a run").split(";")
            values = [v.strip() for v in (values[:-1] if values[-1].strip() == "" else values)]
            if len(values) != len(names):
                raise ValueError(f"{source}:{line}: {len(values)} values, {len(names)} "
                                 "properties")
            runs.append(dict(zip(names, values)))
        if cursor.peek().startswith(tuple("0123456789")):     # OMPL's progress properties
            for _ in range(cursor.count(r"(\d+) progress properties for each run")):
                cursor.next("a progress property's name")
            for _ in range(cursor.count(r"(\d+) runs")):
                cursor.next("a run's progress")
        line = cursor.line
        if cursor.next("the planner's closing '.'") != ".":
            raise ValueError(f"{source}:{line}: not the '.' closing planner {name}")
        planners[name] = LoggedPlanner(common, tuple(runs))
    return OmplLog(blocks[0] if blocks else "", planners)


class _Cursor:
    """The log's lines outside its free text, read in order."""

    def __init__(self, body: Sequence[Tuple[int, str]], source: str):
        self.body, self.source, self.k = body, source, 0

    @property
    def line(self) -> int:
        return self.body[self.k][0] if self.k < len(self.body) else \
            (self.body[-1][0] + 1 if self.body else 1)

    def peek(self) -> str:
        return self.body[self.k][1] if self.k < len(self.body) else ""

    def next(self, what: str) -> str:
        if self.k >= len(self.body):
            raise ValueError(f"{self.source}: ends before {what}")
        self.k += 1
        return self.body[self.k - 1][1]

    def count(self, pattern: str) -> int:
        line, text = self.line, self.next(f"'{pattern}'")
        found = re.fullmatch(pattern, text.strip())
        if not found:
            raise ValueError(f"{self.source}:{line}: {text!r} is not '{pattern}'")
        return int(found.group(1))

    def find(self, pattern: str, what: str) -> int:
        while self.k < len(self.body):
            found = re.fullmatch(pattern, self.next(what).strip())
            if found:
                return int(found.group(1))
        raise ValueError(f"{self.source}: ends before {what}")


# -- each side's checks and seconds --------------------------------------------------------------
class Tally(NamedTuple):
    """Runs of one side: their ``checks`` as logged, of which at least ``untimed`` were made
    outside the timed search and simplification (Kautham's path checks), and ``seconds`` (s:
    search + simplification)."""
    runs: int
    checks: int
    untimed: int
    seconds: float

    def rate(self) -> float:
        """Configurations checked per second of search and simplification."""
        return (self.checks - self.untimed) / self.seconds


def total(tallies: Iterable[Tally]) -> Tally:
    tallies = list(tallies)
    return Tally(sum(t.runs for t in tallies), sum(t.checks for t in tallies),
                 sum(t.untimed for t in tallies), sum(t.seconds for t in tallies))


def _number(run: Dict[str, str], name: str) -> float:
    """A run's value, 0 when not measured (a run not solved has no simplification)."""
    value = run.get(name, "")
    return float(value) if value else 0.0


def segment_length(log: OmplLog, planner: str) -> Optional[float]:
    """The longest motion OMPL's discrete motion check takes without a state between, in the
    space's metric (``longest_valid_segment_fraction`` x the space's extent), when the space has
    one component; None for several (each then has its own, and a motion's states are their
    largest count)."""
    leaves = {m.group(1) for m in re.finditer(r"^(?!\s*Compound)[^\n]*state space '([^']*)' of "
                                              r"dimension", log.setup, re.MULTILINE)}
    extent = re.search(r"^\s*- extent: (\S+)", log.setup, re.MULTILINE)
    fraction = log.planners[planner].common.get("longest_valid_segment_fraction")
    if len(leaves) != 1 or extent is None or not fraction:
        return None
    return float(fraction) * float(extent.group(1))


def path_checks(run: Dict[str, str], segment: Optional[float]) -> int:
    """At least how many configurations OMPL's Benchmark checked on a Kautham run's paths
    after its search and around its simplification (PATH_PASSES; a pass counts only when it
    found the path valid, so checked every state): per pass the first state, then per segment
    its discrete motion check's states (OMPL: ceil(its length / ``segment``), at least one;
    ``segment`` None: one per segment)."""
    checked = 0
    for flag, length, segments in PATH_PASSES:
        if run.get(flag) != "1" or not run.get(segments):
            continue
        states = int(run[segments])
        if segment is not None and run.get(length):
            states = max(states, math.ceil(float(run[length]) / segment * (1 - LOGGED_DIGITS)))
        checked += 1 + states
    return checked


def _runs(log: OmplLog) -> Tuple[str, Tuple[Dict[str, str], ...]]:
    if len(log.planners) != 1:
        raise ValueError(f"{len(log.planners)} planners in the log, not one")
    name, planner = next(iter(log.planners.items()))
    for k, run in enumerate(planner.runs):
        if not run.get("collision checks"):
            raise ValueError(f"run {k + 1} has no collision checks")
    return name, planner.runs


def kautham_tally(log: OmplLog) -> Tally:
    """Kautham's runs, its path checks counted apart (``path_checks``)."""
    name, runs = _runs(log)
    segment = segment_length(log, name)
    return Tally(len(runs), sum(int(r["collision checks"]) for r in runs),
                 sum(path_checks(r, segment) for r in runs),
                 sum(_number(r, "time") + _number(r, "simplification time") for r in runs))


def odin_tally(log: OmplLog) -> Tally:
    """Odin's runs (no checks outside its search and simplification)."""
    _, runs = _runs(log)
    return Tally(len(runs), sum(int(r["collision checks"]) for r in runs), 0,
                 sum(_number(r, "time") + _number(r, "simplification time") for r in runs))


# -- the figures ---------------------------------------------------------------------------------
Side = Optional[object]      # a Tally, a Refused, or None (the side was skipped)


def _rate(side) -> object:
    if isinstance(side, Refused):
        return side
    if side.runs == 0 or not side.seconds > 0:
        return Refused(f"{side.runs} runs in {side.seconds} s: no rate")
    return round(side.rate())


def figures_of(measured: Dict[str, Tuple[Side, Side]], wanted: Sequence[str] = SLUGS) -> dict:
    """The figures (module docstring) of each problem's (Kautham, Odin) tallies; ``wanted``:
    the problems the ratio is over."""
    figures = {}
    for slug, (kautham, odin) in measured.items():
        if kautham is not None:
            figures[f"geo_checks_per_s_{slug}_kautham"] = _rate(kautham)
        if odin is not None:
            figures[f"geo_checks_per_s_{slug}"] = _rate(odin)
    if all(kautham is None for kautham, _ in measured.values()):
        return figures                          # Kautham skipped: said in one line
    ratios = []
    for slug in wanted:
        if slug not in measured:
            figures["geo_checks_over_kautham"] = Refused(
                f"{slug} not measured: no {GEOMETRIC_PROBLEMS[slug]} in the Kautham corpora")
            return figures
        rates = [_rate(side) for side in measured[slug]]
        refused = next((r for r in rates if isinstance(r, Refused)), None)
        if refused is not None:
            figures["geo_checks_over_kautham"] = Refused(f"{slug}: {refused.reason}")
            return figures
        kautham, odin = measured[slug]
        ratios.append(odin.rate() / kautham.rate())
    figures["geo_checks_over_kautham"] = round(min(ratios), 3)
    return figures


# -- running both sides --------------------------------------------------------------------------
def benchmark_text(slug: str, problem: pathlib.Path, folder: pathlib.Path, limit_s: float,
                   runs: int) -> str:
    """A Kautham ``<Benchmark>`` file in ``folder`` running ``problem``'s own planner ``runs``
    times at ``limit_s`` s, its log named ``<slug>.log`` (the problem's path relative to the
    folder: Kautham's console joins it to the file's folder as text)."""
    file = os.path.relpath(pathlib.Path(problem).resolve(), pathlib.Path(folder).resolve())
    return (f'<Benchmark Name="{slug}">\n'
            f'\t<Problem File="{file}" PlannerAlias="{slug}" />\n'
            f'\t<Parameter Name="maxTime" Value="{limit_s:g}" />\n'
            f'\t<Parameter Name="maxMem" Value="4096" />\n'
            f'\t<Parameter Name="runCount" Value="{runs}" />\n'
            f'\t<Parameter Name="displayProgress" Value="false" />\n'
            f'\t<Parameter Name="saveConsoleOutput" Value="false" />\n'
            f'\t<Parameter Name="filename" Value="{slug}.log" />\n'
            '</Benchmark>\n')


def _kautham_round(file: pathlib.Path, work: pathlib.Path, limit_s: float) -> str:
    """Kautham's console runs the benchmark ``file``; its log's text (it writes the log beside
    the file). RuntimeError, with its last lines, when it wrote none."""
    log = file.with_name(f"{file.stem}.log")
    log.unlink(missing_ok=True)
    try:
        done = subprocess.run([str(CONSOLE), "-b", str(file)], cwd=work, capture_output=True,
                              text=True, timeout=RUNS * limit_s + MARGIN_S)
    except subprocess.TimeoutExpired:
        raise RuntimeError(f"kautham-console: no end within {RUNS * limit_s + MARGIN_S:g} "
                           "s: killed") from None
    if not log.is_file():
        tail = " | ".join(line.strip() for line in done.stdout.splitlines()[-3:])
        raise RuntimeError(f"kautham-console wrote no log (status {done.returncode}): {tail}")
    return log.read_text()


def _odin_round(file: pathlib.Path, work: pathlib.Path, seed: int, limit_s: float) -> str:
    """``rosrun GUI benchmark FILE`` (the tool run by this python, runs one after another, each
    a process of its own) with run k's seed ``seed + k``; its log's text. RuntimeError with the
    tool's one-line error when it fails."""
    out = work / "odin"
    shutil.rmtree(out, ignore_errors=True)
    try:
        done = subprocess.run([sys.executable, str(ODIN_TOOL), str(file), "--out", str(out),
                               "--workers", "0", "--no-plots", "--seed", str(seed)],
                              capture_output=True, text=True, timeout=RUNS * limit_s + MARGIN_S)
    except subprocess.TimeoutExpired:
        raise RuntimeError(f"rosrun GUI benchmark: no end within {RUNS * limit_s + MARGIN_S:g} "
                           "s: killed") from None
    if done.returncode != 0:
        said = done.stderr.strip().splitlines()
        raise RuntimeError(f"rosrun GUI benchmark: status {done.returncode}: "
                           f"{said[-1] if said else 'nothing said'}")
    return (out / f"{file.stem}.log").read_text()


def problems() -> Dict[str, pathlib.Path]:
    """Slug -> problem file of SLUGS found in the Kautham corpus or the whole one (each one
    not found said in one line)."""
    from gui.core.kautham.corpus import corpus_dir, whole_corpus_dir
    roots = [root for root in (corpus_dir(), whole_corpus_dir()) if root is not None]
    found = {}
    for slug in SLUGS:
        paths = [root / GEOMETRIC_PROBLEMS[slug] for root in roots
                 if (root / GEOMETRIC_PROBLEMS[slug]).is_file()]
        if paths:
            found[slug] = paths[0]
        else:
            print(f"  geo_checks: {slug} skipped: no {GEOMETRIC_PROBLEMS[slug]} in the Kautham "
                  "corpus ($ODIN_KAUTHAM_DIR) nor the whole one (tools/get_kautham.sh --all)")
    return found


def _side(name: str, logs: list, reader, text_of) -> object:
    """A side's tally of one round (``text_of()`` runs it and answers its log's text, kept in
    ``logs``), or Refused saying why there is none."""
    try:
        text = text_of()
    except RuntimeError as error:
        return Refused(str(error))
    logs.append(text)
    try:
        return reader(read_log(text, f"{name}'s log"))
    except ValueError as error:
        return Refused(str(error))


def _said(tally) -> str:
    if isinstance(tally, Refused):
        return f"REFUSED ({tally.reason})"
    untimed = f" ({tally.untimed:,} of them path checks, untimed)" if tally.untimed else ""
    return (f"{tally.checks:,} checks{untimed} in {tally.seconds:.3f} s: "
            f"{tally.rate():,.0f} /s" if tally.seconds > 0 else f"{tally.checks:,} checks in 0 s")


def run(out_dir: pathlib.Path) -> dict:
    work_dir = pathlib.Path(out_dir) / "geo_checks"
    with_kautham = CONSOLE.is_file() and os.access(CONSOLE, os.X_OK)
    if not with_kautham:
        print(f"  geo_checks: Kautham's side skipped: Kautham is not built: no {CONSOLE}; "
              "`make bench-kautham` builds it")
    measured, details = {}, {}
    for slug, problem in problems().items():
        limit_s = kautham_peer.own_time_limit(problem)
        print(f"  geo_checks: {slug} ({problem.name}, {limit_s:g} s, {ROUNDS} rounds of {RUNS} "
              "runs a side)", flush=True)
        sides: Dict[str, list] = {"kautham": [], "odin": []}
        logs: Dict[str, list] = {"kautham": [], "odin": []}
        with tempfile.TemporaryDirectory(prefix="odin_geo_checks_") as temporary:
            folder = pathlib.Path(temporary)
            file = folder / f"{slug}.xml"
            file.write_text(benchmark_text(slug, problem, folder, limit_s, RUNS))
            for r in range(ROUNDS):
                seed = 1 + r * RUNS
                order = ("kautham", "odin") if r % 2 == 0 else ("odin", "kautham")
                for side in order:
                    if side == "kautham" and with_kautham:
                        sides[side].append(_side("Kautham", logs[side], kautham_tally,
                                                 lambda: _kautham_round(file, folder, limit_s)))
                    elif side == "odin":
                        sides[side].append(_side("Odin", logs[side], odin_tally,
                                                 lambda: _odin_round(file, folder, seed, limit_s)))
                print(f"    round {r + 1}: " + "; ".join(
                    f"{side} {_said(tallies[-1])}" for side, tallies in sides.items()
                    if tallies), flush=True)
        _keep(work_dir / slug, logs)
        kautham, odin = (_sum(sides[s]) if sides[s] else None for s in ("kautham", "odin"))
        measured[slug] = (kautham, odin)
        details[slug] = {"problem": str(problem), "time_limit_s": limit_s, "runs_a_round": RUNS,
                         **{s: [t._asdict() if isinstance(t, Tally) else {"refused": t.reason}
                                for t in sides[s]] for s in sides}}
    work_dir.mkdir(parents=True, exist_ok=True)
    (work_dir / "runs.json").write_text(json.dumps(details, indent=1) + "\n")
    return figures_of(measured)


def _sum(tallies: list) -> object:
    refused = next((t for t in tallies if isinstance(t, Refused)), None)
    return refused if refused is not None else total(tallies)


def _keep(folder: pathlib.Path, logs: Dict[str, list]) -> None:
    """Each round's log of each side, as round<k>_<side>.log."""
    folder.mkdir(parents=True, exist_ok=True)
    for side, texts in logs.items():
        for k, text in enumerate(texts):
            (folder / f"round{k + 1}_{side}.log").write_text(text)


if __name__ == "__main__":
    print(run(ROOT / "out" / "bench"))
