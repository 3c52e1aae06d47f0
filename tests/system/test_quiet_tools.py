"""Every Odin executable ends quietly on a closed pipe and on Ctrl-C, with the usual codes:
``rosrun GUI problem_info FILE | head`` prints its lines and no BrokenPipeError traceback
(exit 141, as a C tool killed by SIGPIPE), and Ctrl-C ends a tool with 130 and no traceback."""
from __future__ import annotations

import fcntl
import os
import signal
import subprocess

import pytest

PROBLEM = "current_2025/demos/OMPL_ode_demos/Sphere/Sphere.xml"
# the smallest pipe Linux makes (one page): problem_info's JSON for PROBLEM (about 12 kB) can
# never fit in it, so the tool is still writing when the reader closes, however fast it runs
SMALL_PIPE = 4096


def _small_pipe() -> tuple[int, int]:
    read, write = os.pipe()
    fcntl.fcntl(write, fcntl.F_SETPIPE_SZ, SMALL_PIPE)
    assert fcntl.fcntl(write, fcntl.F_GETPIPE_SZ) == SMALL_PIPE
    return read, write


def _problem_info(kautham_dir, stdout: int) -> subprocess.Popen:
    return subprocess.Popen(["rosrun", "GUI", "problem_info", str(kautham_dir / PROBLEM),
                             "--indent", "4"], stdout=stdout, stderr=subprocess.PIPE)


def _assert_ended_quietly(tool: subprocess.Popen) -> None:
    err = tool.stderr.read().decode()
    assert tool.wait(timeout=120) == 128 + signal.SIGPIPE, err
    assert "Traceback" not in err and "BrokenPipe" not in err, err


def test_problem_info_into_a_pipe_closed_after_one_line_ends_quietly(kautham_dir):
    """What ``| head -1`` does: read the first line, close the pipe."""
    read, write = _small_pipe()
    tool = _problem_info(kautham_dir, write)
    os.close(write)
    first = b""
    while not first.endswith(b"\n"):            # byte by byte: take nothing past the line
        byte = os.read(read, 1)
        assert byte, "problem_info ended before its first line"
        first += byte
    os.close(read)
    _assert_ended_quietly(tool)
    assert first.startswith(b"{")


def test_problem_info_into_a_pipe_closed_before_it_writes_ends_quietly(kautham_dir):
    """The reader is gone before the tool starts: its first write meets a closed pipe."""
    read, write = _small_pipe()
    os.close(read)
    tool = _problem_info(kautham_dir, write)
    os.close(write)
    _assert_ended_quietly(tool)


@pytest.mark.parametrize("package, executable", [("VirtualWorld", "virtualWorld"),
                                                 ("Viewer", "viewer")])
def test_ctrl_c_ends_a_node_waiting_for_its_master_quietly(package, executable, tmp_path):
    """No master runs on the port: the node waits to register, and Ctrl-C ends that wait."""
    env = dict(os.environ, ROS_MASTER_URI="http://127.0.0.1:9", ROS_HOME=str(tmp_path))
    node = subprocess.Popen(["rosrun", package, executable], stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, env=env, start_new_session=True)
    try:
        said = ""                               # until it is imported and waiting
        while "waiting for the ROS master" not in said:
            line = node.stderr.readline().decode()
            assert line, said
            said += line
        os.killpg(node.pid, signal.SIGINT)      # a terminal's Ctrl-C reaches the whole group
        assert node.wait(timeout=30) == 128 + signal.SIGINT
        err = node.stderr.read().decode()
        assert "Traceback" not in err, err
    finally:
        if node.poll() is None:
            os.killpg(node.pid, signal.SIGKILL)
            node.wait()
