"""The GUI's ROS layer, the one that talks to nodes (no Qt):

- ``services``: ``ServiceCaller``, calling a node's services by name (proxies, failures as
  ``gui.errors.ServiceError``), and whether a node answers;
- ``client``: ``WorldClient``, the typed client of the VirtualWorld's services;
- ``viewer``: ``ViewerClient``, the typed client of the Viewer's services;
- ``pool``: ``WorldPool``, several world nodes used as one (planning);
- ``topics``: the topics the window reads;
- ``node``: the window's process as the ROS node ``gui``; ``parameters``: its ~parameters.
"""
