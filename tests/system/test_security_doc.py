"""docs/SECURITY.md names, for each promise, the test that keeps it: every file and test it
names exists, so that the page cannot keep a promise whose test was renamed or removed."""
from __future__ import annotations

import pathlib
import re

ROOT = pathlib.Path(__file__).resolve().parents[2]
# `path.py`, `path.py::test_name` or `...::test_name` (the same file as the reference before)
REFERENCE = re.compile(r"`((?:[\w/]+\.py)|\.\.\.)(?:::(test_\w+))?`")


def _references(text: str):
    last = None
    for match in REFERENCE.finditer(text):
        path, test = match.groups()
        if path == "...":
            assert last is not None, f"{match.group(0)} follows no file"
            path = last
        last = path
        yield path, test


def test_every_test_security_md_names_exists():
    text = (ROOT / "docs" / "SECURITY.md").read_text()
    references = list(_references(text))
    assert len(references) >= 30, references
    where = {}
    for path, test in references:
        if test is None and not path.startswith(("tests/", "Odin/")):
            continue                # a module named in prose, not a test
        assert path.startswith(("tests/", "Odin/")), f"{path}::{test}: name the whole path"
        file = ROOT / path
        assert file.is_file(), f"docs/SECURITY.md names {path}, which does not exist"
        if test is not None:
            source = where.setdefault(path, file.read_text())
            assert re.search(rf"^def {test}\(", source, re.M), \
                f"docs/SECURITY.md names {path}::{test}, which is not defined there"
