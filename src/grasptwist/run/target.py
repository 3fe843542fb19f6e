"""Where output goes: a file replaced atomically, or a pipe or device written through.

The rule for an output path (``-o``):

* a new path or a regular file is written to a temporary file in the same
  folder, which takes the path's name only when the run succeeds, so a
  failed or interrupted run leaves the path as it was.  The temporary file
  has no name at all where the system allows it (Linux ``O_TMPFILE``, named
  by ``linkat`` at the end); elsewhere it is ``.grasptwist-<host>-<pid>-*.tmp``,
  which the next run writing to that folder removes if its owner is gone;
* a symbolic link is followed: its target obeys this rule, the link stays;
* a FIFO, a character device (a terminal, ``/dev/null``) and anything under
  ``/dev`` or ``/proc`` (``/dev/stdout``) are opened and written through, as
  a shell's ``>`` does, never replaced;
* a folder, a block device, a socket, a link loop or a path in a missing
  folder is refused (:func:`check_target` raises ValueError) before any work.

Every failure to write, including the final rename, is one
:class:`WriteError` naming the path and the system's reason.
"""

from __future__ import annotations

import errno
import os
import re
import stat
import sys
from collections.abc import Iterator
from contextlib import contextmanager, suppress
from typing import IO

from .scratch import owned_prefix, remove_orphans

__all__ = ["WriteError", "check_target", "opened", "guarded"]

#: How errors name standard output.
STDOUT = "standard output"

#: Name stem of the named temporary files beside an output.
TEMP_STEM = ".grasptwist-"

#: Errors that only writing can raise: an OSError with one of these and no
#: file name (``write``, ``sendfile``), met while output is written, is a write error.
WRITE_ERRNOS = frozenset({errno.ENOSPC, errno.EDQUOT, errno.EFBIG, errno.EIO, errno.EROFS})


class WriteError(Exception):
    """The output could not be written.

    >>> str(WriteError("out.jsonl", OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))))
    'cannot write out.jsonl: No space left on device'
    """

    def __init__(self, path: str, exc: OSError):
        self.path = path
        self.reason = exc.strerror or str(exc)
        super().__init__(f"cannot write {path}: {self.reason}")


def check_target(path: str) -> tuple[str, str]:
    """How ``path`` is written: ``("replace", file)`` for a file replaced
    atomically (``file`` is ``path`` with its links followed), or
    ``("through", path)`` for a pipe or device.

    Raises
    ------
    ValueError
        Naming ``path`` and why it cannot be an output.
    """
    if os.path.abspath(path).startswith(("/dev/", "/proc/")):
        return "through", path
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        mode = None  # a new file (or the missing target of a link)
    except OSError as exc:  # a link loop, a file where a folder should be, no permission
        raise ValueError(f"cannot write {path}: {exc.strerror}") from None
    if mode is not None and stat.S_ISDIR(mode):
        raise ValueError(f"cannot write {path}: it is a folder; give a file name")
    if mode is not None and (stat.S_ISFIFO(mode) or stat.S_ISCHR(mode)):
        return "through", path
    if mode is not None and not stat.S_ISREG(mode):
        raise ValueError(f"cannot write {path}: not a regular file, a pipe or a character device")
    real = os.path.realpath(path)
    folder = os.path.dirname(real)
    if not os.path.isdir(folder):
        shown = os.path.dirname(path) if not os.path.islink(path) else folder
        raise ValueError(f"cannot write {path}: no folder {shown or folder}")
    if not os.access(folder, os.W_OK):
        raise ValueError(f"cannot write {path}: the folder is not writable")
    return "replace", real


@contextmanager
def opened(path: str | None) -> Iterator[IO[bytes]]:
    """``path`` open for writing (and reading back, for zip archives) by the
    rule above, or stdout for None or ``-``; the output is committed when
    the block ends normally.

    Raises
    ------
    ValueError
        From :func:`check_target`.
    WriteError
        When opening, writing or committing fails.
    """
    if path is None or path == "-":
        with _errors_named(STDOUT):
            out = guarded(sys.stdout.buffer, STDOUT)
            yield out
            out.flush()
        return
    how, real = check_target(path)
    if how == "through":
        try:
            raw = _open_through(path)
        except OSError as exc:
            raise WriteError(path, exc) from None
        with _errors_named(path):
            with raw:
                yield guarded(raw, path)
            return
    with _errors_named(path), _replacing(real) as f:
        yield guarded(f, path)


