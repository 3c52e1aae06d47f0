"""Odin's physics node: a ROS-free Core over libode (``virtual_world.core``, ``virtual_world.ode``)
and its ROS Portal (``virtual_world.portal``)."""
import odin_common  # noqa: F401  (first: numpy on the reference BLAS, odin_common.blas)
