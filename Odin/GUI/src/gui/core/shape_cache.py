"""Shapes read from geometry files, kept on disk between runs (``~/.cache/odin/shapes``).

Reading a Kautham model is mostly Coin3D parsing VRML and Python receiving its triangles one
callback at a time (the TX90 and its hand: 81,000 triangles, seconds), then merging their
vertices; the result is a few arrays. They are stored once per file *content* (SHA-256 of the
bytes, so an edited or replaced file is read again, wherever it lives) and per reading
(scale, ShapeDefaults, and the source of the reading code itself, so a change to the readers
never meets an entry they did not write): one ``.shape`` file per entry, a JSON header (the
primitives, the mesh's colour and its arrays' sizes) then the mesh's vertices (float64) and
triangles (uint32) as raw little-endian bytes. Loading one is a JSON parse and two array
views: an ``.npz`` of nine arrays took ~15 ms to open, mostly parsing each array's header
(the TX90 grasp problem's 16 entries: 0.2 s of every load). Nothing in an entry is run: a
planted file can only fail to load.

Safe against corrupt and concurrent entries: an entry is written to a temporary file in the
cache folder and renamed into place (atomic on one file system), so a reader sees a whole
entry or none. An entry is read as any input file is (``gui.core.sizes.read_input_file``:
a regular file, bounded) and verified field by field before it is used (``_decode``: sizes
that match the bytes, finite vertices within the world's reach, triangles naming vertices the
mesh has, primitives of a known kind with positive finite sizes and rigid poses, colours in
[0, 1]); one that fails any check is removed (one debug line) and the file is read again.
A cache folder that cannot be written only costs the speed.
Files that name other files (VRML ``Inline``, Inventor ``File`` nodes) are never cached: their
content alone does not say what they hold.

``ODIN_CACHE_DIR`` moves the folder (default ``$XDG_CACHE_HOME/odin``, else ``~/.cache/odin``);
``ODIN_NO_CACHE=1`` or :func:`set_enabled` (the tools' ``--no-cache``) bypasses it.
"""
from __future__ import annotations

import hashlib
import json
import logging
import os
import pathlib
import re
import struct
import tempfile
from typing import Callable, Optional

import numpy as np

from gui.core.geometry import Mesh, Primitive, Shape
from gui.core.kautham.units import lengths_problem
from odin_common.limits import shown

log = logging.getLogger(__name__)

FORMAT_VERSION = 2
"""Bumped when an entry's layout changes."""

ENTRY_SUFFIX = ".shape"
_MAGIC = b"odin shape cache entry\n"
_HEADER_SIZE = struct.Struct("<Q")         # bytes of the JSON header that follows

MAX_ENTRIES = 2000
"""Entries kept: past it the least recently used are removed when one is stored (the whole
Kautham corpus holds about 700 geometry files)."""

_REFERENCES = re.compile(rb"\b(Inline|File)\s*\{")
_REFERENCE_WORDS = (b"Inline", b"File")    # searched for first: the pattern alone scans a
                                           # megabyte of VRML in ~20 ms
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


def cached(content: bytes, source: str, reading: str, read: Callable[[], Shape]) -> Shape:
    """The shape of a geometry file's ``content`` (its bytes, as read once by
    ``gui.core.sizes.read_input_file``; ``source`` names the file) read as ``reading`` says (a
    text naming scale and defaults): from the cache when an entry for that content exists,
    else ``read()``, stored for next time. Errors of ``read`` (ShapeError) pass through and are
    not cached."""
    if not enabled() or _names_other_files(content):
        return read()
    digest = hashlib.sha256(content)
    digest.update(f"\0{reading}\0{FORMAT_VERSION}\0{_readers_version()}".encode())
    entry = cache_dir() / f"{digest.hexdigest()}{ENTRY_SUFFIX}"
    shape = _load(entry, source)
    if shape is None:
        shape = read()
        _store(entry, shape)
        _prune(entry.parent)
    return shape


