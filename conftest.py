"""pytest configuration for the whole repository: a private roscore per test that asks for one
(``ros_master``, odin_common.ros_master), the Kautham corpus (``kautham_dir``), and tests marked
``forked`` run in a child process of their own (rospy.init_node works once per process). The
child sends its reports back through pytest's own report serialisation."""
import json
import os
import pathlib
import signal
import subprocess
import sys
import tempfile

import pytest

from odin_common.blas import use_reference_blas

use_reference_blas()  # before world_client (rospy) or a test imports numpy (odin_common.blas)

ROOT = pathlib.Path(__file__).resolve().parent
# the raw test client of the world node (tests/nodes/world_client.py) serves the GUI's window
# tests too, whichever test file runs first or alone
sys.path.insert(0, str(ROOT / "tests" / "nodes"))

from odin_common.ros_master import RosMaster  # noqa: E402

# imported here, once per worker, so that every forked test inherits them: rospy, the
# messages and the services took a node test's child 1.3 s of CPU to import again
import world_client  # noqa: E402,F401


def pytest_configure(config):
    """A suite started in the background (a non-interactive shell's ``&``, nohup, some CI
    runners) inherits SIGINT ignored, and so would every node and tool it starts: the tests
    of Ctrl-C would fail and every node stopped with SIGINT would sit out its 8 s to SIGKILL.
    A Python handler here makes the processes started from now on begin with SIGINT's default
    (an ignored signal stays ignored across exec, a handled one does not)."""
    if signal.getsignal(signal.SIGINT) == signal.SIG_IGN:
        signal.signal(signal.SIGINT, signal.default_int_handler)
    # shapes read by the tests (hostile files among them) stay out of the user's cache; the
    # tools and nodes the tests start inherit the folder
    if "ODIN_CACHE_DIR" not in os.environ:
        os.environ["ODIN_CACHE_DIR"] = tempfile.mkdtemp(prefix="odin_test_cache_")
        config._odin_cache_dir = os.environ["ODIN_CACHE_DIR"]


def pytest_unconfigure(config):
    import shutil
    folder = getattr(config, "_odin_cache_dir", None)
    if folder is not None:
        shutil.rmtree(folder, ignore_errors=True)
        os.environ.pop("ODIN_CACHE_DIR", None)


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
    """The real Kautham corpus (read-only, $ODIN_KAUTHAM_DIR). A clone without it skips the
    tests that need it, each listed by name at the end with the line saying where the corpus
    comes from; with ODIN_REQUIRE_KAUTHAM=1 (CI) they fail instead."""
    from gui.core.kautham.corpus import corpus_dir, missing_message
    path = corpus_dir()
    if path is None:
        if os.environ.get("ODIN_REQUIRE_KAUTHAM") == "1":
            pytest.fail(missing_message())
        pytest.skip(_CORPUS_SKIP + missing_message())
    return path


_CORPUS_SKIP = "needs the Kautham corpus: "


@pytest.fixture(scope="session")
def ode_demos_dir() -> pathlib.Path:
    """Kautham's car and chain physics demos, vendored in the repository (read-only;
    tools/kautham/ode_demos/MANIFEST.md)."""
    return ROOT / "tools" / "kautham" / "ode_demos"


@pytest.fixture
def tro_singularity(kautham_dir, tmp_path) -> pathlib.Path:
    """The folder ``examples/TRO`` holding Kautham 2012's 2DRR_singularity problem and its
    solution (vendored: tools/kautham/tro_singularity/MANIFEST.md) beside the corpus's
    ``robots`` and ``scenes`` (linked), so that the problem's ``../`` references resolve."""
    examples = tmp_path / "tro_singularity" / "examples"
    (examples / "TRO").mkdir(parents=True)
    for folder in ("robots", "scenes"):
        (examples / folder).symlink_to(kautham_dir / "legacy_2012" / "examples" / folder)
    for vendored in (ROOT / "tools" / "kautham" / "tro_singularity" / "examples" /
                     "TRO").iterdir():
        (examples / "TRO" / vendored.name).write_bytes(vendored.read_bytes())
    return examples / "TRO"


