"""Where output goes, round two (issue 27): ``-o`` never replaces an input, a
replaced file keeps its mode and nothing of a failed write is left, odd targets
are refused by their type, closed standard streams are one line, and ``-j``
starts no more processes than the work has tasks.

Each test asserts the outcome: the exit code, the stderr line (its stable
part), every file's bytes and mode as they were, nothing left beside the
target or in TMPDIR, and for ``-j`` the processes the run forked.
"""

from __future__ import annotations

import os
import shutil
import stat
import subprocess
import sys
import threading
from pathlib import Path

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from grasptwist.cli import app
from grasptwist.cli.exits import CLICK_ERROR, EXIT_FAILED, EXIT_OK, EXIT_USAGE, EXIT_WRITE
from grasptwist.io.grasp.text import standard_input
from grasptwist.run import pipeline
from grasptwist.run.pool import MAX_WORKERS, Pool, pool_size
from grasptwist.run.target import WriteError, check_target, opened
from hostile import entry_point
from places import ROOT

POLY = ROOT / "grasps" / "polyhedron.yaml"
HAND_GRASP = ROOT / "grasps" / "three-finger-hand.yaml"
pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux descriptors and /proc")


def invoke(*args, **kw):
    return CliRunner().invoke(app, [str(a) for a in args], **kw)


def usage_line(*args) -> str:
    """The message of the usage error (exit 2) of ``grasptwist ARGS``, on one line as
    :func:`grasptwist.cli.exits.usage_error` prints it."""
    r = invoke(*args, standalone_mode=False)
    assert isinstance(r.exception, CLICK_ERROR) and r.exception.exit_code == EXIT_USAGE, (r.output, r.exception)
    assert r.stdout == ""  # no record: refused before any work
    return " ".join(r.exception.format_message().split())


def snapshot(folder: Path) -> dict:
    """Every entry under ``folder``: its bytes (or link target) and mode."""
    found = {}
    for p in sorted(folder.rglob("*")):
        info = p.lstat()
        content = os.readlink(p) if p.is_symlink() else p.read_bytes() if p.is_file() else None
        found[str(p.relative_to(folder))] = (content, stat.S_IMODE(info.st_mode))
    return found


def shell(tmp_path: Path, redirect: str, *args) -> subprocess.CompletedProcess:
    """``grasptwist ARGS REDIRECT`` run by sh in ``tmp_path`` (``>&-`` closes stdout
    as a user's shell does), with a TMPDIR of its own."""
    tmpdir = tmp_path / "tmpdir"
    tmpdir.mkdir(exist_ok=True)
    env = {**os.environ, "NO_COLOR": "1", "TMPDIR": str(tmpdir)}
    command = ["sh", "-c", f'exec "$@" {redirect}', "sh", *entry_point(), *map(str, args)]
    return subprocess.run(command, capture_output=True, text=True, cwd=tmp_path, env=env, timeout=30)


@pytest.fixture
def inputs(tmp_path):
    """A grasp file with a hard link and a symbolic link to it, a folder holding
    a grasp file, an npz data set, a stream of twists and a hand file."""
    shutil.copy(POLY, tmp_path / "a.yaml")
    os.link(tmp_path / "a.yaml", tmp_path / "hard.yaml")
    os.link(tmp_path / "a.yaml", tmp_path / "hard.png")
    (tmp_path / "soft.yaml").symlink_to("a.yaml")
    (tmp_path / "dir" / "sub").mkdir(parents=True)
    shutil.copy(POLY, tmp_path / "dir" / "sub" / "p.yaml")
    rng = np.random.default_rng(3)
    np.savez(tmp_path / "ds.npz", points=rng.normal(size=(5, 3, 3)), normals=np.tile(np.eye(3), (5, 1, 1)))
    (tmp_path / "t.jsonl").write_text("[0, 0, 1, 0, 0, 0]\n")
    hand = yaml.safe_load(HAND_GRASP.read_text())["hand"]
    (tmp_path / "hand.yaml").write_text(yaml.safe_dump({"hand": hand}))
    return tmp_path


# --------------------------------------------------------------------------
# -o never replaces one of the run's inputs


