"""What every reader of a Kautham robot file does first, whatever its format (a .rob/.dh file,
``gui.core.kautham.robot_rob``; a URDF, ``gui.core.kautham.urdf``): parse the file, check the
problem's scale, check the root element and name the robot."""
from __future__ import annotations

import pathlib
from typing import Optional

from gui.core.kautham.units import scale_problem
from gui.core.kautham.xmlfile import Node, read_xml


def read_robot_root(path: pathlib.Path, what: str, tag: str, scale: float,
                    lenient: Optional[list] = None) -> tuple[Node, str]:
    """The root element of the robot file ``path`` and the robot's name (its ``name=``, else
    the file's stem). ``what``: the kind of file its errors name; ``tag``: the root element of
    the format; ``scale``: the problem's factor of the robot's lengths (refused as
    ``units.scale_problem`` says); ``lenient``: as ``xmlfile.read_xml``'s. Errors are
    ``ProblemError``s naming the file and line."""
    root = read_xml(path, what, lenient)
    problem = scale_problem(scale)
    if problem is not None:
        raise root.error(f"scale {scale!r} {problem}")
    if root.tag != tag:
        raise root.error(f"expected a <{tag}> element, found <{root.tag}>")
    return root, root.get("name") or path.stem
