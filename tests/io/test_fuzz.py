"""Fuzzing with hypothesis: grasp-like YAML documents with mutations, and raw
bytes, through the loader and through the command line on stdin.

What must hold whatever the input: the loader raises nothing but
InputError (and what it returns is sound), the command exits 0 or 1,
never shows a traceback or an internal error, writes parseable records with no
NaN in an ok one, and only one-line diagnostics.

The default run tries 100 to 200 inputs per property; the long run
(``python -m pytest -m slow tests/io/test_fuzz.py``) tries 10,000 each.
"""

import contextlib

import numpy as np
import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from grasptwist.io.grasp import Grasp, InputError, load_grasps, read_grasps
from hostile import assert_no_crash, jsonl, run, summary

# --------------------------------------------------------------------------
# Inputs.

EXTREME = [0, -0.0, 1, -1, 1e200, -1e200, 1e-300, 5e-324, 1.7976931348623157e308, 10**400, -(10**30), 2**63]
numbers = st.one_of(
    st.floats(-10, 10),
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(-(10**6), 10**6),
    st.sampled_from(EXTREME),
)
junk = st.recursive(
    st.one_of(numbers, st.text(max_size=12), st.booleans(), st.none()),
    lambda inner: st.one_of(st.lists(inner, max_size=4), st.dictionaries(st.text(max_size=8), inner, max_size=4)),
    max_leaves=12,
)


def vector(n):
    """Mostly ``n`` numbers; sometimes the wrong length, or junk."""
    return st.one_of(st.lists(numbers, min_size=n, max_size=n), st.lists(numbers, max_size=7), junk)


names = st.one_of(
    st.text(max_size=10), st.integers(), st.none(), st.sampled_from(["", "a\nb", "\x1b[2J", "1e3", "thumb"])
)
contact = st.fixed_dictionaries({"point": vector(3), "normal": vector(3)}, optional={"name": names})
twist = st.one_of(
    st.fixed_dictionaries({"screw": vector(6)}, optional={"name": names}),
    st.fixed_dictionaries({}, optional={"angular": vector(3), "linear": vector(3), "at": vector(3), "name": names}),
)
grasp = st.fixed_dictionaries(
    {"contacts": st.one_of(st.lists(contact, min_size=3, max_size=3), st.lists(contact, max_size=5))},
    optional={"name": names, "units": names, "wrist": vector(3), "twists": st.lists(twist, max_size=3)},
)

KEYS = [
    "contacts",
    "point",
    "normal",
    "wrist",
    "twists",
    "screw",
    "angular",
    "linear",
    "at",
    "name",
    "units",
    "nromal",
    "<<",
]


@st.composite
def mutated(draw, value):
    """``value`` with a few edits anywhere in it: a key dropped or renamed, a
    value replaced by junk, wrapped in extra lists, or duplicated."""
    for _ in range(draw(st.integers(0, 3))):
        value = _edit(draw, value)
    return value


def _edit(draw, value):
    if isinstance(value, dict) and value and draw(st.booleans()):
        key = draw(st.sampled_from(sorted(value, key=str)))
        action = draw(st.sampled_from(["drop", "rename", "recurse", "junk"]))
        value = dict(value)
        if action == "drop":
            del value[key]
        elif action == "rename":
            value[draw(st.sampled_from(KEYS))] = value.pop(key)
        elif action == "recurse":
            value[key] = _edit(draw, value[key])
        else:
            value[key] = draw(junk)
        return value
    if isinstance(value, list) and value and draw(st.booleans()):
        i = draw(st.integers(0, len(value) - 1))
        value = list(value)
        value[i] = _edit(draw, value[i])
        return value
    return draw(st.sampled_from([lambda v: [v], lambda v: [[[v]]], lambda v: [v, v], lambda v: draw(junk)]))(value)


# Text edits no dumper makes: tags, anchors and aliases, syntax, controls.
SPLICES = ["!!python/object/apply:os.system [ls] ", "!!python/name:os.system ", "&a ", "*a", "!local ", "!!set ",
           "<<: *a\n", "\t", "[", "}", ": ", "\n---\n", "\n...\n", "%YAML 1.1\n", '"\\e[2J"', "\x00", "\ufeff", "#"]  # fmt: skip


@st.composite
def yaml_documents(draw):
    """One or more mutated grasp documents as YAML bytes, sometimes with spliced text."""
    docs = draw(st.lists(grasp.flatmap(mutated), min_size=1, max_size=3))
    text = yaml.safe_dump_all(
        docs, default_flow_style=draw(st.sampled_from([False, True, None])), allow_unicode=draw(st.booleans())
    )
    for _ in range(draw(st.integers(0, 2))):
        at = draw(st.integers(0, len(text)))
        text = text[:at] + draw(st.sampled_from(SPLICES)) + text[at:]
    return text.encode("utf-8", "surrogatepass")


