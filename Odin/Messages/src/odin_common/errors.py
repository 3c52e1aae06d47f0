"""The root of every exception Odin raises on purpose.

Each package derives its own meaningful subclasses (a bad request, a file that does not parse,
an ODE configuration that does not fit); a Portal turns any ``OdinError`` into a service answer
``success: false`` with ``str(error)`` as the message.
"""


class OdinError(Exception):
    """Something the caller asked for, or a file it gave, cannot be done or read.

    The message says what was wrong, with the offending value and where it came from.
    """


class InvalidArgument(OdinError, ValueError):
    """A value is malformed: not finite, out of its range, the wrong count, not a unit
    quaternion... Raised by the checks every node shares (``odin_common``); each node's own
    errors of this kind derive from it."""


class NoMasterError(OdinError):
    """No ROS master answered at ROS_MASTER_URI in the time a tool waits for one (nodes wait
    for theirs for ever; ``odin_common.node.wait_for_master``)."""
