"""What every Core request does around its own work (ROS-free): take the Core's lock and refuse
once it is closed, note that the world's contents or state changed (the reset point), and wake
the bodies auto-disabling put to sleep. Each is a decorator of a ``Core`` method; the Core's
``_lock`` and ``_scene`` are what they read.
"""
from __future__ import annotations

import functools

from virtual_world.core import snapshots
from virtual_world.errors import Closed


def locked(method):
    """A request that needs the Core open: run under its lock, Closed once it is closed."""
    @functools.wraps(method)
    def wrapper(self, *args, **kwargs):
        with self._lock:
            _open_scene(self, method)
            return method(self, *args, **kwargs)
    return wrapper


def _open_scene(core, method):
    """The Core's scene; Closed once the Core is closed."""
    if core._scene is None:
        raise Closed(f"Core is closed ({method.__name__})")
    return core._scene


def _wake_sleepers(scene) -> None:
    """Under auto_disable, a request that changed the world wakes every body: a body asleep on
    a support just removed must fall, one given a velocity or a force must move. ODE itself
    wakes a sleeper only when an awake body touches it."""
    if scene.parameters.auto_disable:
        scene.c.wake()


def changes_contents(method):
    """A call that may add or remove objects, joints or motors: the next change of state takes
    a new reset point."""
    @functools.wraps(method)
    def wrapper(self, *args, **kwargs):
        result = method(self, *args, **kwargs)
        self._scene.contents_changed = True
        _wake_sleepers(self._scene)
        return result
    return locked(wrapper)


def changes_state(method):
    """A call that changes the dynamic state, under the lock (as ``locked``, in one frame: a
    planner makes thousands a second): first, if the contents changed since the reset point
    was taken, the state as the last build left it becomes the reset point."""
    @functools.wraps(method)
    def wrapper(self, *args, **kwargs):
        with self._lock:
            scene = _open_scene(self, method)
            if scene.contents_changed:
                scene.reset_point = snapshots.take(scene)
                scene.contents_changed = False
            return method(self, *args, **kwargs)
    return wrapper


def disturbs(method):
    """A request that changes the dynamic state from outside (poses, velocities, forces, motor
    goals, surfaces): ``changes_state``, and then the sleepers wake. Putting back a recorded
    state, stepping and propagating do not wake: the state says which bodies sleep."""
    @functools.wraps(method)
    def wrapper(self, *args, **kwargs):
        result = method(self, *args, **kwargs)
        _wake_sleepers(self._scene)
        return result
    return changes_state(wrapper)
