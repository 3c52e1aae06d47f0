"""Shapes read from geometry files, kept on disk between runs (``~/.cache/odin/shapes``).

Reading a Kautham model is mostly Coin3D parsing VRML and Python receiving its triangles one
callback at a time (the TX90 and its hand: 81,000 triangles, seconds), then merging their
vertices; the result is a few arrays. They are stored once per file *content* (SHA-256 of the
bytes, so an edited or replaced file is read again, wherever it lives) and per reading
(scale, ShapeDefaults, and the source of the reading code itself, so a change to the readers
never meets an entry they did not write): one ``.npz`` file per entry, holding only arrays
(loaded with ``allow_pickle=False``: a planted cache file cannot run code).

Safe against corrupt and concurrent entries: an entry is written to a temporary file in the
cache folder and renamed into place (atomic on one file system), so a reader sees a whole
entry or none; an entry that does not load or does not hold what a shape needs is removed and
the file is read again. A cache folder that cannot be written only costs the speed.
Files that name other files (VRML ``Inline``, Inventor ``File`` nodes) are never cached: their
content alone does not say what they hold.

``ODIN_CACHE_DIR`` moves the folder (default ``$XDG_CACHE_HOME/odin``, else ``~/.cache/odin``);
``ODIN_NO_CACHE=1`` or :func:`set_enabled` (the tools' ``--no-cache``) bypasses it.
"""
from __future__ import annotations

import hashlib
import logging
import os
import pathlib
import re
import tempfile
from typing import Callable, Optional

import numpy as np

log = logging.getLogger(__name__)

FORMAT_VERSION = 1
"""Bumped when an entry's layout changes."""

MAX_ENTRIES = 2000
"""Entries kept: past it the least recently used are removed when one is stored (the whole
Kautham corpus holds about 700 geometry files)."""

_REFERENCES = re.compile(rb"\b(Inline|File)\s*\{")
_enabled: Optional[bool] = None        # None: from the environment


def set_enabled(enabled: bool) -> None:
    """Turns the disk cache on or off for this process (``--no-cache``)."""
    global _enabled
    _enabled = bool(enabled)


def enabled() -> bool:
    if _enabled is not None:
        return _enabled
    return os.environ.get("ODIN_NO_CACHE", "") in ("", "0")


def cache_dir() -> pathlib.Path:
    """The folder of cached shapes."""
    root = os.environ.get("ODIN_CACHE_DIR")
    if not root:
        base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"),
                                                                ".cache")
        root = os.path.join(base, "odin")
    return pathlib.Path(root) / "shapes"


def cached(path: pathlib.Path, reading: str, read: Callable[[], "Shape"]) -> "Shape":
    """The shape of ``path`` read as ``reading`` says (a text naming scale and defaults):
    from the cache when an entry for its content exists, else ``read()``, stored for next time.
    Errors of ``read`` (ShapeError) pass through and are not cached."""
    if not enabled():
        return read()
    try:
        content = path.read_bytes()
    except OSError:
        return read()                       # the reader says what is wrong with the file
    if _REFERENCES.search(content):
        return read()
    digest = hashlib.sha256(content)
    digest.update(f"\0{reading}\0{FORMAT_VERSION}\0{_readers_version()}".encode())
    entry = cache_dir() / f"{digest.hexdigest()}.npz"
    shape = _load(entry, str(path))
    if shape is None:
        shape = read()
        _store(entry, shape)
        _prune(entry.parent)
    return shape


_readers_digest: Optional[str] = None


def _readers_version() -> str:
    """SHA-256 of the source of the modules that turn a file into a shape."""
    global _readers_digest
    if _readers_digest is None:
        from gui.core import shapes
        digest = hashlib.sha256()
        for source in (shapes.__file__, __file__):
            digest.update(pathlib.Path(source).read_bytes())
        _readers_digest = digest.hexdigest()
    return _readers_digest


def _load(entry: pathlib.Path, source: str):
    from gui.core.shapes import Mesh, Primitive, Shape
    try:
        with np.load(entry, allow_pickle=False) as data:
            mesh = None
            if data["has_mesh"]:
                mesh = Mesh(np.array(data["vertices"], dtype=np.float64),
                            np.array(data["triangles"], dtype=np.uint32),
                            _color(data["mesh_color"]))
            primitives = tuple(
                Primitive(str(kind), tuple(float(v) for v in dims[:int(count)]),
                          np.array(pose, dtype=np.float64), _color(color))
                for kind, dims, count, pose, color in zip(
                    data["kinds"], data["dims"], data["dim_counts"], data["poses"],
                    data["colors"]))
    except FileNotFoundError:
        return None
    except Exception as error:   # corrupt, truncated, of another layout: read the file again
        log.warning("shape cache: dropping unreadable entry %s (%s)", entry, error)
        _remove(entry)
        return None
    try:
        os.utime(entry)             # used now: the last to go when the cache is pruned
    except OSError:
        pass
    return Shape(source, mesh, primitives)


def _color(values) -> tuple:
    return tuple(float(v) for v in values)


def _store(entry: pathlib.Path, shape) -> None:
    mesh, primitives = shape.mesh, shape.primitives
    arrays = dict(
        has_mesh=np.array(mesh is not None),
        vertices=mesh.vertices if mesh is not None else np.zeros((0, 3)),
        triangles=mesh.triangles if mesh is not None else np.zeros((0, 3), np.uint32),
        mesh_color=np.array(mesh.color if mesh is not None else (0, 0, 0, 0), dtype=float),
        kinds=np.array([p.kind for p in primitives], dtype="U16"),
        dims=np.array([list(p.parameters) + [0.0] * (3 - len(p.parameters))
                       for p in primitives], dtype=float).reshape(-1, 3),
        dim_counts=np.array([len(p.parameters) for p in primitives], dtype=np.int64),
        poses=np.array([p.pose for p in primitives], dtype=float).reshape(-1, 4, 4),
        colors=np.array([p.color for p in primitives], dtype=float).reshape(-1, 4))
    try:
        entry.parent.mkdir(parents=True, exist_ok=True)
        fd, temporary = tempfile.mkstemp(prefix=".writing-", suffix=".npz", dir=entry.parent)
    except OSError as error:     # a read-only or full cache folder costs only the speed
        log.info("shape cache: not stored (%s)", error)
        return
    try:
        with os.fdopen(fd, "wb") as file:
            np.savez(file, **arrays)
        os.replace(temporary, entry)
    except OSError as error:
        log.info("shape cache: not stored (%s)", error)
        _remove(pathlib.Path(temporary))


def _prune(folder: pathlib.Path) -> None:
    """Removes the least recently used entries past MAX_ENTRIES (and writes left by a
    process that died mid-write)."""
    try:
        entries = [(e.stat().st_mtime, e.path) for e in os.scandir(folder)
                   if e.name.endswith(".npz")]
    except OSError:
        return
    if len(entries) <= MAX_ENTRIES:
        return
    for _, path in sorted(entries)[:len(entries) - MAX_ENTRIES]:
        _remove(pathlib.Path(path))


def _remove(path: pathlib.Path) -> None:
    try:
        path.unlink()
    except OSError:
        pass
