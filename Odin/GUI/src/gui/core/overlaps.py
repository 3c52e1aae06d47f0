"""Parts a problem builds inside each other, found by the world's Check Collision right after
a build and reported to the user (the loaders warn; `make corpus` records them).

Kautham places robots and obstacles where the problem says, and a geometric problem never
simulates them: a 2012 robot without ``<Home>`` stands at the origin (``Problem::
setupFromFile``: "If robot hasn't a home, it will be assumed in the origin"), which may be
inside its scene. In a physical world the contacts of such a pair push the parts apart as soon
as the world runs: the robot moves off the pose it was built at. Odin builds what the problem
says and says so, once, naming the pairs.

A pair counts when it overlaps by more than ``BUILT_OVERLAP`` (resting contact is a fraction
of a millimetre deep) and at least one of its parts can move (two static parts never push each
other).
"""
from __future__ import annotations

from typing import List, NamedTuple, Sequence, Tuple

#: m, the least depth of a pair reported as built inside each other
BUILT_OVERLAP = 0.001
#: pairs a warning names (the deepest first); the rest are counted
PAIRS_NAMED = 3


class Overlap(NamedTuple):
    """Two geometries (names as the world reports them) built ``depth`` m inside each other."""
    first: str
    second: str
    depth: float


def built_overlaps(plan, pairs: Sequence[Tuple[str, str, float]],
                   deeper_than: float = BUILT_OVERLAP) -> List[Overlap]:
    """The pairs of ``pairs`` ((first, second, depth m), Check Collision's answer for the scene
    ``plan`` built) deeper than ``deeper_than`` where a part can move, deepest first."""
    static = _static_geometries(plan)
    found = [Overlap(a, b, float(d)) for a, b, d in pairs
             if d > deeper_than and not (a in static and b in static)]
    return sorted(found, key=lambda o: (-o.depth, o.first, o.second))


def overlap_warning(source: str, overlaps: Sequence[Overlap]) -> str:
    """One line for the user: ``source`` (the problem file) and the deepest pairs."""
    named = ", ".join(f"{o.first} in {o.second} by {o.depth * 1000:.1f} mm"
                      for o in overlaps[:PAIRS_NAMED])
    more = len(overlaps) - PAIRS_NAMED
    rest = f" and {more} more pair{'s' if more > 1 else ''}" if more > 0 else ""
    return (f"{source}: built with parts inside each other, where the problem places them: "
            f"{named}{rest}; their contacts push them apart when the world runs")


def _static_geometries(plan) -> set:
    """Names of the geometries of the plan's static (geometry-only) bodies."""
    names = set()
    for body in plan.bodies():
        if not body.geometry_only:
            continue
        parts = getattr(body, "parts", None)     # a composite's geometries are its parts
        if parts:
            names.update(part.name for part in parts)
        else:
            names.add(body.name)
    return names
