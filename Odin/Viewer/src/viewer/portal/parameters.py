"""The Viewer node's ``~parameters`` (read once at start), as data: the Portal reads them and
tools/interface_doc.py writes docs/parameters.md from them. ROS-free."""
from __future__ import annotations

from typing import Tuple

from odin_common.interface import WORLD_NAMESPACE, NodeParameter
from viewer.core.scene import DEFAULT_BACKGROUND

NODE_PARAMETERS: Tuple[NodeParameter, ...] = (
    NodeParameter("rate", 25.0, "Hz",
                  "frames per second, rendered while an image topic has a subscriber"),
    NodeParameter("width", 640, "px", "image width (16..4096)"),
    NodeParameter("height", 480, "px", "image height (16..4096)"),
    NodeParameter("fov_y", 0.8, "rad", "vertical field of view"),
    NodeParameter("world", WORLD_NAMESPACE, "-", "namespace of the world's topics"),
    NodeParameter("eye", None, "m", "camera position, world frame; with `~target`: a fixed "
                  "camera (unset: it re-fits to the whole scene whenever an object is added)"),
    NodeParameter("target", None, "m", "point the camera looks at, world frame"),
    NodeParameter("up", [0.0, 0.0, 1.0], "-", "camera up vector, world frame (z is up, REP 103)"),
    NodeParameter("background", list(DEFAULT_BACKGROUND), "-", "r, g, b in [0, 1]"),
    NodeParameter("snapshot_dir", "$ROS_HOME/odin_snapshots", "-",
                  "folder of Save Snapshot files and numbered frames (created if missing)"),
    NodeParameter("snapshot_every", 0, "frames",
                  "0 = off; N = write `frame_NNNNNN.png` every N rendered frames"),
)
"""The Viewer's parameters, in documentation order."""

DEFAULTS = {p.name: p.default for p in NODE_PARAMETERS}
