"""The ROS harness itself: a private master comes up, answers, and leaves nothing behind."""
import subprocess

import pytest

from odin_common.ros_master import RosMaster


def test_private_master_starts_and_stops_cleanly():
    with RosMaster() as master:
        assert master.run(["rosparam", "get", "/rosdistro"]).returncode == 0
        roscore = master._processes[0]
        pid = roscore.pid
    assert roscore.poll() is not None
    alive = subprocess.run(["pgrep", "-g", str(pid)], capture_output=True)
    assert alive.returncode == 1, "processes of the master's group survived"


def test_two_masters_do_not_share_a_port():
    with RosMaster() as first, RosMaster() as second:
        assert first.port != second.port
        first.run(["rosparam", "set", "/odin_probe", "1"])
        assert second.run(["rosparam", "get", "/odin_probe"], check=False).returncode != 0


@pytest.mark.slow
def test_master_moves_to_another_port_when_its_port_is_taken():
    import socket
    master = RosMaster()
    taken = master.port
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as squatter:
        squatter.bind(("127.0.0.1", taken))
        squatter.listen()
        with master:
            assert master.port != taken
            assert master.env["ROS_MASTER_URI"].endswith(f":{master.port}")
            assert master.run(["rosparam", "get", "/rosdistro"]).returncode == 0


def test_nodes_are_started_as_rosrun_would_start_them():
    """RosMaster.rosrun runs the program rosrun itself picks (find_executable does rosrun's
    search in-process): the same path for Odin's nodes and a tool (a devel-space relay beside
    its source script), rosout and a ROS tool, and none where rosrun finds none. Each
    rosrun here costs 0.8 s of CPU: the programs are a sample of each kind."""
    import os
    from odin_common.ros_master import find_executable
    env = dict(os.environ)
    programs = [("VirtualWorld", "virtualWorld"), ("Viewer", "viewer"), ("GUI", "gui"),
                ("GUI", "problem_info"), ("rosout", "rosout"), ("rostopic", "rostopic"),
                ("GUI", "no_such_program"), ("no_such_package", "gui")]
    for package, program in programs:
        rosrun = subprocess.run(["rosrun", "--prefix", "echo", package, program],
                                capture_output=True, text=True, stdin=subprocess.DEVNULL)
        chosen = rosrun.stdout.strip() if rosrun.returncode == 0 else None
        assert find_executable(package, program, env) == chosen, (package, program)
    assert find_executable("GUI", "problem_info", env) is not None


def test_waiting_for_a_service_probes_it_as_rospy_does_and_the_node_logs_no_warning():
    from rosgraph.network import encode_ros_handshake_header
    from odin_common.ros_master import _tcpros_header
    fields = {"probe": "1", "md5sum": "*", "callerid": "/odin_ros_master", "service": "/a/b"}
    assert _tcpros_header(fields) == encode_ros_handshake_header(fields)
    with RosMaster() as master:
        world = master.rosrun("VirtualWorld", "virtualWorld")
        master.wait_for_service("/virtual_world/step_once")
        master.wait_for_service("/virtual_world/start")
        assert master.run(["rosservice", "call", "/virtual_world/step_once", "cycles: 1"]
                          ).returncode == 0           # the log holds the whole start-up
        assert "Inbound TCP/IP connection failed" not in master.log_text(world)


def test_the_in_process_rosrun_search_prints_no_package_name_lint(capfd):
    # catkin_pkg lints the thesis's capitalised package names on stderr at every search
    import os
    from odin_common import ros_master
    ros_master._rosrun_choice.cache_clear()
    assert ros_master.find_executable("GUI", "load_problem", dict(os.environ))
    assert "naming conventions" not in capfd.readouterr().err
