"""The one table of codes (``grasptwist.codes``) against what the package writes and what the docs say.

Numbers, codes and exit statuses are a contract: the first test pins them, so a change to any is
a failing test rather than a silent change in users' records and scripts."""

import re
from pathlib import Path

import pytest

import grasptwist as gt
from code_tables import PAGE, index, written
from grasptwist import codes
from grasptwist.codes import ERRORS, EXIT, NO_GRASP_CONSTRAINTS, STATUSES, WARNINGS
from places import ROOT

SRC = ROOT / "src" / "grasptwist"
DOCS = ROOT / "docs"

#: The contract, written out: the number of each status, the exit status of each error.
PINNED_STATUSES = {
    "ok": 0,
    "nonfinite-input": 1,
    "coincident-contacts": 2,
    "collinear-contacts": 3,
    "wrist-coplanar": 4,
    "zero-normal": 5,
    "normals-rank-deficient": 6,
    "theta-not-unique": 7,
    "theta-sigma-zero": 8,
    "overflow": 9,
    "nonfinite-result": 9,
    "normal-in-contact-plane": 10,
    "finger-cannot-follow": 11,
    "no-wrist": 12,
    "contact-off-finger": 13,
    "unreachable": 14,
    "outside-limits": 15,
    "nonfinite-pose": 16,
    "cannot-hold": 20,
    "no-closure": 21,
    "mixed-frictionless": 22,
}
PINNED_EXITS = {"ok": 0, "failed": 1, "usage": 2, "write": 3, "worker": 4, "broken_pipe": 141, "signal": 128}
#: Every error code; all exit 1 but the one that stops ``-o`` being written.
PINNED_ERRORS = """
    alias bad-dataset bad-scalar conflicting-keys contact-count contact-inside-object contact-off-finger
    contact-off-surface control-character duplicate-key duplicate-name empty-document empty-mesh empty-path
    finger-count fixed-finger forbidden-dtd forbidden-tag internal-error invalid-clearance invalid-contact-model
    invalid-density invalid-duration invalid-frame invalid-friction invalid-key invalid-limit invalid-mass
    invalid-mesh invalid-name invalid-object invalid-pose invalid-radius invalid-rotation invalid-scale
    invalid-size invalid-torsion invalid-urdf invalid-utf8 mesh-not-solid mesh-unavailable missing-key
    no-friction no-grasp no-grasp-files no-mass no-object no-path no-tip-points no-twist no-weight non-finite
    not-a-list not-a-mapping not-a-number not-a-string nothing-to-hold object-below-table outside-limits
    output-is-input outward-normal package-not-found path-outside read-error scene-error shared-joint
    simulation-unstable tolerance-too-large too-deep too-large too-many-documents too-many-errors
    too-many-samples too-many-triangles too-many-vertices unknown-joint unknown-key unknown-link
    unknown-twist unknown-units unreachable unsearchable-hand unsupported-joint unsupported-mesh
    unsupported-url urdf-syntax urdf-unavailable vector-length yaml-syntax zero-axis zero-normal
""".split()  # noqa: SIM905 (a paragraph of codes reads as one)


def test_the_numbers_codes_and_exit_statuses_are_the_contract():
    assert {s.code: s.number for s in STATUSES} == PINNED_STATUSES
    assert {name.lower(): getattr(codes, f"EXIT_{name.upper()}") for name in PINNED_EXITS} == PINNED_EXITS
    assert sorted(ERRORS) == sorted(PINNED_ERRORS)
    assert {code for code, c in ERRORS.items() if c.exit != codes.EXIT_FAILED} == {"output-is-input"}
    assert ERRORS["output-is-input"].exit == codes.EXIT_USAGE == 2
    assert sorted(EXIT) == [0, 1, 2, 3, 4, 141]


