"""Odin's GUI package: Kautham problems and paths turned into the world's requests.

Layers, each a sub-package: ``gui.core`` is ROS-free and Qt-free (Kautham loaders, robot models,
shapes, kinematics, build plans, path files); ``gui.ros`` is the rospy client of the world's
services; ``gui.window`` is the Qt window, which talks to the world only through that client.
``gui.cli`` holds the ``problem_info``, ``load_problem`` and ``run_path`` tools.
"""

import odin_common  # noqa: F401,E402  (first: numpy on the reference BLAS, odin_common.blas)
