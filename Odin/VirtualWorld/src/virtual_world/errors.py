"""Exceptions of the VirtualWorld Core; every one derives from ``odin_common.OdinError``.

Each is raised *before* any call into ODE (ODE ends the process on bad input), so a raised
error means nothing in the simulation changed. Messages name the offending value.
"""
from odin_common import errors as common


class CoreError(common.OdinError):
    """Root of the VirtualWorld Core's errors."""


class InvalidArgument(CoreError, common.InvalidArgument):
    """A value is malformed: non-finite, out of range, wrong count, bad quaternion, ..."""


class UnknownName(CoreError, KeyError):
    """An id names no object, joint, motor or force."""

    def __str__(self) -> str:  # KeyError would quote the message
        return str(self.args[0]) if self.args else ""


class DuplicateName(CoreError):
    """An id is already taken (or two pieces of one request share a name)."""


class Unsupported(CoreError):
    """The request does not fit the target: e.g. a joint force on a fixed joint."""


class OdeConfigurationError(CoreError):
    """The installed libode does not fit Odin (e.g. single precision)."""


class Closed(CoreError):
    """The Core was closed."""
