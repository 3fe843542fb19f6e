"""Grasp files: read YAML grasp descriptions into arrays, strictly checked.

A grasp file holds one grasp per YAML document (see "Grasp files" in README.md
for the format).  Reading never constructs arbitrary Python objects and
never lets a parser exception escape: every problem becomes a
:class:`GraspFileError` that names the file, line, column and field path.
Every problem of a document is reported, in file order, not just its first
(at most ``MAX_ERRORS`` per file; one more entry counts the rest).

How the YAML is read, and why
-----------------------------
The file is parsed into *events* by the safe loader (libyaml's
``CSafeLoader`` when available, else the pure-Python ``SafeLoader``) and the
events are assembled here into a small node tree, instead of letting PyYAML
compose or construct.  Doing the composition ourselves lets us

- stop at a nesting depth of ``MAX_DEPTH`` before anything recurses: both
  PyYAML composers recurse once per level (the pure one raises
  ``RecursionError`` near 500 levels; the C one, in PyYAML 6.0, crashes the
  interpreter with a segmentation fault at 100,000 levels, a 200 kB file),
  and both scanners slow down quadratically with depth, so a deep document
  must end the parse at once;
- reject aliases outright, so no alias bomb can expand, and reject every
  tag except the core ones, so no tag can ever construct an object, and go
  on composing after either, to find the document's other problems;
- see duplicate keys, which PyYAML silently merges;
- resolve plain scalars with the YAML 1.2 core schema (``1e-3`` is a
  number, ``yes`` is a string, as in editors' YAML language servers),
  identically for both parsers.

The two parsers report the same events and marks, so results and error
positions do not depend on whether libyaml is installed; only the wording
of YAML syntax errors differs between them.

For speed, a plainly written valid document is first read straight from
its events into floats and strings (``_fast_document``); at anything it is
not sure of, the document's recorded events go through the general path
above, which gives every error.  Both paths give the same grasps.
"""

from __future__ import annotations

import errno
import math
import os
import re
import stat
import sys
from dataclasses import dataclass, replace
from itertools import chain
from pathlib import Path

import numpy as np
import orjson
import yaml

from ..engine import screws
from ..model import Grasp, GraspFileError, ObjectPath, Segment, Twist

__all__ = [
    "read_line",
    "read_twist_line",
    "Twist",
    "Grasp",
    "GraspFileError",
    "DEFAULT_MAX_BYTES",
    "MAX_DEPTH",
    "MAX_DOCUMENTS",
    "MAX_ERRORS",
    "Reading",
    "read_grasps",
    "load_grasps",
    "grasp_schema",
]

DEFAULT_MAX_BYTES = 1 << 20
"""Default size cap in bytes; larger files are rejected before parsing."""

MAX_DEPTH = 32
"""Deepest collection nesting accepted.  A valid grasp needs 4 (document,
``contacts``, a contact, its ``point``); the margin lets mistyped nested
values get their specific error instead of ``too-deep``."""

MAX_DOCUMENTS = 10_000
"""Most documents read from one file; the rest of a longer file is refused
with one ``too-many-documents`` entry.  A grasp takes at least about 110
bytes, so no valid file within the default size cap has this many; a file of
``---`` lines would otherwise give one entry per 4 bytes."""

MAX_ERRORS = 100
"""Most problems reported for one file (the first, in file order); one more
``too-many-errors`` entry says how many were left out."""

#: Why a path that is not a regular file (or folder) is not read.
NOT_REGULAR = "not a regular file (a pipe, socket or device)"


@dataclass(frozen=True)
class Reading:
    """How :func:`read_grasps` reads a file: its YAML parser, per-file limits, and paths.

    The defaults are what the command line uses; tests pass others to run
    both parsers, small limits, or the general path alone.

    Attributes
    ----------
    parser : type
        The PyYAML loader class whose events are read: libyaml's
        ``CSafeLoader`` where PyYAML has it, else the pure ``SafeLoader``.
    max_documents : int
        Documents read from one file (see :data:`MAX_DOCUMENTS`).
    max_errors : int
        Problems reported for one file (see :data:`MAX_ERRORS`).
    fast : bool
        Try the fast path on each document first (False: every document
        through the general composer, which must give the same entries).
    """

    parser: type = yaml.CSafeLoader if yaml.__with_libyaml__ else yaml.SafeLoader
    max_documents: int = MAX_DOCUMENTS
    max_errors: int = MAX_ERRORS
    fast: bool = True


#: The command line's way of reading.
READING = Reading()

# Keys of each mapping, in the order the values are checked.
GRASP_KEYS = ("name", "units", "wrist", "contacts", "twists", "paths", "hand")
CONTACT_KEYS = ("name", "point", "normal")
TWIST_KEYS = ("name", "screw", "angular", "linear", "at")
PATH_KEYS = ("name", "frame", "segments")
SEGMENT_KEYS = ("duration", "screw", "angular", "linear", "at", "pose")
POSE_KEYS = ("position", "rotation", "rotvec")


def read_grasps(source, *, file=None, max_bytes=DEFAULT_MAX_BYTES, reading=READING):
    """Read every grasp of a grasp file, keeping errors as values.

    Parameters
    ----------
    source : str, os.PathLike or bytes
        A path (``"-"`` reads standard input) or the file's content.  A
        ``str`` is content exactly when ``file`` is given, else a path;
        bytes are always content.
    file : str, optional
        Name used in results and messages; default the path, ``"<stdin>"``
        or ``"<string>"``.
    max_bytes : int
        Size cap; a larger input fails with ``too-large`` before parsing.
    reading : Reading
        The parser and per-file limits (default: the command line's).

    Returns
    -------
    list of Grasp or GraspFileError
        In file order: a Grasp for each good document and an error for each
        problem of a bad one (several per document, each with its own
        position).  A syntax error, a too-deep document or more than
        ``reading.max_documents`` documents stop the reading: one error after the
        entries before it.  Beyond ``reading.max_errors`` problems one last
        ``too-many-errors`` error counts the rest.  A whole-file failure
        gives a single error.

    Examples
    --------
    >>> text = "contacts:\\n  - {point: [0, 0], normal: [1, 0, '0']}\\n"
    >>> for error in read_grasps(text, file="g.yaml"):
    ...     print(error)
    g.yaml:2:3: contacts: expected exactly 3 contacts, got 1
    g.yaml:2:13: contacts[0].point: expected 3 numbers, got 2
    g.yaml:2:36: contacts[0].normal[2]: expected a number, got the string '0'
    """
    is_content = isinstance(source, (bytes, bytearray, memoryview)) or (isinstance(source, str) and file is not None)
    if file is None:
        file = "<string>" if is_content else "<stdin>" if source == "-" else os.fspath(source)
    try:
        data = _encode(source) if is_content else _read_file(source, max_bytes)
        if len(data) > max_bytes:
            raise _Reject("too-large", "", f"larger than the size limit of {max_bytes} bytes")
        text = _decode(data)
    except _Reject as reject:
        return [reject.error(file, None)]
    return _read_text(text, file, reading)


def load_grasps(source, **kw):
    """Like :func:`read_grasps`, but raise its first :class:`GraspFileError`."""
    entries = read_grasps(source, **kw)
    for entry in entries:
        if isinstance(entry, GraspFileError):
            raise entry
    return entries


