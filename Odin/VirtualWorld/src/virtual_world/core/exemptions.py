"""Pairs built inside each other that do not collide until they have parted (Exempt Overlaps).

A Kautham problem places robots and obstacles where it says, and a geometric problem never
simulates them: a 2012 robot without ``<Home>`` stands at the origin, which may be inside its
scene. In ODE the contacts of such a pair push the parts apart the first step: a fixed-base arm
is bent off the pose its problem gave it. Asked after a build, the world exempts every pair
found inside each other deeper than ``min_depth`` (m) where a part has a body: such a pair
makes no contacts (it is still reported as colliding) until the first step whose collide pass
finds it no deeper than ``min_depth``, or apart; then it has parted, for good, and collides as
any pair from the next step on. So the arm stands where the problem built it and meets the
column once it has moved out of it. An exempt pair may move apart, never further in: found
deeper than it was built by more than ``min_depth``, it parts at once and collides in that
very step (a body built sunk into its support and falling further is stopped as ODE stops
it). odin_step.c: collide_exempt, part_exempt_pairs.

Which pairs are still exempt is dynamic state: snapshots hold it and body state vectors end
with it (one value per exempt pair, 1.0 exempt or 0.0 parted), so stepping on from a snapshot or
propagating from a vector is bit-identical. The list of pairs is contents: asking again
replaces it, a snapshot taken under another list is refused, and removing an object drops its
pairs.
"""
from __future__ import annotations

from typing import List, NamedTuple, Set

import numpy as np

from virtual_world.core import readout
from virtual_world.core.records import Collision
from virtual_world.core.scene import Scene


class ExemptPair(NamedTuple):
    """Two geometries built inside each other (names in order) and the depth (m) they may
    reach while exempt."""
    first: str
    second: str
    limit: float


def exempt(scene: Scene, min_depth: float) -> List[Collision]:
    """Exempts the pairs inside each other now deeper than ``min_depth`` m where a part has a
    body (replacing the exemptions before); returns them, in name order."""
    found = [c for c in readout.touching_now(scene)
             if c.depth > min_depth and _movable(scene, c)]
    pairs = [ExemptPair(c.first, c.second, c.depth + min_depth) for c in found]
    scene.exempt_depth = min_depth
    _install(scene, pairs, np.ones(len(pairs)))
    return found


def live(scene: Scene) -> np.ndarray:
    """Each exempt pair's state (1.0 exempt, 0.0 parted), in ``scene.exempt_pairs``' order."""
    return scene.c.exempt_live


def put_live(scene: Scene, values: np.ndarray) -> None:
    """Puts back states ``live`` read (the same pairs)."""
    scene.c.exempt_live = values


def drop_geometries(scene: Scene, names: Set[str]) -> None:
    """Forgets the exempt pairs of geometries about to be removed, the others keeping their
    state."""
    kept = [i for i, pair in enumerate(scene.exempt_pairs)
            if pair.first not in names and pair.second not in names]
    if len(kept) < len(scene.exempt_pairs):
        _install(scene, [scene.exempt_pairs[i] for i in kept], live(scene)[kept])


def _install(scene: Scene, pairs: List[ExemptPair], states: np.ndarray) -> None:
    """The exempt pairs and their states, in the C world's order (by key)."""
    order = sorted(range(len(pairs)), key=lambda i: _key(scene, pairs[i]))
    scene.exempt_pairs = tuple(pairs[i] for i in order)
    scene.c.set_exemptions([_key(scene, p) for p in scene.exempt_pairs],
                           [p.limit for p in scene.exempt_pairs], states[order],
                           scene.exempt_depth)


def _movable(scene: Scene, collision: Collision) -> bool:
    """Whether a part of the pair has a body (two static parts never push each other)."""
    return any(scene.objects[scene.geometries[name].object_id].body is not None
               for name in (collision.first, collision.second))


def _key(scene: Scene, pair: ExemptPair) -> int:
    """The pair's key as odin_step.c orders pairs: the lower serial << 32 | the higher."""
    low, high = sorted(int(scene.geometries[name].owner.data.serial)
                       for name in (pair.first, pair.second))
    return low << 32 | high
