"""Geometry files -> Odin shapes: triangle meshes and primitives, in metres.

Readers:
- VRML 1.0 / 2.0 and Inventor 2.x (every dialect in Kautham's corpus, including "VRML 1.0"
  headers over Coin's VRML node names and .wrl files that are Inventor) through Coin3D (pivy):
  ``SoDB.readAll`` then a ``SoCallbackAction`` whose triangle callback receives each shape's
  triangles in that shape's *object* space (contrary to what one might expect); the shape's
  model matrix, taken in a pre-callback, is applied afterwards with numpy, one shape at a time.
  Spheres, cylinders and cubes are *not* triangulated: Coin tessellates them as open
  meshes, so they stay ODE primitives (a pre-callback records them with their model matrix and
  prunes them).
- STL, OBJ, PLY, OFF, GLB... through trimesh (imported only when such a file is read); Collada
  (.dae) through trimesh and pycollada, as Kautham reads it (``_read_trimesh``).

Mapping a file to Odin (``Shape``):
- Triangles of every non-primitive node, in the file's frame, become one ``Mesh``; duplicate
  vertices are merged within ``ShapeDefaults.merge_tolerance`` (vectorised: vertices are
  snapped to a grid of that pitch and made unique with numpy, O(n log n) instead of the thesis's
  quadratic loop) and triangles that collapse are dropped.
- Each primitive becomes a ``Primitive`` with Odin's parameters (sphere: radius; cylinder:
  radius, length along z -- Inventor's cylinders are along y, so the part's frame is rotated by
  -90 degrees about x; box: x, y, z sides) and its pose in the file's frame.
- ``gui.core.bodies`` turns a shape made only of a mesh into a mesh object, one made of a single
  primitive into a primitive object whose body sits at the primitive's pose, and anything mixed
  into a composite (one body, one part per primitive plus one for the mesh).
- Colour: the diffuse colour (and 1 - transparency as alpha) of the first shape node; a mesh
  takes the colour of the node that gave it the most triangles.
"""
from __future__ import annotations

import contextlib
import io
import os
import pathlib
import re
import tempfile
import warnings
from dataclasses import dataclass

import numpy as np

from gui.core import shape_cache
from gui.core.geometry import DEFAULT_COLOR, Mesh, Primitive, Shape, check_lengths
from gui.errors import ShapeError
from gui.core.kautham.units import scale_problem
from gui.core.kinematics import rot_x
from gui.core.sizes import check_input_path, read_input_file
from odin_common.limits import MAX_MESH_TRIANGLES

COIN_SUFFIXES = (".wrl", ".iv", ".vrml")
TRIMESH_SUFFIXES = (".stl", ".obj", ".ply", ".off", ".glb", ".gltf", ".dae")


@dataclass(frozen=True)
class ShapeDefaults:
    """Tunables of shape reading."""
    merge_tolerance: float = 1e-6   # m: vertices closer than about this are merged
    default_color: tuple = DEFAULT_COLOR
    # a file holding more is refused: the world refuses such a mesh anyway, and a VRML file's
    # DEF/USE instancing can make a few lines expand into billions of triangles
    max_triangles: int = MAX_MESH_TRIANGLES
    # VRML/Inventor shape nodes (each costs Python work, ~0.3 ms): real models hold a handful
    # (the public Kautham corpus at most 6), an instancing bomb billions
    max_shape_nodes: int = 10_000


DEFAULTS = ShapeDefaults()


