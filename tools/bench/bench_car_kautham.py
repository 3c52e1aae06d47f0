"""The car's planning speed against Kautham 5.1.1 (issue 42): Kautham's ODE car demo
(tools/kautham/ode_demos/.../Car/k-PMPCar.xml, its KPIECECarPlanner: OMPL's control KPIECE1)
searched by both with the same seeds (1..SEEDS) and the same time limit, the problem's own
``_Max Planning Time`` (120 s; KauthamDEPlanner's default, 60 s, when a problem sets none),
passed to both explicitly. Every run is a process of its own (OMPL seeds its generators once
per process): Kautham's driver (``kautham-peer-solve``, kautham_peer.py) and Odin's
``gui.planning.bridge.plan`` over a ``CoreBackend`` in a forked child; the two alternate who
goes first from seed to seed (Kautham first on odd seeds).

What each side counts, over its search only (OMPL's solve; not loading, setup or replay):
  Kautham  ODE world steps: ``dWorldQuickStep`` + ``dWorldStep`` calls of the whole process,
           counted by LD_PRELOAD=build/kautham/libodecount.so (its ``ODECOUNT quickstep N
           worldstep M`` line on stderr at exit; OMPL's OpenDEStatePropagator makes one
           QuickStep of PropagationStepSize, 0.05 s, per propagation, and nothing else in
           the process steps), over OMPL's own search time T, its ``Solution found in T
           seconds`` (or ``No solution found after T seconds``) line.
  Odin     ODE world steps: its search's propagations (PlanResult.propagations) times the
           world steps one propagation makes (the problem's step over the world's: 1 for the
           car, 0.05 s each; recorded per run), over PlanResult.time_s (wall s of OMPL's
           solve).

Kautham runs headless (DISPLAY removed): after a search with a solution its
KauthamDEPlanner::trySolve opens a drawstuff window, whose ``dsError("can not open X11
display")`` ends the process with status 1 before the driver's ``PEER solved`` line (under a
display, or Xvfb, the window never closes); the step counter still prints at exit. So a run is
read from Kautham's and OMPL's own lines: ``1st Query is solved`` (Kautham's ``_solved``, OMPL's
status as a bool: true for an approximate solution too), OMPL's ``ProblemDefinition: Adding
approximate solution`` line, and T. The rule for "solved": Kautham says ``1st Query is solved``
and OMPL added no approximate solution. KPIECE1 stops before its limit only with an exact
solution, so a solved run ends below the limit and one with an approximate solution at it
(checked on runs here: seed 1 at 60 s, exact in 33.4 s; seed 1 at 20 s, approximate at 20.08
s); an approximate solution more than EXACT_MARGIN below the limit contradicts that and the
run counts as no answer. A run gives no answer (refusing its side's figures and the
comparisons) when it has no search time or no ODECOUNT line, ended otherwise than with status 0
or 1 (a signal, Kautham's load failure 3, its error 4), or was killed after its limit and
kautham_peer.MARGIN_S.

The two searches are the same problem as far as the files say: the same query, planner
(KPIECE1, goal bias 0.05), PropagationStepSize (0.05 s), Max Control Steps (50) and time limit.
Where Kautham 5.1.1 departs from its file, Odin is given what Kautham searches, so that both
solve the same query: its CarEnvironment takes the control steps in the planner's constructor,
before the file's parameters are read, so it searches with 2 to 50 steps a control (OMPL prints
``min_control_duration = 2``; KAUTHAM_MIN_CONTROL_STEPS) where Odin would read the file's 5 to
50; its goal region (KauthamDEGoalRegion, threshold 0.05) sums the base's planar distance to
the goal, plus a term for moving away from it, once per robot link (5 for SimpleCar), so the
base must end within about 0.01 m (KAUTHAM_GOAL_M), where Odin's own region is 0.25 m
(SearchSettings.goal_tolerance). Still different:
Odin's world keeps CFM 1e-05 where the file's 0.3 would sink its contacts (its loader says so);
and Odin counts a run solved only when its replay ends in the goal region with no forbidden
contact (PlanResult.solved), Kautham on OMPL's exact solution.

Figures:
  plan_car_steps_over_kautham   median over seeds of Odin's world steps per second over
                                Kautham's, each pair of the same seed (goal >= 1)
  plan_car_steps_per_s          median over seeds of Odin's world steps per second
  plan_car_kautham_steps_per_s  the same for Kautham
  plan_car_success              fraction of the seeds Odin solves (PlanResult.solved)
  plan_car_kautham_success      fraction of the seeds Kautham solves exactly (the rule above)
  plan_car_median_s             median search seconds of Odin's solved runs (the limit when
                                none solved: a bound, not a time)
  plan_car_kautham_median_s     the same for Kautham (OMPL's T)
  plan_car_success_minus_kautham  plan_car_success - plan_car_kautham_success (goal >= 0)
  plan_car_time_over_kautham    plan_car_median_s / plan_car_kautham_median_s, from the
                                unrounded medians (goal <= 1)
Without the peer built (`make bench-kautham`: the driver and libodecount.so in build/kautham)
the Kautham side is skipped, said in one line, and Odin's three figures still come. Every run
is written to out_dir/car_kautham/runs.json. ``ODIN_BENCH_ROUNDS`` sets SEEDS (default 5).
"""
from __future__ import annotations

