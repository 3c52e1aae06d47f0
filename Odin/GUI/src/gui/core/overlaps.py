"""Parts a problem builds inside each other, found by the world's Check Collision right after
a build and reported to the user (the loaders warn; `make corpus` records them).

Kautham places robots and obstacles where the problem says, and a geometric problem never
simulates them: a 2012 robot without ``<Home>`` stands at the origin (``Problem::
setupFromFile``: "If robot hasn't a home, it will be assumed in the origin"), which may be
inside its scene. In a physical world the contacts of such a pair push the parts apart as soon
as the world runs: the robot would move off the pose it was built at. So after building a
problem Kautham never simulates, the loader asks the world to exempt such pairs (Exempt
Overlaps): they stand where the problem put them and collide once they have moved apart, never
further in. Under Kautham's physics (one of its ODE planners) Kautham's own ODE world pushes
them apart, and so does Odin's. Either way Odin builds what the problem says and says so, once,
naming the pairs.

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


def settle_overlaps(world, plan) -> Tuple[List[Overlap], bool]:
    """After ``plan`` was built in ``world`` (a gui.core.world_port.WorldPort):
    the pairs it built inside each other and whether they are exempt. In a problem Kautham
    never simulates the world is asked to exempt them (Exempt Overlaps) until they have moved
    apart; under Kautham's physics they are only found (Check Collision)."""
    exempt = not plan.problem.physics
    found = world.exempt_overlaps(BUILT_OVERLAP) if exempt else world.check_collision([])
    return built_overlaps(plan, found), exempt


def overlap_warning(source: str, overlaps: Sequence[Overlap], exempt: bool) -> str:
    """One line for the user: ``source`` (the problem file), the deepest pairs and what the
    world does with them (``exempt``: they do not collide until they have moved apart)."""
    named = ", ".join(f"{o.first} in {o.second} by {o.depth * 1000:.1f} mm"
                      for o in overlaps[:PAIRS_NAMED])
    more = len(overlaps) - PAIRS_NAMED
    rest = f" and {more} more pair{'s' if more > 1 else ''}" if more > 0 else ""
    return (f"{source}: built with parts inside each other, where the problem places them: "
            f"{named}{rest}; " + (EXEMPT if exempt else PUSHED))


def goal_overlaps(world, plan, built: Sequence[Overlap]) -> List[Overlap]:
    """The pairs the query's goal would put inside each other, deeper than BUILT_OVERLAP
    (where a part can move): every robot with a goal placed there at once by forward
    kinematics, asked of ``world`` (a gui.core.world_port.WorldPort) by Check Collision, which
    changes nothing; the pairs ``built`` so (``settle_overlaps``' answer) are not counted."""
    poses = _query_poses(plan, "goal")
    if not poses:
        return []
    known = {frozenset((o.first, o.second)) for o in built}
    return built_overlaps(plan, [pair for pair in world.check_collision(poses)
                                 if frozenset(pair[:2]) not in known])


def start_overlaps(world, plan) -> List[Overlap]:
    """The pairs inside each other where the robots start, deeper than BUILT_OVERLAP (where a
    part can move): every robot with a query's start placed there at once by forward
    kinematics, the others where they were built, asked of ``world`` (a
    gui.core.world_port.WorldPort) by Check Collision, which changes nothing and, unlike
    ``settle_overlaps``, leaves no pair exempt. A robot is built at its start unless the
    build says otherwise (gui.core.translate): these are then the pairs of ``plan``'s robots
    that ``settle_overlaps`` found, exempt or not."""
    return built_overlaps(plan, world.check_collision(_query_poses(plan, "start")))


def _query_poses(plan, at: str) -> list:
    """(body ID, position m, quaternion (w, x, y, z)), world frame, of every link of each of
    ``plan``'s robots with a query, at its ``at`` ("start" or "goal") configuration."""
    poses = []
    for handle in plan.robots:
        configuration = getattr(handle, at)
        if configuration is not None:
            poses.extend(handle.situations(configuration.joints, configuration.base_pose))
    return poses


def goal_warning(source: str, overlaps: Sequence[Overlap]) -> str:
    """One line for the user: ``source`` (the problem file) and the deepest pairs its goal
    puts inside each other."""
    return query_warning(source, overlaps, "goal")


def query_warning(source: str, overlaps: Sequence[Overlap], at: str) -> str:
    """One line for the user: ``source`` (the problem file) and the deepest pairs the query's
    ``at`` ("start" or "goal") puts inside each other."""
    named = ", ".join(f"{o.first} in {o.second} by {o.depth * 1000:.1f} mm"
                      for o in overlaps[:PAIRS_NAMED])
    more = len(overlaps) - PAIRS_NAMED
    rest = f" and {more} more pair{'s' if more > 1 else ''}" if more > 0 else ""
    path = "a path to it ends" if at == "goal" else "a path from it begins"
    return (f"{source}: the query's {at} puts parts inside each other: {named}{rest}; {path} "
            "in collision")


#: what the world does with the pairs of a problem Kautham never simulates
EXEMPT = "they do not collide until they have moved apart (Kautham never simulates this problem)"
#: ... and under Kautham's physics
PUSHED = "their contacts push them apart when the world runs, as in Kautham's ODE world"


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
