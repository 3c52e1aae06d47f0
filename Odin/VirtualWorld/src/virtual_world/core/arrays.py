"""Message arrays as numpy arrays, fast.

A numpy request's array field (odin_common.node.numpy_requests) is taken as it is.

A deserialised float64[] or uint32[] field is a tuple of Python numbers. numpy converts such a
tuple one object at a time (~18 ms for the 270,000 vertex coordinates of the TX90 + hand,
~20 ms more for its 545,000 indices); ``array.array`` reads it in one C loop, about four times
faster, and numpy then takes its buffer as it is. The values are the same bit for bit: both
convert each Python number to a C double (or unsigned int) the same way.

One Build Entity hands the same tuple to the Core's checks, its markers and its size, so the
arrays of the tuples converted last are kept (read-only), by the tuple itself: a tuple cannot
change, and holding it keeps its identity from being reused.
"""
from __future__ import annotations

import array
import collections
import threading
from typing import Optional, Tuple

import numpy as np


def float64_array(values) -> Optional[np.ndarray]:
    """``values`` (a flat tuple or list of Python numbers, or a float64 array: flattened, not
    copied) as a float64 array; None when they are anything else (the caller converts them as
    before, with its own errors)."""
    return _converted(values, "d", np.float64)


def flat_float64(values) -> np.ndarray:
    """``values`` as a flat float64 array: float64_array's when it gives one, else numpy's."""
    converted = float64_array(values)
    return np.asarray(values, dtype=float).reshape(-1) if converted is None else converted


def uint32_array(values) -> Optional[np.ndarray]:
    """``values`` (a flat tuple or list of Python ints in [0, 2**32), or a uint32 array:
    flattened, not copied) as a uint32 array; None when they are anything else (floats,
    negatives, nested sequences, arrays of other types)."""
    return _converted(values, "I", np.uint32)


#: numbers whose arrays are kept at most (the TX90 + hand's entity: ~820,000); the tuples
#: kept are those the Core's geometries hold anyway while they are built
KEPT_NUMBERS = 1_500_000


class _Kept:
    """The arrays of the tuples converted last, least recently used first (any thread: two
    Cores may build at once)."""

    def __init__(self) -> None:
        self.arrays: "collections.OrderedDict[Tuple[int, str], Tuple[tuple, np.ndarray]]" = \
            collections.OrderedDict()
        self.numbers = 0
        self._lock = threading.Lock()

    def get(self, values: tuple, typecode: str) -> Optional[np.ndarray]:
        key = (id(values), typecode)
        with self._lock:
            kept = self.arrays.get(key)
            if kept is None or kept[0] is not values:
                return None
            self.arrays.move_to_end(key)
            return kept[1]

    def put(self, values: tuple, typecode: str, converted: np.ndarray) -> None:
        key = (id(values), typecode)
        with self._lock:
            old = self.arrays.pop(key, None)     # a tuple gone, its identity reused
            self.numbers += len(values) - (len(old[0]) if old is not None else 0)
            self.arrays[key] = (values, converted)
            while len(self.arrays) > 1 and self.numbers > KEPT_NUMBERS:
                self.numbers -= len(self.arrays.popitem(last=False)[1][0])


_kept = _Kept()


def _converted(values, typecode: str, dtype) -> Optional[np.ndarray]:
    kind = type(values)
    if kind is np.ndarray:       # a numpy request's field (odin_common.node.numpy_requests)
        return values.reshape(-1) if values.dtype == dtype else None
    if kind is tuple:
        converted = _kept.get(values, typecode)
        if converted is not None:
            return converted
    elif kind is not list:
        return None
    try:
        converted = np.frombuffer(array.array(typecode, values), dtype=dtype)
    except (TypeError, OverflowError, ValueError):
        return None
    if kind is tuple:
        converted.flags.writeable = False
        _kept.put(values, typecode, converted)
    return converted