import json
import logging
import os
import pathlib
import re
import statistics
import subprocess
import sys
import xml.etree.ElementTree as ElementTree
from typing import List, Mapping, NamedTuple, Optional

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent.parent
sys.path.insert(0, str(HERE))

import kautham_peer  # noqa: E402
from forked import in_child  # noqa: E402
from report import Refused  # noqa: E402

SEEDS = int(os.environ.get("ODIN_BENCH_ROUNDS", 5))
CAR = ROOT / "tools" / "kautham" / "ode_demos" / "demos" / "OMPL_ode_demos" / "Car" / \
    "k-PMPCar.xml"
PLANNER = "KPIECE1"
KAUTHAM_GOAL_M = 0.05 / 5
"""m: Kautham's car goal region as Odin's planar radius: KauthamDEGoalRegion's 0.05 threshold
over its sum of the base's planar distance once per link of SimpleCar (5). Odin searches it,
not its own 0.25 m, so that both sides solve the same query (its term for moving away from the
goal has no equivalent: Odin's region is the looser by it)."""
KAUTHAM_MIN_CONTROL_STEPS = 2
"""The fewest steps a control lasts in Kautham 5.1.1's car search (its CarEnvironment is built
before the file's Min Control Steps 5 is read; OMPL prints min_control_duration = 2): Odin is
given the same."""
"""OMPL's control KPIECE1: what Kautham's KPIECECarPlanner runs (oc::KPIECE1)."""
BUILD_DIR = kautham_peer.BUILD_DIR
ODECOUNT_NAME = "libodecount.so"
ODE_DEFAULT_TIME_S = 60.0
"""s: KauthamDEPlanner's ``_Max Planning Time`` when a problem sets none (its constructor)."""
EXACT_MARGIN = 0.01
"""An approximate solution before (1 - EXACT_MARGIN) of the limit contradicts KPIECE1, which
stops early only with an exact one: such a run is no answer."""
TAIL_LINES = 6

_SEARCH_TIME = re.compile(r"(?:Solution found in|No solution found after) (\S+) seconds")
_ODECOUNT = re.compile(r"^ODECOUNT quickstep (\d+) worldstep (\d+)\s*$", re.MULTILINE)
KAUTHAM_SOLVED = "1st Query is solved"
OMPL_APPROXIMATE = "ProblemDefinition: Adding approximate solution"


class Run(NamedTuple):
    """One side's run of one seed: ``solved`` (the module docstring's rule), ``time_s`` (s, the
    search's), ``steps`` (ODE world steps of the search); ``error`` (empty when the run
    answered, solved or not; then time_s and steps may be None)."""
    seed: int
    solved: bool
    time_s: Optional[float]
    steps: Optional[int]
    error: str = ""

    @property
    def steps_per_s(self) -> float:
        return self.steps / self.time_s


def time_limit(problem_file: pathlib.Path) -> float:
    """s: the problem's own time limit as Kautham's ODE planners read it (its planner's
    ``_Max Planning Time``), else ODE_DEFAULT_TIME_S."""
    root = ElementTree.parse(problem_file).getroot()
    for parameter in root.iterfind("./Planner/Parameters/Parameter"):
        if (parameter.get("name") or "").strip() == kautham_peer.KAUTHAM_TIME_PARAMETER:
            return float((parameter.text or "").strip())
    return ODE_DEFAULT_TIME_S


