"""Faults, reproduced on real processes (issue 11): odd output targets, stop
signals, dead workers, slow readers, full disks.

Each test runs ``python -m grasptwist`` in its own session, acts when the run
says it has started (its first line on stderr, or a file appearing), and
then checks that nothing is left behind: no spool folder of that run in
``/dev/shm``, no temporary file beside the output, nothing in its TMPDIR, no
process of its session.  The tests needing a small private file system
mount one through ``unshare -m``, which needs root.
"""

from __future__ import annotations

import contextlib
import errno
import glob
import json
import os
import re
import resource
import shutil
import signal
import stat
import subprocess
import sys
import tempfile
import threading
import time
import zipfile
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from grasptwist.cli import app
from grasptwist.cli.exits import EXIT_USAGE, EXIT_WORKER, EXIT_WRITE
from grasptwist.io.datasets import MAX_INFLATION, Member, open_dataset
from grasptwist.io.inputs import read
from grasptwist.model import InputError
from grasptwist.run.pipeline import TUNING, Spool
from grasptwist.run.pool import Pool, WorkerDied, WorkerFailed
from grasptwist.run.scratch import owned_prefix
from hostile import assert_no_crash, jsonl, run_installed, run_measured, summary
from places import ROOT

POLY = ROOT / "grasps" / "polyhedron.yaml"
TWIST = ("--twist", "0,0,1,0,0,0")
ROWS = 200_000
DIAGNOSTIC = re.compile(r": (warning|error): ")
pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="watches processes through Linux's /proc")
ROOT_ONLY = pytest.mark.skipif(
    os.geteuid() != 0 or shutil.which("unshare") is None, reason="mounting a private tmpfs needs root and unshare"
)


# --------------------------------------------------------------------------
# Running and watching a real grasptwist process


class Run:
    """``python -m grasptwist ARGS`` in a new session, its stderr collected by a thread."""

    def __init__(self, tmp: Path, *args, launcher: str | None = None, prefix=(), **popen):
        self.tmpdir = tmp / "tmpdir"
        self.tmpdir.mkdir(exist_ok=True)
        env = {**os.environ, "PYTHONPATH": str(ROOT / "src"), "TMPDIR": str(self.tmpdir)}
        env.pop("NO_COLOR", None)
        code = ["-c", launcher] if launcher else ["-m", "grasptwist"]
        popen.setdefault("stdout", subprocess.DEVNULL)
        self.p = subprocess.Popen(
            [*prefix, sys.executable, *code, *map(str, args)],
            stdin=popen.pop("stdin", subprocess.DEVNULL),
            stderr=subprocess.PIPE,
            env=env,
            start_new_session=True,
            **popen,
        )
        self.lines: list[str] = []
        self.started = threading.Event()
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _read(self):
        for raw in self.p.stderr:
            self.lines.append(raw.decode(errors="replace").rstrip("\n"))
            self.started.set()
        self.started.set()

    def wait_started(self, timeout=30):
        assert self.started.wait(timeout), "the run wrote nothing on stderr"
        assert self.p.poll() is None, f"the run ended before it could be interrupted: {self.lines}"

    def finish(self, timeout=30) -> tuple[int, resource.struct_rusage]:
        """Exit status and the resources of the run's processes (a run that hangs fails after
        ``timeout`` s; how fast a run stops is measured in bench/faults.py, not asserted)."""
        deadline = time.monotonic() + timeout
        while True:
            pid, status, usage = os.wait4(self.p.pid, os.WNOHANG)
            if pid:
                break
            if time.monotonic() > deadline:
                os.killpg(self.p.pid, signal.SIGKILL)
                pytest.fail(f"the run did not end within {timeout} s (0.1 hung here); stderr: {self.lines[-5:]}")
            time.sleep(0.005)
        self.p.returncode = os.waitstatus_to_exitcode(status)
        self._reader.join(10)
        return self.p.returncode, usage

    def workers(self) -> list[int]:
        try:
            return [int(x) for x in Path(f"/proc/{self.p.pid}/task/{self.p.pid}/children").read_text().split()]
        except OSError:
            return []

    def stalled(self) -> bool:
        """Whether the run has workers and none of its processes ran for 0.2 s
        (everyone waits: for an unread pipe, or for the parent to take a result)."""

        def cpu():
            ticks = 0
            for pid in session(self.p.pid):
                with contextlib.suppress(OSError), open(f"/proc/{pid}/stat") as f:
                    ticks += sum(int(x) for x in f.read().rsplit(")", 1)[1].split()[11:13])  # utime, stime
            return ticks

        before = cpu()
        time.sleep(0.2)
        return bool(self.workers()) and cpu() == before

    def said(self) -> list[str]:
        """What stderr said besides the records' own diagnostics (``path: ...: warning: ...``)."""
        return [line for line in self.lines if line.startswith("grasptwist:") or not DIAGNOSTIC.search(line)]


def wait_for(condition, what: str, timeout: float = 30, run: Run | None = None):
    """Poll ``condition`` until it holds; fail after ``timeout`` or when ``run`` ends first."""
    deadline = time.monotonic() + timeout
    while not (value := condition()):
        if run is not None and run.p.poll() is not None:
            pytest.fail(f"the run ended (exit {run.p.returncode}) before {what}: {run.lines[-3:]}")
        if time.monotonic() > deadline:
            pytest.fail(f"timed out waiting for {what}")
        time.sleep(0.005)
    return value


