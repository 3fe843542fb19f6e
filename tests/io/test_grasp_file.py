"""The grasp-file loader: format, located errors, safety, both YAML parsers."""

import errno
import io
import os
import pickle
import sys
from dataclasses import replace
from pathlib import Path

import jsonschema
import numpy as np
import orjson
import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from grasptwist.engine import screws
from grasptwist.io.grasp import (
    DEFAULT_MAX_BYTES,
    MAX_DEPTH,
    MAX_ERRORS,
    READING,
    Grasp,
    InputError,
    Reading,
    grasp_schema,
    load_grasps,
    one_per_document,
    read_grasps,
)
from grasptwist.run import placement
from hostile import jsonl, run
from hostile import summary as summary_line
from loaders import CONTACTS, LOADERS
from places import GRASPS, TESTS

INVALID = TESTS / "invalid_grasps"
BUNDLED = GRASPS


def read(text, name="g.yaml", **kw):
    return read_grasps(text, file=name, **kw)


def only_error(text, **kw):
    (entry,) = read(text, **kw)
    assert isinstance(entry, InputError), entry
    return entry


def only_grasp(text, **kw):
    (entry,) = read(text, **kw)
    assert isinstance(entry, Grasp), str(entry)
    return entry


def summary(entry):
    """What must agree between the two parsers: everything but YAML's own wording."""
    if isinstance(entry, InputError):
        message = None if entry.code == "yaml-syntax" else entry.message
        return ("error", entry.code, message, entry.file, entry.line, entry.column, entry.document)
    return (
        "grasp",
        entry.name,
        entry.units,
        entry.file,
        entry.document,
        entry.line,
        entry.contact_names,
        entry.points.tolist(),
        entry.normals.tolist(),
        None if entry.wrist is None else entry.wrist.tolist(),
        [(t.name, t.screw.tolist(), t.line) for t in entry.twists],
    )


# --------------------------------------------------------------------------
# The invalid fixtures: each file's header says what it must give.


def fixture_header(path):
    """``(code, line, column, schema verdict)`` from the file's ``# expect:``/``# schema:`` lines."""
    lines = path.read_bytes().decode("ascii", "replace").splitlines()
    code, where = lines[0].removeprefix("# expect: ").split()
    line, column = (None, None) if where == "-" else map(int, where.split(":"))
    verdict = lines[1].removeprefix("# schema: ").split()[0]
    return code, line, column, verdict


FIXTURES = sorted(INVALID.glob("*.yaml"))


def test_fixtures_cover_every_rejection():
    codes = {fixture_header(path)[0] for path in FIXTURES}
    assert len(FIXTURES) >= 15
    assert codes >= {
        "unknown-key", "duplicate-key", "contact-count", "vector-length", "not-a-number", "non-finite",
        "zero-normal", "duplicate-name", "empty-document", "not-a-mapping", "invalid-utf8", "forbidden-tag",
        "alias", "missing-key", "conflicting-keys", "yaml-syntax", "control-character", "not-a-list",
        "not-a-string", "invalid-name", "invalid-key", "invalid-friction", "invalid-mass",
    }  # fmt: skip


@pytest.mark.parametrize("path", FIXTURES, ids=lambda p: p.stem)
def test_invalid_fixture_is_rejected_where_its_header_says(path, loader):
    code, line, column, _ = fixture_header(path)
    entries = placement.read_grasps(path, reading=loader)  # a hand's fixtures: placed on their contacts
    error = next(e for e in entries if isinstance(e, InputError))
    assert (error.code, error.line, error.column) == (code, line, column)
    where = f"{path}:{line}:{column}: " if line else f"{path}: "
    assert str(error).startswith(where)
    assert error.file == str(path)


@pytest.mark.parametrize("path", FIXTURES + sorted(BUNDLED.glob("*.yaml")), ids=lambda p: p.stem)
@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_both_parsers_give_identical_results(path):
    if len(LOADERS) < 2:
        pytest.skip("libyaml not available")
    results = []
    for parser in LOADERS:
        results.append([summary(entry) for entry in read_grasps(path, reading=Reading(parser=parser))])
    assert results[0] == results[1]


# --------------------------------------------------------------------------
# Safety.


@pytest.mark.parametrize(
    "template",
    [
        '!!python/object/apply:os.system ["touch {}"]\n',
        "name: x\n" + CONTACTS.replace("point: [1, 0, 0]", 'point: !!python/object/apply:os.system ["touch {}"]'),
        CONTACTS + 'twists:\n  - !!python/object/apply:os.system ["touch {}"]\n',
        '? !!python/object/apply:os.system ["touch {}"]\n: 1\n',
    ],
    ids=["top-level", "nested-value", "list-item", "key"],
)
def test_python_tags_never_run(template, loader, tmp_path):
    target = tmp_path / "pwned"
    text = template.format(target)
    errors = read(text, reading=loader)
    assert [e.code for e in errors if e.code != "missing-key"] == ["forbidden-tag"]
    assert not target.exists()
    # Control: the same text does run under an unsafe loader, so the test can fail.
    yaml.load(text, Loader=yaml.UnsafeLoader)
    assert target.exists()


def test_billion_laughs_is_refused_unexpanded_in_ten_lines(loader):
    text = 'a: &a ["lol","lol","lol","lol","lol","lol","lol","lol","lol"]\n'
    text += "".join(
        f"{b}: &{b} [*{a},*{a},*{a},*{a},*{a},*{a},*{a},*{a},*{a}]\n" for a, b in zip("abcdefgh", "bcdefghi")
    )
    errors = read(text, reading=loader)  # its time: bench/loader.py
    # 72 aliases inside the values of 9 unknown keys: no news once the keys are reported (issue 21: 83 lines);
    # each unknown key is a line of its own (issue 26)
    assert [(e.code, e.line, e.column) for e in errors] == [("unknown-key", 1, 1), ("missing-key", 1, 1)] + [
        ("unknown-key", line, 1) for line in range(2, 10)
    ]
    assert errors[0].message.startswith("a: unknown key (expected one of: name, ")


