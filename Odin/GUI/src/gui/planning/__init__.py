"""Physics-based planning: OMPL's control planners solve Kautham's physics problems through
Odin's world (issue 17; docs/PLANNING.md).

- ``gui.planning.problem``: what a loaded problem asks of a planner, OMPL-free and ROS-free:
  the robot's bodies, the bounds of its base from the problem's limits, the control size
  (the `.cntr`'s [0, 1]^k), the goal region from the query's ``<Goal>``, the contacts that
  invalidate a motion (Kautham's rule), and the settings of a search.
- ``gui.planning.backend``: the ``Backend`` interface (propagate a batch of (state, control)
  pairs: restore, apply the control for its duration, read the result) and ``CoreBackend``,
  the VirtualWorld's Core in this process.
- ``gui.planning.pool``: ``PoolBackend``, the back end over a pool of world nodes
  (``gui.ros.pool.WorldPool``): the one module of this package that uses ROS, through gui.ros
  only, imported only when a pool is asked for.
- ``gui.planning.bridge``: OMPL's state space, control space, propagator, validity checker,
  goal region and planners over a back end; ``plan()`` answers a ``PlanResult`` whose rows
  are a Kautham control path (``gui.core.control_path.write_control_path``).
"""
