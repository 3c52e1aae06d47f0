"""Kautham's DH robot files: 2012 ``.rob`` (mm, degrees) and 2017-2021 ``.dh`` (m, radians).

    <Robot name DHType="Standard|Modified" robType="Chain|Tree|Freeflying">
      <Joints size><Joint name ivFile>
          <DHPars alpha a theta d/> <PreTrans X Y Z WX WY WZ TH/>
          <Description rotational movable/> <Limits Hi Low/> <Weight weight/> <Parent name/>
      </Joint>...</Joints>
      <ControlSet>...</ControlSet>        (optional; see gui.core.kautham.controls)
    </Robot>

The first joint is the robot's base, never a joint, whatever its ``<Description movable>``
says: Kautham's reader (``Robot::Robot``, libproblem/robot.cpp) gives a robot of n joints n - 1
joint coordinates and skips the first ("First link is ommited because it is the base"); the 2012
free-flying robots (``table.rob``, ``minicube.rob``: one ``Base`` joint marked movable) move by
their base's controls only. The 2009 files of the IROS09 hand problems
(``3DOFCy_RHand*.rob``) list their ``<Joint>`` elements directly under ``<Robot>``, without the
``<Joints>`` wrapper that the 2010-2012 reader (pugixml's ``child("Joints")``) requires and that
later files all have; they are read as the joint list they are, and a file holding both is
refused as ambiguous.

Lengths (a, d, PreTrans X/Y/Z, prismatic limits) and the link geometry are multiplied by the
problem's ``scale`` and the file's length unit; angles are converted to radians. A missing
``<Parent>`` means the previous joint (a chain); ``<Parent name="">`` the robot's base.
``<Weight>`` is a weight Kautham's planners give the joint in distances, not a mass: it is kept
as ``LinkModel.planner_weight`` and the links get the build's default mass. ``<Weight>`` and
``<WeightSE3>`` (planner weights) are listed in ``RobotModel.ignored``; a malformed value there
never stops a load. ``robType="Freeflying"`` gives the robot a free base
(``RobotModel.free_base``).
"""
from __future__ import annotations

import pathlib

import numpy as np

from gui.core.kautham.controls import parse_control_set
from gui.core.kautham.robot_file import read_robot_root
from gui.core.kautham.units import LEGACY, SI, Units
from gui.core.kautham.xmlfile import Node
from gui.core.kinematics import pose_from_axis_angle, rot_x, rot_z, translation
from gui.core.model import FIXED, PRISMATIC, REVOLUTE, Ignored, LinkModel, RobotModel
from gui.core.shapes import read_shape

DH_TYPES = ("Standard", "Modified")


def units_of(path: pathlib.Path) -> Units:
    return SI if path.suffix.lower() == ".dh" else LEGACY


def read_dh_robot(path: pathlib.Path, scale: float = 1.0) -> RobotModel:
    """Reads a .rob/.dh file with its link geometry; everything in SI."""
    units = units_of(path)
    root, name = read_robot_root(path, "robot file", "Robot", scale)
    dh_raw = root.get("DHType", "Standard").strip()
    matches = [t for t in DH_TYPES if t.lower() == dh_raw.lower()]
    if not matches:
        raise root.error(f"unknown DHType=\"{dh_raw}\" (expected Standard or Modified)")
    dh_type = matches[0]
    joints = _joint_nodes(root)
    length = units.length * scale
    links: list[LinkModel] = []
    index: dict[str, int] = {}
    for k, joint in enumerate(joints):
        link = _read_link(joint, k, links, index, dh_type, units, length, path)
        if link.name in index:
            raise joint.error(f"a second joint named \"{link.name}\"")
        index[link.name] = len(links)
        links.append(link)
    controls = None
    cs = root.find("ControlSet")
    if cs is not None:
        controls = parse_control_set(cs)
    return RobotModel(name=name, links=links, source=str(path), kind="rob", dh_type=dh_type,
                      controls=controls, ignored=_planner_weights(root, joints, path),
                      free_base=root.get("robType", "").strip().lower() == "freeflying")


def _joint_nodes(root: Node) -> list:
    """The robot's ``<Joint>`` elements: those of its ``<Joints>``, or (the 2009 files) those
    directly under ``<Robot>``."""
    joints_node = root.find("Joints")
    wrapped = list(joints_node.findall("Joint")) if joints_node is not None else []
    bare = list(root.findall("Joint"))
    if wrapped and bare:
        raise bare[0].error("<Joint> elements both inside <Joints> and directly under <Robot>: "
                            "which are the robot's is ambiguous")
    if not (wrapped or bare):
        raise root.error("has no <Joints> with <Joint> elements (nor <Joint> elements "
                         "directly under <Robot>)")
    return wrapped or bare


