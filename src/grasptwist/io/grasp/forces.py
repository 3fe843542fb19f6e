"""The force keys: ``friction``, ``wrenches``, ``mass``, ``center_of_mass`` and ``gravity``.

A wrench is ``(force; moment about the origin)``, the resultant the fingers
must exert on the object (docs/guide/forces.md).  ``mass`` adds the wrench
named ``hold`` that balances the weight: gravity pulls with ``m g`` at the
centre of mass ``c``, so the fingers must exert ``(-m g; -c x m g)``.
An ``object`` with a ``mass`` or ``density`` gives both ``m`` and ``c`` (its
centre of mass, in the grasp's frame): the top-level ``mass`` and
``center_of_mass`` are then an error (``conflicting-keys``: one weight,
given once), ``gravity`` still applies.
A contact's own ``friction`` (read by :mod:`.contacts` with
:func:`read_friction`) overrides the grasp's.
"""

from __future__ import annotations

import numpy as np

from ...engine import screws
from ...model import Wrench
from .problems import Reject, located
from .values import (
    Section,
    read_entry_name,
    read_mapping,
    read_number,
    read_screw_parts,
    read_sequence,
    read_vector,
    readonly,
)

__all__ = ["FORCE_KEYS", "WRENCH_KEYS", "HOLD", "GRAVITY", "SECTION", "read_friction", "read_wrenches"]

FORCE_KEYS = ("friction", "wrenches", "mass", "center_of_mass", "gravity")
WRENCH_KEYS = ("name", "wrench", "force", "moment", "at")

#: The name of the wrench that ``mass`` adds.
HOLD = "hold"

#: Gravity when a grasp with a ``mass`` does not give it: 9.81 down the z axis.
GRAVITY = (0.0, 0.0, -9.81)


def read_friction(node, path, problems):
    """A Coulomb friction coefficient: a finite number ``>= 0`` (0: frictionless)."""
    mu = read_number(node, path, problems)
    if mu is not None and mu < 0:
        problems.add(Reject("invalid-friction", path, f"must be >= 0, got {mu!r}", **located(node)))
        return None
    return mu


def read_torsion(node, path, problems):
    """A soft contact's torsional radius: a finite length ``> 0``."""
    e = read_number(node, path, problems)
    if e is not None and not e > 0:
        problems.add(
            Reject(
                "invalid-torsion",
                path,
                f"must be a length > 0 (a soft finger's torsional radius), got {e!r}",
                **located(node),
            )
        )
        return None
    return e


def read_wrenches(node, problems):
    """The ``wrenches`` entries as ``(name, wrench (6,), line)`` (None after a problem)."""
    items = read_sequence(node, "wrenches", problems)
    if items is None:
        return None
    names, parts = {}, []
    for i, item in enumerate(items):
        path = f"wrenches[{i}]"
        fields = read_mapping(item, path, WRENCH_KEYS, (), problems)
        if fields is None:
            continue
        read_entry_name(fields, item, "wrenches", i, names, problems)
        parts.append(read_screw_parts(fields, item, path, problems, ("wrench", "force", "moment")))
    if problems.count or not items:
        return None if problems.count else ()
    force, moment, at = np.array(parts).transpose(1, 0, 2)
    # Carried from the point ``at`` to the origin: M_o = M_at + at x F.
    with np.errstate(over="ignore", invalid="ignore"):
        wrench = np.concatenate([force, moment + screws.cross(at, force)], axis=-1)
    for i in np.flatnonzero(~np.isfinite(wrench).all(axis=1)):
        problems.add(
            Reject(
                "non-finite",
                f"wrenches[{i}]",
                "the moment about the origin overflows (moment + at x force)",
                **located(items[i]),
            )
        )
    if problems.count:
        return None
    return [(name, w, item.line) for name, w, item in zip(names, wrench, items)]


def _read_hold(fields, obj, problems):
    """``(mass, center_of_mass, gravity, hold wrench)`` from the weight's keys or the object
    ``obj`` (None, or a :class:`~grasptwist.model.GraspObject` whose ``mass`` may be None), or None."""
    if obj is not None and obj.mass is not None:
        return _object_hold(fields, obj, problems)
    if obj is None and "object" in fields:  # not read (its error is said): its mass may be the one asked for
        return None
    given = [key for key in ("mass", "center_of_mass", "gravity") if key in fields]
    if not given:
        return None
    for needed in ("mass", "center_of_mass"):
        if needed not in fields:
            problems.add(
                Reject(
                    "missing-key",
                    needed,
                    f"required with {' and '.join(repr(k) for k in given)} (the weight to hold)",
                    **located(fields[given[0]]),
                )
            )
    mass = read_number(fields["mass"], "mass", problems) if "mass" in fields else None
    if mass is not None and not mass > 0:
        problems.add(Reject("invalid-mass", "mass", f"must be > 0, got {mass!r}", **located(fields["mass"])))
        mass = None
    center = (
        read_vector(fields["center_of_mass"], 3, "center_of_mass", problems) if "center_of_mass" in fields else None
    )
    gravity = read_vector(fields["gravity"], 3, "gravity", problems) if "gravity" in fields else list(GRAVITY)
    if mass is None or center is None or gravity is None:
        return None
    return _hold(mass, center, gravity, fields["mass"], "mass", problems)


