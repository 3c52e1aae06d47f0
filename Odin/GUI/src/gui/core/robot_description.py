"""A robot loaded from a Kautham problem as a ROS robot: its robot_description (URDF) and what
Set Robot tells the world (ROS-free; gui.ros.client sends it).

``describe_robot(handle, mesh_dir)`` takes a robot as the build plan drove it into the world
(``gui.core.plan.RobotHandle``: its model, its links' world bodies, its world joints) and
returns a ``RobotDescription``:

- **URDF robots** keep their URDF as given, except that every ``<mesh filename>`` becomes the
  absolute ``file://`` URI the loader read it from (RViz and MoveIt then find the meshes; a
  ``package://`` URI of a package ROS does not know would not resolve). Joint names are the
  URDF's. A URDF read at a problem scale other than 1 no longer describes the robot the world
  holds: it gets a generated description instead.
- **DH robots** (.rob, .dh) and bare shapes get a URDF generated from the model: one URDF link
  per model link, named by the link's name (``odin_common.interface.name_segment``, a "_2"...
  suffix on collision), each joint named as its child link (Kautham names a DOF by its link);
  revolute / continuous (no limits) / prismatic / fixed joints with the model's axes and limits;
  ``effort`` 0 and ``velocity`` the world servos' default speed (.rob files give neither);
  visual and collision geometry from the link's shape: primitives as URDF primitives, a mesh as
  a binary STL written to ``mesh_dir`` (named by its content's hash, so a reload reuses it) and
  referenced by its ``file://`` URI; no ``<inertial>`` (the world computes inertia from the
  shapes: Get State reports it).

In URDF a child link's frame sits on its joint's axis, where a DH link frame is at the far end
of the link, so a generated URDF link's frame is the joint frame after the joint's motion
(``parent link @ pre @ motion(q)``) and the model's ``post`` becomes the offset of the geometry
and of the next joint. Either way the description says where each URDF link frame sits in its
world object's frame (``link_positions``, ``link_orientations``) and the offset of each joint
(the robot's joint value is the Home value the world built it at plus the world joint's
value), so the world publishes tf and joint states that robot_state_publisher reproduces.
"""
from __future__ import annotations

import hashlib
import os
import pathlib
import re
import struct
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np

from gui.core.kautham.xmlfile import parse_xml_bytes, read_xml
from gui.core.kinematics import pose_to_position_quaternion
from gui.core.model import FIXED, PRISMATIC, REVOLUTE, LinkModel, RobotModel
from gui.core.sizes import read_input_file
from gui.errors import ProblemError
from odin_common.defaults import DEFAULT_COLOR, SERVO_MAX_SPEED
from odin_common.interface import name_segment, unique_frame


@dataclass(frozen=True)
class RobotDescription:
    """Everything Set Robot takes (Messages/Robot), as plain values."""
    name: str                               # the robot's name in the problem
    urdf: str                               # the robot_description
    links: Tuple[str, ...]                  # URDF link names, one per world object
    objects: Tuple[str, ...]                # the world object of each link
    link_positions: Tuple[float, ...]       # m, 3 per link: the link frame in the object's frame
    link_orientations: Tuple[float, ...]    # 4 per link, (w, x, y, z)
    joint_names: Tuple[str, ...]            # the robot's movable joints, its own names
    joints: Tuple[str, ...]                 # the world joint of each
    joint_axes: Tuple[int, ...]             # which of the world joint's values each is (a
    #                                        car's wheel: 1, its hinge-2's spin; else 0)
    joint_offsets: Tuple[float, ...]        # rad or m: robot value = offset + world value (the
    #                                        configuration it was built in, RobotHandle.built_at)
    generated: bool                         # a URDF generated here, not the robot's own file


def describe_robot(handle, mesh_dir: Optional[os.PathLike] = None) -> RobotDescription:
    """The description of a robot the world built (gui.core.plan.RobotHandle, with the
    world's IDs recorded); ``mesh_dir``: where generated descriptions' mesh files go (None:
    meshes are left out of a generated URDF, primitives stay)."""
    model: RobotModel = handle.instance.model
    given = model.kind == "urdf" and _urdf_matches_model(model)
    urdf_frames = _urdf_link_frames(model) if not given else [np.eye(4)] * len(model.links)
    if given:
        urdf, link_names, joint_of_link = _given_urdf(model)
    else:
        link_names = _link_names(model)
        joint_of_link = dict(enumerate(link_names))
        urdf = _generated_urdf(handle.instance.name, model, link_names, urdf_frames,
                               None if mesh_dir is None else pathlib.Path(mesh_dir))
    positions, orientations = [], []
    for link_index, body in enumerate(handle.bodies):
        # the URDF link frame in the object's frame: offset^-1 (link -> object) . post'
        T = np.linalg.inv(body.offset) @ urdf_frames[link_index]
        position, quaternion = pose_to_position_quaternion(T)
        positions.extend(position)
        orientations.extend(quaternion)
    movable = model.movable_links()
    return RobotDescription(
        name=handle.name, urdf=urdf, links=tuple(link_names),
        objects=tuple(b.body_id for b in handle.bodies),
        link_positions=tuple(positions), link_orientations=tuple(orientations),
        joint_names=tuple(joint_of_link[i] for i in movable[:len(handle.joint_ids)]),
        joints=tuple(handle.joint_ids), joint_axes=tuple(handle.joint_axes),
        joint_offsets=tuple(float(v) for v in handle.built_at[:len(handle.joint_ids)]),
        generated=not given)


