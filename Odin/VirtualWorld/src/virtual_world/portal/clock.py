"""The stamps of the world's topics: one simulated time that never goes back (ROS-free).

The Core counts simulated time per scene: New Scene starts it at 0, Restore State and Reset put
a snapshot's time back. A ROS graph cannot follow that: a tf buffer or a ``use_sim_time`` node
that sees /clock go back drops its transforms or fails its sleeps. So every stamp the world
publishes (``world_update``, ``/clock``, ``/tf``, joint states, contacts, markers' updates) is
the **world clock**, one value for all of them per publication:

    stamp = Core simulated time + offset

The offset is 0 until the Core's time first goes back (a world used without New Scene, Restore
State or Reset stamps its topics with the Core's own time). When it goes back, the offset grows
so that the next stamp is one ODE step after the last one published: time goes on across the
scenes, at the same pace. When the world changed while its time stood still (paused: Set
Position, a build, an interactive marker dragged), the next stamp is one microsecond later, so
that tf never receives two different poses under one stamp. The Core's own time stays what
Get World's ``sim_time`` and the services answer; Get World's ``clock`` is the world clock.
"""
from __future__ import annotations

from typing import Optional

#: s: how far the clock moves when the world changed while its simulated time stood still
STILL_CHANGE_TICK = 1e-6


class WorldClock:
    """Turns the Core's simulated time into stamps that never go back (see the module)."""

    def __init__(self) -> None:
        self.offset = 0.0
        self.last: Optional[float] = None   # s, the last stamp given

    def stamp(self, scene_time: float, step: float, changed: bool) -> float:
        """The stamp (s) of a publication of the world at the Core's ``scene_time`` (s);
        ``step`` (s) is the ODE step in force, ``changed`` says whether the world changed since
        the last publication other than by stepping."""
        stamp = scene_time + self.offset
        if self.last is not None:
            if stamp < self.last:
                self.offset += self.last + step - stamp
                stamp = self.last + step
            elif stamp == self.last and changed:
                self.offset += STILL_CHANGE_TICK
                stamp += STILL_CHANGE_TICK
        self.last = stamp
        return stamp

    def now(self, scene_time: float) -> float:
        """The world clock for ``scene_time`` without publishing: the last stamp if the Core's
        time went back since (the next publication moves on from there)."""
        stamp = scene_time + self.offset
        return stamp if self.last is None else max(stamp, self.last)
