"""ROS-free pieces every Odin node and tool shares: the exception root, the interface's
constants and tables (``interface``), the tuning constants (``defaults``), quaternions
(``rotations``), request specs (``specs``), the world parameters (``world_parameters``), mesh
simplification (``meshes``) and how a Portal answers a service (``replies``). Importing it
changes nothing in the process: the reference BLAS is the node packages' explicit call
(``blas.use_reference_blas``)."""
from odin_common.errors import InvalidArgument, OdinError

__all__ = ["OdinError", "InvalidArgument"]