# ---------------------------------------------------------------------------------- frames

def _urdf_link_frames(model: RobotModel) -> List[np.ndarray]:
    """Each URDF link's frame in its model link's frame (``post^-1`` but for the root, whose
    URDF frame is its model frame)."""
    return [np.eye(4) if link.parent is None else np.linalg.inv(link.post)
            for link in model.links]


def _joint_origin(model: RobotModel, link: LinkModel) -> np.ndarray:
    """A generated joint's origin in its parent's URDF frame: the parent's post, then pre."""
    parent = model.links[link.parent]
    parent_post = np.eye(4) if parent.parent is None else parent.post
    return parent_post @ link.pre


# ---------------------------------------------------------------------------------- given URDF

def _urdf_matches_model(model: RobotModel) -> bool:
    """Whether the file's joint origins are the model's (the problem's scale was 1)."""
    try:
        root = read_xml(model.source, "URDF file")
    except ProblemError:     # gone or changed since it was loaded: describe the model instead
        return False
    origins = {}
    for joint in root.findall("joint"):
        child = joint.find("child")
        origin = joint.find("origin")
        if child is not None:
            origins[child.get("link")] = (origin.numbers("xyz", 3, (0.0, 0.0, 0.0))
                                          if origin is not None else (0.0, 0.0, 0.0))
    for link in model.links:
        if link.parent is not None and link.name in origins:
            if not np.allclose(link.pre[:3, 3], origins[link.name], rtol=1e-9, atol=1e-12):
                return False
    return True


_MESH = re.compile(r"(<mesh\b[^>]*?\bfilename\s*=\s*)([\"'])(.*?)\2", re.DOTALL)


def _given_urdf(model: RobotModel) -> Tuple[str, List[str], Dict[int, str]]:
    """The file's text with mesh URIs made absolute, its link names, its joints' names by the
    model index of their child link."""
    path = pathlib.Path(model.source)
    folder = path.parent.resolve()

    def absolute(match) -> str:
        filename = match.group(3)
        if filename.startswith("package://"):
            filename = filename[len("package://"):].split("/", 1)[-1]
        elif filename.startswith("file://"):
            filename = filename[len("file://"):]
        resolved = (folder / filename).resolve()
        return f"{match.group(1)}{match.group(2)}file://{resolved}{match.group(2)}"

    data = read_input_file(path, "URDF file")   # once, bounded: read_input_file's checks
    try:
        text = _MESH.sub(absolute, data.decode("utf-8"))
    except UnicodeDecodeError as error:
        raise ProblemError(f"URDF file is not UTF-8 text ({error.reason} at byte "
                           f"{error.start})", path) from None
    names = {}
    for joint in parse_xml_bytes(data, str(path)).findall("joint"):
        child = joint.find("child")
        if child is not None:
            names[child.get("link")] = joint.get("name", "")
    links = [link.name for link in model.links]
    return text, links, {i: names.get(link.name, link.name) for i, link in enumerate(model.links)}


# ---------------------------------------------------------------------------------- generated

def _link_names(model: RobotModel) -> List[str]:
    names: List[str] = []
    for link in model.links:
        names.append(unique_frame(name_segment(link.name) or "link", set(names)))
    return names


def _xyz_rpy(T: np.ndarray) -> Dict[str, str]:
    """URDF's origin attributes of a pose: xyz and fixed-axis roll, pitch, yaw."""
    R = T[:3, :3]
    pitch = float(np.arctan2(-R[2, 0], np.hypot(R[0, 0], R[1, 0])))
    if np.hypot(R[0, 0], R[1, 0]) < 1e-12:     # gimbal lock: put the whole turn in yaw
        roll, yaw = 0.0, float(np.arctan2(-R[0, 1], R[1, 1]))
    else:
        roll = float(np.arctan2(R[2, 1], R[2, 2]))
        yaw = float(np.arctan2(R[1, 0], R[0, 0]))
    return {"xyz": " ".join(f"{v:.17g}" for v in T[:3, 3]),
            "rpy": f"{roll:.17g} {pitch:.17g} {yaw:.17g}"}


def _color(color: Sequence[float]) -> str:
    values = tuple(float(v) for v in color)
    if not any(values):
        values = DEFAULT_COLOR
    return " ".join(f"{v:.6g}" for v in values)


