"""One line of a JSON Lines stream: a grasp document, or a twist (io/lines.py reads the stream)."""

from __future__ import annotations

import math
from dataclasses import replace

import orjson
import yaml

from ...engine import screws
from ...model import Grasp, InputError, Twist
from ..limits import DEFAULT_MAX_BYTES
from .compose import PARSER, compose, syntax_error
from .problems import MAX_ERRORS, Problems, Reject, located, located_mark
from .reader import READING, read_text, stem_name
from .text import decode
from .twists import TWIST_KEYS, twist_parts
from .values import describe, read_mapping, read_name, readonly

__all__ = ["read_line", "read_twist_line"]

_INF = math.inf
_ZERO = (0.0, 0.0, 0.0)


def read_line(data, *, file, line, max_bytes=DEFAULT_MAX_BYTES, reading=READING):
    """The grasp of one line of a JSON Lines stream, or its errors, placed at ``line``.

    The line is one grasp document (JSON is YAML), checked as in a grasp
    file; positions count from the stream's start, an unnamed grasp is
    ``stem#line`` and ``document`` is ``line - 1``.  ``max_bytes`` caps the
    line, not the stream; ``reading`` as for
    :func:`~grasptwist.read_grasps`.

    >>> for error in read_line(b'{"contacts": []}', file="in.jsonl", line=7):
    ...     print(error)
    in.jsonl:7:14: contacts: expected exactly 3 contacts, got 0
    """
    try:
        text = _line_text(data, max_bytes)
    except Reject as reject:
        return [_on_line(reject.error(file, None), line)]
    return [_on_line(entry, line) for entry in read_text(text, file, reading, name=f"{stem_name(file)}#{line}")]


def read_twist_line(data, *, file, line, max_bytes=DEFAULT_MAX_BYTES):
    """The twist of one line of a JSON Lines stream of twists, or its errors.

    A line is a 6-array ``(omega; v)`` (``v`` at the origin), or a mapping
    with a grasp file's twist keys (``name``, ``screw`` or ``angular``,
    ``linear``, ``at``), checked as there.  An unnamed twist is named after
    its line number.

    Returns
    -------
    Twist or list of InputError

    Examples
    --------
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
            return Twist(str(line), readonly([*screw[:3], *screws.twist_at3(screw[:3], screw[3:], _ZERO)]), line)
    problems = Problems(MAX_ERRORS)
    try:
        root = _line_node(_line_text(data, max_bytes), problems)
    except Reject as reject:
        return [_on_line(reject.error(file, None), line)]
    if root.kind == "sequence":
        fields = {"screw": root}
    elif root.kind in ("mapping", "invalid"):
        fields = read_mapping(root, "", TWIST_KEYS, (), problems)
    else:
        fields = None
        problems.add(
            Reject(
                "not-a-mapping",
                "",
                f"expected a twist [wx, wy, wz, vx, vy, vz] or a mapping, got {describe(root)}",
                **located(root),
            )
        )
    name = str(line)
    if fields is not None and "name" in fields:
        name = read_name(fields["name"], "name", problems)
    parts = None if fields is None else twist_parts(fields, root, "", problems)
    if not problems.count:
        screw = [*parts[0], *screws.twist_at3(*parts)]
        if all(map(math.isfinite, screw)):
            return Twist(name, readonly(screw), line)
        problems.add(
            Reject(
                "non-finite",
                "",
                "the velocity of the origin overflows (linear + angular x (origin - at))",
                **located(root),
            )
        )
    return [_on_line(reject.error(file, None), line) for reject in problems.first()[0]]


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
        raise Reject("too-large", "", f"the line is longer than the size limit of {max_bytes} bytes")
    return decode(data)


def _line_node(text, problems):
    """The node tree of the one document of a line."""
    parser = PARSER(text)
    try:
        parser.get_event()  # StreamStartEvent
        if parser.check_event(yaml.StreamEndEvent):
            raise Reject("empty-document", "", "no value on the line")
        parser.get_event()  # DocumentStartEvent
        root = compose(parser.get_event, problems)
        if not parser.check_event(yaml.StreamEndEvent):
            raise Reject(
                "yaml-syntax", "", "more than one document on the line", **located_mark(parser.peek_event().start_mark)
            )
        return root
    except yaml.YAMLError as exc:
        raise syntax_error(exc, text) from None
    finally:
        parser.dispose()


def _on_line(entry, line):
    """An entry read from one line's text, placed at ``line`` of the stream."""
    if isinstance(entry, Grasp):
        p = entry.placement  # a hand's fingers are reported where their tips stand: on this line
        placement = p if p is None else replace(p, tips=tuple((line, column) for _, column in p.tips))
        twists = tuple(replace(t, line=line) for t in entry.twists)
        return replace(entry, line=line, document=line - 1, twists=twists, placement=placement)
    return InputError(entry.code, entry.message, entry.file, line, entry.column, line - 1)
