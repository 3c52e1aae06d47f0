"""The one size check every file the GUI reads goes through before it is read.

A problem names its robot, URDF, geometry, control and path files; any of them may come from
someone else. Reading one is bounded by ``odin_common.limits.MAX_INPUT_FILE_MB``, so a file of
absurd size is refused with its name before it is loaded, not after the host runs out of memory.
"""
from __future__ import annotations

import os
import pathlib
from typing import Type

from gui.errors import ProblemError
from odin_common.limits import MAX_INPUT_FILE_MB


def check_file_size(path: os.PathLike | str, what: str, error: Type[ProblemError]) -> None:
    """Raises ``error`` (a ProblemError class taking a message and the path) when ``path`` is
    larger than MAX_INPUT_FILE_MB; a file that cannot be stat'ed is left to the reader."""
    p = pathlib.Path(path)
    try:
        size = p.stat().st_size
    except OSError:
        return
    if size > MAX_INPUT_FILE_MB * 2 ** 20:
        raise error(f"{what} of {size / 2 ** 20:,.0f} MB is larger than the "
                    f"{MAX_INPUT_FILE_MB} MB the GUI reads", p)