def _write_stl(mesh_dir: pathlib.Path, vertices: np.ndarray, triangles: np.ndarray) -> str:
    """A binary STL of the mesh (m) in ``mesh_dir``, named by its content (the vertices' and
    triangles' bytes); its file:// URI. Made only when no file of that name is there yet:
    building the records of a robot's meshes on every load was 0.2 s of the flagship's."""
    vertices = np.ascontiguousarray(vertices, dtype=float)
    triangles = np.ascontiguousarray(triangles, dtype=np.int64).reshape(-1, 3)
    digest = hashlib.sha1(vertices.tobytes())
    digest.update(triangles.tobytes())
    path = mesh_dir / (digest.hexdigest()[:20] + ".stl")
    if not path.exists():
        mesh_dir.mkdir(parents=True, exist_ok=True)
        temporary = path.with_suffix(f".{os.getpid()}.tmp")
        temporary.write_bytes(_stl_bytes(vertices, triangles))
        temporary.replace(path)
    return f"file://{path.resolve()}"


def _stl_bytes(vertices: np.ndarray, triangles: np.ndarray) -> bytes:
    """Binary STL: an 80-byte header, the count, a record per triangle (normal, corners)."""
    corners = vertices[triangles]
    normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    lengths = np.linalg.norm(normals, axis=1, keepdims=True)
    normals = np.divide(normals, lengths, out=np.zeros_like(normals), where=lengths > 0)
    records = np.zeros(len(corners), dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)),
                                            ("a", "<u2")])
    records["n"], records["v"] = normals, corners
    return (b"odin robot_description mesh".ljust(80, b" ") + struct.pack("<I", len(corners))
            + records.tobytes())


def _geometries(link: LinkModel, frame: np.ndarray, mesh_dir: Optional[pathlib.Path]) -> list:
    """(origin pose in the URDF link, geometry element, colour) of each piece of the shape;
    ``frame`` is the model link frame in the URDF link frame."""
    shape = link.shape
    if shape is None:
        return []
    pieces = []
    if shape.mesh is not None and mesh_dir is not None:
        uri = _write_stl(mesh_dir, shape.mesh.vertices, shape.mesh.triangles)
        pieces.append((frame, ET.Element("mesh", filename=uri), shape.mesh.color))
    for prim in shape.primitives:
        p = prim.parameters
        if prim.kind == "sphere":
            element = ET.Element("sphere", radius=f"{p[0]:.17g}")
        elif prim.kind == "cylinder":
            element = ET.Element("cylinder", radius=f"{p[0]:.17g}", length=f"{p[1]:.17g}")
        else:
            element = ET.Element("box", size=" ".join(f"{v:.17g}" for v in p[:3]))
        pieces.append((frame @ prim.pose, element, prim.color))
    return pieces


def _generated_urdf(name: str, model: RobotModel, link_names: List[str],
                    urdf_frames: List[np.ndarray], mesh_dir: Optional[pathlib.Path]) -> str:
    robot = ET.Element("robot", name=name)
    robot.append(ET.Comment(f" generated by Odin from {model.source} ({model.kind}, "
                            f"{model.dh_type or 'URDF'} frames); docs/ROS.md "))
    for index, link in enumerate(model.links):
        element = ET.SubElement(robot, "link", name=link_names[index])
        frame = np.linalg.inv(urdf_frames[index])     # the model link frame in the URDF link
        for k, (origin, geometry, color) in enumerate(_geometries(link, frame, mesh_dir)):
            for kind in ("visual", "collision"):
                part = ET.SubElement(element, kind)
                ET.SubElement(part, "origin", _xyz_rpy(origin))
                ET.SubElement(part, "geometry").append(geometry)
                if kind == "visual":
                    material = ET.SubElement(part, "material",
                                             name=f"{link_names[index]}_{k}")
                    ET.SubElement(material, "color", rgba=_color(color))
    for index, link in enumerate(model.links):
        if link.parent is None:
            continue
        kind = "fixed"
        if link.joint == REVOLUTE:
            kind = "revolute" if link.limits is not None else "continuous"
        elif link.joint == PRISMATIC:
            kind = "prismatic"
        joint = ET.SubElement(robot, "joint", name=link_names[index], type=kind)
        ET.SubElement(joint, "origin", _xyz_rpy(_joint_origin(model, link)))
        ET.SubElement(joint, "parent", link=link_names[link.parent])
        ET.SubElement(joint, "child", link=link_names[index])
        if link.joint != FIXED:
            ET.SubElement(joint, "axis", xyz=" ".join(f"{v:.17g}" for v in link.axis))
            if link.limits is not None:
                ET.SubElement(joint, "limit", lower=f"{link.limits[0]:.17g}",
                              upper=f"{link.limits[1]:.17g}", effort="0",
                              velocity=f"{SERVO_MAX_SPEED:g}")
    ET.indent(robot)
    return '<?xml version="1.0"?>\n' + ET.tostring(robot, encoding="unicode") + "\n"


__all__ = ["RobotDescription", "describe_robot"]