def read_kautham(stdout: str, stderr: str, returncode: Optional[int], limit_s: float) -> dict:
    """One Kautham run from its output and exit status (None: killed), as runs.json keeps
    it: ``solved``, ``claimed`` (Kautham's ``1st Query is solved``), ``approximate`` (OMPL
    added an approximate solution), ``time_s`` (OMPL's T), ``quicksteps``, ``worldsteps``,
    ``steps`` (their sum), ``returncode``, ``error`` (module docstring)."""
    found = _SEARCH_TIME.search(stdout)
    time_s = float(found.group(1)) if found else None
    counted = _ODECOUNT.search(stderr)
    quick, world = (int(counted.group(1)), int(counted.group(2))) if counted else (None, None)
    claimed = KAUTHAM_SOLVED in stdout
    approximate = OMPL_APPROXIMATE in stdout
    run = {"solved": False, "claimed": claimed, "approximate": approximate, "time_s": time_s,
           "quicksteps": quick, "worldsteps": world,
           "steps": quick + world if counted else None, "returncode": returncode, "error": ""}
    why = []
    if returncode is None:
        why.append("no answer within the time limit and kautham_peer.MARGIN_S: killed")
    elif returncode < 0:
        why.append(f"Kautham ended by signal {-returncode}")
    elif returncode not in (0, 1):
        why.append(kautham_peer.FAILURES.get(returncode, f"Kautham ended with status "
                                                         f"{returncode}"))
    if time_s is None:
        why.append("no OMPL search time (Solution found in / No solution found after)")
    elif time_s <= 0:
        why.append(f"OMPL's search time {time_s} s is not positive")
    elif approximate and time_s < (1.0 - EXACT_MARGIN) * limit_s:
        why.append(f"an approximate solution after {time_s:g} s, before the {limit_s:g} s "
                   "limit: KPIECE1 stops early only with an exact one")
    if not counted:
        why.append(f"no ODECOUNT line (LD_PRELOAD={ODECOUNT_NAME})")
    if why:
        said = [line.strip() for line in stdout.splitlines()
                if line.startswith(("Error", "PEER load failed"))]
        tail = [line.strip() for line in stderr.splitlines() if line.strip()][-TAIL_LINES:]
        run["error"] = "; ".join(why) + "".join(f" | {line}" for line in said + tail)
    else:
        run["solved"] = claimed and not approximate
    return run


def runs_of(records: List[dict]) -> List[Run]:
    """The runs of runs.json's records (either side's)."""
    return [Run(r["seed"], bool(r.get("solved")), r.get("time_s"), r.get("steps"),
                r.get("error") or "") for r in records]


def _refusal(runs: List[Run]) -> Optional[Refused]:
    failed = [r.error for r in runs if r.error]
    return Refused(f"{len(failed)} of {len(runs)} runs gave no answer: {failed[0]}") \
        if failed else None


def _median_time(runs: List[Run], limit_s: float) -> float:
    return statistics.median([r.time_s for r in runs if r.solved] or [limit_s])


def _side(prefix: str, runs: List[Run], limit_s: float) -> dict:
    names = [f"{prefix}_success", f"{prefix}_median_s", f"{prefix}_steps_per_s"]
    refused = _refusal(runs)
    if refused is not None:
        return dict.fromkeys(names, refused)
    solved = sum(r.solved for r in runs)
    return dict(zip(names, (round(solved / len(runs), 3),
                            round(_median_time(runs, limit_s), 3),
                            round(statistics.median(r.steps_per_s for r in runs), 1))))


def figures_of(limit_s: float, kautham: Optional[List[Run]],
               odin: Optional[List[Run]]) -> dict:
    """The figures (module docstring) from each side's runs (None: the side skipped)."""
    figures = {}
    if odin:
        figures.update(_side("plan_car", odin, limit_s))
    if kautham:
        figures.update(_side("plan_car_kautham", kautham, limit_s))
    if not (odin and kautham):
        return figures
    names = ("plan_car_steps_over_kautham", "plan_car_success_minus_kautham",
             "plan_car_time_over_kautham")
    refused = _refusal(odin) or _refusal(kautham)
    if refused is not None:
        figures.update(dict.fromkeys(names, refused))
        return figures
    theirs = {r.seed: r for r in kautham}
    paired = [r.steps_per_s / theirs[r.seed].steps_per_s for r in odin if r.seed in theirs]
    figures["plan_car_steps_over_kautham"] = round(statistics.median(paired), 3) \
        if paired else Refused("no seed run by both sides")
    figures["plan_car_success_minus_kautham"] = round(
        figures["plan_car_success"] - figures["plan_car_kautham_success"], 3)
    # from the unrounded medians
    figures["plan_car_time_over_kautham"] = round(
        _median_time(odin, limit_s) / _median_time(kautham, limit_s), 3)
    return figures


def kautham_environment(environ: Mapping[str, str]) -> dict:
    """``environ`` for Kautham's driver: no DISPLAY (the module docstring: its drawstuff
    window would never close), the step counter preloaded before anything else preloaded."""
    environment = {k: v for k, v in environ.items() if k != "DISPLAY"}
    preload = [str(BUILD_DIR / ODECOUNT_NAME)] + environ.get("LD_PRELOAD", "").split()
    environment["LD_PRELOAD"] = " ".join(preload)
    return environment