def merge_vertices(corners: np.ndarray, tolerance: float = DEFAULTS.merge_tolerance
                   ) -> tuple[np.ndarray, np.ndarray]:
    """Merges duplicate vertices of a triangle soup.

    corners: (M, 3, 3) or (3M, 3) float, the three corners of each triangle.
    Returns (vertices (N, 3), triangles (K, 3) uint32), K <= M: triangles whose corners merged
    into fewer than three vertices are dropped. Vertices are snapped to a grid of pitch
    ``tolerance`` (so points closer than half of it always merge, points farther than it never
    do); each merged vertex is the mean of the points that merged into it.
    """
    pts = np.asarray(corners, dtype=np.float64).reshape(-1, 3)
    if len(pts) == 0:
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.uint32)
    if len(pts) % 3:
        raise ValueError("corners must come three per triangle")
    keys = np.round(pts / tolerance).astype(np.int64)
    keys = np.ascontiguousarray(keys)
    view = keys.view(np.dtype((np.void, keys.dtype.itemsize * 3))).ravel()
    _, first, inverse = np.unique(view, return_index=True, return_inverse=True)
    counts = np.bincount(inverse)
    vertices = np.zeros((len(first), 3))
    for axis in range(3):
        vertices[:, axis] = np.bincount(inverse, weights=pts[:, axis]) / counts
    tri = inverse.reshape(-1, 3)
    keep = (tri[:, 0] != tri[:, 1]) & (tri[:, 1] != tri[:, 2]) & (tri[:, 0] != tri[:, 2])
    tri = tri[keep]
    # Renumber so that only used vertices remain.
    used = np.unique(tri)
    if len(used) != len(vertices):
        remap = np.full(len(vertices), -1, dtype=np.int64)
        remap[used] = np.arange(len(used))
        vertices = vertices[used]
        tri = remap[tri]
    return vertices, tri.astype(np.uint32)


# -- reading ----------------------------------------------------------------------------------

_CACHE: dict = {}


def read_shape(path: os.PathLike | str, scale: float = 1.0,
               defaults: ShapeDefaults = DEFAULTS) -> Shape:
    """Reads a geometry file and returns its ``Shape`` with coordinates multiplied by
    ``scale`` (the file unit in metres times the problem's scale: 0.001 for a millimetre file
    at scale 1). Reading is cached in this process by (file, scale): the SAH hand uses each
    finger file four times; and on disk by the file's content (gui.core.shape_cache). The file
    is read once, by ``gui.core.sizes.read_input_file`` (a regular file of bounded size), and
    every reader parses those bytes: none opens the path itself."""
    p = pathlib.Path(path)
    key = (os.path.realpath(p), float(scale), defaults)
    shape = _CACHE.get(key)
    if shape is None:
        check_scale(scale, p)
        data = read_input_file(p, "geometry file", ShapeError)
        shape = shape_cache.cached(data, str(p), f"scale={float(scale)!r} {defaults!r}",
                                   lambda: _finish(_read_raw(p, data, defaults), scale,
                                                   defaults, str(p)))
        _CACHE[key] = shape
    return shape


@dataclass
class _Raw:
    corners: np.ndarray                  # (M, 3, 3) file units
    tri_colors: list                     # [(count, color)]
    primitives: list                     # [(kind, dims (file units), pose 4x4 file units, color)]
    shape_nodes: int = 0                 # VRML/Inventor shape nodes traversed


def check_scale(scale: float, source) -> None:
    """A ShapeError naming ``source`` unless ``scale`` is a valid scale factor
    (gui.core.kautham.units.scale_problem)."""
    problem = scale_problem(float(scale))
    if problem is not None:
        raise ShapeError(f"scale {float(scale)!r} {problem}", source)


def _finish(raw: _Raw, scale: float, defaults: ShapeDefaults, source: str) -> Shape:
    """The Shape of a file's raw triangles and primitives at ``scale`` (m per file unit),
    every scaled length checked (check_lengths)."""
    check_lengths(raw.corners, "a vertex", source, scale)
    for _kind, dims, pose, _color in raw.primitives:
        check_lengths(dims, "a sphere, cylinder or cube's size", source, scale)
        check_lengths(pose[:3, 3], "a sphere, cylinder or cube's position", source, scale)
    mesh = None
    if len(raw.corners):
        vertices, triangles = merge_vertices(raw.corners * scale, defaults.merge_tolerance)
        if len(triangles):
            color = max(raw.tri_colors, key=lambda c: c[0])[1] if raw.tri_colors else \
                defaults.default_color
            mesh = Mesh(vertices, triangles, color)
    prims = []
    for kind, dims, pose, color in raw.primitives:
        T = pose.copy()
        T[:3, 3] *= scale
        prims.append(Primitive(kind, tuple(float(d) * scale for d in dims), T, color))
    shape = Shape(source, mesh, tuple(prims))
    if shape.is_empty:
        raise ShapeError("holds no geometry (no triangles and no sphere, cylinder or cube)",
                         source)
    return shape


