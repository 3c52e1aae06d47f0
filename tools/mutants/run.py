"""``make mutants``: mutation testing of the VirtualWorld Core, one change at a time.

    python tools/mutants/run.py                 # both parts
    python tools/mutants/run.py --part c        # the C step code only (or --part python)
    python tools/mutants/run.py --part c --only force_sign hinge_torque_sign
    python tools/mutants/run.py --part python --files core/forces.py ode/world.py
    python tools/mutants/run.py --fresh         # ignore the cached verdicts

Two parts, each breaking the Core and running the Core's tests against every break:
  * C: the hand-written source mutations of odin_step.c in c_mutations.py, each built with
    build_ode.py in a scratch folder and tested with that module first on PYTHONPATH
    (c_part.py);
  * Python: mutmut over virtual_world/core and virtual_world/ode (python_part.py).

Writes out/mutants/report.json (counts and score per part, every survivor with its file, line
and change) and out/mutants/report.md, and prints the survivors. Exits 0 whatever survives
(it is a report); non-zero only when no report could be made (the unmutated tests fail, a tool
is missing). Survivors accepted as equivalent (no observable change) are listed with the reason
in accepted.py and do not count against the score. Scratch work goes to build/mutants/ (the
cache included: an unchanged part is not run again). Everything runs at nice 10.
"""
from __future__ import annotations

import argparse
import json
import os
import pathlib
import subprocess
import sys
import time

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import accepted  # noqa: E402
import c_part  # noqa: E402
import python_part  # noqa: E402
from c_mutations import GOAL_PATHS, PATHS  # noqa: E402

ROOT = HERE.parents[1]
SCRATCH = ROOT / "build" / "mutants"
OUT = ROOT / "out" / "mutants"


def say(text: str) -> None:
    print(f"[mutants {time.strftime('%H:%M:%S')}] {text}", flush=True)


def _score(detected: int, survived: int) -> float | None:
    judged = detected + survived
    return round(detected / judged, 4) if judged else None


def _counts(mutants, detected_statuses, survived_statuses=("survived",)) -> dict:
    counts = {}
    for m in mutants:
        counts[m["status"]] = counts.get(m["status"], 0) + 1
    detected = sum(counts.get(s, 0) for s in detected_statuses)
    survived = sum(1 for m in mutants if m["status"] in survived_statuses
                   and not m.get("accepted"))
    n_accepted = sum(1 for m in mutants if m.get("accepted"))
    return dict(total=len(mutants), detected=detected, survived=survived, accepted=n_accepted,
                by_status=dict(sorted(counts.items())), score=_score(detected, survived))


def summarise_c(result: dict) -> dict:
    for m in result["mutants"]:
        reason = accepted.C.get(m["name"])
        if reason and m["status"] == c_part.SURVIVED:
            m["accepted"] = reason
    parts = {}
    for path in PATHS:
        of_path = [m for m in result["mutants"] if m["path"] == path]
        if of_path:
            parts[path] = _counts(of_path, c_part.DETECTED)
    goal = [m for m in result["mutants"] if m["path"] in GOAL_PATHS]
    other = [m for m in result["mutants"] if m["path"] not in GOAL_PATHS]
    survivors = [m for m in result["mutants"] if m["status"] == c_part.SURVIVED
                 and not m.get("accepted")]
    return dict(tool=result["tool"], seconds=result["seconds"], baseline=result["baseline"],
                parts=parts, goal_paths=list(GOAL_PATHS), goal=_counts(goal, c_part.DETECTED),
                other=_counts(other, c_part.DETECTED),
                total=_counts(result["mutants"], c_part.DETECTED),
                survivors=[dict(file=m["file"], line=m["line"], path=m["path"],
                                name=m["name"], bug=m["bug"],
                                change=f"{m['find']!r} -> {m['replace']!r}") for m in survivors],
                stale=[m["name"] for m in result["mutants"] if m["status"] == c_part.STALE],
                errors=[dict(name=m["name"], detail=m["detail"]) for m in result["mutants"]
                        if m["status"] == c_part.ERROR],
                accepted=[dict(name=m["name"], path=m["path"], line=m["line"],
                               reason=m["accepted"]) for m in result["mutants"]
                          if m.get("accepted")],
                mutants=result["mutants"])


