"""The loader's two paths give the same: the fast one (``io/grasp/fast.py``,
plain valid documents straight from the events) and the general one
(``compose`` + ``read_document``, every document, every error).

A property over generated grasp documents (:func:`documents`: every section,
flow and block style, several documents, and the mutations a fast path must
hand over at), whose hand-picked corner cases are its explicit examples: the
numbers and names at every place they stand, and documents of odd shapes
(:data:`CORNERS`); and every bundled, invalid and corpus file.  Each input
is read twice, once as the loader does it and once with the fast path
switched off, and the entries are compared field by field, arrays bit for
bit.  The YAML is parsed only once for both (and for every reading of
the same text in a test): the parser's events are recorded and replayed,
since parsing is what costs (seconds, for the pure-Python parser on
corpus/many-contacts.yaml) and both paths read the same events.  Also: the fast
path is really taken for every bundled grasp (else the loader is slow without
failing a test), and the chunked capped read.
"""

import dataclasses
import io
import sys
from dataclasses import replace

import numpy as np
import pytest
import yaml
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from grasptwist.io.grasp import READING, Grasp, InputError, Reading, read_grasps, reader, text
from loaders import CONTACTS, LOADERS
from places import TESTS

FILES = sorted(
    path
    for folder in (TESTS.parent / "grasps", TESTS / "invalid_grasps", TESTS / "corpus")
    if folder.is_dir()
    for path in folder.rglob("*.yaml")
)


def _array(a):
    return None if a is None else (a.dtype.str, a.shape, a.tobytes(), a.flags.writeable, a.flags.c_contiguous)


def _fields(value):
    """Every field of a Grasp (its twists, paths and hand too), arrays as their bytes and flags."""
    if isinstance(value, np.ndarray):
        return _array(value)
    if dataclasses.is_dataclass(value):
        return (type(value).__name__, *(_fields(getattr(value, f.name)) for f in dataclasses.fields(value)))
    if isinstance(value, (tuple, list)):
        return tuple(map(_fields, value))
    return value


def signature(entries):
    out = []
    for e in entries:
        if isinstance(e, InputError):
            out.append(("error", e.code, e.message, e.file, e.line, e.column, e.document, str(e)))
        else:
            assert type(e) is Grasp
            out.append(_fields(e))
    return out


#: (parser, text) -> (its events, the error that ends them or None); emptied after each test.
_TAPES = {}


@pytest.fixture(autouse=True)
def _fresh_tapes():
    yield
    _TAPES.clear()


def _record(parser, text):
    """Every event ``parser`` gives for ``text``, and the error it stops with (or None)."""
    live = parser(text)
    events = []
    try:
        while live.check_event():
            events.append(live.get_event())
    except yaml.YAMLError as exc:
        return events, exc
    finally:
        live.dispose()
    return events, None


def _taped(parser):
    """A stand-in for the YAML ``parser`` class that parses each text once and
    replays its events (then its error, if it stopped at one) on each reading."""

    class Taped:
        def __init__(self, text):
            if (parser, text) not in _TAPES:
                _TAPES[parser, text] = _record(parser, text)
            self.events, self.error = _TAPES[parser, text]
            events = iter(self.events)
            self.left = events.__length_hint__
            self.next = events.__next__
            self.get_event = self.next if self.error is None else self.get_or_fail

        def get_or_fail(self):
            try:
                return self.next()
            except StopIteration:
                raise self.error from None

        def peek_event(self):
            at = len(self.events) - self.left()
            if at == len(self.events):
                raise self.error or AssertionError("read past the end of the stream")
            return self.events[at]

        def check_event(self, *kinds):
            return isinstance(self.peek_event(), kinds)

        def dispose(self):
            pass

    return Taped


def both_paths(source, reading=READING, **kw):
    """The entries of ``source`` by the loader, checked equal to the general path's."""
    taped = replace(reading, parser=_taped(reading.parser))
    fast = read_grasps(source, reading=taped, **kw)
    general = read_grasps(source, reading=replace(taped, fast=False), **kw)
    assert signature(fast) == signature(general)
    return fast


