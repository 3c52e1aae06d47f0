"""The stamps of the world's topics: one simulated time that never goes back (ROS-free).

The Core counts simulated time per scene: New Scene starts it at 0, Restore State and Reset put
a snapshot's time back. A ROS graph cannot follow that: a tf buffer or a ``use_sim_time`` node
that sees /clock go back drops its transforms or fails its sleeps. So every stamp the world
publishes (``world_update``, ``/clock``, ``/tf``, joint states, collisions, diagnostics) is the
**world clock**, one value for all of them per publication:

    stamp = Core simulated time + offset

The offset is 0 until the Core's time first goes back, so a world used without New Scene,
Restore State or Reset stamps its topics with the Core's own simulated time. When the Core's
time goes back, the offset grows so that the stamp goes on one ODE step after the last one
published: time passes across scenes at the pace of the simulation. While the Core's time
stands still (paused), a publication after a change of the world (Set Position, a build, an
interactive marker dragged) is stamped one nanosecond after the previous one, so that tf never
receives two different poses under one stamp; the next step's stamp is the simulated time again.
Stamps are whole nanoseconds (``rospy.Time``'s resolution). The Core's own time stays what Get
World's ``sim_time`` and the services answer; Get World's ``clock`` is the world clock.
"""
from __future__ import annotations

from typing import Optional, Tuple

NANOSECONDS = 1_000_000_000


class WorldClock:
    """Turns the Core's simulated time into stamps that never go back (see the module)."""

    def __init__(self) -> None:
        self.offset = 0                     # ns
        self.last: Optional[int] = None     # ns, the last stamp given
        self._last_scene: Optional[int] = None

    def stamp(self, scene_time: float, step: float, changed: bool) -> Tuple[int, int]:
        """The stamp (secs, nsecs) of a publication of the world at the Core's ``scene_time``
        (s); ``step`` (s) is the ODE step in force, ``changed`` says whether the world changed
        since the last publication other than by stepping."""
        scene = round(scene_time * NANOSECONDS)
        if self._last_scene is not None and scene < self._last_scene:
            self.offset = self.last + round(step * NANOSECONDS) - scene
        stamp = scene + self.offset
        if self.last is not None and stamp <= self.last:
            stamp = self.last + 1 if changed else self.last
        self._last_scene, self.last = scene, stamp
        return divmod(stamp, NANOSECONDS)

    def now(self, scene_time: float) -> float:
        """The world clock (s) for the Core's ``scene_time`` without publishing: the last stamp
        while that is later (the Core's time went back or stands still)."""
        stamp = round(scene_time * NANOSECONDS) + self.offset
        return (stamp if self.last is None else max(stamp, self.last)) / NANOSECONDS
