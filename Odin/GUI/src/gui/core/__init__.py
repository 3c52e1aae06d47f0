"""The GUI's Core, ROS-free and Qt-free: Kautham problems, robots, shapes and paths
(``kautham``, ``model``, ``shapes``, ``kinematics``, ``paths``) and the build plans that turn a
problem into the world's requests (``build``)."""
