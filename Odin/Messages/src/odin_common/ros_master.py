"""A private ROS master, and the nodes started against it: what Odin's node tests, demo,
experiments and benchmarks run on (and what a user's own test suite may use).

Every test that needs ROS gets its own roscore on a free loopback port and its own ROS_HOME,
so tests never see each other's nodes, and every process started here is stopped (process
group and all) when the test ends, pass or fail. The core is what ``roscore`` starts
(rosmaster, roscore.xml's parameters, the rosout node), started directly rather than through
roslaunch. Needs the ROS command-line tools (rosmaster, rosrun), not rospy: the master is
asked over its XML-RPC API from this process (a test waits for many services, and a
``rosservice`` process a poll cost 0.4 s of a core each).

    with RosMaster() as master:
        master.rosrun("VirtualWorld", "virtualWorld")
        master.wait_for_service("/virtual_world/start")
        master.run(["rosservice", "call", "/virtual_world/start", "simulate: true"])

rospy's own ``init_node`` works once per process: a test that talks to nodes with rospy runs
in a forked process (``@pytest.mark.forked``, the ros_master fixture sets the environment
before rospy is used in that process).
"""
from __future__ import annotations

import contextlib
import functools
import io
import os
import pathlib
import random
import re
import signal
import socket
import struct
import subprocess
import sys
import tempfile
import time
import urllib.parse
import uuid
import xmlrpc.client
from typing import Any, Sequence

from odin_common.master_link import MasterRefusal, call_master

# Masters listen below the kernel's ephemeral range (net.ipv4.ip_local_port_range starts at
# 32768 on Debian): a port handed out by bind(0) can be taken again by any node's XML-RPC
# server or outgoing connection before roscore binds it, and rosmaster then hangs for good
# with its server thread dead ("port ... is already in use").
_MASTER_PORTS = range(20000, 32768)


