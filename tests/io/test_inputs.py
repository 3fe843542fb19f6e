"""Which files a command reads (io/inputs.py): folder walks, suffixes, odd
entries (links, FIFOs, undecodable names, 2,000 levels of folders) and the
empty folder, through ``expand``/``read`` and through the command line."""

import errno
import json
import os
import shutil
import signal

import pytest
import yaml

from grasptwist.io.inputs import expand, read
from grasptwist.model import Grasp
from hostile import assert_no_crash, jsonl, run, run_installed, summary
from places import GRASPS

BUNDLED = GRASPS


def listed(paths):
    """``expand``'s answer as file names and ``(file, code, message)`` for errors."""
    return [p if isinstance(p, str) else (p.file, p.code, p.message) for p in expand([str(x) for x in paths])]


def test_suffixes_in_any_case_and_json_files_are_read(tmp_path):
    shutil.copyfile(BUNDLED / "sphere.yaml", tmp_path / "BOX.YAML")
    shutil.copyfile(BUNDLED / "cylinder.yaml", tmp_path / "c.Yml")
    poly = yaml.safe_load((BUNDLED / "polyhedron.yaml").read_text())
    (tmp_path / "poly.json").write_text(json.dumps(poly, indent=2))
    (tmp_path / "notes.txt").write_text("not read\n")
    (tmp_path / "yaml").write_text("no suffix, not read\n")
    assert listed([tmp_path]) == [str(tmp_path / name) for name in ("BOX.YAML", "c.Yml", "poly.json")]
    # JSON is YAML: the JSON copy gives the same records as the bundled file, but for its name
    result, _ = run("resolve", tmp_path / "poly.json", "-f", "jsonl")
    original, _ = run("resolve", BUNDLED / "polyhedron.yaml", "-f", "jsonl")
    assert result.exit_code == 0 and len(jsonl(result.stdout)) == 1
    assert [r | {"file": ""} for r in jsonl(result.stdout)] == [r | {"file": ""} for r in jsonl(original.stdout)]


@pytest.mark.parametrize("content", [{}, {"notes.txt": "x", "sub/data.npz": "", "sub/deeper/README": ""}])
def test_a_folder_without_grasp_files_is_an_error(tmp_path, content):
    for name, text in content.items():
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_text(text)
    message = "no grasp files in this folder or below it (looked for names ending in .yaml, .yml or .json, in any letter case)"
    assert listed([tmp_path]) == [(str(tmp_path), "no-grasp-files", message)]
    result, _ = run("resolve", tmp_path, "-f", "jsonl")
    assert result.exit_code == 1
    [record] = jsonl(result.stdout)
    assert (record["ok"], record["error"]["code"]) == (False, "no-grasp-files")
    assert result.stderr.splitlines() == [f"{tmp_path}: error: no-grasp-files: {message}", summary([record])]


def test_only_the_folder_named_must_hold_grasp_files(tmp_path):
    (tmp_path / "empty").mkdir()
    shutil.copyfile(BUNDLED / "sphere.yaml", tmp_path / "s.yaml")
    assert listed([tmp_path]) == [str(tmp_path / "s.yaml")]


def test_links_that_cannot_be_followed_say_why(tmp_path):
    os.symlink("self.yaml", tmp_path / "self.yaml")  # a link to itself
    os.symlink("nowhere.yaml", tmp_path / "dangling.yaml")
    loop = (str(tmp_path / "self.yaml"), "read-error", f"cannot read: {os.strerror(errno.ELOOP)}")
    dangling = (str(tmp_path / "dangling.yaml"), "read-error", "cannot read: a symbolic link to nothing")
    assert listed([tmp_path]) == [dangling, loop]  # in a folder
    assert listed([tmp_path / "self.yaml", tmp_path / "dangling.yaml", tmp_path / "none.yaml"]) == [
        loop, dangling, (str(tmp_path / "none.yaml"), "read-error", "cannot read: no such file or folder"),
    ]  # fmt: skip


