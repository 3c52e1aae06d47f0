"""Every Odin executable ends quietly on a closed pipe and on Ctrl-C, with the usual codes:
``rosrun GUI problem_info FILE | head`` prints its lines and no BrokenPipeError traceback
(exit 141, as a C tool killed by SIGPIPE), and Ctrl-C ends a tool with 130 and no traceback."""
from __future__ import annotations

import os
import signal
import subprocess
import time

import pytest

PROBLEM = "current_2025/demos/OMPL_ode_demos/Sphere/Sphere.xml"


def test_problem_info_into_a_pipe_closed_early_ends_quietly(kautham_dir):
    tool = subprocess.Popen(["rosrun", "GUI", "problem_info", str(kautham_dir / PROBLEM),
                             "--indent", "4"], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    first = tool.stdout.readline()
    tool.stdout.close()                        # what `| head -1` does after its line
    err = tool.stderr.read().decode()
    assert tool.wait(timeout=120) == 128 + signal.SIGPIPE, err
    assert first.startswith(b"{")
    assert "Traceback" not in err and "BrokenPipe" not in err, err


@pytest.mark.parametrize("package, executable", [("VirtualWorld", "virtualWorld"),
                                                 ("Viewer", "viewer")])
def test_ctrl_c_ends_a_node_waiting_for_its_master_quietly(package, executable, tmp_path):
    """No master runs on the port: the node waits to register, and Ctrl-C ends that wait."""
    env = dict(os.environ, ROS_MASTER_URI="http://127.0.0.1:9", ROS_HOME=str(tmp_path))
    node = subprocess.Popen(["rosrun", package, executable], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, env=env, start_new_session=True)
    try:
        time.sleep(4.0)                         # imported and waiting for the master
        assert node.poll() is None, node.stderr.read().decode()
        os.killpg(node.pid, signal.SIGINT)      # a terminal's Ctrl-C reaches the whole group
        assert node.wait(timeout=30) == 128 + signal.SIGINT
        err = node.stderr.read().decode()
        assert "Traceback" not in err, err
    finally:
        if node.poll() is None:
            os.killpg(node.pid, signal.SIGKILL)
            node.wait()
