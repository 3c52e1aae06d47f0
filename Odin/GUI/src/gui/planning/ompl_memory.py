"""The values of OMPL's real-vector states as numpy arrays over OMPL's own memory (ROS-free).

OMPL's Python wheel (2.0.1, nanobind) reads and writes a state one value per call: a control
planner's propagation moves the world's whole body state vector (a few hundred values) into
and out of OMPL's states every step, and those calls cost as much as the ODE step itself
(docs/PERFORMANCE.md). A ``RealVectorStateSpace::StateType`` holds a ``double *values`` to
its ``dimension`` values; ``values(state, n)`` answers a numpy array over them, so that a
state is read and written by one copy.

How the pointer is found, and why it is safe to use:
- a nanobind instance (nanobind's ``nb_inst``) begins with the Python object header (16 bytes
  on 64-bit CPython), then an ``int32`` offset and a ``uint32`` of flags whose bit 2
  (``direct``) says whether the C++ object lies at the instance's address plus the offset,
  or a pointer to it does;
- OMPL's ``State`` has a virtual destructor: its subclasses begin with a vtable pointer;
  ``RealVectorStateSpace::StateType`` then holds ``values``, and ``CompoundState`` its
  ``components``.
These are facts of the wheel pinned in tools/requirements.txt (``KNOWN_WHEEL``), on 64-bit
CPython: under any other the bridge copies value by value as before. ``LayoutProbe.holds``
checks them again before a search uses them: a state of the search's own space written value
by value through the wheel is read back through the arrays, and written through the arrays is
read back value by value; any difference, and the bridge copies value by value. The arrays are only
used during a callback, while OMPL holds the state alive.
"""
from __future__ import annotations

import ctypes
import platform
import sys
from importlib import metadata

import numpy as np

KNOWN_WHEEL = "2.0.1"
"""The OMPL wheel whose objects' layout is the module docstring's (tools/requirements.txt)."""
HEADER_BYTES = 16
"""A CPython object's header on a 64-bit build (reference count, type): nanobind's fields
follow it."""
DIRECT_FLAG = 1 << 2
"""nb_inst's ``direct`` bit: the C++ object lies inside the Python object."""
VALUES_OFFSET = 8
"""Bytes from a State's start to its first member (after the vtable pointer)."""

_int32 = ctypes.c_int32.from_address
_uint32 = ctypes.c_uint32.from_address
_pointer = ctypes.c_void_p.from_address


def _cpp_address(wrapper) -> int:
    """The address of the C++ object a nanobind instance wraps."""
    address = id(wrapper)
    at = address + _int32(address + HEADER_BYTES).value
    if _uint32(address + HEADER_BYTES + 4).value & DIRECT_FLAG:
        return at
    return _pointer(at).value


def values(state, size: int) -> np.ndarray:
    """(size,) float64 over the values of ``state`` (a ``RealVectorStateType`` wrapper):
    writing it writes the state. Valid while OMPL keeps the state; only after
    ``LayoutProbe.holds`` said yes."""
    array = (ctypes.c_double * size).from_address(
        _pointer(_cpp_address(state) + VALUES_OFFSET).value)
    return np.frombuffer(array)


class LayoutProbe:
    """Whether ``values`` reads OMPL's states as the wheel's own calls do, for a compound
    space of real-vector components (checked once per space; module docstring)."""

    @staticmethod
    def holds(space, sizes) -> bool:
        """True when every component k of a state of ``space`` (sizes[k] values each) reads
        and writes through ``values`` exactly as through the wheel's indexing."""
        if sys.implementation.name != "cpython" or platform.architecture()[0] != "64bit":
            return False
        try:
            if metadata.version("ompl") != KNOWN_WHEEL:
                return False
        except metadata.PackageNotFoundError:
            return False
        state = space.allocState()      # the wrapper owns it (nanobind deletes it)
        for k, size in enumerate(sizes):
            component = state[k]
            written = np.arange(1.0, size + 1.0) * (0.5 + k)
            for i, value in enumerate(written.tolist()):
                component[i] = value
            if not np.array_equal(values(component, size), written):
                return False
            values(component, size)[:] = -written
            if [component[i] for i in range(size)] != (-written).tolist():
                return False
        return True


__all__ = ["KNOWN_WHEEL", "LayoutProbe", "values"]