def _open_through(path: str) -> IO[bytes]:
    """A pipe or device opened for writing; a name of one of our own file
    descriptors (``/dev/stdout``, ``/dev/fd/N``) is that descriptor as it is
    (reopening would truncate a file the shell opened for appending)."""
    match = re.fullmatch(r"/dev/(stdout|stderr)|/(?:dev|proc/self)/fd/(\d+)", os.path.abspath(path))
    if match:
        fd = {"stdout": 1, "stderr": 2}.get(match[1]) or int(match[2])
        return os.fdopen(os.dup(fd), "wb")
    return open(path, "wb")  # noqa: SIM115 - the caller closes it; a FIFO waits for its reader, as with `>`


@contextmanager
def _errors_named(path: str):
    """Write errors raised inside, from Python's files or from the kernel, as :class:`WriteError`."""
    try:
        yield
    except OSError as exc:
        if isinstance(exc, BrokenPipeError) or exc.filename is not None or exc.errno not in WRITE_ERRNOS:
            raise
        raise WriteError(path, exc) from None


@contextmanager
def _replacing(path: str) -> Iterator[IO[bytes]]:
    folder = os.path.dirname(path)
    prefix = owned_prefix(TEMP_STEM)
    remove_orphans(folder, TEMP_STEM)  # what runs killed by SIGKILL left
    try:
        fd, name = _temporary(folder, prefix)
    except OSError as exc:
        raise WriteError(path, exc) from None
    try:
        with os.fdopen(fd, "w+b") as f:
            yield f
            try:
                f.flush()
                if name is None:
                    name = _named(f.fileno(), folder, prefix)
            except OSError as exc:
                raise WriteError(path, exc) from None
        try:
            os.replace(name, path)
        except OSError as exc:
            raise WriteError(path, exc) from None
    except BaseException:
        if name is not None:
            with suppress(OSError):
                os.unlink(name)
        raise


def _temporary(folder: str, prefix: str) -> tuple[int, str | None]:
    """A new file in ``folder`` readable as an ordinary output (mode 0666 less
    the umask): unnamed when the system can name it later, else named."""
    if _can_name_unnamed(folder, prefix):
        return os.open(folder, os.O_TMPFILE | os.O_RDWR | os.O_CLOEXEC, 0o666), None
    import tempfile

    fd, name = tempfile.mkstemp(prefix=prefix, suffix=".tmp", dir=folder)
    umask = os.umask(0)
    os.umask(umask)
    os.fchmod(fd, 0o666 & ~umask)  # mkstemp makes it private; the output is an ordinary file
    return fd, name


def _can_name_unnamed(folder: str, prefix: str) -> bool:
    """Whether an ``O_TMPFILE`` file in ``folder`` can be given a name (tried on an empty one)."""
    if not hasattr(os, "O_TMPFILE"):
        return False
    try:
        fd = os.open(folder, os.O_TMPFILE | os.O_RDWR | os.O_CLOEXEC, 0o666)
    except OSError:  # the file system has no unnamed files
        return False
    try:
        os.unlink(_named(fd, folder, prefix))
    except OSError:
        return False
    finally:
        os.close(fd)
    return True


def _named(fd: int, folder: str, prefix: str) -> str:
    """Give the unnamed file ``fd`` a new temporary name in ``folder``; return it."""
    name = os.path.join(folder, f"{prefix}{os.urandom(4).hex()}.tmp")
    try:
        os.link(f"/proc/self/fd/{fd}", name)  # any user, where /proc allows it
    except OSError:
        _link_empty_path(fd, name)  # needs CAP_DAC_READ_SEARCH
    return name


def _link_empty_path(fd: int, name: str) -> None:
    import ctypes

    at_fdcwd, at_empty_path = -100, 0x1000
    libc = ctypes.CDLL(None, use_errno=True)
    if libc.linkat(fd, b"", at_fdcwd, os.fsencode(name), at_empty_path) != 0:
        code = ctypes.get_errno()
        raise OSError(code, os.strerror(code))


def guarded(raw: IO[bytes], path: str) -> IO[bytes]:
    """``raw`` whose ``write`` and ``flush`` raise :class:`WriteError` (a
    reader gone away stays BrokenPipeError); everything else is ``raw``'s."""
    return _Guarded(raw, path)  # type: ignore[return-value]


class _Guarded:
    def __init__(self, raw: IO[bytes], path: str):
        self._raw = raw
        self._path = path

    def write(self, data) -> int:
        try:
            return self._raw.write(data)
        except BrokenPipeError:
            raise
        except OSError as exc:
            raise WriteError(self._path, exc) from None

    def flush(self) -> None:
        try:
            self._raw.flush()
        except BrokenPipeError:
            raise
        except OSError as exc:
            raise WriteError(self._path, exc) from None

    def __getattr__(self, name):
        return getattr(self._raw, name)
