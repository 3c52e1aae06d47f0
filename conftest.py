"""pytest configuration for the whole repository: the ROS test harness lives in tests/."""
import os
import pathlib
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(ROOT / "tests"))

from ros_harness import RosMaster  # noqa: E402


@pytest.fixture
def ros_master(tmp_path):
    """A roscore of this test's own (free port, ROS_HOME in tmp_path), stopped afterwards
    together with every node started through it; this process's environment points at it."""
    saved = {k: os.environ.get(k) for k in ("ROS_MASTER_URI", "ROS_HOME", "ROS_IP", "ROS_LOG_DIR")}
    with RosMaster(ros_home=tmp_path / "ros_home") as master:
        master.apply_to_this_process()
        yield master
    for key, value in saved.items():
        if value is None:
            os.environ.pop(key, None)
        else:
            os.environ[key] = value


@pytest.fixture(scope="session")
def kautham_dir() -> pathlib.Path:
    """The real Kautham corpus (read-only): $ODIN_KAUTHAM_DIR or ../shared/kautham."""
    path = pathlib.Path(os.environ.get("ODIN_KAUTHAM_DIR", ROOT.parent / "shared" / "kautham"))
    if not (path / "MANIFEST.md").exists():
        pytest.fail(f"Kautham corpus not found at {path} (set ODIN_KAUTHAM_DIR)")
    return path
