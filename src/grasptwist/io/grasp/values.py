"""Typed values of a grasp document's nodes, shared by every section.

Each ``read_*`` adds its problems to ``problems`` and returns None after one;
an ``"invalid"`` node (its problem already added while composing) is passed
over in silence.  :class:`Section` is how a section module plugs into the
document (see :mod:`.document`).
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable
from typing import NamedTuple

import numpy as np

from .problems import Reject, join, located

__all__ = [
    "Section",
    "describe",
    "shorten",
    "misspelt",
    "read_mapping",
    "read_sequence",
    "read_name",
    "read_entry_name",
    "read_vector",
    "read_number",
    "read_screw_parts",
    "readonly",
    "NOT_IN_A_NAME",
]


class Section(NamedTuple):
    """One section of a grasp document: its top-level keys and how they are read.

    Attributes
    ----------
    keys : tuple of str
        The top-level keys it reads, in the order they are checked.
    read : callable
        ``read(fields, found, problems)``: ``fields`` maps each known key of
        the document to its node, ``found`` holds the Grasp fields read by
        the sections before (and ``"file"``, the grasp file's name).
        Returns a dict of :class:`~grasptwist.model.Grasp` fields (empty
        when its keys are absent and have no default), or None after a
        problem.
    required : tuple of str
        Those of ``keys`` every document must have.
    reads_also : tuple of str
        Other sections' keys that give it something to read when none of its
        own is there (the forces: an object's weight).
    """

    keys: tuple
    read: Callable
    required: tuple = ()
    reads_also: tuple = ()


def read_entry_name(fields, item, collection, index, taken, problems):
    """Name entry ``index`` of a list of contacts or twists (default: its
    1-based position) in ``taken`` (name -> index), unless it is invalid or
    already taken."""
    path = f"{collection}[{index}]"
    node = fields.get("name")
    name = read_name(node, path + ".name", problems) if node is not None else str(index + 1)
    if name is None:
        return
    if name in taken:
        problems.add(
            Reject(
                "duplicate-name",
                path + ".name" if node is not None else path,
                f"duplicate name {name!r} (also {collection}[{taken[name]}])",
                **located(node if node is not None else item),
            )
        )
        return
    taken[name] = index


# --------------------------------------------------------------------------
# Typed values.  Each adds its problems and returns None after one; an
# "invalid" node (its problem already added) is passed over in silence.


def describe(node):
    """How a node reads in a message: 'a list', 'the string "x"', ..."""
    if node.kind != "scalar":
        return "a list" if node.kind == "sequence" else "a mapping"
    value = node.value
    if value is None:
        return "null"
    if isinstance(value, bool):
        return f"a boolean ({str(value).lower()})"
    if isinstance(value, (int, float)):
        return f"the number {shorten(node.text)}"
    return f"the string {shorten(value)!r}"


def misspelt(node, keys):
    """Whether a key of mapping ``node`` is a misspelling of one of ``keys``: its "did you mean"
    line then stands in for the missing key's (as :func:`read_mapping` does for required keys)."""
    from difflib import get_close_matches

    return any(key not in keys and get_close_matches(key, keys, n=1) for key in node.value)


def shorten(text):
    """``text`` cut to 30 characters for a message (a long number or string stays one short line)."""
    return text if len(text) <= 30 else text[:27] + "..."


def read_mapping(node, path, keys, required, problems):
    """The ``{key: value node}`` of the known keys of a mapping node."""
    if node.kind == "invalid":
        return None
    if node.kind != "mapping":
        problems.add(
            Reject("not-a-mapping", path or "top level", f"expected a mapping, got {describe(node)}", **located(node))
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
        problems.drop_within(value)  # the key is wrong: what is inside its value is no news
        if unknown > problems.keep:
            # Only so many are reported (the first, in the file): spare the rest the suggestion.
            problems.add(Reject("unknown-key", join(path, key), "unknown key", **located(key_node)))
            continue
        # difflib is only needed on this error path.
        from difflib import get_close_matches

        close = get_close_matches(key, keys, n=1)
        meant.update(close)
        hint = f"did you mean {close[0]!r}?" if close else f"expected one of: {', '.join(keys)}"
        problems.add(Reject("unknown-key", join(path, key), f"unknown key ({hint})", **located(key_node)))
    for key in required:
        if key not in fields and key not in meant:  # a misspelling already says it
            problems.add(Reject("missing-key", join(path, key), "required key is missing", **located(node)))
    return fields


def read_sequence(node, path, problems, expected="a list", hint=None):
    """The items of a sequence node."""
    if node.kind == "sequence":
        return node.value
    if node.kind != "invalid":
        more = hint(node) if hint else ""
        problems.add(Reject("not-a-list", path, f"expected {expected}, got {describe(node)}{more}", **located(node)))
    return None


def read_name(node, path, problems):
    """A label: a non-empty single line, taken as written.

    A plain ``1``, ``1e3`` or ``true`` is the label "1", "1e3", "true":
    PyYAML's dumper leaves strings like "1e3" unquoted (YAML 1.1 reads
    them as strings), and a label has no use for the number.
    """
    if node.kind == "invalid":
        return None
    if node.kind != "scalar" or node.value is None:
        problems.add(Reject("not-a-string", path, f"expected a name, got {describe(node)}", **located(node)))
        return None
    if not node.text.strip():
        problems.add(Reject("invalid-name", path, "must be a non-empty single line", **located(node)))
        return None
    bad = NOT_IN_A_NAME.search(node.text)
    if bad:
        problems.add(
            Reject(
                "invalid-name",
                path,
                f"must be a non-empty single line without control characters (found U+{ord(bad.group()):04X})",
                **located(node),
            )
        )
        return None
    return node.text


# Names are echoed into one-line diagnostics and terminal tables, so none of
# the characters that break a line or drive a terminal: C0 and C1 controls
# (newline, ESC, NUL, NEL ...), which double-quoted escapes such as "\e[2J"
# or "\0" can produce although the file itself holds none, and the Unicode
# line and paragraph separators.
NOT_IN_A_NAME = re.compile("[\x00-\x1f\x7f-\x9f\u2028\u2029]")


def read_vector(node, length, path, problems):
    """A list of ``length`` finite numbers, as floats."""
    if node.kind == "invalid":
        return None
    if node.kind != "sequence":
        problems.add(Reject("not-a-list", path, f"expected {length} numbers, got {describe(node)}", **located(node)))
        return None
    values = [read_number(item, f"{path}[{i}]", problems) for i, item in enumerate(node.value)]
    if len(values) != length:
        hint = ""
        wrench = path.startswith("wrenches")
        if length == 3 and len(values) == 6:
            hint = (
                "; a 6-vector (force; moment) goes under `wrench:`"
                if wrench
                else "; a 6-vector (omega; v) goes under `screw:`"
            )
        elif length == 6 and len(values) == 3:
            hint = (
                "; a 3-vector goes under `force:` or `moment:`"
                if wrench
                else "; a 3-vector goes under `angular:` or `linear:`"
            )
        problems.add(
            Reject("vector-length", path, f"expected {length} numbers, got {len(values)}{hint}", **located(node))
        )
        return None
    return None if None in values else values


def read_number(node, path, problems):
    """A finite number (int or float; booleans and strings are not numbers)."""
    value = node.value
    if node.kind == "invalid":
        return None
    if node.kind != "scalar" or type(value) not in (int, float):
        problems.add(Reject("not-a-number", path, f"expected a number, got {describe(node)}", **located(node)))
        return None
    try:
        value = float(value)
    except OverflowError:  # an integer beyond the float range
        value = math.inf
    if not math.isfinite(value):
        problems.add(Reject("non-finite", path, f"expected a finite number, got {shorten(node.text)}", **located(node)))
        return None
    return value


def readonly(values):
    array = np.array(values, dtype=float)
    array.setflags(write=False)
    return array


def read_screw_parts(fields, item, path, problems, keys):
    """``(first, second, at)`` halves of a screw entry given either whole or by its parts, zeros
    where not given (None after a problem): ``keys`` names the whole and its two halves, e.g.
    ``("screw", "angular", "linear")`` for a twist or ``("wrench", "force", "moment")`` for a
    wrench; ``at`` is the point the second half is given about (the origin when absent)."""
    whole, first, second = keys
    zero = [0.0, 0.0, 0.0]
    if whole in fields:
        for other in (first, second, "at"):
            if other in fields:
                problems.add(
                    Reject(
                        "conflicting-keys",
                        join(path, other),
                        f"cannot be combined with '{whole}' (give {whole}, or {first}/{second}/at)",
                        **located(fields[other]),
                    )
                )
        vector = read_vector(fields[whole], 6, join(path, whole), problems)
        return None if vector is None else (vector[:3], vector[3:], zero)
    if first not in fields and second not in fields and not misspelt(item, keys):
        problems.add(Reject("missing-key", path, f"needs '{whole}', or '{first}' and/or '{second}'", **located(item)))
    parts = [
        read_vector(fields[key], 3, join(path, key), problems) if key in fields else zero
        for key in (first, second, "at")
    ]
    return None if None in parts else parts
