"""Problems as values: a located problem (:class:`Reject`) and a document's list of them.

Every check of the loader adds its problems to a :class:`Problems` and goes
on, so one pass finds them all; each becomes a
:class:`~grasptwist.model.InputError` when the document is done.
"""

from __future__ import annotations

import re

from ...model import InputError
from ..limits import MAX_ERRORS

__all__ = ["MAX_ERRORS", "Reject", "StreamStop", "Problems", "located", "located_mark", "join"]


class Reject(Exception):
    """Internal: one located problem, turned into a InputError later."""

    def __init__(self, code, path, problem, line=None, column=None):
        super().__init__(code)
        self.code = code
        self.message = f"{path}: {problem}" if path else problem
        self.line = line
        self.column = column

    def error(self, file, document):
        return InputError(self.code, self.message, file, self.line, self.column, document)


class StreamStop(Reject):
    """Internal: a problem after which the rest of the stream is not read."""


class Problems:
    """The problems of one document as they are found, reported as a compiler would:
    every one with its own position, in file order, the first ``keep`` of them (the
    file's limit, :data:`MAX_ERRORS`) and a count of all.

    At most ``2 * keep`` are held between trims, so a document with a hundred
    thousand problems costs no more memory than one with a few.

    >>> problems = Problems(2)
    >>> for line in (5, 1, 3):
    ...     problems.add(Reject("unknown-key", "", "unknown key", line, 1))
    >>> [r.line for r in problems.first()[0]], problems.first()[1], problems.count
    ([1, 3], 2, 3)
    """

    __slots__ = ("keep", "count", "_held")

    def __init__(self, keep):
        self.keep = keep
        self.count = 0
        self._held = []

    def add(self, reject):
        self.count += 1
        if self.keep:
            self._held.append(reject)
            if len(self._held) >= 2 * self.keep:
                self._trim()

    def drop_within(self, node):
        """Forget the problems found inside ``node`` (the value of a key reported
        unknown: what is wrong inside it is no news), so none cascades."""
        start, end = (node.line, node.column), node.end
        kept = [reject for reject in self._held if not start <= _position(reject) < end]
        self.count -= len(self._held) - len(kept)
        self._held = kept

    def first(self):
        """The problems to report, the first ``keep`` in file order, and how many problems they stand
        for (one each: the rest are counted by the file's ``too-many-errors`` entry)."""
        self._trim()
        return list(self._held), len(self._held)

    def _trim(self):
        self._held.sort(key=_position)  # stable: ties stay in the order found
        del self._held[self.keep :]


def _position(reject):
    return reject.line or 0, reject.column or 0


def located(node):
    """Keyword arguments locating a node (1-based)."""
    return {"line": node.line, "column": node.column}


def located_mark(mark):
    """Keyword arguments locating a parser mark (0-based) as 1-based."""
    return {"line": mark.line + 1, "column": mark.column + 1}


_SIMPLE_KEY = re.compile(r"[A-Za-z_][A-Za-z0-9_-]*")


def join(path, key):
    """``path.key``, or ``path['key']`` for keys that do not read as names."""
    if isinstance(key, str) and _SIMPLE_KEY.fullmatch(key):
        return f"{path}.{key}" if path else key
    return f"{path}[{key!r}]"
