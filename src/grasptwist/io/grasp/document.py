"""A grasp document as a whole: its own keys, and the sections that read the rest.

Each top-level key beyond ``name``, ``units`` and ``wrist`` belongs to a
*section* (:class:`~.values.Section`): a module of this package that reads
its keys into fields of the :class:`~grasptwist.model.Grasp`.  A new part
of the format is a new module with a ``SECTION`` (as ``forces.py`` did, issue
19), imported and added to :data:`SECTIONS` below; its keys then join
:data:`GRASP_KEYS`, the fast path hands them to it, and the JSON Schema must
list them (tests/io/test_grasp_schema.py checks both agree).
"""

from __future__ import annotations

import numpy as np

from ...model import CONTACT_NAMES, Grasp
from .contacts import SECTION as CONTACTS
from .environment import SECTION as ENVIRONMENT
from .forces import SECTION as FORCES
from .hand import SECTION as HAND
from .objects import SECTION as OBJECT
from .paths import SECTION as PATHS
from .problems import Reject, located
from .twists import SECTION as TWISTS
from .values import read_mapping, read_name, read_vector, readonly

__all__ = ["SECTIONS", "GRASP_KEYS", "read_document", "grasp_schema"]

#: The sections of a grasp document, in the order they are read (a later one
#: sees the fields of the earlier ones: the object puts the contacts on its
#: surface, the hand needs the contacts there, the forces the contacts' own
#: frictions and the object's weight).
SECTIONS = (CONTACTS, OBJECT, TWISTS, PATHS, HAND, FORCES, ENVIRONMENT)

#: The top-level keys, in the order the values are checked.
GRASP_KEYS = ("name", "units", "wrist", *(key for section in SECTIONS for key in section.keys))

_REQUIRED = tuple(key for section in SECTIONS for key in section.required)

#: The points and normals of a document read without contacts (``Reading(contacts=False)``).
_NO_CONTACTS = readonly(np.full((3, 3), np.nan))


def read_document(root, problems, *, file, document, name, line, reading):
    """Check one document's node tree: its Grasp, or None when ``problems`` has any
    (``reading``: how the files it names are read)."""
    if root.kind == "scalar" and root.value is None:
        problems.add(Reject("empty-document", "", "empty document", **located(root)))
        return None
    required = _REQUIRED if reading.contacts else tuple(k for k in _REQUIRED if k != "contacts")
    fields = read_mapping(root, "", GRASP_KEYS, required, problems)
    if fields is None:
        return None
    if "name" in fields:
        name = read_name(fields["name"], "name", problems)
    units = read_name(fields["units"], "units", problems) if "units" in fields else None
    wrist = read_vector(fields["wrist"], 3, "wrist", problems) if "wrist" in fields else None
    found = {"file": file, "reading": reading, "units": units}
    for section in SECTIONS:
        found.update(section.read(fields, found, problems) or {})
    if problems.count:
        return None
    for key in ("file", "reading", "units"):
        del found[key]
    if "points" not in found:  # contacts not required of this reading: to be found (NaN)
        found.update(contact_names=CONTACT_NAMES, points=_NO_CONTACTS, normals=_NO_CONTACTS)
    return Grasp(
        name=name,
        units=units,
        file=file,
        document=document,
        wrist=None if wrist is None else readonly(wrist),
        line=line,
        **found,
    )


def grasp_schema():
    """The JSON Schema of a grasp document (a fresh dict on each call)."""
    # Imported here: only the ``schema`` command and tests need them.
    import json
    from importlib.resources import files

    return json.loads(files(__package__).joinpath("grasp_schema.json").read_text("utf-8"))
