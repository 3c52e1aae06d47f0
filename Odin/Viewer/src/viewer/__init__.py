"""Odin's Viewer: renders the world's scene off-screen (OSMesa) and publishes the frames.

``viewer.core`` is ROS-free (shapes and poses, camera, scene, OSMesa renderer, the render
thread, PNG snapshots); ``viewer.portal`` is the ROS node over it (``main()``).
"""

from odin_common.blas import use_reference_blas

use_reference_blas()  # before anything imports numpy (odin_common.blas: why, and who calls it)
