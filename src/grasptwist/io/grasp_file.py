"""Grasp files: read YAML grasp descriptions into arrays, strictly checked.

A grasp file holds one grasp per YAML document (see "Grasp files" in README.md
for the format).  Reading never constructs arbitrary Python objects and
never lets a parser exception escape: every problem becomes a
:class:`GraspFileError` that names the file, line, column and field path.

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
  tag except the core ones, so no tag can ever construct an object;
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
from itertools import chain
from pathlib import Path

import numpy as np
import yaml

from ..engine import screws
from ..model import Grasp, GraspFileError, Twist

__all__ = [
    "Twist",
    "Grasp",
    "GraspFileError",
    "DEFAULT_MAX_BYTES",
    "MAX_DEPTH",
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

# Parser used by read_grasps; tests swap it to check both give the same.
_LOADER = yaml.CSafeLoader if yaml.__with_libyaml__ else yaml.SafeLoader

# Keys of each mapping, in the order the values are checked.
GRASP_KEYS = ("name", "units", "wrist", "contacts", "twists")
CONTACT_KEYS = ("name", "point", "normal")
TWIST_KEYS = ("name", "screw", "angular", "linear", "at")


def read_grasps(source, *, file=None, max_bytes=DEFAULT_MAX_BYTES):
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

    Returns
    -------
    list of Grasp or GraspFileError
        One entry per YAML document, in order.  A syntax error that stops
        the parser ends the list with one error after the good documents
        before it; a whole-file failure gives a single error.
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
    return _read_text(text, file)


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
    """At most ``max_bytes + 1`` bytes of a file, or of stdin for ``"-"``.

    One byte past the cap is enough to know it is exceeded, without
    trusting stat (pipes, /proc) or reading a huge file into memory.
    """
    try:
        if isinstance(path, str) and path == "-":
            return _read_capped(sys.stdin.buffer, max_bytes + 1)
        with open(path, "rb", opener=_open_no_pipe) as handle:
            return _read_capped(handle, max_bytes + 1)
    except OSError as exc:
        raise _Reject("read-error", "", f"cannot read: {exc.strerror or exc}") from None


def _open_no_pipe(path, flags):
    """Open without blocking and refuse a pipe or socket, whose reading could
    wait forever: a path swapped for a FIFO after the folder was listed must
    not hang the run (devices such as /dev/zero are read up to the cap)."""
    fd = os.open(path, flags | os.O_NONBLOCK)
    mode = os.fstat(fd).st_mode
    if stat.S_ISFIFO(mode) or stat.S_ISSOCK(mode):
        os.close(fd)
        raise OSError(errno.EINVAL, "not a regular file (a pipe, socket or device)")
    return fd


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
    node)), ``"sequence"`` (list of nodes) or ``"scalar"`` (the resolved
    str, int, float, bool or None, and its ``text`` as written).
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


def _scalar(event, stack):
    """The node of a scalar event, its value resolved from text and tag."""
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
            raise _Reject(
                kind, _here(stack), f"{text!r} is not a valid {_short_tag(tag)}", **_at_mark(event.start_mark)
            )
    else:
        raise _forbidden_tag(tag, event, _here(stack))
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
    for node, key in stack:
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


def _compose(get_event):
    """Node tree of one document, read (``get_event()``) up to and including its end event.

    Returns the root node, or the document's first problem as a
    ``_Reject``; after a problem the document's remaining events are only
    counted for depth.  Raises ``_StreamStop`` for nesting beyond
    ``MAX_DEPTH``.
    """
    stack = []  # open collections, innermost last: [node, key awaiting its value]
    root = problem = None
    depth = 0
    while True:
        event = get_event()
        kind = type(event)
        if kind is yaml.DocumentEndEvent:
            return problem or root
        if kind in _STARTS:
            depth += 1
            if depth > MAX_DEPTH:
                raise _StreamStop(
                    "too-deep",
                    _stack_path(stack) if problem is None else "",
                    f"nested deeper than {MAX_DEPTH} levels",
                    **_at_mark(event.start_mark),
                )
        elif kind in _ENDS:
            depth -= 1
        if problem is not None:
            continue
        try:
            node = _step(stack, event, kind)
        except _Reject as reject:
            problem = reject
            continue
        if node is not None:
            root = node


def _step(stack, event, kind):
    """Apply one event to the open collections; return the root when complete."""
    if kind is yaml.ScalarEvent:
        node = _scalar(event, stack)
    elif kind in _STARTS:
        collection = _STARTS[kind]
        if event.tag not in (None, "!", _COLLECTION_TAGS[collection]):
            raise _forbidden_tag(event.tag, event, _here(stack))
        stack.append([_Node(collection, {} if collection == "mapping" else [], event.start_mark), None])
        return None
    elif kind in _ENDS:
        node = stack.pop()[0]
    elif kind is yaml.AliasEvent:
        raise _Reject(
            "alias",
            _here(stack),
            f"aliases (*{event.anchor}) are not allowed; write the value out",
            **_at_mark(event.start_mark),
        )
    else:  # no other event can occur inside a document
        raise AssertionError(f"unexpected YAML event {event}")
    if not stack:
        return node
    frame = stack[-1]
    parent, key = frame
    if parent.kind == "sequence":
        parent.value.append(node)
    elif key is None:
        _check_key(node, parent, stack)
        frame[1] = node
    else:
        parent.value[key.value] = (key, node)
        frame[1] = None
    return None


def _check_key(key, mapping, stack):
    """Keys must be strings and must not repeat."""
    if key.kind != "scalar" or not isinstance(key.value, str):
        raise _Reject("invalid-key", _here(stack), f"keys must be strings, got {_describe(key)}", **_at(key))
    if key.value in mapping.value:
        first = mapping.value[key.value][0]
        raise _Reject(
            "duplicate-key",
            _join(_stack_path(stack), key.value),
            f"duplicate key (first given at line {first.line})",
            **_at(key),
        )


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
        normals.append(_unit_normal(*normal))
    if len(names) != 3:
        raise _Bail
    return tuple(names), points, normals


def _unit_normal(x, y, z):
    """``_contacts``'s normalisation of a non-zero finite vector in floats:
    the same operations as ``screws.unit(a / np.abs(a).max())``, in the same
    order, so the same IEEE results."""
    big = max(abs(x), abs(y), abs(z))
    x /= big
    y /= big
    z /= big
    length = math.sqrt(x * x + y * y + z * z)
    return [x / length, y / length, z / length]


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
        # screws.twist_at: velocity - cross(omega, at), term by term.
        v0 = u0 - (w1 * p2 - w2 * p1)
        v1 = u1 - (w2 * p0 - w0 * p2)
        v2 = u2 - (w0 * p1 - w1 * p0)
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


def _read_text(text, file):
    """Parse ``text`` and turn each document into a Grasp or an error."""
    roots = []  # (start line, _Parts, root node or _Reject), one per complete document
    stop = None
    parser = _LOADER(text)
    get_event = parser.get_event
    try:
        get_event()  # StreamStartEvent
        while not parser.check_event(yaml.StreamEndEvent):
            start = get_event()  # DocumentStartEvent
            events = []
            try:
                root = _fast_document(get_event, events.append)
            except _Bail:
                # The general composer, from the document's first event.
                root = _compose(chain(events, iter(get_event, None)).__next__)
            roots.append((start.start_mark.line + 1, root))
    except _StreamStop as reject:
        stop = reject
    except yaml.YAMLError as exc:
        stop = _syntax_error(exc, text)
    finally:
        parser.dispose()
    if not roots and stop is None:
        return [GraspFileError("empty-document", "no YAML document in the file", file)]
    several = len(roots) + (stop is not None) > 1
    stem = None  # Path(file).stem, only if a grasp has no name of its own
    entries = []
    for document, (line, root) in enumerate(roots):
        if type(root) is _Parts and root.name is not None:
            name = root.name
        else:
            if stem is None:
                stem = Path(file).stem
            name = f"{stem}#{document + 1}" if several else stem
        try:
            if type(root) is _Parts:
                entries.append(root.grasp(file=file, document=document, name=name, line=line))
                continue
            if isinstance(root, _Reject):
                raise root
            entries.append(_grasp(root, file=file, document=document, name=name, line=line))
        except _Reject as reject:
            entries.append(reject.error(file, document))
    if stop is not None:
        entries.append(stop.error(file, len(roots)))
    return entries


def _syntax_error(exc, text):
    """A ``_StreamStop`` for a PyYAML or libyaml syntax error."""
    mark = getattr(exc, "problem_mark", None)
    if mark is None:
        return _StreamStop("yaml-syntax", "", f"invalid YAML: {exc}")
    problem = exc.problem or "syntax error"
    lines = text.split("\n")
    if mark.line < len(lines) and lines[mark.line][mark.column : mark.column + 1] == "\t":
        # The two parsers word this differently; it is common enough to fix.
        problem = "tab character; YAML indentation must use spaces"
    return _StreamStop("yaml-syntax", "", f"invalid YAML: {problem}", line=mark.line + 1, column=mark.column + 1)


def _grasp(root, *, file, document, name, line):
    """Check one document's node tree and build its Grasp."""
    if root.kind == "scalar" and root.value is None:
        raise _Reject("empty-document", "", "empty document", **_at(root))
    fields = _mapping(root, "", GRASP_KEYS, ("contacts",))
    if "name" in fields:
        name = _name(fields["name"], "name")
    units = _name(fields["units"], "units") if "units" in fields else None
    wrist = _readonly(_vector(fields["wrist"], 3, "wrist")) if "wrist" in fields else None
    contact_names, points, normals = _contacts(fields["contacts"])
    twists = _twists(fields["twists"]) if "twists" in fields else ()
    return Grasp(
        name=name,
        units=units,
        file=file,
        document=document,
        contact_names=contact_names,
        points=points,
        normals=normals,
        wrist=wrist,
        twists=twists,
        line=line,
    )


