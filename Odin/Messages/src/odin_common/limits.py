"""Sane ranges for what requests may ask: a value outside them is refused (naming the field and
the limit) before it can reach ODE, where it would make a step diverge or exhaust memory. Where
a range depends on the world, it is a world parameter (world_parameters: divergence_speed,
divergence_angular_speed, world_extent: velocities and positions are checked against those).
What a world may hold in all (objects, snapshots, a request's bytes) is a ResourceLimits, which
the world node reads from its ~parameters."""
from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Optional

import numpy as np

from odin_common.errors import InvalidArgument

MAX_FORCE = 1e7
"""N (forces) or N m (torques): a persistent body or joint force, a motor's maximum force."""

MAX_FORCES_PER_OWNER = 16
"""Persistent forces and torques (Set External Force, Set Joint Force, a Propagate's forces)
one body or one joint may hold at a time: each is applied at every step, and adding one
walks those held, so their number bounds a step's and a request's work."""

MIN_MASS = 1e-9
"""kg: the lightest body."""
MAX_MASS = 1e9
"""kg: the heaviest body."""

MIN_SIZE = 1e-6
"""m: the smallest dimension of a primitive (the largest is twice the world's extent)."""

MIN_GYRATION_FRACTION = 0.003
"""A given inertia's radius of gyration about each principal axis, as a fraction of how far the
body's geometry reaches from that axis (through the centre of mass): the least allowed. A body
far lighter in rotation than its size says makes ODE's dense solver return non-finite
velocities when contacts push it at arm's length, and ODE then aborts the process in its
quaternion normalisation (a 12 m room of 0.05 kg and 7e-8 kg m^2, a radius of gyration of
0.02 % of its reach, did; 0.1 % did not). Uniform solids have 20 % and more."""

MAX_GYRATION_MULTIPLE = 10.0
"""A given inertia's radius of gyration about each principal axis, as a multiple of the
farthest any point of the body's geometry lies from its centre of mass: the most allowed. No
rigid body's exceeds 1 (its mass is within its geometry's reach); a larger multiple leaves
room for geometry that only roughly covers the mass (a link's collision shape). A body
heavier in rotation than its size allows turns ODE's rotation update into overflow: 1 kg of
sphere with 1e200 kg m^2 ended the process in ODE's quaternion normalisation at its first
step."""

MAX_INERTIA = 1e30
"""kg m^2: the largest principal moment of a given inertia, whatever its mass and geometry.
The heaviest body (MAX_MASS) the size of the largest world (2 x 1e8 m) has ~4e25; with
angular speeds below the divergence guard's (<= 1e8 rad/s) every product ODE forms (I w,
w x I w) stays below 1e50, far inside float64."""

MAX_MOTOR_SPEED = 1e5
"""rad/s or m/s: a motor's goal speed."""

MIN_STEP = 1e-7
"""s: the shortest step."""

MAX_GRAVITY = 1e4
"""m/s^2: each component of gravity."""

MAX_SNAPSHOT_MB = 1024
"""MB (estimated) all of a world's saved states (Save State) may hold together: a snapshot
grows with the scene (~0.3 kB a body), so max_snapshots of a 100,000-body scene would be
hundreds of GB; Save State beyond it is refused, naming both."""

MAX_MESH_TRIANGLES = 2_000_000
"""Triangles of one mesh, by default (ResourceLimits.max_mesh_triangles)."""

MAX_INPUT_FILE_MB = 256
"""MB: the largest file the GUI reads (a problem, robot, URDF, control, path or geometry file);
a larger one is refused before it is read. The real Kautham corpus's largest is under 10 MB."""

MAX_XML_ELEMENTS = 200_000
"""Elements of one XML file the GUI reads (problem, robot, URDF, control, path, solution,
benchmark files), counted while parsing: the parse stops at the next one. The largest file of
the public Kautham corpus holds 250 (a .rob); a tree node costs ~0.5 KB, so the bound keeps a
tree near 100 MB where 200 MB of empty elements would otherwise need gigabytes."""

MAX_XML_DEPTH = 100
"""Levels of nested elements in one XML file the GUI reads (Kautham's files: at most 5)."""

MAX_XML_ATTRIBUTES = 1_000
"""Attributes of one element of an XML file the GUI reads (Kautham's files: at most 7)."""

