"""Where output goes: a file replaced atomically, or a pipe or device written through.

The rule for an output path (``-o``), decided by :func:`check_target` before any work:

* the empty name, a folder, a block device (a disk), a socket, a link loop
  and a path in a missing or read-only folder are refused (ValueError); a
  path is the system's, never tidied as text (``r/nosuch/../a.yaml`` is in
  the missing folder ``r/nosuch/..``, as for a shell's ``>``);
* so is a regular file that is one of the run's inputs, found by its
  device and inode (through symbolic and hard links, and for standard
  output and ``-`` too), so that a run never replaces what it reads;
* a name of one of the process's own descriptors (``/dev/stdout``,
  ``/dev/fd/N``, ``/proc/self/fd/N``) is that descriptor as it is, written
  through; it must be open for writing, else :class:`WriteError`;
* a FIFO and a character device (a terminal, ``/dev/null``) are opened and
  written through, as a shell's ``>`` does, never replaced;
* a new path or a regular file, wherever it is (``/dev/shm`` too), is
  written to a temporary file in the same folder, which takes the path's
  name, and the permission bits of the file it replaces, only when the run
  succeeds, so a failed or interrupted run leaves the path as it was.  The
  temporary file has no name at all where the system allows it (Linux
  ``O_TMPFILE``, named by ``linkat`` at the end); elsewhere it is
  ``.grasptwist-<host>-<pid>-*.tmp``, which the next run writing to that
  folder removes if its owner is gone.  A symbolic link is followed: its
  target obeys this rule, the link stays.

Standard output is checked the same way: closed, it is a :class:`WriteError`.
Every failure to write, including the final rename, is one
:class:`WriteError` naming the path and the system's reason.
"""

from __future__ import annotations

import errno
import os
import re
import stat
import sys
from collections.abc import Iterable, Iterator
from contextlib import contextmanager, suppress
from typing import IO, NamedTuple

from .scratch import owned_prefix, remove_orphans

__all__ = ["STDOUT", "Target", "WriteError", "check_target", "replaced_file", "opened", "guarded"]

#: How errors name standard output.
STDOUT = "standard output"

#: Name stem of the named temporary files beside an output.
TEMP_STEM = ".grasptwist-"

#: Errors that only writing can raise: an OSError with one of these and no
#: file name (``write``, ``sendfile``), met while output is written, is a write error.
WRITE_ERRNOS = frozenset({errno.ENOSPC, errno.EDQUOT, errno.EFBIG, errno.EIO, errno.EROFS})

#: Names of the process's own descriptors: group 1 a standard stream's name, group 2 a number.
_DESCRIPTOR = re.compile(r"/dev/(stdin|stdout|stderr)|/(?:dev|proc/self)/fd/(\d+)")

#: Links followed in a row at most, as Linux does (MAXSYMLINKS): a loop made after the check ends.
_MAX_LINKS = 40


class WriteError(Exception):
    """The output could not be written.

    >>> str(WriteError("out.jsonl", OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))))
    'cannot write out.jsonl: No space left on device'
    """

    def __init__(self, path: str, exc: OSError):
        self.path = path
        self.reason = exc.strerror or str(exc)
        super().__init__(f"cannot write {path}: {self.reason}")


class Target(NamedTuple):
    """An output checked by :func:`check_target`: ``how`` it is written
    (``"stdout"``, ``"through"`` or ``"replace"``), the ``path`` as given
    and the ``file`` written (for ``"replace"``, ``path`` with its links followed)."""

    how: str
    path: str
    file: str


def check_target(path: str | None, inputs: Iterable = ()) -> Target:
    """How ``path`` (None or ``-``: standard output) is written, by the rule
    above; ``inputs`` are the paths the run reads (``-``: standard input;
    other entries, like the errors of a folder's listing, are skipped).

    Raises
    ------
    ValueError
        Naming ``path`` and why it cannot be the output.

    >>> check_target("")
    Traceback (most recent call last):
    ...
    ValueError: cannot write '': the file name is empty
    """
    if path is None or path == "-":
        target, info = Target("stdout", STDOUT, STDOUT), _descriptor_stat(1)
    elif not path:
        raise ValueError("cannot write '': the file name is empty")
    elif (fd := _descriptor(path)) is not None:
        target, info = Target("through", path, path), _descriptor_stat(fd)
    else:
        target, info = _by_type(path)
    if info is not None and stat.S_ISREG(info.st_mode):
        _not_an_input(target.path, info, inputs)
    return target


