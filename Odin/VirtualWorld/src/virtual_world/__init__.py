"""Odin's physics node: a ROS-free Core over libode (``virtual_world.core``, ``virtual_world.ode``)
and its ROS Portal (``virtual_world.portal``)."""
from odin_common.blas import use_reference_blas

use_reference_blas()  # before anything imports numpy (odin_common.blas: why, and who calls it)
