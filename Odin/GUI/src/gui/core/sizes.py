"""The one way the GUI reads a file: opened once, checked on the open handle, read with a bound.

A problem names its robot, URDF, geometry, control and path files; any of them may come from
someone else, and may be anything a path can name: a FIFO (an open that blocks for ever), a
character device (``/dev/zero``, ``/dev/urandom``: endless), a directory, a socket, a symbolic
link loop, a sparse file of gigabytes, a ``/proc``-like file whose size says 0 and holds more.
``read_input_file`` is the only reader: every format's reader (XML, VRML/Inventor, STL, OBJ,
Collada, path, control and solution files, benchmarks) parses the bytes it returns, and the
shape cache keys on those same bytes. So:

- the path is ``stat``'ed first and anything that is not a regular file is refused by what it
  is, without opening it (opening some devices does something: a tape rewinds, a watchdog
  arms);
- then it is opened once, ``O_RDONLY | O_NONBLOCK | O_CLOEXEC`` (a FIFO put there meanwhile
  does not block the open), and the *open handle* is checked again (``fstat``): a regular
  file of at most ``odin_common.limits.MAX_INPUT_FILE_MB``;
- then at most that limit plus one byte is read, and a file that turns out longer (it grew, or
  lied about its size) is refused, so memory is bounded whatever the file says.

Errors are the caller's ``ProblemError`` class, naming the file and saying what it is: "not
found", "a symbolic link loop", "not readable (permission denied)", "a directory, not a file",
"a character device, not a file", "larger than the 256 MB the GUI reads"...
"""
from __future__ import annotations

import errno
import os
import stat
from typing import Type

from gui.errors import ProblemError
from odin_common.limits import MAX_INPUT_FILE_MB

_CHUNK = 16 * 2 ** 20          # bytes read per call past what fstat announced

_KINDS = ((stat.S_ISDIR, "a directory"), (stat.S_ISCHR, "a character device"),
          (stat.S_ISBLK, "a block device"), (stat.S_ISFIFO, "a FIFO (named pipe)"),
          (stat.S_ISSOCK, "a socket"))

_OPEN_ERRORS = {
    errno.ENOENT: "not found",
    errno.ELOOP: "is a symbolic link loop (its path never ends at a file)",
    errno.EACCES: "is not readable (permission denied)",
    errno.EPERM: "is not readable (operation not permitted)",
    errno.EISDIR: "is a directory, not a file",
    errno.ENOTDIR: "not found (a part of its path is not a folder)",
    errno.ENAMETOOLONG: "not found (its path is too long)",
    errno.ENXIO: "is a socket or a device without its driver, not a file",
}
"""What an open or stat error means, said after the file's kind ("URDF file ...")."""


def max_input_bytes() -> int:
    """Bytes: the largest file the GUI reads (MAX_INPUT_FILE_MB)."""
    return MAX_INPUT_FILE_MB * 2 ** 20


def _kind_problem(mode: int) -> str | None:
    """What a file of ``mode`` (st_mode) is, when it is not a regular file; else None."""
    if stat.S_ISREG(mode):
        return None
    for test, name in _KINDS:
        if test(mode):
            return f"{name}, not a file"
    return "not a regular file"


def _check(st: os.stat_result, what: str, path: str, error: Type[ProblemError]) -> None:
    kind = _kind_problem(st.st_mode)
    if kind is not None:
        raise error(f"{what} is {kind}", path)
    if st.st_size > max_input_bytes():
        raise error(f"{what} of {st.st_size / 2 ** 20:,.0f} MB is larger than the "
                    f"{MAX_INPUT_FILE_MB} MB the GUI reads", path)


def _open_error(exc: OSError, what: str, path: str, error: Type[ProblemError]) -> ProblemError:
    reason = _OPEN_ERRORS.get(exc.errno, f"cannot be read: {exc.strerror or exc}")
    return error(f"{what} {reason}", path)


def check_input_path(path: os.PathLike | str, what: str,
                     error: Type[ProblemError] = ProblemError) -> None:
    """Raises ``error`` unless ``path`` names a regular file of at most MAX_INPUT_FILE_MB
    (following symbolic links), for a path a library will read itself (Coin's ``Inline``);
    the check is on a ``stat``, so it says nothing of what is there later."""
    p = os.fspath(path)
    try:
        st = os.stat(p)
    except OSError as exc:
        raise _open_error(exc, what, p, error) from None
    _check(st, what, p, error)


def read_input_file(path: os.PathLike | str, what: str,
                    error: Type[ProblemError] = ProblemError) -> bytes:
    """The whole content of ``path``, read as the module docstring says; ``what`` names the
    file in errors ("URDF file"), which are ``error`` (a ProblemError class) with the path."""
    p = os.fspath(path)
    check_input_path(p, what, error)        # refused unopened: a device is never opened
    try:
        fd = os.open(p, os.O_RDONLY | os.O_NONBLOCK | os.O_CLOEXEC)
    except OSError as exc:
        raise _open_error(exc, what, p, error) from None
    try:
        st = os.fstat(fd)
        _check(st, what, p, error)          # what was opened, whatever the path names now
        return _read_bounded(fd, st.st_size, what, p, error)
    finally:
        os.close(fd)


def _read_bounded(fd: int, announced: int, what: str, path: str,
                  error: Type[ProblemError]) -> bytes:
    """At most max_input_bytes() of ``fd``: the ``announced`` size plus one byte in one go
    (a regular file is read whole by one call), then chunks while more arrives."""
    limit = max_input_bytes()
    chunks, total = [], 0
    want = min(announced, limit) + 1
    while True:
        try:
            chunk = os.read(fd, want)
        except OSError as exc:
            raise error(f"{what} cannot be read: {exc.strerror or exc}", path) from None
        if not chunk:
            break
        chunks.append(chunk)
        total += len(chunk)
        if total > limit:
            raise error(f"{what} holds more than the {MAX_INPUT_FILE_MB} MB the GUI reads "
                        f"(it said {announced:,} bytes)", path)
        want = min(_CHUNK, limit + 1 - total)
    return chunks[0] if len(chunks) == 1 else b"".join(chunks)