def replaced_file(path: str | None) -> tuple[int, int] | None:
    """The ``(device, inode)`` of the regular file that writing ``path`` would replace (its links
    followed), so that the readers refuse it if a grasp file names it (a mesh, a URDF); None for
    standard output, a descriptor, a pipe or device, and a new file.

    >>> replaced_file(None), replaced_file("-"), replaced_file("no/such/file.jsonl")
    (None, None, None)
    """
    if path is None or path == "-" or _descriptor(path) is not None:
        return None
    try:
        info = os.stat(path)
    except OSError:
        return None
    return (info.st_dev, info.st_ino) if stat.S_ISREG(info.st_mode) else None


def _by_type(path: str) -> tuple[Target, os.stat_result | None]:
    """How the file ``path`` is written, by its type; and its status (None for a new file)."""
    try:
        info = os.stat(path)
    except FileNotFoundError:
        info = None  # a new file (or the missing target of a link)
    except OSError as exc:  # a link loop, a file where a folder should be, no permission
        raise ValueError(f"cannot write {path}: {exc.strerror}") from None
    mode = info.st_mode if info is not None else stat.S_IFREG
    if stat.S_ISDIR(mode):
        raise ValueError(f"cannot write {path}: it is a folder; give a file name")
    if stat.S_ISBLK(mode):
        raise ValueError(f"cannot write {path}: it is a block device (a disk); give a file name")
    if stat.S_ISFIFO(mode) or stat.S_ISCHR(mode):
        return Target("through", path, path), None
    if not stat.S_ISREG(mode):
        raise ValueError(f"cannot write {path}: not a regular file, a pipe or a character device")
    file = _link_followed(path)
    folder = _folder(file)
    if not os.path.isdir(folder):
        raise ValueError(f"cannot write {path}: no folder {folder}")
    if not os.access(folder, os.W_OK):
        raise ValueError(f"cannot write {path}: the folder is not writable")
    return Target("replace", path, file), info


def _link_followed(path: str) -> str:
    """``path`` with its last part's symbolic links followed, each link's target
    joined to the link's folder as text: never normalised, so that the system
    resolves every ``..`` where it stands (after a missing folder, or a linked
    one), as it does for a shell's ``>``.

    >>> _link_followed("r/nosuch/../a.yaml")
    'r/nosuch/../a.yaml'
    """
    for _ in range(_MAX_LINKS):
        if not os.path.islink(path):
            break
        path = os.path.join(os.path.dirname(path), os.readlink(path))
    return path


def _folder(path: str) -> str:
    """The folder ``path`` names its file in, as given (``.`` for a bare name).

    >>> _folder("r/nosuch/../a.yaml"), _folder("a.yaml")
    ('r/nosuch/..', '.')
    """
    return os.path.dirname(path) or os.curdir


def _not_an_input(shown: str, info: os.stat_result, inputs: Iterable) -> None:
    """A ValueError when the regular file of status ``info`` is one of ``inputs``."""
    for p in inputs:
        if not isinstance(p, str):
            continue
        try:
            read = _descriptor_stat(0) if p == "-" else os.stat(p)
        except OSError:  # a path the run cannot read either: it says so itself
            continue
        if read is not None and (read.st_dev, read.st_ino) == (info.st_dev, info.st_ino):
            what = "the file standard input reads, an input" if p == "-" else f"the input {p}"
            raise ValueError(f"cannot write {shown}: it is {what} (the same file); give another file name")


def _descriptor(path: str) -> int | None:
    """The descriptor a name like ``/dev/stdout`` or ``/dev/fd/3`` stands for, or None.

    >>> _descriptor("/dev/stdout"), _descriptor("/dev/fd/3"), _descriptor("/dev/shm/out.jsonl")
    (1, 3, None)
    """
    absolute = os.path.abspath(path)
    match = _DESCRIPTOR.fullmatch(absolute)
    if match is None or not _same_folder(path, absolute):
        return None
    return ("stdin", "stdout", "stderr").index(match[1]) if match[1] else int(match[2])


def _same_folder(path: str, normalised: str) -> bool:
    """Whether the system finds ``path`` in the folder of its ``normalised`` text
    (not so for ``/dev/nosuch/../stdout``, whose folder is missing)."""
    try:
        return os.path.samestat(os.stat(_folder(path)), os.stat(_folder(normalised)))
    except OSError:
        return False


