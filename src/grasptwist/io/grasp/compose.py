"""YAML events -> a small node tree, with the loader's safety rules.

See the package docstring for why the loader composes the events itself:
a depth limit (:data:`MAX_DEPTH`) before anything recurses, no aliases, no
tags beyond the core ones, duplicate keys seen, YAML 1.2 core scalars.
"""

from __future__ import annotations

import math
import re

import yaml

from ..limits import MAX_DEPTH
from .problems import Problems, Reject, StreamStop, join, located, located_mark
from .values import describe

__all__ = ["PARSER", "MAX_DEPTH", "Node", "CORE", "PLAIN_WORDS", "resolve_plain", "compose", "syntax_error", "too_deep"]

#: The YAML parser read by default: libyaml's ``CSafeLoader`` where PyYAML has it, else the pure ``SafeLoader``.
PARSER = yaml.CSafeLoader if yaml.__with_libyaml__ else yaml.SafeLoader


class Node:
    """A composed YAML node.

    ``kind`` is ``"mapping"`` (``value``: dict key -> (key node, value
    node)), ``"sequence"`` (list of nodes), ``"scalar"`` (the resolved
    str, int, float, bool or None, and its ``text`` as written) or
    ``"invalid"`` (refused for its YAML, its problem already reported: a
    forbidden tag, an alias, a tag its text does not fit).
    ``line``/``column`` are 1-based; ``end`` is ``(line, column)`` just past
    the node (set when its last event is read).
    """

    __slots__ = ("kind", "value", "text", "line", "column", "end")

    def __init__(self, kind, value, mark, text=None, end=None):
        self.kind = kind
        self.value = value
        self.text = text
        self.line = mark.line + 1
        self.column = mark.column + 1
        self.end = None if end is None else (end.line + 1, end.column + 1)


CORE = "tag:yaml.org,2002:"

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
PLAIN_WORDS = {
    "": None, "~": None, "null": None, "Null": None, "NULL": None,
    "true": True, "True": True, "TRUE": True,
    "false": False, "False": False, "FALSE": False,
}  # fmt: skip
_NUMBER_START = frozenset("+-.0123456789")


def resolve_plain(text):
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
    return PLAIN_WORDS.get(text, text)


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
    CORE + "str": (str,),
    CORE + "int": (int,),
    CORE + "float": (int, float),
    CORE + "bool": (bool,),
    CORE + "null": (type(None),),
}
_COLLECTION_TAGS = {"mapping": CORE + "map", "sequence": CORE + "seq"}


def _short_tag(tag):
    return "!!" + tag[len(CORE) :] if tag.startswith(CORE) else tag


def _scalar(event, stack, problems):
    """The node of a scalar event, its value resolved from text and tag
    (an ``"invalid"`` node, its problem added, for a tag it does not fit)."""
    tag = event.tag
    text = event.value
    if tag is None:
        value = resolve_plain(text) if event.implicit[0] else text
    elif tag == "!":  # the non-specific tag: a string
        value = text
    elif tag in _SCALAR_TAGS:
        value = text if tag == CORE + "str" else resolve_plain(text)
        if type(value) not in _SCALAR_TAGS[tag]:
            kind = "not-a-number" if tag in (CORE + "int", CORE + "float") else "bad-scalar"
            problems.add(
                Reject(
                    kind, _here(stack), f"{text!r} is not a valid {_short_tag(tag)}", **located_mark(event.start_mark)
                )
            )
            return Node("invalid", None, event.start_mark, text, event.end_mark)
    else:
        problems.add(_forbidden_tag(tag, event, _here(stack)))
        return Node("invalid", None, event.start_mark, text, event.end_mark)
    return Node("scalar", value, event.start_mark, text, event.end_mark)


def _forbidden_tag(tag, event, path):
    return Reject(
        "forbidden-tag",
        path,
        f"tag {_short_tag(tag)} is not allowed (only the core tags !!str, !!int, !!float, !!bool, !!null, !!seq, !!map)",
        **located_mark(event.start_mark),
    )


def _stack_path(stack):
    """Field path of the node that comes next in the innermost open collection."""
    path = ""
    for node, key, _ in stack:
        if node.kind == "sequence":
            path += f"[{len(node.value)}]"
        elif key is not None:
            path = join(path, key.value)
    return path