def summarise_python(result: dict) -> dict:
    undetected = (python_part.SURVIVED, python_part.NOT_COVERED)
    for m in result["mutants"]:
        reason = accepted.python_reason(m)
        if reason and m["status"] in undetected:
            m["accepted"] = reason
    modules = {}
    for file in result["files"]:
        of_file = [m for m in result["mutants"] if m["file"] == file]
        modules[file] = _counts(of_file, python_part.DETECTED, undetected)
    survivors = [m for m in result["mutants"] if m["status"] in undetected
                 and not m.get("accepted")]
    survivors.sort(key=lambda m: (m["file"], m["line"] or 0))
    return dict(tool=result["tool"], seconds=result["seconds"], finished=result["finished"],
                cached=result.get("cached", False), modules=modules,
                total=_counts(result["mutants"], python_part.DETECTED, undetected),
                survivors=[dict(file=m["file"], line=m["line"], function=m["function"],
                                status=m["status"], change=m["change"], key=m["key"],
                                text_only=m.get("text_only", False)) for m in survivors],
                accepted=[dict(file=m["file"], line=m["line"], function=m["function"],
                               change=m["change"], reason=m["accepted"])
                          for m in result["mutants"] if m.get("accepted")],
                not_checked=sum(1 for m in result["mutants"]
                                if m["status"] == python_part.NOT_CHECKED))


def _pct(score) -> str:
    return "n/a" if score is None else f"{100 * score:.1f} %"


def markdown(report: dict) -> str:
    lines = ["# Mutation testing of the VirtualWorld Core", "",
             f"Run {report['finished']} on commit `{report['commit']}`"
             f"{' (with uncommitted changes)' if report['dirty'] else ''}; "
             f"{report['seconds']:.0f} s in all. `make mutants` writes this file; the figures "
             "are in report.json. Score = detected / (detected + surviving), equivalent "
             "survivors (tools/mutants/accepted.py) left out.", ""]
    c = report.get("c")
    if c:
        lines += ["## C step code (odin_step.c)", "",
                  f"{c['tool']}; each built with build_ode.py and tested against the Core's "
                  f"tests ({c['seconds']:.0f} s; baseline build {c['baseline']['build_s']} s, "
                  f"tests {c['baseline']['test_s']} s).", "",
                  "| path | mutants | detected | survived | accepted | other | score |",
                  "|---|---:|---:|---:|---:|---:|---:|"]
        for path, k in c["parts"].items():
            other = k["total"] - k["detected"] - k["survived"] - k["accepted"]
            goal = " (goal: none survive)" if path in c["goal_paths"] else ""
            lines.append(f"| {path}{goal} | {k['total']} | {k['detected']} | {k['survived']} |"
                         f" {k['accepted']} | {other} | {_pct(k['score'])} |")
        t = c["total"]
        lines += [f"| **all** | {t['total']} | {t['detected']} | {t['survived']} | "
                  f"{t['accepted']} | {t['total'] - t['detected'] - t['survived'] - t['accepted']}"
                  f" | {_pct(t['score'])} |", "",
                  "Detected: killed (a test failed), crashed (ODE aborted, a segfault) or timed "
                  f"out; statuses: {t['by_status']}.", ""]
        lines += ["### Surviving C mutants", ""]
        lines += [f"- `{s['name']}` ({s['path']}, odin_step.c:{s['line']}): {s['bug']}; "
                  f"`{s['change']}`" for s in c["survivors"]] or ["None."]
        if c["stale"] or c["errors"]:
            lines += ["", f"Stale mutations (update c_mutations.py): {c['stale']}; errors: "
                          f"{c['errors']}"]
        lines += ["", "### Accepted C survivors (equivalent)", ""]
        lines += [f"- `{a['name']}` ({a['path']}, odin_step.c:{a['line']}): {a['reason']}"
                  for a in c["accepted"]] or ["None."]
        lines.append("")
    p = report.get("python")
    if p:
        lines += ["## Python (virtual_world.core, virtual_world.ode)", "",
                  f"{p['tool']}, {p['seconds']:.0f} s (run {p['finished']}"
                  f"{', cached' if p['cached'] else ''}).", "",
                  "| module | mutants | detected | surviving (not covered) | accepted | score |",
                  "|---|---:|---:|---:|---:|---:|"]
        for file, k in p["modules"].items():
            nc = k["by_status"].get(python_part.NOT_COVERED, 0)
            lines.append(f"| {file} | {k['total']} | {k['detected']} | {k['survived']} ({nc}) |"
                         f" {k['accepted']} | {_pct(k['score'])} |")
        t = p["total"]
        lines += [f"| **all** | {t['total']} | {t['detected']} | {t['survived']} "
                  f"({t['by_status'].get(python_part.NOT_COVERED, 0)}) | {t['accepted']} | "
                  f"{_pct(t['score'])} |", "",
                  f"Statuses: {t['by_status']}.", "", "### Surviving Python mutants", "",
                  "Each changes what the code does; none has a test that notices.", ""]
        code = [s for s in p["survivors"] if not s["text_only"]]
        text = [s for s in p["survivors"] if s["text_only"]]
        lines += [f"- {s['file']}:{s['line']} `{s['function']}`"
                  f"{' (not covered)' if s['status'] != 'survived' else ''}: `{s['change']}`"
                  for s in code] or ["None."]
        lines += ["", "### Surviving Python mutants in message text only", "",
                  "They change the wording of an error or the label a check puts in its "
                  "message (or put None for it); the tests check errors' types, not wording. "
                  "Counted in the score all the same.", ""]
        lines += [f"- {s['file']}:{s['line']} `{s['function']}`: `{s['change']}`"
                  for s in text] or ["None."]
        lines += ["", "### Accepted Python survivors (equivalent)", ""]
        lines += [f"- {a['file']}:{a['line']} `{a['function']}`: `{a['change']}`: {a['reason']}"
                  for a in p["accepted"]] or ["None."]
        lines.append("")
    return "\n".join(lines)


