"""ROS-free pieces every Odin node and tool shares: the exception root, the interface's
constants and tables (``interface``), quaternions (``rotations``), request specs (``specs``),
the world parameters (``world_parameters``) and mesh simplification (``meshes``)."""
from odin_common.errors import InvalidArgument, OdinError

__all__ = ["OdinError", "InvalidArgument"]