def _descriptor_stat(fd: int) -> os.stat_result | None:
    """The status of the open descriptor ``fd``; None if it is closed (opening it says so),
    or is a standard stream the process does not use as such (tests capture them)."""
    if fd < 3:
        stream = (sys.stdin, sys.stdout, sys.stderr)[fd]
        try:
            if stream is None or stream.fileno() != fd:
                return None
        except (OSError, ValueError, AttributeError):
            return None
    try:
        return os.fstat(fd)
    except OSError:
        return None


def _closed_at_start(fd: int) -> bool:
    """Whether ``fd`` is a standard stream the shell closed (``>&-``): Python then has no
    object for it, and the number may since have been given to some other file."""
    return fd < 3 and (sys.stdin, sys.stdout, sys.stderr)[fd] is None


@contextmanager
def opened(path: str | None | Target, inputs: Iterable = ()) -> Iterator[IO[bytes]]:
    """``path`` open for writing (and reading back, for zip archives) by the
    rule above, or stdout for None or ``-``; the output is committed when
    the block ends normally.  ``path`` may be a :class:`Target` already checked.

    Raises
    ------
    ValueError
        From :func:`check_target`.
    WriteError
        When opening, writing or committing fails.
    """
    target = path if isinstance(path, Target) else check_target(path, inputs)
    if target.how == "stdout":
        if _closed_at_start(1):
            raise WriteError(STDOUT, OSError(errno.EBADF, "it is closed"))
        with _errors_named(STDOUT):
            out = guarded(sys.stdout.buffer, STDOUT)
            yield out
            out.flush()
        return
    if target.how == "through":
        raw = _open_through(target.path)
        with _errors_named(target.path):
            with raw:
                yield guarded(raw, target.path)
            return
    with _errors_named(target.path), _replacing(target.file) as f:
        yield guarded(f, target.path)


def _open_through(path: str) -> IO[bytes]:
    """A pipe or device opened for writing; a name of one of our own file
    descriptors (``/dev/stdout``, ``/dev/fd/N``) is that descriptor as it is
    (reopening would truncate a file the shell opened for appending)."""
    fd = _descriptor(path)
    try:
        if fd is None:
            return open(path, "wb")  # noqa: SIM115 - the caller closes it; a FIFO waits for its reader, as with `>`
        return os.fdopen(os.dup(_writable(fd)), "wb")
    except OSError as exc:
        raise WriteError(path, exc) from None


def _writable(fd: int) -> int:
    """``fd``, if it is open for writing; else an OSError saying why not."""
    import fcntl

    try:
        flags = None if _closed_at_start(fd) else fcntl.fcntl(fd, fcntl.F_GETFL)
    except OSError:
        flags = None
    if flags is None:
        raise OSError(errno.EBADF, "it is closed")
    if flags & os.O_ACCMODE == os.O_RDONLY:
        raise OSError(errno.EBADF, "it is open for reading only")
    return fd


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
    folder = _folder(path)  # as given: the folder the system finds the path in
    prefix = owned_prefix(TEMP_STEM)
    remove_orphans(folder, TEMP_STEM)  # what runs killed by SIGKILL left
    try:
        # the permission bits of the file replaced (set-id bits have no business on new content)
        mode = stat.S_IMODE(os.stat(path).st_mode) & 0o777
    except OSError:
        mode = None  # a new file
    try:
        fd, name = _temporary(folder, prefix, mode)
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


def _temporary(folder: str, prefix: str, mode: int | None) -> tuple[int, str | None]:
    """A new file in ``folder`` with the permission bits ``mode`` (None: those of
    a new file, 0666 less the umask): unnamed when the system can name it later,
    else named."""
    if _can_name_unnamed(folder, prefix):
        fd, name = os.open(folder, os.O_TMPFILE | os.O_RDWR | os.O_CLOEXEC, 0o666), None
    else:
        import tempfile

        fd, name = tempfile.mkstemp(prefix=prefix, suffix=".tmp", dir=folder)
        if mode is None:  # mkstemp makes it private; the output is an ordinary file
            umask = os.umask(0)
            os.umask(umask)
            mode = 0o666 & ~umask
    try:
        if mode is not None:
            os.fchmod(fd, mode)
    except OSError:
        os.close(fd)
        if name is not None:
            os.unlink(name)
        raise
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
