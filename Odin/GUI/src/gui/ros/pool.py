"""A pool of world nodes used as one, for planners: several VirtualWorld nodes, each in its own
namespace (on this machine or on other hosts of the ROS graph), hold the same scene; a planner
fans its propagations out over them and gets the answers back in the order it asked.

    rosrun VirtualWorld virtualWorld __ns:=/w0      # one per core, or per host
    rosrun VirtualWorld virtualWorld __ns:=/w1

    with WorldPool(["/w0/virtual_world", "/w1/virtual_world"]) as pool:
        pool.broadcast("build_object", object=...)       # the same scene everywhere
        pool.broadcast("save_state", name="start")
        answers = pool.propagate([dict(start="start", duration=0.5, motors=[...],
                                       velocities=[...]) for ... in controls])

Each world has one thread and one persistent service connection of its own (rospy's proxies
are not shared between threads); a request goes to whichever world is free next, so a slow
world takes fewer. The worlds are deterministic, so the same request gives the same answer
whichever world serves it. Each world's calls go through a ``gui.ros.services.ServiceCaller``
of its thread, whose failures are ``PoolError``. Requires ``rospy.init_node`` (done here,
without signals, unless already done).
"""
from __future__ import annotations

import queue
import threading
from typing import Sequence

from gui.errors import ServiceError
from gui.ros.services import ServiceCaller, join_ros_graph
from odin_common.errors import InvalidArgument
from odin_common.interface import WORLD_SERVICES


class PoolError(ServiceError):
    """A world of the pool refused a request or could not be reached (``service`` says which
    world and which request)."""


class _World:
    """One world's thread and connections; it runs the tasks put on its queue, one at a time,
    and after a task of ``map`` says it is free again."""

    def __init__(self, namespace: str, free: queue.Queue, timeout: float):
        self._caller = ServiceCaller(namespace, WORLD_SERVICES, PoolError)
        self.namespace = self._caller.namespace
        self._caller.wait("propagate", timeout, f"no world answering after {timeout:g} s")
        self.tasks: queue.Queue = queue.Queue()
        self._free = free
        self.thread = threading.Thread(target=self._work, name=f"pool{self.namespace}",
                                       daemon=True)
        self.thread.start()

    def _work(self) -> None:
        while True:
            task = self.tasks.get()
            if task is None:
                break
            index, calls, answers, done, from_free = task
            try:
                for service, fields in calls:
                    answers[index] = self._caller.call(service, **fields)
            except Exception as error:   # handed back to the caller's thread
                answers[index] = error
            finally:
                if from_free:
                    self._free.put(self)
                done.release()
        self._caller.close()


class WorldPool:
    """World nodes at ``namespaces`` (e.g. "/w0/virtual_world"), used as one. Its methods are
    meant for one calling thread."""

    def __init__(self, namespaces: Sequence[str], timeout: float = 30.0,
                 node_name: str = "world_pool"):
        if not namespaces:
            raise InvalidArgument("a pool needs at least one world")
        join_ros_graph(node_name)
        self._free: queue.Queue = queue.Queue()
        self._worlds = [_World(n, self._free, timeout) for n in namespaces]
        for world in self._worlds:
            self._free.put(world)

    @property
    def size(self) -> int:
        return len(self._worlds)

    def broadcast(self, service: str, **fields) -> list:
        """The same call on every world, at once; their answers in the pool's order."""
        answers: list = [None] * self.size
        done = threading.Semaphore(0)
        for k, world in enumerate(self._worlds):
            world.tasks.put((k, [(service, fields)], answers, done, False))
        return self._gather(answers, done)

    def map(self, service: str, requests: Sequence[dict]) -> list:
        """One call of ``service`` per request (its fields), each to the next world that is
        free; the answers in the order of ``requests``."""
        return self.map_calls([[(service, dict(fields))] for fields in requests])

    def map_calls(self, requests: Sequence[Sequence[tuple]]) -> list:
        """Like ``map``, but each request is a list of calls, (service, fields) each, that one
        world makes in order (a Set Servo and the Propagate it is for); the answer to each
        request is its last call's."""
        answers: list = [None] * len(requests)
        done = threading.Semaphore(0)
        for k, calls in enumerate(requests):
            self._free.get().tasks.put((k, list(calls), answers, done, True))
        return self._gather(answers, done)

    def propagate(self, requests: Sequence[dict]) -> list:
        """Propagate requests (Services/Propagate fields: start, duration, step, motors,
        velocities, forces, keep), fanned out; their answers in order."""
        return self.map("propagate", requests)

    @staticmethod
    def _gather(answers: list, done: threading.Semaphore) -> list:
        for _ in answers:
            done.acquire()
        errors = [a for a in answers if isinstance(a, Exception)]
        if errors:
            raise errors[0]
        return answers

    def close(self) -> None:
        for world in self._worlds:
            world.tasks.put(None)
        for world in self._worlds:
            world.thread.join(timeout=5.0)

    def __enter__(self) -> "WorldPool":
        return self

    def __exit__(self, *exc) -> None:
        self.close()
