"""Python mutants of the Core with mutmut (pinned in tools/requirements.txt).

mutmut 3 mutates a copy: it rewrites every function of the files in scope into mutated
variants behind a trampoline (``mutants/``), records which tests call which function, and runs
each mutant with only those tests, fastest first, in a forked child (``--max-children``). The
repository is never touched: the runner lays a project of its own out in a scratch folder,

    <scratch>/src/virtual_world/   a copy of Odin/VirtualWorld/src/virtual_world
    <scratch>/tests/               a copy of the Core's tests (Odin/VirtualWorld/test/test_*.py)
    <scratch>/tests/conftest.py    the repository's ``forked`` hook, and a check that the
                                   package the tests import is the mutated copy
    <scratch>/setup.cfg            mutmut's configuration (the scope) and pytest's markers

and reads the verdicts back from mutmut's ``*.meta`` files, and each mutant's change from the
mutated source (the ``__mutmut_orig`` function against the ``__mutmut_<n>`` one).

What mutmut 3 does not mutate: decorated functions (here the Core's ``@locked`` methods in
world.py, which forward to the topic modules) and module-level code (tables, constants).
"""
from __future__ import annotations

import ast
import difflib
import hashlib
import io
import json
import os
import pathlib
import shutil
import subprocess
import sys
import time
import tokenize
from typing import Dict, Iterable, List, Optional

ROOT = pathlib.Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "Odin" / "VirtualWorld" / "src" / "virtual_world"
TESTS = ROOT / "Odin" / "VirtualWorld" / "test"
COMMON = ROOT / "Odin" / "Messages" / "src" / "odin_common"

SCOPE = ("core/*.py", "ode/*.py")
"""Files mutated, relative to the virtual_world package."""
SKIP = ("ode/build_ode.py", "ode/bindings.py", "ode/__init__.py", "core/__init__.py",
        "core/loop.py", "core/step_values.py")
"""Not mutated: the extension's build script, the re-export modules, and the node's running
loop and step values (no physics; their tests wait on the wall clock, which makes every
surviving mutant cost seconds)."""

MESSAGE_LINES = (r"^\s*raise\s", r"\blog\.(debug|info|warning|error|exception)\(",
                 r"^\s*f?[\"'].*[\"']\)*( from None)?\s*$")
"""Lines whose expressions are not mutated (mutmut's do_not_mutate_patterns): error and log
messages (a raise statement, a logging call, a line that only continues a message). The tests
check an error's type and what it leaves unchanged; a message's wording is read, not tested."""

# mutmut's exit codes -> the report's statuses (mutmut.stats.status_by_exit_code)
KILLED, SURVIVED, TIMEOUT, CRASHED, NOT_COVERED, NOT_CHECKED = (
    "killed", "survived", "timeout", "crashed", "not covered", "not checked")
DETECTED = (KILLED, TIMEOUT, CRASHED)


def status_of(exit_code: Optional[int]) -> str:
    """A mutant's status from the exit code mutmut stored for it. A crash (a signal: ODE's
    abort, a segfault) or a timeout fails the suite as surely as a failed assertion does."""
    if exit_code is None:
        return NOT_CHECKED
    if exit_code in (1, 3):
        return KILLED
    if exit_code == 0:
        return SURVIVED
    if exit_code in (5, 33):
        return NOT_COVERED
    if exit_code in (36, 24, -24, 152, 255):
        return TIMEOUT
    if exit_code == 2:
        return NOT_CHECKED   # interrupted
    return CRASHED


def mutmut_version() -> str:
    from importlib.metadata import version
    return version("mutmut")


def source_files(only: Optional[List[str]] = None) -> List[pathlib.Path]:
    """The files mutated, relative to the package (e.g. core/forces.py): the scope, or those
    of it named in ``only``."""
    files = sorted({p.relative_to(PACKAGE) for pattern in SCOPE for p in PACKAGE.glob(pattern)})
    files = [p for p in files if str(p) not in SKIP]
    if only:
        unknown = set(only) - {str(p) for p in files}
        if unknown:
            raise SystemExit(f"not in the Python scope: {', '.join(sorted(unknown))}")
        files = [p for p in files if str(p) in only]
    return files


def test_files() -> List[pathlib.Path]:
    return sorted(TESTS.glob("test_*.py"))


def fingerprint(max_children: int, files: List[pathlib.Path]) -> str:
    """What the verdicts depend on: the package, odin_common, the tests, the compiled
    extension's sources, the runner and mutmut's version."""
    digest = hashlib.sha256()
    inputs = sorted(PACKAGE.rglob("*.py")) + sorted(PACKAGE.rglob("*.[ch]")) \
        + sorted(COMMON.rglob("*.py")) + test_files() \
        + [ROOT / "conftest.py", pathlib.Path(__file__)]
    for path in inputs:
        if "__pycache__" in path.parts:
            continue
        digest.update(str(path.relative_to(ROOT)).encode())
        digest.update(path.read_bytes())
    digest.update(f"mutmut {mutmut_version()} children {max_children} {files}".encode())
    return digest.hexdigest()