def _object_hold(fields, obj, problems):
    """The weight of an object that gives its mass: the top-level ``mass`` and ``center_of_mass``
    would be a second one."""
    for key in ("mass", "center_of_mass"):
        if key in fields:
            problems.add(
                Reject(
                    "conflicting-keys",
                    key,
                    "the object's mass (or density) already gives the weight and its centre (give it once)",
                    **located(fields[key]),
                )
            )
    gravity = read_vector(fields["gravity"], 3, "gravity", problems) if "gravity" in fields else list(GRAVITY)
    if gravity is None or problems.count:
        return None
    from ...engine.objects import mass_properties

    center = mass_properties(obj).center_of_mass
    return _hold(obj.mass, list(center), gravity, fields["object"], "object", problems)


def _hold(mass, center, gravity, node, path, problems):
    """``(mass, center, gravity, hold wrench)``, or None when the wrench overflows (``path``, at ``node``)."""
    from ...engine.forces.hold import hold_wrench

    with np.errstate(over="ignore", invalid="ignore"):
        hold = hold_wrench(mass, center, gravity)
    if not np.isfinite(hold).all():
        problems.add(
            Reject(
                "non-finite",
                path,
                "the weight or its moment about the origin overflows (mass x gravity, center_of_mass x weight)",
                **located(node),
            )
        )
        return None
    return mass, center, gravity, hold


def _read(fields, found, problems):
    out = {}
    mu = read_friction(fields["friction"], "friction", problems) if "friction" in fields else None
    own = found.get("friction")  # per contact, NaN where a contact gives none
    if own is not None:
        missing = np.isnan(own)
        if mu is None and missing.any() and "friction" not in fields:
            i = int(np.flatnonzero(missing)[0])
            problems.add(
                Reject(
                    "missing-key",
                    f"contacts[{i}].friction",
                    "the other contacts give a friction and the grasp none (give one here, or 'friction' at the top)",
                    **located(fields["contacts"].value[i]),
                )
            )
        elif mu is not None:
            out["friction"] = readonly(np.where(missing, mu, own))
    elif mu is not None:
        out["friction"] = readonly([mu, mu, mu])
    # each contact's friction: the grasp's, or its own where every contact gives one (out holds it only with the grasp's)
    each = out.get("friction", own if own is not None and not np.isnan(own).any() else None)
    soft = found.get("torsion")
    frictionless = np.flatnonzero((soft > 0) & (each == 0)) if soft is not None and each is not None else ()
    for i in frictionless:  # torsional friction is friction: each such contact located
        problems.add(
            Reject(
                "invalid-torsion",
                f"contacts[{i}].torsion",
                "a soft contact needs friction > 0 (its torsion is friction), and this one's friction is 0",
                **located(fields["contacts"].value[i]),
            )
        )
    wrenches = read_wrenches(fields["wrenches"], problems) if "wrenches" in fields else []
    hold = _read_hold(fields, found.get("object"), problems)
    if wrenches is None or problems.count:
        return None
    if hold is not None:
        mass, center, gravity, w = hold
        for i, (name, _, _) in enumerate(wrenches):
            if name == HOLD:
                node = fields["wrenches"].value[i]
                name_node = node.value.get("name", (None, node))[1] if node.kind == "mapping" else node
                problems.add(
                    Reject(
                        "duplicate-name",
                        f"wrenches[{i}].name",
                        f"duplicate name {HOLD!r} (the wrench that 'mass' adds)",
                        **located(name_node),
                    )
                )
                return None
        line = (fields["mass"] if "mass" in fields else fields["object"]).line
        wrenches.append((HOLD, w, line))
        out.update(mass=mass, center_of_mass=readonly(center), gravity=readonly(gravity))
    if wrenches:
        out["wrenches"] = tuple(Wrench(name, readonly(w), line) for name, w, line in wrenches)
    return out


SECTION = Section(FORCE_KEYS, _read, reads_also=("object",))
