"""The world node's own ``~parameters`` (read once at start), as data: the Portal reads them
and tools/interface_doc.py writes docs/parameters.md from them. ROS-free.

Besides these, every world parameter (odin_common.world_parameters) is a ``~parameter`` of the
same name.
"""
from __future__ import annotations

from typing import Tuple

from odin_common.interface import VIEWER_NAMESPACE, NodeParameter
from odin_common.limits import ResourceLimits
from virtual_world.core.step_values import StepValues

_STEP = StepValues()
_RESOURCES = ResourceLimits()

NODE_PARAMETERS: Tuple[NodeParameter, ...] = (
    NodeParameter("rate", _STEP.rate, "Hz", "Portal cycles (publications) per wall-clock second"),
    NodeParameter("step", _STEP.step, "s", "simulated time of one ODE step"),
    NodeParameter("steps_per_cycle", _STEP.steps_per_cycle, "-",
                  "ODE steps per cycle (cycle time = step x steps)"),
    NodeParameter("simulate", False, "-", "start simulating at once"),
    NodeParameter("free_run", False, "-",
                  "cycles back to back (batch work); publications still at `~rate`"),
    NodeParameter("viewer", VIEWER_NAMESPACE, "-", "namespace of the Viewer's services"),
    NodeParameter("record", "", "-", "a rosbag file to record every state-changing request "
                  "and every advance into (`rosrun VirtualWorld replay FILE` re-runs it); "
                  "empty: no recording. Written as FILE.active and renamed onto FILE when "
                  "the node closes it; a full disk stops the recording and leaves FILE as it "
                  "was"),
    NodeParameter("push_speed", 0.5, "m/s", "velocity an interactive marker's Push adds to an "
                  "object (RViz, docs/ROS.md)"),
    NodeParameter("max_objects", _RESOURCES.max_objects, "-",
                  "objects the world may hold (a composite counts once); more are refused"),
    NodeParameter("max_mesh_triangles", _RESOURCES.max_mesh_triangles, "-",
                  "triangles of one mesh; a larger one is refused"),
    NodeParameter("max_snapshots", _RESOURCES.max_snapshots, "-",
                  "saved states held at a time; Save State of one more is refused"),
    NodeParameter("max_request_mb", _RESOURCES.max_request_mb, "MB",
                  "the largest ROS message the node reads: a larger one is refused from its "
                  "length header, before its body is read (the caller's call fails)"),
)
"""The world node's parameters besides the world parameters, in documentation order."""

DEFAULTS = {p.name: p.default for p in NODE_PARAMETERS}

RESOURCE_PARAMETERS = tuple(f for f in ResourceLimits.__dataclass_fields__)
"""The node parameters that make the world's ResourceLimits (same names)."""