def _why_not_built() -> Optional[str]:
    """Why Kautham's side cannot run (one line), or None when it can."""
    if kautham_peer.peer_binary(BUILD_DIR) is None:
        return kautham_peer.why_not(BUILD_DIR)
    if not (BUILD_DIR / ODECOUNT_NAME).is_file():
        return (f"no {BUILD_DIR / ODECOUNT_NAME} to count its ODE steps; `make bench-kautham` "
                "builds it")
    return None


def _kautham(problem: pathlib.Path, seed: int, limit_s: float, work: pathlib.Path) -> dict:
    """One Kautham run in a process of its own, in ``work`` (Kautham writes files beside
    itself), read by ``read_kautham``."""
    work.mkdir(parents=True, exist_ok=True)
    command = [str(BUILD_DIR / kautham_peer.DRIVER), str(problem), "--seed", str(seed),
               "--time", repr(float(limit_s))]
    try:
        done = subprocess.run(command, capture_output=True, text=True, cwd=work,
                              env=kautham_environment(os.environ),
                              timeout=limit_s + kautham_peer.MARGIN_S)
        stdout, stderr, returncode = done.stdout, done.stderr, done.returncode
    except subprocess.TimeoutExpired as expired:
        stdout, stderr, returncode = (_text(expired.stdout), _text(expired.stderr), None)
    return {"seed": seed, **read_kautham(stdout, stderr, returncode, limit_s)}


def _text(output) -> str:
    return output.decode(errors="replace") if isinstance(output, bytes) else (output or "")


def _odin_solve(problem: str, seed: int, limit_s: float) -> dict:
    """(in a child) One Odin search of the car: the problem's build and search settings, a
    CoreBackend, KPIECE1 with ``seed`` for ``limit_s`` s."""
    from gui.core.kautham.problem import load_problem
    from gui.core.translate import plan_problem
    from gui.planning.backend import CoreBackend
    from gui.planning.bridge import plan
    from gui.planning.problem import SearchSettings, planning_problem
    logging.disable(logging.WARNING)
    build = plan_problem(load_problem(problem))
    search = planning_problem(build, None, SearchSettings.of_problem(
        build, goal_tolerance=KAUTHAM_GOAL_M, min_control_steps=KAUTHAM_MIN_CONTROL_STEPS))
    backend = CoreBackend(build, search)
    try:
        world_step = backend.world.step_values().step
        per = max(1, round(search.step / world_step))    # as the Core splits a propagation
        result = plan(backend, PLANNER, limit_s, seed=seed)
    finally:
        backend.close()
    return {"solved": bool(result.solved), "time_s": float(result.time_s),
            "propagations": int(result.propagations), "steps_per_propagation": per,
            "steps": int(result.propagations) * per, "world_step_s": float(world_step),
            "status": str(result.status), "goal_distance_m": round(result.goal_distance, 4),
            "verdict": result.verdict}


def _odin(problem: pathlib.Path, seed: int, limit_s: float) -> dict:
    try:
        return {"seed": seed, **in_child(_odin_solve, str(problem), seed, limit_s)}
    except RuntimeError as error:     # Odin raised or died: no answer, said in the figures
        return {"seed": seed, "error": str(error)}


def _said(run: dict) -> str:
    if run.get("error"):
        return "FAILED"
    rate = f"{run['steps'] / run['time_s']:,.0f} steps/s"
    return (f"solved in {run['time_s']:.1f} s" if run["solved"] else
            f"not solved in {run['time_s']:.1f} s") + f", {rate}"


def run(out_dir: pathlib.Path) -> dict:
    work = pathlib.Path(out_dir) / "car_kautham"
    limit_s = time_limit(CAR)
    missing = _why_not_built()
    if missing:
        print(f"  car_kautham: Kautham's side skipped: {missing}")
    print(f"  car_kautham: {CAR.name} ({PLANNER}, {limit_s:g} s, seeds 1-{SEEDS})", flush=True)
    runs: dict = {"kautham": [], "odin": []}
    for seed in range(1, SEEDS + 1):
        for side in (("kautham", "odin") if seed % 2 else ("odin", "kautham")):
            if side == "kautham" and not missing:
                runs[side].append(_kautham(CAR, seed, limit_s, work / "kautham"))
            elif side == "odin":
                runs[side].append(_odin(CAR, seed, limit_s))
        print(f"    seed {seed}: " + ", ".join(
            f"{side} {_said(rs[-1])}" for side, rs in runs.items() if rs), flush=True)
    work.mkdir(parents=True, exist_ok=True)
    (work / "runs.json").write_text(json.dumps(
        {"problem": str(CAR), "planner": PLANNER, "time_limit_s": limit_s, **runs},
        indent=1) + "\n")
    return figures_of(limit_s, None if missing else runs_of(runs["kautham"]),
                      runs_of(runs["odin"]))


if __name__ == "__main__":
    print(run(ROOT / "out" / "bench"))
