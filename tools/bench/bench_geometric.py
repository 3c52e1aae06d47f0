"""Odin's geometric planning side by side with Kautham 5.1.1's (issue 43): Kautham's public
geometric demos, each solved by both with the same seeds (1..SEEDS) and the same time limit,
the problem's own (Kautham's ``_Max Planning Time``, kautham_peer.own_time_limit), passed to
both explicitly. Each run is a process of its own (OMPL seeds its generators once per process):
Kautham's driver (kautham_peer.solve) and Odin's ``gui.planning.geometric.solve`` (the problem
loaded as ``solve_file`` loads it) in a forked child, then, when solved, its path checked
(``deepest_along``, not timed); the two alternate who goes first from seed to seed.

Per problem P (PROBLEMS' slugs):
  geo_P_kautham_success         fraction of the seeds Kautham solved
  geo_P_kautham_median_s        median wall seconds of Kautham's solved runs (the driver's
                                Planner::solveAndInherit: setup, search, simplification)
  geo_P_success, geo_P_median_s the same for Odin (its result's time_s)
  geo_P_time_over_kautham       geo_P_median_s / geo_P_kautham_median_s (goal <= 1)
  geo_P_success_minus_kautham   geo_P_success - geo_P_kautham_success (goal >= 0)
  geo_P_deepest_mm              the deepest any link of Odin's solved paths goes into
                                anything (mm; 0 when none solved or none touched), each path
                                checked after its search (not timed) at DEEPEST_SPACING along
                                every segment (gui.planning.geometric.deepest_along; goal
                                <= 1: half the search's 2 mm resolution, issue 43)
  geo_P_kautham_deepest_mm      the same for Kautham's solved paths (its task files read back
                                as controls: gui.planning.geometric.path_of_solution), when
                                Odin is here to check them; not a goal, what Kautham's own
                                motion checks let through
Kautham 2012's problems (ODIN_ONLY) have Odin's figures only. A side that solved no run has the
time limit as its median: a bound, not a time. A run that
gave no answer (Kautham could not load the problem, Odin raised) refuses that side's figures
and the comparisons (report.Refused, with the first reason). Without the peer built (`make
bench-kautham`) the Kautham side is skipped, said in one line, and Odin's figures still come;
without ``gui.planning.geometric`` the Odin side is skipped the same way. A problem whose file
is in neither the Kautham corpus ($ODIN_KAUTHAM_DIR) nor the whole one
(tools/get_kautham.sh --all) is skipped in one line. Every run is written to
out_dir/geometric/runs.json, Kautham's paths (Task files) beside it.

``ODIN_BENCH_ROUNDS`` runs fewer seeds; ``ODIN_BENCH_GEO_PROBLEMS=tx90,ur5`` only those
problems.
"""
from __future__ import annotations

import importlib.util
import json
import logging
import os
import pathlib
import statistics
import sys
from typing import List, NamedTuple, Optional

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent.parent
sys.path.insert(0, str(HERE))

import kautham_peer  # noqa: E402
from forked import in_child  # noqa: E402
from report import Refused  # noqa: E402

SEEDS = int(os.environ.get("ODIN_BENCH_ROUNDS", 10))
GEO = pathlib.PurePosixPath("current_2025", "demos", "OMPL_geo_demos")
LEGACY = pathlib.PurePosixPath("legacy_2012", "examples")
PROBLEMS = {
    "tx90": GEO / "TX90_IOC" / "OMPL_RRTConnect_TX90_TwoCan.xml",
    "ur5": GEO / "UR5" / "ur5_table.xml",
    "ur3e": GEO / "UR3e" / "ur3e_fib_upc.xml",
    "spassage": GEO / "Cube-sPassage_R2" / "OMPL_RRTconnect_bigcube-s-passage_R2_0.05.xml",
    "maze": GEO / "Cube_Maze_R2" / "OMPL_RRTconnect_bigcube-maze2D_R2.xml",
    "chess": GEO / "chess" / "OMPL_RRTconnect_chess_ur3_gripper_2.xml",
    "tiago": GEO / "Tiago_kitchen" / "tiago_counter_A_topgrasp_simple.xml",
    "arm2012": LEGACY / "Staubli_R6_two_columns.xml",
    "se3_2012": LEGACY / "ele_two_columns_SE3.xml",
    "r2_2012": LEGACY / "table_rooms_R2.xml",
    "mobile2012": LEGACY / "Staubli_R6_mobileBase_two_columns.xml",
}
"""Slug -> the problem's path in the corpus (the issue's demos with a geometric planner: Kautham
5.1.1's, and Kautham 2012's arm, free-flyers in SE3 and R2 and arm on a mobile base, all PRM)."""
ODIN_ONLY = {"arm2012", "se3_2012", "r2_2012", "mobile2012"}
"""Problems Kautham 5.1.1 cannot load (2012's Inventor and VRML models: "iv or wrl extension no
longer supported"): Odin's side only, said in one line."""
ODIN_MODULE = "gui.planning.geometric"
PROBLEMS_ENVIRONMENT = "ODIN_BENCH_GEO_PROBLEMS"
DEEPEST_SPACING = 0.001
"""m: the spacing Odin's solved paths are checked at (gui.planning.geometric.deepest_along)."""


