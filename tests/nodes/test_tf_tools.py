"""ROS's own tf tools against a running world (issue 28): ``rosrun tf tf_echo world ball``
(Debian's tf-tools and libtf-dev, tools/apt-packages.txt) reads the object's frame from the
world's /tf. Started after the world it runs on the world clock (docs/ROS.md, "ROS time"), so
it prints once the world runs; on the wall clock (/use_sim_time set false before the world
starts) it reads a paused world's latched frame at once."""
from __future__ import annotations

import os
import signal
import subprocess

BALL = ("{object: {name: ball, parameters: [0.1], mass: 1.0, position: [0.5, -0.25, 1], "
        "orientation: [1, 0, 0, 0]}}")


def test_tf_echo_reads_an_objects_frame_from_the_world(ros_master):
    # the world runs (its clock passes: tf_echo waits for its time to pass), without gravity
    ros_master.rosrun("VirtualWorld", "virtualWorld", "_simulate:=true", "_gravity:=[0,0,0]")
    ros_master.wait_for_service("/virtual_world/build_object")
    ros_master.run(["rosservice", "call", "/virtual_world/build_object", BALL])
    _echo_ball(ros_master)


def test_on_the_wall_clock_tf_echo_reads_a_paused_worlds_frame(ros_master):
    ros_master.run(["rosparam", "set", "/use_sim_time", "false"])
    ros_master.rosrun("VirtualWorld", "virtualWorld")
    ros_master.wait_for_service("/virtual_world/build_object")
    ros_master.run(["rosservice", "call", "/virtual_world/build_object", BALL])
    _echo_ball(ros_master)      # the world is paused: one frame, latched


def _echo_ball(ros_master) -> None:
    """``rosrun tf tf_echo world ball`` prints the ball where BALL put it."""
    echo = subprocess.Popen(["rosrun", "tf", "tf_echo", "world", "ball"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env=ros_master.env, start_new_session=True)
    try:
        said = ""
        while "Translation:" not in said:
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
