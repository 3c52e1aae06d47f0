"""A private ROS master, and the nodes started against it: what Odin's node tests, demo,
experiments and benchmarks run on (and what a user's own test suite may use).

Every test that needs ROS gets its own roscore on a free loopback port and its own ROS_HOME,
so tests never see each other's nodes, and every process started here is stopped (process
group and all) when the test ends, pass or fail. Needs the ROS command-line tools (roscore,
rosrun), not rospy: the master is asked over its XML-RPC API from this process (a test waits
for many services, and a ``rosservice`` process a poll cost 0.4 s of a core each).

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
import random
import signal
import socket
import subprocess
import tempfile
import time
import urllib.parse
import xmlrpc.client
from typing import Any, Sequence


# Masters listen below the kernel's ephemeral range (net.ipv4.ip_local_port_range starts at
# 32768 on Debian): a port handed out by bind(0) can be taken again by any node's XML-RPC
# server or outgoing connection before roscore binds it, and rosmaster then hangs for good
# with its server thread dead ("port ... is already in use").
_MASTER_PORTS = range(20000, 32768)


def free_port() -> int:
    """A TCP port on 127.0.0.1, outside the ephemeral range, that nobody is bound to now."""
    for _ in range(200):
        port = random.choice(_MASTER_PORTS)
        with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as sock:
            try:
                sock.bind(("127.0.0.1", port))
            except OSError:
                continue
            return port
    raise RuntimeError(f"no free port in {_MASTER_PORTS.start}-{_MASTER_PORTS.stop - 1}")


class RosMaster:
    """A roscore of our own; ``env`` is the environment that points at it."""

    def __init__(self, ros_home: str | os.PathLike | None = None, startup_timeout: float = 30.0):
        self._own_home = ros_home is None
        self.ros_home = pathlib.Path(ros_home or tempfile.mkdtemp(prefix="odin_ros_home_"))
        self.ros_home.mkdir(parents=True, exist_ok=True)
        self.env = dict(os.environ)
        self._use_port(free_port())
        self.env.update(ROS_HOME=str(self.ros_home),
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

    def start(self, attempts: int = 3) -> None:
        """Starts roscore; on a port taken meanwhile (or a roscore that died) tries a new port."""
        failures = []
        for _ in range(attempts):
            roscore = self.popen(["roscore", "-p", str(self.port)], log_name="roscore")
            try:
                failure = self._wait_for_master(roscore)
            except BaseException:
                self.stop()
                raise
            if failure is None:
                return
            failures.append(f"port {self.port}: {failure}")
            self.stop()
            self._use_port(free_port())
        raise RuntimeError("roscore did not come up: " + "; ".join(failures))

    def restart_master(self) -> None:
        """Kills roscore (SIGKILL, as a crash would) and starts a new one on the same port:
        the new master knows no node, no parameter (a fault drill, tests/nodes)."""
        old = next(p for p in self._processes if p.args[:1] == ["roscore"])
        _stop_group(old, signal_first=signal.SIGKILL)
        self._processes.remove(old)
        roscore = self.popen(["roscore", "-p", str(self.port)], log_name="roscore")
        failure = self._wait_for_master(roscore)
        if failure is not None:
            raise RuntimeError(f"roscore did not come back on port {self.port}: {failure}")

    def _wait_for_master(self, roscore: subprocess.Popen) -> str | None:
        """None once the master answers, else why it will not."""
        deadline = time.monotonic() + self._startup_timeout
        while time.monotonic() < deadline:
            # before asking: whatever squats a port may accept and never answer (each question
            # would then wait out its timeout), and roscore waits on it silently for minutes
            if _held_by_others(self.port, roscore.pid):
                return "port already in use by another process"
            if self._master_answers():
                return None
            log = self.log_text(roscore)
            if "already in use" in log:
                return "port already in use"
            if roscore.poll() is not None:
                return f"roscore exited with {roscore.returncode}: {log[-500:]}"
            time.sleep(0.2)
        return f"no answer after {self._startup_timeout} s"

    def _master_answers(self) -> bool:
        # roslaunch sets /rosdistro once the master is up: the same sign rosparam waited for
        return self.master_call("getParam", "/rosdistro") is not None

    def master_call(self, method: str, *args: Any, timeout: float = 5.0) -> Any:
        """The value of one ROS Master API call (``lookupService``, ``getParam``, ...) made as
        caller /odin_test, or None when the master does not answer in ``timeout`` s or answers
        with an error code (whatever holds a taken port may accept and never answer)."""
        proxy = xmlrpc.client.ServerProxy(self.uri, transport=_TimeoutTransport(timeout))
        try:
            code, _, value = getattr(proxy, method)("/odin_test", *args)
        except (OSError, xmlrpc.client.Error):
            return None
        return value if code == 1 else None

    def _use_port(self, port: int) -> None:
        self.port = port
        self.uri = f"http://127.0.0.1:{port}"
        self.env["ROS_MASTER_URI"] = self.uri

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
        """Until the service ``name`` is registered with the master and takes connections, as
        rospy.wait_for_service waits; raises when a node started here died meanwhile."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            self._raise_if_a_node_died()
            if self._service_answers(name):
                return
            time.sleep(0.1)
        raise TimeoutError(f"service {name} not up after {timeout} s; logs in {self.ros_home}")

    def subscribers(self, topic: str) -> list[str]:
        """The nodes that the master knows to subscribe to ``topic`` (none while it does not
        answer)."""
        state = self.master_call("getSystemState")
        subscriptions = state[1] if state is not None else []
        return next((nodes for name, nodes in subscriptions if name == topic), [])

    def _service_answers(self, name: str) -> bool:
        uri = self.master_call("lookupService", name)
        if uri is None:
            return False
        address = urllib.parse.urlsplit(uri)        # rosrpc://host:port
        try:
            with socket.create_connection((address.hostname, address.port), timeout=5):
                return True
        except OSError:
            return False

    def log_text(self, process: subprocess.Popen) -> str:
        return pathlib.Path(process.log_path).read_text(errors="replace")

    def _raise_if_a_node_died(self) -> None:
        for process in self._processes:
            if process.poll() is not None:
                raise RuntimeError(f"{process.args} exited with {process.returncode}:\n"
                                   + self.log_text(process)[-3000:])


