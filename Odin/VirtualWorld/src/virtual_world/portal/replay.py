"""``rosrun VirtualWorld replay BAG``: re-runs a recording of a world (the node's ``~record``) in
a fresh Core, through the same service handlers, and says whether every pose matches bit for
bit. Needs no master.

Exit status 0 when every advance ends in the recorded poses, 1 at the first that does not (the
line says where and by how much), 2 when the file cannot be read.
"""
from __future__ import annotations

import argparse
import sys
from typing import Optional, Sequence

import numpy as np

from odin_common import OdinError, messages
from odin_common.step_values import StepValues
from virtual_world.core import Core
from virtual_world.portal.recorder import ADVANCE, PREFIX, START
from virtual_world.portal.services import LOOP_CONTROL, WorldServices


class ReplayLoop:
    """What the service handlers ask of a loop, for a replay: the step values in force; the
    recorded advances stand for Start and Step Once."""

    def __init__(self, values: StepValues):
        self.step_values = values
        self.simulate = False
        self.sim_time = 0.0


class Mismatch(Exception):
    """The replay departed from the recording."""


def replay(path: str) -> dict:
    """Re-runs the recording at ``path``; returns counts of what it re-ran; raises Mismatch at
    the first difference, OdinError or an I/O error when the file cannot be read."""
    import rosbag
    core = Core()
    services, counts = None, {"requests": 0, "advances": 0, "poses": 0}
    try:
        with rosbag.Bag(path) as bag:
            for index, (topic, message, _) in enumerate(bag.read_messages()):
                if topic == START:
                    core.set_world_parameters(
                        **messages.world_parameters_of(message.parameters).as_dict())
                    services = WorldServices(core, ReplayLoop(StepValues(
                        message.step, message.steps_per_cycle, message.rate)))
                elif services is None:
                    raise OdinError(f"{path}: entry {index} ({topic}) before the start entry")
                elif topic == ADVANCE:
                    core.step(message.step, message.steps)
                    _compare(core, message, index)
                    counts["advances"] += 1
                    counts["poses"] += len(message.situations)
                elif topic.startswith(PREFIX):
                    name = topic[len(PREFIX):]
                    if name not in LOOP_CONTROL:
                        _rerun(services, name, message, index)
                        counts["requests"] += 1
        return counts
    finally:
        core.close()


def _rerun(services: WorldServices, name: str, request, index: int) -> None:
    handler = getattr(services, name, None)
    if handler is None:
        raise OdinError(f"entry {index}: no world service {name!r}")
    try:
        handler(request)
    except OdinError as error:
        raise Mismatch(f"entry {index}: {name} succeeded when recorded but is refused now: "
                       f"{error}") from None


def _compare(core: Core, advance, index: int) -> None:
    names, positions, quaternions = core.poses()
    recorded = {s.name: (s.position, s.orientation) for s in advance.situations}
    if names != list(recorded):
        raise Mismatch(f"entry {index} (t = {advance.sim_time:g} s): geometries "
                       f"{sorted(set(names) ^ set(recorded))} differ")
    if abs(core.sim_time - advance.sim_time) > 0:
        raise Mismatch(f"entry {index}: simulated time {core.sim_time!r} s, recorded "
                       f"{advance.sim_time!r} s")
    want_p = np.array([recorded[n][0] for n in names]).reshape(-1, 3)
    want_q = np.array([recorded[n][1] for n in names]).reshape(-1, 4)
    for got, want in ((positions, want_p), (quaternions, want_q)):
        if got.tobytes() != want.tobytes():
            k = int(np.flatnonzero(np.any(got != want, axis=1))[0])
            raise Mismatch(f"entry {index} (t = {advance.sim_time:g} s): {names[k]} is at "
                           f"{got[k].tolist()}, recorded {want[k].tolist()} "
                           f"(largest difference {np.abs(got - want).max():.3g})")


def main(argv: Optional[Sequence[str]] = None) -> int:
    parser = argparse.ArgumentParser(prog="replay", description=__doc__.splitlines()[0])
    parser.add_argument("bag", help="a recording made with the world node's ~record")
    args = parser.parse_args(argv)
    try:
        counts = replay(args.bag)
    except Mismatch as error:
        print(f"replay: {args.bag}: differs: {error}", file=sys.stderr)
        return 1
    except Exception as error:   # OdinError, OSError and rosbag's own: one line for the user
        print(f"replay: {args.bag}: cannot replay: {' '.join(str(error).split())}",
              file=sys.stderr)
        return 2
    print(f"replay: {args.bag}: identical: {counts['requests']} requests, "
          f"{counts['advances']} advances, {counts['poses']} poses bit for bit")
    return 0
