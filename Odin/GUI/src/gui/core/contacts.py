"""The contacts a run met, told apart (ROS-free): those the scene stood in when the run began
(support: a can resting on its table, a mobile base on its floor, parts built touching) from
those the run made (a link driven into an obstacle, two arms into each other, a fingertip on
the can it grasps).

A pair is support when it was touching, by Check Collision, before the run's first step,
however deep it goes later: under Kautham's soft contacts a resting box sinks into its ground
by centimetres on its own, and a can pressed into its table by a hand is still the can on its
table (the hand's pair with the can is the one the run made). Geometry names are the world's;
a pair is named in sorted order. Depths are m, times s from the run's start.
"""
from __future__ import annotations

from typing import Dict, Iterable, List, Tuple

PAIRS_NAMED = 3
"""Pairs a one-line account names (the deepest); the rest are counted."""


def _key(first: str, second: str) -> Tuple[str, str]:
    return (first, second) if first <= second else (second, first)


class ContactLedger:
    """The pairs one run met, support apart from those it made (module docstring).
    ``before``: (first, second, depth m) of every pair touching when the run began."""

    def __init__(self, before: Iterable[Tuple[str, str, float]]):
        self._before: Dict[Tuple[str, str], float] = {}
        for first, second, depth, *_ in before:
            key = _key(first, second)
            self._before[key] = max(self._before.get(key, 0.0), float(depth))
        self._support: Dict[Tuple[str, str], float] = {}
        self._made: Dict[Tuple[str, str], List[float]] = {}     # pair -> [first time, depth]

    def see(self, first: str, second: str, depth: float, time: float) -> None:
        """A pair found colliding ``depth`` m deep ``time`` s into the run."""
        key = _key(first, second)
        if key in self._made:
            self._made[key][1] = max(self._made[key][1], float(depth))
        elif key in self._before:
            self._support[key] = max(self._support.get(key, 0.0), float(depth))
        else:
            self._made[key] = [float(time), float(depth)]

    @property
    def made(self) -> List[dict]:
        """The pairs the run made, in the order they were first met: ``first``, ``second``,
        ``first_time_s``, ``depth_m`` (the deepest)."""
        return [dict(first=a, second=b, first_time_s=t, depth_m=d)
                for (a, b), (t, d) in sorted(self._made.items(), key=lambda i: (i[1][0], i[0]))]

    @property
    def support(self) -> List[dict]:
        """The contacts the scene rested on through the run: ``first``, ``second``,
        ``depth_m`` (the deepest met)."""
        return [dict(first=a, second=b, depth_m=d) for (a, b), d in sorted(self._support.items())]

    def describe(self) -> str:
        """One clause: how many pairs the run made (the deepest named, with depth and time)
        and how many contacts it rested on."""
        made = self.made
        deepest = sorted(made, key=lambda c: -c["depth_m"])[:PAIRS_NAMED]
        named = ", ".join(f"{c['first']} | {c['second']} {c['depth_m'] * 1000:.1f} mm at "
                          f"{c['first_time_s']:.2f} s" for c in deepest)
        more = len(made) - len(deepest)
        text = f"{len(made)} colliding pair{'' if len(made) == 1 else 's'} made by the path"
        if named:
            text += f" ({named}{f' and {more} more' if more else ''})"
        resting = len(self._support)
        return text + f", {resting} resting contact{'' if resting == 1 else 's'}"


__all__ = ["ContactLedger", "PAIRS_NAMED"]
