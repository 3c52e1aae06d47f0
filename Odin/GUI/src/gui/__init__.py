"""Odin's GUI package.

The Core (everything here but ``client``) is ROS-free and Qt-free: it loads Kautham problems,
robots, shapes and paths, and turns them into plain request data (``gui.build``). ``gui.client``
is the thin rospy layer that sends those requests to the VirtualWorld; ``gui.cli`` holds the
``problem_info``, ``load_problem`` and ``run_path`` tools.
"""
