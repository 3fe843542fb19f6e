"""Problems as values: a located problem (:class:`Reject`) and a document's list of them.

Every check of the loader adds its problems to a :class:`Problems` and goes
on, so one pass finds them all; each becomes a
:class:`~grasptwist.model.GraspFileError` when the document is done.
"""

from __future__ import annotations

import re

from ...model import GraspFileError

__all__ = ["MAX_ERRORS", "Reject", "StreamStop", "Problems", "located", "located_mark", "join"]

MAX_ERRORS = 100
"""Most problems reported for one file (the first, in file order); one more
``too-many-errors`` entry says how many were left out."""


class Reject(Exception):
    """Internal: one located problem, turned into a GraspFileError later."""

    def __init__(self, code, path, problem, line=None, column=None):
        super().__init__(code)
        self.code = code
        self.message = f"{path}: {problem}" if path else problem
        self.line = line
        self.column = column

    def error(self, file, document):
        return GraspFileError(self.code, self.message, file, self.line, self.column, document)


class StreamStop(Reject):
    """Internal: a problem after which the rest of the stream is not read."""


class Problems:
    """The problems of one document as they are found, reported as a compiler would:
    in file order, each kind (code) once, with a count of its repeats.

    At most ``2 * keep`` of each kind are held between trims, so a document
    with a hundred thousand problems costs no more memory than one with a few.
    """

    __slots__ = ("keep", "count", "_held", "_counts")

    def __init__(self, keep):
        self.keep = keep
        self.count = 0
        self._held = []
        self._counts = {}  # code -> problems of that kind found

    def add(self, reject):
        self.count += 1
        self._counts[reject.code] = self._counts.get(reject.code, 0) + 1
        if self.keep:
            self._held.append(reject)
            if len(self._held) >= 2 * self.keep * len(self._counts):
                self._trim()

    def drop_within(self, node):
        """Forget the problems found inside ``node`` (the value of a key reported
        unknown: what is wrong inside it is no news), so none cascades."""
        start, end = (node.line, node.column), node.end
        kept = []
        for reject in self._held:
            if start <= _position(reject) < end:
                self.count -= 1
                self._counts[reject.code] -= 1
            else:
                kept.append(reject)
        self._held = kept

    def first(self):
        """The problems to report, in file order: the first ``keep`` kinds, each by its first
        problem, its message counting the rest of its kind; and how many problems they stand for."""
        self._trim()
        out, covered, seen = [], 0, set()
        for reject in self._held:
            if reject.code in seen:
                continue
            seen.add(reject.code)
            if len(out) == self.keep:
                break
            rest = self._counts[reject.code] - 1
            covered += rest + 1
            if rest:
                more = f"{rest} more {reject.code} problem{'s' if rest > 1 else ''} in this document"
                reject = Reject(reject.code, "", f"{reject.message}; {more}", reject.line, reject.column)
            out.append(reject)
        return out, covered

    def _trim(self):
        self._held.sort(key=_position)  # stable: ties stay in the order found
        per_code = {}
        kept = []
        for reject in self._held:
            n = per_code.get(reject.code, 0)
            if n < self.keep:
                per_code[reject.code] = n + 1
                kept.append(reject)
        self._held = kept


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
