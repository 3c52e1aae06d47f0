"""The GUI window's process as the ROS node ``gui`` (``rosrun GUI gui``): started, its
``~parameters`` read (gui.ros.parameters), ended. No Qt; the window (gui.window) calls these
so that it never touches rospy itself.
"""
from __future__ import annotations

from typing import Any, Dict, List, Optional, Sequence

from gui.ros.parameters import NODE_PARAMETERS


def without_remappings(argv: Sequence[str]) -> List[str]:
    """``argv`` without the ROS remappings and private parameters (``__ns:=``, ``_world:=``),
    for Qt's own argument parsing."""
    import rospy
    return rospy.myargv(list(argv))


def join_as_gui(name: str = "gui", master_timeout: Optional[float] = None) -> None:
    """This process as the ROS node ``name`` (not anonymous: one window per name), once the
    master answers (within ``master_timeout`` s, else odin_common.errors.NoMasterError);
    Ctrl-C is left to the window."""
    from odin_common.node import init_ros_node
    init_ros_node(name, disable_signals=True, master_timeout=master_timeout)


def start_gui_node(name: str = "gui", master_timeout: Optional[float] = None
                   ) -> Dict[str, Any]:
    """``join_as_gui(name, master_timeout)``, registered again with a master that restarts
    (MasterWatch); returns its ``~parameters`` {name: value}, each its default when not set."""
    import rospy

    from odin_common.node import MasterWatch
    join_as_gui(name, master_timeout)
    MasterWatch()
    return {p.name: rospy.get_param(f"~{p.name}", p.default) for p in NODE_PARAMETERS}


def stop_gui_node(reason: str) -> None:
    """Ends the node (its subscriptions, services and connections)."""
    import rospy
    rospy.signal_shutdown(reason)