def _contacts(node):
    """Names, points and unit normals of the three contacts."""
    items = _sequence(node, "contacts")
    if len(items) != 3:
        raise _Reject("contact-count", "contacts", f"expected exactly 3 contacts, got {len(items)}", **_at(node))
    names, points, normals = [], [], []
    for i, item in enumerate(items):
        path = f"contacts[{i}]"
        fields = _mapping(item, path, CONTACT_KEYS, ("point", "normal"))
        names.append(_entry_name(fields, item, "contacts", i, names))
        points.append(_vector(fields["point"], 3, path + ".point"))
        normal = _vector(fields["normal"], 3, path + ".normal")
        if not any(normal):
            raise _Reject("zero-normal", path + ".normal", "a zero vector has no direction", **_at(fields["normal"]))
        normals.append(normal)
    normals = np.array(normals)
    # Scale by the largest component first: screws.unit squares the
    # components, which would overflow for 1e200 or underflow for 1e-200.
    normals = screws.unit(normals / np.abs(normals).max(axis=1, keepdims=True))
    return tuple(names), _readonly(np.array(points)), _readonly(normals)


def _twists(node):
    """The desired twists, converted to ``(omega; v)`` at the origin."""
    items = _sequence(node, "twists")
    names, parts = [], []
    for i, item in enumerate(items):
        path = f"twists[{i}]"
        fields = _mapping(item, path, TWIST_KEYS, ())
        names.append(_entry_name(fields, item, "twists", i, names))
        parts.append(_twist_parts(fields, item, path))
    if not items:
        return ()
    omega, velocity, at = np.array(parts).transpose(1, 0, 2)
    with np.errstate(over="ignore", invalid="ignore"):
        screw = screws.twist_at(omega, velocity, at)
    overflowed = np.flatnonzero(~np.isfinite(screw).all(axis=1))
    if overflowed.size:
        i = int(overflowed[0])
        raise _Reject(
            "non-finite",
            f"twists[{i}]",
            "the velocity of the origin overflows (linear + angular x (origin - at))",
            **_at(items[i]),
        )
    return tuple(Twist(name, _readonly(s), item.line) for name, s, item in zip(names, screw, items))