def test_aliases_where_values_belong_are_each_a_problem(loader):
    text = "a: &p [1, 0, 0]\n" + CONTACTS.replace("point: [1, 0, 0]", "point: *p").replace("[-0.5, 0.866, 0]", "*p")
    errors = read(text, reading=loader)
    assert [(e.code, e.line, e.column) for e in errors] == [("unknown-key", 1, 1), ("alias", 3, 12), ("alias", 5, 12)]
    assert errors[1].message == "contacts[0].point: aliases (*p) are not allowed; write the value out"


def test_nothing_inside_an_unknown_keys_value_is_reported(loader):
    inside = "colour: {a: !!python/none 1, a: *x, b: [!!binary aGk=]}\n"
    errors = read(CONTACTS + inside, reading=loader)
    assert [(e.code, e.line, e.column) for e in errors] == [("unknown-key", 8, 1)]
    # the same value under a known key: each of its problems is one
    codes = [e.code for e in read(CONTACTS + inside.replace("colour", "wrist"), reading=loader)]
    assert codes == ["not-a-list", "forbidden-tag", "duplicate-key", "forbidden-tag"]  # in file order


class LimitedLibyaml(yaml.SafeLoader):
    """A parser with a nesting limit of its own (here 100 levels) that it
    enforces while scanning ahead, as libyaml does from PyYAML 6.0.4 on (about
    1000 levels): at a document's start it refuses the document if it nests
    deeper than that anywhere, at the mark where it does, before any of the
    document's collections is an event.  The loader must still say
    ``too-deep`` where ``MAX_DEPTH`` is crossed, whatever PyYAML is installed."""

    LIMIT = 100

    def __init__(self, text):
        super().__init__(text)
        self.text = text
        self.documents = 0

    def get_event(self):
        event = super().get_event()
        if isinstance(event, yaml.DocumentStartEvent):
            self.documents += 1
            ahead, depth, document = yaml.SafeLoader(self.text), 0, 0
            while document <= self.documents:
                seen = ahead.get_event()
                document += isinstance(seen, yaml.DocumentStartEvent)
                depth += isinstance(seen, yaml.CollectionStartEvent) - isinstance(seen, yaml.CollectionEndEvent)
                if depth > self.LIMIT and document == self.documents:
                    raise yaml.parser.ParserError(None, None, "exceeded the nesting limit", seen.start_mark)
                if isinstance(seen, yaml.DocumentEndEvent) and document == self.documents:
                    break
        return event


@pytest.mark.parametrize(
    "deep, line",
    [
        ("[" * 20000 + "]" * 20000, 9),
        ("{a: " * 20000 + "1" + "}" * 20000, 9),
        ("- " * 20000 + "1", 9),
        ("".join(" " * i + "a:\n" for i in range(200)) + " " * 200 + "1\n", 9 + MAX_DEPTH),
    ],
    ids=["flow-lists", "flow-maps", "block-lists", "block-maps"],
)
@pytest.mark.parametrize("parser", [*LOADERS, LimitedLibyaml], ids=lambda parser: parser.__name__)
def test_deep_nesting_fails_fast(deep, line, parser):
    text = CONTACTS + "---\n" + deep + "\n---\n" + CONTACTS
    entries = read(text, max_bytes=1 << 30, reading=Reading(parser=parser))
    # The good document before is kept; the parse stops at the deep one.
    assert isinstance(entries[0], Grasp)
    (error,) = entries[1:]
    assert (error.code, error.line, error.document) == ("too-deep", line, 1)
    assert f"deeper than {MAX_DEPTH}" in error.message


def test_nesting_up_to_the_limit_gets_the_specific_error(loader):
    text = CONTACTS.replace("[1, 0, 0]", "[1, 0, " + "[" * (MAX_DEPTH - 4) + "]" * (MAX_DEPTH - 4) + "]")
    error = only_error(text, reading=loader)
    assert (error.code, error.message) == ("not-a-number", "contacts[0].point[2]: expected a number, got a list")


def test_oversized_content_is_refused_before_parsing():
    error = only_error(b"[" * 101, max_bytes=100)
    assert (error.code, error.line, error.document) == ("too-large", None, None)
    assert str(error) == "g.yaml: larger than the size limit of 100 bytes"
    assert isinstance(read(b"#" * 100, max_bytes=100)[0], InputError)  # at the cap: parsed (empty)
    assert read(b"#" * 100, max_bytes=100)[0].code == "empty-document"


@pytest.mark.skipif(not Path("/dev/zero").exists(), reason="needs /dev/zero")
def test_a_device_is_never_read():
    # an endless stream: refused after opening, before any byte is read
    (error,) = read_grasps("/dev/zero", max_bytes=DEFAULT_MAX_BYTES)
    assert (error.code, error.file, error.message) == (
        "read-error", "/dev/zero", "cannot read: not a regular file (a pipe, socket or device)"
    )  # fmt: skip


@pytest.mark.parametrize("path, why", [("no/such/file.yaml", errno.ENOENT), (".", errno.EISDIR)])
def test_unreadable_paths_give_read_error(path, why):
    (error,) = read_grasps(path)
    assert error.code == "read-error"
    assert str(error) == f"{path}: cannot read: {os.strerror(why)}"


def test_invalid_utf8_is_located_by_line_and_character():
    error = only_error("name: x\ncontacts: [é, ".encode() + b"\xff\xfe]\n")
    assert (error.code, error.line, error.column) == ("invalid-utf8", 2, 15)
    assert "byte offset 23" in error.message


