#!/usr/bin/env python3
"""rostest node for chain.test: GUI-like calls -> VirtualWorld -> Viewer."""
import sys
import time
import unittest

import numpy as np
import rospy
import rostest
from sensor_msgs.msg import Image

from Messages.msg import Object, SpaceDistribution
from Services.srv import BuildObject, BuildObjectRequest, Start


def _object(name, parameters, position, **extra):
    return Object(name=name, parameters=parameters, position=position,
                  orientation=[1, 0, 0, 0], **extra)


class ChainTest(unittest.TestCase):
    def test_sphere_falls_onto_box_and_is_rendered(self):
        rospy.wait_for_service("/virtual_world/build_object", timeout=60)
        rospy.wait_for_service("/viewer/view_object", timeout=60)
        build = rospy.ServiceProxy("/virtual_world/build_object", BuildObject)
        for body in (_object("box", [0.6, 0.6, 0.4], [0, 0, 0.2], geometry_only=True,
                             color=[0.2, 0.4, 0.9, 1]),
                     _object("sphere", [0.15], [0, 0, 1.5], mass=1.0, color=[0.9, 0.2, 0.2, 1])):
            response = build(BuildObjectRequest(body))
            self.assertTrue(response.success, response.message)
        first_frame = self._frame()
        self.assertTrue(rospy.ServiceProxy("/virtual_world/start", Start)(True).success)
        update = self._update_at(1.5)
        height = {s.name: s.position[2] for s in update.situations}["sphere"]
        # resting on the box: box top 0.4 m + radius 0.15 m, within the surface layer
        self.assertAlmostEqual(height, 0.55, delta=0.01)
        last_frame = self._frame()
        self.assertEqual(first_frame.shape, last_frame.shape)
        changed = np.abs(first_frame.astype(int) - last_frame.astype(int)).sum(axis=2) > 60
        self.assertGreater(changed.sum(), 100, "the rendered frame did not change")

    @staticmethod
    def _update_at(sim_time: float, timeout: float = 60.0) -> SpaceDistribution:
        """The first world update stamped at or after ``sim_time`` (s, simulated): the world
        runs in real time only when the machine keeps up."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            update = rospy.wait_for_message("/virtual_world/world_update", SpaceDistribution, 10)
            if update.header.stamp.to_sec() >= sim_time:
                return update
        raise AssertionError(f"the world did not reach {sim_time} s in {timeout} s")

    @staticmethod
    def _frame():
        time.sleep(0.3)  # a frame rendered after the last change
        image = rospy.wait_for_message("/viewer/image", Image, timeout=10)
        return np.frombuffer(image.data, np.uint8).reshape(image.height, image.width, 3)


if __name__ == "__main__":
    rospy.init_node("chain_check")
    rostest.rosrun("VirtualWorld", "chain", ChainTest, sys.argv)
