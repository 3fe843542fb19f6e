"""The ``contacts`` section: the three contact points and their normals."""

from __future__ import annotations

import math

import numpy as np

from ...engine import screws
from .forces import read_friction, read_torsion
from .problems import Reject, located
from .values import Section, read_entry_name, read_mapping, read_name, read_sequence, read_vector, readonly, shorten

__all__ = ["CONTACT_KEYS", "NO_NORMAL", "SECTION", "read_contacts"]

CONTACT_KEYS = ("name", "point", "normal", "friction", "model", "torsion")

#: A contact's ``model``: a point contact with friction, or a soft finger (``torsion``: its torsional radius).
CONTACT_MODELS = ("point", "soft")

#: The normal of a contact on an object that gives none, until the surface's is taken.
NO_NORMAL = (math.nan, math.nan, math.nan)

# What contacts look like, for the message when they are not a list.
_CONTACTS_SHAPE = "a list of 3 contacts like [{point: [x, y, z], normal: [x, y, z]}, ...]"


def read_contacts(node, problems, on_object=False):
    """Names, points, unit normals and own frictions (None, or NaN where a
    contact gives none) of the three contacts (None after a problem).

    ``on_object``: the grasp gives an object, so a contact may leave out its
    normal (a row of NaN here; :mod:`.objects` takes the surface's)."""
    items = read_sequence(node, "contacts", problems, _CONTACTS_SHAPE, _contacts_hint)
    if items is None:
        return None
    if len(items) != 3:
        problems.add(
            Reject("contact-count", "contacts", f"expected exactly 3 contacts, got {len(items)}", **located(node))
        )
    names, points, normals, friction, torsion = {}, [], [], [], []
    for i, item in enumerate(items):
        path = f"contacts[{i}]"
        fields = read_mapping(item, path, CONTACT_KEYS, ("point",) if on_object else ("point", "normal"), problems)
        if fields is None:
            continue
        read_entry_name(fields, item, "contacts", i, names, problems)
        points.append(read_vector(fields["point"], 3, path + ".point", problems) if "point" in fields else None)
        normal = read_vector(fields["normal"], 3, path + ".normal", problems) if "normal" in fields else None
        if normal is not None and not any(normal):
            problems.add(
                Reject("zero-normal", path + ".normal", "a zero vector has no direction", **located(fields["normal"]))
            )
        normals.append(normal)
        node = fields.get("friction")
        friction.append(math.nan if node is None else read_friction(node, path + ".friction", problems))
        torsion.append(_read_model(fields, item, path, problems))
    if problems.count:
        return None
    # of any finite size: no over- or underflow
    normals = [NO_NORMAL if n is None else screws.direction3(*n) for n in normals]
    # The grasp's own ``friction`` fills the NaNs (forces.py).
    own = None if all(math.isnan(mu) for mu in friction) else readonly(friction)
    soft = None if not any(torsion) else readonly(torsion)
    return tuple(names), readonly(np.array(points)), readonly(normals), own, soft


def _read_model(fields, item, path, problems):
    """A contact's torsional radius: ``model: soft`` with ``torsion: e``, else 0 (a point contact)."""
    model = read_name(fields["model"], path + ".model", problems) if "model" in fields else "point"
    if model is not None and model not in CONTACT_MODELS:
        problems.add(
            Reject(
                "invalid-contact-model",
                path + ".model",
                f"must be point or soft, got {shorten(model)!r}",
                **located(fields["model"]),
            )
        )
        return 0.0
    if model == "soft" and "torsion" not in fields:
        problems.add(
            Reject(
                "missing-key",
                path + ".torsion",
                "a soft contact needs its torsional radius (torsion: E)",
                **located(item),
            )
        )
    elif model != "soft" and "torsion" in fields:
        # model: point beside a torsion: the two exclude each other; no model: the soft one missing
        problems.add(
            Reject(
                "conflicting-keys" if "model" in fields else "missing-key",
                path + ".model",
                "a torsion is a soft contact's (give model: soft beside it)",
                **located(item),
            )
        )
    e = read_torsion(fields["torsion"], path + ".torsion", problems) if "torsion" in fields else None
    return 0.0 if e is None else e


def _contacts_hint(node):
    """What to change when ``contacts`` is a mapping."""
    if node.kind != "mapping" or not node.value:
        return ""
    if set(node.value) & set(CONTACT_KEYS):
        return "; start each of the three contacts with '- '"
    name = shorten(str(next(iter(node.value))))
    return f"; write each as '- name: {name}' with its point and normal under it"


def _read(fields, found, problems):
    contacts = read_contacts(fields["contacts"], problems, "object" in fields) if "contacts" in fields else None
    if contacts is None:
        return None
    names, points, normals, friction, torsion = contacts
    fields = {"contact_names": names, "points": points, "normals": normals}
    if friction is not None:
        fields["friction"] = friction
    if torsion is not None:
        fields["torsion"] = torsion
    return fields


SECTION = Section(("contacts",), _read, required=("contacts",))