SETUP_CFG = """\
# written by tools/mutants/python_part.py
[mutmut]
source_paths = src/virtual_world
only_mutate =
{only}
pytest_add_cli_args_test_selection = tests/
# no collection at the session's end either (see conftest.py)
pytest_add_cli_args = -p no:unraisableexception
do_not_mutate_patterns =
{patterns}
# the Core's tests take ~10 s in all; a mutant that loops (a step count, a probe) is cut off
timeout_multiplier = 10.0
timeout_constant = 5.0

[tool:pytest]
markers =
    forked: run the test in a forked child process (the repository's conftest.py)
    slow: takes more than ~20 s
"""

CONFTEST = '''\
"""Written by tools/mutants/python_part.py: the repository's ``forked`` hook, a check that the
package under test is the mutated copy, not the repository's, and caches emptied before every
test (mutmut forks each mutant's run from a process that ran the clean tests: a module-level
cache would hand the mutant the unmutated results)."""
import gc
import importlib.util
import pathlib

import pytest

# No cyclic garbage collection in the mutants' processes: the collector finalizes a dropped
# Core's handles in no set order, and a mutant of handles.py that breaks their records would
# then crash whichever later test the collection happened in (docs/MUTANTS.md); without the
# collector it fails in the test that closes the Core.
gc.disable()

_spec = importlib.util.spec_from_file_location("_odin_root_conftest", {root_conftest!r})
_root = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(_root)
pytest_runtest_protocol = _root.pytest_runtest_protocol

import virtual_world.core  # noqa: E402

_HERE = pathlib.Path(virtual_world.core.__file__).resolve()
if not str(_HERE).startswith({mutants!r}):
    raise RuntimeError(f"the tests import virtual_world from {{_HERE}}, not the mutated copy")


@pytest.fixture(autouse=True)
def _empty_caches():
    from virtual_world.core import mass
    mass._MESH_MASS_CACHE.clear()
'''


def prepare(scratch: pathlib.Path, files: List[pathlib.Path]) -> None:
    """A fresh scratch project: the package, the tests, the configuration."""
    if scratch.exists():
        shutil.rmtree(scratch)
    (scratch / "src").mkdir(parents=True)
    shutil.copytree(PACKAGE, scratch / "src" / "virtual_world",
                    ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
    (scratch / "tests").mkdir()
    for path in test_files():
        shutil.copy2(path, scratch / "tests" / path.name)
    only = "\n".join(f"    src/virtual_world/{p}" for p in files)
    patterns = "\n".join(f"    {p}" for p in MESSAGE_LINES)
    (scratch / "setup.cfg").write_text(SETUP_CFG.format(only=only, patterns=patterns))
    (scratch / "tests" / "conftest.py").write_text(CONFTEST.format(
        root_conftest=str(ROOT / "conftest.py"),
        mutants=str((scratch / "mutants").resolve()) + os.sep))


def run_mutmut(scratch: pathlib.Path, max_children: int, log: pathlib.Path) -> float:
    """Runs ``mutmut run`` in the scratch project; returns the seconds it took."""
    start = time.monotonic()
    env = dict(os.environ, PYTHONDONTWRITEBYTECODE="1", OMP_NUM_THREADS="1",
               OPENBLAS_NUM_THREADS="1")
    with open(log, "w") as out:
        code = subprocess.call([sys.executable, "-m", "mutmut", "run", "--max-children",
                                str(max_children)], cwd=scratch, env=env, stdout=out,
                               stderr=subprocess.STDOUT)
    if code != 0:
        tail = log.read_text(errors="replace")[-3000:]
        raise RuntimeError(f"mutmut run failed (exit {code}); the end of {log}:\n{tail}")
    return time.monotonic() - start


# ---------------------------------------------------------------------------------- results

def _functions(tree: ast.AST) -> Dict[str, ast.FunctionDef]:
    return {node.name: node for node in ast.walk(tree)
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef))}


def _original_def(tree: ast.AST, function: str, cls: Optional[str]):
    """The function (or the method of ``cls``) of the original source."""
    scopes = [tree] if cls is None else [n for n in ast.walk(tree)
                                        if isinstance(n, ast.ClassDef) and n.name == cls]
    for scope in scopes:
        for node in scope.body:
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and node.name == function:
                return node
    return None


def _split_key(mangled: str):
    """'x_name' -> ('name', None); 'xǁClsǁname' -> ('name', 'Cls')."""
    if mangled.startswith("xǁ"):
        _, cls, function = mangled.split("ǁ", 2)
        return function, cls
    return mangled[2:], None