def catches(pid: int, sig: signal.Signals) -> bool:
    """Whether process ``pid`` has a handler for ``sig`` (before it has one, a
    signal has its default effect: a run still starting just dies)."""
    with contextlib.suppress(OSError):
        for line in Path(f"/proc/{pid}/status").read_text().splitlines():
            if line.startswith("SigCgt:"):
                return bool(int(line.split()[1], 16) >> (sig - 1) & 1)
    return False


def session(sid: int) -> list[int]:
    """Processes of session ``sid`` (a run and everything it started)."""
    pids = []
    for stat_file in glob.glob("/proc/[0-9]*/stat"):
        try:
            fields = Path(stat_file).read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[3]) == sid and fields[0] != "Z":
            pids.append(int(stat_file.split("/")[2]))
    return pids


def spool_of(pid: int) -> list[str]:
    return glob.glob(f"/dev/shm/grasptwist-*-{pid}-*")


def assert_no_debris(run: Run, folder: Path | None = None):
    wait_for(lambda: not session(run.p.pid), "the run's worker processes to end")
    assert spool_of(run.p.pid) == []
    assert list(run.tmpdir.iterdir()) == []
    if folder is not None:
        assert [p.name for p in folder.iterdir() if p.name.startswith(".grasptwist-")] == []


@pytest.fixture(scope="module")
def rows(tmp_path_factory) -> Path:
    """A data set of ROWS random grasps: about 2.5 s of work on two processes."""
    path = tmp_path_factory.mktemp("data") / "rows.npy"
    np.save(path, np.random.default_rng(11).normal(size=(ROWS, 21)))
    return path


# --------------------------------------------------------------------------
# 1. Output targets: replaced atomically, written through, or refused


def invoke(*args):
    return CliRunner().invoke(app, [str(a) for a in args])


def test_a_fifo_is_written_through_and_stays_a_fifo(tmp_path):
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    got = []
    reader = threading.Thread(target=lambda: got.append(fifo.read_bytes()))
    reader.start()
    assert invoke("resolve", POLY, "-f", "jsonl", "-o", fifo).exit_code == 0
    reader.join(10)
    assert stat.S_ISFIFO(fifo.lstat().st_mode)
    assert got[0].count(b"\n") == 1 and got[0].startswith(b'{"file":')


@pytest.mark.skipif(os.geteuid() != 0, reason="mknod needs root")
def test_a_character_device_is_written_through_never_replaced(tmp_path):
    null = tmp_path / "null"
    os.mknod(null, 0o666 | stat.S_IFCHR, os.makedev(1, 3))  # a /dev/null of our own
    assert invoke("resolve", POLY, "-f", "jsonl", "-o", null).exit_code == 0
    assert stat.S_ISCHR(null.lstat().st_mode) and null.lstat().st_rdev == os.makedev(1, 3)


def test_a_symlink_stays_and_its_target_gets_the_output(tmp_path):
    (tmp_path / "target.jsonl").write_text("old\n")
    (tmp_path / "link").symlink_to("target.jsonl")
    (tmp_path / "dangling").symlink_to("new.jsonl")
    assert invoke("resolve", POLY, "-f", "jsonl", "-o", tmp_path / "link").exit_code == 0
    assert invoke("resolve", POLY, "-f", "jsonl", "-o", tmp_path / "dangling").exit_code == 0
    assert os.readlink(tmp_path / "link") == "target.jsonl" and os.readlink(tmp_path / "dangling") == "new.jsonl"
    assert (tmp_path / "target.jsonl").read_text().count("\n") == 1
    assert (tmp_path / "target.jsonl").read_bytes() == (tmp_path / "new.jsonl").read_bytes()


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_dev_stdout_is_written_through(tmp_path):
    out = tmp_path / "out.jsonl"
    with open(out, "wb") as f:
        inode = os.fstat(f.fileno()).st_ino
        run = Run(tmp_path, "resolve", POLY, "-f", "jsonl", "-o", "/dev/stdout", stdout=f)
        assert run.finish()[0] == 0
    assert out.stat().st_ino == inode and out.read_text().count("\n") == 1  # the shell's file, not a new one


def test_a_folder_is_a_usage_error_before_any_work(tmp_path):
    # stdin is never closed: a run that started its work would wait for it forever
    run = Run(tmp_path, "resolve", "-", "-f", "jsonl", "-o", tmp_path, stdin=subprocess.PIPE)
    assert run.finish(timeout=20)[0] == EXIT_USAGE
    (line,) = run.lines  # the help named as this run was started ("python -m grasptwist resolve -h" here)
    assert line.startswith(
        f"grasptwist: error: Invalid value for -o: cannot write {tmp_path}: it is a folder; give a file name (see '"
    ) and line.endswith(" resolve -h')")
    (tmp_path / "loop").symlink_to("loop")
    r = invoke("resolve", POLY, "-o", tmp_path / "loop")
    assert r.exit_code == EXIT_USAGE and "cannot write" in r.stderr and "Too many levels of symbolic links" in r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["loop", "tmpdir"]


def test_a_link_to_itself_is_reported_as_a_loop_not_missing(tmp_path):
    (tmp_path / "self.yaml").symlink_to("self.yaml")
    r = invoke("resolve", tmp_path / "self.yaml", "-f", "jsonl")
    assert r.exit_code == 1 and "read-error: cannot read: Too many levels of symbolic links" in r.stderr


