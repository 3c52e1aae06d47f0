"""URDF robots and obstacles (Kautham since 2021), SI units times the problem's scale.

Geometry: each link's ``<collision_checking>`` elements (Kautham's own), else its
``<collision>`` (what the physics uses), else its ``<visual>``; several geometries of a link are
merged into one shape; the colour is the visual's material (inline ``<color>`` or a named
``<material>`` of the robot). Mesh files are resolved against the URDF's folder
(``package://pkg/`` prefixes are dropped).

Physics (``gui.core.model.LinkModel``): ``<inertial>`` gives the mass, the centre of mass
frame (scaled) and the inertia tensor (times scale^2: the same mass spread over a body
``scale`` times larger); ``<limit effort velocity>`` the joint's force and speed limits;
``<dynamics damping friction>`` its damping and friction; ``<collision><contact_coefficients
mu kp kd>`` (Kautham's per-link ODE contact data) and Gazebo's ``<gazebo reference="link">``
``mu1 mu2 fdir1 kp kd`` the link's contact surface. A ``<safety_controller>`` gives the joint's
limits, as in Kautham (its soft limits). Joint types: revolute, continuous (no limits),
prismatic, fixed; floating and planar joints are refused. What Odin does not use
(transmissions, mimic joints, calibration, other Gazebo settings, Kautham's joint
``<weight>``) is listed in ``RobotModel.ignored``.

Numbers are read as Kautham reads them (``gui.core.kautham.xmlfile``: ``ixx="0.46 5"``, in the
TIAGo base's URDF, is 0.46), each such reading listed in ``RobotModel.ignored`` and so warned
about.
"""
from __future__ import annotations

import pathlib
from typing import List, Optional

import numpy as np

from gui.core.geometry import Primitive, Shape
from gui.core.kautham.robot_file import read_robot_root
from gui.core.kautham.units import inertia_problem, mass_problem
from gui.core.kautham.xmlfile import LenientNumber, Node, parse_number
from gui.core.kinematics import rpy_matrix
from gui.core.model import FIXED, PRISMATIC, REVOLUTE, Ignored, Inertial, LinkModel, RobotModel
from gui.core.shapes import read_shape
from gui.errors import ShapeError
from odin_common.limits import shown
from odin_common.specs import WORLD_SURFACE, Surface

_JOINT_KINDS = {"revolute": REVOLUTE, "continuous": REVOLUTE, "prismatic": PRISMATIC,
                "fixed": FIXED}
_GAZEBO_SURFACE = ("mu1", "mu2", "fdir1", "kp", "kd")
_ROBOT_CHILDREN_USED = ("link", "joint", "material", "gazebo")
_PRIMITIVE_SIZES = {"box": ("size",), "sphere": ("radius",), "cylinder": ("radius", "length")}


def _origin(node: Optional[Node], scale: float) -> np.ndarray:
    T = np.eye(4)
    if node is None:
        return T
    o = node.find("origin")
    if o is None:
        return T
    xyz = o.numbers("xyz", 3, (0.0, 0.0, 0.0))
    rpy = o.numbers("rpy", 3, (0.0, 0.0, 0.0))
    T[:3, :3] = rpy_matrix(*rpy)
    T[:3, 3] = o.scaled_lengths(f"<origin xyz={shown(o.get('xyz'))}>", xyz, scale)
    return T


def _color(visual: Optional[Node], materials: dict) -> Optional[tuple]:
    if visual is None:
        return None
    mat = visual.find("material")
    if mat is None:
        return None
    col = mat.find("color")
    if col is not None:
        return tuple(col.numbers("rgba", 4))
    return materials.get(mat.get("name", ""))


def _geometry(owner: Node, scale: float, urdf: pathlib.Path) -> Optional[Shape]:
    geom = owner.find("geometry")
    if geom is None:
        raise owner.error(f"<{owner.tag}> has no <geometry>")
    pose = _origin(owner, scale)
    for child in geom.children:
        tag = child.tag.lower()
        if tag == "mesh":
            return _mesh(child, scale, urdf).transformed(pose)
        if tag in _PRIMITIVE_SIZES:
            sizes = _PRIMITIVE_SIZES[tag]
            raw = child.numbers(sizes[0], 3) if tag == "box" else \
                tuple(child.number(name) for name in sizes)
            dims = child.scaled_lengths(f"<{tag}> {' '.join(sizes)}", raw, scale)
            return Shape(str(urdf), None,
                         (Primitive(tag, tuple(float(v) for v in dims), pose),))
        raise child.error(f"unknown URDF geometry <{child.tag}>")
    raise geom.error("<geometry> is empty")


