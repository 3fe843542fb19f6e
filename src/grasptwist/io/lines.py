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
from collections.abc import Iterator

from ..model import Grasp, InputError, Twist
from .grasp import READING, Reading, one_per_document, read_grasps, read_line, read_twist_line
from .grasp.text import standard_input
from .inputs import STDIN
from .limits import DEFAULT_MAX_BYTES, NOT_REGULAR

__all__ = ["JSONL_SUFFIX", "is_json_lines", "numbered_batches", "grasp_batches", "twist_batches"]

JSONL_SUFFIX = ".jsonl"

# Most bytes read at a time.
_CHUNK = 1 << 16
_BOM = b"\xef\xbb\xbf"


def is_json_lines(path: str) -> bool:
    """Whether ``path`` is read as JSON Lines by its name.

    >>> [is_json_lines(p) for p in ("grasps.jsonl", "G.JSONL", "grasps.json", "-")]
    [True, True, False, False]
    """
    return path.lower().endswith(JSONL_SUFFIX)


def numbered_batches(handle, max_bytes: int, per_batch: int, head: bytes = b"") -> Iterator[list[tuple[int, bytes]]]:
    """``(line number, line)`` of the non-blank lines of ``head`` and then ``handle``,
    in lists of the complete lines that have arrived (at most ``per_batch``):
    it waits for input only when no complete line is left, so each line is
    handed on as soon as it arrives, and lines that come together go together.

    A line longer than ``max_bytes`` comes cut to ``max_bytes + 1`` bytes (so
    that it is refused) as soon as that much of it has arrived; its rest is
    dropped as it comes.

    >>> import io
    >>> list(numbered_batches(io.BytesIO(b'{"a": 1}\\n\\n[1, 2]\\n' + b"x" * 9), 8, 64))
    [[(1, b'{"a": 1}'), (3, b'[1, 2]'), (4, b'xxxxxxxxx')]]
    """
    # The line not yet ended is held as the pieces it came in and joined once, when it ends:
    # adding each piece to the bytes so far would copy a long line once per piece (quadratic).
    number, held, size, skipping = 0, [], 0, False
    chunk, ended = head, False
    while True:
        *lines, rest = chunk.split(b"\n")
        if lines:
            lines[0] = b"".join((*held, lines[0]))
            held, size = [], 0
        if rest:
            held.append(rest)
            size += len(rest)
        if ended and held:
            lines.append(b"".join(held))
            held, size = [], 0
        batch = []
        for line in lines:
            if skipping:  # the end of a line already refused
                skipping = False
                continue
            number += 1
            if line.strip():
                batch.append((number, line[: max_bytes + 1]))
        if not skipping and size > max_bytes:
            number += 1
            batch.append((number, b"".join(held)[: max_bytes + 1]))
            skipping = True
        if skipping:
            held, size = [], 0
        for start in range(0, len(batch), per_batch):
            yield batch[start : start + per_batch]
        if ended:
            return
        chunk = handle.read1(_CHUNK)
        ended = not chunk


def _sniff(handle, max_bytes: int) -> tuple[bool, bytes]:
    """Whether ``handle`` holds JSON Lines (its first non-blank character is ``{``),
    and the bytes read to tell (each looked at once, however many blank ones come first)."""
    head, blank = bytearray(), 0  # head[:blank] is known to be a BOM and blanks
    while len(head) <= max_bytes:
        chunk = handle.read1(_CHUNK)
        if not chunk:
            break
        head += chunk
        if not blank:
            if len(head) < len(_BOM) and _BOM.startswith(head):  # the rest of a BOM may follow
                continue
            blank = len(_BOM) if head.startswith(_BOM) else 0
        text = head[blank:].lstrip()
        if text:
            return text[:1] == b"{", bytes(head)
        blank = len(head)
    return False, bytes(head)


def _opened(path: str):
    """A JSON Lines file opened for reading (never a pipe or device: it could block forever)."""
    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    if not stat.S_ISREG(os.fstat(fd).st_mode):
        os.close(fd)
        raise OSError(NOT_REGULAR)
    return os.fdopen(fd, "rb")


def grasp_batches(
    path: str, max_bytes: int | None = None, per_batch: int = 64, reading: Reading = READING
) -> Iterator[list[Grasp | InputError]]:
    """The grasps (and errors) of a JSON Lines file, or of standard input
    (``-``: JSON Lines or a YAML grasp file, as its first character says),
    in lists: one per line when the lines may come one by one; ``reading``
    as for :func:`~grasptwist.read_grasps`."""

    def read(data, **where):
        return read_line(data, reading=reading, **where)

    return _stream(path, max_bytes, per_batch, read, sniff=path == STDIN, reading=reading)


def twist_batches(path: str, max_bytes: int | None = None, per_batch: int = 64) -> Iterator[list[Twist | InputError]]:
    """The twists (and errors) of a JSON Lines stream of twists (``-``: standard
    input), in lists: one per line when the lines may come one by one."""

    def read(data, **where):
        entry = read_twist_line(data, **where)
        return entry if isinstance(entry, list) else [entry]

    return _stream(path, max_bytes, per_batch, read, sniff=False, reading=READING)


def _stream(path, max_bytes, per_batch, read, sniff, reading):
    """``read(line, file=, line=, max_bytes=)`` of each line of ``path``, in batches
    (see :func:`numbered_batches`); with ``sniff``, a stream that is not JSON
    Lines is read whole as a YAML grasp file."""
    cap = DEFAULT_MAX_BYTES if max_bytes is None else max_bytes
    file = "<stdin>" if path == STDIN else path
    try:
        handle = standard_input() if path == STDIN else _opened(path)
    except OSError as exc:
        yield [InputError("read-error", f"cannot read: {exc.strerror or exc}", file)]
        return
    try:
        head = b""
        if sniff:
            json_lines, head = _sniff(handle, cap)
            if not json_lines:
                yield one_per_document(
                    read_grasps(
                        head + handle.read(max(0, cap + 1 - len(head))), file=file, max_bytes=cap, reading=reading
                    )
                )
                return
        for batch in numbered_batches(handle, cap, per_batch, head):
            yield [
                entry for n, line in batch for entry in one_per_document(read(line, file=file, line=n, max_bytes=cap))
            ]
    finally:
        if path != STDIN:
            handle.close()