BIG = 1 << 16


def _small(path):
    return path.stat().st_size < BIG


def test_files_read_the_same_both_ways():
    """Every small file, with libyaml's parser (the pure one in the long run), under its own
    name and as content under another."""
    reading = Reading(parser=LOADERS[-1])
    for path in filter(_small, FILES):
        both_paths(path, reading)
        both_paths(path.read_bytes(), reading, file="other/name.yaml")


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
@pytest.mark.parametrize("parser", LOADERS)
def test_every_file_reads_the_same_both_ways_with_each_parser(parser):
    """Big files too (corpus/many-contacts.yaml: seconds with either parser, read twice)."""
    for path in FILES:
        both_paths(path, Reading(parser=parser))


# Values at which the fast path must hand over, or where its arithmetic must
# match numpy's to the bit.
NUMBERS = [
    "0", "-0", "+0", "-00", "-0.0", "0.0", "-0e5", ".5", "-.5", "+.5", "1.", "1e3", "1E+3", "007",
    "1e-320", "4.9e-324", "1e-400", "-1e-400", "1e200", "-1e200", "1.7976931348623157e308",
    "1.7976931348623159e308", "1e309", "9" * 400, "-" + "9" * 320, "1" + "0" * 308, "0." + "0" * 400 + "1",
    "0x1F", "0o17", "1_000", ".inf", "-.inf", ".nan", "'1'", '"2"', "!!float 1", "!!int 2", "! 3", "&a 4",
    "true", "null", "~", "", "1e", ".", "+", "1e5.5", "١", "0.1", "-2.718281828459045", "123456789012345678901234567890",
]  # fmt: skip
NAMES = [
    "a", "'q'", '"d"', "1", "1e3", "true", "null", "~", "''", "' '", '"\\e[2J"', '"\\0"', '"a\\tb"', '"\\L"',
    "!!str s", "! t", "&n m", "[a]", "{a: b}", "2", "'1'", "é",
]  # fmt: skip


#: Where in a vector a number stands: first, middle, last.
SLOTS = ("[{}, 0, 0]", "[1, {}, 2]", "[0, 0, {}]")


def _number_places(number, slot):
    """Documents with ``number`` at ``slot`` of each vector a number stands in: a point, a
    normal, the wrist, a twist's angular, linear, at and screw."""
    vector = slot.format(number)
    yield CONTACTS.replace("[1, 0, 0]", vector, 1)
    yield CONTACTS.replace("[-1, 0, 0]", vector, 1)
    yield f"wrist: {vector}\n" + CONTACTS
    for twist in (f"angular: {vector}", f"linear: {vector}", f"at: {vector}\n    angular: [1, 1, 1]"):
        yield CONTACTS + f"twists:\n  - {twist}\n"
    yield CONTACTS + f"twists:\n  - screw: [1, 2, 3, {vector[1:-1]}]\n"


def _name_places(name):
    """Documents with ``name`` in each place a name stands: the grasp's, the units, a contact's, a twist's."""
    yield f"name: {name}\n" + CONTACTS
    yield f"units: {name}\n" + CONTACTS
    yield CONTACTS.replace("  - point: [1, 0, 0]", f"  - name: {name}\n    point: [1, 0, 0]")
    yield CONTACTS + f"twists:\n  - name: {name}\n    angular: [0, 0, 1]\n  - linear: [1, 0, 0]\n"


