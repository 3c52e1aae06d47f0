"""The experiments' record of world updates (tools/experiments/common.py), without ROS."""
import pathlib
import sys

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tools" / "experiments"))

import common  # noqa: E402

IDENTITY = (1.0, 0.0, 0.0, 0.0)


def test_trajectories_pair_poses_of_the_same_cycle_only():
    """A paused world's update sent between two Build Object calls holds the palm and not yet
    the can: the pair's trajectories start at the next update, sample for sample (the grasp's
    slip was once measured between the can of one cycle and the palm of the next)."""
    session = common.Session("record", {}, camera=None, frames=False, viewer=False)
    poses = session.record.poses
    poses[0.0] = {"palm": ((0.0, 0.0, 1.0), IDENTITY)}
    for k in range(1, 4):
        t = round(0.01 * k, 6)
        poses[t] = {"palm": ((0.1 * k, 0.0, 1.0), IDENTITY),
                    "can": ((0.1 * k, 0.0, 0.9), IDENTITY)}
    times, both = session.trajectories("can", "palm")
    assert times.tolist() == [0.01, 0.02, 0.03]
    can, palm = both["can"][0], both["palm"][0]
    assert np.allclose(palm - can, [0.0, 0.0, 0.1])
    assert both["palm"][1].shape == (3, 4)
    assert len(session.trajectory("palm")[0]) == 4      # a lone trajectory keeps every sample


def test_trajectories_of_nothing_recorded_are_empty():
    session = common.Session("record", {}, camera=None, frames=False, viewer=False)
    times, both = session.trajectories("can", "palm")
    assert len(times) == 0 and both["can"][0].shape == (0, 3)
