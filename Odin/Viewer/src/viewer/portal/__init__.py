"""The Viewer node's ROS layer (Portal) over its Core; ``main()`` is ``rosrun Viewer viewer``."""
from viewer.portal.node import Portal, main

__all__ = ["Portal", "main"]
