"""URDF robots and obstacles (Kautham since 2021), SI units times the problem's scale.

Each link's geometry is its ``<collision>`` (what the physics uses), or its ``<visual>`` when
it has none; several geometries of a link are merged into one shape; the colour is the
visual's material (inline ``<color>`` or a named ``<material>`` of the robot). Mesh files are
resolved against the URDF's folder (``package://pkg/`` prefixes are dropped). Masses come from
``<inertial><mass>``; inertias are not used (see ``gui.core.build``). Joint types: revolute and
continuous (unlimited), prismatic, fixed; floating and planar joints are refused.
"""
from __future__ import annotations

import pathlib
from typing import Optional

import numpy as np

from gui.errors import ProblemError
from gui.core.kautham.xmlfile import Node, read_xml
from gui.core.kinematics import rpy_matrix
from gui.core.model import FIXED, PRISMATIC, REVOLUTE, LinkModel, RobotModel
from gui.core.shapes import Mesh, Primitive, Shape, read_shape

_JOINT_KINDS = {"revolute": REVOLUTE, "continuous": REVOLUTE, "prismatic": PRISMATIC,
                "fixed": FIXED}


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
    T[:3, 3] = np.asarray(xyz) * scale
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
            filename = child.require("filename")
            if filename.startswith("package://"):
                filename = filename[len("package://"):].split("/", 1)[-1]
            elif filename.startswith("file://"):
                filename = filename[len("file://"):]
            factors = child.numbers("scale", 3, (1.0, 1.0, 1.0))
            if max(factors) - min(factors) > 1e-9 * max(abs(f) for f in factors):
                raise child.error("a non-uniform mesh scale is not supported")
            return read_shape(urdf.parent / filename, factors[0] * scale).transformed(pose)
        if tag == "box":
            dims = tuple(v * scale for v in child.numbers("size", 3))
            return Shape(str(urdf), None, (Primitive("box", dims, pose),))
        if tag == "sphere":
            return Shape(str(urdf), None,
                         (Primitive("sphere", (child.number("radius") * scale,), pose),))
        if tag == "cylinder":
            dims = (child.number("radius") * scale, child.number("length") * scale)
            return Shape(str(urdf), None, (Primitive("cylinder", dims, pose),))
        raise child.error(f"unknown URDF geometry <{child.tag}>")
    raise geom.error("<geometry> is empty")


def _link_shape(link: Node, scale: float, urdf: pathlib.Path, materials: dict
                ) -> Optional[Shape]:
    owners = list(link.findall("collision")) or list(link.findall("visual"))
    shape = None
    for owner in owners:
        s = _geometry(owner, scale, urdf)
        shape = s if shape is None else shape.merged(s)
    visual = link.find("visual")
    color = _color(visual, materials)
    if shape is not None and color is not None:
        shape = shape.with_color(color)
    return shape


def read_urdf(path: pathlib.Path, scale: float = 1.0) -> RobotModel:
    root = read_xml(path, "URDF file")
    if root.tag != "robot":
        raise root.error(f"expected a <robot> element, found <{root.tag}>")
    name = root.get("name") or path.stem
    materials = {}
    for mat in root.findall("material"):
        col = mat.find("color")
        if col is not None:
            materials[mat.get("name", "")] = tuple(col.numbers("rgba", 4))
    link_nodes = {}
    for link in root.findall("link"):
        lname = link.require("name")
        if lname in link_nodes:
            raise link.error(f"a second link named \"{lname}\"")
        link_nodes[lname] = link
    if not link_nodes:
        raise root.error("has no <link>")
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
    roots = [n for n in link_nodes if n not in joint_of_child]
    if len(roots) != 1:
        raise root.error(f"needs exactly one root link, found {len(roots)}: {roots}")
    # Parents first (breadth-first from the root, children in file order).
    children: dict = {n: [] for n in link_nodes}
    for child_name, joint in joint_of_child.items():
        children[joint.find("parent").get("link")].append(child_name)
    order = [roots[0]]
    for n in order:
        order.extend(sorted(children[n], key=lambda c: joint_of_child[c].line))
    index = {n: i for i, n in enumerate(order)}
    links = []
    for lname in order:
        node = link_nodes[lname]
        mass = None
        inertial = node.find("inertial")
        if inertial is not None and inertial.find("mass") is not None:
            mass = inertial.find("mass").number("value")
            if mass <= 0:
                mass = None
        shape = _link_shape(node, scale, path, materials)
        joint = joint_of_child.get(lname)
        if joint is None:
            links.append(LinkModel(name=lname, parent=None, pre=np.eye(4), post=np.eye(4),
                                   mass=mass, shape=shape, source=str(path), line=node.line))
            continue
        kind = _JOINT_KINDS[joint.get("type")]
        axis = np.array([1.0, 0.0, 0.0])
        ax = joint.find("axis")
        if ax is not None:
            axis = np.asarray(ax.numbers("xyz", 3), dtype=float)
        norm = float(np.linalg.norm(axis))
        if kind != FIXED and norm == 0.0:
            raise (ax or joint).error("joint axis is zero")
        axis = axis / norm if norm else np.array([1.0, 0.0, 0.0])
        limits = None
        lim = joint.find("limit")
        if lim is not None and joint.get("type") != "continuous" and kind != FIXED:
            factor = scale if kind == PRISMATIC else 1.0
            limits = (lim.number("lower", 0.0) * factor, lim.number("upper", 0.0) * factor)
            if limits[0] > limits[1]:
                raise lim.error("lower is above upper")
        links.append(LinkModel(
            name=lname, parent=index[joint.find("parent").get("link")],
            pre=_origin(joint, scale), post=np.eye(4), joint=kind, axis=axis, limits=limits,
            mass=mass, shape=shape, source=str(path), line=joint.line))
    return RobotModel(name=name, links=links, source=str(path), kind="urdf")