def test_temporary_files_of_killed_runs_are_removed_by_the_next_run(tmp_path):
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    stem = owned_prefix(".grasptwist-").rsplit("-", 2)[0]  # ".grasptwist-<host>"
    left = tmp_path / f"{stem}-{dead.stdout.strip()}-abcd1234.tmp"
    live = tmp_path / f"{stem}-{os.getpid()}-abcd1234.tmp"  # a run still going on: not ours to touch
    left.write_text("debris")
    live.write_text("in use")
    assert invoke("resolve", POLY, "-f", "jsonl", "-o", tmp_path / "out.jsonl").exit_code == 0
    assert not left.exists() and live.exists()


# --------------------------------------------------------------------------
# 2-3. Stop signals: SIGINT to the whole group (Ctrl-C), SIGTERM to the
# parent (kill, timeout), SIGHUP to the group (the terminal went away)


@pytest.mark.parametrize(
    ("sig", "group", "to_file"),
    [
        (signal.SIGINT, True, None),
        (signal.SIGTERM, False, "tmp"),
        pytest.param(signal.SIGHUP, True, "tmp", marks=pytest.mark.slow),
        # a regular file in /dev/shm is replaced as anywhere else, never truncated first (issue 27)
        pytest.param(signal.SIGTERM, False, "shm", marks=pytest.mark.slow),
    ],
    ids=["INT-to-a-stalled-pipe", "TERM", "HUP", "TERM-to-a-file-in-dev-shm"],
)
def test_a_stop_signal_ends_a_parallel_run_cleanly(tmp_path, rows, sig, group, to_file):
    folder = Path(tempfile.mkdtemp(prefix="grasptwist-test-", dir="/dev/shm")) if to_file == "shm" else tmp_path
    out = folder / "out.jsonl"
    out.write_text("old\n")
    # the pipe is not read until the run has ended: the run is stuck writing to it (0.1 could hang here)
    target = ("-o", out) if to_file else ()
    run = Run(tmp_path, "resolve", rows, *TWIST, "-f", "jsonl", "-j", "2", *target, stdout=subprocess.PIPE)
    run.wait_started() if to_file else wait_for(run.stalled, "the run to stall on its unread pipe", run=run)
    assert len(run.workers()) == 2 and spool_of(run.p.pid)
    (os.killpg if group else os.kill)(run.p.pid, sig)
    code, _ = run.finish()
    assert code == 128 + sig
    assert run.said() == [f"grasptwist: stopped by {sig.name}"]  # no traceback from any process
    assert out.read_text() == "old\n"
    assert_no_debris(run, folder)
    if to_file == "shm":
        shutil.rmtree(folder)


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_a_stop_signal_removes_the_npz_spill(tmp_path, rows):
    # the npz format with a spill threshold of 1 MiB instead of 512 MiB, so that a small data set spills
    launcher = (
        "from grasptwist.output import formats, npz; "
        "formats.FORMATS['npz'] = formats.FORMATS['npz']._replace("
        "open=lambda out, kind, order='omega-v', **_: npz.NpzWriter(out, order, spill_bytes=1 << 20)); "
        "from grasptwist.cli import main; main()"
    )
    run = Run(tmp_path, "resolve", rows, *TWIST, "-f", "npz", "-o", tmp_path / "out.npz", launcher=launcher)
    wait_for(lambda: glob.glob(f"{run.tmpdir}/grasptwist-npz-*/*"), "the npz writer to spill", run=run)
    os.kill(run.p.pid, signal.SIGTERM)
    code, _ = run.finish()
    assert code == 128 + signal.SIGTERM and run.said() == ["grasptwist: stopped by SIGTERM"]
    assert not (tmp_path / "out.npz").exists()
    assert_no_debris(run, tmp_path)


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_sigkill_of_the_parent_takes_its_workers_and_leaves_no_output(tmp_path, rows):
    run = Run(tmp_path, "resolve", rows, *TWIST, "-f", "jsonl", "-j", "2", "-o", tmp_path / "out.jsonl")
    run.wait_started()
    spool = spool_of(run.p.pid)
    os.kill(run.p.pid, signal.SIGKILL)
    assert run.finish()[0] == -signal.SIGKILL
    wait_for(lambda: not session(run.p.pid), "the workers to die with their parent")
    # the output was an unnamed file: nothing to see; the spool is named after its dead owner
    assert sorted(p.name for p in tmp_path.iterdir()) == ["tmpdir"]
    assert spool and spool_of(run.p.pid) == spool
    with Spool.opened(workers=2, budget=1 << 20):  # as the next parallel run does
        assert spool_of(run.p.pid) == []


# --------------------------------------------------------------------------
# 4. Dead workers, and inputs that change under a run


def test_a_worker_killed_like_by_the_oom_killer_ends_the_run(tmp_path, rows):
    out = tmp_path / "out.jsonl"
    run = Run(tmp_path, "resolve", rows, *TWIST, "-f", "jsonl", "-j", "2", "-o", out)
    run.wait_started()
    victim = run.workers()[0]
    os.kill(victim, signal.SIGKILL)
    code, _ = run.finish()
    assert code == EXIT_WORKER
    assert run.said() == [
        f"grasptwist: error: worker process {victim} was stopped by SIGKILL (killed; the system may be out of memory)"
    ]
    assert not out.exists()
    assert_no_debris(run, tmp_path)


