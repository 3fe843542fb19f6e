"""The fast path: a plainly written valid document read straight from its events."""

from __future__ import annotations

import math
import re

import yaml

from ...engine import screws
from ...model import Grasp, Twist
from .compose import PLAIN_WORDS, compose, resolve_plain
from .contacts import NO_NORMAL
from .document import SECTIONS
from .problems import Problems, StreamStop
from .values import NOT_IN_A_NAME, readonly

__all__ = ["Bail", "Parts", "fast_document"]

# Nearly every document read is a valid grasp written plainly: no tags,
# numbers as plain decimal scalars.  ``fast_document`` reads such a document's
# name, units, wrist, contacts and twists straight from its events into
# strings and floats, without a node tree or the general checks, two to three
# times quicker (bench/loader.py).  The other sections (paths, a hand: a few
# per file) are composed and read by their section modules, as on the general
# path.  At the first thing it
# does not take for certain (a tag, an alias, a non-decimal or non-finite
# number, a null, an unknown, repeated or missing key, a wrong count, a
# repeated or invalid name, deeper nesting than a grasp has, an overflow...)
# it raises ``Bail``; ``read_text`` then composes the document again from
# its recorded events with ``compose`` and checks it with ``read_document``, which
# give every error and its position.  So the fast path returns a grasp only
# where the general one returns the same grasp, bit for bit
# (tests/io/test_grasp_file_speed_paths.py compares the two).


class Bail(Exception):
    """Internal: the fast path leaves this document to the general one."""


_ScalarEvent = yaml.ScalarEvent
_SequenceStart = yaml.SequenceStartEvent
_SequenceEnd = yaml.SequenceEndEvent
_MappingStart = yaml.MappingStartEvent
_MappingEnd = yaml.MappingEndEvent

# The plain scalars resolve_plain reads as a decimal int or float.  For
# them float(text) is the value read_number gives (both round correctly), except
# that an integer "-0" is int 0, so 0.0 rather than -0.0.
_DECIMAL = re.compile(r"[-+]?(?:\.[0-9]+|[0-9]+(?:\.[0-9]*)?)(?:[eE][-+]?[0-9]+)?")
_NULLS = frozenset(word for word, value in PLAIN_WORDS.items() if value is None)
_INF = math.inf
_ZERO = (0.0, 0.0, 0.0)


def fast_document(get, keep, file, reading):
    """A plain valid document's ``Parts``, from the events after its start.

    ``get()`` gives the next event; each one read is passed to ``keep``.
    ``file`` is the grasp file's name (a URDF hand or a mesh is found from its
    folder, read as ``reading`` says).
    """
    if reading.table is not None or reading.clearance is not None:
        raise Bail  # the environment's section reads every document then, with or without its key
    event = get()
    keep(event)
    if type(event) is not _MappingStart or event.tag is not None:
        raise Bail
    name = units = wrist = contacts = None
    twists = ()
    composed = {}  # key -> node of the sections composed here
    seen = []
    for key in _fast_keys(get, keep):
        if key in seen:
            raise Bail
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
        elif key in _COMPOSED:
            composed[key] = _value(get, keep)
        else:
            raise Bail
    if contacts is None or ("object" not in composed and any(n is NO_NORMAL for n in contacts[2])):
        raise Bail  # a contact without its normal needs an object
    event = get()
    keep(event)
    if type(event) is not yaml.DocumentEndEvent:
        raise Bail
    parts = Parts(name, units, wrist, contacts, twists)
    if composed:
        parts.sections = _sections(composed, parts, {"file": file, "reading": reading, "units": units})
    return parts


# The sections read by their own modules: all but the contacts and twists read here.
_COMPOSED_SECTIONS = tuple(section for section in SECTIONS if not {"contacts", "twists"} & set(section.keys))
_COMPOSED = frozenset(key for section in _COMPOSED_SECTIONS for key in section.keys)


def _value(get, keep):
    """The node of the value that comes next, composed as the general path does."""

    def get_kept():
        event = get()
        keep(event)
        return event

    problems = Problems(0)
    try:
        node = compose(get_kept, problems, value=True)
    except StreamStop:  # too deep: the general path stops at the same event, with the place
        raise Bail from None
    if problems.count:
        raise Bail
    return node


def _sections(composed, parts, found):
    """The Grasp fields of the composed sections, read by their modules (after the contacts);
    ``found`` holds the file's name and how the files it names are read."""
    contact_names, points, normals = parts.contacts
    found.update(contact_names=contact_names, points=readonly(points), normals=readonly(normals))
    fields = {}
    problems = Problems(0)
    for section in _COMPOSED_SECTIONS:
        if not composed.keys().isdisjoint((*section.keys, *section.reads_also)):
            read = section.read(composed, found, problems) or {}
            found.update(read)
            fields.update(read)
    if problems.count or fields.get("warnings"):  # a warning names a contact's place: the general path has it
        raise Bail
    return fields


def _fast_keys(get, keep):
    """Each key of the mapping whose start was just read (untagged plain keys only)."""
    while True:
        event = get()
        keep(event)
        if type(event) is not _ScalarEvent:
            if type(event) is _MappingEnd:
                return
            raise Bail
        if event.tag is not None:
            raise Bail
        yield event.value


