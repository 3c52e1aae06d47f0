"""Fixtures of the node tests (the root conftest.py gives each test its roscore)."""
import pytest


@pytest.fixture
def world(ros_master):
    """A VirtualWorld node on this test's master, up to its servo service; the master is what
    the test gets. Checks at the end that the node lived. (A test file that needs the world
    otherwise defines a ``world`` fixture of its own.)"""
    node = ros_master.rosrun("VirtualWorld", "virtualWorld")
    ros_master.wait_for_service("/virtual_world/set_servo")
    yield ros_master
    assert node.poll() is None, "virtualWorld died:\n" + ros_master.log_text(node)[-3000:]
