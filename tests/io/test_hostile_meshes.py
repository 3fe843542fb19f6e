"""Hostile mesh files (tests/corpus/meshes/, issue 36): each alone, named by grasp files in a
folder, and given to synthesize; the caps, one per kind of input whichever way it arrives; and
memory, measured on a subprocess, for the big ones generated here (sparse where they can be).

What each committed file must give is pinned in ``tests/corpus/meshes/expected.tsv``, by kind:
numbers beyond what the format can mean (a face index past 64 bits, a count below none), headers
that declare what the body does not hold, words where numbers go, and paths that never resolve.
"""

import errno
import hashlib
import json
import os
import shutil
import warnings
from dataclasses import dataclass

import pytest

from grasptwist.io.limits import MAX_MESH_BYTES, MAX_TRIANGLES, MAX_VERTICES
from grasptwist.io.mesh_file import read_mesh
from grasptwist.model import InputError
from hostile import assert_no_crash, jsonl, run, run_measured, summary
from places import GRASPS, TESTS

MESHES = TESTS / "corpus" / "meshes"


@dataclass(frozen=True)
class Row:
    file: str
    code: str
    line: int | None
    fragment: str


def _table():
    lines = [x for x in (MESHES / "expected.tsv").read_text("utf-8").splitlines() if x and not x.startswith("#")]
    rows = [dict(zip(lines[0].split("\t"), x.split("\t"), strict=True)) for x in lines[1:]]
    return [Row(r["file"], r["code"], None if r["line"] == "-" else int(r["line"]), r["fragment"]) for r in rows]


ROWS = _table()

# Paths that never resolve: a link to itself and two links to each other (made here: git keeps
# links, but not every checkout makes them).
LOOPS = {"link-to-itself.obj": "link-to-itself.obj", "loop-a.obj": "loop-b.obj", "loop-b.obj": "loop-a.obj"}
LOOP = Row("-", "read-error", None, f"cannot read: {os.strerror(errno.ELOOP)}")

TETRA = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"
ON_MESH = """\
object: {{mesh: {mesh}}}
contacts:
  - {{point: [0.5, 0.5, -0.001]}}
  - {{point: [-0.01, 0.25, 0.25]}}
  - {{point: [0.25, 0, 0.25]}}
twists: [{{angular: [0, 0, 1]}}]
"""


def hostile_folder(folder):
    """Every corpus mesh and the loops in ``folder``; returns ``{name: Row}``."""
    folder.mkdir(parents=True, exist_ok=True)
    for row in ROWS:
        shutil.copyfile(MESHES / row.file, folder / row.file)
    for name, target in LOOPS.items():
        (folder / name).symlink_to(target)
    return {**{row.file: row for row in ROWS}, **dict.fromkeys(LOOPS, LOOP)}


def digests(folder):
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in folder.iterdir() if not p.is_symlink()}


def test_the_table_lists_every_mesh_of_the_corpus_and_each_kind():
    assert {p.name for p in MESHES.iterdir()} - {"expected.tsv"} == {row.file for row in ROWS}
    kinds = {row.file.split("-")[0] for row in ROWS}
    assert kinds == {"obj", "ply", "stl"}
    # the three: an index past 64 bits, a header count the body does not hold, in ASCII and binary
    assert {"obj-index-beyond-64-bits.obj", "ply-ascii-declares-2e9-vertices.ply"} <= {row.file for row in ROWS}


@pytest.mark.parametrize("row", ROWS, ids=[row.file for row in ROWS])
def test_each_hostile_mesh_alone_is_one_located_error(row):
    before = (MESHES / row.file).read_bytes()
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no numpy warning reaches a user's stderr either
        with pytest.raises(InputError) as caught:
            read_mesh(row.file, MESHES)
    e = caught.value
    assert (e.code, e.file, e.line) == (row.code, row.file, row.line), str(e)
    assert row.fragment in e.message and "\n" not in str(e)
    assert (MESHES / row.file).read_bytes() == before


def test_a_path_that_never_resolves_is_a_read_error(tmp_path):
    # issue 36: RuntimeError (Symlink loop), an internal error that lost the run's other records
    hostile_folder(tmp_path)
    for name in LOOPS:
        with pytest.raises(InputError, match=f"^{name}: {LOOP.fragment}$") as caught:
            read_mesh(name, tmp_path)
        assert caught.value.code == "read-error"