SHAPES = [
    "",
    "null",
    "[]",
    "- 1",
    "!!map {contacts: []}",
    "&top " + CONTACTS.replace("\n", "\n", 1),
    CONTACTS + "name: x\nname: y\n",
    CONTACTS + "contacts: []\n",
    "'contacts':" + CONTACTS[len("contacts:") :],
    "!!str contacts:" + CONTACTS[len("contacts:") :],
    CONTACTS.replace("point", "'point'"),
    CONTACTS.replace("- point: [1, 0, 0]", "- !!map {point: [1, 0, 0]}"),
    CONTACTS.replace("[1, 0, 0]", "!!seq [1, 0, 0]"),
    CONTACTS.replace("[1, 0, 0]", "&p [1, 0, 0]"),
    CONTACTS.replace("[1, 0, 0]", "[1, [0], 0]"),
    CONTACTS.replace("[1, 0, 0]", "[1, 0, 0, 0]"),
    CONTACTS.replace("[1, 0, 0]", "[1, 0]"),
    CONTACTS.replace("[1, 0, 0]", "[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[1]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]"),
    CONTACTS.replace("[-1, 0, 0]", "[0, 0, 0]"),
    CONTACTS.replace("[-1, 0, 0]", "[-0.0, 0, -0]"),
    CONTACTS.replace("    normal: [-1, 0, 0]\n", ""),
    CONTACTS.replace("    normal: [-1, 0, 0]\n", "    normal: [-1, 0, 0]\n    normal: [-1, 0, 0]\n"),
    CONTACTS.replace("    normal: [-1, 0, 0]\n", "    normal: [-1, 0, 0]\n    point: [1, 0, 0]\n"),
    CONTACTS.replace("    normal: [-1, 0, 0]\n", "    normal: [-1, 0, 0]\n    extra: 1\n"),
    CONTACTS.replace("    normal: [-1, 0, 0]\n", "    normal: [-1, 0, 0]\n    name: a\n    name: b\n"),
    CONTACTS.replace("  - point: [1, 0, 0]\n    normal: [-1, 0, 0]\n", ""),
    CONTACTS + "  - point: [1, 0, 0]\n    normal: [-1, 0, 0]\n",
    CONTACTS.replace("  - point: [1, 0, 0]", "  - name: '2'\n    point: [1, 0, 0]"),
    CONTACTS.replace("  - point: [1, 0, 0]", "  - *a"),
    CONTACTS.replace("  - point: [1, 0, 0]", "  - [1, 0, 0]\n  - point: [1, 0, 0]"),
    CONTACTS + "wrist: *a\n",
    CONTACTS + "extra: 1\n",
    CONTACTS + "? [a]\n: 1\n",
    CONTACTS + "1: 1\n",
    CONTACTS + "twists:\n",
    CONTACTS + "twists: []\n",
    CONTACTS + "twists: {}\n",
    CONTACTS + "twists:\n  - at: [0, 0, 1]\n",
    CONTACTS + "twists:\n  - name: z\n",
    CONTACTS + "twists:\n  - {}\n",
    CONTACTS + "twists:\n  - screw: [1, 2, 3, 4, 5, 6]\n    angular: [0, 0, 1]\n",
    CONTACTS + "twists:\n  - screw: [1, 2, 3, 4, 5, 6]\n    at: [0, 0, 1]\n",
    CONTACTS + "twists:\n  - screw: [1, 2, 3, 4, 5, 6]\n    screw: [1, 2, 3, 4, 5, 6]\n",
    CONTACTS + "twists:\n  - screw: [1, 2, 3, 4, 5]\n",
    CONTACTS + "twists:\n  - angular: [0, 0, 1]\n    angular: [0, 0, 1]\n",
    CONTACTS + "twists:\n  - angular: [0, 0, 1]\n    spin: 1\n",
    CONTACTS + "twists:\n  - angular: [0, 0, 1]\n  - name: '1'\n    linear: [1, 0, 0]\n",
    CONTACTS + "twists:\n  - angular: [1e200, 1e200, 1e200]\n    at: [1e200, -1e200, 0]\n",
    CONTACTS + "twists:\n  - angular: [1e200, 0, 0]\n    at: [0, 1e200, 0]\n  - angular: [1, 0, 0]\n",
    CONTACTS
    + "twists:\n  - angular: [1e-200, 3, -7e-300]\n    linear: [1e300, -1e-300, 5]\n    at: [1e10, -1e-310, 2]\n",
    CONTACTS + "twists:\n  - !!map {angular: [0, 0, 1]}\n",
    CONTACTS + "twists:\n  - &t {angular: [0, 0, 1]}\n  - *t\n",
    CONTACTS + "twists:\n  - angular: [0, 0, 1]\n  - [1, 2, 3]\n",
    CONTACTS + "twists:\n  - angular: [0, 0, 1]\n...\n---\n" + CONTACTS,
    CONTACTS + "---\n" + CONTACTS + "name: second\n---\n",
    CONTACTS + "---\nname: broken\n" + CONTACTS + "  - [1, 2\n",
    CONTACTS + "]\n",
    CONTACTS + "\tx: 1\n",
    (
        "contacts: [{point: [1, 0, 0], normal: [-1, 0, 0]}, {point: [0, 1, 0], normal: [0, -1, 0]},"
        " {point: [0, 0, 1], normal: [0, 0, -1]}]\ntwists: [{screw: [0, 0, 1, 0, 0, 0]}]\n"
    ),
    "\ufeff" + CONTACTS,
    CONTACTS.replace("[1, 0, 0]", "[1, 0, 0]  # é"),
    CONTACTS + "name: \x7f\n",
    CONTACTS + "name: \x0b\n",
    CONTACTS + "name: é\x85\x01\n",
    # sections the fast path has composed and read by their modules: valid, before the
    # contacts, and with each kind of problem (theirs, the composer's, the stream's)
    CONTACTS
    + "paths:\n  - {name: p, segments: [{duration: 1, angular: [0, 0, 1]}, {duration: 2, pose: {rotvec: [0, 0, 1]}}]}\n",
    "paths: [{frame: body, segments: [{duration: 0.5, screw: [0, 0, 1, 0, 0, 0]}]}]\n" + CONTACTS,
    CONTACTS + "paths: [{segments: []}]\n",
    CONTACTS + "paths: [{segments: [{duration: 1, angular: &a [0, 0, 1], linear: *a}]}]\n",
    CONTACTS + "paths: [{segments: [{duration: 1, angular: !!python/tuple [0, 0, 1]}]}]\n",
    CONTACTS + "paths: [{segments: [{duration: 1, duration: 2, angular: [0, 0, 1]}]}]\n",
    CONTACTS + "paths: " + "[" * 40 + "]" * 40 + "\n",
    CONTACTS + "paths: [{segments: [{duration: 1, angular: [0, 0, 1]}\n",
    CONTACTS + "paths: []\npaths: []\n",
    CONTACTS + "hand:\n  fingers:\n" + "    - joints: [{axis: [0, 0, 1], point: [0, 0, 0]}]\n" * 3,
    CONTACTS + "hand:\n  fingers:\n" + "    - joints: [{axis: [0, 0, 0], point: [0, 0, 0]}]\n" * 3,
    CONTACTS.replace("[1, 0, 0]", "[1, 0, x]") + "hand: {fingers: [{joints: [{axis: [0, 0, 1]}]}]}\n",
]


