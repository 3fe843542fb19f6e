"""The hostile-input corpus (tests/corpus/): each file alone, and all of them in one
folder with good files, links, a cycle and unreadable entries.

What a file must give is pinned in ``tests/corpus/expected.tsv``; the two big
inputs (20,000 nesting levels, a file far above the size cap) are generated
here into a temporary folder instead of being committed.  That no YAML tag
ever runs code is proven, with a control that does run it, by
``test_grasp_file.py::test_python_tags_never_run``; here the corpus's tag files
go through the installed command too, and create nothing.
"""

import os
import shutil
import socket
from dataclasses import dataclass

import pytest

from hostile import (
    assert_no_crash,
    error_codes,
    error_lines,
    jsonl,
    run,
    run_installed,
    run_measured,
    summary,
)
from places import GRASPS, TESTS

CORPUS = TESTS / "corpus"
TABLE = CORPUS / "expected.tsv"
BUNDLED = GRASPS


@dataclass(frozen=True)
class Expected:
    """One row of expected.tsv."""

    file: str
    exit: int
    code: str | None
    where: str | None  # "line:column"
    records: int
    ok: int
    category: str
    fragment: str | None


def _table():
    rows = []
    lines = [line for line in TABLE.read_text("utf-8").splitlines() if line and not line.startswith("#")]
    header = lines[0].split("\t")
    for line in lines[1:]:
        f = dict(zip(header, line.split("\t"), strict=True))
        total, ok = map(int, f["records"].split("/"))
        dash = lambda v: None if v == "-" else v  # noqa: E731
        rows.append(
            Expected(
                f["file"],
                int(f["exit"]),
                dash(f["code"]),
                dash(f["where"]),
                total,
                ok,
                f["category"],
                dash(f["fragment"]),
            )
        )
    return rows


ROWS = _table()
BY_NAME = {row.file: row for row in ROWS}


def _deep(path):
    """20,000 nested flow lists (40 kB): libyaml's own composer would crash on far fewer."""
    path.write_text("[" * 20000 + "]" * 20000 + "\n")


def _far_above_cap(path):
    """A good grasp followed by a 1 GiB hole: sparse, so it costs no disk, and only
    one byte past the 1 MiB cap may be read."""
    path.write_bytes((CORPUS / "zero-twist.yaml").read_bytes())
    with open(path, "r+b") as handle:
        handle.truncate(1 << 30)


GENERATED = {"deep-20000.yaml": _deep, "far-above-cap.yaml": _far_above_cap}


def materialise(name, folder):
    """The corpus file ``name`` inside ``folder`` (copied, or generated)."""
    target = folder / name
    if name in GENERATED:
        GENERATED[name](target)
    else:
        shutil.copyfile(CORPUS / name, target)
    return target


@pytest.fixture
def corpus_file(request, tmp_path):
    return materialise(request.param, tmp_path)


# --------------------------------------------------------------------------
# The table itself.


def test_the_table_lists_every_corpus_file_and_the_issue_s_cases():
    committed = {p.name for p in CORPUS.iterdir() if p.is_file() and p.name != TABLE.name}  # urdf/: test_urdf.py
    assert committed == set(BY_NAME) - set(GENERATED), "expected.tsv and tests/corpus/ disagree"
    assert len(ROWS) == len(BY_NAME) >= 40
    # The cases issue 5 names, each by the file that covers it.
    required = [
        "empty.yaml", "comments-only.yaml", "not-yaml.yaml", "top-level-list.yaml", "top-level-scalar.yaml",
        "binary.png.yaml", "latin1.yaml", "tab-indent.yaml", "missing-contacts.yaml", "misspelled-key.yaml",
        "duplicate-key.yaml", "two-contacts.yaml", "four-contacts.yaml", "vector-length-2.yaml", "vector-length-4.yaml",
        "string-number.yaml", "boolean-number.yaml", "null-number.yaml", "nan.yaml", "infinity.yaml",
        "negative-infinity.yaml", "overflow-product.yaml", "zero-normal.yaml", "identical-points.yaml",
        "collinear-contacts.yaml", "wrist-coplanar.yaml", "normals-rank-deficient.yaml", "theta-not-unique.yaml",
        "theta-sigma-zero.yaml", "zero-twist.yaml", "python-tag-top.yaml", "python-tag-nested.yaml",
        "alias-bomb.yaml", "deep-20000.yaml", "far-above-cap.yaml", "multi-document-one-bad.yaml",
    ]  # fmt: skip
    assert set(required) <= set(BY_NAME)
    # every tangent degeneracy the README lists ("Degenerate grasps") has its own file, with its own code
    assert {"normals-rank-deficient", "theta-not-unique", "theta-sigma-zero"} <= {r.code for r in ROWS}


