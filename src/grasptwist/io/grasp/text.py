"""A grasp file's bytes: read under a size cap, then decoded as strict UTF-8 that YAML accepts."""

from __future__ import annotations

import errno
import os
import re
import stat
import sys

from ..limits import NOT_REGULAR
from .problems import Reject

__all__ = ["encode", "read_file", "read_capped", "decode", "file_text", "standard_input"]


def encode(content):
    """Content given as bytes or str, as bytes (to check size and UTF-8 alike)."""
    if not isinstance(content, str):
        return bytes(content)
    try:
        return content.encode("utf-8")
    except UnicodeEncodeError as exc:  # lone surrogates
        raise Reject("invalid-utf8", "", f"not valid Unicode at character {exc.start}") from None


def standard_input():
    """Standard input, as bytes; an OSError when the shell closed it (``<&-``), which
    readers report as they report any input they cannot read."""
    if sys.stdin is None:  # Python found descriptor 0 closed when it started
        raise OSError(errno.EBADF, "standard input is closed")
    return sys.stdin.buffer


def read_file(path, max_bytes):
    """At most ``max_bytes + 1`` bytes of a regular file, or of stdin for ``"-"``.

    One byte past the cap is enough to know it is exceeded, without
    trusting stat (/proc) or reading a huge file into memory.  The file is
    opened non-blocking and checked after opening: a path that is (or was
    swapped for) a FIFO, socket or device never hangs or streams forever.
    """
    try:
        if isinstance(path, str) and path == "-":
            return read_capped(standard_input(), max_bytes + 1)
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
        with open(fd, "rb") as handle:
            mode = os.fstat(fd).st_mode
            if not stat.S_ISREG(mode):
                why = os.strerror(errno.EISDIR) if stat.S_ISDIR(mode) else NOT_REGULAR
                raise Reject("read-error", "", f"cannot read: {why}")
            return read_capped(handle, max_bytes + 1)
    except OSError as exc:
        raise Reject("read-error", "", f"cannot read: {exc.strerror or exc}") from None


_CHUNK = 1 << 16


def read_capped(handle, limit):
    """``handle.read(limit)``, in chunks: reading a small file with a 1 MiB
    ``limit`` allocates (and frees) a 1 MiB buffer each time, which costs
    more than parsing the file."""
    if type(limit) is not int or limit <= _CHUNK:
        return handle.read(limit)
    data = handle.read(_CHUNK)
    if len(data) < _CHUNK:  # a short read of a blocking stream: its end
        return data
    parts = [data]
    limit -= _CHUNK
    while limit > 0:
        data = handle.read(min(limit, _CHUNK))
        if not data:
            break
        parts.append(data)
        limit -= len(data)
    return b"".join(parts)


# What PyYAML's and libyaml's readers refuse (YAML 1.1 "printable").
_NON_PRINTABLE = re.compile("[^\x09\x0a\x0d\x20-\x7e\x85\xa0-\ud7ff\ue000-\ufffd\U00010000-\U0010ffff]")

_ASCII_PRINTABLE = b"\t\n\r" + bytes(range(0x20, 0x7F))


def decode(data):
    """Strict UTF-8 text of ``data``, checked for characters YAML refuses.

    Done here rather than by the parsers so that both report the same
    error at the same place.
    """
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        start = data.rfind(b"\n", 0, exc.start) + 1
        column = len(data[start : exc.start].decode("utf-8", "replace")) + 1
        raise Reject(
            "invalid-utf8",
            "",
            f"not valid UTF-8 (byte offset {exc.start}: {data[exc.start : exc.start + 1]!r})",
            line=data.count(b"\n", 0, exc.start) + 1,
            column=column,
        ) from None
    # Most files are ASCII: deleting their allowed bytes is ~10x quicker
    # than the search, which then runs only to locate a culprit.
    if data.isascii() and not data.translate(None, _ASCII_PRINTABLE):
        return text
    bad = _NON_PRINTABLE.search(text)
    if bad:
        pos = bad.start()
        raise Reject(
            "control-character",
            "",
            f"control character U+{ord(bad.group()):04X} is not allowed in YAML (escape it in a double-quoted string)",
            line=text.count("\n", 0, pos) + 1,
            column=pos - text.rfind("\n", 0, pos),
        )
    return text


def file_text(source, is_content, max_bytes):
    """The checked text of a file (a path, or ``"-"`` for standard input) or of content.

    Raises
    ------
    Reject
        ``read-error``, ``too-large``, ``invalid-utf8`` or ``control-character``.
    """
    data = encode(source) if is_content else read_file(source, max_bytes)
    if len(data) > max_bytes:
        raise Reject("too-large", "", f"larger than the size limit of {max_bytes} bytes")
    return decode(data)
