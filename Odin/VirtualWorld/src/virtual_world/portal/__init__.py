"""The VirtualWorld node's ROS layer (Portal): servers, publishers and the Viewer link over the
ROS-free Core (``virtual_world.core``). ``main()`` is ``rosrun VirtualWorld virtualWorld``."""
from virtual_world.portal.node import Portal, main

__all__ = ["Portal", "main"]