def _git(*args: str) -> str:
    return subprocess.run(["git", *args], cwd=ROOT, capture_output=True, text=True).stdout.strip()


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--part", choices=("c", "python", "both"), default="both")
    parser.add_argument("--jobs", type=int, default=2,
                        help="C mutants built and tested at once; mutmut's children (default 2)")
    parser.add_argument("--only", nargs="*", help="C mutations to run, by name")
    parser.add_argument("--files", nargs="*",
                        help="Python files to mutate (relative to virtual_world/)")
    parser.add_argument("--fresh", action="store_true", help="ignore cached verdicts")
    args = parser.parse_args()
    if os.nice(0) < 10:
        os.nice(10 - os.nice(0))
    start = time.monotonic()
    report = dict(commit=_git("rev-parse", "--short", "HEAD"),
                  dirty=bool(_git("status", "--porcelain", "--untracked-files=no", "--",
                                  "Odin/VirtualWorld", "Odin/Messages")))
    previous = OUT / "report.json"
    old = json.loads(previous.read_text()) if previous.exists() else {}
    try:
        if args.part in ("c", "both"):
            report["c"] = summarise_c(c_part.run(SCRATCH / "c", args.jobs, args.fresh, say,
                                                 args.only))
        elif "c" in old:
            report["c"] = old["c"]
        if args.part in ("python", "both"):
            report["python"] = summarise_python(python_part.run(
                SCRATCH / "python" / "project", args.jobs, args.fresh, say, args.files))
        elif "python" in old:
            report["python"] = old["python"]
    except RuntimeError as error:
        say(f"no report: {error}")
        return 1
    report["seconds"] = round(time.monotonic() - start, 1)
    report["finished"] = time.strftime("%Y-%m-%d %H:%M:%S")
    OUT.mkdir(parents=True, exist_ok=True)
    (OUT / "report.json").write_text(json.dumps(report, indent=1))
    (OUT / "report.md").write_text(markdown(report))

    say(f"report: {OUT / 'report.md'} and report.json ({report['seconds']:.0f} s)")
    if "c" in report:
        c = report["c"]
        for path, k in c["parts"].items():
            say(f"c {path:9s} {k['detected']:3d}/{k['total'] - k['accepted']:3d} detected, "
                f"{k['survived']} survived, score {_pct(k['score'])}")
        for s in c["survivors"]:
            print(f"  SURVIVED c {s['path']}/{s['name']} odin_step.c:{s['line']}: {s['bug']}")
    if "python" in report:
        p = report["python"]
        for file, k in p["modules"].items():
            say(f"python {file:34s} {k['detected']:4d}/{k['total'] - k['accepted']:4d} "
                f"detected, {k['survived']} survived, score {_pct(k['score'])}")
        for s in p["survivors"]:
            if not s["text_only"]:
                print(f"  SURVIVED py {s['file']}:{s['line']} {s['function']}: {s['change']}")
        text = sum(1 for s in p["survivors"] if s["text_only"])
        if text:
            print(f"  ... and {text} Python survivors that change message text only "
                  f"(listed in {OUT / 'report.md'})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