finite = st.floats(allow_nan=False, allow_infinity=False)
extreme = st.sampled_from([0.0, -0.0, 1e-310, -5e-324, 1e200, -1e200, 1.7976931348623157e308, 3.0, -0.5])
number = st.one_of(
    finite.map(repr),
    extreme.map(repr),
    st.integers(-(10**30), 10**30).map(str),
    st.sampled_from(NUMBERS),
)
vector = st.lists(number, min_size=3, max_size=3).map(lambda v: "[" + ", ".join(v) + "]")
name = st.one_of(st.sampled_from(NAMES + ["g", "h"]), st.text(st.characters(codec="utf-8"), max_size=6).map(repr))

#: Changes to a document's text after which a fast path must hand over (or read on, the same).
MUTATIONS = [
    lambda t: t,
    lambda t: t + "extra: 1\n",
    lambda t: t + "name: x\nname: y\n",
    lambda t: "&top " + t,
    lambda t: t.replace("point", "'point'", 1),
    lambda t: t.replace("normal:", "normal: !!seq", 1),
    lambda t: t.replace("contacts:", "!!str contacts:", 1),
    lambda t: t + "wrist: *a\n",
    lambda t: t + "]\n",
    lambda t: t + "\tx: 1\n",
    lambda t: "\ufeff" + t,
    lambda t: t.replace("\n", "  # é\n", 1),
    lambda t: t + "? [a]\n: 1\n",
]


