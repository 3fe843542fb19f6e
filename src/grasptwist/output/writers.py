"""Stream writers: encoded records onto an output, one JSON array or one record a line."""

from __future__ import annotations

import os
from typing import IO

__all__ = ["JsonArray", "Lines"]


def _copy_file(out: IO[bytes], path: str) -> None:
    """Append the file at ``path`` to ``out`` (in the kernel when both are files or pipes), then delete it."""
    with open(path, "rb") as f:
        size = os.fstat(f.fileno()).st_size
        try:
            target = out.fileno()
        except (OSError, AttributeError, ValueError):  # not a real file (tests' buffers)
            out.write(f.read())
        else:
            out.flush()
            sent = 0
            while sent < size:
                sent += os.sendfile(target, f.fileno(), sent, size - sent)
    os.unlink(path)


class JsonArray:
    """One JSON array, written element by element so a batch streams."""

    def __init__(self, out: IO[bytes]):
        self.out = out
        self.count = 0

    def write(self, encoded: bytes) -> None:
        self.out.write(b"[\n" if self.count == 0 else b",\n")
        self.out.write(encoded)
        self.count += 1

    def write_spooled(self, path: str) -> None:
        self.out.write(b"[\n" if self.count == 0 else b",\n")
        _copy_file(self.out, path)
        self.count += 1

    def close(self) -> None:
        self.out.write(b"[]\n" if self.count == 0 else b"\n]\n")


class Lines:
    """One encoded record per line (JSONL, CSV rows after a header), flushed per batch."""

    def __init__(self, out: IO[bytes], header: bytes = b"", newline: bytes = b"\n"):
        self.out = out
        self.newline = newline
        out.write(header)

    def write(self, encoded: bytes) -> None:
        self.out.write(encoded + self.newline)

    def write_spooled(self, path: str) -> None:
        _copy_file(self.out, path)
        self.out.write(self.newline)

    def close(self) -> None:
        self.out.flush()
