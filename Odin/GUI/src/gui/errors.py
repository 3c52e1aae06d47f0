"""The GUI's exceptions: one root (``GuiError``) under Odin's ``OdinError``.

Messages say what was wrong, with the offending value and where it came from: parsed files
are named with their line (``file:line: what``) so the command-line tools can print one line.
"""
from __future__ import annotations

import os
from typing import Optional

from odin_common import OdinError


class GuiError(OdinError):
    """Root of everything the GUI raises on purpose."""


MAX_REASON_CHARS = 1000
"""Characters of a ProblemError's reason (and of its path) kept: a message that quotes what a
file gave (a 10 MB attribute, a file name of a megabyte) keeps its head and its tail, which
say what and why, and a note of how long it was, so that a hostile file never makes a huge
error line. Readers quote values through ``odin_common.limits.shown`` (80 characters); this
is the bound for whatever else a message holds."""


def bounded(text: str, limit: int = MAX_REASON_CHARS) -> str:
    """``text`` itself when at most ``limit`` characters, else its head and tail around a
    note of its length."""
    if len(text) <= limit:
        return text
    tail = limit // 4
    return f"{text[:limit - tail]} … ({len(text):,} characters) … {text[-tail:]}"


class ProblemError(GuiError):
    """A problem, robot, control or path file that cannot be read or does not make sense.

    ``path`` and ``line`` (1-based, ``None`` when unknown) say where; ``str(error)`` is
    ``"path:line: reason"``; reason and path are ``bounded``.
    """

    def __init__(self, reason: str, path: Optional[os.PathLike | str] = None,
                 line: Optional[int] = None):
        self.reason = bounded(str(reason))
        self.path = None if path is None else bounded(str(path))
        self.line = line
        where = ""
        if self.path is not None:
            where = f"{self.path}:{line}: " if line else f"{self.path}: "
        super().__init__(f"{where}{self.reason}")


class ShapeError(ProblemError):
    """A geometry file (VRML, Inventor, STL...) that does not parse or holds no geometry."""


class PathFileError(ProblemError):
    """A path or initial-position file that does not fit the robot it drives."""


class ServiceError(GuiError):
    """A node answered a service call ``success: false`` (its message is kept as ``reason``)
    or did not answer (the call broke: ``reason`` starts with "call failed"). ``service`` is the
    service's path (``/virtual_world/build_object``), or the node's namespace when no service
    of it was found; ``str(error)`` is ``"service: reason"``."""

    def __init__(self, service: str, reason: str):
        self.service = service
        self.reason = reason
        super().__init__(f"{service}: {reason}")


class WorldError(ServiceError):
    """The VirtualWorld answered ``success: false`` (its message is kept) or did not answer."""


class ViewerError(ServiceError):
    """The Viewer answered ``success: false`` (its message is kept) or did not answer."""


class PlanningError(GuiError):
    """A problem the planner cannot take (its robot's kind, a missing goal, a bad setting),
    or a back end that failed while planning."""
