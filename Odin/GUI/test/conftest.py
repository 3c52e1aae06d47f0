"""Fixtures of the GUI package's tests (beside the repository's own, in the root conftest.py)."""
from __future__ import annotations

import pytest


@pytest.fixture
def world():
    """An in-process world (the VirtualWorld's Core behind the world port), closed after."""
    # imported here: the many tests that need no world do not load the planning stack
    from gui_core_world import CoreWorld
    w = CoreWorld()
    yield w
    w.close()