def grasp_schema():
    """The JSON Schema of a grasp document (a fresh dict on each call)."""
    # Imported here: only the ``schema`` command and tests need them.
    import json
    from importlib.resources import files

    return json.loads(files("grasptwist.io").joinpath("grasp_schema.json").read_text("utf-8"))


# --------------------------------------------------------------------------
# Whole-file checks: size, encoding, characters.


class _Reject(Exception):
    """Internal: one located problem, turned into a GraspFileError later."""

    def __init__(self, code, path, problem, line=None, column=None):
        super().__init__(code)
        self.code = code
        self.message = f"{path}: {problem}" if path else problem
        self.line = line
        self.column = column

    def error(self, file, document):
        return GraspFileError(self.code, self.message, file, self.line, self.column, document)


class _StreamStop(_Reject):
    """Internal: a problem after which the rest of the stream is not read."""


class _Problems:
    """The problems of one document as they are found: the first ``keep`` of
    them in file order, and how many there are in all.

    At most ``2 * keep`` are held between trims, so a document with a
    hundred thousand problems costs no more memory than one with ``keep``.
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

    def first(self):
        """The problems kept, in file order (found order among equal positions)."""
        self._trim()
        return self._held

    def _trim(self):
        self._held.sort(key=_position)  # stable: ties stay in the order found
        del self._held[self.keep :]


def _position(reject):
    return reject.line or 0, reject.column or 0


def _at(node):
    """Keyword arguments locating a node (1-based)."""
    return {"line": node.line, "column": node.column}


def _at_mark(mark):
    """Keyword arguments locating a parser mark (0-based) as 1-based."""
    return {"line": mark.line + 1, "column": mark.column + 1}


def _encode(content):
    """Content given as bytes or str, as bytes (to check size and UTF-8 alike)."""
    if not isinstance(content, str):
        return bytes(content)
    try:
        return content.encode("utf-8")
    except UnicodeEncodeError as exc:  # lone surrogates
        raise _Reject("invalid-utf8", "", f"not valid Unicode at character {exc.start}") from None


def _read_file(path, max_bytes):
    """At most ``max_bytes + 1`` bytes of a regular file, or of stdin for ``"-"``.

    One byte past the cap is enough to know it is exceeded, without
    trusting stat (/proc) or reading a huge file into memory.  The file is
    opened non-blocking and checked after opening: a path that is (or was
    swapped for) a FIFO, socket or device never hangs or streams forever.
    """
    try:
        if isinstance(path, str) and path == "-":
            return _read_capped(sys.stdin.buffer, max_bytes + 1)
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
        with open(fd, "rb") as handle:
            mode = os.fstat(fd).st_mode
            if not stat.S_ISREG(mode):
                why = os.strerror(errno.EISDIR) if stat.S_ISDIR(mode) else NOT_REGULAR
                raise _Reject("read-error", "", f"cannot read: {why}")
            return _read_capped(handle, max_bytes + 1)
    except OSError as exc:
        raise _Reject("read-error", "", f"cannot read: {exc.strerror or exc}") from None


_CHUNK = 1 << 16


def _read_capped(handle, limit):
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


def _decode(data):
    """Strict UTF-8 text of ``data``, checked for characters YAML refuses.

    Done here rather than by the parsers so that both report the same
    error at the same place.
    """
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        start = data.rfind(b"\n", 0, exc.start) + 1
        column = len(data[start : exc.start].decode("utf-8", "replace")) + 1
        raise _Reject(
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
        raise _Reject(
            "control-character",
            "",
            f"control character U+{ord(bad.group()):04X} is not allowed in YAML (escape it in a double-quoted string)",
            line=text.count("\n", 0, pos) + 1,
            column=pos - text.rfind("\n", 0, pos),
        )
    return text


# --------------------------------------------------------------------------
# Events -> node tree.


class _Node:
    """A composed YAML node.

    ``kind`` is ``"mapping"`` (``value``: dict key -> (key node, value
    node)), ``"sequence"`` (list of nodes), ``"scalar"`` (the resolved
    str, int, float, bool or None, and its ``text`` as written) or
    ``"invalid"`` (refused for its YAML, its problem already reported: a
    forbidden tag, an alias, a tag its text does not fit).
    ``line``/``column`` are 1-based.
    """

    __slots__ = ("kind", "value", "text", "line", "column")

    def __init__(self, kind, value, mark, text=None):
        self.kind = kind
        self.value = value
        self.text = text
        self.line = mark.line + 1
        self.column = mark.column + 1


_CORE = "tag:yaml.org,2002:"

# YAML 1.2 core schema: the plain scalars that are not strings.
_PLAIN_NUMBER = re.compile(
    r"""(?P<int>[-+]?[0-9]+)
      | 0o(?P<oct>[0-7]+)
      | 0x(?P<hex>[0-9a-fA-F]+)
      | (?P<float>[-+]?(?:\.[0-9]+|[0-9]+(?:\.[0-9]*)?)(?:[eE][-+]?[0-9]+)?)
      | (?P<inf>[-+]?)\.(?:inf|Inf|INF)
      | (?P<nan>\.(?:nan|NaN|NAN))""",
    re.VERBOSE,
)
_PLAIN_WORDS = {
    "": None, "~": None, "null": None, "Null": None, "NULL": None,
    "true": True, "True": True, "TRUE": True,
    "false": False, "False": False, "FALSE": False,
}  # fmt: skip
_NUMBER_START = frozenset("+-.0123456789")


def _resolve_plain(text):
    """Value of an untagged plain scalar under the YAML 1.2 core schema."""
    if text and text[0] in _NUMBER_START:
        match = _PLAIN_NUMBER.fullmatch(text)
        if match:
            kind = match.lastgroup
            if kind == "int":
                return _integer(text.lstrip("+-"), 10, text[0] == "-")
            if kind == "float":
                return float(text)
            if kind == "oct":
                return _integer(match["oct"], 8)
            if kind == "hex":
                return _integer(match["hex"], 16)
            if kind == "nan":
                return math.nan
            return -math.inf if match["inf"] == "-" else math.inf
    return _PLAIN_WORDS.get(text, text)


# Bits beyond which an integer is far outside the float range (2**1024).
_INTEGER_BITS = 1100


def _integer(digits, base, negative=False):
    """An integer literal's value; ``+-inf`` when it is far beyond the float range.

    Such a value can only be refused as ``non-finite``, and Python (3.11+)
    refuses to convert more than 4300 decimal digits to or from ``int``, so
    a long literal anywhere in a file would otherwise raise ``ValueError``.
    """
    significant = digits.lstrip("0")
    if len(significant) * math.log2(base) > _INTEGER_BITS:
        return -math.inf if negative else math.inf
    value = int(significant or "0", base)
    return -value if negative else value


# Core scalar tags: the Python types the tagged text must resolve to.
_SCALAR_TAGS = {
    _CORE + "str": (str,),
    _CORE + "int": (int,),
    _CORE + "float": (int, float),
    _CORE + "bool": (bool,),
    _CORE + "null": (type(None),),
}
_COLLECTION_TAGS = {"mapping": _CORE + "map", "sequence": _CORE + "seq"}


def _short_tag(tag):
    return "!!" + tag[len(_CORE) :] if tag.startswith(_CORE) else tag


def _scalar(event, stack, problems):
    """The node of a scalar event, its value resolved from text and tag
    (an ``"invalid"`` node, its problem added, for a tag it does not fit)."""
    tag = event.tag
    text = event.value
    if tag is None:
        value = _resolve_plain(text) if event.implicit[0] else text
    elif tag == "!":  # the non-specific tag: a string
        value = text
    elif tag in _SCALAR_TAGS:
        value = text if tag == _CORE + "str" else _resolve_plain(text)
        if type(value) not in _SCALAR_TAGS[tag]:
            kind = "not-a-number" if tag in (_CORE + "int", _CORE + "float") else "bad-scalar"
            problems.add(
                _Reject(kind, _here(stack), f"{text!r} is not a valid {_short_tag(tag)}", **_at_mark(event.start_mark))
            )
            return _Node("invalid", None, event.start_mark, text)
    else:
        problems.add(_forbidden_tag(tag, event, _here(stack)))
        return _Node("invalid", None, event.start_mark, text)
    return _Node("scalar", value, event.start_mark, text)


def _forbidden_tag(tag, event, path):
    return _Reject(
        "forbidden-tag",
        path,
        f"tag {_short_tag(tag)} is not allowed (only the core tags !!str, !!int, !!float, !!bool, !!null, !!seq, !!map)",
        **_at_mark(event.start_mark),
    )


def _stack_path(stack):
    """Field path of the node that comes next in the innermost open collection."""
    path = ""
    for node, key, _ in stack:
        if node.kind == "sequence":
            path += f"[{len(node.value)}]"
        elif key is not None:
            path = _join(path, key.value)
    return path


def _here(stack):
    """Path of the next node for a message: the stack path, or "top level"."""
    return _stack_path(stack) or "top level"


_SIMPLE_KEY = re.compile(r"[A-Za-z_][A-Za-z0-9_-]*")


def _join(path, key):
    """``path.key``, or ``path['key']`` for keys that do not read as names."""
    if isinstance(key, str) and _SIMPLE_KEY.fullmatch(key):
        return f"{path}.{key}" if path else key
    return f"{path}[{key!r}]"


_STARTS = {yaml.MappingStartEvent: "mapping", yaml.SequenceStartEvent: "sequence"}
_ENDS = (yaml.MappingEndEvent, yaml.SequenceEndEvent)


def _compose(get_event, problems):
    """Node tree of one document, read (``get_event()``) up to and including its end event.

    Each problem found goes to ``problems`` and composing goes on, so that
    one pass finds them all: a node with a problem of its own (a forbidden
    tag, an alias, a tagged scalar its tag does not fit) becomes an
    ``"invalid"`` node, which the checks pass over in silence, and the value
    of a key that is not a string, or is repeated, is skipped.  Raises
    ``_StreamStop`` for nesting beyond ``MAX_DEPTH``.
    """
    stack = []  # open collections, innermost last: [node, key awaiting its value, tag allowed]
    root = None
    depth = 0
    skip = None  # while a value is skipped: its collections still open
    while True:
        event = get_event()
        kind = type(event)
        if kind is yaml.DocumentEndEvent:
            return root
        if kind in _STARTS:
            depth += 1
            if depth > MAX_DEPTH:
                raise _StreamStop(
                    "too-deep",
                    _stack_path(stack),
                    f"nested deeper than {MAX_DEPTH} levels",
                    **_at_mark(event.start_mark),
                )
        elif kind in _ENDS:
            depth -= 1
        if skip is not None:
            skip += (kind in _STARTS) - (kind in _ENDS)
            if not skip:
                skip = None
            continue
        if kind in _STARTS:
            collection = _STARTS[kind]
            allowed = event.tag in (None, "!", _COLLECTION_TAGS[collection])
            if not allowed:
                problems.add(_forbidden_tag(event.tag, event, _here(stack)))
            stack.append([_Node(collection, {} if collection == "mapping" else [], event.start_mark), None, allowed])
            continue
        if kind in _ENDS:
            node, _, allowed = stack.pop()
            if not allowed:
                node.kind = "invalid"  # its content was composed for the problems in it
        elif kind is yaml.ScalarEvent:
            node = _scalar(event, stack, problems)
        elif kind is yaml.AliasEvent:
            problems.add(
                _Reject(
                    "alias",
                    _here(stack),
                    f"aliases (*{event.anchor}) are not allowed; write the value out",
                    **_at_mark(event.start_mark),
                )
            )
            node = _Node("invalid", None, event.start_mark)
        else:  # no other event can occur inside a document
            raise AssertionError(f"unexpected YAML event {event}")
        if not stack:
            root = node
            continue
        frame = stack[-1]
        parent, key = frame[0], frame[1]
        if parent.kind == "sequence":
            parent.value.append(node)
        elif key is not None:
            parent.value[key.value] = (key, node)
            frame[1] = None
        elif _good_key(node, parent, stack, problems):
            frame[1] = node
        else:
            skip = 0  # the value that comes next


def _good_key(key, mapping, stack, problems):
    """Whether ``key`` can key ``mapping``: a string, not repeated (its problem added if not)."""
    if key.kind == "invalid":  # its problem is already added
        return False
    if key.kind != "scalar" or not isinstance(key.value, str):
        problems.add(_Reject("invalid-key", _here(stack), f"keys must be strings, got {_describe(key)}", **_at(key)))
        return False
    if key.value in mapping.value:
        first = mapping.value[key.value][0]
        problems.add(
            _Reject(
                "duplicate-key",
                _join(_stack_path(stack), key.value),
                f"duplicate key (first given at line {first.line})",
                **_at(key),
            )
        )
        return False
    return True


# --------------------------------------------------------------------------
# Events -> grasp, for plain valid documents.
#
# Nearly every document read is a valid grasp written plainly: no tags,
# numbers as plain decimal scalars.  ``_fast_document`` reads such a document
# straight from its events into strings and floats, without a node tree or
# the general checks, and is several times quicker.  At the first thing it
# does not take for certain (a tag, an alias, a non-decimal or non-finite
# number, a null, an unknown, repeated or missing key, a wrong count, a
# repeated or invalid name, deeper nesting than a grasp has, an overflow...)
# it raises ``_Bail``; ``_read_text`` then composes the document again from
# its recorded events with ``_compose`` and checks it with ``_grasp``, which
# give every error and its position.  So the fast path returns a grasp only
# where the general one returns the same grasp, bit for bit
# (tests/test_grasp_file_speed_paths.py compares the two).


class _Bail(Exception):
    """Internal: the fast path leaves this document to the general one."""


_ScalarEvent = yaml.ScalarEvent
_SequenceStart = yaml.SequenceStartEvent
_SequenceEnd = yaml.SequenceEndEvent
_MappingStart = yaml.MappingStartEvent
_MappingEnd = yaml.MappingEndEvent

# The plain scalars _resolve_plain reads as a decimal int or float.  For
# them float(text) is the value _number gives (both round correctly), except
# that an integer "-0" is int 0, so 0.0 rather than -0.0.
_DECIMAL = re.compile(r"[-+]?(?:\.[0-9]+|[0-9]+(?:\.[0-9]*)?)(?:[eE][-+]?[0-9]+)?")
_NULLS = frozenset(word for word, value in _PLAIN_WORDS.items() if value is None)
_INF = math.inf
_ZERO = (0.0, 0.0, 0.0)


def _fast_document(get, keep):
    """A plain valid document's ``_Parts``, from the events after its start.

    ``get()`` gives the next event; each one read is passed to ``keep``.
    """
    event = get()
    keep(event)
    if type(event) is not _MappingStart or event.tag is not None:
        raise _Bail
    name = units = wrist = contacts = None
    twists = ()
    seen = []
    for key in _fast_keys(get, keep):
        if key in seen:
            raise _Bail
        seen.append(key)
        if key == "contacts":
            contacts = _fast_contacts(get, keep)
        elif key == "twists":
            twists = _fast_twists(get, keep)
        elif key == "wrist":
            wrist = _fast_vector(get, keep, 3)
        elif key == "name":
            name = _fast_name(get, keep)
        elif key == "units":
            units = _fast_name(get, keep)
        else:
            raise _Bail
    if contacts is None:
        raise _Bail
    event = get()
    keep(event)
    if type(event) is not yaml.DocumentEndEvent:
        raise _Bail
    return _Parts(name, units, wrist, contacts, twists)


def _fast_keys(get, keep):
    """Each key of the mapping whose start was just read (untagged plain keys only)."""
    while True:
        event = get()
        keep(event)
        if type(event) is not _ScalarEvent:
            if type(event) is _MappingEnd:
                return
            raise _Bail
        if event.tag is not None:
            raise _Bail
        yield event.value


def _fast_entries(get, keep):
    """The start event of each mapping in the sequence that comes next (untagged only)."""
    event = get()
    keep(event)
    if type(event) is not _SequenceStart or event.tag is not None:
        raise _Bail
    while True:
        event = get()
        keep(event)
        if type(event) is not _MappingStart:
            if type(event) is _SequenceEnd:
                return
            raise _Bail
        if event.tag is not None:
            raise _Bail
        yield event


def _fast_name(get, keep):
    """What ``_name`` returns for the next node, if it accepts it."""
    event = get()
    keep(event)
    if type(event) is not _ScalarEvent or event.tag is not None:
        raise _Bail
    text = event.value
    if (event.implicit[0] and text in _NULLS) or not text.strip() or _NOT_IN_A_NAME.search(text):
        raise _Bail
    return text


def _fast_vector(get, keep, length):
    """What ``_vector`` returns for the next node, if it is a flat list of
    ``length`` plain decimal finite numbers."""
    event = get()
    keep(event)
    if type(event) is not _SequenceStart or event.tag is not None:
        raise _Bail
    values = []
    for _ in range(length):
        event = get()
        keep(event)
        if type(event) is not _ScalarEvent or event.tag is not None or not event.implicit[0]:
            raise _Bail
        text = event.value
        if _DECIMAL.fullmatch(text) is None:
            raise _Bail
        value = float(text)
        if not -_INF < value < _INF:
            raise _Bail
        if not value and text[0] == "-":
            value = float(_resolve_plain(text))  # -0 is the int 0
        values.append(value)
    event = get()
    keep(event)
    if type(event) is not _SequenceEnd:
        raise _Bail
    return values


def _fast_contacts(get, keep):
    """``_contacts`` for the next node, with the normals made unit."""
    names, points, normals = [], [], []
    for _ in _fast_entries(get, keep):
        if len(names) == 3:
            raise _Bail
        name = point = normal = None
        for key in _fast_keys(get, keep):
            if key == "point" and point is None:
                point = _fast_vector(get, keep, 3)
            elif key == "normal" and normal is None:
                normal = _fast_vector(get, keep, 3)
            elif key == "name" and name is None:
                name = _fast_name(get, keep)
            else:
                raise _Bail
        if point is None or normal is None or not any(normal):
            raise _Bail
        if name is None:
            name = str(len(names) + 1)
        if name in names:
            raise _Bail
        names.append(name)
        points.append(point)
        normals.append(screws.direction3(*normal))
    if len(names) != 3:
        raise _Bail
    return tuple(names), points, normals


def _fast_twists(get, keep):
    """``_twists`` for the next node, as ``(name, screw list, line)`` tuples."""
    names, twists = [], []
    for start in _fast_entries(get, keep):
        line = start.start_mark.line + 1
        fields = {}
        for key in _fast_keys(get, keep):
            if key in fields:
                raise _Bail
            if key == "angular" or key == "linear" or key == "at":
                fields[key] = _fast_vector(get, keep, 3)
            elif key == "name":
                fields[key] = _fast_name(get, keep)
            elif key == "screw":
                fields[key] = _fast_vector(get, keep, 6)
            else:
                raise _Bail
        name = fields.pop("name", None)
        if name is None:
            name = str(len(names) + 1)
        if name in names:
            raise _Bail
        screw = fields.get("screw")
        if screw is not None:
            if len(fields) != 1:
                raise _Bail
            w0, w1, w2, u0, u1, u2 = screw
            p0, p1, p2 = _ZERO
        elif "angular" in fields or "linear" in fields:
            w0, w1, w2 = fields.get("angular", _ZERO)
            u0, u1, u2 = fields.get("linear", _ZERO)
            p0, p1, p2 = fields.get("at", _ZERO)
        else:
            raise _Bail
        # the same operations as _twists's screws.twist_at, so the same bits
        v0, v1, v2 = screws.twist_at3((w0, w1, w2), (u0, u1, u2), (p0, p1, p2))
        if not (-_INF < v0 < _INF and -_INF < v1 < _INF and -_INF < v2 < _INF):
            raise _Bail
        names.append(name)
        twists.append((name, [w0, w1, w2, v0, v1, v2], line))
    return twists


class _Parts:
    """What ``_fast_document`` read; ``grasp`` makes it a Grasp."""

    __slots__ = ("name", "units", "wrist", "contacts", "twists")

    def __init__(self, name, units, wrist, contacts, twists):
        self.name = name
        self.units = units
        self.wrist = wrist
        self.contacts = contacts
        self.twists = twists

    def grasp(self, *, file, document, name, line):
        contact_names, points, normals = self.contacts
        return Grasp(
            name=name,
            units=self.units,
            file=file,
            document=document,
            contact_names=contact_names,
            points=_readonly(points),
            normals=_readonly(normals),
            wrist=None if self.wrist is None else _readonly(self.wrist),
            twists=tuple(Twist(twist, _readonly(screw), twist_line) for twist, screw, twist_line in self.twists),
            line=line,
        )


# --------------------------------------------------------------------------
# Stream -> grasps.


def _read_text(text, file, reading, name=None):
    """Parse ``text`` and turn each document into a Grasp or its errors, as it is read
    (an unnamed grasp called ``name`` if given)."""
    entries = _Entries(file, reading.max_errors, name)
    stop = None
    parser = reading.parser(text)
    get_event = parser.get_event
    document_line = 0  # where the document being read starts (0-based)
    try:
        get_event()  # StreamStartEvent
        while not parser.check_event(yaml.StreamEndEvent):
            if entries.documents == reading.max_documents:
                raise _StreamStop(
                    "too-many-documents",
                    "",
                    f"more than {reading.max_documents} documents; the rest of the file is not read",
                    **_at_mark(parser.peek_event().start_mark),
                )
            start = get_event()  # DocumentStartEvent
            document_line = start.start_mark.line
            events = []
            problems = None
            try:
                if not reading.fast:
                    raise _Bail
                root = _fast_document(get_event, events.append)
            except _Bail:
                # The general composer, from the document's first event.
                problems = _Problems(reading.max_errors - entries.reported)
                root = _compose(chain(events, iter(get_event, None)).__next__, problems)
            entries.add(start.start_mark.line + 1, root, problems)
    except _StreamStop as reject:
        stop = reject
    except yaml.YAMLError as exc:
        stop = _syntax_error(exc, text, document_line)
    finally:
        parser.dispose()
    return entries.close(stop)


class _Entries:
    """The entries of one file, made as its documents are read.

    Unnamed grasps are called after the file's stem, ``stem#k`` when the
    file has several documents (or a stop after the first): the first
    document's grasp is named ``stem`` until a second document shows up.
    """

    def __init__(self, file, max_errors, name=None):
        self.file = file
        self.max_errors = max_errors
        self.name = name  # the default name, if not the file's stem
        self.entries = []
        self.documents = 0
        self.reported = 0  # problems given an entry, at most max_errors
        self.unreported = 0
        self._stem = None
        self._first_unnamed = None  # the first document's grasp, when it took the default name

    def add(self, line, root, problems):
        """The entries of the next document, from its ``_Parts`` (``problems``
        None) or its node tree (with the problems found composing it)."""
        document = self.documents
        self.documents += 1
        if document == 1:
            self._number_the_first()
        if type(root) is _Parts:
            named = root.name is not None
            name = root.name if named else self._default_name(document)
            grasp = root.grasp(file=self.file, document=document, name=name, line=line)
        else:
            grasp = _grasp(
                root, problems, file=self.file, document=document, name=self._default_name(document), line=line
            )
            if grasp is None:
                first = problems.first()
                self.reported += len(first)
                self.unreported += problems.count - len(first)
                self.entries += [reject.error(self.file, document) for reject in first]
                return
            named = "name" in root.value
        if document == 0 and not named:
            self._first_unnamed = len(self.entries)
        self.entries.append(grasp)

    def close(self, stop):
        """All the entries, ``stop`` (the problem that ended the reading, or None) among them."""
        if stop is not None:
            self._number_the_first()
            self.entries.append(stop.error(self.file, self.documents))
        elif not self.documents:
            return [GraspFileError("empty-document", "no YAML document in the file", self.file)]
        if self.unreported:
            self.entries.append(
                GraspFileError(
                    "too-many-errors",
                    f"{self.unreported} more problems in this file not reported (only the first {self.max_errors} are)",
                    self.file,
                )
            )
        return self.entries

    def _default_name(self, document):
        if self.name is not None:
            return self.name
        if self._stem is None:
            self._stem = _stem_name(self.file)
        return self._stem if document == 0 else f"{self._stem}#{document + 1}"

    def _number_the_first(self):
        """The file has more than one document: an unnamed first grasp is ``stem#1``."""
        if self._first_unnamed is not None:
            grasp = self.entries[self._first_unnamed]
            self.entries[self._first_unnamed] = replace(grasp, name=f"{grasp.name}#1")
            self._first_unnamed = None


