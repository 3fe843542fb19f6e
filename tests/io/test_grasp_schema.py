"""The JSON Schema (io/grasp/grasp_schema.json) against the loader, the format's one definition.

Every bundled grasp file and every fixture of tests/invalid_grasps/ and
tests/corpus/ is read twice: by the loader, and as data (the loader's own
YAML reading, the YAML 1.2 core schema, so ``1e-9`` is a number for both)
checked against the JSON Schema.  Each document must get the same verdict
from both, except for the rules a JSON Schema cannot state, listed in
``NOT_IN_THE_SCHEMA`` (and in the schema's description): then the schema
accepts what the loader refuses, and only for that reason.  A document that
is not data (YAML syntax, aliases, tags, duplicate keys, too deep, not
UTF-8: refused before any value is looked at) must be refused by the loader.
"""

from functools import cache

import jsonschema
import pytest
import yaml

from grasptwist.io import grasp
from grasptwist.io.grasp import DEFAULT_MAX_BYTES, InputError, grasp_schema, read_grasps
from grasptwist.io.grasp.compose import PARSER, compose
from grasptwist.io.grasp.problems import Problems, Reject, StreamStop
from grasptwist.io.grasp.text import file_text
from places import TESTS

FILES = sorted(
    [*(TESTS.parent / "grasps").glob("*.yaml"), *(TESTS / "invalid_grasps").glob("*.yaml")]
    + [*(TESTS / "corpus").glob("*.yaml")]
)

#: Loader codes for rules no JSON Schema states, and why.
NOT_IN_THE_SCHEMA = {
    "non-finite": "JSON has no NaN or infinity, and a schema cannot bound linear + angular x (origin - at)",
    "duplicate-name": "a name unique over the items of a list (JSON Schema's uniqueItems compares whole items)",
    # the hand's URDF is another file: what it holds is not in the grasp document
    "unknown-joint": "a joint_positions key that is no joint of the URDF",
    "contact-off-finger": "a contact farther from its URDF tip link than the finger is long",
    "unreachable": "a contact no joint positions of its URDF finger reach (inverse kinematics)",
    "outside-limits": "a contact its URDF finger reaches only outside its joint limits (inverse kinematics)",
    # the object's geometry, and its mesh, another file
    "contact-off-surface": "a contact farther from the object's surface than the tolerance",
    "outward-normal": "a given normal pointing out of the object",
    "path-outside": "a mesh path that leaves the grasp file's folder",
    "object-below-table": "an object whose lowest point is below its environment's table",
}

NOT_DATA = object()


def _data(node):
    """The plain value of a composed node."""
    if node.kind == "mapping":
        return {key: _data(value) for key, (_, value) in node.value.items()}
    if node.kind == "sequence":
        return [_data(item) for item in node.value]
    return node.value


def documents(path):
    """Each document of the file as data, as the loader's composer reads it (``NOT_DATA``
    where it refuses the YAML itself); None when the file is not text."""
    try:
        text = file_text(path, False, DEFAULT_MAX_BYTES)
    except Reject:
        return None
    out = []
    parser = PARSER(text)
    try:
        parser.get_event()  # StreamStartEvent
        while not parser.check_event(yaml.StreamEndEvent):
            parser.get_event()  # DocumentStartEvent
            problems = Problems(0)
            root = compose(parser.get_event, problems)
            out.append(NOT_DATA if problems.count else _data(root))
    except (yaml.YAMLError, StreamStop):
        out.append(NOT_DATA)
    finally:
        parser.dispose()
    return out


@pytest.fixture(scope="module")
def validator():
    return jsonschema.Draft202012Validator(grasp_schema())


