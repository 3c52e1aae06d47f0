"""A private ROS master per test, and the nodes started against it.

Every test that needs ROS gets its own roscore on a free loopback port and its own ROS_HOME,
so tests never see each other's nodes, and every process started here is stopped (process
group and all) when the test ends, pass or fail.

    with RosMaster() as master:
        master.rosrun("VirtualWorld", "virtualWorld")
        master.wait_for_service("/virtual_world/start")
        master.run(["rosservice", "call", "/virtual_world/start", "simulate: true"])

rospy's own ``init_node`` works once per process: a test that talks to nodes with rospy runs
in a forked process (``@pytest.mark.forked``, the ros_master fixture sets the environment
before rospy is used in that process).
"""
from __future__ import annotations

import os
import pathlib
import signal
import socket
import subprocess
import tempfile
import time
from typing import Sequence


def free_port() -> int:
    """A TCP port on 127.0.0.1 that nobody listens on right now."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


class RosMaster:
    """A roscore of our own; ``env`` is the environment that points at it."""

    def __init__(self, ros_home: str | os.PathLike | None = None, startup_timeout: float = 20.0):
        self._own_home = ros_home is None
        self.ros_home = pathlib.Path(ros_home or tempfile.mkdtemp(prefix="odin_ros_home_"))
        self.ros_home.mkdir(parents=True, exist_ok=True)
        self.port = free_port()
        self.uri = f"http://127.0.0.1:{self.port}"
        self.env = dict(os.environ)
        self.env.update(ROS_MASTER_URI=self.uri, ROS_HOME=str(self.ros_home),
                        ROS_IP="127.0.0.1", ROS_LOG_DIR=str(self.ros_home / "log"),
                        PYTHONUNBUFFERED="1")
        self.env.pop("ROS_HOSTNAME", None)
        self._startup_timeout = startup_timeout
        self._processes: list[subprocess.Popen] = []
        self._logs: list = []

    # -- lifecycle -------------------------------------------------------------------------
    def __enter__(self) -> "RosMaster":
        self.start()
        return self

    def __exit__(self, *exc_info) -> None:
        self.stop()

    def start(self) -> None:
        self.popen(["roscore", "-p", str(self.port)], log_name="roscore")
        deadline = time.monotonic() + self._startup_timeout
        while time.monotonic() < deadline:
            if self.run(["rosparam", "get", "/rosdistro"], check=False, timeout=10).returncode == 0:
                return
            time.sleep(0.2)
        self.stop()
        raise RuntimeError(f"roscore did not come up on port {self.port}")

    def stop(self) -> None:
        """Stops every process started here, newest first: SIGINT, then SIGKILL."""
        for process in reversed(self._processes):
            _stop_group(process)
        self._processes.clear()
        for log in self._logs:
            log.close()
        self._logs.clear()

    def apply_to_this_process(self) -> None:
        """Points this process's environment (and so rospy) at this master."""
        for key in ("ROS_MASTER_URI", "ROS_HOME", "ROS_IP", "ROS_LOG_DIR"):
            os.environ[key] = self.env[key]

    # -- processes -------------------------------------------------------------------------
    def popen(self, args: Sequence[str], log_name: str | None = None,
              env: dict | None = None) -> subprocess.Popen:
        """Starts a long-running process in its own process group, output to a log file."""
        name = log_name or pathlib.Path(args[0]).name
        log = open(self.ros_home / f"{name}.{len(self._logs)}.out", "wb")
        self._logs.append(log)
        process = subprocess.Popen(list(args), env=env or self.env, stdout=log,
                                   stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                                   start_new_session=True)
        process.log_path = log.name  # type: ignore[attr-defined]
        self._processes.append(process)
        return process

    def rosrun(self, package: str, executable: str, *args: str) -> subprocess.Popen:
        return self.popen(["rosrun", package, executable, *args], log_name=executable)

    def run(self, args: Sequence[str], check: bool = True, timeout: float = 60,
            input: str | None = None) -> subprocess.CompletedProcess:
        """Runs a short command against this master and returns its completed process."""
        return subprocess.run(list(args), env=self.env, capture_output=True, text=True,
                              check=check, timeout=timeout, input=input,
                              stdin=None if input is not None else subprocess.DEVNULL)

    def wait_for_service(self, name: str, timeout: float = 30.0) -> None:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            self._raise_if_a_node_died()
            if self.run(["rosservice", "type", name], check=False, timeout=10).returncode == 0:
                return
            time.sleep(0.2)
        raise TimeoutError(f"service {name} not up after {timeout} s; logs in {self.ros_home}")

    def log_text(self, process: subprocess.Popen) -> str:
        return pathlib.Path(process.log_path).read_text(errors="replace")

    def _raise_if_a_node_died(self) -> None:
        for process in self._processes:
            if process.poll() is not None:
                raise RuntimeError(f"{process.args} exited with {process.returncode}:\n"
                                   + self.log_text(process)[-3000:])


def _stop_group(process: subprocess.Popen) -> None:
    if process.poll() is None:
        try:
            os.killpg(process.pid, signal.SIGINT)
            process.wait(timeout=8)
        except (ProcessLookupError, subprocess.TimeoutExpired):
            pass
    try:
        os.killpg(process.pid, signal.SIGKILL)  # also whatever the process left behind
    except ProcessLookupError:
        pass
    process.wait()


def run_rostest(test_file: str, env: dict | None = None,
                timeout: float = 300) -> subprocess.CompletedProcess:
    """Runs ``rostest FILE`` (a fresh master of its own) with a private ROS_HOME and returns
    the completed process; ``returncode`` is non-zero when a test case failed."""
    home = tempfile.mkdtemp(prefix="odin_rostest_")
    run_env = dict(env or os.environ)
    run_env.update(ROS_HOME=home, ROS_LOG_DIR=str(pathlib.Path(home) / "log"),
                   ROS_IP="127.0.0.1", PYTHONUNBUFFERED="1")
    return subprocess.run(["rostest", "--text", test_file], env=run_env,
                          capture_output=True, text=True, timeout=timeout,
                          stdin=subprocess.DEVNULL, start_new_session=True)