class _TimeoutTransport(xmlrpc.client.Transport):
    """XML-RPC over HTTP that gives up after ``timeout`` s (the standard one waits forever)."""

    def __init__(self, timeout: float):
        super().__init__()
        self._timeout = timeout

    def make_connection(self, host):
        connection = super().make_connection(host)
        connection.timeout = self._timeout
        return connection


def _stop_group(process: subprocess.Popen, signal_first: int = signal.SIGINT) -> None:
    """``signal_first`` to the process's group, then SIGKILL to the group and to every
    descendant: roslaunch starts its nodes (rosmaster, rosout, rostest's nodes) in sessions of
    their own, and a hung rosmaster outlives a killed roscore."""
    tree = _descendants(process.pid)
    if process.poll() is None:
        try:
            os.killpg(process.pid, signal_first)
            process.wait(timeout=8)
        except (ProcessLookupError, subprocess.TimeoutExpired):
            pass
    tree |= _descendants(process.pid)
    for kill, target in [(os.killpg, process.pid), *((os.kill, pid) for pid in tree)]:
        try:
            kill(target, signal.SIGKILL)
        except ProcessLookupError:
            pass
    process.wait()


def _descendants(pid: int) -> set[int]:
    """Process ids of pid's children, their children, and so on (from /proc)."""
    children: dict[int, list[int]] = {}
    for stat in pathlib.Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue  # exited meanwhile
        children.setdefault(int(fields[1]), []).append(int(stat.parent.name))
    found, frontier = set(), [pid]
    while frontier:
        for child in children.get(frontier.pop(), []):
            if child not in found:
                found.add(child)
                frontier.append(child)
    return found


def _held_by_others(port: int, root_pid: int) -> bool:
    """Some process outside ``root_pid``'s tree listens on TCP ``port`` (any address; from
    /proc). The tree is read only when something listens: most polls find nobody yet."""
    listening = _listening_socket_inodes(port)
    if not listening:
        return False
    for pid in {root_pid} | _descendants(root_pid):
        try:
            links = {os.readlink(fd) for fd in pathlib.Path(f"/proc/{pid}/fd").iterdir()}
        except OSError:
            continue  # exited meanwhile
        if any(f"socket:[{inode}]" in links for inode in listening):
            return False
    return True


def _listening_socket_inodes(port: int) -> set[str]:
    """Inodes of the sockets in state LISTEN on TCP ``port`` (IPv4 and IPv6)."""
    inodes = set()
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        try:
            rows = pathlib.Path(table).read_text().splitlines()[1:]
        except OSError:
            continue
        for row in rows:
            fields = row.split()   # sl local_address rem_address st ... uid timeout inode
            if fields[3] == "0A" and int(fields[1].rsplit(":", 1)[1], 16) == port:
                inodes.add(fields[9])
    return inodes


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
