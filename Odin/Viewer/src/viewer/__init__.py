"""Odin's Viewer: renders the world's scene off-screen (OSMesa) and publishes the frames.

``viewer.core`` is ROS-free (shapes and poses, camera, scene, OSMesa renderer, the render
thread, PNG snapshots); ``viewer.portal`` is the ROS node over it (``main()``).
"""

import odin_common  # noqa: F401,E402  (first: numpy on the reference BLAS, odin_common.blas)
