"""A recording of what changed a world (the world node's ``~record``): a rosbag that holds, in
the order they happened, the values the world started with, every state-changing request that
succeeded, and every advance of the world with the poses after it. ``replay`` re-runs it in a
fresh Core and compares every pose bit for bit.

Topics (bag times are the wall-clock times of the entries, strictly increasing, so a reader
gets them in the order they happened):
  ``/odin/record/start``     Messages/RecordStart: world parameters and step values at start;
  ``/odin/record/<service>`` the request message of each state-changing call that succeeded
                             (Services/<Type>Request; odin_common.interface.WORLD_SERVICES);
  ``/odin/record/advance``   Messages/Advance: steps taken and the poses after them.
"""
from __future__ import annotations

import pathlib
import time

import rospy

from Messages.msg import Advance, RecordStart, Situation
from odin_common import messages
from odin_common.step_values import StepValues
from odin_common.world_parameters import WorldParameters

PREFIX = "/odin/record/"
START = PREFIX + "start"
ADVANCE = PREFIX + "advance"


class Recorder:
    """Writes one recording; ``close()`` finishes the bag (idempotent)."""

    def __init__(self, path: str, parameters: WorldParameters, values: StepValues):
        self.path = pathlib.Path(path).expanduser().resolve()
        self.path.parent.mkdir(parents=True, exist_ok=True)
        # imported on the first recording: its crypto imports were 0.14 s of every node's start
        import rosbag
        self._bag = rosbag.Bag(str(self.path), "w")
        self._last = 0
        self._write(START, RecordStart(messages.world_parameters_message(parameters),
                                       values.step, values.steps_per_cycle, values.rate))

    def request(self, service: str, request) -> None:
        self._write(PREFIX + service, request)

    def advance(self, step: float, steps: int, sim_time: float, names, positions,
                quaternions) -> None:
        situations = [Situation(name, p.tolist(), q.tolist())
                      for name, p, q in zip(names, positions, quaternions)]
        self._write(ADVANCE, Advance(step, steps, sim_time, situations))

    def _write(self, topic: str, message) -> None:
        now = max(time.time_ns(), self._last + 1)     # strictly increasing: the order is kept
        self._last = now
        self._bag.write(topic, message, rospy.Time(nsecs=now))

    def close(self) -> None:
        if self._bag is not None:
            self._bag.close()
            self._bag = None
