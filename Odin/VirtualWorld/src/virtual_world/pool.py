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
whichever world serves it. Requires ``rospy.init_node`` (done here, without signals, unless
already done).
"""
from __future__ import annotations

import queue
import threading
from typing import Any, Dict, Sequence

from odin_common import OdinError
from odin_common.interface import WORLD_SERVICES


class PoolError(OdinError):
    """A world of the pool refused a request or could not be reached (the message says which
    world and which request)."""


class _World:
    """One world's thread and connections; it runs the tasks put on its queue, one at a time,
    and after a task of ``map`` says it is free again."""

    def __init__(self, namespace: str, free: queue.Queue, timeout: float):
        import rospy
        self.namespace = namespace.rstrip("/")
        self._rospy = rospy
        try:
            rospy.wait_for_service(f"{self.namespace}/propagate", timeout=timeout)
        except rospy.ROSException:
            raise PoolError(f"{self.namespace}: no world answering after {timeout:g} s") \
                from None
        self.tasks: queue.Queue = queue.Queue()
        self._free = free
        self._proxies: Dict[str, Any] = {}
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
                    answers[index] = self._call(service, fields)
            except Exception as error:   # handed back to the caller's thread
                answers[index] = error
            finally:
                if from_free:
                    self._free.put(self)
                done.release()
        for proxy in self._proxies.values():
            proxy.close()

    def _call(self, service: str, fields: dict):
        from Services import srv
        proxy = self._proxies.get(service)
        if proxy is None:
            proxy = self._rospy.ServiceProxy(f"{self.namespace}/{service}",
                                             getattr(srv, WORLD_SERVICES[service]),
                                             persistent=True)
            self._proxies[service] = proxy
        try:
            response = proxy(proxy.request_class(**fields))
        except (self._rospy.ServiceException, OSError) as error:
            self._proxies.pop(service, None)
            raise PoolError(f"{self.namespace}/{service}: call failed: {error}") from None
        if not response.success:
            raise PoolError(f"{self.namespace}/{service}: {response.message}")
        return response


class WorldPool:
    """World nodes at ``namespaces`` (e.g. "/w0/virtual_world"), used as one. Its methods are
    meant for one calling thread."""

    def __init__(self, namespaces: Sequence[str], timeout: float = 30.0,
                 node_name: str = "world_pool"):
        import rospy
        if not namespaces:
            raise PoolError("a pool needs at least one world")
        if not rospy.core.is_initialized():
            rospy.init_node(node_name, anonymous=True, disable_signals=True)
            from odin_common.node import prompt_shutdown
            prompt_shutdown()
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