def _read_raw(p: pathlib.Path, data: bytes, defaults: ShapeDefaults) -> _Raw:
    """The triangles and primitives of a geometry file's bytes ``data`` (``p`` names it and
    its suffix says its format)."""
    suffix = p.suffix.lower()
    max_triangles = defaults.max_triangles
    if suffix == ".stl":
        _check_stl_count(p, data, max_triangles)
    elif suffix in _ANNOUNCED_COUNTS:
        _check_announced_counts(p, _ANNOUNCED_COUNTS[suffix](data), max_triangles)
    if suffix in TRIMESH_SUFFIXES:
        raw = _read_trimesh(p, data)
    else:
        raw = _read_coin(p, data, defaults)
    if raw.shape_nodes > defaults.max_shape_nodes:
        raise ShapeError(f"holds more than {defaults.max_shape_nodes:,} shape nodes (a "
                         f"model holds a handful; instancing can make billions)", p)
    if len(raw.corners) > max_triangles or len(raw.primitives) > max_triangles:
        raise ShapeError(f"holds more than {max_triangles:,} triangles or primitives (the "
                         f"limit of one mesh)", p)
    return raw


def _check_stl_count(p: pathlib.Path, data: bytes, max_triangles: int) -> None:
    """A binary STL says its triangle count in bytes 80-84 and holds 50 bytes per triangle:
    a count over the limit is refused before the file is parsed (an ASCII STL, or a file whose
    size does not match its count, is bounded by the file size limit)."""
    if len(data) < 84:
        return
    count = int.from_bytes(data[80:84], "little")
    if count > max_triangles and len(data) == 84 + 50 * count:
        raise ShapeError(f"holds {count:,} triangles, more than the {max_triangles:,} of one "
                         f"mesh", p)


def _obj_counts(data: bytes) -> tuple:
    """(vertices, faces) an OBJ file's ``v`` and ``f`` lines say (a face is one triangle or
    more)."""
    def lines(word: bytes) -> int:
        return sum(data.count(b"\n" + word + gap) + data.startswith(word + gap)
                   for gap in (b" ", b"\t"))
    return lines(b"v"), lines(b"f")


def _ply_counts(data: bytes) -> tuple:
    """(vertices, faces) a PLY header's ``element vertex N`` and ``element face N`` say."""
    header = data[:data.find(b"end_header")] if b"end_header" in data[:65536] else b""
    counts = dict(re.findall(rb"element\s+(vertex|face)\s+(\d+)", header))
    return int(counts.get(b"vertex", 0)), int(counts.get(b"face", 0))


def _off_counts(data: bytes) -> tuple:
    """(vertices, faces) an OFF file's first line of counts says."""
    for line in data[:65536].splitlines()[:50]:
        words = line.split(b"#")[0].split()
        if words and words[0].upper().endswith(b"OFF"):
            words = words[1:]
        if len(words) >= 2 and all(w.isdigit() for w in words[:2]):
            return int(words[0]), int(words[1])
    return 0, 0


_ANNOUNCED_COUNTS = {".obj": _obj_counts, ".ply": _ply_counts, ".off": _off_counts}
"""Counts a text mesh format announces or lists, read before trimesh parses it: trimesh
needs ~20 bytes of memory per byte of OBJ (a 20 MB file of faces took 500 MB), so a file
within the size limit could exhaust memory before the triangle limit is checked."""


def _check_announced_counts(p: pathlib.Path, counts: tuple, max_triangles: int) -> None:
    """Refuses a mesh whose faces (each one triangle or more) are over ``max_triangles``, or
    whose vertices are more than its triangles could use (three each)."""
    vertices, faces = counts
    if faces > max_triangles or vertices > 3 * max_triangles:
        raise ShapeError(f"holds {faces:,} faces and {vertices:,} vertices, more than the "
                         f"{max_triangles:,} triangles of one mesh can have", p)


