"""Odin's numpy computes with Debian's reference BLAS and LAPACK whichever BLAS the machine
prefers (odin_common.blas): on this machine OpenBLAS came in with python3-matplotlib and
outranked the reference library, and the thesis's grasp then released its can 40 ms late."""
import subprocess
import sys

import pytest

from odin_common import blas

NEEDS_REFERENCE = pytest.mark.skipif(len(blas.reference_paths()) != 2,
                                     reason="Debian's libblas3 and liblapack3 are not installed")

PROBE = """
import {first}
import numpy
from odin_common.blas import in_use
a = numpy.arange(16.0).reshape(4, 4) + numpy.eye(4) * 7.3
print(in_use())
print((a @ numpy.linalg.inv(a)).tobytes().hex())
"""


#: what a process does to put numpy on the reference libraries (the node packages do it first)
PINNED = "odin_common.blas; odin_common.blas.use_reference_blas()"


def _probe(first: str) -> list:
    run = subprocess.run([sys.executable, "-c", PROBE.format(first=first)], capture_output=True,
                         text=True, timeout=60)
    assert run.returncode == 0, run.stderr
    return run.stdout.split()


@NEEDS_REFERENCE
@pytest.mark.parametrize("first", [PINNED, "gui.core.kinematics", "virtual_world.core",
                                   "viewer.core.camera"])
def test_importing_odin_first_puts_numpy_on_the_reference_libraries(first):
    library, _ = _probe(first)
    assert library.startswith(tuple(p.rsplit("/", 1)[0] for p in blas.reference_paths())), \
        library


@NEEDS_REFERENCE
def test_the_numbers_are_the_reference_libraries_own():
    """The same product and inverse, bit for bit, as a process that loads nothing but the
    reference libraries (what the machine's default BLAS may differ from)."""
    _, odin = _probe(PINNED)
    env_first = "ctypes; [ctypes.CDLL(p, mode=ctypes.RTLD_GLOBAL) for p in {!r}]".format(
        blas.reference_paths())
    _, reference = _probe(env_first)
    assert odin == reference


def test_numpy_imported_first_is_said_not_hidden():
    run = subprocess.run([sys.executable, "-c", "import numpy, odin_common.blas as b; "
                          "print(b.use_reference_blas())"], capture_output=True, text=True,
                         timeout=60)
    assert run.stdout.split() == ["False"], run.stderr


@NEEDS_REFERENCE
def test_importing_odin_common_alone_loads_no_library():
    """The floor of facts changes nothing in a process that only reads them: the reference
    libraries come with the node packages' explicit call."""
    run = subprocess.run([sys.executable, "-c", "import sys, odin_common.interface, "
                          "odin_common.blas as b; print(b.in_use(), 'numpy' in sys.modules)"],
                         capture_output=True, text=True, timeout=60)
    assert run.stdout.split() == ["None", "False"], run.stderr
