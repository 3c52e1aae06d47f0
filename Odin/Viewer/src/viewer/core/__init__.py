"""The Viewer's Core, ROS-free: shapes and poses (``geometry``), the ``camera``, the ``scene``
it draws, the OSMesa ``renderer`` (fixed-function OpenGL), the render ``loop`` (the one thread
that owns the scene and the GL context) and PNG ``snapshots``."""