def _collada_surfaces(p: pathlib.Path, data: bytes) -> io.BytesIO:
    """A Collada file without its ``<lines>`` and ``<linestrips>``: they hold no surface
    (nothing collides with a line, and Kautham draws only faces), and pycollada refuses some
    that assimp, Kautham's reader, reads (an ``<input>`` without ``offset``, in the IOC lab's
    steel cupboard). The XML is read without entities or network access, and only once
    within the bounds every XML file the GUI reads has (``xmlfile.check_xml_bounds``: lxml
    would build a tree of any size)."""
    from gui.core.kautham.xmlfile import check_xml_bounds
    from lxml import etree
    check_xml_bounds(data, str(p), ShapeError)
    parser = etree.XMLParser(resolve_entities=False, no_network=True, load_dtd=False)
    root = etree.fromstring(data, parser)
    for element in list(root.iter("{*}lines", "{*}linestrips", "lines", "linestrips")):
        element.getparent().remove(element)
    return io.BytesIO(etree.tostring(root))


def _bounded_resolver(p: pathlib.Path):
    """trimesh's resolver of the files a mesh names (an OBJ's materials, a glTF's buffers),
    in the mesh's folder as trimesh's own, each read by ``read_input_file``."""
    import trimesh.resolvers

    class Bounded(trimesh.resolvers.FilePathResolver):
        def get(self, name: str) -> bytes:
            for candidate in (name.strip(), name.strip().lstrip("/"), os.path.split(name)[-1]):
                try:
                    path = self.absolute(candidate)
                except ValueError:
                    continue
                if os.path.lexists(path):
                    return read_input_file(path, f"file named by {p.name}", ShapeError)
            self.absolute(name)          # a name outside the folder: trimesh's own error
            raise FileNotFoundError(name)

        def namespaced(self, namespace: str):
            return Bounded(os.path.join(self.parent, namespace))

    return Bounded(str(p))


def _read_trimesh(p: pathlib.Path, data: bytes) -> _Raw:
    """Triangles and the main colour of a mesh file's bytes read by trimesh (Collada through
    pycollada). A Collada file's ``<unit>`` and ``<up_axis>`` are not applied, as in Kautham:
    assimp puts them in the scene's root transform, which Kautham's import
    (``Assimp2Inventor``, src/problem/assimpImport.cpp) skips; URDFs scale such meshes
    themselves (``<mesh scale="0.0254 0.0254 0.0254">`` for an inch file)."""
    import trimesh  # slow to import: only when such a file is read
    try:
        with warnings.catch_warnings():     # numpy's overflow warnings on absurd
            warnings.simplefilter("ignore", RuntimeWarning)  # coordinates: checked after
            if p.suffix.lower() == ".dae":
                loaded = trimesh.load(_collada_surfaces(p, data), file_type="dae",
                                      force="mesh", process=False)
            else:
                loaded = trimesh.load(io.BytesIO(data), file_type=p.suffix.lower()[1:],
                                      force="mesh", process=False,
                                      resolver=_bounded_resolver(p))
    except ShapeError:       # a file it names (an OBJ's material), refused by what it is
        raise
    except Exception as error:  # trimesh raises many kinds; all mean "does not parse"
        raise ShapeError(f"does not parse as a mesh: {error}", p) from None
    corners = np.asarray(loaded.triangles, dtype=np.float64) if len(loaded.faces) else \
        np.zeros((0, 3, 3))
    color = DEFAULTS.default_color
    try:
        rgba = np.asarray(loaded.visual.main_color, dtype=float) / 255.0
        color = tuple(float(c) for c in rgba)
    except Exception:  # no colour information: keep the default
        pass
    return _Raw(corners, [(len(corners), color)], [])


_coin = None


def _coin_module():
    global _coin
    if _coin is None:
        from pivy import coin
        coin.SoDB.init()
        _coin = coin
    return _coin


@contextlib.contextmanager
def _captured_stderr():
    """Coin prints read errors on the C stderr; capture them to name the line."""
    captured = {"text": ""}
    with tempfile.TemporaryFile() as tmp:
        try:
            saved = os.dup(2)
        except OSError:
            yield captured
            return
        os.dup2(tmp.fileno(), 2)
        try:
            yield captured
        finally:
            os.dup2(saved, 2)
            os.close(saved)
            tmp.seek(0)
            captured["text"] = tmp.read().decode(errors="replace")


_NAMED_FILES = re.compile(rb'\b(?:url|name|filename)\s*\[?\s*((?:"[^"]*"\s*,?\s*)+)')
_QUOTED = re.compile(rb'"([^"]*)"')


