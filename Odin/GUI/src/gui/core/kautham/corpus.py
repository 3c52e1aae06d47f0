"""Where the Kautham corpus is: real Kautham problems, robots, geometry and controls that the
tests, the demo and the experiments use (tools/kautham/MANIFEST.md lists them). A clone of
Odin alone does not have it; tools/get_kautham.sh lays it out from the public Kautham
repository at the pinned commits. The whole corpus (every file of the repository at those
commits, ``tools/get_kautham.sh --all``) is for `make corpus` only."""
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


WHOLE_ENVIRONMENT = "ODIN_KAUTHAM_ALL_DIR"
"""The variable that names the whole corpus's folder (default: ../shared/kautham_all beside
the clone, where tools/get_kautham.sh --all puts it)."""
WHOLE_CORPUS_TESTS = "ODIN_WHOLE_CORPUS_TESTS"
"""Set to 1 (by `make corpus`) to run the tests over the whole corpus; `make test` does not."""
_CLONE = pathlib.Path(__file__).resolve().parents[6]


def whole_corpus_dir() -> Optional[pathlib.Path]:
    """The whole corpus's folder, or None when it is not there (no ALL.md in it)."""
    value = os.environ.get(WHOLE_ENVIRONMENT)
    path = pathlib.Path(value) if value else _CLONE.parent / "shared" / "kautham_all"
    return path if (path / "ALL.md").is_file() else None


def whole_missing_message() -> str:
    """One line saying that the whole corpus is missing and where it comes from."""
    where = os.environ.get(WHOLE_ENVIRONMENT) or str(_CLONE.parent / "shared" / "kautham_all")
    return (f"no whole Kautham corpus at {where}: tools/get_kautham.sh --all lays it out, or "
            f"set {WHOLE_ENVIRONMENT} to a copy")
