"""`catkin_make install` gives a working install space: every Python sub-package, the compiled
cffi module, the nodes and scripts, the .msg/.srv files. Installed into an emptied folder
(tools/install_space.sh), then used with nothing of the source tree or the devel space in
sight."""
import fcntl
import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
VENV_BIN = ROOT / ".venv" / "bin"


def _environment_of(setup: pathlib.Path) -> dict:
    """The environment a shell has after sourcing ``setup`` from a bare one (venv first on
    PATH, as setup.bash would give; no PYTHONPATH, no ROS_PACKAGE_PATH of the source tree)."""
    bare = {"HOME": os.environ.get("HOME", "/root"), "PATH": f"{VENV_BIN}:/usr/bin:/bin"}
    dump = subprocess.run(["bash", "-c", f"source {setup} && env -0"], env=bare, check=True,
                          capture_output=True).stdout.decode()
    return dict(item.split("=", 1) for item in dump.split("\0") if "=" in item)


@pytest.fixture(scope="session")
def install_env(tmp_path_factory, worker_id) -> dict:
    """The install space (tools/install_space.sh: build/install_ws, its install folder
    emptied and installed again), once per run: under pytest-xdist the first worker to need
    it installs it while the others wait on the lock, then all use it. make setup built it
    once (tools/build.sh), so a run recompiles only what changed since: a build from nothing
    took 50-90 s of the suite's first minute."""
    base = tmp_path_factory.getbasetemp()
    shared = base if worker_id == "master" else base.parent
    prefix = ROOT / "build" / "install_ws" / "install"
    (ROOT / "build").mkdir(exist_ok=True)
    with open(ROOT / "build" / "install_ws.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not (shared / "install_space.done").exists():
            result = subprocess.run([str(ROOT / "tools" / "install_space.sh")],
                                    capture_output=True, text=True, timeout=900)
            assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
            (shared / "install_space.done").touch()
    return _environment_of(prefix / "setup.bash")


def _python(env: dict, code: str) -> str:
    result = subprocess.run([str(VENV_BIN / "python"), "-c", code], env=env,
                            capture_output=True, text=True, timeout=120, cwd="/")
    assert result.returncode == 0, result.stderr[-3000:]
    return result.stdout


@pytest.mark.slow
def test_every_package_imports_from_the_install_space_and_steps(install_env):
    out = _python(install_env, """
import importlib, pkgutil
for top in ("odin_common", "virtual_world", "viewer", "gui"):
    package = importlib.import_module(top)
    print(package.__file__)
    for module in pkgutil.walk_packages(package.__path__, top + "."):
        if module.name.startswith(("gui.window", "viewer.core.renderer")):
            continue      # Qt and OpenGL: imported below only as far as they need no screen
        importlib.import_module(module.name)
import _odin_ode
print(_odin_ode.__file__)
from Messages.msg import Object
from Services.srv import BuildObject
from virtual_world.core import Core, ObjectSpec
core = Core()
core.build_object(ObjectSpec("ball", [0.1], position=(0, 0, 1)))
core.step(0.001, 100)
print("z", core.body_state("ball")[0][2])
""")
    install = install_env["CMAKE_PREFIX_PATH"].split(":")[0]
    files = [line for line in out.splitlines() if line.startswith("/")]
    assert files and all(f.startswith(install) for f in files), (install, files)
    z = float(out.split("z ")[1])
    assert z == pytest.approx(1.0 - 0.5 * 9.81 * 0.1 ** 2, abs=0.01)


# not marked slow, unlike the test above: it runs after it (slow tests go first), on the
# install space that test's worker built, instead of waiting beside it for the build
def test_a_node_started_from_the_install_space_serves(install_env, ros_master):
    env = dict(install_env)
    env.update({key: ros_master.env[key] for key in ("ROS_MASTER_URI", "ROS_HOME", "ROS_IP",
                                                      "ROS_LOG_DIR")})
    node = ros_master.popen(["rosrun", "VirtualWorld", "virtualWorld"], log_name="world",
                            env=env)
    ros_master.wait_for_service("/virtual_world/build_object")
    call = subprocess.run(
        ["rosservice", "call", "/virtual_world/build_object",
         "{object: {name: ball, parameters: [0.1], mass: 1.0, orientation: [1, 0, 0, 0]}}"],
        env=env, capture_output=True, text=True, timeout=60)
    assert "success: True" in call.stdout, call.stdout + call.stderr
    assert node.poll() is None
    install = pathlib.Path(install_env["CMAKE_PREFIX_PATH"].split(":")[0])
    for package, tool in (("GUI", "problem_info"), ("GUI", "load_problem"),
                          ("GUI", "run_path"), ("GUI", "gui"), ("Viewer", "viewer")):
        assert os.access(install / "lib" / package / tool, os.X_OK), (package, tool)
    interface = subprocess.run(["rossrv", "show", "Services/SetWorld"], env=env,
                               capture_output=True, text=True)
    assert "collision_mesh_tolerance" in interface.stdout