def _here(stack):
    """Path of the next node for a message: the stack path, or "top level"."""
    return _stack_path(stack) or "top level"


_STARTS = {yaml.MappingStartEvent: "mapping", yaml.SequenceStartEvent: "sequence"}
_ENDS = (yaml.MappingEndEvent, yaml.SequenceEndEvent)


def compose(get_event, problems, *, value=False):
    """Node tree of one document, read (``get_event()``) up to and including its end event.

    Each problem found goes to ``problems`` and composing goes on, so that
    one pass finds them all: a node with a problem of its own (a forbidden
    tag, an alias, a tagged scalar its tag does not fit) becomes an
    ``"invalid"`` node, which the checks pass over in silence, and the value
    of a key that is not a string, or is repeated, is skipped.  Raises
    ``StreamStop`` for nesting beyond ``MAX_DEPTH``.

    With ``value``, composes just the value of a top-level key instead (its
    depth counted from the document's mapping), up to its last event.
    """
    stack = []  # open collections, innermost last: [node, key awaiting its value, tag allowed]
    root = None
    depth = 1 if value else 0
    skip = None  # while a value is skipped: its collections still open
    while True:
        event = get_event()
        kind = type(event)
        if kind is yaml.DocumentEndEvent:
            return root
        if kind in _STARTS:
            depth += 1
            if depth > MAX_DEPTH:
                raise StreamStop(
                    "too-deep",
                    _stack_path(stack),
                    f"nested deeper than {MAX_DEPTH} levels",
                    **located_mark(event.start_mark),
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
            stack.append([Node(collection, {} if collection == "mapping" else [], event.start_mark), None, allowed])
            continue
        if kind in _ENDS:
            node, _, allowed = stack.pop()
            node.end = (event.end_mark.line + 1, event.end_mark.column + 1)
            if not allowed:
                node.kind = "invalid"  # its content was composed for the problems in it
        elif kind is yaml.ScalarEvent:
            node = _scalar(event, stack, problems)
        elif kind is yaml.AliasEvent:
            problems.add(
                Reject(
                    "alias",
                    _here(stack),
                    f"aliases (*{event.anchor}) are not allowed; write the value out",
                    **located_mark(event.start_mark),
                )
            )
            node = Node("invalid", None, event.start_mark, end=event.end_mark)
        else:  # no other event can occur inside a document
            raise AssertionError(f"unexpected YAML event {event}")
        if not stack:
            if value:
                return node
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
        problems.add(Reject("invalid-key", _here(stack), f"keys must be strings, got {describe(key)}", **located(key)))
        return False
    if key.value in mapping.value:
        first = mapping.value[key.value][0]
        problems.add(
            Reject(
                "duplicate-key",
                join(_stack_path(stack), key.value),
                f"duplicate key (first given at line {first.line})",
                **located(key),
            )
        )
        return False
    return True


def syntax_error(exc, text, document_line=0):
    """A ``StreamStop`` for a PyYAML or libyaml syntax error raised while
    reading the document that starts at ``document_line`` (0-based) of ``text``:
    ``too-deep`` where the document crosses ``MAX_DEPTH`` before that error."""
    mark = getattr(exc, "problem_mark", None)
    deep = too_deep(text, document_line, mark)
    if deep is not None:
        return deep
    if mark is None:
        return StreamStop("yaml-syntax", "", f"invalid YAML: {exc}")
    problem = exc.problem or "syntax error"
    lines = text.split("\n")
    if mark.line < len(lines) and lines[mark.line][mark.column : mark.column + 1] == "\t":
        # The two parsers word this differently; it is common enough to fix.
        problem = "tab character; YAML indentation must use spaces"
    return StreamStop("yaml-syntax", "", f"invalid YAML: {problem}", line=mark.line + 1, column=mark.column + 1)


def too_deep(text, document_line, mark):
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
            compose(parser.get_event, Problems(0))
    except StreamStop as stop:
        line, column = stop.line - 1 + document_line, stop.column - 1
        if mark is None or (line, column) <= (mark.line, mark.column):
            stop.line = line + 1
            return stop
    except yaml.YAMLError:
        pass
    finally:
        parser.dispose()
    return None
