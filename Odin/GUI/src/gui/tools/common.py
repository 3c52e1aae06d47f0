"""What every GUI tool (``problem_info``, ``load_problem``, ``run_path``, ``plan``,
``benchmark``) shares: its command line, its one-line failure, the checks it makes before any
work, and the problem file it reads.

Whatever its input holds, a tool that fails prints ONE line on stderr, "<tool>: error: ...",
and exits with status 2; never a traceback.

- ``one_line_errors(tool)`` wraps a tool's ``main(argv)``: an ``OdinError`` (a refusal the
  code names: a file and line, a world's message) is printed as it is; an exception the
  system raises about data (``DATA_ERRORS``: a file that cannot be read or decoded, a number
  too large, memory exhausted, nesting too deep) with its class; any other exception is a
  bug, said as one: "internal error: <class>: <message> (please report)". Ctrl-C and a closed
  stdout are left to ``odin_common.tool.run`` (exit 130 and 141, quietly).
- ``reading(what, path)``: around a reader's call, a DATA_ERRORS exception names the file.
- ``ToolParser``: argparse with one line for a bad command line; ``seconds``, ``count`` and
  ``hertz`` are the option types whose values are checked where they are parsed (a timeout of
  1e300 s would overflow the socket's timer, a negative one would wait for nothing).
- ``ProblemFile``: the problem a tool is given and how to build it (``add_build_options``);
  ``ProblemFile.read()`` is its build plan (``gui.core.plan.BuildPlan``).
"""
from __future__ import annotations

import argparse
import atexit
import contextlib
import functools
import logging
import math
import os
import re
import sys
from dataclasses import dataclass
from typing import TYPE_CHECKING, Callable, Iterator, Optional, Sequence

from gui.errors import GuiError
from odin_common.errors import OdinError
from odin_common.limits import shown
from odin_common.step_values import MAX_RATE

if TYPE_CHECKING:
    from gui.core.plan import BuildPlan
    from gui.core.translate import BuildDefaults

DATA_ERRORS = (OSError, UnicodeError, OverflowError, MemoryError, RecursionError)
"""What Python raises about the data a tool was given (a file's bytes, a number's size), as
opposed to a mistake in the code."""

MAX_SECONDS = 1e6
"""s: the longest time an option may give (a timeout, a search's time limit): 11.6 days. A
socket's timer overflows near 9e9 s."""

MAX_MESSAGE_CHARS = 300
"""Characters of an unexpected exception's message that a tool's error line quotes."""

Main = Callable[[Optional[Sequence[str]]], Optional[int]]


# ------------------------------------------------------------------- the one-line failure

def fail(tool: str, error: object) -> int:
    """Prints "<tool>: error: <error>" on stderr, on one line; returns 2."""
    text = " ".join(str(error).split())
    print(f"{tool}: error: {text}", file=sys.stderr, flush=True)
    return 2


def described(error: BaseException) -> str:
    """"<class>: <message>", the message on one line and cut to MAX_MESSAGE_CHARS."""
    text = " ".join(str(error).split())
    if len(text) > MAX_MESSAGE_CHARS:
        text = f"{text[:MAX_MESSAGE_CHARS]}… ({len(text):,} characters)"
    return f"{type(error).__name__}: {text}" if text else type(error).__name__


def one_line_errors(tool: str) -> Callable[[Main], Main]:
    """Decorates a tool's ``main(argv)``: what escapes it becomes the tool's one error line and
    status 2 (module docstring)."""
    def decorate(main: Main) -> Main:
        @functools.wraps(main)
        def guarded(argv: Optional[Sequence[str]] = None) -> Optional[int]:
            try:
                return main(argv)
            except (KeyboardInterrupt, BrokenPipeError):
                raise                       # odin_common.tool.run: 130, 141, quietly
            except OdinError as error:
                return fail(tool, error)
            except DATA_ERRORS as error:
                return fail(tool, described(error))
            except Exception as error:      # a bug: said as one, in one line
                return fail(tool, f"internal error: {described(error)} (please report)")
        return guarded
    return decorate


