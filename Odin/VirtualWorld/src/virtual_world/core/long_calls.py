"""Calls that step many times (Propagate, Step Once of many cycles), run in pieces so that
they can stop when their caller has gone.

A long call takes a ``cancelled`` function (no arguments -> why to stop, or None/False; the
Portal's says when the service client's connection is closed or the call has run too long)
and asks it between pieces of about CHECK_SECONDS: a caller that gave up is noticed within a
second or so, not when its ten minutes of work are done. Pieces are steps of the same one C
loop: run in pieces or in one call, the steps, collisions and states are bit for bit the same.
"""
from __future__ import annotations

import time
from typing import Callable, Optional

from virtual_world.core import guard
from virtual_world.core.scene import Scene
from virtual_world.errors import CoreError

CHECK_SECONDS = 0.25
"""s of wall time between two looks at ``cancelled``: pieces are sized from the steps per
second of the pieces before (a step's cost spans orders of magnitude: bodies, contacts, the
solver and its iterations), starting at one step and growing at most fourfold a piece."""


class Cancelled(CoreError):
    """A long call stopped because its caller was gone (what it leaves: its docstring)."""


def never() -> Optional[str]:
    """The ``cancelled`` of a call nobody can cancel."""
    return None


Cancel = Callable[[], object]
"""Why a long call should stop (a str, or any true value: its caller has gone), or a false
value to go on."""


def run_steps(scene: Scene, step_size: float, steps: int,
              cancelled: Optional[Cancel] = None) -> int:
    """Steps ``steps`` steps of ``step_size`` s, in pieces between which ``cancelled()`` is
    asked (None: one piece); the scene's simulated time and the divergence guard follow
    each piece. Returns the steps taken (fewer when the guard paused the world); raises
    Cancelled, with the steps of the pieces before it taken, when ``cancelled()`` says so."""
    start_time, taken, piece = scene.sim_time, 0, steps if cancelled is None else 1
    while taken < steps:
        why = cancelled() if cancelled is not None else None
        if why:
            raise Cancelled(f"cancelled after {taken:,} of {steps:,} steps: "
                            f"{why if isinstance(why, str) else 'the caller has gone'}")
        asked = min(piece, steps - taken)
        started = time.perf_counter()
        done = scene.c.step(step_size, asked)
        piece = _next_piece(asked, time.perf_counter() - started)
        taken += done
        scene.sim_time = start_time + step_size * taken
        guard.collect(scene, step_size)
        if done < asked:
            break
    return taken


def _next_piece(asked: int, seconds: float) -> int:
    """Steps of the next piece after ``asked`` steps took ``seconds``: CHECK_SECONDS' worth,
    at most four times as many, at least one."""
    if seconds <= 0.0:
        return 4 * asked
    return max(1, min(4 * asked, int(asked * CHECK_SECONDS / seconds)))
