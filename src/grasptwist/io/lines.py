"""JSON Lines: grasps or twists one per line, each read as soon as its line arrives.

``resolve -`` and files named ``*.jsonl`` (any letter case) may hold one
grasp document per line; ``--twists-from`` one twist per line.  Lines are
read one at a time, so a stream has no size limit and memory stays
constant: only each line is held to the size cap of a grasp file
(``--max-bytes``); a longer line is passed over to its end and gets a
``too-large`` error.  Blank lines are skipped (they still count for line
numbers).

Standard input is JSON Lines when its first non-blank character is ``{``,
else it is read as a YAML grasp file (one multi-line JSON document that
starts with ``{`` on its own line is therefore read as lines: put it on
one line, or start it with ``---``).  Streams of twists are always JSON
Lines.
"""

from __future__ import annotations

import os
import stat
import sys
from collections.abc import Iterator
from itertools import chain

from ..model import Grasp, GraspFileError, Twist
from .grasp_file import DEFAULT_MAX_BYTES, NOT_REGULAR, read_grasps, read_line, read_twist_line
from .inputs import STDIN

__all__ = ["JSONL_SUFFIX", "is_json_lines", "numbered_lines", "grasp_batches", "twist_batches"]

JSONL_SUFFIX = ".jsonl"

# Bytes read at a time while passing over the rest of a line that is too long.
_SKIP = 1 << 16
_BOM = b"\xef\xbb\xbf"


def is_json_lines(path: str) -> bool:
    """Whether ``path`` is read as JSON Lines by its name.

    >>> [is_json_lines(p) for p in ("grasps.jsonl", "G.JSONL", "grasps.json", "-")]
    [True, True, False, False]
    """
    return path.lower().endswith(JSONL_SUFFIX)


def numbered_lines(handle, max_bytes: int, head=()) -> Iterator[tuple[int, bytes]]:
    """``(line number, line)`` of each non-blank line of ``handle`` (after the
    lines ``head`` already read from it), as soon as it is complete.

    A line longer than ``max_bytes`` comes cut to ``max_bytes + 1`` bytes (so
    that it is refused), its rest read and dropped a piece at a time.
    """
    for number, line in enumerate(chain(head, iter(lambda: handle.readline(max_bytes + 2), b"")), 1):
        rest = line
        while len(rest) > max_bytes and not rest.endswith(b"\n"):
            rest = handle.readline(_SKIP)
        if line.strip():
            yield number, line[: max_bytes + 1] if len(line.rstrip(b"\r\n")) > max_bytes else line


def _sniff(handle, max_bytes: int) -> tuple[bool, list[bytes]]:
    """Whether ``handle`` holds JSON Lines (its first non-blank character is ``{``),
    and the lines read to tell."""
    head, size = [], 0
    while size <= max_bytes:
        line = handle.readline(max_bytes + 2)
        if not line:
            break
        head.append(line)
        size += len(line)
        text = line.removeprefix(_BOM) if len(head) == 1 else line
        if text.strip():
            return text.lstrip()[:1] == b"{", head
    return False, head


def _opened(path: str):
    """A JSON Lines file opened for reading (never a pipe or device: it could block forever)."""
    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    if not stat.S_ISREG(os.fstat(fd).st_mode):
        os.close(fd)
        raise OSError(NOT_REGULAR)
    return os.fdopen(fd, "rb")


def _interactive(handle) -> bool:
    """Whether lines may arrive one by one (a pipe, terminal or socket, not a file)."""
    try:
        return not stat.S_ISREG(os.fstat(handle.fileno()).st_mode)
    except (OSError, ValueError, AttributeError):
        return True


def _batches(entries, handle, per_batch: int):
    """Lists of what ``entries`` gives: each alone when lines may arrive one by
    one (each must be out before the next arrives), else ``per_batch`` at a time."""
    per_batch = 1 if _interactive(handle) else per_batch
    batch = []
    for items in entries:
        batch.extend(items)
        if len(batch) >= per_batch:
            yield batch
            batch = []
    if batch:
        yield batch


def _source(path: str, file: str):
    """The handle of ``path`` (``-``: standard input), or the error for it."""
    if path == STDIN:
        return sys.stdin.buffer
    try:
        return _opened(path)
    except OSError as exc:
        return GraspFileError("read-error", f"cannot read: {exc.strerror or exc}", file)


def grasp_batches(
    path: str, max_bytes: int | None = None, per_batch: int = 64
) -> Iterator[list[Grasp | GraspFileError]]:
    """The grasps (and errors) of a JSON Lines file, or of standard input
    (``-``: JSON Lines or a YAML grasp file, as its first character says),
    in lists: one per line when the lines may come one by one."""
    return _stream(path, max_bytes, per_batch, read_line, sniff=path == STDIN)


def twist_batches(
    path: str, max_bytes: int | None = None, per_batch: int = 64
) -> Iterator[list[Twist | GraspFileError]]:
    """The twists (and errors) of a JSON Lines stream of twists (``-``: standard
    input), in lists: one per line when the lines may come one by one."""

    def read(data, **where):
        entry = read_twist_line(data, **where)
        return entry if isinstance(entry, list) else [entry]

    return _stream(path, max_bytes, per_batch, read, sniff=False)


def _stream(path, max_bytes, per_batch, read, sniff):
    """``read(line, file=, line=, max_bytes=)`` of each line of ``path``, in batches;
    with ``sniff``, a stream that is not JSON Lines is read whole as a YAML grasp file."""
    cap = DEFAULT_MAX_BYTES if max_bytes is None else max_bytes
    file = "<stdin>" if path == STDIN else path
    try:
        handle = sys.stdin.buffer if path == STDIN else _opened(path)
    except OSError as exc:
        yield [GraspFileError("read-error", f"cannot read: {exc.strerror or exc}", file)]
        return
    try:
        head = ()
        if sniff:
            json_lines, head = _sniff(handle, cap)
            if not json_lines:
                data = b"".join(head)
                yield read_grasps(data + handle.read(max(0, cap + 1 - len(data))), file=file, max_bytes=cap)
                return
        entries = (read(line, file=file, line=n, max_bytes=cap) for n, line in numbered_lines(handle, cap, head))
        yield from _batches(entries, handle, per_batch)
    finally:
        if path != STDIN:
            handle.close()