def test_meshes_named_by_grasp_files_in_a_folder_each_give_one_located_record(tmp_path):
    """Each grasp file naming a hostile mesh: one error record, located at its ``mesh`` key, the
    mesh's own words and line in its message; the bottle beside them keeps its records."""
    expected = hostile_folder(tmp_path / "in" / "meshes")
    for name in expected:
        (tmp_path / "in" / f"{name}.yaml").write_text(ON_MESH.format(mesh=f"meshes/{name}"))
    shutil.copyfile(GRASPS / "bottle.yaml", tmp_path / "in" / "bottle.yaml")
    shutil.copyfile(GRASPS / "meshes" / "bottle.obj", tmp_path / "in" / "meshes" / "bottle.obj")
    before = digests(tmp_path / "in" / "meshes")
    result, _ = run("resolve", tmp_path / "in", "-f", "jsonl")
    assert_no_crash(result.output)
    assert result.exit_code == 1 and result.python_warnings == []
    records = jsonl(result.stdout)
    failed = {os.path.basename(r["file"]).removesuffix(".yaml"): r for r in records if not r["ok"]}
    assert set(failed) == set(expected)
    for name, row in expected.items():
        error = failed[name]["error"]
        where = f"meshes/{name}" + (f":{row.line}" if row.line else "")
        assert (error["code"], error["line"], error["column"]) == (row.code, 1, 16), name  # at the mesh's name
        assert error["message"].startswith(f"object.mesh: {where}: ") and row.fragment in error["message"], error
    alone, _ = run("resolve", GRASPS / "bottle.yaml", "-f", "jsonl")
    bottle = [r for r in records if r["file"].endswith("bottle.yaml")]
    strip = lambda rs: [{k: v for k, v in r.items() if k != "file"} for r in rs]  # noqa: E731
    assert len(bottle) == 2 and strip(bottle) == strip(jsonl(alone.stdout))
    assert result.stderr.splitlines()[-1] == summary(records)
    assert digests(tmp_path / "in" / "meshes") == before


def test_synthesize_gives_each_hostile_mesh_of_a_folder_one_record(tmp_path):
    expected = hostile_folder(tmp_path / "in")
    result, _ = run("synthesize", tmp_path / "in", "--friction", "0.5", "--mass", "0.1", "-f", "jsonl")
    assert_no_crash(result.output)
    assert result.exit_code == 1
    records = jsonl(result.stdout)
    assert sorted(os.path.basename(r["file"]) for r in records) == sorted(expected)
    for r in records:
        row = expected[os.path.basename(r["file"])]
        assert (r["error"]["code"], r["error"]["line"]) == (row.code, row.line) and row.fragment in r["error"][
            "message"
        ]


# --------------------------------------------------------------------------
# One cap per kind of input (io/limits.py), whichever way the input arrives.


def over_the_caps(folder):
    """A mesh over each cap, named as a grasp file's object and given as a path: ``{file: (code, words)}``."""
    folder.mkdir(exist_ok=True)
    with open(folder / "sparse.obj", "wb") as f:  # past the byte cap: a hole, no disk
        f.truncate(MAX_MESH_BYTES + 1)
    (folder / "faces.obj").write_text(TETRA + "f 1 2 3\n" * (MAX_TRIANGLES - 3))  # 200,001 f lines
    (folder / "vertices.obj").write_text("v 0 0 0\n" * (MAX_VERTICES + 1) + TETRA)
    return {
        "sparse.obj": ("too-large", f"larger than the size limit of {MAX_MESH_BYTES} bytes"),
        "faces.obj": ("too-many-triangles", f"declares {MAX_TRIANGLES + 1:,} faces, more than the limit"),
        "vertices.obj": ("too-many-vertices", f"declares {MAX_VERTICES + 5:,} vertices, more than the limit"),
    }


def test_a_mesh_has_one_set_of_caps_whether_a_grasp_file_names_it_or_synthesize_reads_it(tmp_path):
    # issue 36: a grasp file's mesh got --max-bytes (1 MiB), synthesize's 64 MiB and no triangle cap
    caps = over_the_caps(tmp_path)
    for name in caps:
        (tmp_path / f"{name}.yaml").write_text(ON_MESH.format(mesh=name))
    named, _ = run("resolve", *[tmp_path / f"{name}.yaml" for name in caps], "-f", "jsonl")
    given, _ = run("synthesize", *[tmp_path / name for name in caps], "--friction", "0.5", "-f", "jsonl")
    for result in (named, given):
        assert_no_crash(result.output)
        assert result.exit_code == 1
    for by_file, said in zip(jsonl(named.stdout), jsonl(given.stdout)):
        code, words = caps[os.path.basename(said["file"])]
        assert by_file["error"]["code"] == said["error"]["code"] == code
        assert words in by_file["error"]["message"] and words in said["error"]["message"]


def test_a_mesh_over_a_mebibyte_is_read_with_the_default_max_bytes(tmp_path):
    # the grasp file's --max-bytes (1 MiB) no longer caps the mesh it names
    (tmp_path / "big.obj").write_text("#" * (3 << 20) + "\n" + TETRA)
    (tmp_path / "g.yaml").write_text(ON_MESH.format(mesh="big.obj"))
    result, _ = run("resolve", tmp_path / "g.yaml", "-f", "jsonl")
    assert result.exit_code == 0, result.output
    assert [r["ok"] for r in jsonl(result.stdout)] == [True]
    result, _ = run("resolve", tmp_path / "g.yaml", "-f", "jsonl", "--max-bytes", "100")
    assert jsonl(result.stdout)[0]["error"]["code"] == "too-large"  # the grasp file's own cap still holds