@pytest.mark.parametrize(("engine", "enum"), [("twist", gt.Status), ("force", gt.forces.Status)])
def test_each_engine_s_statuses_are_the_table_s(engine, enum):
    mine = [s for s in STATUSES if getattr(s, engine) is not None]
    assert [(member.value, member.code) for member in enum] == [(s.number, s.code) for s in mine]
    assert len({s.number for s in mine}) == len(mine)  # a number is one status of an engine
    for s in mine:  # every sentence is the table's, filled in
        said = (gt.status_message if engine == "twist" else gt.forces.status_message)(s.number, 0)
        first = getattr(s, engine) if isinstance(getattr(s, engine), str) else getattr(s, engine)[0]
        assert said == first.format(i="1", j="2", k="3", n=1)


def test_a_number_names_one_condition_in_every_engine():
    by_number = {}
    for s in STATUSES:
        by_number.setdefault(s.number, set()).add(s.code)
    # 9 alone has two names: an overflow, said by each engine as it was first written
    assert {n: c for n, c in by_number.items() if len(c) > 1} == {9: {"overflow", "nonfinite-result"}}
    assert [s.number for s in STATUSES] == sorted(s.number for s in STATUSES)


def test_the_force_engine_s_pairs_are_said_with_and_without_a_culprit():
    assert gt.forces.status_message(20, -1).endswith(
        "needs a finger to pull (no pushing forces make it, whatever the friction)"
    )
    assert gt.forces.status_message(21, -1).endswith(": no internal force pushes at all three contacts")
    assert "contact east" in gt.forces.status_message(21, 1, ("north", "east", "south"))


# --- every code written in the package is in the table, every code in the table is written ---

#: A string literal that is a kebab-case word (``"no-twist"``, ``'too-large'``), or a one-word one, or
#: the start of one that says a code first (``f"outward-normals: ..."``); read off the modules' text,
#: 30 times quicker than their syntax trees.
LITERAL = re.compile(r"""["']([a-z][a-z0-9]*(?:-[a-z0-9]+)*)(?:["']|: )""")
#: Kebab-case words that are no code: a method, the output orders, an encoding, the command line's path,
#: a 3D page's HTML names (and a picture's parts: ``plot.scene.KINDS``).
NOT_CODES = {"off-tangent", "omega-v", "v-omega", "utf-8", "command-line", "grasptwist-figure", "figure-0-json"}


def _literals(path: Path):
    """The code-like string literals of a module: kebab-case words, and one-word codes (``alias``)."""
    return [w for w in LITERAL.findall(path.read_text("utf-8")) if "-" in w or w in ERRORS]


@pytest.fixture(scope="module")
def written_in_src():
    """Each kebab-case word of the package's modules but the table's own, with the modules that write it."""
    from grasptwist.plot.scene import KINDS

    found = {}
    for path in sorted(SRC.rglob("*.py")):
        if path.name != "codes.py" or path.parent != SRC:
            for word in _literals(path):
                found.setdefault(word, set()).add(str(path.relative_to(SRC)))
    return {word: where for word, where in found.items() if word not in NOT_CODES | set(KINDS)}


def test_every_code_a_module_writes_is_in_the_table(written_in_src):
    known = set(ERRORS) | set(WARNINGS) | {s.code for s in STATUSES}
    assert {word: sorted(where) for word, where in written_in_src.items() if word not in known} == {}


def test_every_error_and_warning_of_the_table_is_written_by_a_module(written_in_src):
    # (statuses are the engines' enums', built from the table: a hand placed on its contacts gives
    # its ``unreachable`` as an error by its status's code)
    assert sorted(set(ERRORS) - set(written_in_src) - {s.code for s in STATUSES}) == []
    assert sorted(set(WARNINGS) - set(written_in_src)) == []


def test_a_search_s_constraints_are_the_table_s():
    from grasptwist.engine.synthesis.clearance import ClearTriples
    from grasptwist.engine.synthesis.scores import CONSTRAINTS

    diagnosis = (SRC / "engine" / "synthesis" / "diagnosis.py").read_text("utf-8")
    failures = set(re.findall(r'Failure\(\s*"(\w+)"', diagnosis))  # those the search names itself
    assert set(NO_GRASP_CONSTRAINTS) == {*CONSTRAINTS, ClearTriples.name, *failures}
    assert failures == {"budget", "verification"}