def mesh_file(uri: str, urdf: pathlib.Path) -> pathlib.Path:
    """The file a ``<mesh filename>`` names: ``package://pkg/rest`` is ``rest`` and
    ``file://path`` is ``path``, both beside the URDF unless absolute (as Kautham finds them)."""
    if uri.startswith("package://"):
        uri = uri[len("package://"):].split("/", 1)[-1]
    elif uri.startswith("file://"):
        uri = uri[len("file://"):]
    return urdf.parent / uri


def _mesh(node: Node, scale: float, urdf: pathlib.Path) -> Shape:
    """A ``<mesh filename scale>``'s shape, scaled; an error of its file names the URI as
    written, where it was looked for and what is wrong there."""
    uri = node.require("filename")
    file = mesh_file(uri, urdf)
    factors = node.numbers("scale", 3, (1.0, 1.0, 1.0))
    try:
        if factors[0] > 0 and max(factors) - min(factors) <= 1e-9 * factors[0]:
            return read_shape(file, factors[0] * scale)
        # uneven or mirroring factors (TIAGo's arm meshes: "1 -1 -1")
        return read_shape(file, scale).scaled(factors)
    except ShapeError as error:
        scaled = "" if node.get("scale") is None else f" scale={shown(node.get('scale'))}"
        raise ShapeError(f"<mesh filename={shown(uri)}{scaled}>: {error.path or file}"
                         f"{f':{error.line}' if error.line else ''}: {error.reason}",
                         node.path, node.line) from None


def _link_shape(link: Node, scale: float, urdf: pathlib.Path, materials: dict
                ) -> Optional[Shape]:
    owners = list(link.findall("collision_checking")) or list(link.findall("collision")) \
        or list(link.findall("visual"))
    shape = None
    for owner in owners:
        s = _geometry(owner, scale, urdf)
        shape = s if shape is None else shape.merged(s)
    visual = link.find("visual")
    color = _color(visual, materials)
    if shape is not None and color is not None:
        shape = shape.with_color(color)
    return shape


