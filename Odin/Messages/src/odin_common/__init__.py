"""ROS-free pieces every Odin node and tool shares: the exception root, the interface's
constants and tables (``interface``), quaternions (``rotations``), request specs (``specs``),
the world parameters (``world_parameters``), mesh simplification (``meshes``) and how a
Portal answers a service (``replies``). Importing it makes numpy use the reference BLAS
(``blas``)."""
from odin_common.blas import use_reference_blas

use_reference_blas()      # before anything imports numpy: the same numbers on every machine

from odin_common.errors import InvalidArgument, OdinError  # noqa: E402

__all__ = ["OdinError", "InvalidArgument"]
