"""ROS's own tf tools against a running world (issue 28): ``rosrun tf tf_echo world ball``
(Debian's tf-tools and libtf-dev, tools/apt-packages.txt) reads the object's frame from the
world's /tf."""
from __future__ import annotations

import os
import signal
import subprocess

BALL = ("{object: {name: ball, parameters: [0.1], mass: 1.0, position: [0.5, -0.25, 1], "
        "orientation: [1, 0, 0, 0]}}")


def test_tf_echo_reads_an_objects_frame_from_the_world(ros_master):
    ros_master.rosrun("VirtualWorld", "virtualWorld")
    ros_master.wait_for_service("/virtual_world/build_object")
    ros_master.run(["rosservice", "call", "/virtual_world/build_object", BALL])
    echo = subprocess.Popen(["rosrun", "tf", "tf_echo", "world", "ball"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env=ros_master.env, start_new_session=True)
    try:
        said = ""
        while "Translation:" not in said:          # the world is paused: one frame, latched
            line = echo.stdout.readline()
            assert line, said + echo.stderr.read()
            said += line
        assert "Translation: [0.500, -0.250, 1.000]" in said, said
    finally:
        os.killpg(echo.pid, signal.SIGINT)
        try:
            echo.wait(timeout=10)
        except subprocess.TimeoutExpired:
            os.killpg(echo.pid, signal.SIGKILL)
            echo.wait()
