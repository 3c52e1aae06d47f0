"""The thesis's three experiments (chapter 10) end to end: each runs its own roscore, the
world and Viewer nodes by rosrun and this process as the GUI (tools/experiments), and its
outcome is asserted on what the nodes published and what the Viewer drew.

Each test runs in a forked child (rospy.init_node works once per process).
"""
import pathlib
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tools" / "experiments"))


@pytest.mark.forked
def test_contactless_pair_greys_exactly_while_touching():
    import contactless
    facts = contactless.run()
    o = facts["outcome"]
    assert o["pairs_reported"] == [["KukaLWR/Link7", "can"]]
    assert o["collision_runs"] == 1
    assert 0.2 < o["collision_start_s"] < o["collision_stop_s"] < 0.7
    assert 0.0005 < o["max_depth_m"] < 0.01
    assert o["collided_messages"] >= o["cycles"]
    frames = facts["frames"]
    assert frames["frames_touching"] >= 5 and frames["frames_free"] >= 5
    assert frames["can_grey_exactly_while_touching"]
    assert frames["tip_grey_exactly_while_touching"]


@pytest.mark.forked
def test_pile_cans_knocked_down_fall_and_bounce():
    import pile
    facts = pile.run(frames=False)
    cans = facts["outcome"]["cans"]
    for name, can in cans.items():
        assert can["moved_m"] > 0.2, name
        assert can["knocked_off_the_table"], name
    assert all(can["hit_ground"] and can["bounced"] and not can["fell_past_the_floor_edge"]
               for can in cans.values())
    assert facts["contacts"]["cycles_with_contacts"] > 0


@pytest.mark.forked
def test_grasp_carries_the_can_and_releases_it_when_the_hand_opens(tmp_path):
    import grasp
    facts = grasp.run(frames=False, out_root=tmp_path)  # out/experiments/grasp keeps its frames
    o = facts["outcome"]
    assert o["can_height_above_table_while_carried_m"]["min"] > 0.1
    assert o["can_moved_while_carried_m"] > 0.5
    # held from the lift until the opening: within millimetres of its place in the palm's frame,
    # and not sinking through the grip
    # (16 mm and 4 mm with the 4 mm collision meshes, the same in every run; 13 mm and 5 mm
    # with the meshes as given)
    assert o["max_slip_in_hand_before_opening_m"] < 0.02
    assert o["max_slip_in_hand_while_carried_m"] < 0.015
    assert o["can_sank_in_hand_before_opening_m"] < 0.003
    assert o["released_only_when_hand_opens"]
    assert o["can_released_at_s"] >= o["hand_opens_at_s"]
    assert o["can_on_floor_at_end"]


def test_one_command_runs_several_experiments():
    """`make experiments` runs them one after another from one command; each has a roscore of
    its own, which one rospy process cannot follow (it hung on the second before)."""
    import subprocess
    result = subprocess.run(
        [sys.executable, str(ROOT / "tools" / "experiments" / "run.py"), "--no-frames",
         "contactless", "pile"], capture_output=True, text=True, timeout=600,
        stdin=subprocess.DEVNULL)
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr[-2000:]
    assert "experiment contactless: outcome held" in result.stdout, result.stdout[-2000:]
    assert "experiment pile: outcome held" in result.stdout, result.stdout[-2000:]