# Characters a grasp name must not hold (see _NOT_IN_A_NAME), and the
# surrogates that stand for undecodable bytes in a file name.
_NOT_IN_A_STEM = re.compile("[\x00-\x1f\x7f-\x9f\u2028\u2029\ud800-\udfff]")


def _stem_name(file):
    """A file's stem as a valid grasp name: bytes that are not UTF-8 (which
    Python keeps as surrogates) and control characters shown escaped,
    ``\\xff``, ``\\x1b``, as in a Python string."""

    def escape(match):
        code = ord(match.group())
        if 0xDC80 <= code <= 0xDCFF:  # os.fsdecode's stand-in for byte code - 0xDC00
            code -= 0xDC00
        return f"\\x{code:02x}" if code < 0x100 else f"\\u{code:04x}"

    return _NOT_IN_A_STEM.sub(escape, Path(file).stem)


def _syntax_error(exc, text, document_line=0):
    """A ``_StreamStop`` for a PyYAML or libyaml syntax error raised while
    reading the document that starts at ``document_line`` (0-based) of ``text``:
    ``too-deep`` where the document crosses ``MAX_DEPTH`` before that error."""
    mark = getattr(exc, "problem_mark", None)
    deep = _too_deep(text, document_line, mark)
    if deep is not None:
        return deep
    if mark is None:
        return _StreamStop("yaml-syntax", "", f"invalid YAML: {exc}")
    problem = exc.problem or "syntax error"
    lines = text.split("\n")
    if mark.line < len(lines) and lines[mark.line][mark.column : mark.column + 1] == "\t":
        # The two parsers word this differently; it is common enough to fix.
        problem = "tab character; YAML indentation must use spaces"
    return _StreamStop("yaml-syntax", "", f"invalid YAML: {problem}", line=mark.line + 1, column=mark.column + 1)