class Attempt(NamedTuple):
    """One side's run: ``solved``, ``time_s`` (wall s; None when it said none), ``error``
    (empty when the run answered, solved or not), ``deepest_mm`` (how deep its path goes
    into anything, mm; None when not checked: not solved, or Kautham's)."""
    solved: bool
    time_s: Optional[float]
    error: str = ""
    deepest_mm: Optional[float] = None


def _odin_solve(problem: str, seed: int, time_limit: float) -> dict:
    """One Odin run (in a child): the problem loaded and planned as ``solve_file`` does, its
    search (``time_s`` is the search's own), then, when solved, how deep its path goes
    (``deepest_along``, after the search, not timed)."""
    from gui.planning.geometric import load_plan, settings_of, solve
    logging.disable(logging.WARNING)
    plan = load_plan(problem)
    result = solve(plan, settings_of(plan, time_limit), seed)
    run = {"solved": bool(result.solved), "time_s": float(result.time_s),
           "planner": str(result.planner)}
    if result.solved:
        run.update(_depth(plan, result.path))
    return run


def _depth(plan, path) -> dict:
    """How deep ``path`` (control vectors) goes into anything: ``deepest_mm`` and its pair
    (gui.planning.geometric.deepest_along at DEEPEST_SPACING)."""
    from gui.planning.geometric import deepest_along
    deepest, pair = deepest_along(plan, path, DEEPEST_SPACING)
    return {"deepest_mm": deepest * 1000, "deepest_pair": " into ".join(pair) if pair else None}


def _odin(problem: pathlib.Path, seed: int, time_limit: float) -> dict:
    try:
        return in_child(_odin_solve, str(problem), seed, time_limit)
    except RuntimeError as error:     # Odin raised or died: no answer, said in the figures
        return {"error": str(error)}


def _kautham(problem: pathlib.Path, seed: int, time_limit: float, out_dir: pathlib.Path,
             with_odin: bool = True) -> dict:
    """One Kautham run; when solved (and Odin is here to check it), how deep its path goes
    on the problem's geometry, as Odin's paths are checked (``deepest_mm``, or
    ``deepest_error`` when Odin cannot read the path back as controls)."""
    run = kautham_peer.solve(problem, seed, time_limit, out_dir)
    said = {"solved": run.solved, "time_s": run.wall_s, "planner": run.planner,
            "states": run.states, "returncode": run.returncode, "error": run.error,
            "task_file": str(run.task_file) if run.task_file else None}
    if run.solved and run.task_file and with_odin:
        try:
            said.update(in_child(_path_depth, str(problem), str(run.task_file)))
        except RuntimeError as error:
            said["deepest_error"] = str(error).splitlines()[-1] if str(error) else "failed"
    return said


def _path_depth(problem: str, task_file: str) -> dict:
    """(in a child) How deep the path of ``task_file`` goes into anything, checked as
    ``_odin_solve`` checks Odin's (gui.planning.geometric.path_of_solution, deepest_along);
    ``deepest_error`` when the path cannot be read as the problem's (Kautham writes the chess
    gripper's mimic joints outside their limits)."""
    from gui.core.kautham.solutions import read_solution
    from gui.errors import GuiError
    from gui.planning.geometric import load_plan, path_of_solution
    logging.disable(logging.WARNING)
    plan = load_plan(problem)
    try:
        path = path_of_solution(plan, read_solution(task_file, plan.problem))
    except GuiError as error:
        return {"deepest_error": str(error)}
    return _depth(plan, path)


def attempts(runs: List[dict]) -> List[Attempt]:
    return [Attempt(bool(r.get("solved")), r.get("time_s"), r.get("error") or "",
                    r.get("deepest_mm")) for r in runs]


def _side(prefix: str, runs: List[Attempt], limit_s: float) -> dict:
    """The success and median figures of one side's runs (Refused if a run gave no answer)."""
    failed = [r.error for r in runs if r.error]
    if failed:
        why = Refused(f"{len(failed)} of {len(runs)} runs gave no answer: {failed[0]}")
        return {f"{prefix}_success": why, f"{prefix}_median_s": why}
    times = [r.time_s for r in runs if r.solved]
    return {f"{prefix}_success": round(len(times) / len(runs), 3),
            f"{prefix}_median_s": round(statistics.median(times), 4) if times else limit_s}


def _deepest(runs: List[Attempt]):
    """The largest ``deepest_mm`` of the solved runs (0.0: none solved or none touched;
    Refused if a run gave no answer)."""
    failed = [r.error for r in runs if r.error]
    if failed:
        return Refused(f"{len(failed)} of {len(runs)} runs gave no answer: {failed[0]}")
    return round(max([r.deepest_mm or 0.0 for r in runs if r.solved], default=0.0), 4)


