"""The report of `make corpus` (tools/corpus/run.py): counts, out/corpus/report.md, and the
counts between the README's corpus markers, generated as the bench table is."""
from __future__ import annotations

import datetime
import pathlib

ROOT = pathlib.Path(__file__).resolve().parent.parent.parent
README_PATH = ROOT / "README.md"
BEGIN = ("<!-- corpus figures begin: written by tools/corpus/corpus_report.py from "
         "out/corpus/report.json; do not edit -->")
END = "<!-- corpus figures end -->"


def outcome(result: dict) -> str:
    """ok | refused | failed for one file, every pass together (a search that is not solved,
    or refused with its reason, is no failure)."""
    if result["status"] != "ok":
        return result["status"]
    failed = result.get("world") == "failed" or result.get("plan") == "failed"
    return "failed" if failed else "ok"


def counts(results: dict) -> dict:
    out = dict(files=len(results), ok=0, refused=0, failed=0, tracebacks=0,
               refused_not_problem=0, refused_missing=0, refused_unexpected=0, simulated=0,
               world_failed=0)
    for result in results.values():
        out[outcome(result)] += 1
        out["tracebacks"] += bool(result.get("traceback"))
        if result["status"] == "refused":
            key = {"not a problem": "refused_not_problem",
                   "missing file": "refused_missing"}.get(result["refusal"],
                                                          "refused_unexpected")
            out[key] += 1
        out["simulated"] += result.get("world") == "ok"
        out["world_failed"] += result.get("world") == "failed"
    out.update(plan_counts(results))
    return out


def plan_counts(results: dict) -> dict:
    """The planning pass's counts (tools/corpus/corpus_plan.py): planned, solved, not solved,
    refused (``plan_refusals``: by kind), failed, and skipped (physics problems, problems
    naming no planner)."""
    out = dict(planned=0, solved=0, not_solved=0, plan_refused=0, plan_failed=0,
               skipped_physics=0, skipped_no_planner=0, plan_refusals={})
    for result in results.values():
        plan = result.get("plan")
        if plan == "skipped":
            out["skipped_physics" if result["skip"] == "physics" else "skipped_no_planner"] += 1
            continue
        if plan is None:
            continue
        out["planned"] += 1
        out[{"solved": "solved", "not solved": "not_solved", "refused": "plan_refused",
             "failed": "plan_failed"}[plan]] += 1
        if plan == "refused":
            kinds = out["plan_refusals"]
            kinds[result["refusal"]] = kinds.get(result["refusal"], 0) + 1
    return out


def _refusals(c: dict) -> str:
    """"12 (5 planner unknown, 4 no query, ...)": the refused problems by kind, most first."""
    kinds = sorted(c["plan_refusals"].items(), key=lambda item: (-item[1], item[0]))
    return f"{c['plan_refused']}" + (" (" + ", ".join(f"{n} {kind}" for kind, n in kinds)
                                     + ")" if kinds else "")


def plan_summary_line(c: dict) -> str:
    return (f"corpus: planning: {c['planned']} problems planned: {c['solved']} solved, "
            f"{c['not_solved']} not solved in their time limit, refused {_refusals(c)}, "
            f"{c['plan_failed']} failed; skipped {c['skipped_physics']} physics problems, "
            f"{c['skipped_no_planner']} naming no planner")


def summary_line(c: dict) -> str:
    return (f"corpus: {c['files']} problem files: {c['ok']} ok, {c['refused']} refused "
            f"({c['refused_not_problem']} not problems, {c['refused_missing']} naming a file "
            f"the repository lacks, {c['refused_unexpected']} unexpected), {c['failed']} "
            f"failed, {c['tracebacks']} tracebacks")


def _when(run: dict) -> str:
    return datetime.datetime.fromtimestamp(run["started"], datetime.timezone.utc) \
        .strftime("%Y-%m-%d %H:%M UTC")


def readme_block(run: dict, c: dict) -> str:
    return (f"Last run: {_when(run)}; `make corpus` took {run['minutes']:.0f} min, "
            f"{run['seconds']:g} s simulated per problem.\n\n"
            "| problem files | ok (loads, builds, stands, plans or says why not) | refused: "
            "not a problem | refused: names a file the repository lacks | refused: other | "
            "failed | tracebacks |\n"
            "|---|---|---|---|---|---|---|\n"
            f"| {c['files']} | {c['ok']} | {c['refused_not_problem']} | {c['refused_missing']} "
            f"| {c['refused_unexpected']} | {c['failed']} | {c['tracebacks']} |\n\n"
            + _plan_block(run, c) +
            "Tests over the whole corpus (fuzz of every file problem_info opens; URDF "
            "kinematics against robot_state_publisher): "
            + (run["tests"]["summary"] if run.get("tests") else "not run") + ".\n")


