"""Kautham's control sets: the ``<ControlSet>`` of a .rob file and the current ``.cntr`` files.

    <ControlSet> <Offset><DOF name value/>...</Offset>
                 <Control name eigValue><DOF name value/>...</Control>... </ControlSet>

DOF names are joint names, in ``.cntr`` files prefixed by the robot's name ("TX90/link_1").
Odin uses the control set only to describe a robot; paths give joint values directly.
"""
from __future__ import annotations

import pathlib

from gui.core.kautham.xmlfile import Node, read_xml
from gui.core.model import ControlSet


def parse_control_set(node: Node) -> ControlSet:
    offset = {}
    off = node.find("Offset")
    if off is not None:
        for dof in off.findall("DOF"):
            offset[dof.require("name")] = dof.number("value")
    controls = []
    for control in node.findall("Control"):
        values = {dof.require("name"): dof.number("value") for dof in control.findall("DOF")}
        controls.append((control.get("name", ""), values))
    return ControlSet(offset=offset, controls=controls, source=node.path)


def read_cntr(path: pathlib.Path) -> ControlSet:
    root = read_xml(path, "control file")
    if root.tag != "ControlSet":
        raise root.error(f"expected a <ControlSet> element, found <{root.tag}>")
    return parse_control_set(root)
