"""Fixtures of the Core's tests."""
import pytest

from virtual_world.core import Core, WorldParameters


@pytest.fixture
def core():
    """A Core without gravity, closed after the test. (A test file that needs another world
    defines a ``core`` fixture of its own.)"""
    c = Core(WorldParameters(gravity=(0.0, 0.0, 0.0)))
    yield c
    c.close()