def test_files_come_sorted_by_path_components_with_errors_in_place(tmp_path):
    for rel in ["b.yaml", "a/z.yaml", "a.yaml", "a-b/c.yaml", "a/b/c.yaml", "B.yaml"]:
        (tmp_path / rel).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / rel).write_text("x: 1\n")
    (tmp_path / "a/locked").mkdir()
    (tmp_path / "a/locked").chmod(0)
    try:
        order = listed([tmp_path])
    finally:
        (tmp_path / "a/locked").chmod(0o755)
    names = [p if isinstance(p, str) else p[0] for p in order]
    rels = ["B.yaml", "a/b/c.yaml", "a/locked", "a/z.yaml", "a-b/c.yaml", "a.yaml", "b.yaml"]
    if not isinstance(order[2], tuple):  # root lists a mode-000 folder: nothing in it, nothing to say
        rels.remove("a/locked")
    assert names == [str(tmp_path / rel) for rel in rels]
    assert names == sorted(names, key=lambda p: os.path.relpath(p, tmp_path).split(os.sep))


def test_a_file_swapped_for_a_fifo_after_the_walk_is_a_read_error(tmp_path):
    path = tmp_path / "g.yaml"
    shutil.copyfile(BUNDLED / "sphere.yaml", path)
    assert listed([tmp_path]) == [str(path)]
    path.unlink()
    os.mkfifo(path)  # no writer: a blocking open would wait forever
    signal.signal(signal.SIGALRM, lambda *_: pytest.fail("reading the FIFO hung"))
    signal.alarm(5)
    try:
        (error,) = read(str(path))
    finally:
        signal.alarm(0)
    assert (error.code, error.message) == ("read-error", "cannot read: not a regular file (a pipe, socket or device)")


def test_an_undecodable_file_name_is_read_and_named_safely(tmp_path):
    raw = os.fsencode(tmp_path) + b"/caf\xe9 \xff.yaml"  # Latin-1, not UTF-8
    with open(raw, "wb") as f:
        f.write((BUNDLED / "cylinder.yaml").read_bytes().replace(b"name: cylinder\n", b""))
    [path] = listed([tmp_path])
    assert os.fsencode(path) == raw  # the str path (surrogate escapes) opens the very file
    entries = read(path)
    assert entries and all(isinstance(e, Grasp) for e in entries)
    # the default name, from the stem, shows the bytes escaped: a valid name, printable UTF-8
    assert {e.name for e in entries} == {"caf\\xe9 \\xff"}
    assert {e.file for e in entries} == {path}


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_an_undecodable_file_name_costs_no_good_record(tmp_path):
    shutil.copyfile(BUNDLED / "sphere.yaml", tmp_path / "good.yaml")
    with open(os.fsencode(tmp_path) + b"/b\xff.yaml", "wb") as f:
        f.write((BUNDLED / "cylinder.yaml").read_bytes())
    alone, _ = run_installed("resolve", tmp_path / "good.yaml", "-f", "jsonl")
    proc, _ = run_installed("resolve", tmp_path, "-f", "jsonl")
    assert_no_crash(proc.stderr)
    records = jsonl(proc.stdout)
    assert [r for r in records if r["file"] == str(tmp_path / "good.yaml")] == jsonl(alone.stdout)
    assert len(records) > len(jsonl(alone.stdout))  # the other file's records are there too


def test_stdin_is_read_once():
    assert listed(["-", "-"]) == ["-", ("-", "read-error", "cannot read: standard input can be read only once")]


def test_a_family_s_suffixes_list_mesh_files_in_folders(tmp_path):
    from grasptwist.io.inputs import OBJECT_SUFFIXES

    for name in ("a.yaml", "b.STL", "c.obj", "d.ply", "e.txt"):
        (tmp_path / name).write_text("")
    names = [os.path.basename(p) for p in expand([str(tmp_path)], OBJECT_SUFFIXES)]
    assert names == ["a.yaml", "b.STL", "c.obj", "d.ply"]
    assert [os.path.basename(p) for p in expand([str(tmp_path)])] == ["a.yaml"]
    (tmp_path / "empty").mkdir()
    (empty,) = expand([str(tmp_path / "empty")], OBJECT_SUFFIXES)
    assert empty.code == "no-grasp-files" and ".stl, .obj or .ply" in empty.message