def _planner_weights(root: Node, joints: list, path: pathlib.Path) -> list:
    """One Ignored entry per kind of planner weight the file gives."""
    out = []
    weights = [j.find("Weight") for j in joints if j.find("Weight") is not None]
    if weights:
        out.append(Ignored(str(path), weights[0].line, f"<Weight> ({len(weights)} joints)",
                           "a planner's weight of the joint in distances, not a mass: links "
                           "get the default mass"))
    se3 = root.find("WeightSE3")
    if se3 is not None:
        out.append(Ignored(str(path), se3.line, "<WeightSE3>", "a planner's weights of the "
                           "base in distances"))
    return out


def _read_link(joint: Node, k: int, links: list, index: dict, dh_type: str, units: Units,
               length: float, path: pathlib.Path) -> LinkModel:
    name = joint.require("name")
    desc = joint.find("Description")
    rotational = desc.flag("rotational", True) if desc is not None else True
    movable = desc.flag("movable", True) if desc is not None else True
    base = k == 0            # the base: never a joint (module docstring)
    kind = FIXED if base or not movable else (REVOLUTE if rotational else PRISMATIC)
    dh = joint.find("DHPars")
    if dh is not None:
        alpha = dh.number("alpha", 0.0) * units.angle
        theta = dh.number("theta", 0.0) * units.angle
        a, d = (float(v) for v in dh.scaled_lengths(
            "<DHPars a d>", (dh.number("a", 0.0), dh.number("d", 0.0)), length))
    else:
        alpha = a = theta = d = 0.0
    pre_trans = np.eye(4)
    pt = joint.find("PreTrans")
    if pt is not None:
        pre_trans = pose_from_axis_angle(
            pt.scaled_lengths("<PreTrans X Y Z>",
                              [pt.number(c, 0.0) for c in ("X", "Y", "Z")], length),
            [pt.number(c, 0.0) for c in ("WX", "WY", "WZ")],
            pt.number("TH", 0.0) * units.angle)
    if dh_type == "Standard":
        pre = pre_trans @ rot_z(theta)
        post = translation(0, 0, d) @ translation(a, 0, 0) @ rot_x(alpha)
        if kind == PRISMATIC:
            pre, post = pre @ translation(0, 0, d), translation(a, 0, 0) @ rot_x(alpha)
    else:
        pre = pre_trans @ rot_x(alpha) @ translation(a, 0, 0) @ rot_z(theta)
        post = translation(0, 0, d)
        if kind == PRISMATIC:
            pre, post = pre @ translation(0, 0, d), np.eye(4)
    limits = None
    lim = joint.find("Limits")
    if lim is not None and kind != FIXED:
        factor = units.angle if kind == REVOLUTE else length
        low, high = (float(v) for v in lim.scaled_lengths(
            "<Limits Low Hi>", (lim.number("Low"), lim.number("Hi")), factor,
            "rad" if kind == REVOLUTE else "m"))
        if low > high:
            raise lim.error(f"Low={lim.get('Low')} is above Hi={lim.get('Hi')}")
        limits = (low, high)
    planner_weight = None
    weight = joint.find("Weight")
    if weight is not None:
        try:
            planner_weight = float(weight.get("weight", "").strip())
        except ValueError:
            planner_weight = None      # unused by Odin: a quirk there never stops a load
    parent_node = joint.find("Parent")
    if parent_node is None:
        parent = len(links) - 1 if links else None
    else:
        pname = (parent_node.get("name") or "").strip()
        if not pname:
            parent = None
            if links:
                raise parent_node.error(f"joint \"{name}\" has an empty parent but is not "
                                        "the first joint")
        elif pname not in index:
            raise parent_node.error(f"parent \"{pname}\" of joint \"{name}\" is not a joint "
                                    "defined before it")
        else:
            parent = index[pname]
    iv = joint.get("ivFile")
    shape = None
    if iv:
        shape = read_shape(path.parent / iv, length)
    return LinkModel(name=name, parent=parent, pre=pre, post=post, joint=kind,
                     limits=limits, shape=shape, source=str(path), line=joint.line,
                     joint_name=name, planner_weight=planner_weight)


def read_shape_robot(path: pathlib.Path, scale: float, units: Units) -> RobotModel:
    """A robot or obstacle given as a bare geometry file: one free link."""
    shape = read_shape(path, units.length * scale)
    link = LinkModel(name=path.stem, parent=None, pre=np.eye(4), post=np.eye(4),
                     shape=shape, source=str(path))
    return RobotModel(name=path.stem, links=[link], source=str(path), kind="shape")