def test_lone_surrogate_in_str_content():
    assert only_error("name: \udc80\n").code == "invalid-utf8"


def test_utf8_bom_is_accepted(loader):
    assert only_grasp("\ufeffname: bom\n" + CONTACTS).name == "bom"


def test_random_bytes_never_raise(loader):
    # Every outcome is a Grasp or a InputError, whatever the input.
    rng = np.random.default_rng(3)
    seeds = [CONTACTS.encode(), b"- [{a: *b}, !!x 1, &c ~]\n", b"\t\x00\xff---\n..."]
    for _ in range(300):
        seed = seeds[rng.integers(len(seeds))]
        data = bytearray(seed)
        for _ in range(rng.integers(1, 6)):
            data[rng.integers(len(data))] = rng.integers(256)
        for entry in read_grasps(bytes(data), reading=loader):
            assert isinstance(entry, (Grasp, InputError))


@settings(max_examples=150, deadline=None)
@given(st.text(alphabet=st.sampled_from(list(" \t\n-:?[]{},&*!|>'\"#%@`~.0123456789aez_\u00e9\u2028")), max_size=60))
def test_random_yaml_like_text_never_raises(text):
    for parser in LOADERS:
        for entry in read(text, reading=Reading(parser=parser)):
            assert isinstance(entry, (Grasp, InputError))


# --------------------------------------------------------------------------
# Format: values, defaults, conversions.


def test_complete_grasp(loader):
    grasp = only_grasp(
        "name: cyl\nunits: mm\nwrist: [0, 0, 1]\n"
        + CONTACTS.replace("  - point: [1", "  - name: thumb\n    point: [1")
        + "twists:\n  - name: spin\n    angular: [0, 0, 1]\n  - screw: [1, 2, 3, 4, 5, 6]\n"
    )
    assert (grasp.name, grasp.units, grasp.file, grasp.document, grasp.line) == ("cyl", "mm", "g.yaml", 0, 1)
    assert grasp.contact_names == ("thumb", "2", "3")
    assert grasp.points.tolist() == [[1, 0, 0], [-0.5, 0.866, 0], [-0.5, -0.866, 0]]
    assert grasp.wrist.tolist() == [0, 0, 1]
    assert [(t.name, t.screw.tolist(), t.line) for t in grasp.twists] == [
        ("spin", [0, 0, 1, 0, 0, 0], 13),
        ("2", [1, 2, 3, 4, 5, 6], 15),
    ]


def test_defaults(loader):
    grasp = only_grasp(CONTACTS, name="some/dir/mug.yaml")
    assert (grasp.name, grasp.units, grasp.wrist, grasp.twists) == ("mug", None, None, ())
    assert grasp.contact_names == ("1", "2", "3")
    assert only_grasp(CONTACTS + "twists: []\n").twists == ()


def test_arrays_are_read_only_floats(loader):
    grasp = only_grasp("wrist: [0, 0, 1]\n" + CONTACTS + "twists:\n  - angular: [0, 0, 1]\n")
    for array in (grasp.points, grasp.normals, grasp.wrist, grasp.twists[0].screw):
        assert array.dtype == np.float64
        with pytest.raises(ValueError, match="read-only"):
            array[0] = 1.0


def test_normals_are_normalised_even_at_extreme_scales(loader):
    text = CONTACTS.replace("[-1, 0, 0]", "[-3.0e+200, 4.0e+200, 0]").replace(
        "[0.5, -0.866, 0]", "[1.0e-200, 0, 1.0e-200]"
    )
    normals = only_grasp(text).normals
    np.testing.assert_allclose(normals[0], [-0.6, 0.8, 0], rtol=1e-15)
    np.testing.assert_allclose(normals[1], [0.5**0.5, 0, 0.5**0.5], rtol=1e-15)
    np.testing.assert_allclose(screws.norm(normals), 1, rtol=1e-15)


@pytest.mark.parametrize(
    "twist, expected",
    [
        ("angular: [0, 0, 1]", [0, 0, 1, 0, 0, 0]),
        ("linear: [0, 0, 1]", [0, 0, 0, 0, 0, 1]),
        ("angular: [0, 0, 1]\n    at: [1, 0, 0]", [0, 0, 1, 0, -1, 0]),
        ("angular: [0, 0, 2]\n    linear: [0, 1, 0]\n    at: [1, 0, 0]", [0, 0, 2, 0, -1, 0]),
        ("linear: [1, 2, 3]\n    at: [7, 8, 9]", [0, 0, 0, 1, 2, 3]),
        ("screw: [0, -1, 0, 0, 0, 0.5]", [0, -1, 0, 0, 0, 0.5]),
    ],
)
def test_twists_are_moved_to_the_origin(twist, expected, loader):
    (t,) = only_grasp(CONTACTS + "twists:\n  - " + twist + "\n").twists
    assert t.screw.tolist() == expected
    # The origin screw gives the stated velocity at `at`.
    if "at:" in twist:
        fields = yaml.safe_load("  - " + twist)[0]
        np.testing.assert_allclose(screws.field_at(t.screw, fields["at"]), fields.get("linear", [0, 0, 0]))


@pytest.mark.parametrize(
    "text, value",
    [
        ("1e-3", 1e-3), ("1E+3", 1e3), ("-.5", -0.5), ("+2.", 2.0), ("0x1F", 31), ("0o17", 15),
        ("012", 12), ("1e200", 1e200), ("!!float 1", 1.0), ("!!int '7'", 7), ("-0", 0.0),
        ("123456789012345678901234567890", 1.2345678901234568e29),
    ],
)  # fmt: skip
def test_yaml_12_core_numbers(text, value, loader):
    grasp = only_grasp(f"wrist: [{text}, 0, 0]\n" + CONTACTS)
    assert grasp.wrist[0] == value


