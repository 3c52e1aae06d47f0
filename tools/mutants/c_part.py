"""C mutants of the step code: each mutation of c_mutations.py built and tested on its own.

For one mutation: the ode/ folder is copied into a scratch folder, the one edit is applied to
the copy's odin_step.c, the copy's build_ode.py compiles the extension into the scratch folder,
and the Core's tests run from the repository with that folder first on PYTHONPATH. A pytest
plugin written next to the scratch module checks at the session's start that ``_odin_ode`` is
imported from there (else the mutant is an *error*, not a survivor). The repository's sources
are never modified.

Statuses: killed (a test failed), crashed (the test process died of a signal: ODE's abort, a
segfault), timeout (it ran past its limit: a loop that never ends), survived (every test
passed), compile-error (the mutant does not build: not counted in the score), stale (the
mutation's text is no longer in odin_step.c: update c_mutations.py), error (the run could not
judge the mutant).

Results are cached per mutation (build/mutants/c/cache.json), keyed by the mutation and
everything the verdict depends on (the ode/ folder, the Core's Python, odin_common, the tests).
"""
from __future__ import annotations

import concurrent.futures
import hashlib
import json
import os
import pathlib
import shutil
import signal
import subprocess
import sys
import threading
import time
from typing import Callable, Dict, List, Optional

from c_mutations import MUTATIONS, CMutation

ROOT = pathlib.Path(__file__).resolve().parents[2]
ODE = ROOT / "Odin" / "VirtualWorld" / "src" / "virtual_world" / "ode"
STEP_C = ODE / "odin_step.c"
TEST_DIRS = ("Odin/VirtualWorld/test", "Odin/Messages/test")
"""The Core's tests, run from the repository root (its pytest.ini and conftest.py)."""
DEPENDS = (ROOT / "Odin" / "VirtualWorld" / "src" / "virtual_world",
           ROOT / "Odin" / "Messages" / "src" / "odin_common",
           ROOT / "Odin" / "VirtualWorld" / "test", ROOT / "Odin" / "Messages" / "test")

KILLED, CRASHED, TIMEOUT, SURVIVED, COMPILE_ERROR, STALE, ERROR = (
    "killed", "crashed", "timeout", "survived", "compile-error", "stale", "error")
DETECTED = (KILLED, CRASHED, TIMEOUT)

PLUGIN = '''\
"""Written by tools/mutants/c_part.py: the mutant's _odin_ode must be the one imported."""
import os
import pathlib

import pytest


def pytest_sessionstart(session):
    import _odin_ode
    where = pathlib.Path(_odin_ode.__file__).resolve()
    pathlib.Path(os.environ["ODIN_MUTANT_IMPORTED"]).write_text(str(where))
    if where.parent != pathlib.Path(os.environ["ODIN_MUTANT_DIR"]).resolve():
        raise pytest.UsageError(f"_odin_ode imported from {where}, not the mutant's folder")
'''


def line_of(source: str, find: str) -> int:
    return source[:source.index(find)].count("\n") + 1 + len(find) - len(find.lstrip("\n"))


def depends_digest() -> str:
    digest = hashlib.sha256()
    for folder in DEPENDS:
        for path in sorted(folder.rglob("*")):
            if path.is_file() and "__pycache__" not in path.parts and path.suffix in (
                    ".py", ".c", ".h", ".test"):
                digest.update(str(path.relative_to(ROOT)).encode())
                digest.update(path.read_bytes())
    for path in (ROOT / "conftest.py", ROOT / "pytest.ini", pathlib.Path(__file__)):
        digest.update(path.read_bytes())
    return digest.hexdigest()


def cache_key(common: str, mutation: Optional[CMutation]) -> str:
    text = common if mutation is None else f"{common}\0{mutation.find}\0{mutation.replace}"
    return hashlib.sha256(text.encode()).hexdigest()


def _kill_group(process: subprocess.Popen) -> None:
    try:
        os.killpg(process.pid, signal.SIGKILL)
    except ProcessLookupError:
        pass