def test_a_pool_reports_a_dead_worker_and_a_task_that_raised():
    def task(i):
        if i == 5:
            os.kill(os.getpid(), signal.SIGKILL)
        return 10 // (7 - i)

    got = []
    with pytest.raises(WorkerDied, match=r"worker process \d+ was stopped by SIGKILL") as died, Pool(task, 2) as pool:
        got.extend(pool.results(9))
    assert got == [1, 1, 2, 2, 3][: len(got)] and died.value.exitcode == -signal.SIGKILL  # as soon as it died
    failing = pytest.raises(WorkerFailed, match="ZeroDivisionError: integer division or modulo by zero")
    with failing as failed, Pool(lambda i: 10 // (7 - i), 2) as pool:
        list(pool.results(9))
    assert "Traceback" in failed.value.__notes__[0]


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_a_data_set_shrinking_under_a_parallel_run_is_a_bus_error_not_a_hang(tmp_path, rows):
    victim = tmp_path / "victim.npy"
    shutil.copy(rows, victim)
    run = Run(tmp_path, "resolve", victim, *TWIST, "-f", "jsonl", "-j", "2", "-o", tmp_path / "out.jsonl")
    run.wait_started()
    os.truncate(victim, 4096)  # what rewriting it in place does first
    code, _ = run.finish()
    assert code == EXIT_WORKER
    [line] = run.said()
    assert "was stopped by SIGBUS (bus error; a memory-mapped input file changed or shrank" in line
    assert_no_debris(run, tmp_path)


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_a_file_swapped_for_a_fifo_after_the_listing_is_a_read_error_not_a_hang(tmp_path):
    folder = tmp_path / "grasps"
    folder.mkdir()
    for name in ("a.yaml", "b.yaml"):
        shutil.copy(POLY, folder / name)
    run = Run(tmp_path, "resolve", "-", folder, "-f", "jsonl", stdin=subprocess.PIPE, stdout=subprocess.PIPE)

    def reading_stdin():  # the folder is listed before stdin is read
        return Path(f"/proc/{run.p.pid}/syscall").read_text().split()[:2] == ["0", "0x0"]

    wait_for(reading_stdin, "the run to read stdin", run=run)
    (folder / "b.yaml").unlink()
    os.mkfifo(folder / "b.yaml")  # nobody will ever write to it: opening it for reading would wait forever
    run.p.stdin.write(POLY.read_bytes())
    run.p.stdin.close()
    records = run.p.stdout.read().count(b"\n")
    code, _ = run.finish()
    assert code == 1 and records == 3  # stdin, a.yaml and the error record of b.yaml
    assert (
        f"{folder / 'b.yaml'}: error: read-error: cannot read: not a regular file (a pipe, socket or device)"
        in run.lines
    )


# --------------------------------------------------------------------------
# 5. Backpressure: a slow reader stops the workers; the spool is bounded


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_a_reader_that_stops_reading_stops_the_workers(tmp_path, rows):
    small = tmp_path / "small.npy"
    np.save(small, np.load(rows, mmap_mode="r")[: 8 * TUNING.grasps_per_task])  # 8 tasks
    run = Run(tmp_path, "resolve", small, *TWIST, "-f", "jsonl", "-j", "2", "-q", stdout=subprocess.PIPE)
    wait_for(run.stalled, "the run to stall on its unread pipe", run=run)
    held = sum(os.stat(f).st_blocks * 512 for d in spool_of(run.p.pid) for f in glob.glob(d + "/*"))
    lines = size = 0
    peak = largest_peak(run)
    for chunk in iter(lambda: run.p.stdout.read(1 << 20), b""):
        lines, size = lines + chunk.count(b"\n"), size + len(chunk)
        peak = max(peak, largest_peak(run))
    code, _ = run.finish()
    assert code in (0, 1) and lines == 8 * TUNING.grasps_per_task
    # each worker holds at most `in_flight` tasks, and the parent is copying one more
    print(f"spool with a stalled reader: {held / 1e6:.1f} MB of {size / 1e6:.1f} MB; largest process {peak} kB")
    assert 0 < held <= min(TUNING.spool_bytes, (2 * TUNING.in_flight + 1) * size / 8)
    assert 0 < peak < 400_000  # kB
    assert_no_debris(run)


def largest_peak(run: Run) -> int:
    """The largest peak resident size (VmHWM, kB) of the run's processes now.  Not wait4's ru_maxrss: a
    process started by fork and exec keeps the forking process's size as its own (a test worker's,
    600 MB after the slow tier's compiled tests, where the run's own are 90 MB)."""
    peak = 0
    for pid in session(run.p.pid):
        # gone meanwhile (OSError), or a zombie, whose status has no memory lines (IndexError)
        with contextlib.suppress(OSError, ValueError, IndexError):
            status = Path(f"/proc/{pid}/status").read_text()
            peak = max(peak, int(status.split("VmHWM:")[1].split()[0]))
    return peak


@ROOT_ONLY
@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_a_small_dev_shm_sends_the_output_by_pipe_instead(tmp_path, rows):
    # Docker gives containers 64 MB; 4 MB leaves a spool budget of 1 MB, less than one output
    mount = 'mount -t tmpfs -o size=4m tmpfs /dev/shm && exec "$@"'
    prefix = ("unshare", "-m", "sh", "-c", mount, "sh")
    small = tmp_path / "small.npy"
    np.save(small, np.load(rows, mmap_mode="r")[: 2 * TUNING.grasps_per_task])
    args = ("resolve", small, *TWIST, "-f", "jsonl", "-q")
    parallel = Run(tmp_path, *args, "-j", "2", "-o", tmp_path / "two.jsonl", prefix=prefix)
    alone = Run(tmp_path, *args, "-j", "1", "-o", tmp_path / "one.jsonl")
    assert parallel.finish()[0] == alone.finish()[0] in (0, 1)
    assert parallel.lines == alone.lines  # no "No space left on device"
    assert (tmp_path / "two.jsonl").read_bytes() == (tmp_path / "one.jsonl").read_bytes()


@ROOT_ONLY
def test_a_spool_write_that_fails_declines_and_leaves_nothing(tmp_path):
    (tmp_path / "shm").mkdir()
    code = (
        "import os, sys; from grasptwist.run.pipeline import Spool; s = Spool(sys.argv[1], share=1 << 30); "
        "print(s.put(b'x' * (2 << 20)), os.listdir(sys.argv[1]), bool(s.put(b'y' * 1000)))"
    )
    mount = f'mount -t tmpfs -o size=1m tmpfs {tmp_path / "shm"} && exec "$@"'
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    p = subprocess.run(
        ["unshare", "-m", "sh", "-c", mount, "sh", sys.executable, "-c", code, tmp_path / "shm"],
        capture_output=True,
        text=True,
        timeout=30,
        env=env,
    )
    assert p.stdout == "None [] True\n", p.stderr


def test_a_spool_holds_at_most_its_share_per_worker(tmp_path):
    spool = Spool(str(tmp_path), share=3000)
    first = spool.put(b"a" * 2000)
    assert first and spool.put(b"b" * 2000) is None  # over the share: by pipe
    os.unlink(first)  # the parent took it
    assert spool.put(b"c" * 2000)


# --------------------------------------------------------------------------
# 6. Small hostile files stay small in memory


@pytest.mark.parametrize("files", [pytest.param(4, marks=pytest.mark.slow), pytest.param(16, marks=pytest.mark.slow)])
def test_mebibytes_of_document_markers_in_a_folder_take_little_memory(tmp_path, files):
    # 0.1: 262,144 records and error lines per file, 20.4 GB for the folder of sixteen
    (tmp_path / "in").mkdir()
    for k in range(files):
        (tmp_path / "in" / f"{k:02d}.yaml").write_bytes(b"---\n" * (1 << 18))  # 1 MiB of empty documents
    code, stderr, peak = run_measured("resolve", "in", "-f", "jsonl", "-j", "2", "-o", "out.jsonl", cwd=tmp_path)
    print(f"{files} files of '---': peak {peak:.0f} MB")
    assert code == 1 and peak < 300
    # per file: 100 errors, too-many-documents at document 10,001 and in its record the count of the 9,900 others
    records = jsonl((tmp_path / "out.jsonl").read_text())
    assert len(records) == files * 101
    lines = stderr.splitlines()
    assert len(lines) == files * 102 + 1
    assert lines[-2].endswith("9900 more problems in this file not reported (only the first 100 are)")
    assert (
        lines[-1]
        == summary(records)
        == f"{files * 101} records: 0 with a degenerate method, {files * 101} inputs failed"
    )


@pytest.fixture(scope="module")
def bomb(tmp_path_factory) -> Path:
    """A 70 kB ``.npz`` declaring 72 MB of zeros (the issue's bomb scaled down to just over the
    64 MiB a member may declare before its inflation is looked at, to be quick to make)."""
    path = tmp_path_factory.mktemp("bomb") / "bomb.npz"
    np.savez_compressed(path, points=np.zeros((1_000_000, 3, 3)))
    return path


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_an_npz_zip_bomb_is_refused_unread_and_costs_no_other_record(tmp_path, bomb):
    # 0.1 inflated every member whole: 2.85 GB and 12.7 s for the 2.8 MB bomb, MemoryError under a limit
    code, stderr, peak = run_measured("resolve", bomb, POLY, "-f", "jsonl", "-o", "out.jsonl", cwd=tmp_path)
    print(f"npz bomb: peak {peak:.0f} MB")
    assert code == 1 and peak < 150
    assert stderr.splitlines()[0] == (
        f"{bomb}: error: bad-dataset: points: declares 72,000,128 bytes decoded from "
        f"{zipfile.ZipFile(bomb).getinfo('points.npy').compress_size:,} "
        f"(over {MAX_INFLATION} times): refused unread, as a likely zip bomb"
    )
    records = jsonl((tmp_path / "out.jsonl").read_text())
    assert [r["file"] for r in records] == [str(bomb), str(POLY)] and records[1]["ok"]


@pytest.mark.parametrize(
    "save",
    [pytest.param(np.savez, marks=pytest.mark.slow), pytest.param(np.savez_compressed, marks=pytest.mark.slow)],
    ids=["stored", "compressed"],
)
def test_npz_members_are_read_a_block_at_a_time_with_the_same_records(tmp_path, rows, save):
    data = np.load(rows, mmap_mode="r")[: 3 * TUNING.grasps_per_task]  # three tasks for two workers
    n = len(data)
    save(
        tmp_path / "set.npz",
        points=data[:, :9].reshape(n, 3, 3),
        normals=data[:, 9:18].reshape(n, 3, 3),
        wrist=data[:, 18:],
        twist=data[:, :6],
        names=np.array([f"g{i}" for i in range(n)]),
    )
    ds = open_dataset(str(tmp_path / "set.npz"))
    assert isinstance(ds.points, Member) and ds.points.shape == (n, 3, 3)
    np.testing.assert_array_equal(ds.points[5000:5100], data[5000:5100, :9].reshape(100, 3, 3))
    np.testing.assert_array_equal(ds.twist[n - 5 :], data[n - 5 :, :6])
    # forked workers, each reading its own tasks' rows: as one process reading them all
    args = ("resolve", tmp_path / "set.npz", "-f", "jsonl", "-q")
    two, one = (Run(tmp_path, *args, "-j", j, stdout=subprocess.PIPE) for j in ("2", "1"))
    assert two.p.stdout.read() == one.p.stdout.read()
    assert two.finish()[0] == one.finish()[0] in (0, 1)


def test_a_damaged_npz_member_is_a_read_error_where_it_is_found(tmp_path, rows):
    points = np.load(rows, mmap_mode="r")[:3000, :9].reshape(-1, 3, 3)
    np.savez_compressed(tmp_path / "set.npz", points=points, normals=points)
    info = zipfile.ZipFile(tmp_path / "set.npz").getinfo("points.npy")
    data = bytearray((tmp_path / "set.npz").read_bytes())
    end = info.header_offset + info.compress_size  # the member's last bytes: its checksum fails at its end
    data[end - 100 : end - 50] = bytes(50)
    (tmp_path / "set.npz").write_bytes(data)
    r = invoke("resolve", tmp_path / "set.npz", POLY, *TWIST, "-f", "jsonl", "-j", "1")
    assert_no_crash(r.stderr)  # the commands' catch-all says so in process too
    assert r.exit_code == 1
    [line] = [x for x in r.stderr.splitlines() if "read-error" in x]
    assert line.startswith(f"{tmp_path / 'set.npz'}: error: read-error: points.npy: ")
    assert line.endswith("(damaged, or changed while being read)")
    assert jsonl(r.stdout)[-1]["file"] == str(POLY)  # the next input is still resolved


@pytest.mark.parametrize(
    ("member", "message"),
    [
        ("shape", "points: shape (5, 3, 3) of float64 needs 360 bytes, the member holds 288"),
        ("objects", "names: holds Python objects (object), which are never read"),
        ("fortran", "points: stored column-major; save it with np.ascontiguousarray"),
    ],
)
def test_what_an_npz_member_declares_is_checked_before_it_is_read(tmp_path, member, message):
    path = tmp_path / "odd.npz"
    arrays = {"points": np.zeros((4, 3, 3)), "normals": np.ones((4, 3, 3))}
    if member == "objects":
        arrays["names"] = np.array(["a", 1, None, 2.0], dtype=object)
    if member == "fortran":
        arrays["points"] = np.asfortranarray(arrays["points"])
    with zipfile.ZipFile(path, "w") as zf:
        for key, a in arrays.items():
            with zf.open(f"{key}.npy", "w") as f:
                if member == "shape" and key == "points":  # a header declaring one more row than there is
                    header = {"descr": "<f8", "fortran_order": False, "shape": (5, 3, 3)}
                    np.lib.format.write_array_header_1_0(f, header)
                    f.write(a.tobytes())
                else:
                    np.lib.format.write_array(f, a, allow_pickle=True)
    with pytest.raises(InputError, match=re.escape(message)) as err:
        open_dataset(str(path))
    assert err.value.code == "bad-dataset"


# --------------------------------------------------------------------------
# 7. Names that are not UTF-8


@pytest.mark.parametrize(
    "fmt",
    [
        # over a second: docs/reference/development.md, Test time (the JSON string's escape, as jsonl's)
        pytest.param("json", marks=pytest.mark.slow),
        "jsonl",
        "csv",
        "check",
        "-o",
    ],
)
def test_an_undecodable_file_name_is_escaped_in_every_format(tmp_path, fmt):
    # 0.1: internal error (TypeError: str is not valid UTF-8, or UnicodeEncodeError), no record at all
    folder = tmp_path / "in"
    folder.mkdir()
    shutil.copy(POLY, folder / "good.yaml")
    with open(os.fsencode(folder) + b"/b\xff.yaml", "wb") as f:
        f.write(POLY.read_bytes())
    out = tmp_path / "out.jsonl"
    args = ("check", folder) if fmt == "check" else ("resolve", folder, "-f", "jsonl" if fmt == "-o" else fmt)
    run = Run(tmp_path, *args, *(("-o", out) if fmt == "-o" else ()), stdout=subprocess.PIPE)
    text = run.p.stdout.read()
    assert run.finish()[0] == 0 and run.said() == ["2 records: all ok"]
    text = out.read_bytes() if fmt == "-o" else text
    escaped = f"{folder}/b\\xff.yaml"
    assert text.decode("utf-8").count(escaped if fmt in ("csv", "check") else json.dumps(escaped)[1:-1]) == 1


def test_bytes_names_in_an_npz_are_decoded_and_the_other_inputs_kept(tmp_path):
    # 0.1: internal error: UnicodeDecodeError, and the good input given alongside was lost
    path = tmp_path / "names.npz"
    arrays = np.random.default_rng(7).normal(size=(2, 3, 3, 3))
    np.savez(path, points=arrays[0], normals=arrays[1], names=np.array([b"ok", b"\xff", b"caf\xc3\xa9"]))
    r = invoke("resolve", path, POLY, *TWIST, "-f", "jsonl")
    assert_no_crash(r.stderr)
    assert [rec["grasp"] for rec in jsonl(r.stdout)] == ["ok", "\\xff", "caf\u00e9", "polyhedron"]


# --------------------------------------------------------------------------
# 9. Deep trees

DEPTH = 2000


@pytest.fixture
def deep_tree(tmp_path):
    """``deep/d/d/.../d/g.yaml``, DEPTH folders down, beside ``top.yaml``; made
    and removed by file descriptors, since the paths outgrow what Python's
    recursive ``os.makedirs`` and ``shutil.rmtree`` can take."""
    (tmp_path / "deep").mkdir()
    shutil.copyfile(ROOT / "grasps" / "sphere.yaml", tmp_path / "deep" / "top.yaml")
    fd = os.open(tmp_path / "deep", os.O_RDONLY)
    for _ in range(DEPTH):
        os.mkdir("d", dir_fd=fd)
        fd, parent = os.open("d", os.O_RDONLY, dir_fd=fd), fd
        os.close(parent)
    leaf = os.open("g.yaml", os.O_WRONLY | os.O_CREAT, 0o644, dir_fd=fd)
    os.write(leaf, POLY.read_bytes())
    os.close(leaf)
    yield tmp_path
    os.unlink("g.yaml", dir_fd=fd)
    for _ in range(DEPTH):
        fd, child = os.open("..", os.O_RDONLY, dir_fd=fd), fd
        os.close(child)
        os.rmdir("d", dir_fd=fd)
    os.close(fd)


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_a_folder_2000_levels_deep(deep_tree):
    # 0.1: internal error: RecursionError after 11 s, and no records, not even for top.yaml
    # relative to the tree's parent the deepest path has ~4,000 characters, within PATH_MAX
    proc, _ = run_installed("resolve", "deep", "-f", "jsonl", cwd=deep_tree)
    assert_no_crash(proc.stderr)
    deepest = "deep/" + "d/" * DEPTH + "g.yaml"
    # every record of both files, depth first in name order: one per grasp and twist
    expected = [deepest] * records_of(POLY) + ["deep/top.yaml"] * records_of(ROOT / "grasps" / "sphere.yaml")
    assert [r["file"] for r in jsonl(proc.stdout)] == expected


def records_of(path):
    return sum(len(grasp.twists) for grasp in read(str(path)))


# --------------------------------------------------------------------------
# 11. Nits


def test_nan_in_a_data_set_wrist_column_is_nonfinite_input_not_no_wrist(tmp_path):
    # 0.1: a row whose wrist held NaN or infinity was silently resolved as if it had no wrist
    points, normals = np.random.default_rng(5).normal(size=(2, 3, 3, 3))
    wrist = np.array([[0.0, 0.0, 1.0], [np.nan, 0.0, 1.0], [0.0, np.inf, 1.0]])
    np.savez(tmp_path / "set.npz", points=points, normals=normals, wrist=wrist)
    r = invoke("resolve", tmp_path / "set.npz", *TWIST, "-f", "jsonl")
    records = jsonl(r.stdout)
    assert ["error" not in rec["off_tangent"] for rec in records] == [True, False, False]
    assert [rec["off_tangent"]["error"]["code"] for rec in records[1:]] == ["nonfinite-input"] * 2
    assert all(rec["tangent"] and "alpha" in rec["tangent"] for rec in records)  # the other method still answers
    assert r.exit_code == 1


# --------------------------------------------------------------------------
# 10. Write errors: one line, exit 3, nothing left


@ROOT_ONLY
def test_a_full_disk_is_one_line_and_exit_3(tmp_path, rows):
    disk = tmp_path / "disk"
    disk.mkdir()
    small = tmp_path / "small.npy"
    np.save(small, np.load(rows, mmap_mode="r")[:2000])  # 5 MB of JSON on a 256 kB disk
    mount = f'mount -t tmpfs -o size=256k tmpfs {disk} && exec "$@"'
    prefix = ("unshare", "-m", "sh", "-c", mount, "sh")
    to_file = Run(tmp_path, "resolve", small, *TWIST, "-f", "jsonl", "-q", "-o", disk / "out.jsonl", prefix=prefix)
    assert to_file.finish()[0] == EXIT_WRITE
    assert to_file.lines == [f"grasptwist: error: cannot write {disk / 'out.jsonl'}: {os.strerror(errno.ENOSPC)}"]
    shell = f'mount -t tmpfs -o size=256k tmpfs {disk} && exec "$@" > {disk / "out.jsonl"}'
    to_stdout = Run(
        tmp_path, "resolve", small, *TWIST, "-f", "jsonl", "-q", prefix=("unshare", "-m", "sh", "-c", shell, "sh")
    )
    assert to_stdout.finish()[0] == EXIT_WRITE
    assert to_stdout.lines == [f"grasptwist: error: cannot write standard output: {os.strerror(errno.ENOSPC)}"]
    assert_no_debris(to_file)


# --------------------------------------------------------------------------
# 8. Names in tables: never read as rich markup, control characters escaped

MARKUP_GRASP = """\
name: "[/]x"
wrist: [0, 0, 0]
contacts:
  - {name: "[/]a", point: [0, 2, 2], normal: [1, 0, 0]}
  - {name: "[bold]b", point: [2, 0, 2], normal: [0, 1, 0]}
  - {name: "[blink]c", point: [2, 2, 0], normal: [0, 0, 1]}
twists:
  - {name: "[red]t", screw: [0, 0, 1, 0, 0, 0]}
"""


@pytest.mark.parametrize("command", ["resolve", "basis", "check"])
def test_markup_and_control_characters_in_names_are_shown_as_written(tmp_path, command):
    path = tmp_path / "g\x1b[2Jrid\x07.yaml"  # a file name that would clear the screen and ring
    path.write_text(MARKUP_GRASP)
    r = invoke(command, path)
    assert r.exit_code == 0, r.output  # 0.1: internal error: MarkupError
    shown = r.stdout
    assert "\x1b" not in shown and "\x07" not in shown
    assert "g\\x1b[2Jrid\\x07.yaml" in shown  # escaped as stderr escapes it
    assert "[/]x" in shown
    if command != "check":
        assert "[/]x (" in shown.splitlines()[0]  # the title
        for name in ("[/]a", "[bold]b", "[blink]c"):
            assert re.search(rf"^  {re.escape(name)} ", shown, re.M), name  # a row, neither swallowed nor raw
    if command == "resolve":
        assert "twist [red]t = (0.0000, 0.0000, 1.0000; 0.0000, 0.0000, 0.0000)" in shown


def test_data_set_names_with_control_characters_are_escaped_in_tables(tmp_path):
    path = tmp_path / "rows.npz"
    points = np.tile([[0.0, 2, 2], [2, 0, 2], [2, 2, 0]], (2, 1, 1))
    names = np.array(["\x1b]0;owned\x07", "[/]y"])
    np.savez(path, points=points, normals=np.tile(np.eye(3), (2, 1, 1)), twist=[0, 0, 1, 0, 0, 0.0], names=names)
    for command in ("resolve", "check"):
        r = invoke(command, path)
        assert r.exit_code == 0, r.output
        assert "\x1b" not in r.stdout and "\x07" not in r.stdout
        assert "\\x1b]0;owned\\x07" in r.stdout and "[/]y" in r.stdout


def test_an_undecodable_file_name_renders_in_tables(tmp_path):
    folder = os.fsencode(tmp_path)
    with open(folder + b"/b\xff.yaml", "wb") as f:
        f.write(MARKUP_GRASP.encode())
    (tmp_path / "good.yaml").write_text(POLY.read_text())
    for command in ("resolve", "basis", "check"):
        r = invoke(command, tmp_path)
        assert r.exit_code == 0, r.output
        assert "b\\xff.yaml" in r.stdout and "polyhedron" in r.stdout


# --------------------------------------------------------------------------
# Soaks: faults at random moments (python -m pytest -m slow tests/run/test_faults.py)


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(30))
def test_stop_signals_at_random_moments(tmp_path, rows, seed):
    rng = np.random.default_rng(seed)
    sig, group = [(signal.SIGINT, True), (signal.SIGTERM, False), (signal.SIGHUP, True)][seed % 3]
    fmt = ["jsonl", "csv", "npz"][rng.integers(3)]
    workers = str(rng.integers(1, 3))
    out = tmp_path / f"out.{fmt}"
    out.write_text("old\n")
    to_file = fmt == "npz" or rng.random() < 0.5
    target = ("-o", out) if to_file else ()
    run = Run(tmp_path, "resolve", rows, *TWIST, "-f", fmt, "-j", workers, *target, stdout=subprocess.PIPE)
    if rng.random() < 0.5:  # a reader that keeps up, or one that never reads until the end
        threading.Thread(target=lambda: [None for _ in iter(lambda: run.p.stdout.read(1 << 16), b"")]).start()
    wait_for(lambda: catches(run.p.pid, sig), f"the run to catch {sig.name}", run=run)
    time.sleep(rng.uniform(0, 1.5))  # the moment is the point of the test
    with contextlib.suppress(ProcessLookupError):  # it finished first
        (os.killpg if group else os.kill)(run.p.pid, sig)
    code, _ = run.finish()
    assert "Traceback" not in "\n".join(run.lines)
    if code in (0, 1, -sig):  # it finished first (-sig: the signal came as it exited, its handlers gone)
        assert run.said()[-1].endswith(" failed")
    else:
        assert code == 128 + sig, (code, run.said())
        assert run.said()[-1] == f"grasptwist: stopped by {sig.name}" and len(run.said()) <= 1
        assert out.read_text() == "old\n"
    assert_no_debris(run, tmp_path)


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(15))
def test_workers_killed_at_random_moments(tmp_path, rows, seed):
    rng = np.random.default_rng(seed)
    run = Run(tmp_path, "resolve", rows, *TWIST, "-f", "jsonl", "-j", "2", "-q", "-o", tmp_path / "out.jsonl")
    workers = wait_for(run.workers, "the workers", run=run)
    time.sleep(rng.uniform(0, 2.0))
    victim = workers[rng.integers(len(workers))]
    with contextlib.suppress(ProcessLookupError):  # it finished first
        os.kill(victim, [signal.SIGKILL, signal.SIGSEGV, signal.SIGBUS][seed % 3])
    code, _ = run.finish()
    if code in (0, 1):  # it finished first
        assert (tmp_path / "out.jsonl").exists()
    else:
        assert code == EXIT_WORKER
        [line] = run.lines
        assert line.startswith(f"grasptwist: error: worker process {victim} was stopped by SIG")
        assert not (tmp_path / "out.jsonl").exists()
    assert_no_debris(run, tmp_path)


@pytest.mark.slow
@pytest.mark.skipif(shutil.which("timeout") is None, reason="needs coreutils' timeout")
def test_timeout_on_a_large_data_set_leaves_nothing(tmp_path):
    big = tmp_path / "big.npy"
    np.save(big, np.random.default_rng(3).normal(size=(1_500_000, 21)))  # 250 MB, ~20 s of work
    for fmt, workers in (("jsonl", "2"), ("npz", "1")):
        out = tmp_path / f"out.{fmt}"
        # then standard input, never closed: a run that got through the data set waits there, so
        # `timeout` always has something to stop
        args = ("resolve", big, "-", *TWIST, "-f", fmt, "-j", workers, "-o", out)
        run = Run(tmp_path, *args, prefix=("timeout", "3"), stdin=subprocess.PIPE)
        code, _ = run.finish()
        assert code == 124 and "Traceback" not in "\n".join(run.lines)
        assert run.said() == ["grasptwist: stopped by SIGTERM"]
        assert not out.exists()
        assert_no_debris(run, tmp_path)