@pytest.mark.parametrize(
    "text, code, problem",
    [
        ("true", "not-a-number", "expected a number, got a boolean (true)"),
        ("'1'", "not-a-number", "expected a number, got the string '1'"),
        ("1_000", "not-a-number", "expected a number, got the string '1_000'"),
        ("~", "not-a-number", "expected a number, got null"),
        ("!!str 1", "not-a-number", "expected a number, got the string '1'"),
        ("!!int abc", "not-a-number", "'abc' is not a valid !!int"),
        ("!!bool 1", "bad-scalar", "'1' is not a valid !!bool"),
        (".NaN", "non-finite", "expected a finite number, got .NaN"),
        ("+.inf", "non-finite", "expected a finite number, got +.inf"),
        ("1" * 400, "non-finite", "expected a finite number, got " + "1" * 27 + "..."),
        # beyond Python's 4300-digit limit of int(str) and str(int)
        ("-" + "9" * 5000, "non-finite", "expected a finite number, got -" + "9" * 26 + "..."),
        ("0x" + "f" * 5000, "non-finite", "expected a finite number, got 0x" + "f" * 25 + "..."),
        ("[1]", "not-a-number", "expected a number, got a list"),
    ],
)
def test_non_numbers(text, code, problem, loader):
    error = only_error(f"wrist: [0, {text}, 0]\n" + CONTACTS, reading=loader)
    assert (error.code, error.message, error.line, error.column) == (code, "wrist[1]: " + problem, 1, 12)


def test_integers_of_any_length_anywhere_give_an_error_not_an_exception(loader):
    # int() and str() of more than 4300 decimal digits raise ValueError in Python 3.11+.
    long = "7" * 5000
    assert (
        only_error(f"? {long}\n: x\n" + CONTACTS, reading=loader).message
        == f"top level: keys must be strings, got the number {long[:27]}..."
    )
    assert only_error(f"contacts: 0x{long}\n", reading=loader).message.endswith(f", got the number 0x{long[:25]}...")
    assert only_grasp(f"name: {long}\n" + CONTACTS).name == long  # a label, as written
    assert only_grasp(f"wrist: [0, {'0' * 5000}1, 0o{'0' * 5000}7]\n" + CONTACTS).wrist.tolist() == [0, 1, 7]


@pytest.mark.parametrize("name", ["1", "1e3", "true", "0x1F", "yes", "a b", "'quoted: yes'"])
def test_names_are_taken_as_written(name, loader):
    grasp = only_grasp(f"name: {name}\n" + CONTACTS.replace("- point: [1", f"- name: {name}\n    point: [1"))
    assert grasp.name == grasp.contact_names[0] == name.strip("'")


@pytest.mark.parametrize(
    "quoted, char",
    [('"a\\nb"', "U+000A"), ('"\\e[2J\\e[31mred"', "U+001B"), ('"nul\\0"', "U+0000"), ('"a\\tb"', "U+0009"),
     ('"next\\Nline"', "U+0085"), ('"a\\Lb"', "U+2028"), ('"a\\Pb"', "U+2029")],
    ids=["newline", "escape", "nul", "tab", "nel", "line-separator", "paragraph-separator"],
)  # fmt: skip
def test_names_that_would_break_a_diagnostic_line_or_drive_a_terminal(quoted, char, loader):
    # The file holds only printable characters; YAML's double-quoted escapes make the controls.
    for text in (f"name: {quoted}\n" + CONTACTS, f"units: {quoted}\n" + CONTACTS,
                 CONTACTS.replace("- point: [1", f"- name: {quoted}\n    point: [1")):  # fmt: skip
        error = only_error(text, reading=loader)
        assert error.code == "invalid-name" and error.message.endswith(f"without control characters (found {char})")
    assert only_grasp('name: "caf\u00e9 \u2013 \U0001f91d"\n' + CONTACTS).name == "caf\u00e9 \u2013 \U0001f91d"


def test_core_tags_are_allowed(loader):
    text = "!!map\nname: !!str x\nwrist: !!seq [!!float 0, !!int 0, ! 1]\n" + CONTACTS
    assert only_error(text, reading=loader).message == "wrist[2]: expected a number, got the string '1'"
    assert only_grasp(text.replace("! 1", "1")).name == "x"


@pytest.mark.parametrize(
    "text, message",
    [
        ("!!set {a}", "top level: tag !!set is not allowed"),
        ("wrist: !!omap [a: 1]", "wrist: tag !!omap is not allowed"),
        ("wrist: !!binary aGk=", "wrist: tag !!binary is not allowed"),
        ("wrist: !!map [1]", "wrist: tag !!map is not allowed"),
        ("wrist: !<tag:example.com,2000:x> 1", "wrist: tag tag:example.com,2000:x is not allowed"),
    ],
)
def test_other_tags_are_forbidden(text, message, loader):
    *others, error = read(text + "\n", reading=loader)
    assert error.code == "forbidden-tag"
    assert error.message.startswith(message)
    # a refused node is passed over in silence; the document's other problems are not
    top = message.startswith("top level")
    assert [str(e) for e in others] == ([] if top else ["g.yaml:1:1: contacts: required key is missing"])


def test_unknown_key_suggestion(loader):
    error = only_error(CONTACTS + "twist:\n  - angular: [0, 0, 1]\n", reading=loader)
    assert error.message == "twist: unknown key (did you mean 'twists'?)"
    assert (error.line, error.column) == (8, 1)


def test_odd_keys_are_quoted_in_paths(loader):
    assert only_error(CONTACTS + "'a b': 1\n", reading=loader).message.startswith("['a b']: unknown key")