def _check_named_files(p: pathlib.Path, data: bytes) -> None:
    """Every file a VRML or Inventor file names (``Inline``/``WWWInline`` url, ``File``
    name, texture filename or url) that Coin would open itself, where Coin looks for it (the
    file's folder, the current folder, or the path as written): it must be a regular file
    within the size limit (``gui.core.sizes.check_input_path``), so that a name leading to a
    FIFO or ``/dev/zero`` is refused instead of read for ever. Coin opens these by path, after
    this check: what this cannot see is a file swapped in between."""
    if b'"' not in data:
        return
    for match in _NAMED_FILES.finditer(data):
        for quoted in _QUOTED.findall(match.group(1)):
            name = os.fsdecode(quoted).strip()
            if name.startswith("file://"):
                name = name[len("file://"):]
            if not name or "://" in name:
                continue
            for candidate in (p.parent / name, pathlib.Path(name)):
                if os.path.lexists(candidate):
                    check_input_path(candidate, f"file named by {p.name}", ShapeError)


def _read_coin(p: pathlib.Path, data: bytes, defaults: ShapeDefaults) -> _Raw:
    """The triangles and primitives of VRML or Inventor bytes, parsed by Coin from memory
    (``SoInput.setBuffer``); the file's folder is searched first for the files its ``Inline``
    and ``File`` nodes name, as when Coin opens the file itself, each checked first
    (``_check_named_files``)."""
    _check_named_files(p, data)
    coin = _coin_module()
    inp = coin.SoInput()
    inp.addDirectoryFirst(str(p.parent))
    with _captured_stderr() as err:
        inp.setBuffer(data)                  # ``data`` outlives the read: Coin does not copy
        root = coin.SoDB.readAll(inp)
    if root is None:
        text = err["text"]
        match = re.search(r"line\s+(\d+)", text)
        first = text.strip().splitlines()[0] if text.strip() else "unknown error"
        first = first.replace("Coin read error: ", "")
        raise ShapeError(f"does not parse as VRML/Inventor: {first}", p,
                         int(match.group(1)) if match else None)
    root.ref()
    try:
        _check_coin_counts(coin, root, p, defaults)
        return _collect(coin, root, defaults.max_triangles, defaults.max_shape_nodes)
    finally:
        root.unref()


def _check_coin_counts(coin, root, p: pathlib.Path, defaults: ShapeDefaults) -> None:
    """Refuses a scene of more shape nodes than ``defaults.max_shape_nodes`` (counted by a
    traversal that prunes every shape, stopping past the limit: an instancing bomb's
    billions are never walked) or more triangles than ``defaults.max_triangles`` (Coin's
    SoGetPrimitiveCountAction, in C++: milliseconds), before ``_collect`` receives triangles
    one Python callback each (~0.1 ms: 2 million took minutes)."""
    nodes = [0]

    def on_shape(_data, _action, _node):
        nodes[0] += 1
        if nodes[0] > defaults.max_shape_nodes:
            return coin.SoCallbackAction.ABORT
        return coin.SoCallbackAction.PRUNE

    walk = coin.SoCallbackAction()
    walk.addPreCallback(coin.SoShape.getClassTypeId(), on_shape, None)
    walk.apply(root)
    if nodes[0] > defaults.max_shape_nodes:
        raise ShapeError(f"holds more than {defaults.max_shape_nodes:,} shape nodes (a "
                         f"model holds a handful; instancing can make billions)", p)
    count = coin.SoGetPrimitiveCountAction()
    count.apply(root)
    triangles = int(count.getTriangleCount())
    if triangles > defaults.max_triangles:
        raise ShapeError(f"holds more than {defaults.max_triangles:,} triangles ({triangles:,}; "
                         "the limit of one mesh)", p)


_PRIMITIVE_TYPES = ("SoSphere", "SoCylinder", "SoCube")