def _how_planned(run: dict) -> str:
    capped = run.get("plan_seconds")
    return ("OMPL seed 1, each search in the problem's own time limit"
            + (f", capped at {capped:g} s: a quick run, not the problems' own figures"
               if capped else ""))


def _plan_block(run: dict, c: dict) -> str:
    """The README's planning figures, or a line saying the pass did not run."""
    if not run.get("planned"):
        return "Planning (the geometric problems searched): not run.\n\n"
    return (f"Planning: every geometric problem's query searched by Odin ({_how_planned(run)})."
            "\n\n| planned | solved | not solved in its time limit | refused (by kind) | "
            "failed | skipped: physics problems | skipped: no planner named |\n"
            "|---|---|---|---|---|---|---|\n"
            f"| {c['planned']} | {c['solved']} | {c['not_solved']} | {_refusals(c)} | "
            f"{c['plan_failed']} | {c['skipped_physics']} | {c['skipped_no_planner']} |\n\n")


def rewrite_readme(block: str, path: pathlib.Path = README_PATH) -> None:
    text = path.read_text()
    start, end = text.find(BEGIN), text.find(END)
    if start < 0 or end < start:
        raise ValueError(f"{path} has no {BEGIN!r} ... {END!r} markers")
    path.write_text(text[:start + len(BEGIN)] + "\n" + block + text[end:])


def markdown(run: dict, results: dict, c: dict) -> str:
    lines = [f"# Kautham's whole corpus through Odin ({_when(run)})", "",
             summary_line(c) + ".", "",
             f"Corpus: `{run['corpus']}`; {run['seconds']:g} s simulated per problem"
             + ("" if run["simulated"] else " (no simulation: problem_info only)")
             + (f"; only files holding `{run['only']}`" if run["only"] else "") + ".", "",
             "Tests over the whole corpus (fuzz; URDF kinematics against KDL): "
             + (run["tests"]["summary"] if run.get("tests") else "not run") + ".", "",
             f"{_overlapping(results)} files build parts inside each other where the problem "
             "places them (gui.core.overlaps: exempt until they have moved apart in a problem "
             "Kautham never simulates, pushed apart under its physics; last column).", "",
             "| file | outcome | reason | load s | bodies | diverged | fell | ground | "
             "largest drop m | robots (kind: largest link move mm) | built inside each other: "
             "pairs (deepest mm) |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for name, result in sorted(results.items()):
        reason = result.get("world_reason") or result.get("reason") or ""
        if result["status"] == "refused":
            reason = f"{result['refusal']}: {reason}"
        robots = ", ".join(f"{r['name']} ({r['kind']}: {r['moved_m'] * 1000:.2f})"
                           for r in result.get("robots", []))
        lines.append(f"| {name} | {outcome(result)} | {reason.replace('|', '/')} | "
                     f"{result.get('load_s', '')} | {result.get('bodies', '')} | "
                     f"{result.get('diverged', '')} | {len(result.get('fell', []))} | "
                     f"{result.get('ground', '')} | {result.get('drop_m', '')} | {robots} | "
                     f"{_overlap_cell(result.get('overlaps', []))} |")
    return "\n".join(lines + _plan_table(run, results, c)) + "\n"


def _plan_table(run: dict, results: dict, c: dict) -> list:
    """report.md's planning section: a row per problem planned."""
    if not run.get("planned"):
        return ["", "Planning: not run."]
    lines = ["", "## Planning", "", plan_summary_line(c) + f" ({_how_planned(run)}).", "",
             "| file | Kautham's planner | OMPL's | time limit s | outcome | reason | search s "
             "| states | collision checks | path length |", "|---" * 10 + "|"]
    for name, r in sorted(results.items()):
        if r.get("plan") in (None, "skipped"):
            continue
        reason = r.get("plan_reason", "")
        if r["plan"] == "refused":
            reason = f"{r['refusal']}: {reason}"
        lines.append(f"| {name} | {r.get('planner', '')} | {r.get('ompl_planner', '')} | "
                     f"{r.get('time_limit', '')} | {r['plan']} | {reason.replace('|', '/')} | "
                     f"{r.get('plan_s', '')} | {r.get('states', '')} | {r.get('checks', '')} | "
                     f"{r.get('length', '')} |")
    return lines


def _overlapping(results: dict) -> int:
    return sum(bool(r.get("overlaps")) for r in results.values())


def _overlap_cell(overlaps: list) -> str:
    """"5 (TX90/Arm in columns#2, 47.3)" for a file's pairs built inside each other."""
    if not overlaps:
        return ""
    first, second, depth = overlaps[0]
    return f"{len(overlaps)} ({first} in {second}, {depth * 1000:.1f})"
