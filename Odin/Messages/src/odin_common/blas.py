"""The same numbers on every machine: Odin's numpy runs on Debian's reference BLAS and LAPACK,
whichever implementation the machine has chosen for everything else.

Debian lets one BLAS stand in for another (update-alternatives ``libblas.so.3``): installing
python3-scipy or python3-matplotlib brings OpenBLAS, which then outranks the reference
library for every program. OpenBLAS's kernels round differently (fused multiply-adds, other
summation orders), so the 4x4 products and inverses that place links and turn controls into
forces differ in their last bits, and contact physics turns last bits into other outcomes:
the thesis's grasp released its can 40 ms later and KPIECE1 found another car plan on the same
machine once OpenBLAS came in. Odin's promise (a seed repeats a plan bit for bit, on any
worker of a benchmark) needs one arithmetic, and Odin's matrices are 3x3 and 4x4, where the
reference library is also the fastest (OpenBLAS wakes a thread pool for each call: 1.4 ms for
a 4x4 inverse on a busy 2-core host instead of 5 us).

How: the reference libraries are loaded by path, globally, before numpy. numpy's extensions ask
for ``libblas.so.3`` and ``liblapack.so.3`` by soname, and the dynamic loader hands them the
libraries of that soname already loaded. A process that imported numpy first keeps the
machine's choice (:func:`in_use` says which). ``OPENBLAS_NUM_THREADS`` is set to 1 as well, for
a process where OpenBLAS is loaded all the same.

Who calls :func:`use_reference_blas`, first thing: the ``__init__`` of each node package
(``virtual_world``, ``viewer``, ``gui``), which every process that computes with Odin imports
before numpy (a node, a tool, a test, a Dask worker unpickling a search: workers start no
entry point of Odin's); the repository's ``conftest.py``; and the tools that import numpy
before any of those packages (``tools/bench/run.py``, ``tools/corpus/corpus_checks.py``,
``tools/experiments/common.py``). Importing ``odin_common`` itself loads nothing: a process
that only reads the interface's facts keeps its libraries.
"""
from __future__ import annotations

import ctypes
import os
import sys
import sysconfig
from typing import List, Optional

LIBRARIES = ("blas/libblas.so.3", "lapack/liblapack.so.3")
"""Debian's reference BLAS and LAPACK (packages libblas3, liblapack3), under /usr/lib/<arch>."""

BLAS_LIBRARY_NAMES = ("libblas.", "libopenblas", "libblis", "libmkl_rt", "libatlas")
"""How the BLAS libraries a numpy may run on are named (not Python modules such as
scipy's ``cython_blas``)."""

_loaded: List[ctypes.CDLL] = []


def reference_paths() -> List[str]:
    """The reference libraries' paths on this machine (those that exist)."""
    arch = sysconfig.get_config_var("MULTIARCH") or ""
    folder = os.path.join("/usr/lib", arch) if arch else "/usr/lib"
    return [p for p in (os.path.join(folder, name) for name in LIBRARIES) if os.path.exists(p)]


def use_reference_blas() -> bool:
    """Loads the reference BLAS and LAPACK for numpy to use; True when numpy will use them
    (False: numpy was imported already, or the libraries are not installed)."""
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    if _loaded:
        return True
    if "numpy" in sys.modules:
        return False
    paths = reference_paths()
    if len(paths) != len(LIBRARIES):
        return False
    try:
        _loaded.extend(ctypes.CDLL(p, mode=ctypes.RTLD_GLOBAL) for p in paths)
    except OSError:
        return False
    return True


def in_use() -> Optional[str]:
    """The BLAS library this process has loaded (its path, from /proc/self/maps), or None."""
    try:
        with open("/proc/self/maps") as maps:
            lines = maps.read().splitlines()
    except OSError:
        return None
    for line in lines:
        path = line.split()[-1] if line.split() else ""
        if os.path.basename(path).startswith(BLAS_LIBRARY_NAMES):
            return os.path.realpath(path)
    return None