def test_duplicate_key_in_flow_mapping(loader):
    flow = "  - {point: [1, 0, 0], normal: [-1, 0, 0], point: [2, 0, 0]}\n"
    error = only_error(CONTACTS.replace("  - point: [1, 0, 0]\n    normal: [-1, 0, 0]\n", flow), reading=loader)
    assert (error.code, error.message, error.line, error.column) == (
        "duplicate-key", "contacts[0].point: duplicate key (first given at line 2)", 2, 44,
    )  # fmt: skip


def test_empty_and_null_documents(loader):
    for text in ("", "\n\n", "# c\n", "  \n# c\n"):
        error = only_error(text, reading=loader)
        assert (error.code, error.line, error.document) == ("empty-document", None, None)
    assert [e.code for e in read("---\n---\nnull\n", reading=loader)] == ["empty-document"] * 2


# --------------------------------------------------------------------------
# Every problem of a document, in file order.

# Issue 12's example: a misspelled key, a quoted number and a 4-number normal.
THREE_MISTAKES = """\
name: pinch
wrist: [0, 0, "1"]
contacts:
  - point: [1, 0, 0]
    nromal: [-1, 0, 0]
  - point: [-0.5, 0.866, 0]
    normal: [0.5, -0.866, 0, 1]
  - point: [-0.5, -0.866, 0]
    normal: [0.5, 0.866, 0]
"""


def where(entries):
    return [(e.code, e.line, e.column, e.document) for e in entries]


def test_every_problem_of_a_document_is_reported(loader):
    errors = read(THREE_MISTAKES, reading=loader)
    assert where(errors) == [("not-a-number", 2, 15, 0), ("unknown-key", 5, 5, 0), ("vector-length", 7, 13, 0)]
    assert [e.message for e in errors] == [
        "wrist[2]: expected a number, got the string '1'",
        "contacts[0].nromal: unknown key (did you mean 'normal'?)",
        "contacts[1].normal: expected 3 numbers, got 4",
    ]
    # The JSON Schema says the misspelling twice (unknown key, missing key); the suggestion says it once.
    validator = jsonschema.Draft202012Validator(grasp_schema())
    assert len(list(validator.iter_errors(yaml.safe_load(THREE_MISTAKES)))) == 4
    with pytest.raises(InputError) as caught:
        load_grasps(THREE_MISTAKES, file="g.yaml", reading=loader)
    assert str(caught.value) == "g.yaml:2:15: wrist[2]: expected a number, got the string '1'"


def test_the_command_line_gives_a_document_one_record_and_each_problem_a_line(tmp_path):
    path = tmp_path / "pinch.yaml"
    path.write_text(THREE_MISTAKES + "---\n" + (BUNDLED / "polyhedron.yaml").read_text())
    result, _ = run("resolve", path, "-f", "jsonl")
    assert result.exit_code == 1
    failed, *good = jsonl(result.stdout)
    assert good and all(r["ok"] for r in good)
    problems = read(THREE_MISTAKES)
    assert failed["errors"] == [
        {"code": e.code, "message": e.message, "line": e.line, "column": e.column} for e in problems
    ]
    assert (failed["ok"], failed["error"]) == (False, failed["errors"][0])
    lines = result.stderr.splitlines()
    assert lines[:3] == [f"{path}:{e.line}:{e.column}: error: {e.code}: {e.message}" for e in problems]
    assert lines[3:] == [summary_line([failed, *good])]


def test_issue_21_one_bad_file_is_one_failed_record(tmp_path):
    (tmp_path / "a.yaml").write_text((BUNDLED / "polyhedron.yaml").read_text())
    (tmp_path / "b.yaml").write_text("contacts: [1, 2]\n")
    result, _ = run("resolve", tmp_path, "-f", "jsonl")
    *good, bad = jsonl(result.stdout)
    assert good and all(r["ok"] and r["file"].endswith("a.yaml") for r in good)
    assert (bad["file"].endswith("b.yaml"), bad["ok"]) == (True, False)
    assert [e["code"] for e in bad["errors"]] == ["contact-count", "not-a-mapping", "not-a-mapping"]
    assert result.stderr.splitlines()[-1] == summary_line([*good, bad])


FOUR_TYPOS = CONTACTS.replace("point: [1", "pointt: [1").replace("normal: [0.5, -", "normall: [0.5, -") + (
    "wrsit: [0, 0, 1]\ntwistz: []\n"
)


@pytest.mark.parametrize("warnings", ["summary", "all"])
def test_issue_26_every_problem_of_a_document_is_in_its_one_record_and_on_a_line_of_its_own(tmp_path, warnings):
    path = tmp_path / "typo.yaml"
    path.write_text(FOUR_TYPOS)
    result, _ = run("resolve", path, "-f", "json", "--warnings", warnings)
    (rec,) = orjson.loads(result.stdout)
    assert result.exit_code == 1 and not rec["ok"]
    assert [(e["code"], e["line"], e["column"]) for e in rec["errors"]] == [
        ("unknown-key", 2, 5),  # each suggestion stands in for its key's "required key is missing"
        ("unknown-key", 5, 5),
        ("unknown-key", 8, 1),
        ("unknown-key", 9, 1),
    ]
    assert [e["message"] for e in rec["errors"] if e["code"] == "unknown-key"] == [
        "contacts[0].pointt: unknown key (did you mean 'point'?)",
        "contacts[1].normall: unknown key (did you mean 'normal'?)",
        "wrsit: unknown key (did you mean 'wrist'?)",
        "twistz: unknown key (did you mean 'twists'?)",
    ]
    assert rec["error"] == rec["errors"][0]
    lines = result.stderr.splitlines()
    assert lines[:-1] == [
        f"{path}:{e['line']}:{e['column']}: error: {e['code']}: {e['message']}" for e in rec["errors"]
    ]


