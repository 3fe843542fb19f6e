"""The ``twists`` section: the object's desired twists, as ``(omega; v)`` at the origin."""

from __future__ import annotations

import numpy as np

from ...engine import screws
from ...model import Twist
from .problems import Reject, located
from .values import Section, read_entry_name, read_mapping, read_screw_parts, read_sequence, readonly

__all__ = ["TWIST_KEYS", "SECTION", "read_twists", "twist_parts"]

TWIST_KEYS = ("name", "screw", "angular", "linear", "at")


def read_twists(node, problems):
    """The desired twists, converted to ``(omega; v)`` at the origin (None after a problem)."""
    items = read_sequence(node, "twists", problems)
    if items is None:
        return None
    names, parts = {}, []
    for i, item in enumerate(items):
        path = f"twists[{i}]"
        fields = read_mapping(item, path, TWIST_KEYS, (), problems)
        if fields is None:
            continue
        read_entry_name(fields, item, "twists", i, names, problems)
        parts.append(twist_parts(fields, item, path, problems))
    if problems.count or not items:
        return None if problems.count else ()
    omega, velocity, at = np.array(parts).transpose(1, 0, 2)
    with np.errstate(over="ignore", invalid="ignore"):
        screw = screws.twist_at(omega, velocity, at)
    for i in np.flatnonzero(~np.isfinite(screw).all(axis=1)):
        problems.add(
            Reject(
                "non-finite",
                f"twists[{i}]",
                "the velocity of the origin overflows (linear + angular x (origin - at))",
                **located(items[i]),
            )
        )
    if problems.count:
        return None
    return tuple(Twist(name, readonly(s), item.line) for name, s, item in zip(names, screw, items))


def twist_parts(fields, item, path, problems):
    """``(angular, linear, at)`` of one twist entry, zeros where not given (None after a problem)."""
    return read_screw_parts(fields, item, path, problems, ("screw", "angular", "linear"))


def _read(fields, found, problems):
    twists = read_twists(fields["twists"], problems) if "twists" in fields else ()
    return None if twists is None else {"twists": twists}


SECTION = Section(("twists",), _read)
