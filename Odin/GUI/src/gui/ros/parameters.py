"""The GUI node's ``~parameters`` (``rosrun GUI gui``), as data: the window reads them and
tools/interface_doc.py writes docs/parameters.md from them. ROS-free."""
from __future__ import annotations

from typing import Tuple

from odin_common.interface import VIEWER_NAMESPACE, WORLD_NAMESPACE, NodeParameter

NODE_PARAMETERS: Tuple[NodeParameter, ...] = (
    NodeParameter("world", WORLD_NAMESPACE, "-", "namespace of the world's services and topics"),
    NodeParameter("viewer", VIEWER_NAMESPACE, "-", "namespace of the Viewer's image topic"),
)

DEFAULTS = {p.name: p.default for p in NODE_PARAMETERS}