def test_issue_26_a_document_past_the_limit_gives_the_limit_and_a_count(tmp_path):
    path = tmp_path / "typos.yaml"
    path.write_text(CONTACTS + "".join(f"extra{k}: 1\n" for k in range(MAX_ERRORS + 20)))
    result, _ = run("resolve", path, "-f", "json", "--warnings", "all")
    (rec,) = orjson.loads(result.stdout)
    *first, rest = rec["errors"]
    assert [(e["code"], e["line"]) for e in first] == [("unknown-key", 8 + k) for k in range(MAX_ERRORS)]
    assert (rest["code"], rest["message"]) == (
        "too-many-errors",
        f"20 more problems in this file not reported (only the first {MAX_ERRORS} are)",
    )
    assert len(result.stderr.splitlines()) == MAX_ERRORS + 2  # each reported problem, the count, the summary


def test_a_grouped_error_pickles_with_its_problems():
    (error,) = one_per_document(read("contacts: [1, 2]\n"))
    copy = pickle.loads(pickle.dumps(error))
    assert [(p.code, p.line, p.column) for p in copy.problems] == [(p.code, p.line, p.column) for p in error.problems]
    assert (copy.code, str(copy)) == (error.code, str(error)) == (copy.problems[0].code, str(copy.problems[0]))


def test_the_schema_states_the_units_of_angular_velocity():
    twist = grasp_schema()["$defs"]["twist"]["properties"]
    assert "radians per unit time" in twist["angular"]["description"]
    assert "radians per unit time" in twist["screw"]["description"]


def test_problems_come_in_file_order_whatever_order_they_are_found_in(loader):
    # the checks go name, contacts, twists; the file has them the other way round
    errors = read("twists:\n  - angular: [0, 0]\ncontacts: 3\nname: [x]\n", reading=loader)
    assert where(errors) == [("vector-length", 2, 14, 0), ("not-a-list", 3, 11, 0), ("not-a-string", 4, 7, 0)]


def test_refused_yaml_does_not_stop_the_checks(loader):
    text = (
        "wrist: !!python/tuple [0, 0, 0]\ncontacts: &c\n  - {point: *p, normal: [1, 0, 0]}\n"
        "  - {point: [0, 1, 0], normal: [0, 1, 0], point: [1, 1, 1]}\n  - {point: [0, 0, 1], normal: [0, 0, x]}\n"
    )
    assert where(read(text, reading=loader)) == [
        ("forbidden-tag", 1, 8, 0), ("alias", 3, 13, 0), ("duplicate-key", 4, 43, 0), ("not-a-number", 5, 39, 0),
    ]  # fmt: skip
    # a refused node is passed over: no second error for what it holds or stands for
    assert where(read("contacts: !!set {a, b}\n", reading=loader)) == [("forbidden-tag", 1, 11, 0)]
    assert where(read("wrist: [!!binary aGk=, 0, 0]\n" + CONTACTS, reading=loader)) == [("forbidden-tag", 1, 9, 0)]


def test_a_misspelling_is_one_problem_an_unknown_key_and_a_missing_one_are_two(loader):
    assert where(read(CONTACTS.replace("normal: [-1", "nromal: [-1"), reading=loader)) == [("unknown-key", 3, 5, 0)]
    unrelated = where(read(CONTACTS.replace("normal: [-1", "color: [-1"), reading=loader))
    assert unrelated == [("missing-key", 2, 5, 0), ("unknown-key", 3, 5, 0)]
    # a twist's motion key: the suggestion stands in for "needs 'screw', or 'angular' and/or 'linear'"
    twists = CONTACTS + "twists:\n  - angluar: [0, 0, 1]\n  - colour: [0, 0, 1]\n"
    assert where(read(twists, reading=loader)) == [
        ("unknown-key", 9, 5, 0),
        ("unknown-key", 10, 5, 0),
        ("missing-key", 10, 5, 0),
    ]


@pytest.mark.parametrize(
    "text, message",
    [
        (
            CONTACTS + "twists:\n  - angular: [0, 0, 1, 0, 0, 0]\n",
            "twists[0].angular: expected 3 numbers, got 6; a 6-vector (omega; v) goes under `screw:`",
        ),
        (
            CONTACTS + "twists:\n  - screw: [0, 0, 1]\n",
            "twists[0].screw: expected 6 numbers, got 3; a 3-vector goes under `angular:` or `linear:`",
        ),
        (
            "contacts:\n  thumb: {point: [0, 2, 2], normal: [1, 0, 0]}\n",
            "contacts: expected a list of 3 contacts like [{point: [x, y, z], normal: [x, y, z]}, ...], got a mapping;"
            " write each as '- name: thumb' with its point and normal under it",
        ),
        (
            "contacts:\n  point: [0, 2, 2]\n  normal: [1, 0, 0]\n",
            "contacts: expected a list of 3 contacts like [{point: [x, y, z], normal: [x, y, z]}, ...], got a mapping;"
            " start each of the three contacts with '- '",
        ),
    ],
    ids=["angular-6", "screw-3", "contacts-by-name", "one-contact-unlisted"],
)
def test_messages_that_say_what_to_write(text, message, loader):
    assert only_error(text, reading=loader).message == message


# --------------------------------------------------------------------------
# Per-file limits.


def test_a_file_of_document_markers_is_cut_short(loader):
    entries = read(b"---\n" * (1 << 18), reading=loader)  # 1 MiB: 262,144 empty documents (its time: bench/loader.py)
    assert where(entries[:2]) == [("empty-document", 2, 1, 0), ("empty-document", 3, 1, 1)]
    assert len(entries) == MAX_ERRORS + 2 == 102
    assert where(entries[-2:]) == [("too-many-documents", 10001, 1, 10000), ("too-many-errors", None, None, None)]
    assert [e.message for e in entries[-2:]] == [
        "more than 10000 documents; the rest of the file is not read",
        "9900 more problems in this file not reported (only the first 100 are)",
    ]


