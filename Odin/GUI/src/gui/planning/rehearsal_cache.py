"""What a rehearsal proved, kept by content: a plan the Core took once is taken again.

A rehearsal (``gui.planning.rehearsal``) builds a whole plan in a Core of the tool's process:
for the TX90 + hand about 0.5 s of a 1.2 s load (trimesh's import and its mesh masses, ODE's
collision data). Whether the Core takes a plan depends only on the plan's contents, the world
it starts as (parameters, step values, resource limits) and the Core's own code, so a taken
plan is remembered under a digest of all three (``gui.core.shape_cache``'s rule: what is slow
to compute and depends only on bytes is kept by content). Refusals are not kept: they are
found again, and quickly, on the step that fails.

An entry is an empty file ``<cache>/rehearsals/<plan digest>/<world digest>``: a folder per
plan says, before the world is asked anything, whether the plan is worth warming up for. The
plan digest covers every value of every step (arrays by dtype, shape and bytes, floats
exactly) and the source of the Core and of the modules that send a plan to it; a value of a
kind the digest does not know makes the plan not kept (rehearsed every time), never a wrong
match. ``--no-cache`` (``shape_cache.set_enabled(False)``) turns it off.
"""
from __future__ import annotations

import dataclasses
import enum
import hashlib
import os
import pathlib
from typing import Optional

import numpy as np

from gui.core import shape_cache

MAX_PLANS = 256
"""Plans kept; the least recently used go first."""

_code_digest: Optional[str] = None


class _Unknown(Exception):
    """A value the digest cannot encode exactly."""


def plan_digest(plan) -> Optional[str]:
    """SHA-256 of ``plan.steps`` and the Core's code, or None when the plan cannot be kept."""
    digest = hashlib.sha256(_code().encode())
    try:
        _feed(digest, plan.steps, set())
    except _Unknown:
        return None
    return digest.hexdigest()


def world_digest(parameters, step_values, resources) -> str:
    """SHA-256 of the world a rehearsal starts as (frozen dataclasses of numbers)."""
    digest = hashlib.sha256()
    _feed(digest, (parameters, step_values, resources), set())
    return digest.hexdigest()


def seen(plan_key: Optional[str]) -> bool:
    """Whether a plan of this digest was taken before, in any world."""
    return plan_key is not None and shape_cache.enabled() and (_folder() / plan_key).is_dir()


def taken(plan_key: Optional[str], world_key: str) -> bool:
    """Whether the plan was taken by a Core that started as this world."""
    if plan_key is None or not shape_cache.enabled():
        return False
    entry = _folder() / plan_key / world_key
    if not entry.is_file():
        return False
    try:
        os.utime(entry.parent)      # recently used: pruned last
    except OSError:
        pass
    return True


def remember(plan_key: Optional[str], world_key: str) -> None:
    """Keeps that the plan was taken; a cache that cannot be written is left as it is."""
    if plan_key is None or not shape_cache.enabled():
        return
    try:
        folder = _folder() / plan_key
        folder.mkdir(parents=True, exist_ok=True)
        (folder / world_key).touch()
        _prune(folder.parent)
    except OSError:
        pass


def _folder() -> pathlib.Path:
    return shape_cache.cache_dir().parent / "rehearsals"


def _prune(folder: pathlib.Path) -> None:
    plans = sorted((p.stat().st_mtime, p) for p in folder.iterdir() if p.is_dir())
    for _, plan in plans[:max(0, len(plans) - MAX_PLANS)]:
        for entry in plan.iterdir():
            entry.unlink()
        plan.rmdir()


def _code() -> str:
    """SHA-256 of the sources a rehearsal's outcome depends on: the VirtualWorld Core and its
    ODE layer, the shared limits, and the modules that send a plan to a Core."""
    global _code_digest
    if _code_digest is None:
        import odin_common
        import virtual_world
        digest = hashlib.sha256()
        world = pathlib.Path(virtual_world.__file__).parent
        files = sorted([*world.glob("core/*.py"), *world.glob("ode/*.[pch]*")])
        common = pathlib.Path(odin_common.__file__).parent
        files += sorted(common.glob("*.py"))
        # read by path, not imported: the rehearsal imports this module
        here = pathlib.Path(__file__).parent
        files += [here.parent / "core" / "plan.py", here / "core_world.py", here / "rehearsal.py",
                  pathlib.Path(__file__)]
        for path in files:
            digest.update(path.name.encode() + b"\0" + path.read_bytes())
        _code_digest = digest.hexdigest()
    return _code_digest


def _feed(digest, value, active: set) -> None:
    """Adds ``value`` to ``digest``, exactly and with its type; _Unknown for anything else."""
    if value is None or isinstance(value, (bool, int, str, enum.Enum)):
        digest.update(f"{type(value).__name__}:{value!r};".encode())
    elif isinstance(value, float):
        digest.update(f"f:{value.hex()};".encode())
    elif isinstance(value, (np.ndarray, np.generic)):
        array = np.ascontiguousarray(value)
        digest.update(f"a:{array.dtype.str}{array.shape};".encode())
        digest.update(array.tobytes())
    elif isinstance(value, (tuple, list, dict)) or dataclasses.is_dataclass(value):
        if id(value) in active:
            raise _Unknown("a cycle")
        active.add(id(value))
        _feed_container(digest, value, active)
        active.discard(id(value))
    else:
        raise _Unknown(type(value).__name__)


def _feed_container(digest, value, active: set) -> None:
    if isinstance(value, dict):
        items = sorted(value.items(), key=lambda item: repr(item[0]))
        digest.update(f"d{len(items)}(".encode())
        for key, item in items:
            _feed(digest, key, active)
            _feed(digest, item, active)
    elif isinstance(value, (tuple, list)):
        digest.update(f"{type(value).__name__}{len(value)}(".encode())
        for item in value:
            _feed(digest, item, active)
    else:
        digest.update(f"{type(value).__module__}.{type(value).__qualname__}(".encode())
        for f in dataclasses.fields(value):
            digest.update(f.name.encode() + b"=")
            _feed(digest, getattr(value, f.name), active)
    digest.update(b")")


__all__ = ["plan_digest", "world_digest", "seen", "taken", "remember", "MAX_PLANS"]