MAX_NAME_BYTES = 256
"""Bytes (UTF-8) of a name a request gives (an object, part, joint, snapshot, robot): longer
names are refused before anything is stored, as are names with a control character (NUL, a
newline, a tab...), which would make logs, frames and file names ambiguous."""

MAX_SHOWN_CHARS = 80
"""Characters of an offending value that an error message quotes (``shown``): a refusal of a
10 MB name or a 100,000-row array is one short line, not a copy of the request."""

MAX_STEPS_PER_CALL = 1_000_000
"""Steps one call may ask for (a Step Once, a Propagate): the node answers nothing else
meanwhile, so a longer run is asked for in pieces (at 1 ms steps, 1,000 s of simulated time)."""


MAX_BODY_STEPS_PER_CALL = 10_000_000
"""Body-steps (steps times the bodies that step) one call may ask for: a Propagate, a Step
Once of several cycles. The node answers nothing else meanwhile, and a step's work grows with
the bodies: 1,000 s of 1 ms steps over 200 bodies (2e8 body-steps) held a world for more
than ten minutes (~3 us a body-step on a 2-core host); 1e7 is about half a minute there.
A longer run is asked for in pieces."""


MAX_CALL_SECONDS = 60.0
"""s of wall time a long call (a Propagate, a Step Once of many cycles) of the world node may
run before it is stopped as if its caller had gone: MAX_BODY_STEPS_PER_CALL bounds the work
in body-steps, but a body-step's cost spans orders of magnitude (0.3 us in a scattering pile
under QuickStep, 1.4 ms in a stack of 99 boxes under the exact solver)."""


def check_work(what: str, steps: int, bodies: int) -> int:
    """``steps`` if ``steps`` x ``bodies`` (at least 1) is within MAX_BODY_STEPS_PER_CALL,
    else InvalidArgument naming ``what`` and both numbers."""
    work = int(steps) * max(int(bodies), 1)
    if work > MAX_BODY_STEPS_PER_CALL:
        raise InvalidArgument(f"{what}: {float(steps):.3g} steps x {bodies:,} bodies = "
                              f"{float(work):.3g} body-steps; one call runs at most "
                              f"{MAX_BODY_STEPS_PER_CALL:.3g} (MAX_BODY_STEPS_PER_CALL): ask "
                              "in pieces")
    return int(steps)


def shown(value, limit: int = MAX_SHOWN_CHARS) -> str:
    """``repr(value)`` cut to ``limit`` characters (saying how long it was), for error messages
    that quote what a request or file gave."""
    if isinstance(value, np.ndarray) and value.size > limit:
        return f"<array of {value.size:,} values, shape {value.shape}>"
    if isinstance(value, (list, tuple)) and len(value) > limit:
        return f"<{type(value).__name__} of {len(value):,} items>"
    if isinstance(value, (str, bytes)) and len(value) > limit:
        # the repr of the head only: a huge value is never copied whole
        return f"{repr(value[:limit])[:limit - 1]}… ({len(value):,} characters)"
    text = repr(value)
    if len(text) <= limit:
        return text
    return f"{text[:limit - 1]}… ({len(text):,} characters of repr)"


MAX_LISTED = 10
"""Items of a list (saved snapshot names, unknown IDs...) an error message names before it
says how many more there are (``shown_list``)."""


def shown_list(items, limit: int = MAX_LISTED) -> str:
    """The first ``limit`` of ``items``, each ``shown``, and "N more": a refusal that lists
    what a world holds stays short however much it holds."""
    items = list(items)
    head = ", ".join(shown(item) for item in items[:limit])
    more = len(items) - limit
    return f"[{head}{f', and {more:,} more' if more > 0 else ''}]"


def name_problem(value) -> Optional[str]:
    """Why ``value`` is not a valid name (MAX_NAME_BYTES, printable, non-empty), or None."""
    if not isinstance(value, str) or not value:
        return "must be a non-empty string"
    if len(value) > MAX_NAME_BYTES or len(value.encode("utf-8", "surrogatepass")) > \
            MAX_NAME_BYTES:
        return f"is longer than {MAX_NAME_BYTES} bytes (MAX_NAME_BYTES)"
    if not value.isprintable():
        return "holds a control character (NUL, newline, tab...): names must be printable"
    return None


def check_name(what: str, value) -> str:
    """``value`` if it is a valid name (``name_problem``), else InvalidArgument naming ``what``
    and the value (cut to MAX_SHOWN_CHARS)."""
    problem = name_problem(value)
    if problem is not None:
        raise InvalidArgument(f"{what}={shown(value)} {problem}")
    return value