def test_good_documents_past_the_error_limit_still_load(loader):
    entries = read("---\n" * 5 + CONTACTS + "---\n- 1\n", name="g.yaml", reading=replace(loader, max_errors=3))
    assert where(entries[:3]) == [("empty-document", k + 1, 1, k - 1) for k in (1, 2, 3)]
    assert (entries[3].name, entries[3].document) == ("g#5", 4)
    assert entries[4].message == "2 more problems in this file not reported (only the first 3 are)"
    assert len(entries) == 5


def test_the_document_limit_keeps_the_documents_before_it(loader):
    text = CONTACTS + "---\n" + CONTACTS + "---\n" + CONTACTS
    first, second, stop = read(text, name="g.yaml", reading=replace(loader, max_documents=2))
    assert (first.name, second.name) == ("g#1", "g#2")
    assert (stop.code, stop.line, stop.document) == ("too-many-documents", 16, 2)


def test_a_document_reports_its_first_problems_in_file_order_and_counts_the_rest(loader):
    # 150 bad twists early in the file, found after 150 bad contacts later in it
    twists = "".join(f"  - angular: [{k}]\n" for k in range(150))
    contacts = "".join(f"  - {{point: [{k}], normal: [1, 0, 0]}}\n" for k in range(150))
    entries = read(f"twists:\n{twists}contacts:\n{contacts}", reading=loader)
    assert len(entries) == MAX_ERRORS + 1
    assert [(e.code, e.line, e.column) for e in entries[:-1]] == [("vector-length", 2 + k, 14) for k in range(100)]
    assert entries[0].message == "twists[0].angular: expected 3 numbers, got 1"
    # the 50 other twists, the contact count and the 150 contacts
    assert entries[-1].code == "too-many-errors"
    assert entries[-1].message == "201 more problems in this file not reported (only the first 100 are)"


def test_a_file_reports_its_first_problems_and_counts_the_rest(loader):
    text = "---\n".join(f"wrist: [{k}]\n" + CONTACTS for k in range(150))
    entries = read(text, reading=loader)
    assert [e.document for e in entries[:-1]] == list(range(100))
    assert entries[-1].message == "50 more problems in this file not reported (only the first 100 are)"


def test_default_names(loader):
    assert [e.name for e in read(CONTACTS, reading=loader)] == ["g"]
    assert [e.name for e in read(CONTACTS + "---\n" + CONTACTS, reading=loader)] == ["g#1", "g#2"]
    assert [e.name for e in read("name: g\n" + CONTACTS + "---\n" + CONTACTS, reading=loader)] == ["g", "g#2"]
    labels = lambda entries: [e.code if isinstance(e, InputError) else e.name for e in entries]  # noqa: E731
    assert labels(read(CONTACTS + "---\n[", reading=loader)) == ["g#1", "yaml-syntax"]
    assert labels(read("- 1\n---\n" + CONTACTS, reading=loader)) == ["not-a-mapping", "g#2"]
    # a file name's undecodable bytes (surrogate escapes) and controls are shown escaped
    assert [e.name for e in read(CONTACTS, name="d/a\x1bb \udcff.yaml", reading=loader)] == ["a\\x1bb \\xff"]


# --------------------------------------------------------------------------
# Multi-document streams.


def test_multi_document_keeps_good_documents_around_a_bad_one(loader):
    text = CONTACTS + "---\n" + CONTACTS.replace("[1, 0, 0]", "[1, 0]") + "---\nname: third\n" + CONTACTS
    first, second, third = read(text, name="hand.yaml", reading=loader)
    assert (first.name, first.document, first.line) == ("hand#1", 0, 1)
    assert (second.code, second.document, second.line) == ("vector-length", 1, 10)
    assert (third.name, third.document, third.line) == ("third", 2, 16)


def test_syntax_error_keeps_the_documents_before_it(loader):
    text = CONTACTS + "---\n" + CONTACTS + "---\nwrist: [0, 0\n---\n" + CONTACTS
    *good, error = read(text, name="hand.yaml", reading=loader)
    assert [g.name for g in good] == ["hand#1", "hand#2"]
    assert (error.code, error.document, error.line) == ("yaml-syntax", 2, 18)


def test_depth_is_checked_after_a_documents_first_problem(loader):
    # A nesting bomb after a document's first problem still stops the parse
    # at once, and is what is reported for the document it cuts.
    text = "bad: !!python/none 1\nx: " + "[" * 100000 + "\n---\n" + CONTACTS
    (error,) = read(text, reading=loader)  # its time: bench/loader.py
    assert (error.code, error.line, error.column) == ("too-deep", 2, 35)


# --------------------------------------------------------------------------
# Sources and the error type.


def test_sources(tmp_path, monkeypatch, loader):
    path = tmp_path / "pinch.yaml"
    path.write_text(CONTACTS)
    assert read_grasps(path, reading=loader)[0].file == str(path)
    assert read_grasps(str(path), reading=loader)[0].name == "pinch"
    assert read_grasps(path, file="shown.yaml", reading=loader)[0].file == "shown.yaml"
    assert read_grasps(CONTACTS.encode(), reading=loader)[0].file == "<string>"
    assert read_grasps(CONTACTS, file="x/typed.yaml", reading=loader)[0].name == "typed"
    monkeypatch.setattr(sys, "stdin", io.TextIOWrapper(io.BytesIO(CONTACTS.encode())))
    (grasp,) = read_grasps("-", reading=loader)
    assert (grasp.file, grasp.name) == ("<stdin>", "<stdin>")