def figures_of(slug: str, limit_s: float, kautham: Optional[List[Attempt]],
               odin: Optional[List[Attempt]]) -> dict:
    """A problem's figures (module docstring) from each side's runs (None: side skipped)."""
    figures = {}
    for prefix, runs in ((f"geo_{slug}_kautham", kautham), (f"geo_{slug}", odin)):
        if runs:
            figures.update(_side(prefix, runs, limit_s))
    if odin:
        figures[f"geo_{slug}_deepest_mm"] = _deepest(odin)
    if kautham and any(r.deepest_mm is not None for r in kautham):
        figures[f"geo_{slug}_kautham_deepest_mm"] = _deepest(kautham)
    if not (kautham and odin):
        return figures
    k_success, o_success = figures[f"geo_{slug}_kautham_success"], figures[f"geo_{slug}_success"]
    refused = next((v for v in (o_success, k_success) if isinstance(v, Refused)), None)
    if refused is not None:
        figures[f"geo_{slug}_time_over_kautham"] = refused
        figures[f"geo_{slug}_success_minus_kautham"] = refused
        return figures
    # from the unrounded medians: Kautham's TX90 solves in a few hundredths of a second
    medians = [statistics.median([r.time_s for r in runs if r.solved] or [limit_s])
               for runs in (odin, kautham)]
    figures[f"geo_{slug}_time_over_kautham"] = round(medians[0] / medians[1], 3)
    figures[f"geo_{slug}_success_minus_kautham"] = round(o_success - k_success, 3)
    return figures


def problems() -> dict:
    """Slug -> problem file of the problems found (each one not found said in one line)."""
    from gui.core.kautham.corpus import corpus_dir, whole_corpus_dir
    wanted = os.environ.get(PROBLEMS_ENVIRONMENT)
    slugs = [s.strip() for s in wanted.split(",") if s.strip()] if wanted else list(PROBLEMS)
    unknown = [s for s in slugs if s not in PROBLEMS]
    if unknown:
        raise ValueError(f"{PROBLEMS_ENVIRONMENT}: no problem {unknown}; there are "
                         f"{sorted(PROBLEMS)}")
    roots = [root for root in (corpus_dir(), whole_corpus_dir()) if root is not None]
    found = {}
    for slug in slugs:
        paths = [root / PROBLEMS[slug] for root in roots if (root / PROBLEMS[slug]).is_file()]
        if paths:
            found[slug] = paths[0]
        else:
            print(f"  geometric: {slug} skipped: no {PROBLEMS[slug]} in the Kautham corpus "
                  f"($ODIN_KAUTHAM_DIR) nor the whole one (tools/get_kautham.sh --all)")
    return found


def side_by_side(problem: pathlib.Path, limit_s: float, with_kautham: bool, with_odin: bool,
                 out_dir: pathlib.Path) -> dict:
    """Every seed's run of each side, the side going first alternating from seed to seed."""
    runs: dict = {"kautham": [], "odin": []}
    for seed in range(1, SEEDS + 1):
        for side in (("kautham", "odin") if seed % 2 else ("odin", "kautham")):
            if side == "kautham" and with_kautham:
                runs[side].append(_kautham(problem, seed, limit_s, out_dir, with_odin))
            elif side == "odin" and with_odin:
                runs[side].append(_odin(problem, seed, limit_s))
        print(f"    seed {seed}: " + ", ".join(
            f"{side} {_said(rs[-1])}" for side, rs in runs.items() if rs), flush=True)
    return runs


def _said(run: dict) -> str:
    if run.get("error"):
        return "FAILED"
    if not run["solved"]:
        return "not solved"
    deepest = run.get("deepest_mm")
    return f"solved in {run['time_s']:.3f} s" + (
        f" (deepest {deepest:.3f} mm)" if deepest is not None else "")


def run(out_dir: pathlib.Path) -> dict:
    work = pathlib.Path(out_dir) / "geometric"
    with_kautham = kautham_peer.peer_binary() is not None
    with_odin = importlib.util.find_spec(ODIN_MODULE) is not None
    if not with_kautham:
        print(f"  geometric: Kautham's side skipped: {kautham_peer.why_not()}")
    if not with_odin:
        print(f"  geometric: Odin's side skipped: no {ODIN_MODULE} to import")
    figures, details = {}, {}
    for slug, problem in problems().items():
        limit_s = kautham_peer.own_time_limit(problem)
        print(f"  geometric: {slug} ({problem.name}, {limit_s:g} s, seeds 1-{SEEDS})",
              flush=True)
        peer = with_kautham and slug not in ODIN_ONLY
        if with_kautham and not peer:
            print(f"  geometric: {slug}: Kautham's side skipped: Kautham 5.1.1 loads no 2012 "
                  "problem (its Inventor and VRML models)")
        runs = side_by_side(problem, limit_s, peer, with_odin, work / slug)
        details[slug] = {"problem": str(problem), "time_limit_s": limit_s, **runs}
        figures.update(figures_of(slug, limit_s, attempts(runs["kautham"]) if peer else None,
                                  attempts(runs["odin"]) if with_odin else None))
    work.mkdir(parents=True, exist_ok=True)
    (work / "runs.json").write_text(json.dumps(details, indent=1) + "\n")
    return figures


if __name__ == "__main__":
    print(run(ROOT / "out" / "bench"))
