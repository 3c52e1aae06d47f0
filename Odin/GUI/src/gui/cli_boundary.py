"""Where the GUI's tools (``problem_info``, ``load_problem``, ``run_path``, ``plan``,
``benchmark``) meet their input: whatever it holds, a tool that fails prints ONE line on
stderr, "<tool>: error: ...", and exits with status 2; never a traceback.

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
"""
from __future__ import annotations

import argparse
import contextlib
import functools
import math
import re
import sys
from typing import Callable, Iterator, Optional, Sequence

from gui.errors import GuiError
from odin_common.errors import OdinError
from odin_common.limits import shown
from odin_common.step_values import MAX_RATE

DATA_ERRORS = (OSError, UnicodeError, OverflowError, MemoryError, RecursionError)
"""What Python raises about the data a tool was given (a file's bytes, a number's size), as
opposed to a mistake in the code."""

MAX_SECONDS = 1e6
"""s: the longest time an option may give (a timeout, a search's time limit): 11.6 days. A
socket's timer overflows near 9e9 s."""

MAX_MESSAGE_CHARS = 300
"""Characters of an unexpected exception's message that a tool's error line quotes."""

Main = Callable[[Optional[Sequence[str]]], Optional[int]]


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


__all__ = ["DATA_ERRORS", "MAX_SECONDS", "ToolParser", "count", "described", "fail", "hertz",
           "one_line_errors", "reading", "seconds"]