def _too_deep(text, document_line, mark):
    """The ``too-deep`` stop of the text from ``document_line`` on, where it
    nests deeper than ``MAX_DEPTH`` before ``mark`` (a parser's error mark, or
    None for anywhere); else None.

    libyaml has a nesting limit of its own (about 1000 levels in the one
    PyYAML 6.0.4 ships) and its scanner reads a flow collection's brackets far
    ahead of the events, so it can refuse a deep document before the events
    that cross ``MAX_DEPTH`` are seen.  The pure-Python parser, which has no
    such limit, reads the document again to find where the crossing is; the
    error path alone pays for it, and it stops at the crossing.
    """
    rest = "\n".join(text.split("\n")[document_line:]) if document_line else text
    parser = yaml.SafeLoader(rest)
    try:
        parser.get_event()  # StreamStartEvent
        while not parser.check_event(yaml.StreamEndEvent):
            parser.get_event()  # DocumentStartEvent
            _compose(parser.get_event, _Problems(0))
    except _StreamStop as stop:
        line, column = stop.line - 1 + document_line, stop.column - 1
        if mark is None or (line, column) <= (mark.line, mark.column):
            stop.line = line + 1
            return stop
    except yaml.YAMLError:
        pass
    finally:
        parser.dispose()
    return None