_CORNERS = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)


def primitive_corners(kind: str, dims) -> np.ndarray:
    """(8, 3) m: the corners of the box around a sphere (radius), box (sides), cylinder or
    capsule (radius, length; along z), in its own frame: the points ``thin_inertia`` reads."""
    if kind == "box":
        half = np.asarray(dims, dtype=float) / 2.0
    elif kind == "sphere":
        half = np.full(3, float(dims[0]))
    else:
        radius, length = float(dims[0]), float(dims[1])
        half = np.array([radius, radius, length / 2.0 + (radius if kind == "capsule" else 0)])
    return _CORNERS * half


def thin_inertia(inertia: np.ndarray, mass: float, points: np.ndarray) -> Optional[str]:
    """Why a body of ``mass`` kg whose ``inertia`` ((3, 3) kg m^2, about its centre of mass)
    is too light in rotation for its geometry (``points`` (n, 3) m, from the centre of mass,
    the inertia's axes: mesh vertices, primitives' box corners), per MIN_GYRATION_FRACTION;
    None when it is not."""
    moments, axes = np.linalg.eigh(inertia)
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    for moment, axis in zip(moments, axes.T):
        along = points @ axis
        reach = float(np.sqrt(np.max(np.einsum("ij,ij->i", points, points) - along * along,
                                     initial=0.0)))
        least = mass * (MIN_GYRATION_FRACTION * reach) ** 2
        if moment < least:
            return (f"principal moment {moment:.3g} kg m^2 is below {least:.3g} kg m^2: its "
                    f"radius of gyration {np.sqrt(max(moment, 0.0) / mass):.3g} m is under "
                    f"{MIN_GYRATION_FRACTION:g} of the {reach:.3g} m its geometry reaches from "
                    "that axis (MIN_GYRATION_FRACTION)")
    return None


def heavy_inertia(inertia: np.ndarray, mass: float, points: np.ndarray) -> Optional[str]:
    """Why a body of ``mass`` kg whose ``inertia`` ((3, 3) kg m^2, about its centre of mass) is
    too heavy in rotation for its geometry (``points`` as ``thin_inertia``'s): a principal
    moment above MAX_INERTIA, or a radius of gyration above MAX_GYRATION_MULTIPLE times the
    farthest point's distance from the centre of mass; None when it is not."""
    moments = np.linalg.eigvalsh(inertia)
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    reach = float(np.sqrt(np.max(np.einsum("ij,ij->i", points, points), initial=0.0)))
    most = min(mass * (MAX_GYRATION_MULTIPLE * reach) ** 2, MAX_INERTIA)
    if moments[-1] > most:
        why = ("MAX_INERTIA" if most == MAX_INERTIA else
               f"a radius of gyration {MAX_GYRATION_MULTIPLE:g} times the {reach:.3g} m its "
               "geometry reaches from the centre of mass (MAX_GYRATION_MULTIPLE)")
        return (f"principal moment {moments[-1]:.3g} kg m^2 is above {most:.3g} kg m^2 for "
                f"{mass:.3g} kg: {why}")
    return None


def inertia_problem(inertia: np.ndarray, mass: float, points: np.ndarray) -> Optional[str]:
    """Why a given inertia cannot be this body's (``thin_inertia`` or ``heavy_inertia``), or
    None: the one check of a given inertia against mass and geometry, both ways."""
    return thin_inertia(inertia, mass, points) or heavy_inertia(inertia, mass, points)


@dataclass(frozen=True)
class ResourceLimits:
    """What one world may hold, so that no request can exhaust the node's memory; each a
    positive integer, refused with a message naming it when a request would exceed it.

    max_objects: objects (a composite counts once) in the scene.
    max_mesh_triangles: triangles of one mesh.
    max_snapshots: saved states (Save State) at a time.
    max_request_mb: MB of one incoming ROS message (the world node drops a connection whose
        next message announces more, before reading it)."""
    max_objects: int = 100_000
    max_mesh_triangles: int = MAX_MESH_TRIANGLES
    max_snapshots: int = 10_000
    max_request_mb: int = 256

    def __post_init__(self):
        for f in fields(self):
            value = getattr(self, f.name)
            if isinstance(value, bool) or not isinstance(value, int) or value < 1:
                raise InvalidArgument(f"{f.name}={value!r} must be a positive integer")
