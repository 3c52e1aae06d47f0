"""ROS-free pieces every Odin node and tool shares: the exception root, the interface's
constants and tables (``interface``), quaternions (``rotations``), request specs (``specs``),
the world parameters (``world_parameters``), mesh simplification (``meshes``) and how a
Portal answers a service (``replies``)."""
import os

# Odin's matrices are 3x3 and 4x4. Debian's OpenBLAS starts a thread pool for every call, and
# on a busy 2-core host a 4x4 inverse then waits 1.4 ms for its threads instead of taking 5 us
# (measured: numpy.linalg.inv, two per planning propagation, was 85 % of a planner's time
# under load). The pool's size is read once, when numpy first loads the library: every Odin
# node and tool imports this package before numpy. A user's own setting wins.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from odin_common.errors import InvalidArgument, OdinError  # noqa: E402

__all__ = ["OdinError", "InvalidArgument"]
