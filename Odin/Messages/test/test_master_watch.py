"""MasterWatch's rule for a forgotten registration (odin_common.node.forgotten); the whole
watch against a master that restarts is tests/nodes/test_fault_drills.py's."""
from odin_common.node import MASTER_LOST, forgotten

NEW_TOPIC = ("publication", "/virtual_world/robot/joint_states")


def test_a_registration_missing_at_one_look_only_is_in_flight_not_forgotten():
    # rospy lists a new topic a moment before it tells the master
    assert not forgotten(set(), {NEW_TOPIC})
    assert not forgotten({NEW_TOPIC}, set())
    assert not forgotten({NEW_TOPIC}, {("service", "/virtual_world/start")})


def test_a_registration_missing_at_two_looks_in_a_row_is_forgotten():
    assert forgotten({NEW_TOPIC}, {NEW_TOPIC, ("service", "/virtual_world/start")})
    assert forgotten({MASTER_LOST}, {MASTER_LOST})