def _grasp(root, problems, *, file, document, name, line):
    """Check one document's node tree: its Grasp, or None when ``problems`` has any."""
    if root.kind == "scalar" and root.value is None:
        problems.add(_Reject("empty-document", "", "empty document", **_at(root)))
        return None
    fields = _mapping(root, "", GRASP_KEYS, ("contacts",), problems)
    if fields is None:
        return None
    if "name" in fields:
        name = _name(fields["name"], "name", problems)
    units = _name(fields["units"], "units", problems) if "units" in fields else None
    wrist = _vector(fields["wrist"], 3, "wrist", problems) if "wrist" in fields else None
    contacts = _contacts(fields["contacts"], problems) if "contacts" in fields else None
    twists = _twists(fields["twists"], problems) if "twists" in fields else ()
    paths = _paths(fields["paths"], problems) if "paths" in fields else ()
    hand = _hand(fields["hand"], contacts, file, problems) if "hand" in fields else None
    if problems.count:
        return None
    contact_names, points, normals = contacts
    return Grasp(
        name=name,
        units=units,
        file=file,
        document=document,
        contact_names=contact_names,
        points=points,
        normals=normals,
        wrist=None if wrist is None else _readonly(wrist),
        twists=twists,
        line=line,
        paths=paths,
        hand=None if hand is None else hand[0],
        joint_positions=None if hand is None else _readonly(hand[1]),
    )


