"""Bounds the README's "Bad, malicious and degenerate input" section states, measured.

Run: ``python bench/faults.py``.  Each figure is one real ``grasptwist``
process (``python -m grasptwist``); peak memory is the largest resident set
of the run's processes (``wait4``'s rusage), seconds are wall time from start
to exit, or from the moment a signal was sent.  Not a speed test: these are
bounds (memory, time to stop, spool size), so a loaded machine shows the
same order of magnitude.

(a) hostile files: the corpus one at a time (median and slowest), 1 MiB of
    ``---`` lines, sixteen such files in one folder, one 50 MB JSON line, the 2.8 MB ``.npz`` zip
    bomb (``zeros((40_000_000, 3, 3))``) beside a good file, and an honest
    compressed ``.npz`` of 10^6 grasps (232 MB compressed);
(b) stopping: SIGTERM, SIGINT to the group, and SIGKILL of one worker,
    each 1 s into a two-worker run on 200,000 grasps (median of 5);
(c) the spool a reader that stopped reading leaves in ``/dev/shm``.
"""

import glob
import os
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from _data import grasp_arrays

ROOT = Path(__file__).resolve().parents[1]
TWIST = ("--twist", "0,0,1,0,0,0")


def start(*args, stdout=subprocess.DEVNULL):
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src"), "NO_COLOR": "1"}
    cmd = [sys.executable, "-m", "grasptwist", *map(str, args)]
    return subprocess.Popen(cmd, stdout=stdout, stderr=subprocess.DEVNULL, env=env, start_new_session=True)


def finish(p):
    """Exit status of ``p``."""
    _, status = os.waitpid(p.pid, 0)
    return os.waitstatus_to_exitcode(status)


def measured(*args):
    """Seconds, peak MB and exit status of ``grasptwist ARGS``, run by a fresh
    wrapper process that reads ``getrusage(RUSAGE_CHILDREN)``: a child forked
    straight from this process would inherit this process's own peak."""
    wrapper = (
        "import resource, subprocess, sys; code = subprocess.run(sys.argv[1:], stdout=subprocess.DEVNULL, "
        "stderr=subprocess.DEVNULL).returncode; print(code, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)"
    )
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src"), "NO_COLOR": "1"}
    t = time.monotonic()
    out = subprocess.run(
        [sys.executable, "-c", wrapper, sys.executable, "-m", "grasptwist", *map(str, args)],
        env=env, capture_output=True, text=True, check=True,
    ).stdout  # fmt: skip
    code, kib = map(int, out.split())
    return time.monotonic() - t, kib / 1024, code


def hostile(tmp: Path):
    corpus = sorted((ROOT / "tests" / "corpus").glob("*.yaml"))
    times = [measured("resolve", f, "-f", "jsonl")[0] for f in corpus]
    base = statistics.median(
        measured("resolve", ROOT / "grasps" / "polyhedron.yaml", "-f", "jsonl")[0] for _ in range(5)
    )
    print(
        f"corpus, each file alone ({len(corpus)}): median {statistics.median(times):.3f} s, "
        f"slowest {max(times):.3f} s; the bundled polyhedron.yaml: {base:.3f} s (start-up)"
    )
    (tmp / "dashes").mkdir()
    for k in range(16):
        (tmp / "dashes" / f"{k:02d}.yaml").write_bytes(b"---\n" * (1 << 18))
    s, peak, _ = measured("resolve", tmp / "dashes" / "00.yaml", "-f", "jsonl", "-o", tmp / "out.jsonl")
    print(f"1 MiB of '---' lines: {s:.2f} s, peak {peak:.0f} MB")
    s, peak, _ = measured("resolve", tmp / "dashes", "-f", "jsonl", "-o", tmp / "out.jsonl")
    print(f"sixteen such files in one folder: {s:.2f} s, peak {peak:.0f} MB")
    (tmp / "long.jsonl").write_bytes(b'{"name": "' + b"x" * 50_000_000 + b'"}\n')
    s, peak, _ = measured("resolve", tmp / "long.jsonl", "--max-bytes", 10**8, "-f", "jsonl")
    print(f"one 50 MB line with --max-bytes 1e8: {s:.2f} s, peak {peak:.0f} MB")
    np.savez_compressed(tmp / "bomb.npz", points=np.zeros((40_000_000, 3, 3)))
    size = (tmp / "bomb.npz").stat().st_size
    s, peak, code = measured("resolve", tmp / "bomb.npz", ROOT / "grasps" / "polyhedron.yaml", "-f", "jsonl")
    print(
        f"npz zip bomb ({size / 1e6:.1f} MB declaring 2.88 GB) beside a good file: {s:.2f} s, peak {peak:.0f} MB, exit {code}"
    )
    np.savez_compressed(tmp / "honest.npz", **dict(zip(("points", "normals", "wrist", "twist"), grasp_arrays(10**6))))
    size = (tmp / "honest.npz").stat().st_size
    for j in ("1", "2"):
        s, peak, _ = measured("resolve", tmp / "honest.npz", "-f", "jsonl", "-q", "-j", j, "-o", tmp / "out.jsonl")
        print(f"compressed npz of 10^6 grasps ({size / 1e6:.0f} MB) to JSONL, -j {j}: {s:.1f} s, peak {peak:.0f} MB")


def stopping(tmp: Path):
    np.save(tmp / "rows.npy", np.random.default_rng(11).normal(size=(200_000, 21)))
    args = ("resolve", tmp / "rows.npy", *TWIST, "-f", "jsonl", "-j", "2", "-q", "-o", tmp / "out.jsonl")

    def after(act):
        p = start(*args)
        time.sleep(1.0)
        act(p)
        t = time.monotonic()
        code = finish(p)
        return time.monotonic() - t, code

    def kill_worker(p):
        children = Path(f"/proc/{p.pid}/task/{p.pid}/children").read_text().split()
        os.kill(int(children[0]), signal.SIGKILL)

    for name, act in (
        ("SIGTERM to the parent", lambda p: os.kill(p.pid, signal.SIGTERM)),
        ("SIGINT to the group", lambda p: os.killpg(p.pid, signal.SIGINT)),
        ("SIGKILL of a worker", kill_worker),
    ):
        runs = [after(act) for _ in range(5)]
        print(
            f"{name}: ended {statistics.median(s for s, _ in runs):.3f} s after "
            f"(slowest {max(s for s, _ in runs):.3f} s), exit {sorted({c for _, c in runs})}"
        )


def spool(tmp: Path):
    p = start("resolve", tmp / "rows.npy", *TWIST, "-f", "jsonl", "-j", "2", "-q", stdout=subprocess.PIPE)
    time.sleep(6)  # nobody reads: the workers fill what they may and wait
    held = sum(os.stat(f).st_blocks * 512 for f in glob.glob(f"/dev/shm/grasptwist-*-{p.pid}-*/*"))
    size = sum(len(chunk) for chunk in iter(lambda: p.stdout.read(1 << 20), b""))
    finish(p)
    print(f"spool with a reader that stopped: {held / 1e6:.1f} MB held, of {size / 1e6:.0f} MB of output")


if __name__ == "__main__":
    # a shell starts a background job with SIGINT ignored, and its children would inherit that
    signal.signal(signal.SIGINT, signal.default_int_handler)
    with tempfile.TemporaryDirectory() as d:
        hostile(Path(d))
        stopping(Path(d))
        spool(Path(d))