@contextlib.contextmanager
def reading(what: str, path) -> Iterator[None]:
    """Within the block, a DATA_ERRORS exception (not the reader's own ProblemError) becomes a
    GuiError naming ``path`` as the ``what`` that could not be read."""
    try:
        yield
    except BrokenPipeError:
        raise
    except DATA_ERRORS as error:
        raise GuiError(f"{path}: cannot read this {what}: {described(error)}") from None


def without_teardown(main: Callable[[], Optional[int]]) -> Callable[[], int]:
    """``main`` for a tool's process that ends with it: once ``main`` has returned, stdout and
    stderr are flushed, the exit handlers run (rospy leaves the ROS graph, logging flushes
    its files) and the process ends with ``main``'s status, without the interpreter's
    teardown, which frees every object one at a time: 0.45 s after load_problem (a problem's
    meshes, rospy's and numpy's modules), where the system frees the memory at once. An
    exception (a closed pipe, Ctrl-C) leaves as usual, for odin_common.tool.run."""
    def ended() -> int:
        status = main() or 0
        sys.stdout.flush()
        sys.stderr.flush()
        atexit._run_exitfuncs()
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(status)
    return ended


# ----------------------------------------------------------------------- the command line

class ToolParser(argparse.ArgumentParser):
    """argparse whose refusal of a command line is one line ("<prog>: error: ..."), status 2,
    like every other refusal of the tools."""

    def error(self, message: str):
        # "argument --runs: 0: at least 1" -> "--runs 0: at least 1", the tools' own style
        text = re.sub(r"^argument ([^:]+): ", r"\1 ", " ".join(message.split()))
        self.exit(2, f"{self.prog}: error: {text} (--help: usage)\n")


def seconds(text: str) -> float:
    """An option's time, s: finite, positive, at most MAX_SECONDS."""
    value = _number(text)
    if not (math.isfinite(value) and 0 < value <= MAX_SECONDS):
        raise argparse.ArgumentTypeError(f"{shown(text)}: must be positive and at most "
                                         f"{MAX_SECONDS:g} s")
    return value


def hertz(text: str) -> float:
    """Rows per second, Hz: 0 (the world's rate) or in [1 / MAX_SECONDS, MAX_RATE]."""
    value = _number(text)
    if value != 0 and not (math.isfinite(value) and 1 / MAX_SECONDS <= value <= MAX_RATE):
        raise argparse.ArgumentTypeError(f"{shown(text)}: must be 0 (the world's) or in "
                                         f"[{1 / MAX_SECONDS:g}, {MAX_RATE:g}] Hz")
    return value


def count(low: int, high: int) -> Callable[[str], int]:
    """The type of an integer option in [low, high]."""
    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{shown(text)}: not an integer") from None
        if value < low:
            raise argparse.ArgumentTypeError(f"{value}: at least {low}")
        if value > high:
            raise argparse.ArgumentTypeError(f"{value}: at most {high:,}")
        return value
    parse.__name__ = "integer"
    return parse