def _contact(draw, flow):
    fields = [("point", draw(vector)), ("normal", draw(vector))]
    if draw(st.integers(0, 4)) == 0:
        fields.insert(draw(st.integers(0, 2)), ("name", draw(name)))
    if flow:
        return "  - {" + ", ".join(f"{k}: {v}" for k, v in fields) + "}"
    return "\n".join(f"  {'-' if i == 0 else ' '} {k}: {v}" for i, (k, v) in enumerate(fields))


def _twist(draw):
    named = [f"name: {draw(name)}"] if draw(st.integers(0, 3)) == 0 else []
    if draw(st.booleans()):
        parts = [*named, f"screw: [{', '.join(draw(st.lists(number, min_size=6, max_size=6)))}]"]
    else:
        keys = draw(st.lists(st.sampled_from(["angular", "linear", "at"]), min_size=1, max_size=3, unique=True))
        parts = [*named, *(f"{key}: {draw(vector)}" for key in keys)]
    return "\n".join(f"  {'-' if i == 0 else ' '} {part}" for i, part in enumerate(parts))


@st.composite
def documents(draw):
    """A grasp document: a name, units and wrist or not, contacts (three, or a wrong count) in
    block or flow style, twists, a path, an inline hand, then one of :data:`MUTATIONS`."""
    lines = []
    for key, value in (("name", name), ("units", name), ("wrist", vector)):
        if draw(st.booleans()):
            lines.append(f"{key}: {draw(value)}")
    flow = draw(st.booleans())
    lines.append("contacts:")
    lines += [_contact(draw, flow) for _ in range(draw(st.sampled_from([3, 3, 3, 2, 4])))]
    twists = draw(st.integers(0, 3))
    if twists:
        lines.append("twists:")
    lines += [_twist(draw) for _ in range(twists)]
    if draw(st.integers(0, 3)) == 0:
        lines.append(f"paths: [{{name: p, segments: [{{duration: {draw(number)}, angular: {draw(vector)}}}]}}]")
    if draw(st.integers(0, 5)) == 0:
        lines.append("hand:\n  fingers:\n" + f"    - joints: [{{axis: {draw(vector)}, point: [0, 0, 0]}}]\n" * 3)
    text = "\n".join(lines) + "\n"
    if draw(st.booleans()):
        text = text.replace("\n", "\n", 1)
    return draw(st.sampled_from(MUTATIONS))(text)


#: The parsers of the hand-picked properties below: libyaml's (the loader's own when present) in
#: the default run, the pure-Python one with ``-m slow`` (over a second each: its events reach the
#: fast path as libyaml's do, and the default run still reads random streams and every bundled
#: grasp through both paths with it).
PARSERS = [
    pytest.param(
        p,
        id=p.__name__,
        # over a second: docs/reference/development.md, Test time
        marks=() if p is LOADERS[-1] else pytest.mark.slow,
    )
    for p in LOADERS
]


def _examples(cases, **strategies):
    """A property over ``strategies``, run with each parser, with every value of ``cases`` among
    its explicit examples: the hand-picked values are always tried."""
    (key,) = strategies

    def decorate(test):
        for case in cases:
            test = example(**{key: case})(test)
        return pytest.mark.parametrize("parser", PARSERS)(given(**strategies)(test))

    return decorate