def _names_other_files(content: bytes) -> bool:
    """Whether a VRML ``Inline`` or an Inventor ``File`` node is in the file's text."""
    return (any(word in content for word in _REFERENCE_WORDS)
            and _REFERENCES.search(content) is not None)


_READERS = ("shapes.py", "geometry.py", "shape_cache.py")
"""The modules (beside this one) that turn a file's bytes into a shape: read by their files,
not imported (``shapes`` imports this module)."""
_readers_digest: Optional[str] = None


def _readers_version() -> str:
    """SHA-256 of the source of the modules that turn a file into a shape (_READERS)."""
    global _readers_digest
    if _readers_digest is None:
        digest = hashlib.sha256()
        for name in _READERS:
            digest.update(pathlib.Path(__file__).with_name(name).read_bytes())
        _readers_digest = digest.hexdigest()
    return _readers_digest


def _load(entry: pathlib.Path, source: str):
    from gui.core.sizes import read_input_file
    from gui.errors import ProblemError
    if not os.path.lexists(entry):
        return None
    try:
        data = read_input_file(entry, "shape cache entry")
    except ProblemError as error:   # planted, or removed meanwhile: read the file again
        log.debug("shape cache: %s", error)
        _remove(entry)
        return None
    try:
        shape = _decode(data, source)
    except (ValueError, KeyError, TypeError, IndexError, AttributeError, OverflowError) \
            as error:    # corrupt, truncated, of another layout: read the file again
        log.debug("shape cache: dropping entry %s (%s)", entry, shown(str(error)))
        _remove(entry)
        return None
    try:
        os.utime(entry)             # used now: the last to go when the cache is pruned
    except OSError:
        pass
    return shape


def _refuse_constant(name: str):
    raise ValueError(f"{name} in the header")


def _decode(data: bytes, source: str):
    """The Shape an entry's bytes hold, every field verified (module docstring); raises
    ValueError (or a KeyError, TypeError...) for bytes that are not a whole, sound entry."""
    if not data.startswith(_MAGIC) or len(data) < len(_MAGIC) + _HEADER_SIZE.size:
        raise ValueError("not an entry of this format")
    at = len(_MAGIC) + _HEADER_SIZE.size
    (header_size,) = _HEADER_SIZE.unpack_from(data, len(_MAGIC))
    if at + header_size > len(data):
        raise ValueError(f"a header of {header_size} bytes in {len(data)}")
    header = json.loads(data[at:at + header_size].decode("utf-8"),
                        parse_constant=_refuse_constant)
    if not isinstance(header, dict) or not isinstance(header["primitives"], list):
        raise ValueError("the header is not a shape's")
    at += header_size
    mesh = None
    if header["mesh"] is not None:
        mesh = _decode_mesh(header["mesh"], data, at)
    elif len(data) != at:
        raise ValueError(f"{len(data) - at} bytes after the header of a shape without a mesh")
    primitives = tuple(_decode_primitive(p) for p in header["primitives"])
    if mesh is None and not primitives:
        raise ValueError("an empty shape")
    return Shape(source, mesh, primitives)


def _whole(value) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < 0:
        raise ValueError(f"{shown(value)} is not a count")
    return value


def _decode_mesh(header, data: bytes, at: int):
    sizes = header["sizes"]
    if not isinstance(sizes, list) or len(sizes) != 2:
        raise ValueError(f"mesh sizes {shown(sizes)}")
    n_vertices, n_triangles = (_whole(v) for v in sizes)
    if n_vertices < 3 or n_triangles < 1:
        raise ValueError(f"a mesh of {n_vertices} vertices and {n_triangles} triangles")
    vertex_bytes, triangle_bytes = 24 * n_vertices, 12 * n_triangles
    if len(data) != at + vertex_bytes + triangle_bytes:
        raise ValueError(f"{len(data)} bytes, expected {at + vertex_bytes + triangle_bytes}")
    vertices = np.frombuffer(data, "<f8", 3 * n_vertices, at).reshape(-1, 3)
    triangles = np.frombuffer(data, "<u4", 3 * n_triangles, at + vertex_bytes).reshape(-1, 3)
    problem = lengths_problem(vertices)
    if problem is not None:
        raise ValueError(f"a vertex {problem}")
    if int(triangles.max()) >= n_vertices:
        raise ValueError("a triangle names a vertex the mesh does not have")
    return Mesh(vertices.astype(np.float64), triangles.astype(np.uint32),
                _color(header["color"]))