def test_one_name_for_the_error_of_every_input():
    said = [str(path.relative_to(SRC)) for path in SRC.rglob("*.py") if "GraspFileError" in path.read_text("utf-8")]
    # the deprecated alias (_moved.py), the 0.1 path's, and the class's own word of its old name
    assert sorted(said) == ["_moved.py", "io/grasp_file.py", "model/__init__.py"]
    with pytest.warns(
        DeprecationWarning, match=r"GraspFileError is deprecated since 0\.6: use grasptwist\.InputError$"
    ):
        assert gt.GraspFileError is gt.InputError
    assert "InputError" in gt.__all__ and "GraspFileError" not in gt.__all__


# --- the docs -------------------------------------------------------------------------------


def _backticked(page: str) -> set:
    return set(re.findall(r"`([a-z_][a-z0-9_]*(?:-[a-z0-9]+)*)`", (DOCS / page).read_text("utf-8")))


def test_the_index_of_every_code_is_generated_from_the_table():
    assert written(PAGE.read_text("utf-8")) == index(), "run: python tests/code_tables.py --update"


@pytest.mark.parametrize("table", ["ERRORS", "WARNINGS"])
def test_each_code_is_explained_on_its_pages(table):
    missing = [
        f"{page}: {code}"
        for code, c in getattr(codes, table).items()
        for page in c.pages
        if code not in _backticked(page)
    ]
    assert missing == []


def test_each_engine_s_statuses_are_explained_on_its_page():
    # a hand's statuses (a finger that cannot follow, reach or stay within its limits) are the hands page's
    pages = {"twist": ("reference/conventions.md", "guide/hands.md"), "force": ("guide/forces.md",)}
    for engine, where in pages.items():
        said = set().union(*map(_backticked, where))
        assert [s.code for s in STATUSES if getattr(s, engine) is not None and s.code not in said] == [], where


def _code_tables():
    """``(page, first column's codes)`` of each Markdown table whose first header cell is a code's or
    a warning's: the tables of codes the docs write by hand."""
    for path in sorted(DOCS.rglob("*.md")):
        lines = path.read_text("utf-8").splitlines()
        for i, line in enumerate(lines):
            head = re.match(r"^\| `?(code|warning|Warning)`? \|", line)
            if head and i + 1 < len(lines) and lines[i + 1].startswith("|---"):
                rows = []
                for row in lines[i + 2 :]:
                    if not row.startswith("|"):
                        break
                    rows += re.findall(r"`([^`]+)`", row.split("|")[1])
                yield str(path.relative_to(DOCS)), head.group(1).lower(), rows


def test_every_code_a_table_of_the_docs_lists_is_in_the_table():
    statuses = {s.code for s in STATUSES}
    tables = list(_code_tables())
    assert len(tables) >= 10  # grasp files, hands, objects, conventions, the search's, the simulation's, ...
    unknown = [
        f"{page}: {code}"
        for page, kind, rows in tables
        for code in rows
        if code not in (WARNINGS if kind == "warning" else {**ERRORS, **dict.fromkeys(statuses)})
    ]
    assert unknown == []


def test_the_exit_statuses_the_command_line_page_lists_are_the_table_s():
    text = (DOCS / "guide" / "command-line.md").read_text("utf-8")
    section = text[text.index("## Exit codes and diagnostics") :]
    numbers = re.findall(r"^\| (\d+) \|", section, re.M)
    assert sorted(map(int, numbers)) == sorted(EXIT)
    assert "128 + the signal's number" in section


def test_a_status_s_number_in_the_docs_is_the_table_s():
    numbers = {s.code: s.number for s in STATUSES}
    said = [
        (str(path.relative_to(DOCS)), code, int(n))
        for path in sorted(DOCS.rglob("*.md"))
        for code, n in re.findall(r"`([a-z]+(?:-[a-z]+)*)` (?:is )?(\d+)\b", path.read_text("utf-8"))
        if code in numbers
    ]
    assert len(said) >= 10  # forces.md's list of statuses, the output contract's
    assert [(page, code, n) for page, code, n in said if numbers[code] != n] == []