# --------------------------------------------------------------------------
# Each file alone.


def _check_alone(row, path, exit_code, stdout, stderr):
    """Everything a hostile file alone must give, whichever way the command was run."""
    assert_no_crash(stdout + stderr)
    assert exit_code == row.exit, stderr
    records = jsonl(stdout)
    assert (len(records), sum(r["ok"] for r in records)) == (row.records, row.ok)
    assert all(r["file"] == str(path) for r in records)
    errors = error_lines(stderr)
    lines = stderr.splitlines()
    if row.code is None:
        assert errors == [] and lines[-1] == summary(records)
        return
    # the errors, one line each (a document's problems in one record, a grasp's one per failed method),
    # a line per warning of a record (a method skipped for want of a wrist), then the summary
    failed = [r for r in records if not r["ok"]]
    warned = sum(len(r.get("warnings", ())) for r in records)
    assert len(errors) == sum(len(error_codes(r)) for r in failed) and len(lines) == len(errors) + warned + 1, stderr
    assert lines[-1] == summary(records)
    assert all(line.startswith(f"{path}:") for line in errors), errors
    prefix = f"{path}:{row.where}: error: {row.code}: " if row.where else f"{path}: "
    assert any(line.startswith(prefix) and f"{row.code}: " in line and row.fragment in line for line in errors), errors
    assert any(row.code in error_codes(r) for r in failed)
    located = [(r["error"]["line"], r["error"]["column"]) for r in failed if "error" in r]
    assert located == sorted(located, key=lambda at: (at[0] or 0, at[1] or 0))  # in file order
    if row.where and located[0][0] is not None:  # the record locates the error as stderr does
        assert tuple(map(int, row.where.split(":"))) in located


@pytest.mark.parametrize(
    "corpus_file, row",
    # the 10,000-contact file takes seconds: the long run's
    [
        pytest.param(r.file, r, id=r.file, marks=[pytest.mark.slow] if r.file == "many-contacts.yaml" else [])
        for r in ROWS
    ],
    indirect=["corpus_file"],
)
def test_each_hostile_file_alone(corpus_file, row):
    result, _ = run("resolve", corpus_file, "-f", "jsonl")
    assert result.exception is None or isinstance(result.exception, SystemExit), repr(result.exception)
    assert result.python_warnings == []
    _check_alone(row, corpus_file, result.exit_code, result.stdout, result.stderr)


# Through the installed script: the big and the malicious, where the process
# (not CliRunner) must stay bounded in time and memory.
INSTALLED = ["alias-bomb.yaml", "deep-20000.yaml", "far-above-cap.yaml", "binary.png.yaml", "python-tag-top.yaml",
             "python-tag-nested.yaml", "integer-5000-digits.yaml", "multi-document-one-bad.yaml", "terminal-escape-name.yaml"]  # fmt: skip


