"""Odin's GUI package: Kautham problems and paths turned into the world's requests.

Layers, each a sub-package: ``gui.core`` is ROS-free and Qt-free (Kautham loaders, robot models,
shapes, kinematics, build plans, path files); ``gui.ros`` is the rospy client of the world's
services; ``gui.window`` is the Qt window, which talks to the world only through that client.
``gui.tools`` holds the executables, one module each (``problem_info``, ``load_problem``,
``run_path``, ``plan``, ``benchmark``).
"""

from odin_common.blas import use_reference_blas

use_reference_blas()  # before anything imports numpy (odin_common.blas: why, and who calls it)