def _hand(node, contacts, file, problems):
    """``(Hand, joint positions)`` of the ``hand`` key (see :mod:`grasptwist.io.grasp_hand`)."""
    from .grasp_hand import read_hand  # only documents with a hand need it

    return read_hand(node, None if contacts is None else contacts[1], file, problems)


# What contacts look like, for the message when they are not a list.
_CONTACTS_SHAPE = "a list of 3 contacts like [{point: [x, y, z], normal: [x, y, z]}, ...]"


def _contacts(node, problems):
    """Names, points and unit normals of the three contacts (None after a problem)."""
    items = _sequence(node, "contacts", problems, _CONTACTS_SHAPE, _contacts_hint)
    if items is None:
        return None
    if len(items) != 3:
        problems.add(
            _Reject("contact-count", "contacts", f"expected exactly 3 contacts, got {len(items)}", **_at(node))
        )
    names, points, normals = {}, [], []
    for i, item in enumerate(items):
        path = f"contacts[{i}]"
        fields = _mapping(item, path, CONTACT_KEYS, ("point", "normal"), problems)
        if fields is None:
            continue
        _entry_name(fields, item, "contacts", i, names, problems)
        points.append(_vector(fields["point"], 3, path + ".point", problems) if "point" in fields else None)
        normal = _vector(fields["normal"], 3, path + ".normal", problems) if "normal" in fields else None
        if normal is not None and not any(normal):
            problems.add(
                _Reject("zero-normal", path + ".normal", "a zero vector has no direction", **_at(fields["normal"]))
            )
        normals.append(normal)
    if problems.count:
        return None
    normals = [screws.direction3(*n) for n in normals]  # of any finite size: no over- or underflow
    return tuple(names), _readonly(np.array(points)), _readonly(normals)


def _contacts_hint(node):
    """What to change when ``contacts`` is a mapping."""
    if node.kind != "mapping" or not node.value:
        return ""
    if set(node.value) & set(CONTACT_KEYS):
        return "; start each of the three contacts with '- '"
    name = _shorten(str(next(iter(node.value))))
    return f"; write each as '- name: {name}' with its point and normal under it"


def _twists(node, problems):
    """The desired twists, converted to ``(omega; v)`` at the origin (None after a problem)."""
    items = _sequence(node, "twists", problems)
    if items is None:
        return None
    names, parts = {}, []
    for i, item in enumerate(items):
        path = f"twists[{i}]"
        fields = _mapping(item, path, TWIST_KEYS, (), problems)
        if fields is None:
            continue
        _entry_name(fields, item, "twists", i, names, problems)
        parts.append(_twist_parts(fields, item, path, problems))
    if problems.count or not items:
        return None if problems.count else ()
    omega, velocity, at = np.array(parts).transpose(1, 0, 2)
    with np.errstate(over="ignore", invalid="ignore"):
        screw = screws.twist_at(omega, velocity, at)
    for i in np.flatnonzero(~np.isfinite(screw).all(axis=1)):
        problems.add(
            _Reject(
                "non-finite",
                f"twists[{i}]",
                "the velocity of the origin overflows (linear + angular x (origin - at))",
                **_at(items[i]),
            )
        )
    if problems.count:
        return None
    return tuple(Twist(name, _readonly(s), item.line) for name, s, item in zip(names, screw, items))


def _twist_parts(fields, item, path, problems):
    """``(angular, linear, at)`` of one twist entry, zeros where not given (None after a problem)."""
    zero = [0.0, 0.0, 0.0]
    if "screw" in fields:
        for other in ("angular", "linear", "at"):
            if other in fields:
                problems.add(
                    _Reject(
                        "conflicting-keys",
                        _join(path, other),
                        "cannot be combined with 'screw' (give screw, or angular/linear/at)",
                        **_at(fields[other]),
                    )
                )
        screw = _vector(fields["screw"], 6, _join(path, "screw"), problems)
        return None if screw is None else (screw[:3], screw[3:], zero)
    if "angular" not in fields and "linear" not in fields and not _misspelt(item, ("screw", "angular", "linear")):
        problems.add(_Reject("missing-key", path, "needs 'screw', or 'angular' and/or 'linear'", **_at(item)))
    parts = [
        _vector(fields[key], 3, _join(path, key), problems) if key in fields else zero
        for key in ("angular", "linear", "at")
    ]
    return None if None in parts else parts


def _paths(node, problems):
    """The object paths, their segments checked (None after a problem)."""
    items = _sequence(node, "paths", problems)
    if items is None:
        return None
    names, found = {}, []
    for i, item in enumerate(items):
        path = f"paths[{i}]"
        fields = _mapping(item, path, PATH_KEYS, ("segments",), problems)
        if fields is None:
            continue
        _entry_name(fields, item, "paths", i, names, problems)
        frame = _frame(fields["frame"], path + ".frame", problems) if "frame" in fields else "space"
        if "segments" in fields:  # checked whatever the frame, so that every problem is found
            found.append(_segments(fields["segments"], path + ".segments", frame or "space", problems))
    if problems.count:
        return None
    return tuple(ObjectPath(name, segments, item.line) for name, segments, item in zip(names, found, items))


def _frame(node, path, problems):
    """``space`` or ``body``."""
    if node.kind == "invalid":
        return None
    from ..engine.path import FRAMES  # paths, their engine and SE(3) only for documents with paths

    if node.kind != "scalar" or node.value not in FRAMES:
        problems.add(_Reject("invalid-frame", path, f"expected space or body, got {_describe(node)}", **_at(node)))
        return None
    return node.value


def _segments(node, path, frame, problems):
    """A path's segments (None after a problem)."""
    items = _sequence(node, path, problems)
    if items is None:
        return None
    if not items:
        problems.add(_Reject("empty-path", path, "a path needs at least one segment", **_at(node)))
        return None
    segments = [_segment(item, f"{path}[{k}]", frame, problems) for k, item in enumerate(items)]
    if problems.count:
        return None
    from ..engine.path import check_segments

    return check_segments(segments)