_CORE_LOGS = ("rosmaster", "rosout")
"""The log names of the core's processes: what restart_master kills and starts again."""


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
        """Starts the core (see ``_start_core``); on a port taken meanwhile (or a master that
        died) tries a new port."""
        failures = []
        for _ in range(attempts):
            try:
                failure = self._start_core()
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
        """Kills the core (SIGKILL, as a crash would) and starts a new one on the same port:
        the new master knows no node, no parameter (a fault drill, tests/nodes)."""
        core = [p for p in self._processes if p.log_name in _CORE_LOGS]
        _stop_groups(core, signal_first=signal.SIGKILL)
        self._processes = [p for p in self._processes if p not in core]
        failure = self._start_core()
        if failure is not None:
            raise RuntimeError(f"roscore did not come back on port {self.port}: {failure}")

    def _start_core(self) -> str | None:
        """What ``roscore -p PORT`` starts, without roslaunch in between: rosmaster, the
        parameters roscore.xml sets (/run_id, /rosversion, /rosdistro) and the rosout node.
        roslaunch's own start and orderly stop took 2.6 s (1.8 s of CPU) of every node
        test. None once the master answers, else why it will not."""
        rosmaster = self.popen(["rosmaster", "--core", "-p", str(self.port), "-w", "3"],
                               log_name="rosmaster")
        failure = self._wait_for_master(rosmaster)
        if failure is not None:
            return failure
        version, distro = _ros_versions()
        for name, value in (("/run_id", str(uuid.uuid1())), ("/rosversion", version),
                            ("/rosdistro", distro)):
            if self.master_call("setParam", name, value) is None:
                return f"the master refused parameter {name}"
        self.rosrun("rosout", "rosout", "__name:=rosout")
        return None

    def _wait_for_master(self, rosmaster: subprocess.Popen) -> str | None:
        """None once the master answers, else why it will not."""
        deadline = time.monotonic() + self._startup_timeout
        while time.monotonic() < deadline:
            # before asking: whatever squats a port may accept and never answer (each question
            # would then wait out its timeout), and rosmaster waits on it silently for minutes
            if _held_by_others(self.port, rosmaster.pid):
                return "port already in use by another process"
            if self._master_answers():
                return None
            log = self.log_text(rosmaster)
            if "already in use" in log:
                return "port already in use"
            if rosmaster.poll() is not None:
                return f"rosmaster exited with {rosmaster.returncode}: {log[-500:]}"
            time.sleep(0.05)
        return f"no answer after {self._startup_timeout} s"

    def _master_answers(self) -> bool:
        return self.master_call("getPid") is not None

    def master_call(self, method: str, *args: Any, timeout: float = 5.0) -> Any:
        """The value of one ROS Master API call (``lookupService``, ``getParam``, ...) made as
        caller /odin_test, or None when the master does not answer in ``timeout`` s or answers
        with an error code (whatever holds a taken port may accept and never answer)."""
        try:
            return call_master(self.uri, "/odin_test", method, *args, timeout=timeout)
        except (OSError, xmlrpc.client.Error, MasterRefusal):
            return None

    def _use_port(self, port: int) -> None:
        self.port = port
        self.uri = f"http://127.0.0.1:{port}"
        self.env["ROS_MASTER_URI"] = self.uri

    def stop(self) -> None:
        """Stops every process started here, the nodes first (so they unregister from a
        master still there), then the core: SIGINT, then SIGKILL."""
        nodes = [p for p in self._processes if p.log_name not in _CORE_LOGS]
        _stop_groups(nodes)
        _stop_groups([p for p in self._processes if p not in nodes])
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
        """Starts a long-running process in its own process group, output to a log file (a
        ``rosrun`` command as ``rosrun_command`` says)."""
        args = self.rosrun_command(args, env)
        name = log_name or pathlib.Path(args[0]).name
        log = open(self.ros_home / f"{name}.{len(self._logs)}.out", "wb")
        self._logs.append(log)
        process = subprocess.Popen(args, env=env or self.env, stdout=log,
                                   stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                                   start_new_session=True)
        process.log_path = log.name  # type: ignore[attr-defined]
        process.log_name = name  # type: ignore[attr-defined]
        self._processes.append(process)
        return process

    def rosrun(self, package: str, executable: str, *args: str) -> subprocess.Popen:
        """Starts ``rosrun PACKAGE EXECUTABLE ARGS...`` (see ``rosrun_command``)."""
        return self.popen(["rosrun", package, executable, *args], log_name=executable)

    def rosrun_command(self, args: Sequence[str], env: dict | None = None) -> list:
        """``args``, where they are ``rosrun PACKAGE PROGRAM ...``, as the program rosrun
        would exec with the same arguments in ``env`` (this master's by default;
        ``find_executable``): the same process without the rosrun script's 0.8 s of CPU. As
        given where rosrun finds no single program (the error is then rosrun's) or has
        options of its own."""
        args = list(args)
        if len(args) >= 3 and args[0] == "rosrun" and not args[1].startswith("-"):
            program = find_executable(args[1], args[2], env or self.env)
            if program is not None:
                return [program, *args[3:]]
        return args

    def run(self, args: Sequence[str], check: bool = True, timeout: float = 60,
            input: str | None = None) -> subprocess.CompletedProcess:
        """Runs a short command against this master and returns its completed process (a
        ``rosrun`` command as ``rosrun_command`` says)."""
        return subprocess.run(self.rosrun_command(args), env=self.env, capture_output=True,
                              text=True, check=check, timeout=timeout, input=input,
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
            with socket.create_connection((address.hostname, address.port), timeout=5) as link:
                # rospy.wait_for_service's probe header: the server closes without a warning
                # (a bare connection logged "Inbound TCP/IP connection failed" in every node)
                link.sendall(_tcpros_header({"probe": "1", "md5sum": "*",
                                             "callerid": "/odin_ros_master", "service": name}))
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


@functools.lru_cache(maxsize=None)
def _ros_versions() -> tuple[str, str]:
    """(/rosversion, /rosdistro) as roscore.xml computes them (``rosversion roslaunch``,
    ``rosversion -d``), with rosversion's own functions in this process."""
    from rospkg.rosversion import get_distro_name_from_roscore, get_version_from_package_name
    distro = os.environ.get("ROS_DISTRO") or get_distro_name_from_roscore() or "Debian"
    return get_version_from_package_name("roslaunch") or "<unversioned>", distro


def find_executable(package: str, executable: str, env: dict) -> str | None:
    """The program ``rosrun PACKAGE EXECUTABLE`` runs in ``env`` (its ROS_PACKAGE_PATH and
    CMAKE_PREFIX_PATH), or None where rosrun would find none or ask which of several.

    rosrun's own search, done in this process: the package's catkin libexec and share
    folders (``catkin_find --without-underlays --libexec --share``) and its ``rospack find``
    folder, walked for an executable file of that name (not under the package's ``build/``);
    of two, the one outside the share folders (a devel space's relay script). Debian's rosrun
    runs catkin_find up to four times, 0.8 s of CPU for every node a test started.
    tests/nodes/test_ros_master.py checks the answers against ``rosrun --prefix echo``."""
    return _rosrun_choice(package, executable, env.get("ROS_PACKAGE_PATH", ""),
                          env.get("CMAKE_PREFIX_PATH", ""))


@functools.lru_cache(maxsize=None)
def _rosrun_choice(package: str, executable: str, package_path: str,
                   prefix_path: str) -> str | None:
    from catkin.find_in_workspaces import find_in_workspaces
    workspaces = _catkin_workspaces(prefix_path)
    with _without_naming_lint():
        folders = find_in_workspaces(["libexec", "share"], package, _workspaces=workspaces,
                                     first_matching_workspace_only=True)
    rospack = subprocess.run(["rospack", "find", package], capture_output=True, text=True,
                             env=dict(os.environ, ROS_PACKAGE_PATH=package_path,
                                      CMAKE_PREFIX_PATH=prefix_path))
    package_folder = rospack.stdout.strip() if rospack.returncode == 0 else ""
    found = _unique_in_order(_executables_named(
        executable, [*folders, *([package_folder] if package_folder else [])],
        package_folder))
    if len(found) == 2:
        with _without_naming_lint():
            shares = find_in_workspaces(["share"], package, _workspaces=workspaces,
                                        first_matching_workspace_only=True)
        outside = [f for f in found if not any(f.startswith(s) for s in shares)]
        found = outside if len(outside) == 1 else found
    return found[0] if len(found) == 1 else None


#: catkin_pkg's lint of a package name with capitals, printed on stderr each time it reads a
#: package.xml: Odin's packages keep the thesis's names (VirtualWorld, GUI, ...) on purpose
_NAMING_LINT = re.compile(r'^WARNING: Package name "[^"]+" does not follow the naming conventions')


@contextlib.contextmanager
def _without_naming_lint():
    """catkin_pkg's output on stderr, less its package-name lint (six lines per search)."""
    captured = io.StringIO()
    with contextlib.redirect_stderr(captured):
        yield
    for line in captured.getvalue().splitlines(keepends=True):
        if not _NAMING_LINT.match(line):
            sys.stderr.write(line)


def _catkin_workspaces(prefix_path: str) -> list:
    """catkin's workspaces for this CMAKE_PREFIX_PATH (catkin reads it from os.environ only;
    Debian's catkin adds /usr to them)."""
    from catkin.workspace import get_workspaces
    saved = os.environ.get("CMAKE_PREFIX_PATH")
    os.environ["CMAKE_PREFIX_PATH"] = prefix_path
    try:
        return get_workspaces()
    finally:
        if saved is None:
            os.environ.pop("CMAKE_PREFIX_PATH")
        else:
            os.environ["CMAKE_PREFIX_PATH"] = saved


def _executables_named(name: str, folders: list, package_folder: str) -> list:
    """``find -L FOLDERS -name NAME -type f -perm /111 ! -regex '.*PKG/build/.*'``."""
    skipped = os.path.join(package_folder, "build") + os.sep if package_folder else None
    found = []
    for folder in folders:
        for where, _, files in os.walk(folder, followlinks=True):
            path = os.path.join(where, name)
            if name in files and os.path.isfile(path) and os.stat(path).st_mode & 0o111 \
                    and not (skipped and path.startswith(skipped)):
                found.append(path)
    return found


def _unique_in_order(paths: list) -> list:
    """``uniq``: adjacent repeats once."""
    return [p for k, p in enumerate(paths) if k == 0 or paths[k - 1] != p]


def _stop_groups(processes: Sequence[subprocess.Popen],
                 signal_first: int = signal.SIGINT) -> None:
    """``signal_first`` to each process's group at once, up to 8 s for all of them to exit,
    then SIGKILL to the groups and to every descendant: roslaunch starts its nodes (rostest's
    nodes, a user's launch file) in sessions of their own, and a hung rosmaster outlives a
    killed parent. Stopped side by side: a test's nodes each take a second or two to shut
    down cleanly, and one after the other that was a tenth of the suite."""
    if not processes:
        return
    tree = _descendants({p.pid for p in processes})
    running = [p for p in processes if p.poll() is None]
    for process in running:
        try:
            os.killpg(process.pid, signal_first)
        except ProcessLookupError:
            pass
    deadline = time.monotonic() + 8
    for process in running:
        try:
            process.wait(timeout=max(0.0, deadline - time.monotonic()))
        except subprocess.TimeoutExpired:
            pass
    tree |= _descendants({p.pid for p in processes})
    targets = [(os.killpg, p.pid) for p in processes] + [(os.kill, pid) for pid in tree]
    for kill, target in targets:
        try:
            kill(target, signal.SIGKILL)
        except ProcessLookupError:
            pass
    for process in processes:
        process.wait()
    _wait_until_gone(tree)


def _wait_until_gone(pids: set[int], timeout: float = 5.0) -> None:
    """Until none of ``pids`` runs any more (exited, or a zombie: its sockets are closed).
    SIGKILL is delivered asynchronously: a master started on the port of a rosmaster killed a
    moment ago would otherwise find it still listening there."""
    deadline = time.monotonic() + timeout
    while pids and time.monotonic() < deadline:
        pids = {pid for pid in pids if _running(pid)}
        if pids:
            time.sleep(0.01)


def _running(pid: int) -> bool:
    fields = _stat_fields(pathlib.Path(f"/proc/{pid}/stat"))
    return fields is not None and fields[0] not in ("Z", "X")


def _stat_fields(stat: pathlib.Path) -> list | None:
    """The fields of a /proc/PID/stat after the command's name (state, parent, ...), or None
    when the process is gone."""
    try:
        return stat.read_text().rsplit(")", 1)[1].split()
    except (OSError, IndexError):
        return None


def _descendants(roots: set[int]) -> set[int]:
    """Process ids of the roots' children, their children, and so on (from /proc)."""
    children: dict[int, list[int]] = {}
    for stat in pathlib.Path("/proc").glob("[0-9]*/stat"):
        fields = _stat_fields(stat)
        if fields is None:
            continue  # exited meanwhile
        children.setdefault(int(fields[1]), []).append(int(stat.parent.name))
    found, frontier = set(), list(roots)
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
    for pid in {root_pid} | _descendants({root_pid}):
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


def _tcpros_header(fields: dict) -> bytes:
    """A TCPROS connection header (ROS's wiki, "ROS/Connection Header"): each field
    ``key=value`` after its length, all after their total length, lengths 4-byte little
    endian (rosgraph.network.encode_ros_handshake_header, which this layer may not import)."""
    entries = [f"{key}={value}".encode() for key, value in sorted(fields.items())]
    body = b"".join(struct.pack("<I", len(entry)) + entry for entry in entries)
    return struct.pack("<I", len(body)) + body
