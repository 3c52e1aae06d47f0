"""Odin's Viewer: renders the world's scene off-screen (OSMesa) and publishes the frames.

Modules: ``geometry`` (shapes, poses, the one (w, x, y, z) quaternion conversion), ``camera``,
``scene`` (the ROS-free Core), ``renderer`` (OSMesa + fixed-function OpenGL), ``loop`` (the
render thread that owns the GL context), ``snapshots`` (PNG files inside ``~snapshot_dir``) and
``portal`` (the ROS node; ``main()``).
"""