@pytest.mark.parametrize(
    ("args", "output", "read"),
    [
        (["resolve", "a.yaml", "-f", "jsonl"], "a.yaml", "a.yaml"),
        (["resolve", "a.yaml"], "hard.yaml", "a.yaml"),
        (["resolve", "hard.yaml"], "soft.yaml", "hard.yaml"),
        (["check", "dir"], "dir/sub/p.yaml", "dir/sub/p.yaml"),
        (["resolve", "ds.npz", "--twist", "0,0,1,0,0,0", "-f", "npz"], "ds.npz", "ds.npz"),
        (["resolve", "a.yaml", "--twists-from", "t.jsonl", "-f", "jsonl"], "t.jsonl", "t.jsonl"),
        (["resolve", "ds.npz", "--twist", "0,0,1,0,0,0", "--hand", "hand.yaml", "-f", "jsonl"], "hand.yaml", "hand.yaml"),
        (["basis", "soft.yaml", "-f", "json"], "a.yaml", "soft.yaml"),
        (["forces", "dir", "--wrench", "0,0,1,0,0,0"], "dir/sub/p.yaml", "dir/sub/p.yaml"),
        (["follow", "a.yaml", "--twist", "0,0,1,0,0,0", "--duration", "1"], "hard.yaml", "a.yaml"),
        (["plot", "a.yaml"], "hard.png", "a.yaml"),
    ],
    ids=["same-name", "hard-link", "symlink", "found-in-a-folder", "npz", "twists-from", "hand", "basis", "forces",
         "follow", "plot"],
)  # fmt: skip
def test_an_output_that_is_an_input_is_refused_before_any_work(inputs, monkeypatch, args, output, read):
    monkeypatch.chdir(inputs)
    before = snapshot(inputs)
    line = usage_line(*args, "-o", output)
    assert (
        line
        == f"Invalid value for -o: cannot write {output}: it is the input {read} (the same file); give another file name"
    )
    assert snapshot(inputs) == before  # every input's bytes and mode, and nothing new


def test_a_copy_of_an_input_is_another_file_and_is_replaced(inputs, monkeypatch):
    monkeypatch.chdir(inputs)
    shutil.copy(POLY, "copy.yaml")  # the same bytes, another file: the check is by device and inode
    assert invoke("resolve", "a.yaml", "-f", "jsonl", "-o", "copy.yaml").exit_code == EXIT_OK
    assert Path("copy.yaml").read_text().startswith('{"file":"a.yaml"')
    assert Path("a.yaml").read_bytes() == POLY.read_bytes()


WAYS_TO_WRITE = {
    "resolve": ["resolve", "a.yaml", "-f", "jsonl"],
    "forces": ["forces", "a.yaml", "-f", "jsonl"],
    "follow": ["follow", "a.yaml", "--twist", "0,0,1,0,0,0", "--duration", "1"],
    "check-a-folder": ["check", "dir"],
    "plot": ["plot", "a.yaml"],
}


@pytest.mark.parametrize("args", WAYS_TO_WRITE.values(), ids=WAYS_TO_WRITE.keys())
@pytest.mark.parametrize("name", ["a.yaml", "dir/sub/p.yaml", "out.jsonl"], ids=["an-input", "in-a-folder", "new"])
def test_a_dot_dot_after_a_missing_folder_is_a_missing_folder(inputs, monkeypatch, args, name):
    # The system resolves "nosuch/.." as given: no such folder, as a shell's `>` says. Read as
    # text it would be "" and the run would replace a.yaml, or write a file `>` cannot open.
    monkeypatch.chdir(inputs)
    before = snapshot(inputs)
    output = f"nosuch/../{name}"
    folder = os.path.dirname(output)
    assert usage_line(*args, "-o", output) == f"Invalid value for -o: cannot write {output}: no folder {folder}"
    assert snapshot(inputs) == before


@pytest.mark.parametrize("output", ["dir/sub/../../a.yaml", "linked/../../a.yaml"], ids=["real-folders", "linked"])
def test_a_dot_dot_after_a_real_folder_is_resolved_by_the_system(inputs, monkeypatch, output):
    monkeypatch.chdir(inputs)
    Path("linked").symlink_to("dir/sub")  # linked/.. is dir, not the current folder
    before = snapshot(inputs)
    assert usage_line("resolve", "a.yaml", "-o", output) == (
        f"Invalid value for -o: cannot write {output}: it is the input a.yaml (the same file); give another file name"
    )
    assert snapshot(inputs) == before