def _fast_entries(get, keep):
    """The start event of each mapping in the sequence that comes next (untagged only)."""
    event = get()
    keep(event)
    if type(event) is not _SequenceStart or event.tag is not None:
        raise Bail
    while True:
        event = get()
        keep(event)
        if type(event) is not _MappingStart:
            if type(event) is _SequenceEnd:
                return
            raise Bail
        if event.tag is not None:
            raise Bail
        yield event


def _fast_name(get, keep):
    """What ``read_name`` returns for the next node, if it accepts it."""
    event = get()
    keep(event)
    if type(event) is not _ScalarEvent or event.tag is not None:
        raise Bail
    text = event.value
    if (event.implicit[0] and text in _NULLS) or not text.strip() or NOT_IN_A_NAME.search(text):
        raise Bail
    return text


def _fast_vector(get, keep, length):
    """What ``read_vector`` returns for the next node, if it is a flat list of
    ``length`` plain decimal finite numbers."""
    event = get()
    keep(event)
    if type(event) is not _SequenceStart or event.tag is not None:
        raise Bail
    values = []
    for _ in range(length):
        event = get()
        keep(event)
        if type(event) is not _ScalarEvent or event.tag is not None or not event.implicit[0]:
            raise Bail
        text = event.value
        if _DECIMAL.fullmatch(text) is None:
            raise Bail
        value = float(text)
        if not -_INF < value < _INF:
            raise Bail
        if not value and text[0] == "-":
            value = float(resolve_plain(text))  # -0 is the int 0
        values.append(value)
    event = get()
    keep(event)
    if type(event) is not _SequenceEnd:
        raise Bail
    return values


def _fast_contacts(get, keep):
    """``read_contacts`` for the next node, with the normals made unit."""
    names, points, normals = [], [], []
    for _ in _fast_entries(get, keep):
        if len(names) == 3:
            raise Bail
        name = point = normal = None
        for key in _fast_keys(get, keep):
            if key == "point" and point is None:
                point = _fast_vector(get, keep, 3)
            elif key == "normal" and normal is None:
                normal = _fast_vector(get, keep, 3)
            elif key == "name" and name is None:
                name = _fast_name(get, keep)
            else:
                raise Bail
        if point is None or (normal is not None and not any(normal)):
            raise Bail
        if name is None:
            name = str(len(names) + 1)
        if name in names:
            raise Bail
        names.append(name)
        points.append(point)
        normals.append(NO_NORMAL if normal is None else screws.direction3(*normal))
    if len(names) != 3:
        raise Bail
    return tuple(names), points, normals


def _fast_twists(get, keep):
    """``read_twists`` for the next node, as ``(name, screw list, line)`` tuples."""
    names, twists = [], []
    for start in _fast_entries(get, keep):
        line = start.start_mark.line + 1
        fields = {}
        for key in _fast_keys(get, keep):
            if key in fields:
                raise Bail
            if key == "angular" or key == "linear" or key == "at":
                fields[key] = _fast_vector(get, keep, 3)
            elif key == "name":
                fields[key] = _fast_name(get, keep)
            elif key == "screw":
                fields[key] = _fast_vector(get, keep, 6)
            else:
                raise Bail
        name = fields.pop("name", None)
        if name is None:
            name = str(len(names) + 1)
        if name in names:
            raise Bail
        screw = fields.get("screw")
        if screw is not None:
            if len(fields) != 1:
                raise Bail
            w0, w1, w2, u0, u1, u2 = screw
            p0, p1, p2 = _ZERO
        elif "angular" in fields or "linear" in fields:
            w0, w1, w2 = fields.get("angular", _ZERO)
            u0, u1, u2 = fields.get("linear", _ZERO)
            p0, p1, p2 = fields.get("at", _ZERO)
        else:
            raise Bail
        # the same operations as read_twists's screws.twist_at, so the same bits
        v0, v1, v2 = screws.twist_at3((w0, w1, w2), (u0, u1, u2), (p0, p1, p2))
        if not (-_INF < v0 < _INF and -_INF < v1 < _INF and -_INF < v2 < _INF):
            raise Bail
        names.append(name)
        twists.append((name, [w0, w1, w2, v0, v1, v2], line))
    return twists


class Parts:
    """What ``fast_document`` read; ``grasp`` makes it a Grasp."""

    __slots__ = ("name", "units", "wrist", "contacts", "twists", "sections")

    def __init__(self, name, units, wrist, contacts, twists):
        self.name = name
        self.units = units
        self.wrist = wrist
        self.contacts = contacts
        self.twists = twists
        self.sections = {}  # Grasp fields of the composed sections

    def grasp(self, *, file, document, name, line):
        contact_names, points, normals = self.contacts
        contacts = {"points": readonly(points), "normals": readonly(normals)}
        return Grasp(
            name=name,
            units=self.units,
            file=file,
            document=document,
            contact_names=contact_names,
            wrist=None if self.wrist is None else readonly(self.wrist),
            twists=tuple(Twist(twist, readonly(screw), twist_line) for twist, screw, twist_line in self.twists),
            line=line,
            **(contacts | self.sections),  # an object puts the points on its surface
        )
