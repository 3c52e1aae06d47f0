"""ROS-free pieces every Odin node and tool shares: the exception root, the interface's
constants and tables (``interface``), quaternions (``rotations``), request specs (``specs``),
the world parameters (``world_parameters``), mesh simplification (``meshes``) and how a
Portal answers a service (``replies``)."""
from odin_common.errors import InvalidArgument, OdinError

__all__ = ["OdinError", "InvalidArgument"]