_PARAMETER_COUNTS = {"sphere": 1, "cylinder": 2, "box": 3}


def _decode_primitive(p):
    kind = p["kind"]
    if kind not in _PARAMETER_COUNTS:
        raise ValueError(f"a primitive of kind {shown(kind)}")
    parameters = tuple(_finite(v) for v in p["parameters"])
    if len(parameters) != _PARAMETER_COUNTS[kind] or min(parameters) <= 0.0 \
            or lengths_problem(parameters) is not None:
        raise ValueError(f"{kind} parameters {shown(parameters)}")
    values = [_finite(v) for v in p["pose"]]
    if len(values) != 16:
        raise ValueError(f"a pose of {len(values)} values")
    pose = np.array(values, dtype=np.float64).reshape(4, 4)
    rotation = pose[:3, :3]
    if not (np.array_equal(pose[3], [0.0, 0.0, 0.0, 1.0])
            and np.allclose(rotation @ rotation.T, np.eye(3), atol=1e-6)
            and np.linalg.det(rotation) > 0.0 and lengths_problem(pose[:3, 3]) is None):
        raise ValueError("a primitive's pose is not a rigid pose within the world")
    return Primitive(kind, parameters, pose, _color(p["color"]))


def _finite(value) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) \
            or not np.isfinite(value):
        raise ValueError(f"{shown(value)} is not a finite number")
    return float(value)


def _color(values) -> tuple:
    color = tuple(_finite(v) for v in values)
    if len(color) != 4 or not all(0.0 <= c <= 1.0 for c in color):
        raise ValueError(f"colour {shown(color)}")
    return color


def _encode(shape) -> bytes:
    """An entry's bytes: magic, header size, JSON header, vertices, triangles."""
    mesh = shape.mesh
    payload = b""
    header = {"mesh": None, "primitives": [
        {"kind": p.kind, "parameters": [float(v) for v in p.parameters],
         "pose": [float(v) for v in np.asarray(p.pose, dtype=float).reshape(-1)],
         "color": [float(v) for v in p.color]} for p in shape.primitives]}
    if mesh is not None:
        vertices = np.ascontiguousarray(mesh.vertices, dtype="<f8").reshape(-1, 3)
        triangles = np.ascontiguousarray(mesh.triangles, dtype="<u4").reshape(-1, 3)
        header["mesh"] = {"sizes": [len(vertices), len(triangles)],
                          "color": [float(v) for v in mesh.color]}
        payload = vertices.tobytes() + triangles.tobytes()
    text = json.dumps(header).encode("utf-8")
    return _MAGIC + _HEADER_SIZE.pack(len(text)) + text + payload


def _store(entry: pathlib.Path, shape) -> None:
    data = _encode(shape)
    try:
        entry.parent.mkdir(parents=True, exist_ok=True)
        fd, temporary = tempfile.mkstemp(prefix=".writing-", suffix=ENTRY_SUFFIX,
                                         dir=entry.parent)
    except OSError as error:     # a read-only or full cache folder costs only the speed
        log.info("shape cache: not stored (%s)", error)
        return
    try:
        with os.fdopen(fd, "wb") as file:
            file.write(data)
        os.replace(temporary, entry)
    except OSError as error:
        log.info("shape cache: not stored (%s)", error)
        _remove(pathlib.Path(temporary))


def _prune(folder: pathlib.Path) -> None:
    """Removes the least recently used entries past MAX_ENTRIES (and writes left by a
    process that died mid-write, and entries of an earlier format: ``.npz``)."""
    try:
        entries = [(e.stat().st_mtime, e.path) for e in os.scandir(folder)
                   if e.name.endswith((ENTRY_SUFFIX, ".npz"))]
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
