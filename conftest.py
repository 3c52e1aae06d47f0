"""pytest configuration for the whole repository: the ROS test harness lives in tests/, and
tests marked ``forked`` run in a child process of their own (rospy.init_node works once per
process). The child sends its reports back through pytest's own report serialisation."""
import json
import os
import pathlib
import sys
import tempfile

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


@pytest.hookimpl(tryfirst=True)
def pytest_runtest_protocol(item, nextitem):
    if item.get_closest_marker("forked") is None:
        return None
    hook = item.ihook
    hook.pytest_runtest_logstart(nodeid=item.nodeid, location=item.location)
    for report in _run_forked(item):
        hook.pytest_runtest_logreport(report=report)
    # the parent ran no fixtures of this item, but may still hold those of the item before it
    item.session._setupstate.teardown_exact(nextitem)
    hook.pytest_runtest_logfinish(nodeid=item.nodeid, location=item.location)
    return True


def _run_forked(item) -> list:
    from _pytest.reports import TestReport
    from _pytest.runner import runtestprotocol

    config = item.config
    with tempfile.NamedTemporaryFile(suffix=".json", delete=False) as handle:
        result_path = handle.name
    pid = os.fork()
    if pid == 0:  # the child: run setup, call and teardown, write the reports, leave at once
        code = 1
        try:
            reports = runtestprotocol(item, log=False, nextitem=None)
            data = [config.hook.pytest_report_to_serializable(config=config, report=r)
                    for r in reports]
            pathlib.Path(result_path).write_text(json.dumps(data))
            code = 0
        finally:
            os._exit(code)
    _, status = os.waitpid(pid, 0)
    try:
        data = json.loads(pathlib.Path(result_path).read_text() or "null")
    finally:
        os.unlink(result_path)
    if not data:
        return [TestReport(item.nodeid, item.location, {}, "failed",
                           f"the forked test process ended with status {status:#x} "
                           "before reporting", "call")]
    return [config.hook.pytest_report_from_serializable(config=config, data=d) for d in data]
