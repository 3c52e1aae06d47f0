"""join_ros_graph's prompt registration: rospy.init_node's 0.1 s polls become short ones only
while the node joins, and rospy's module is as before afterwards."""
import time

from rospy.impl import init

from gui.ros import services


def test_within_the_block_rospy_init_polls_in_short_sleeps_and_after_it_as_before():
    before = init.time
    with services._prompt_registration():
        started = time.monotonic()
        init.time.sleep(0.1)            # rospy.impl.init.start_node's poll
        assert time.monotonic() - started < 0.05
        assert init.time.monotonic is time.monotonic   # the rest of time as it is
    assert init.time is before


def test_the_block_gives_rospy_its_time_back_after_an_error():
    before = init.time
    try:
        with services._prompt_registration():
            raise RuntimeError("init_node failed")
    except RuntimeError:
        pass
    assert init.time is before
