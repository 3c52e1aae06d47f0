"""Where the Kautham corpus is: real Kautham problems, robots, geometry and controls that the
tests, the demo and the experiments use (tools/kautham/MANIFEST.md lists them). A clone of
Odin alone does not have it; tools/get_kautham.sh lays it out from the public Kautham
repository at the pinned commits."""
from __future__ import annotations

import os
import pathlib
from typing import Optional

ENVIRONMENT = "ODIN_KAUTHAM_DIR"
"""The variable that names the corpus's folder (setup.bash sets it: ../shared/kautham beside
the clone unless it is already set)."""


def corpus_dir() -> Optional[pathlib.Path]:
    """The corpus's folder, or None when it is not there (no MANIFEST.md in it)."""
    value = os.environ.get(ENVIRONMENT)
    if not value:
        return None
    path = pathlib.Path(value)
    return path if (path / "MANIFEST.md").is_file() else None


def missing_message() -> str:
    """One line saying that the corpus is missing and where it comes from."""
    where = os.environ.get(ENVIRONMENT) or f"${ENVIRONMENT} (unset)"
    return (f"no Kautham corpus at {where}: tools/get_kautham.sh lays it out from the public "
            "Kautham repository (iocroblab/kautham) at the commits tools/kautham/MANIFEST.md "
            f"pins, or set {ENVIRONMENT} to a copy")