@cache
def loader_codes(path):
    """``{document (None: the whole file): the codes of its problems}`` of the loader's reading."""
    codes = {}
    for entry in read_grasps(path):
        if isinstance(entry, InputError):
            codes.setdefault(entry.document, set()).add(entry.code)
    return codes


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_the_files_cover_valid_invalid_and_unstated_rules():
    refused = [bool(loader_codes(path)) for path in FILES]
    assert refused.count(False) >= 15  # the bundled grasps and the corpus's engine cases
    assert refused.count(True) >= 60
    assert set().union(*(c for path in FILES for c in loader_codes(path).values())) >= {"non-finite", "duplicate-name"}


@pytest.mark.parametrize(
    "path",
    # the 10,000-contact file takes seconds: the long run's
    [pytest.param(p, marks=pytest.mark.slow) if p.stem == "many-contacts" else p for p in FILES],
    ids=lambda p: f"{p.parent.name}/{p.stem}",
)
def test_the_schema_and_the_loader_give_each_document_the_same_verdict(path, validator):
    codes = loader_codes(path)
    docs = documents(path)
    if docs is None or not docs:  # not text, or no document: the loader refuses the file
        assert None in codes, codes
        return
    for document, data in enumerate(docs):
        found = codes.get(document, set())
        if data is NOT_DATA:
            assert found, f"document {document}: the loader takes what is not data"
            continue
        stated = found - set(NOT_IN_THE_SCHEMA)
        if validator.is_valid(data) != (not stated):
            errors = [f"{e.json_path}: {e.message}" for e in validator.iter_errors(data)][:5]
            pytest.fail(f"document {document}: loader {sorted(found)}, schema {errors}")


def test_the_schema_names_the_loaders_keys_in_its_order():
    schema = grasp_schema()
    jsonschema.Draft202012Validator.check_schema(schema)
    assert tuple(schema["properties"]) == grasp.GRASP_KEYS
    assert ("name", "units", "wrist", *(key for section in grasp.SECTIONS for key in section.keys)) == grasp.GRASP_KEYS
    assert schema["required"] == [key for section in grasp.SECTIONS for key in section.required] == ["contacts"]
    keys = {name: tuple(d.get("properties", ())) for name, d in schema["$defs"].items()}
    assert (keys["contact"], keys["twist"]) == (grasp.CONTACT_KEYS, grasp.TWIST_KEYS)
    assert (keys["path"], keys["segment"], keys["pose"]) == (grasp.PATH_KEYS, grasp.SEGMENT_KEYS, grasp.POSE_KEYS)
    hand = [tuple(form["properties"]) for form in schema["$defs"]["hand"]["oneOf"]]
    assert sorted(set().union(*hand)) == sorted(grasp.hand.HAND_KEYS)
    assert keys["joint"] == grasp.hand.JOINT_KEYS


def test_what_the_schema_cannot_state_is_in_its_description():
    description = grasp_schema()["description"]
    for words in ("unique contact and twist names", "finite numbers", "within the surface tolerance"):
        assert words in description


def test_the_schema_takes_soft_contacts_as_the_loader_does(validator):
    """A contact's model: soft needs its torsion, and a torsion needs model: soft (issue 39).  (The module's
    validator: jsonschema.validate checks the schema against its metaschema at each call, 0.04 s each;
    test_the_schema_names_the_loaders_keys_in_its_order checks it once.)"""
    rest = [{"point": [0.05, 0, 0], "normal": [-1, 0, 0]}, {"point": [0, 0, 0], "normal": [0, 0, 1]}]
    soft = {"point": [-0.05, 0, 0], "normal": [1, 0, 0], "model": "soft", "torsion": 0.01}
    validator.validate({"friction": 0.5, "contacts": [soft, *rest]})
    for bad in (
        {"model": "soft"},
        {"torsion": 0.01},
        {"model": "point", "torsion": 0.01},
        {"model": "soft", "torsion": 0},
    ):
        contact = {"point": [-0.05, 0, 0], "normal": [1, 0, 0], **bad}
        with pytest.raises(jsonschema.ValidationError):
            validator.validate({"friction": 0.5, "contacts": [contact, *rest]})