# --------------------------------------------------------------------------
# Memory: the big ones, generated; each within a few times the mesh cap.


def one_polygon(path, corners=4_000_000):
    """16 MB: one face of millions of corners (0.5: past 0.5 GB before it was killed)."""
    path.write_text(TETRA + "f " + " ".join(["1 2 3 4"] * (corners // 4)) + "\n")


def vertex_lines(path, indent=""):
    """60 MB of vertex lines (0.5: 2.1 GB and 72 s); indented, they escape the quick count."""
    line = f"{indent}v 0.123456 0.234567 0.345678\n"
    path.write_text(line * (60_000_000 // len(line)))


def wide_ascii_ply(path):
    """60 MB of an ASCII PLY whose vertex lines hold 50 numbers for 3 properties (trimesh: 1 GB, 35 s)."""
    header = "ply\nformat ascii 1.0\nelement vertex 600000\nproperty float x\nproperty float y\nproperty float z\n"
    header += "end_header\n"
    path.write_text(header + (" ".join(["0"] * 50) + "\n") * 600_000)


def ascii_stl_words(path):
    """60 MB of an ASCII STL of 2,000,000 vertex lines and not one endfacet: the reader stops at the cap."""
    path.write_text("solid x\n" + "vertex 0.5 0.25 0.125\n" * 2_700_000 + "endsolid x\n")


BIG = {
    "polygon.obj": (one_polygon, "too-many-triangles", 9),
    "vertices.obj": (vertex_lines, "too-many-vertices", None),
    "indented.obj": (lambda p: vertex_lines(p, "  "), "too-many-vertices", MAX_VERTICES + 1),
    "wide.ply": (wide_ascii_ply, "invalid-mesh", None),
    "words.stl": (ascii_stl_words, "too-many-triangles", 3 * MAX_TRIANGLES + 2),
}


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_big_hostile_meshes_cost_a_few_times_the_cap_at_most(tmp_path):
    folder = tmp_path / "in"
    folder.mkdir()
    for name, (make, _, _) in BIG.items():
        make(folder / name)
    with open(folder / "sparse-1-gib.stl", "wb") as f:
        f.truncate(1 << 30)
    code, stderr, peak = run_measured(
        "synthesize", folder, "--friction", "0.5", "-f", "jsonl", "-o", "out.jsonl", cwd=tmp_path
    )
    records = [json.loads(line) for line in (tmp_path / "out.jsonl").read_text().splitlines()]
    assert code == 1 and "Traceback" not in stderr and "internal error" not in stderr, stderr
    said = {os.path.basename(r["file"]): (r["error"]["code"], r["error"]["line"]) for r in records}
    assert said == {**{n: (c, line) for n, (_, c, line) in BIG.items()}, "sparse-1-gib.stl": ("too-large", None)}
    # the mesh cap is 64 MiB, each 60 MB file read whole once: 302 MB here, each alone 58-206 MB
    # (the interpreter's 34 MB with them); 0.5 went past 0.5 GB on the polygon, 2.1 GB on the vertices
    assert peak < 400, f"{peak:.0f} MB"


def test_the_docs_table_of_caps_gives_io_limits_own_numbers():
    import re

    from grasptwist.io import limits
    from places import ROOT

    page = (ROOT / "docs" / "reference" / "bad-input-and-faults.md").read_text("utf-8")
    section = page.split("## Caps: one per kind of input")[1].split("\n## ")[0]
    said = {
        name: int(number.replace(",", "")) << (20 if mib else 0)
        for name, number, mib in re.findall(r"`([A-Z_]+)`,? \(?([\d,]+)( MiB)?\)?", section)
    }
    caps = {name for name in limits.__all__ if name.isupper()} - {"MESH_SUFFIXES", "NOT_REGULAR", "OUTPUT_IS_INPUT"}
    assert set(said) == caps
    assert all(getattr(limits, name) == value for name, value in said.items()), said


def test_a_path_s_samples_have_one_cap_whichever_option_asks_for_them():
    from typer.testing import CliRunner

    from grasptwist.cli import app
    from grasptwist.io.limits import MAX_SAMPLES
    from grasptwist.run.follow import sample_times

    with pytest.raises(ValueError, match=f"gives more than {MAX_SAMPLES} samples"):
        sample_times(1.0, dt=1 / MAX_SAMPLES)  # --dt: a too-many-samples record
    assert len(sample_times(1.0, dt=2 / MAX_SAMPLES)) == MAX_SAMPLES // 2 + 1
    r = CliRunner().invoke(app, ["follow", "x.yaml", "--samples", str(MAX_SAMPLES + 1)])  # --samples: a usage error
    assert r.exit_code == 2 and f"2<=x<={MAX_SAMPLES}" in r.stderr
