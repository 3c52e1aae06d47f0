"""ROS-free pieces every Odin node shares: the exception root and quaternion conventions."""
from odin_common.errors import OdinError

__all__ = ["OdinError"]