def describe(scratch: pathlib.Path, keys: Iterable[str]) -> Dict[str, dict]:
    """For each mutant key (module.x_function__mutmut_n): the file, the line of the original
    source it changes, the function, and the change (removed and added lines)."""
    by_file: Dict[str, List[str]] = {}
    for key in keys:
        module, _, rest = key.rpartition(".x")
        by_file.setdefault(module, []).append(key)
    out = {}
    for module, file_keys in by_file.items():
        relative = pathlib.Path(*module.split(".")).with_suffix(".py")
        original = (scratch / "src" / relative).read_text()
        mutated = (scratch / "mutants" / "src" / relative).read_text()
        original_tree, mutated_tree = ast.parse(original), ast.parse(mutated)
        mutated_defs = _functions(mutated_tree)
        mutated_lines = mutated.splitlines()
        for key in file_keys:
            mangled_n = "x" + key.rpartition(".x")[2]
            mangled, _, number = mangled_n.partition("__mutmut_")
            function, cls = _split_key(mangled)
            entry = {"file": str(relative), "function": f"{cls}.{function}" if cls else function,
                     "line": None, "change": ""}
            orig_node = mutated_defs.get(f"{mangled}__mutmut_orig")
            mutant_node = mutated_defs.get(mangled_n)
            source_node = _original_def(original_tree, function, cls)
            if orig_node is not None and mutant_node is not None:
                a = mutated_lines[orig_node.lineno - 1:orig_node.end_lineno]
                b = mutated_lines[mutant_node.lineno - 1:mutant_node.end_lineno]
                a[0], b[0] = a[0].replace(f"{mangled}__mutmut_orig", function), \
                    b[0].replace(mangled_n, function)
                removed, added, first = [], [], None
                for tag, i1, i2, j1, j2 in difflib.SequenceMatcher(a=a, b=b).get_opcodes():
                    if tag == "equal":
                        continue
                    first = i1 if first is None else first
                    removed += [line.strip() for line in a[i1:i2]]
                    added += [line.strip() for line in b[j1:j2]]
                if source_node is not None and first is not None:
                    entry["line"] = source_node.lineno + first
                entry["change"] = " / ".join(removed) + "  ->  " + " / ".join(added)
                entry["removed"], entry["added"] = removed, added
            out[key] = entry
    return out


def _code_tokens(lines: List[str]) -> Optional[List[str]]:
    """The tokens of ``lines`` with every string literal (and None) as one placeholder."""
    text = "\n".join(lines) + "\n"
    out = []
    try:
        for token in tokenize.generate_tokens(io.StringIO(text).readline):
            if token.type == tokenize.STRING or (token.type == tokenize.NAME
                                                 and token.string == "None"):
                out.append("<text>")
            elif token.type not in (tokenize.NL, tokenize.NEWLINE, tokenize.COMMENT,
                                    tokenize.INDENT, tokenize.DEDENT, tokenize.ENDMARKER):
                out.append(token.string)
    except (tokenize.TokenError, IndentationError, SyntaxError):
        return None
    return out


def text_only(mutant: dict) -> bool:
    """True when the mutant only changes the text of a string literal (a message, a label in
    a message) or puts None for one: the code around it is the same."""
    removed, added = mutant.get("removed"), mutant.get("added")
    if not removed:
        return False
    a, b = _code_tokens(removed), _code_tokens(added)
    return a is not None and a == b


def collect(scratch: pathlib.Path) -> List[dict]:
    """Every mutant of the last mutmut run: key, status, file, line, function, change."""
    mutants = []
    for meta in sorted((scratch / "mutants" / "src").rglob("*.py.meta")):
        data = json.loads(meta.read_text())
        codes = data["exit_code_by_key"]
        durations = data.get("durations_by_key", {})
        details = describe(scratch, codes)
        for key, code in codes.items():
            mutant = dict(key=key, status=status_of(code), exit_code=code,
                          seconds=round(durations.get(key, 0.0), 3), **details[key])
            mutant["text_only"] = text_only(mutant)
            mutants.append(mutant)
    return mutants


def run(scratch: pathlib.Path, max_children: int, fresh: bool, say,
        only: Optional[List[str]] = None) -> dict:
    """The Python part: mutmut over the Core, or over the files of it named in ``only`` (or
    the cached result of an identical run)."""
    files = source_files(only)
    key = fingerprint(max_children, files)
    cache = scratch.parent / "python-result.json"
    if not fresh and cache.exists():
        cached = json.loads(cache.read_text())
        if cached.get("fingerprint") == key:
            say(f"python: nothing changed since the run of {cached['finished']}: its results")
            cached["cached"] = True
            return cached
    say(f"python: mutmut {mutmut_version()} over {len(files)} files of virtual_world "
        f"({', '.join(SCOPE)}), {len(test_files())} test files, {max_children} children; "
        f"log: {scratch / 'mutmut.log'}")
    prepare(scratch, files)
    seconds = run_mutmut(scratch, max_children, scratch / "mutmut.log")
    mutants = collect(scratch)
    result = dict(fingerprint=key, finished=time.strftime("%Y-%m-%d %H:%M:%S"),
                  seconds=round(seconds, 1), tool=f"mutmut {mutmut_version()}",
                  files=[f"virtual_world/{p}" for p in files], mutants=mutants, cached=False)
    cache.write_text(json.dumps(result, indent=1))
    return result