def _twist_parts(fields, item, path):
    """``(angular, linear, at)`` of one twist entry, zeros where not given."""
    zero = [0.0, 0.0, 0.0]
    if "screw" in fields:
        for other in ("angular", "linear", "at"):
            if other in fields:
                raise _Reject(
                    "conflicting-keys",
                    _join(path, other),
                    "cannot be combined with 'screw' (give screw, or angular/linear/at)",
                    **_at(fields[other]),
                )
        screw = _vector(fields["screw"], 6, path + ".screw")
        return screw[:3], screw[3:], zero
    if "angular" not in fields and "linear" not in fields:
        raise _Reject("missing-key", path, "needs 'screw', or 'angular' and/or 'linear'", **_at(item))
    return tuple(
        _vector(fields[key], 3, f"{path}.{key}") if key in fields else zero for key in ("angular", "linear", "at")
    )


def _entry_name(fields, item, collection, index, taken):
    """Name of entry ``index`` of a list of contacts or twists (default: its
    1-based position), checked to be unique among the names ``taken``."""
    path = f"{collection}[{index}]"
    node = fields.get("name")
    name = _name(node, path + ".name") if node is not None else str(index + 1)
    if name in taken:
        raise _Reject(
            "duplicate-name",
            path + ".name" if node is not None else path,
            f"duplicate name {name!r} (also {collection}[{taken.index(name)}])",
            **_at(node if node is not None else item),
        )
    return name


