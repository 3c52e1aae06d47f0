"""Fixtures of the node tests (the root conftest.py gives each test its roscore)."""
import pytest

from world_client import running_world


@pytest.fixture
def world(ros_master):
    """A VirtualWorld node on this test's master, up to its servo service; the master is what
    the test gets. Checks at the end that the node lived. (A test file that needs the world
    otherwise defines a ``world`` fixture of its own.)"""
    yield from running_world(ros_master)