@pytest.fixture
def arm_and_box(tmp_path):
    """``problem(name, box_x_mm) -> path``: a 2012 Kautham problem written from the format in
    tmp_path, an arm (a fixed Base, a movable link J1 300 mm up, 100 mm cubes) without <Home>,
    hence at the origin as Kautham places it, and a 100 mm box of its scene at x = box_x_mm,
    300 mm up: at 50 mm the link is 50 mm inside the box, at 500 mm clear of it."""
    cube = "#Inventor V2.1 ascii\n\nSeparator { Cube { width 100 height 100 depth 100 } }\n"
    (tmp_path / "cube.iv").write_text(cube)
    (tmp_path / "arm.rob").write_text(
        '<?xml version="1.0"?>\n<Robot name="arm" DHType="Modified" robType="Chain">\n'
        '<Joints size="2"><Joint name="Base" ivFile="cube.iv"><DHPars alpha="0" a="0" '
        'theta="0" d="0"/><Description rotational="true" movable="false"/><Limits Hi="0" '
        'Low="0"/><Parent name=""/></Joint><Joint name="J1" ivFile="cube.iv"><DHPars '
        'alpha="0" a="0" theta="0" d="300"/><Description rotational="true" movable="true"/>'
        '<Limits Hi="90" Low="-90"/><Parent name="Base"/></Joint></Joints>\n</Robot>\n')

    def problem(name: str, box_x_mm: float) -> pathlib.Path:
        path = tmp_path / name
        path.write_text(
            '<?xml version="1.0"?>\n<Problem>\n<Robot robot="arm.rob"/>\n'
            f'<Scene scene="cube.iv" scale="1.0"><Location X="{box_x_mm}" Y="0" Z="300" '
            'WX="0" WY="0" WZ="1" TH="0"/></Scene>\n</Problem>\n')
        return path
    return problem


@pytest.fixture(scope="session")
def plan_of():
    """``plan_of(problem_file)``: the build plan of a Kautham problem with gui.core.translate's
    defaults, the loader's warnings silenced."""
    import logging

    def plan(problem_file):
        from gui.core.kautham.problem import load_problem
        from gui.core.translate import plan_problem
        logging.disable(logging.WARNING)
        try:
            return plan_problem(load_problem(problem_file))
        finally:
            logging.disable(logging.NOTSET)
    return plan


@pytest.fixture
def tmpfs(tmp_path):
    """``mount(kib)``: a tmpfs of ``kib`` KiB at a new folder under tmp_path (a disk that fills
    up, for the tests of files written whole or not at all), unmounted at the end; the test is
    skipped where mounting is not allowed."""
    mounted = []

    def mount(kib: int) -> pathlib.Path:
        mount_point = tmp_path / f"tmpfs{len(mounted)}"
        mount_point.mkdir()
        done = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={kib}k", "tmpfs",
                               str(mount_point)], capture_output=True, text=True)
        if done.returncode != 0:
            pytest.skip(f"cannot mount a tmpfs here: {done.stderr.strip() or done.returncode}")
        mounted.append(mount_point)
        return mount_point
    yield mount
    for mount_point in mounted:
        subprocess.run(["umount", "-l", str(mount_point)], check=False)


def pytest_collection_modifyitems(items):
    """Tests marked ``slow`` run first: pytest-xdist hands them out while every worker is
    free, instead of one worker finishing a 40 s test while the others wait."""
    items.sort(key=lambda item: item.get_closest_marker("slow") is None)


def pytest_terminal_summary(terminalreporter):
    skipped = [report for report in terminalreporter.stats.get("skipped", [])
               if _CORPUS_SKIP in str(report.longrepr)]
    if not skipped:
        return
    terminalreporter.section("tests skipped without the Kautham corpus")
    for report in skipped:
        terminalreporter.write_line(report.nodeid)
    terminalreporter.write_line(str(skipped[0].longrepr[-1]).replace("Skipped: ", ""))


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
    reports = [config.hook.pytest_report_from_serializable(config=config, data=d) for d in data]
    for report in reports:
        # JSON made the (path, line, message) of a skip a list; pytest's summary wants a tuple
        if isinstance(report.longrepr, list):
            report.longrepr = tuple(report.longrepr)
    return reports