@pytest.mark.parametrize("corpus_file", INSTALLED, indirect=True)
@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_hostile_files_through_the_installed_command(corpus_file, tmp_path):
    row = BY_NAME[corpus_file.name]
    proc, _ = run_installed("resolve", corpus_file, "-f", "jsonl", cwd=tmp_path)
    # a generous bound: it includes the interpreter's start
    _check_alone(row, corpus_file, proc.returncode, proc.stdout, proc.stderr)
    assert not (tmp_path / "grasptwist-pwned").exists()  # the tags' `touch grasptwist-pwned` never ran
    assert "\x1b" not in proc.stdout + proc.stderr  # no terminal control from a file reaches the terminal


def test_overflow_prints_no_python_warning(tmp_path):
    path = materialise("overflow-product.yaml", tmp_path)
    proc, _ = run_installed("resolve", path, "-f", "jsonl")
    assert "Warning" not in proc.stderr, proc.stderr


def test_the_zero_twist_resolves_to_exact_zeros(tmp_path):
    result, _ = run("resolve", materialise("zero-twist.yaml", tmp_path), "-f", "jsonl")
    [rec] = jsonl(result.stdout)
    amplitudes = rec["off_tangent"]["x"] + rec["off_tangent"]["y"] + rec["tangent"]["alpha"] + rec["tangent"]["beta"]
    assert amplitudes == [0.0] * 12 and rec["warnings"] == []


# --------------------------------------------------------------------------
# Everything in one folder.


def _mixed_folder(root):
    """The whole corpus with good files around it; returns (folder, readable-as-root)."""
    mixed = root / "mixed"
    good = mixed / "good"
    good.mkdir(parents=True)
    for row in ROWS:
        materialise(row.file, mixed)
    for path in BUNDLED.glob("*.yaml"):
        shutil.copyfile(path, good / path.name)
    shutil.copyfile(BUNDLED / "box-edge.yaml", mixed / "box-edge.yaml")
    outside = root / "outside"
    outside.mkdir()
    shutil.copyfile(BUNDLED / "handle.yaml", outside / "handle.yml")
    (mixed / "link-to-good.yaml").symlink_to(good / "sphere.yaml")  # a file link
    (mixed / "link-to-outside").symlink_to(outside, target_is_directory=True)  # a folder link
    (good / "loop").symlink_to(mixed, target_is_directory=True)  # a cycle
    (mixed / "dangling.yaml").symlink_to(root / "nowhere.yaml")  # a link to nothing: unreadable
    locked = mixed / "locked.yaml"
    shutil.copyfile(BUNDLED / "cylinder.yaml", locked)
    locked.chmod(0)
    (mixed / "notes.txt").write_text("not a grasp file, not read\n")
    return mixed, os.access(locked, os.R_OK)


@pytest.fixture
def mixed(tmp_path):
    folder, root_reads = _mixed_folder(tmp_path)
    yield folder, root_reads
    (folder / "locked.yaml").chmod(0o644)


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_a_mixed_folder_gives_each_file_exactly_what_it_gives_alone(mixed):
    folder, root_reads = mixed
    result, _ = run("resolve", folder, "-f", "jsonl")
    assert_no_crash(result.stdout + result.stderr)
    assert result.exit_code == 1
    records = jsonl(result.stdout)

    # Which files, in which order: sorted by path, each once, the cycle cut, the folder link read.
    read = list(dict.fromkeys(r["file"] for r in records))
    good = sorted(p.name for p in BUNDLED.glob("*.yaml"))
    expected = sorted(
        [row.file for row in ROWS] + ["box-edge.yaml", "dangling.yaml", "link-to-good.yaml", "locked.yaml"]
        + [f"good/{name}" for name in good] + ["link-to-outside/handle.yml"],
        key=lambda rel: rel.split("/"),
    )  # fmt: skip
    assert read == [str(folder / rel) for rel in expected]

    # Every file's records, and its error lines, are exactly those it gives alone.
    errors = error_lines(result.stderr)
    total = failed = lines = 0
    for path in read:
        alone, _ = run("resolve", path, "-f", "jsonl")
        mine = [r for r in records if r["file"] == path]
        assert mine == jsonl(alone.stdout), path
        theirs = error_lines(alone.stderr)
        assert [line for line in errors if line.startswith(path + ":")] == theirs, path
        total, failed, lines = total + len(mine), failed + sum(not r["ok"] for r in mine), lines + len(theirs)
    assert len(errors) == lines  # no error line that is not some file's own
    assert result.stderr.splitlines()[-1] == summary(records)

    # One error record and at least one error line per bad input; the good ones all ok.
    by_file = {path: [r for r in records if r["file"] == path] for path in read}
    for row in ROWS:
        recs = by_file[str(folder / row.file)]
        assert (len(recs), sum(r["ok"] for r in recs)) == (row.records, row.ok), row.file
    assert by_file[str(folder / "dangling.yaml")][0]["error"]["code"] == "read-error"
    locked = by_file[str(folder / "locked.yaml")]
    if root_reads:
        # As root, mode 000 does not stop reading (the dangling link stands in): the file is then read.
        assert locked and not any("error" in r for r in locked)
    else:
        assert [r["error"]["code"] for r in locked] == ["read-error"]
    for name in good:
        assert by_file[str(folder / "good" / name)], name