def _inertial(link: Node, scale: float) -> Optional[Inertial]:
    """The link's ``<inertial>`` (None without one, or with a mass that is not positive)."""
    node = link.find("inertial")
    if node is None or node.find("mass") is None:
        return None
    mass_node = node.find("mass")
    mass = mass_node.number("value")
    if mass <= 0:
        return None
    problem = mass_problem(mass)
    if problem is not None:
        raise mass_node.error(f"<mass value={shown(mass_node.get('value'))}>: {problem}")
    tensor = None
    inertia = node.find("inertia")
    if inertia is not None:
        i = {k: inertia.number(k, 0.0) for k in ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")}
        with np.errstate(over="ignore"):      # an overflow is refused just below
            matrix = np.array([[i["ixx"], i["ixy"], i["ixz"]], [i["ixy"], i["iyy"], i["iyz"]],
                               [i["ixz"], i["iyz"], i["izz"]]]) * (scale * scale)
        problem = inertia_problem(matrix)
        if problem is not None:
            raise inertia.error(f"<inertia> times the scale {scale:g} squared: {problem}")
        tensor = matrix if np.any(matrix != 0.0) else None
    return Inertial(mass, _origin(node, scale), tensor)


def _contact_surface(link: Node, gazebo: Optional[Node]) -> Surface:
    """Kautham's ``<collision><contact_coefficients mu kp kd>``, then Gazebo's ``mu1 mu2
    fdir1 kp kd`` for the link (Gazebo's win where both are given)."""
    values: dict = {}
    collision = link.find("collision")
    coefficients = collision.find("contact_coefficients") if collision is not None else None
    if coefficients is not None:
        for name in ("mu", "kp", "kd"):
            if coefficients.get(name) is not None:
                values[name] = coefficients.number(name)
    if gazebo is not None:
        for name in _GAZEBO_SURFACE:
            child = gazebo.find(name)
            if child is None:
                continue
            if name == "fdir1":
                values[name] = _text_numbers(child, 3)
            else:
                values["mu" if name == "mu1" else name] = _text_number(child)
    if not values:
        return WORLD_SURFACE
    for name in ("mu", "mu2", "kp", "kd"):
        if name in values and values[name] < 0:
            raise (coefficients or gazebo).error(f"{name}={values[name]!r} is negative")
    direction = values.get("fdir1", (1.0, 0.0, 0.0))
    if "mu2" in values and not any(direction):
        direction = (1.0, 0.0, 0.0)
    stiffness = values.get("kp")
    return Surface(friction=values.get("mu"), friction2=values.get("mu2"),
                   friction_direction=tuple(float(v) for v in direction),
                   stiffness=stiffness if stiffness else None,
                   damping=values.get("kd", 0.0) if stiffness else 0.0)


def _text_number(node: Node) -> float:
    return parse_number(node.text, f"<{node.tag}>", node.path, node.line)


def _text_numbers(node: Node, count: int) -> tuple:
    parts = node.text.split()
    if len(parts) != count:
        raise node.error(f"<{node.tag}>{node.text.strip()}</{node.tag}> needs {count} numbers")
    return tuple(parse_number(p, f"<{node.tag}>", node.path, node.line) for p in parts)


def _gazebo_blocks(root: Node, link_names, path: pathlib.Path, ignored: List[Ignored]) -> dict:
    """{link name: its <gazebo reference> block}; whatever else Gazebo blocks hold is
    listed as ignored."""
    blocks = {}
    for block in root.findall("gazebo"):
        reference = block.get("reference")
        if reference is None or reference not in link_names:
            ignored.append(Ignored(str(path), block.line, "<gazebo>" if reference is None else
                                   f"<gazebo reference=\"{reference}\">",
                                   "Gazebo settings of no link of this robot (plugins, "
                                   "joints): Odin does not use them"))
            continue
        blocks[reference] = block
        for child in block.children:
            if child.tag.lower() not in _GAZEBO_SURFACE:
                ignored.append(Ignored(str(path), child.line,
                                       f"<gazebo reference=\"{reference}\"><{child.tag}>",
                                       "Gazebo setting Odin does not use"))
    return blocks


def _joint_limits(joint: Node, kind: str, scale: float) -> tuple:
    """(limits (low, high) or None, effort or None, velocity or None) of a joint."""
    lim = joint.find("limit")
    if lim is None or kind == FIXED:
        return None, None, None
    factor = scale if kind == PRISMATIC else 1.0
    effort = lim.number("effort", 0.0)
    velocity = lim.number("velocity", 0.0)
    if kind == PRISMATIC:       # m/s: a length per second, scaled
        velocity = float(lim.scaled_lengths("<limit velocity>", velocity, factor))
    if effort < 0 or velocity < 0:
        raise lim.error("effort and velocity limits cannot be negative")
    limits = None
    if joint.get("type") != "continuous":
        soft = joint.find("safety_controller")
        if soft is not None and soft.get("soft_lower_limit") is not None:
            low = soft.number("soft_lower_limit", 0.0)
            high = soft.number("soft_upper_limit", 0.0)
            where = soft
        else:
            low, high, where = lim.number("lower", 0.0), lim.number("upper", 0.0), lim
        low, high = (float(v) for v in where.scaled_lengths(
            "lower and upper", (low, high), factor, "m" if kind == PRISMATIC else "rad"))
        limits = (low, high)
        if limits[0] > limits[1]:
            raise where.error("lower is above upper")
    return limits, effort or None, velocity or None


def _joint_ignored(joint: Node, path: pathlib.Path, ignored: List[Ignored]) -> None:
    for tag, why in (("mimic", "a mimic joint moves on its own in Odin"),
                     ("calibration", "calibration references are not simulated"),
                     ("weight", "Kautham's planner weight of the joint, not a physical "
                                "quantity")):
        node = joint.find(tag)
        if node is not None:
            ignored.append(Ignored(str(path), node.line,
                                   f"<joint name=\"{joint.get('name', '')}\"><{tag}>", why))


def read_urdf(path: pathlib.Path, scale: float = 1.0) -> RobotModel:
    """Reads a URDF file with its meshes (module docstring); numbers are read as Kautham reads
    them (a malformed one by its leading number, listed in ``RobotModel.ignored``)."""
    lenient: List[LenientNumber] = []
    model = _read_urdf(path, scale, lenient)
    model.ignored.extend(Ignored(n.path, n.line, n.what, f"not a number: read as {n.value!r}, "
                                 "its leading number, as Kautham reads it")
                         for n in lenient)
    return model


def _read_urdf(path: pathlib.Path, scale: float, lenient: list) -> RobotModel:
    root, name = read_robot_root(path, "URDF file", "robot", scale, lenient)
    ignored: List[Ignored] = []
    materials = _materials(root)
    link_nodes = _link_nodes(root)
    for child in root.children:
        if child.tag.lower() not in _ROBOT_CHILDREN_USED:
            ignored.append(Ignored(str(path), child.line, f"<{child.tag}>",
                                   "not simulated by Odin (transmissions and the like)"))
    gazebo = _gazebo_blocks(root, link_nodes, path, ignored)
    joint_of_child = _parent_joints(root, link_nodes)
    order = _parents_first(root, link_nodes, joint_of_child)
    index = {n: i for i, n in enumerate(order)}
    links = []
    for lname in order:
        node = link_nodes[lname]
        inertial = _inertial(node, scale)
        common = dict(mass=inertial.mass if inertial else None, inertial=inertial,
                      shape=_link_shape(node, scale, path, materials),
                      surface=_contact_surface(node, gazebo.get(lname)), source=str(path))
        joint = joint_of_child.get(lname)
        if joint is None:
            links.append(LinkModel(name=lname, parent=None, pre=np.eye(4), post=np.eye(4),
                                   line=node.line, **common))
            continue
        parent = index[joint.find("parent").get("link")]
        links.append(_jointed_link(joint, lname, parent, scale, common))
        _joint_ignored(joint, path, ignored)
    return RobotModel(name=name, links=links, source=str(path), kind="urdf", ignored=ignored)


def _materials(root: Node) -> dict:
    """{name: (r, g, b, a)} of the robot's named ``<material>`` colours."""
    materials = {}
    for mat in root.findall("material"):
        col = mat.find("color")
        if col is not None:
            materials[mat.get("name", "")] = tuple(col.numbers("rgba", 4))
    return materials


def _link_nodes(root: Node) -> dict:
    """{link name: its <link>}, in file order; at least one, no name twice."""
    link_nodes = {}
    for link in root.findall("link"):
        lname = link.require("name")
        if lname in link_nodes:
            raise link.error(f"a second link named \"{lname}\"")
        link_nodes[lname] = link
    if not link_nodes:
        raise root.error("has no <link>")
    return link_nodes


def _parent_joints(root: Node, link_nodes: dict) -> dict:
    """{child link name: the <joint> that moves it}: every joint of a supported type between
    two links of ``link_nodes``, no link with two parent joints."""
    joint_of_child = {}
    for joint in root.findall("joint"):
        jtype = joint.require("type")
        if jtype not in _JOINT_KINDS:
            raise joint.error(f"joint type \"{jtype}\" is not supported")
        parent = joint.find("parent")
        child = joint.find("child")
        if parent is None or child is None:
            raise joint.error("a joint needs <parent link> and <child link>")
        for end in (parent, child):
            if end.require("link") not in link_nodes:
                raise end.error(f"link \"{end.get('link')}\" is not defined")
        if child.get("link") in joint_of_child:
            raise joint.error(f"link \"{child.get('link')}\" has two parent joints")
        joint_of_child[child.get("link")] = joint
    return joint_of_child


def _parents_first(root: Node, link_nodes: dict, joint_of_child: dict) -> list:
    """The link names, parents first: breadth-first from the one root link, children in file
    order."""
    roots = [n for n in link_nodes if n not in joint_of_child]
    if len(roots) != 1:
        raise root.error(f"needs exactly one root link, found {len(roots)}: {roots}")
    children: dict = {n: [] for n in link_nodes}
    for child_name, joint in joint_of_child.items():
        children[joint.find("parent").get("link")].append(child_name)
    order = [roots[0]]
    for n in order:
        order.extend(sorted(children[n], key=lambda c: joint_of_child[c].line))
    return order


def _jointed_link(joint: Node, name: str, parent: int, scale: float, common: dict
                  ) -> LinkModel:
    """The link ``name`` that ``joint`` moves, its parent link the model's link ``parent``;
    ``common``: the link's own fields (mass, inertial, shape, surface, source)."""
    kind = _JOINT_KINDS[joint.get("type")]
    axis = _joint_axis(joint, kind)
    limits, effort, velocity = _joint_limits(joint, kind, scale)
    damping, friction = _joint_dynamics(joint, kind)
    return LinkModel(
        name=name, parent=parent,
        pre=_origin(joint, scale), post=np.eye(4), joint=kind, axis=axis, limits=limits,
        line=joint.line, joint_name=joint.get("name", name),
        continuous=joint.get("type") == "continuous", effort=effort, velocity=velocity,
        damping=damping, friction=friction, **common)


def _joint_axis(joint: Node, kind: str) -> np.ndarray:
    """The unit ``<axis xyz>`` of a joint in its frame (+x without one; a fixed joint's zero
    axis is +x, any other joint's is an error)."""
    axis = np.array([1.0, 0.0, 0.0])
    ax = joint.find("axis")
    if ax is not None:
        axis = np.asarray(ax.numbers("xyz", 3), dtype=float)
    norm = float(np.linalg.norm(axis))
    if kind != FIXED and norm == 0.0:
        raise (ax or joint).error("joint axis is zero")
    return axis / norm if norm else np.array([1.0, 0.0, 0.0])


def _joint_dynamics(joint: Node, kind: str) -> tuple:
    """(damping, friction) of a joint's ``<dynamics>``: (0, 0) without one or when fixed."""
    damping = friction = 0.0
    dynamics = joint.find("dynamics")
    if dynamics is not None and kind != FIXED:
        damping, friction = dynamics.number("damping", 0.0), dynamics.number("friction", 0.0)
        if damping < 0 or friction < 0:
            raise dynamics.error("damping and friction cannot be negative")
    return damping, friction
