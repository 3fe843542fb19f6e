"""Which files a command reads: paths, folders and stdin, in a stable order.

A folder is searched recursively for ``*.yaml`` and ``*.yml``; its files are
sorted by their path relative to it.  Symbolic links are followed, but a
folder reached twice (a link cycle, or two links to one place) is read only
the first time.  A path that does not exist, or a folder that cannot be
listed, becomes a :class:`GraspFileError` in its place so that the rest of
the batch goes on.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Iterable, Iterator

from ..model import Grasp, GraspFileError
from .grasp_file import DEFAULT_MAX_BYTES, read_grasps

__all__ = ["GRASP_SUFFIXES", "STDIN", "expand", "read"]

GRASP_SUFFIXES = (".yaml", ".yml")
STDIN = "-"


def expand(paths: Iterable[str]) -> Iterator[str | GraspFileError]:
    """Every grasp file named by ``paths``, folders expanded, in order."""
    stdin_seen = False
    for path in paths:
        if path == STDIN and stdin_seen:
            yield _io_error(path, "standard input can be read only once")
        elif path == STDIN or os.path.isfile(path):
            stdin_seen |= path == STDIN
            yield path
        elif os.path.isdir(path):
            yield from _walk(path)
        else:
            yield _io_error(path, _not_a_file(path))


def _not_a_file(path: str) -> str:
    try:
        os.stat(path)
    except FileNotFoundError:
        return "no such file or folder"
    except OSError as exc:  # e.g. a link to itself: "Too many levels of symbolic links"
        return exc.strerror or str(exc)
    # a pipe, socket or device would block or never end: never open one
    return "not a regular file (a pipe, socket or device)"


def _walk(top: str) -> Iterator[str | GraspFileError]:
    seen: set[str] = set()
    found: list[str] = []
    errors: list[GraspFileError] = []

    def on_error(exc: OSError):
        errors.append(_io_error(exc.filename or top, exc.strerror or str(exc)))

    for folder, dirs, files in os.walk(top, followlinks=True, onerror=on_error):
        real = os.path.realpath(folder)
        if real in seen:
            dirs[:] = []  # a cycle, or a second link to a folder already read
            continue
        seen.add(real)
        dirs.sort()
        found.extend(os.path.join(folder, f) for f in files if f.endswith(GRASP_SUFFIXES))
    yield from errors
    for path in sorted(found, key=lambda p: os.path.relpath(p, top).split(os.sep)):
        yield path if os.path.isfile(path) else _io_error(path, _not_a_file(path))


def read(path: str, max_bytes: int | None = None) -> list[Grasp | GraspFileError]:
    """The grasps (or errors) of one file; ``-`` reads standard input."""
    cap = DEFAULT_MAX_BYTES if max_bytes is None else max_bytes
    if path == STDIN:
        # one byte past the cap is enough for the loader to refuse it
        return read_grasps(sys.stdin.buffer.read(cap + 1), file="<stdin>", max_bytes=cap)
    return read_grasps(path, max_bytes=cap)


def _io_error(path: str, why: str) -> GraspFileError:
    return GraspFileError(code="read-error", message=f"cannot read: {why}", file=path, line=None, column=None)
