"""Ctrl-C and SIGTERM end a node whose main thread runs its own loop (the world), whatever
that thread holds when the signal comes (odin_common.node.stop_on_signals)."""
import os
import signal
import subprocess
import threading
import time

import pytest


@pytest.mark.forked
def test_a_signal_while_a_topic_lock_is_held_stops_the_loop_and_rospy_then_shuts_down(
        ros_master):
    """The world's loop publishes on its main thread; rospy's own handler ran its whole
    shutdown there, and closing a subscriber's connection whose lock the interrupted publish
    held waited for the connection's thread, which waited for that lock: a world ignored
    Ctrl-C until killed (once in a full run of make test). With rospy's handler this test
    hangs in the kill below until the watchdog ends it."""
    import rospy
    from std_msgs.msg import Empty
    from odin_common.node import init_ros_node, stop_on_signals

    def give_up() -> None:                      # a deadlock fails the test, leaving nothing
        ros_master.stop()
        os._exit(3)
    watchdog = threading.Timer(30, give_up)
    watchdog.daemon = True
    watchdog.start()
    init_ros_node("signal_probe", disable_signals=True)
    publisher = rospy.Publisher("~probe", Empty, queue_size=1)
    rospy.Subscriber("~probe", Empty, lambda message: None)
    deadline = time.monotonic() + 20
    while not publisher.impl.connections and time.monotonic() < deadline:
        time.sleep(0.05)
    connection = publisher.impl.connections[0]
    stopped = threading.Event()
    stop_on_signals(stopped.set)
    with publisher.impl.c_lock, connection._lock:    # what a publish holds while it queues
        os.kill(os.getpid(), signal.SIGINT)
        assert stopped.wait(5), "the handler did not run"
    shutdown = threading.Thread(target=rospy.signal_shutdown, args=("test",), daemon=True)
    shutdown.start()
    shutdown.join(10)
    assert not shutdown.is_alive(), "rospy's shutdown hung"
    watchdog.cancel()


@pytest.mark.parametrize("number", [signal.SIGINT, signal.SIGTERM])
def test_the_world_ends_on_a_signal_while_it_simulates_and_publishes(ros_master, number):
    node = ros_master.rosrun("VirtualWorld", "virtualWorld", "_simulate:=true", "_rate:=200")
    ros_master.wait_for_service("/virtual_world/set_joint_force")
    listener = ros_master.popen(["rostopic", "echo", "-n", "1000000",
                                 "/virtual_world/joint_states"], log_name="echo")
    deadline = time.monotonic() + 30
    while "header" not in ros_master.log_text(listener) and time.monotonic() < deadline:
        time.sleep(0.05)
    os.killpg(node.pid, number)
    try:
        node.wait(15)
    except subprocess.TimeoutExpired:
        pytest.fail("the world did not end on the signal:\n" + ros_master.log_text(node)[-2000:])
    assert node.returncode == 0, ros_master.log_text(node)[-2000:]
