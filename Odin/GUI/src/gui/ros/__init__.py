"""The GUI's ROS layer: the typed client of the VirtualWorld's services (``client``)."""