def test_load_grasps_raises_the_first_error():
    assert len(load_grasps(CONTACTS + "---\n" + CONTACTS, file="a.yaml")) == 2
    with pytest.raises(InputError) as caught:
        load_grasps(CONTACTS + "---\nwrist: 1\n" + CONTACTS + "---\n- 1\n", file="a.yaml")
    assert str(caught.value) == "a.yaml:9:8: wrist: expected 3 numbers, got the number 1"


def test_error_is_one_line_and_pickles():
    error = InputError("vector-length", "contacts[2].normal: expected 3 numbers, got 2", "grasps/mug.yaml", 7, 13, 0)
    assert str(error) == "grasps/mug.yaml:7:13: contacts[2].normal: expected 3 numbers, got 2"
    assert str(InputError("read-error", "cannot read: x", "f.yaml")) == "f.yaml: cannot read: x"
    copy = pickle.loads(pickle.dumps(error))
    assert (copy.code, copy.message, copy.file, copy.line, copy.column, copy.document, str(copy)) == (
        error.code, error.message, error.file, error.line, error.column, error.document, str(error),
    )  # fmt: skip


# --------------------------------------------------------------------------
# Round trip: random valid grasps written by PyYAML load back exactly.

coordinate = st.floats(allow_nan=False, allow_infinity=False, min_value=-1e300, max_value=1e300)
vector = st.lists(coordinate, min_size=3, max_size=3)
label = st.text(st.characters(blacklist_categories=("Cc", "Cs", "Zl", "Zp")), min_size=1, max_size=12).filter(
    lambda s: s.strip()
)
twist_entry = st.one_of(
    st.fixed_dictionaries({"screw": st.lists(st.floats(-1e3, 1e3), min_size=6, max_size=6)}),
    st.fixed_dictionaries(
        {"angular": st.lists(st.floats(-1e3, 1e3), min_size=3, max_size=3)},
        optional={"linear": vector, "at": st.lists(st.floats(-1e3, 1e3), min_size=3, max_size=3)},
    ),
)
document = st.fixed_dictionaries(
    {
        "contacts": st.lists(
            st.fixed_dictionaries(
                {"point": vector, "normal": vector.filter(any)},
                optional={"name": label},
            ),
            min_size=3,
            max_size=3,
        ),
    },
    optional={"name": label, "units": label, "wrist": vector, "twists": st.lists(twist_entry, max_size=4)},
)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(document, min_size=1, max_size=3))
@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_pyyaml_dumped_grasps_load_back(documents):
    text = yaml.safe_dump_all(documents, allow_unicode=True)
    validator = jsonschema.Draft202012Validator(grasp_schema())
    for parser in LOADERS:
        entries = read(text, name="r.yaml", reading=Reading(parser=parser))
        assert [e.document for e in entries] == sorted(e.document for e in entries)
        by_document = [[e for e in entries if e.document == i] for i in range(len(documents))]
        assert sum(map(len, by_document)) == len(entries)
        for i, (doc, mine) in enumerate(zip(documents, by_document)):
            assert validator.is_valid(doc)
            default_names = [str(k + 1) for k in range(3)]
            names = tuple(c.get("name", d) for c, d in zip(doc["contacts"], default_names))
            if len(set(names)) < 3:  # an explicit name equal to another's default
                # each problem located, as a compiler reports (io/grasp/problems.py): one a repeated name
                repeated = sum(name in names[:k] for k, name in enumerate(names))
                assert [e.code for e in mine] == ["duplicate-name"] * repeated
                continue
            (grasp,) = mine
            assert isinstance(grasp, Grasp), str(grasp)
            assert grasp.name == doc.get("name", f"r#{i + 1}" if len(documents) > 1 else "r")
            assert grasp.units == doc.get("units")
            assert grasp.contact_names == names
            assert grasp.points.tolist() == [c["point"] for c in doc["contacts"]]
            given_normals = np.array([c["normal"] for c in doc["contacts"]])
            np.testing.assert_allclose(screws.norm(grasp.normals), 1, rtol=1e-14)
            scaled = given_normals / np.abs(given_normals).max(axis=1, keepdims=True)
            np.testing.assert_allclose(grasp.normals * screws.norm(scaled)[:, None], scaled, rtol=1e-14, atol=1e-15)
            if "wrist" in doc:
                assert grasp.wrist.tolist() == doc["wrist"]
            check_twists(doc.get("twists", []), grasp.twists)


def check_twists(entries, twists):
    assert len(twists) == len(entries)
    for k, (entry, twist) in enumerate(zip(entries, twists)):
        assert twist.name == str(k + 1)
        if "screw" in entry:
            assert twist.screw.tolist() == entry["screw"]
            continue
        omega = np.array(entry["angular"])
        at = np.array(entry.get("at", [0.0, 0.0, 0.0]))
        linear = np.array(entry.get("linear", [0.0, 0.0, 0.0]))
        if not np.isfinite(screws.twist_at(omega, linear, at)).all():
            continue  # cannot happen with these ranges; the overflow case has a fixture
        assert twist.screw[:3].tolist() == entry["angular"]
        # v at the origin gives back `linear` at `at`, to rounding.
        velocity = screws.field_at(twist.screw, at)
        scale = max(1.0, float(np.abs(linear).max()), float(np.abs(omega).max() * np.abs(at).max()))
        assert np.abs(velocity - linear).max() <= 1e-12 * scale


def test_libyaml_is_used_when_present():
    # The parser comparisons need libyaml; skip visibly rather than pass vacuously.
    if not yaml.__with_libyaml__:
        pytest.skip("PyYAML without libyaml: only the pure parser is tested")
    assert READING.parser is yaml.CSafeLoader