raw_bytes = st.one_of(st.binary(max_size=300), st.binary(max_size=40).map(lambda b: b"contacts:\n  - point: [" + b))

# --------------------------------------------------------------------------
# What must hold.


def check_loader(data):
    """Only InputError escapes; every result is sound; every error one line."""
    with contextlib.suppress(InputError):
        load_grasps(data, file="fuzz.yaml")
    entries = read_grasps(data, file="fuzz.yaml")
    # in file order: by document, and each document's problems by position
    errors = [e for e in entries if isinstance(e, InputError)]
    located = [(e.document, e.line, e.column) for e in errors if e.line is not None]
    assert located == sorted(located)
    assert [e.document for e in entries if e.document is not None] == sorted(
        e.document for e in entries if e.document is not None
    )
    for entry in entries:
        if isinstance(entry, InputError):
            assert "\n" not in str(entry) and "\r" not in str(entry) and str(entry).startswith("fuzz.yaml")
            continue
        assert isinstance(entry, Grasp)
        assert entry.points.shape == entry.normals.shape == (3, 3) and np.isfinite(entry.points).all()
        np.testing.assert_allclose(np.linalg.norm(entry.normals, axis=1), 1, rtol=1e-12)
        assert all(np.isfinite(t.screw).all() and t.screw.shape == (6,) for t in entry.twists)
        for name in (entry.name, *entry.contact_names, *(t.name for t in entry.twists)):
            assert name.strip() and name.isprintable(), repr(name)


def check_cli(data):
    """Exit 0 or 1, no crash, records that parse with no NaN in an ok one, one-line diagnostics."""
    # standard input is a stream: every failed document's line, not the first 20 (--warnings)
    result, _ = run("resolve", "-", "-f", "jsonl", "--warnings", "all", input=data)
    assert result.exception is None or isinstance(result.exception, SystemExit), repr(result.exception)
    assert_no_crash(result.stdout + result.stderr)
    assert result.exit_code in (0, 1), result.output
    records = jsonl(result.stdout)
    assert records and result.exit_code == (0 if all(r["ok"] for r in records) else 1)
    lines = result.stderr.splitlines()
    assert lines[-1] == summary(records)
    assert all(line.startswith("<stdin>") for line in lines[:-1]), lines


def fuzz(strategy, check, examples):
    """Run ``check`` on ``examples`` inputs drawn from ``strategy``."""

    @settings(max_examples=examples, deadline=None, database=None,
              suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large, HealthCheck.filter_too_much])  # fmt: skip
    @given(strategy)
    def property_(data):
        check(data)

    property_()


SHORT = {"loader": 30, "cli": 15}  # the default run's share; -m slow runs LONG
LONG = 10_000


@pytest.mark.parametrize("target, check", [("loader", check_loader), ("cli", check_cli)], ids=["loader", "cli"])
@pytest.mark.parametrize("inputs, strategy", [("yaml", yaml_documents()), ("bytes", raw_bytes)], ids=["yaml", "bytes"])
@pytest.mark.parametrize("length", ["short", pytest.param("long", marks=pytest.mark.slow)])
def test_fuzz(target, check, inputs, strategy, length):
    fuzz(strategy, check, SHORT[target] if length == "short" else LONG)


# over a second: docs/reference/development.md, Test time (a check of the fuzz's generator, for
# the long fuzz that -m slow runs; the default run's short fuzz asserts what the loader does)
@pytest.mark.slow
def test_the_generator_makes_valid_grasps_too():
    """The fuzz would prove little if every input were refused at once: unmutated
    documents with plain numbers must load (and some hostile ones must not)."""
    seen = {"grasp": 0, "error": 0}

    @settings(max_examples=25, deadline=None, database=None)
    @given(st.lists(st.fixed_dictionaries({"point": st.lists(st.floats(-5, 5), min_size=3, max_size=3),
                                           "normal": st.lists(st.floats(0.5, 5), min_size=3, max_size=3)}),
                    min_size=3, max_size=3))  # fmt: skip
    def plain(contacts):
        (entry,) = read_grasps(yaml.safe_dump({"contacts": contacts}).encode(), file="ok.yaml")
        assert isinstance(entry, Grasp), str(entry)
        seen["grasp"] += 1

    plain()

    @settings(max_examples=60, deadline=None, database=None)
    @given(yaml_documents())
    def hostile(data):
        seen["error"] += any(isinstance(e, InputError) for e in read_grasps(data, file="x.yaml"))

    hostile()
    assert seen["grasp"] == 25 and seen["error"] > 12