_SETTINGS = settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])


@_SETTINGS
@_examples(NUMBERS, number=number)
# a number last in a list in the default run, first and between in the slow one (development.md, Test time)
@pytest.mark.parametrize("slot", [pytest.param(s, marks=pytest.mark.slow) for s in SLOTS[:2]] + [SLOTS[2]])
def test_a_number_reads_the_same_both_ways_wherever_it_stands(number, slot, parser):
    for doc in _number_places(number, slot):
        both_paths(doc, Reading(parser=parser), file="g.yaml")


@_SETTINGS
@_examples(NAMES, name=name)
def test_a_name_reads_the_same_both_ways_wherever_it_stands(name, parser):
    for doc in _name_places(name):
        both_paths(doc, Reading(parser=parser), file="g.yaml")


@_SETTINGS
@_examples(SHAPES, doc=documents())
def test_a_document_of_any_shape_reads_the_same_both_ways(doc, parser):
    both_paths(doc, Reading(parser=parser), file="dir/shape.yaml")
    both_paths(doc.encode("utf-8", "surrogatepass"), Reading(parser=parser))


@_SETTINGS  # 25 streams in the default run: the many below are -m slow's
@given(st.lists(documents(), min_size=1, max_size=3), st.sampled_from(LOADERS))
def test_streams_of_documents_read_the_same_both_ways(docs, parser):
    both_paths("---\n".join(docs), Reading(parser=parser), file="dir/random.yaml")


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
@settings(max_examples=500, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(documents(), min_size=1, max_size=3), st.sampled_from(LOADERS))
def test_many_more_documents_read_the_same_both_ways(docs, parser):
    both_paths("---\n".join(docs), Reading(parser=parser), file="random.yaml")


def test_every_bundled_grasp_takes_the_fast_path(monkeypatch, loader):
    """Every bundled grasp, with its paths and hand, is read without the general
    path (two to three times slower on a plain grasp, bench/loader.py), so a
    change that sends them there fails here."""

    def fail(*args, **kw):
        raise AssertionError("general path taken")

    monkeypatch.setattr(reader, "read_document", fail)
    bundled = sorted((TESTS.parent / "grasps").rglob("*.yaml"))
    assert len(bundled) == 8
    for path in bundled:
        for entry in read_grasps(path, reading=loader):
            assert isinstance(entry, Grasp), str(entry)


@pytest.mark.parametrize("size", [0, 1, 65535, 65536, 65537, 200_000, 200_001, 200_002, 300_000])
def test_capped_read_in_chunks(size, tmp_path, monkeypatch):
    path = tmp_path / "big.yaml"
    path.write_bytes(b"#" * size)
    cap = 200_000
    expected = "too-large" if size > cap else "empty-document"
    (entry,) = read_grasps(path, max_bytes=cap)
    assert entry.code == expected
    with open(path, "rb") as handle:
        assert text.read_capped(handle, cap + 1) == b"#" * min(size, cap + 1)
    monkeypatch.setattr(sys, "stdin", io.TextIOWrapper(io.BytesIO(b"#" * size)))
    (entry,) = read_grasps("-", max_bytes=cap)
    assert (entry.code, entry.file) == (expected, "<stdin>")


def test_arrays_of_the_fast_path_are_read_only_float_copies(loader):
    (grasp,) = both_paths(
        f"wrist: [1, 2, 3]\n{CONTACTS}twists:\n  - angular: [0, 0, 1]\n  - angular: [1, 0, 0]\n",
        file="g.yaml",
        reading=loader,
    )
    arrays = [grasp.points, grasp.normals, grasp.wrist] + [twist.screw for twist in grasp.twists]
    for array in arrays:
        assert array.dtype == np.float64 and not array.flags.writeable and array.flags.owndata
    assert [a.shape for a in arrays] == [(3, 3), (3, 3), (3,), (6,), (6,)]