def test_a_named_pipe_in_a_folder_does_not_hang_the_batch(tmp_path):
    shutil.copyfile(BUNDLED / "sphere.yaml", tmp_path / "sphere.yaml")
    os.mkfifo(tmp_path / "pipe.yaml")
    with socket.socket(socket.AF_UNIX) as sock:  # a socket file, for good measure
        sock.bind(str(tmp_path / "socket.yaml"))
        proc, _ = run_installed("resolve", tmp_path, "-f", "jsonl", timeout=4)
    records = jsonl(proc.stdout)
    assert [r["error"]["code"] for r in records if r["file"].endswith(("pipe.yaml", "socket.yaml"))] == [
        "read-error"
    ] * 2
    assert sum(r["file"].endswith("sphere.yaml") for r in records) == 5


def test_a_file_name_cannot_split_or_colour_its_error_line(tmp_path):
    # File names come from whoever filled the folder; the loader cannot vet them as it vets names inside.
    bad = tmp_path / "two\nlines \x1b[31mred.yaml"
    shutil.copyfile(CORPUS / "two-contacts.yaml", bad)
    result, _ = run("resolve", tmp_path, "-f", "jsonl")
    [rec] = jsonl(result.stdout)
    assert rec["file"] == str(bad)  # the data keeps the real name
    lines = result.stderr.splitlines()
    assert len(lines) == 2 and ": error: contact-count: " in lines[0], lines
    assert "\x1b" not in result.stderr


# --------------------------------------------------------------------------
# Memory: per-file limits keep a small hostile file small.


DASHES = b"---\n" * (1 << 18)  # 1 MiB: 262,144 empty documents


def _dashes_check(folder, files, limit_mb):
    code, stderr, peak = run_measured("resolve", folder, "-f", "jsonl", "-o", "out.jsonl", cwd=folder.parent)
    records = jsonl((folder.parent / "out.jsonl").read_text())
    # per file: 100 empty documents, one too-many-documents (at document 10,001) with the count of the 9,900 others
    assert len(records) == 101 * files and code == 1
    assert [e["code"] for e in records[-1]["errors"]] == ["too-many-documents", "too-many-errors"]
    assert stderr.splitlines()[-1] == summary(records)
    assert peak < limit_mb, f"{peak:.0f} MB"


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_a_mebibyte_of_document_markers_is_cut_short_in_little_memory(tmp_path):
    # 0.1: 262,144 records and 1.3 GB; now 101 records and ~40 MB (an interpreter's worth)
    (tmp_path / "in").mkdir()
    (tmp_path / "in" / "dashes.yaml").write_bytes(DASHES)
    _dashes_check(tmp_path / "in", 1, 150)