def _segment(item, path, frame, problems):
    """One segment: a ``duration`` and a constant twist or a ``pose`` target."""
    fields = _mapping(item, path, SEGMENT_KEYS, ("duration",), problems)
    if fields is None:
        return None
    duration = _number(fields["duration"], path + ".duration", problems) if "duration" in fields else None
    if duration is not None and not duration > 0:
        problems.add(
            _Reject("invalid-duration", path + ".duration", f"must be > 0, got {duration!r}", **_at(fields["duration"]))
        )
    if "pose" in fields:
        _conflicts(
            fields, path, ("screw", "angular", "linear", "at"), "'pose' (give a twist or a pose target)", problems
        )
        pose = _pose(fields["pose"], path + ".pose", problems)
        return None if pose is None else Segment(duration, position=pose[0], rotation=pose[1])
    if not {"screw", "angular", "linear"} & set(fields):
        problems.add(
            _Reject(
                "missing-key", path, "needs a twist ('screw', or 'angular' and/or 'linear') or a 'pose'", **_at(item)
            )
        )
        return None
    parts = _twist_parts(fields, item, path, problems)
    if parts is None:
        return None
    with np.errstate(over="ignore", invalid="ignore"):
        screw = screws.twist_at(*(np.array(p) for p in parts))
    if not np.isfinite(screw).all():
        problems.add(
            _Reject(
                "non-finite",
                path,
                "the velocity of the origin overflows (linear + angular x (origin - at))",
                **_at(item),
            )
        )
        return None
    return Segment(duration, twist=screw, frame=frame)


def _conflicts(fields, path, others, what, problems):
    """A ``conflicting-keys`` problem for each key of ``others`` given beside ``what``."""
    for other in others:
        if other in fields:
            problems.add(
                _Reject("conflicting-keys", _join(path, other), f"cannot be combined with {what}", **_at(fields[other]))
            )


def _pose(node, path, problems):
    """``(position, rotation matrix)`` of a pose target: position default zero, rotation a
    quaternion ``(w, x, y, z)`` or a rotation vector, default none."""
    from ..engine import se3

    fields = _mapping(node, path, POSE_KEYS, (), problems)
    if fields is None:
        return None
    position = _vector(fields["position"], 3, path + ".position", problems) if "position" in fields else [0.0] * 3
    rotation = np.eye(3)
    if "rotation" in fields:
        _conflicts(fields, path, ("rotvec",), "'rotation' (give a quaternion or a rotation vector)", problems)
        quaternion = _vector(fields["rotation"], 4, path + ".rotation", problems)
        if quaternion is not None and any(quaternion):
            # scaled first: the engine normalises it, and a huge one must not overflow on the way
            rotation = se3.quaternion_to_matrix(np.divide(quaternion, np.abs(quaternion).max()))
        elif quaternion is not None:
            problems.add(
                _Reject(
                    "invalid-rotation",
                    path + ".rotation",
                    "a quaternion (w, x, y, z) of zero length has no rotation",
                    **_at(fields["rotation"]),
                )
            )
    elif "rotvec" in fields:
        rotvec = _vector(fields["rotvec"], 3, path + ".rotvec", problems)
        if rotvec is not None:
            rotation = se3.rotvec_to_matrix(rotvec)
    if position is None or problems.count:
        return None
    return np.array(position), rotation


def _entry_name(fields, item, collection, index, taken, problems):
    """Name entry ``index`` of a list of contacts or twists (default: its
    1-based position) in ``taken`` (name -> index), unless it is invalid or
    already taken."""
    path = f"{collection}[{index}]"
    node = fields.get("name")
    name = _name(node, path + ".name", problems) if node is not None else str(index + 1)
    if name is None:
        return
    if name in taken:
        problems.add(
            _Reject(
                "duplicate-name",
                path + ".name" if node is not None else path,
                f"duplicate name {name!r} (also {collection}[{taken[name]}])",
                **_at(node if node is not None else item),
            )
        )
        return
    taken[name] = index


# --------------------------------------------------------------------------
# Typed values.  Each adds its problems and returns None after one; an
# "invalid" node (its problem already added) is passed over in silence.


def _describe(node):
    """How a node reads in a message: 'a list', 'the string "x"', ..."""
    if node.kind != "scalar":
        return "a list" if node.kind == "sequence" else "a mapping"
    value = node.value
    if value is None:
        return "null"
    if isinstance(value, bool):
        return f"a boolean ({str(value).lower()})"
    if isinstance(value, (int, float)):
        return f"the number {_shorten(node.text)}"
    return f"the string {_shorten(value)!r}"


def _misspelt(node, keys):
    """Whether a key of mapping ``node`` is a misspelling of one of ``keys``: its "did you mean"
    line then stands in for the missing key's (as :func:`_mapping` does for required keys)."""
    from difflib import get_close_matches

    return any(key not in keys and get_close_matches(key, keys, n=1) for key in node.value)


def _shorten(text):
    """``text`` cut to 30 characters for a message (a long number or string stays one short line)."""
    return text if len(text) <= 30 else text[:27] + "..."


def _mapping(node, path, keys, required, problems):
    """The ``{key: value node}`` of the known keys of a mapping node."""
    if node.kind == "invalid":
        return None
    if node.kind != "mapping":
        problems.add(
            _Reject("not-a-mapping", path or "top level", f"expected a mapping, got {_describe(node)}", **_at(node))
        )
        return None
    fields = {}
    meant = set()  # the keys that misspelled ones were taken for
    unknown = 0
    for key, (key_node, value) in node.value.items():
        if key in keys:
            fields[key] = value
            continue
        unknown += 1
        if unknown > problems.keep:
            # After as many unknown keys as can be reported (all before it in
            # the file) this one's problem never is: count it, spare the rest.
            problems.count += 1
            continue
        # difflib is only needed on this error path.
        from difflib import get_close_matches

        close = get_close_matches(key, keys, n=1)
        meant.update(close)
        hint = f"did you mean {close[0]!r}?" if close else f"expected one of: {', '.join(keys)}"
        problems.add(_Reject("unknown-key", _join(path, key), f"unknown key ({hint})", **_at(key_node)))
    for key in required:
        if key not in fields and key not in meant:  # a misspelling already says it
            problems.add(_Reject("missing-key", _join(path, key), "required key is missing", **_at(node)))
    return fields


def _sequence(node, path, problems, expected="a list", hint=None):
    """The items of a sequence node."""
    if node.kind == "sequence":
        return node.value
    if node.kind != "invalid":
        more = hint(node) if hint else ""
        problems.add(_Reject("not-a-list", path, f"expected {expected}, got {_describe(node)}{more}", **_at(node)))
    return None


def _name(node, path, problems):
    """A label: a non-empty single line, taken as written.

    A plain ``1``, ``1e3`` or ``true`` is the label "1", "1e3", "true":
    PyYAML's dumper leaves strings like "1e3" unquoted (YAML 1.1 reads
    them as strings), and a label has no use for the number.
    """
    if node.kind == "invalid":
        return None
    if node.kind != "scalar" or node.value is None:
        problems.add(_Reject("not-a-string", path, f"expected a name, got {_describe(node)}", **_at(node)))
        return None
    if not node.text.strip():
        problems.add(_Reject("invalid-name", path, "must be a non-empty single line", **_at(node)))
        return None
    bad = _NOT_IN_A_NAME.search(node.text)
    if bad:
        problems.add(
            _Reject(
                "invalid-name",
                path,
                f"must be a non-empty single line without control characters (found U+{ord(bad.group()):04X})",
                **_at(node),
            )
        )
        return None
    return node.text