def test_a_new_file_past_a_linked_folder_is_where_the_system_puts_it(inputs, monkeypatch):
    monkeypatch.chdir(inputs)
    Path("linked").symlink_to("dir/sub")
    Path("dir/sub/link.jsonl").symlink_to("../../dir/new.jsonl")  # dangling, relative to dir/sub
    assert invoke("resolve", "a.yaml", "-f", "jsonl", "-o", "linked/../out.jsonl").exit_code == EXIT_OK
    assert invoke("resolve", "a.yaml", "-f", "jsonl", "-o", "linked/link.jsonl").exit_code == EXIT_OK
    # linked/.. is dir (not "." as text would have it); the link's target is found from dir/sub
    for written in ("dir/out.jsonl", "dir/new.jsonl"):
        assert Path(written).read_text().startswith('{"file":"a.yaml"')
    assert not Path("out.jsonl").exists() and not Path("new.jsonl").exists()
    assert os.readlink("dir/sub/link.jsonl") == "../../dir/new.jsonl"  # the link stays


def test_a_descriptor_name_past_a_missing_folder_is_no_descriptor(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(ValueError, match=r"^cannot write /dev/nosuch/\.\./stdout: no folder /dev/nosuch/\.\.$"):
        check_target("/dev/nosuch/../stdout")
    assert check_target("/dev/fd/../fd/1").how == "through"  # /dev/fd/.. is /proc/self, and its fd/1 a descriptor


@pytest.mark.parametrize(
    ("redirect", "line"),
    [
        (
            "-o a.yaml < a.yaml",
            " for -o: cannot write a.yaml: it is the file standard input reads, an input (the same file)",
        ),
        (">> a.yaml", ": cannot write standard output: it is the input a.yaml (the same file)"),
    ],
    ids=["stdin-is-the-output", "stdout-appends-to-an-input"],
)
def test_a_standard_stream_on_an_input_is_refused_in_one_line(tmp_path, redirect, line):
    shutil.copy(POLY, tmp_path / "a.yaml")
    args = ("resolve", "-", "-f", "jsonl") if "<" in redirect else ("resolve", "a.yaml", "-f", "jsonl")
    done = shell(tmp_path, redirect, *args)
    assert done.returncode == EXIT_USAGE
    (said,) = done.stderr.splitlines()
    assert said.startswith(f"grasptwist: error: Invalid value{line}; give another file name (see '")
    assert (tmp_path / "a.yaml").read_bytes() == POLY.read_bytes()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.yaml", "tmpdir"]
    assert not any((tmp_path / "tmpdir").iterdir())


# --------------------------------------------------------------------------
# A replaced file: its mode kept, nothing of a failed write left


def test_a_replaced_file_keeps_its_permission_bits(tmp_path):
    private, setuid = tmp_path / "private.jsonl", tmp_path / "setuid.jsonl"
    for path, mode in ((private, 0o600), (setuid, 0o4750)):
        path.write_text("old\n")
        path.chmod(mode)
    for path in (private, setuid):
        inode = path.stat().st_ino
        assert invoke("resolve", POLY, "-f", "jsonl", "-o", path).exit_code == EXIT_OK
        assert path.read_text().count("\n") == 1 and path.stat().st_ino != inode  # replaced, not rewritten
    assert stat.S_IMODE(private.stat().st_mode) == 0o600
    assert stat.S_IMODE(setuid.stat().st_mode) == 0o750  # never a set-id bit on new content
    umask = os.umask(0o022)
    os.umask(umask)
    assert invoke("resolve", POLY, "-f", "jsonl", "-o", tmp_path / "new.jsonl").exit_code == EXIT_OK
    assert stat.S_IMODE((tmp_path / "new.jsonl").stat().st_mode) == 0o666 & ~umask
    assert sorted(p.name for p in tmp_path.iterdir()) == ["new.jsonl", "private.jsonl", "setuid.jsonl"]


def shm_folder(tmp_path):
    if not os.access("/dev/shm", os.W_OK):
        pytest.skip("no writable /dev/shm")
    folder = Path("/dev/shm") / f"grasptwist-test-{os.getpid()}-{tmp_path.name}"
    folder.mkdir()
    return folder


@pytest.mark.parametrize("where", ["tmp", "dev-shm"])
def test_a_write_that_fails_leaves_the_file_as_it_was(tmp_path, where):
    folder = tmp_path if where == "tmp" else shm_folder(tmp_path)
    try:
        target = folder / "out.jsonl"
        target.write_text("old\n")
        target.chmod(0o640)
        with pytest.raises(RuntimeError, match="stopped half-way"), opened(str(target)) as out:
            out.write(b"partial")
            raise RuntimeError("stopped half-way")
        assert target.read_text() == "old\n" and stat.S_IMODE(target.stat().st_mode) == 0o640
        assert [p.name for p in folder.iterdir()] == ["out.jsonl"]
        with opened(str(target)) as out:  # /dev/shm is no device: a regular file there is replaced too
            out.write(b"new\n")
        assert target.read_text() == "new\n" and stat.S_IMODE(target.stat().st_mode) == 0o640
    finally:
        if where == "dev-shm":
            shutil.rmtree(folder)


@pytest.mark.skipif(os.geteuid() != 0, reason="mknod of a block device needs root")
def test_a_block_device_is_refused_by_its_type_wherever_it_is(tmp_path):
    disk = tmp_path / "disk"
    os.mknod(disk, 0o600 | stat.S_IFBLK, os.makedev(7, 255))  # a loop device node outside /dev
    line = usage_line("resolve", POLY, "-o", disk)
    assert line == f"Invalid value for -o: cannot write {disk}: it is a block device (a disk); give a file name"
    assert stat.S_ISBLK(disk.lstat().st_mode) and sorted(p.name for p in tmp_path.iterdir()) == ["disk"]
    assert check_target("/dev/null").how == "through"  # a character device: written through, as documented


@pytest.mark.parametrize(
    "args",
    [
        ["resolve", "-"],
        ["basis", POLY],
        ["check", POLY],
        ["forces", POLY],
        ["follow", POLY],
        ["schema"],
        ["plot", POLY],
        ["plot", ROOT / "grasps"],
    ],
    ids=["resolve", "basis", "check", "forces", "follow", "schema", "plot", "plot-folder"],
)
def test_an_empty_output_name_is_a_usage_error_before_any_work(args):
    assert usage_line(*args, "-o", "") == "Invalid value for -o: cannot write '': the file name is empty"


# --------------------------------------------------------------------------
# Closed and read-only standard streams: one line each


CLOSED = "grasptwist: error: cannot write standard output: it is closed"


@pytest.mark.parametrize(
    ("args", "redirect", "code", "lines"),
    [
        (["resolve", POLY], ">&-", EXIT_WRITE, [CLOSED]),
        (["resolve", POLY, "-o", "/dev/stdout"], ">&-", EXIT_WRITE, ["grasptwist: error: cannot write /dev/stdout: it is closed"]),
        (["resolve", POLY, "-o", "/dev/fd/0"], "< other.txt", EXIT_WRITE, ["grasptwist: error: cannot write /dev/fd/0: it is open for reading only"]),
        # a standard stream closed by the shell, as a closed stdout: exit 3 before any work
        (["resolve", "-", POLY], "<&-", EXIT_WRITE, ["grasptwist: error: cannot read standard input: it is closed"]),
        # over a second: docs/reference/development.md, Test time (as the help's, cli.main's WriteError)
        pytest.param(["--version"], ">&-", EXIT_WRITE, [CLOSED], marks=pytest.mark.slow),
        ([], ">&-", EXIT_WRITE, [CLOSED]),  # the help that `grasptwist` alone prints
        (["plot", POLY, "-o", "p.html"], ">&-", EXIT_WRITE, [CLOSED]),  # before anything is drawn
    ],
    ids=["closed-stdout", "dev-stdout-closed", "dev-fd-0-read-only", "closed-stdin", "version", "help", "plot"],
)  # fmt: skip
def test_closed_and_read_only_standard_streams_are_one_line(tmp_path, args, redirect, code, lines):
    if "plot" in args:
        pytest.importorskip("plotly")
    (tmp_path / "other.txt").write_text("not an output\n")
    done = shell(tmp_path, redirect, *args, *(["-f", "jsonl"] if "resolve" in args else []))
    assert (done.returncode, done.stderr.splitlines()) == (code, lines)
    assert (tmp_path / "other.txt").read_text() == "not an output\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["other.txt", "tmpdir"]  # no p.html
    assert not any((tmp_path / "tmpdir").iterdir())
    assert done.stdout == ""  # nothing was done


@pytest.mark.parametrize(("grasp", "code"), [(POLY, EXIT_OK), (ROOT / "grasps" / "sphere.yaml", EXIT_FAILED)])
def test_a_closed_stderr_drops_the_diagnostics_and_keeps_the_exit_status(tmp_path, grasp, code):
    """``2>&-``: the records complete on stdout, the exit status the run's own (0, or 1 for the
    sphere's degenerate equator grasp), not 1 for the diagnostics that had nowhere to go."""
    done = shell(tmp_path, "2>&-", "resolve", grasp, "-f", "jsonl")
    expected = invoke("resolve", grasp, "-f", "jsonl")
    assert (done.returncode, expected.exit_code) == (code, code)
    assert done.stdout == expected.stdout and done.stdout.count("\n") >= 1
    assert ('"ok":false' in done.stdout) == (code == EXIT_FAILED)


def test_a_closed_stderr_leaves_an_output_file_its_records_only(tmp_path):
    """Descriptor 2 is held by /dev/null, so the output file gets another."""
    done = shell(tmp_path, "2>&-", "resolve", POLY, "-f", "jsonl", "-o", "out.jsonl")
    assert done.returncode == EXIT_OK
    assert (tmp_path / "out.jsonl").read_text() == invoke("resolve", POLY, "-f", "jsonl").stdout


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time (as -o /dev/stdout's, above)
def test_a_closed_stderr_is_no_output(tmp_path):
    """``-o /dev/stderr`` on a closed stderr is refused as closed (exit 3), as ``-o /dev/stdout`` is."""
    done = shell(tmp_path, "2>&-", "resolve", POLY, "-o", "/dev/stderr")
    assert (done.returncode, done.stdout) == (EXIT_WRITE, "")


def test_closed_streams_in_process(monkeypatch):
    monkeypatch.setattr(sys, "stdout", None)
    with pytest.raises(WriteError, match=r"^cannot write standard output: it is closed$"), opened(None):
        pass
    monkeypatch.setattr(sys, "stdin", None)
    with pytest.raises(OSError, match="standard input is closed"):
        standard_input()


# --------------------------------------------------------------------------
# -j: never more processes than tasks, nor than the cap


def children() -> set[int]:
    """The processes this thread forked that still exist."""
    path = Path(f"/proc/{os.getpid()}/task/{threading.get_native_id()}/children")
    return {int(pid) for pid in path.read_text().split()}


def test_a_pool_starts_no_more_processes_than_its_cap(monkeypatch):
    monkeypatch.setattr(os, "cpu_count", lambda: 1)
    assert pool_size(10_000) == 4 and pool_size(10_000, tasks=2) == 2 and pool_size(3, tasks=0) == 1
    monkeypatch.setattr(os, "cpu_count", lambda: 1024)
    assert pool_size(10_000) == MAX_WORKERS
    monkeypatch.setattr(os, "cpu_count", lambda: 1)
    before = children()
    with Pool(lambda i: i + 1, workers=10_000) as pool:
        started = children() - before
        assert pool.size == len(started) == 4
        assert list(pool.results(6)) == [1, 2, 3, 4, 5, 6]
    assert not children() & started


@pytest.mark.slow  # the default run's 40 s: development.md, Test time
def test_j_10000_starts_a_worker_per_task_only(tmp_path, monkeypatch):
    sizes = []

    class Counted(Pool):
        def __init__(self, *args, **kw):
            before = children()
            super().__init__(*args, **kw)
            sizes.append((self.size, len(children() - before)))

    monkeypatch.setattr(pipeline, "Pool", Counted)
    rows = pipeline.TUNING.grasps_per_task + 5  # two tasks
    np.save(tmp_path / "rows.npy", np.random.default_rng(5).normal(size=(rows, 21)))
    r = invoke("resolve", tmp_path / "rows.npy", "--twist", "0,0,1,0,0,0", "-f", "csv", "-q", "-j", 10_000)
    assert r.exit_code in (EXIT_OK, EXIT_FAILED) and r.stdout.count("\n") == rows + 1
    assert sizes == [(2, 2)]


@pytest.mark.parametrize(
    ("suffix", "extra", "magic"),
    [
        # over a second (matplotlib's import and drawing): docs/reference/development.md, Test time
        pytest.param(".png", "matplotlib", b"\x89PNG", marks=pytest.mark.slow),
        (".html", "plotly", b"<!DOC"),
    ],
)
def test_plot_replaces_a_picture_atomically_keeping_its_mode(tmp_path, suffix, extra, magic):
    pytest.importorskip(extra)
    picture = tmp_path / f"poly{suffix}"
    picture.write_bytes(b"old")
    picture.chmod(0o600)
    inode = picture.stat().st_ino
    r = invoke("plot", POLY, "-o", picture)
    assert (r.exit_code, r.stdout) == (EXIT_OK, f"{picture}\n")
    assert picture.read_bytes().startswith(magic) and picture.stat().st_ino != inode  # a new file took the name
    assert stat.S_IMODE(picture.stat().st_mode) == 0o600 and [p.name for p in tmp_path.iterdir()] == [picture.name]