def _number(text: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{shown(text)}: not a number") from None


def add_timeout_option(parser: argparse.ArgumentParser) -> None:
    """--timeout: the tools that reach a running world wait this long for each answer."""
    parser.add_argument("--timeout", type=seconds, default=10.0,
                        help="seconds to wait for the ROS master, then for the world's "
                        "services [10]")


def add_build_options(parser: argparse.ArgumentParser) -> None:
    """The problem file and the options that change how it is built (``BuildOptions``)."""
    ground = parser.add_mutually_exclusive_group()
    ground.add_argument("--physics", dest="ground", action="store_const", const=True,
                        help="Kautham's ODE physics (world settings, a ground plane) for any "
                        "problem [default: for problems with an ODE planner]")
    ground.add_argument("--no-physics", dest="ground", action="store_const", const=False,
                        help="no ground plane, Odin's default world settings")
    start = parser.add_mutually_exclusive_group()
    start.add_argument("--at-home", dest="start_at_query", action="store_const", const=False,
                       help="build robots at Home (as the thesis's tool built 2012 problems)")
    start.add_argument("--at-start", dest="start_at_query", action="store_const", const=True,
                       help="build robots at the query's start, where Kautham leaves a problem it "
                       "loads [default; Home when the problem has no query]")
    parser.add_argument("--inertia", choices=("auto", "file", "shape"), default="auto",
                        help="links' inertia: the file's where plausible (auto), always the "
                        "file's, or the shape's")
    parser.add_argument("--no-cache", action="store_true",
                        help="read every geometry file, bypassing the cache of shapes read "
                        "before (~/.cache/odin/shapes, gui.core.shape_cache)")


@dataclass(frozen=True)
class BuildOptions:
    """How a tool builds a problem: ``gui.core.translate.BuildDefaults``'s ``ground``,
    ``start_at_query`` and ``inertia`` (None: the problem decides), and whether shapes read
    before come from the cache (``gui.core.shape_cache``)."""
    ground: Optional[bool] = None
    start_at_query: Optional[bool] = None
    inertia: str = "auto"
    use_cache: bool = True

    def defaults(self) -> BuildDefaults:
        from gui.core.translate import BuildDefaults
        return BuildDefaults(ground=self.ground, start_at_query=self.start_at_query,
                             inertia=self.inertia)


@dataclass(frozen=True)
class ProblemFile:
    """A Kautham problem file (``path``) and how a tool builds it."""
    path: str
    build: BuildOptions = BuildOptions()

    @classmethod
    def of_args(cls, args: argparse.Namespace) -> ProblemFile:
        """From a command line parsed with ``add_build_options`` and a ``problem`` argument."""
        return cls(args.problem, BuildOptions(ground=args.ground,
                                              start_at_query=args.start_at_query,
                                              inertia=args.inertia,
                                              use_cache=not args.no_cache))

    def read(self) -> BuildPlan:
        """The build plan of the problem (``gui.core.translate.plan_problem``); the loader's
        refusal (ProblemError) as it is, a data error naming the file (``reading``)."""
        from gui.core import shape_cache
        from gui.core.kautham.problem import load_problem
        from gui.core.translate import plan_problem
        if not self.build.use_cache:
            shape_cache.set_enabled(False)
        defaults = self.build.defaults()
        with reading("problem", self.path):
            return plan_problem(load_problem(self.path), defaults)


# ---------------------------------------------------------------- checks before any work

def check_output(option: str, path: Optional[str]) -> None:
    """Before any work: the folder ``path`` is to be written in exists and is writable."""
    if path is None:
        return
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder):
        raise GuiError(f"{option} {path}: no folder {folder}")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise GuiError(f"{option} {path}: folder {folder} is not writable")
    if os.path.isdir(path):
        raise GuiError(f"{option} {path}: is a folder, not a file")


def check_master(tool: str, timeout: float) -> None:
    """Before any work: a ROS master answers at ROS_MASTER_URI within ``timeout`` s (rospy
    would wait for one for ever, saying "Will keep trying")."""
    from odin_common.node import wait_for_master
    wait_for_master(f"/{tool}", timeout=timeout, quiet=True)


def warnings_to_stderr(tool: str) -> None:
    """The loader's warnings (what Odin does not use) as "<tool>: warning: ..." lines."""
    logger = logging.getLogger("gui.core")
    if not any(getattr(h, "odin_tool", None) == tool for h in logger.handlers):
        handler = logging.StreamHandler(sys.stderr)
        handler.setFormatter(logging.Formatter(f"{tool}: warning: %(message)s"))
        handler.odin_tool = tool
        logger.addHandler(handler)
        logger.propagate = False


__all__ = ["DATA_ERRORS", "MAX_SECONDS", "BuildOptions", "ProblemFile", "ToolParser",
           "add_build_options", "add_timeout_option", "check_master", "check_output", "count",
           "described", "fail", "hertz", "one_line_errors", "reading", "seconds",
           "warnings_to_stderr", "without_teardown"]