def _collect(coin, root, max_triangles: int, max_shape_nodes: int) -> _Raw:
    """The triangles (file units, world frame of the file) and primitives of Coin's scene graph.
    Past ``max_triangles`` (or as many primitives) or ``max_shape_nodes`` collection stops: the
    traversal is aborted at the next shape and the result holds more than the limit, for the
    caller to refuse."""
    tris: list = []
    tri_colors: list = []
    prims: list = []
    current = {"color": DEFAULTS.default_color, "start": 0, "pose": np.eye(4), "shape_nodes": 0}

    def over_limit():
        return (len(tris) > max_triangles or len(prims) > max_triangles
                or current["shape_nodes"] > max_shape_nodes)

    def shape_node():
        current["shape_nodes"] += 1
        return over_limit()

    def on_primitive(_data, action, node):
        if shape_node():
            return coin.SoCallbackAction.ABORT
        prims.append(_coin_primitive(node, _model_pose(action), _coin_color(coin, action)))
        return coin.SoCallbackAction.PRUNE

    runs: list = []   # (first triangle, end, model pose (4, 4), colour) per shape node

    def on_shape(_data, action, node):
        if shape_node():
            return coin.SoCallbackAction.ABORT
        _close_run()
        current["color"] = _coin_color(coin, action)
        current["pose"] = _model_pose(action)
        current["start"] = len(tris)
        return coin.SoCallbackAction.CONTINUE

    def _close_run():
        n = len(tris) - current["start"]
        if n:
            runs.append((current["start"], len(tris), current["pose"], current["color"]))
            tri_colors.append((n, current["color"]))
        current["start"] = len(tris)

    def on_triangle(_data, _action, v1, v2, v3):
        if over_limit():         # Coin finishes this shape's triangles; keep none of them
            return
        # SoCallbackAction gives the corners in the shape's object space.
        tris.append((v1.getPoint().getValue(), v2.getPoint().getValue(),
                     v3.getPoint().getValue()))

    action = coin.SoCallbackAction()
    for type_name in _PRIMITIVE_TYPES:
        action.addPreCallback(getattr(coin, type_name).getClassTypeId(), on_primitive, None)
    action.addPreCallback(coin.SoShape.getClassTypeId(), on_shape, None)
    action.addTriangleCallback(coin.SoShape.getClassTypeId(), on_triangle, None)
    action.apply(root)
    _close_run()
    return _Raw(_placed(tris, runs), tri_colors, prims, current["shape_nodes"])


def _coin_color(coin, action) -> tuple:
    """(r, g, b, a) of the shape ``action`` is at: its diffuse colour, 1 - transparency."""
    state = action.getState()
    d = coin.SoLazyElement.getDiffuse(state, 0).getValue()
    t = coin.SoLazyElement.getTransparency(state, 0)
    return (float(d[0]), float(d[1]), float(d[2]), float(1.0 - t))


def _model_pose(action) -> np.ndarray:
    """(4, 4) the model matrix where ``action`` is, acting on column vectors (file units)."""
    m = action.getModelMatrix()
    rows = np.array(m.getValue(), dtype=np.float64)
    return rows.T  # Coin's matrices act on row vectors


def _coin_primitive(node, T: np.ndarray, color: tuple) -> tuple:
    """(kind, sizes, pose (4, 4), colour) of a Coin sphere, cylinder or cube at the model pose
    ``T`` (file units): the scale of ``T``'s columns goes into the sizes, the pose keeps the
    rotation; Coin's cylinder, along its y, becomes Odin's along z."""
    R = T[:3, :3]
    s = np.linalg.norm(R, axis=0)
    s[s == 0] = 1.0
    T[:3, :3] = R / s
    name = node.getTypeId().getName().getString()
    if name == "Sphere":
        return ("sphere", (node.radius.getValue() * float(np.mean(s)),), T, color)
    if name == "Cylinder":
        dims = (node.radius.getValue() * float((s[0] + s[2]) / 2),
                node.height.getValue() * float(s[1]))
        return ("cylinder", dims, T @ rot_x(-np.pi / 2), color)
    dims = (node.width.getValue() * float(s[0]), node.height.getValue() * float(s[1]),
            node.depth.getValue() * float(s[2]))
    return ("box", dims, T, color)


def _placed(tris: list, runs: list) -> np.ndarray:
    """(M, 3, 3) the triangles' corners in the file's frame: each run of a shape node's
    triangles (first, end, model pose, colour) mapped from its object space by its pose."""
    corners = np.array(tris, dtype=np.float64).reshape(-1, 3, 3)
    for start, end, pose, _color in runs:
        if not np.allclose(pose, np.eye(4)):
            block = corners[start:end]
            corners[start:end] = block @ pose[:3, :3].T + pose[:3, 3]
    return corners