# Names are echoed into one-line diagnostics and terminal tables, so none of
# the characters that break a line or drive a terminal: C0 and C1 controls
# (newline, ESC, NUL, NEL ...), which double-quoted escapes such as "\e[2J"
# or "\0" can produce although the file itself holds none, and the Unicode
# line and paragraph separators.
_NOT_IN_A_NAME = re.compile("[\x00-\x1f\x7f-\x9f\u2028\u2029]")


def _vector(node, length, path, problems):
    """A list of ``length`` finite numbers, as floats."""
    if node.kind == "invalid":
        return None
    if node.kind != "sequence":
        problems.add(_Reject("not-a-list", path, f"expected {length} numbers, got {_describe(node)}", **_at(node)))
        return None
    values = [_number(item, f"{path}[{i}]", problems) for i, item in enumerate(node.value)]
    if len(values) != length:
        hint = ""
        if length == 3 and len(values) == 6:
            hint = "; a 6-vector (omega; v) goes under `screw:`"
        elif length == 6 and len(values) == 3:
            hint = "; a 3-vector goes under `angular:` or `linear:`"
        problems.add(_Reject("vector-length", path, f"expected {length} numbers, got {len(values)}{hint}", **_at(node)))
        return None
    return None if None in values else values


def _number(node, path, problems):
    """A finite number (int or float; booleans and strings are not numbers)."""
    value = node.value
    if node.kind == "invalid":
        return None
    if node.kind != "scalar" or type(value) not in (int, float):
        problems.add(_Reject("not-a-number", path, f"expected a number, got {_describe(node)}", **_at(node)))
        return None
    try:
        value = float(value)
    except OverflowError:  # an integer beyond the float range
        value = math.inf
    if not math.isfinite(value):
        problems.add(_Reject("non-finite", path, f"expected a finite number, got {_shorten(node.text)}", **_at(node)))
        return None
    return value


def _readonly(values):
    array = np.array(values, dtype=float)
    array.setflags(write=False)
    return array


# --------------------------------------------------------------------------
# One line of a JSON Lines stream (io/lines.py reads the stream).


def read_line(data, *, file, line, max_bytes=DEFAULT_MAX_BYTES):
    """The grasp of one line of a JSON Lines stream, or its errors, placed at ``line``.

    The line is one grasp document (JSON is YAML), checked as in a grasp
    file; positions count from the stream's start, an unnamed grasp is
    ``stem#line`` and ``document`` is ``line - 1``.  ``max_bytes`` caps the
    line, not the stream.

    >>> for error in read_line(b'{"contacts": []}', file="in.jsonl", line=7):
    ...     print(error)
    in.jsonl:7:14: contacts: expected exactly 3 contacts, got 0
    """
    try:
        text = _line_text(data, max_bytes)
    except _Reject as reject:
        return [_on_line(reject.error(file, None), line)]
    return [_on_line(entry, line) for entry in _read_text(text, file, READING, name=f"{_stem_name(file)}#{line}")]


def read_twist_line(data, *, file, line, max_bytes=DEFAULT_MAX_BYTES):
    """The twist of one line of a JSON Lines stream of twists, or its errors.

    A line is a 6-array ``(omega; v)`` (``v`` at the origin), or a mapping
    with a grasp file's twist keys (``name``, ``screw`` or ``angular``,
    ``linear``, ``at``), checked as there.  An unnamed twist is named after
    its line number.

    Returns
    -------
    Twist or list of GraspFileError

    >>> read_twist_line(b"[0, 0, 1, 0, 0, 0.5]", file="-", line=3).screw.tolist()
    [0.0, 0.0, 1.0, 0.0, 0.0, 0.5]
    >>> t = read_twist_line(b'{"name": "spin", "angular": [0, 0, 1], "at": [1, 0, 0]}', file="-", line=4)
    >>> t.name, t.screw.tolist()
    ('spin', [0.0, 0.0, 1.0, 0.0, -1.0, 0.0])
    >>> print(*read_twist_line(b"[0, 0, 1]", file="<stdin>", line=5))
    <stdin>:5:1: screw: expected 6 numbers, got 3; a 3-vector goes under `angular:` or `linear:`
    """
    if len(data) <= max_bytes:
        screw = _fast_screw(data)
        if screw is not None:
            return Twist(str(line), _readonly([*screw[:3], *screws.twist_at3(screw[:3], screw[3:], _ZERO)]), line)
    problems = _Problems(MAX_ERRORS)
    try:
        root = _line_node(_line_text(data, max_bytes), problems)
    except _Reject as reject:
        return [_on_line(reject.error(file, None), line)]
    if root.kind == "sequence":
        fields = {"screw": root}
    elif root.kind in ("mapping", "invalid"):
        fields = _mapping(root, "", TWIST_KEYS, (), problems)
    else:
        fields = None
        problems.add(
            _Reject(
                "not-a-mapping",
                "",
                f"expected a twist [wx, wy, wz, vx, vy, vz] or a mapping, got {_describe(root)}",
                **_at(root),
            )
        )
    name = str(line)
    if fields is not None and "name" in fields:
        name = _name(fields["name"], "name", problems)
    parts = None if fields is None else _twist_parts(fields, root, "", problems)
    if not problems.count:
        screw = [*parts[0], *screws.twist_at3(*parts)]
        if all(map(math.isfinite, screw)):
            return Twist(name, _readonly(screw), line)
        problems.add(
            _Reject(
                "non-finite", "", "the velocity of the origin overflows (linear + angular x (origin - at))", **_at(root)
            )
        )
    return [_on_line(reject.error(file, None), line) for reject in problems.first()]


def _fast_screw(data):
    """The six numbers of a line that is a plain JSON array of six finite numbers
    (as floats, the values the general path reads), else None."""
    try:
        value = orjson.loads(data)
    except orjson.JSONDecodeError:
        return None
    if type(value) is not list or len(value) != 6:
        return None
    for x in value:
        if (type(x) is not float and type(x) is not int) or not -_INF < x < _INF:
            return None
    return [float(x) for x in value]


def _line_text(data, max_bytes):
    """A line's text, checked for size and characters."""
    if len(data) > max_bytes:
        raise _Reject("too-large", "", f"the line is longer than the size limit of {max_bytes} bytes")
    return _decode(data)


def _line_node(text, problems):
    """The node tree of the one document of a line."""
    parser = READING.parser(text)
    try:
        parser.get_event()  # StreamStartEvent
        if parser.check_event(yaml.StreamEndEvent):
            raise _Reject("empty-document", "", "no value on the line")
        parser.get_event()  # DocumentStartEvent
        root = _compose(parser.get_event, problems)
        if not parser.check_event(yaml.StreamEndEvent):
            raise _Reject(
                "yaml-syntax", "", "more than one document on the line", **_at_mark(parser.peek_event().start_mark)
            )
        return root
    except yaml.YAMLError as exc:
        raise _syntax_error(exc, text) from None
    finally:
        parser.dispose()


def _on_line(entry, line):
    """An entry read from one line's text, placed at ``line`` of the stream."""
    if isinstance(entry, Grasp):
        return replace(entry, line=line, document=line - 1, twists=tuple(replace(t, line=line) for t in entry.twists))
    return GraspFileError(entry.code, entry.message, entry.file, line, entry.column, line - 1)