def _run(command: List[str], cwd: pathlib.Path, env: dict, timeout: float, log: pathlib.Path):
    """(exit code or None on timeout, seconds); output into ``log``. The command runs in a
    process group of its own, killed whole on timeout."""
    start = time.monotonic()
    with open(log, "w") as out:
        process = subprocess.Popen(command, cwd=cwd, env=env, stdout=out,
                                   stderr=subprocess.STDOUT, start_new_session=True)
        try:
            code = process.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            _kill_group(process)
            process.wait()
            code = None
    return code, time.monotonic() - start


class Workspace:
    """One scratch folder: ode/ (the copy built), out/ (the module), tmp/ (the build's)."""

    def __init__(self, folder: pathlib.Path):
        self.folder = folder
        self.ode = folder / "ode"
        self.out = folder / "out"
        self.tmp = folder / "tmp"

    def build(self, source: str) -> tuple:
        """Lays out the ode/ copy with ``source`` as odin_step.c and builds it into out/.
        Returns (ok, seconds)."""
        if self.ode.exists():
            shutil.rmtree(self.ode)
        shutil.copytree(ODE, self.ode, ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
        (self.ode / "odin_step.c").write_text(source)
        for stale in self.out.glob("_odin_ode*.so"):
            stale.unlink()
        self.out.mkdir(parents=True, exist_ok=True)
        self.tmp.mkdir(parents=True, exist_ok=True)
        (self.out / "odin_mutant_check.py").write_text(PLUGIN)
        code, seconds = _run([sys.executable, str(self.ode / "build_ode.py"), "--out",
                              str(self.out), "--tmp", str(self.tmp)], ROOT, dict(os.environ),
                             600, self.folder / "build.log")
        return code == 0 and any(self.out.glob("_odin_ode*.so")), seconds

    def test(self, timeout: float) -> tuple:
        """Runs the Core's tests against out/'s module. Returns (status, seconds, detail)."""
        imported = self.folder / "imported.txt"
        if imported.exists():
            imported.unlink()
        env = dict(os.environ, PYTHONPATH=f"{self.out}{os.pathsep}"
                   f"{os.environ.get('PYTHONPATH', '')}", ODIN_MUTANT_DIR=str(self.out),
                   ODIN_MUTANT_IMPORTED=str(imported), PYTHONDONTWRITEBYTECODE="1",
                   OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
        command = [sys.executable, "-m", "pytest", "-x", "-q", "-p", "no:cacheprovider",
                   "-p", "odin_mutant_check", "--timeout", str(int(timeout)), *TEST_DIRS]
        log = self.folder / "test.log"
        code, seconds = _run(command, ROOT, env, timeout + 30, log)
        where = imported.read_text() if imported.exists() else ""
        if code is not None and code >= 0 and pathlib.Path(where).parent != self.out.resolve():
            return ERROR, seconds, f"_odin_ode imported from {where or 'nowhere'}"
        if code is None:
            return TIMEOUT, seconds, f"no end after {timeout + 30:.0f} s"
        if code < 0:
            return CRASHED, seconds, f"signal {signal.Signals(-code).name}"
        text = log.read_text(errors="replace")
        if code == 0:
            return SURVIVED, seconds, ""
        if code == 1:
            failed = [line for line in text.splitlines() if line.startswith(("FAILED", "ERROR"))]
            if "Timeout" in text and not failed:
                return TIMEOUT, seconds, "pytest-timeout"
            return KILLED, seconds, failed[0][:200] if failed else "a test failed"
        return ERROR, seconds, f"pytest exit {code}: {text[-300:]}"


def run(scratch: pathlib.Path, jobs: int, fresh: bool, say: Callable[[str], None],
        only: Optional[List[str]] = None) -> dict:
    """The C part: every mutation of c_mutations.py (or those named in ``only``)."""
    source = STEP_C.read_text()
    scratch.mkdir(parents=True, exist_ok=True)
    cache_file = scratch / "cache.json"
    cache: Dict[str, dict] = {} if fresh or not cache_file.exists() \
        else json.loads(cache_file.read_text())
    common = depends_digest()
    mutations = [m for m in MUTATIONS if not only or m.name in only]
    unknown = set(only or ()) - {m.name for m in MUTATIONS}
    if unknown:
        raise SystemExit(f"no C mutation named {', '.join(sorted(unknown))}")

    # the unmutated build must pass, and gives the time limit
    base = Workspace(scratch / "baseline")
    baseline = cache.get(cache_key(common, None))
    if baseline is None:
        say("c: building and testing the unmutated step code (the baseline)")
        ok, build_s = base.build(source)
        if not ok:
            raise RuntimeError(f"the unmutated extension does not build: {base.folder}/build.log")
        status, test_s, detail = base.test(timeout=900)
        if status != SURVIVED:
            raise RuntimeError(f"the Core's tests do not pass on the unmutated build ({status}:"
                               f" {detail}); see {base.folder}/test.log")
        baseline = dict(build_s=round(build_s, 1), test_s=round(test_s, 1))
        cache[cache_key(common, None)] = baseline
        cache_file.write_text(json.dumps(cache, indent=1))
    limit = max(120.0, 6 * baseline["test_s"])

    results: Dict[str, dict] = {}
    todo = []
    for m in mutations:
        entry = dict(name=m.name, path=m.path, file="virtual_world/ode/odin_step.c",
                     bug=m.bug, find=m.find, replace=m.replace)
        if source.count(m.find) != 1:
            results[m.name] = dict(entry, line=None, status=STALE, seconds=0.0,
                                   detail=f"found {source.count(m.find)} times in odin_step.c")
            continue
        entry["line"] = line_of(source, m.find)
        cached = cache.get(cache_key(common, m))
        if cached is not None:
            results[m.name] = dict(entry, **cached, cached=True)
        else:
            todo.append((m, entry))
    say(f"c: {len(mutations)} mutations of odin_step.c, {len(todo)} to build and test "
        f"({len(mutations) - len(todo)} cached or stale), {jobs} at a time; baseline: build "
        f"{baseline['build_s']} s, tests {baseline['test_s']} s, limit {limit:.0f} s")

    free = [Workspace(scratch / f"work{j}") for j in range(jobs)]
    lock = threading.Lock()
    done = [0]
    start = time.monotonic()

    def one(item):
        m, entry = item
        with lock:
            space = free.pop()
        try:
            ok, build_s = space.build(source.replace(m.find, m.replace, 1))
            if not ok:
                log = (space.folder / "build.log").read_text(errors="replace")
                errors = [line for line in log.splitlines() if "error" in line]
                verdict = dict(status=COMPILE_ERROR, seconds=round(build_s, 1),
                               detail=(errors[0] if errors else log[-200:]).strip()[:200])
            else:
                status, test_s, detail = space.test(limit)
                verdict = dict(status=status, seconds=round(build_s + test_s, 1),
                               detail=detail)
        finally:
            with lock:
                free.append(space)
        with lock:
            done[0] += 1
            if verdict["status"] != ERROR:
                cache[cache_key(common, m)] = verdict
                cache_file.write_text(json.dumps(cache, indent=1))
            shown_detail = verdict["status"] in (SURVIVED, ERROR, COMPILE_ERROR)
            say(f"c: [{done[0]}/{len(todo)}] {m.path}/{m.name}: {verdict['status']} "
                f"({verdict['seconds']} s){' ' + verdict['detail'] if shown_detail else ''}")
        return m.name, dict(entry, **verdict, cached=False)

    with concurrent.futures.ThreadPoolExecutor(max_workers=jobs) as pool:
        for name, result in pool.map(one, todo):
            results[name] = result
    ordered = [results[m.name] for m in mutations]
    return dict(seconds=round(time.monotonic() - start, 1), baseline=baseline,
                mutants=ordered, tool=f"tools/mutants/c_mutations.py ({len(MUTATIONS)} "
                                      "mutations)")