# --------------------------------------------------------------------------
# Typed values.


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


def _shorten(text):
    """``text`` cut to 30 characters for a message (a long number or string stays one short line)."""
    return text if len(text) <= 30 else text[:27] + "..."


def _mapping(node, path, keys, required):
    """The ``{key: value node}`` of a mapping node with only known keys."""
    if node.kind != "mapping":
        raise _Reject("not-a-mapping", path or "top level", f"expected a mapping, got {_describe(node)}", **_at(node))
    fields = {}
    for key, (key_node, value) in node.value.items():
        if key not in keys:
            raise _Reject("unknown-key", _join(path, key), f"unknown key{_suggest(key, keys)}", **_at(key_node))
        fields[key] = value
    for key in required:
        if key not in fields:
            raise _Reject("missing-key", _join(path, key), "required key is missing", **_at(node))
    return fields


def _suggest(key, keys):
    # difflib is only needed on this error path.
    from difflib import get_close_matches

    close = get_close_matches(key, keys, n=1)
    if close:
        return f" (did you mean {close[0]!r}?)"
    return f" (expected one of: {', '.join(keys)})"


def _sequence(node, path):
    if node.kind != "sequence":
        raise _Reject("not-a-list", path, f"expected a list, got {_describe(node)}", **_at(node))
    return node.value


def _name(node, path):
    """A label: a non-empty single line, taken as written.

    A plain ``1``, ``1e3`` or ``true`` is the label "1", "1e3", "true":
    PyYAML's dumper leaves strings like "1e3" unquoted (YAML 1.1 reads
    them as strings), and a label has no use for the number.
    """
    if node.kind != "scalar" or node.value is None:
        raise _Reject("not-a-string", path, f"expected a name, got {_describe(node)}", **_at(node))
    if not node.text.strip():
        raise _Reject("invalid-name", path, "must be a non-empty single line", **_at(node))
    bad = _NOT_IN_A_NAME.search(node.text)
    if bad:
        raise _Reject(
            "invalid-name",
            path,
            f"must be a non-empty single line without control characters (found U+{ord(bad.group()):04X})",
            **_at(node),
        )
    return node.text


# Names are echoed into one-line diagnostics and terminal tables, so none of
# the characters that break a line or drive a terminal: C0 and C1 controls
# (newline, ESC, NUL, NEL ...), which double-quoted escapes such as "\e[2J"
# or "\0" can produce although the file itself holds none, and the Unicode
# line and paragraph separators.
_NOT_IN_A_NAME = re.compile("[\x00-\x1f\x7f-\x9f\u2028\u2029]")


def _vector(node, length, path):
    """A list of ``length`` finite numbers, as floats."""
    if node.kind != "sequence":
        raise _Reject("not-a-list", path, f"expected {length} numbers, got {_describe(node)}", **_at(node))
    if len(node.value) != length:
        raise _Reject("vector-length", path, f"expected {length} numbers, got {len(node.value)}", **_at(node))
    return [_number(item, f"{path}[{i}]") for i, item in enumerate(node.value)]


def _number(node, path):
    """A finite number (int or float; booleans and strings are not numbers)."""
    value = node.value
    if node.kind != "scalar" or type(value) not in (int, float):
        raise _Reject("not-a-number", path, f"expected a number, got {_describe(node)}", **_at(node))
    try:
        value = float(value)
    except OverflowError:  # an integer beyond the float range
        value = math.inf
    if not math.isfinite(value):
        raise _Reject("non-finite", path, f"expected a finite number, got {_shorten(node.text)}", **_at(node))
    return value


def _readonly(values):
    array = np.array(values, dtype=float)
    array.setflags(write=False)
    return array
