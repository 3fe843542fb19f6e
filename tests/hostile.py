"""Helpers shared by the hostile-input tests (corpus, sweeps, fuzzing): run the
command line, read its JSON strictly, and check what must hold for any input."""

import json
import math
import os
import subprocess
import sys
import time
import warnings
from pathlib import Path

from typer.testing import CliRunner

from grasptwist.cli import app

#: Fields of a record that may be null in an ``ok`` record: every other null
#: would be a NaN that orjson wrote as null.
NULLABLE = {"units", "wrist", "off_tangent", "tip", "velocity_limit_ratio"}  # tip: inline hands
# forces records: a grasp without a wrench or a friction, closure without one, epsilon without --quality
NULLABLE |= {"wrench", "friction", "manipulating", "grip", "force_closure", "closure_friction", "epsilon"}
NULLABLE |= {"squeeze"}  # a grip on collinear contacts, whose internal forces are not three squeezes
NULLABLE |= {"surface_distance"}  # a contact of a grasp without an object
NULLABLE |= {"joint_positions", "reach_error"}  # a grasp synthesized without a hand
NULLABLE |= {"edge_distance"}  # a contact on a smooth object (no crease)
NULLABLE |= {"clearance"}  # a grasp synthesized without an environment
NULLABLE |= {"simulation"}  # a grasp synthesized without --simulate
NULLABLE |= {"torsion", "contact_torsion", "planned_torsion", "scene"}  # simulate: point contacts, no --mjcf


def run(*args, input=None):
    """``grasptwist ARGS`` through typer's CliRunner; returns (result, seconds).

    Python warnings issued during the run are kept in ``result.python_warnings``
    (pytest would otherwise swallow them, or print them, depending on its plugins):
    a user would see each as lines of noise on stderr.
    """
    start = time.monotonic()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = CliRunner().invoke(app, [str(a) for a in args], input=input)
    result.python_warnings = [f"{w.category.__name__}: {w.message}" for w in caught]
    return result, time.monotonic() - start


def entry_point():
    """The installed ``grasptwist`` script (``python -m grasptwist`` where there is none)."""
    exe = Path(sys.executable).parent / "grasptwist"
    return [str(exe)] if exe.exists() else [sys.executable, "-m", "grasptwist"]


def run_installed(*args, cwd=None, timeout=20, env=None):
    """``grasptwist ARGS`` in a subprocess, colourless (with ``env``'s variables too); returns
    (CompletedProcess, seconds)."""
    env = {**os.environ, "NO_COLOR": "1", **(env or {})}
    start = time.monotonic()
    proc = subprocess.run(
        entry_point() + [str(a) for a in args], capture_output=True, text=True, cwd=cwd, env=env, timeout=timeout
    )
    return proc, time.monotonic() - start


def run_measured(*args, cwd):
    """``grasptwist ARGS`` in a fresh process: (exit status, stderr, peak RSS in MB).

    A wrapper process runs the command and reads ``getrusage(RUSAGE_CHILDREN)``:
    its only children are the command and its workers, so the figure is theirs
    (the largest of them), not that of some earlier test's subprocess; nor is
    it this process's own peak, which a child forked straight from it
    inherits (Linux copies the peak with the memory map, before ``exec``).
    """
    wrapper = (
        "import resource, subprocess, sys; code = subprocess.run(sys.argv[1:]).returncode; "
        "print(code, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)"
    )
    env = {**os.environ, "NO_COLOR": "1"}
    proc = subprocess.run(
        [sys.executable, "-c", wrapper, *entry_point(), *map(str, args)],
        capture_output=True, text=True, cwd=cwd, env=env, timeout=60,
    )  # fmt: skip
    code, kib = map(int, proc.stdout.split())
    return code, proc.stderr, kib / 1024 if sys.platform != "darwin" else kib / 2**20


def strict_json(text):
    """``json.loads`` that refuses NaN and Infinity instead of reading them."""

    def refuse(name):
        raise AssertionError(f"{name} in JSON output")

    return json.loads(text, parse_constant=refuse)


def jsonl(text):
    """The records of ``-f jsonl`` output, each checked by :func:`check_record`."""
    records = [strict_json(line) for line in text.splitlines()]
    for rec in records:
        check_record(rec)
    return records


def check_record(rec):
    """What holds for every record: an ``ok`` flag, and in an ok record no NaN
    (written as null), no infinity and no error anywhere."""
    assert isinstance(rec.get("ok"), bool), rec
    if rec["ok"]:
        _walk_finite(rec, "")
        assert "error" not in rec


def _walk_finite(value, key):
    if value is None:
        assert key in NULLABLE, f"null (a NaN?) at {key!r} in an ok record"
    elif isinstance(value, float):
        assert math.isfinite(value), f"{value} at {key!r} in an ok record"
    elif isinstance(value, dict):
        assert "error" not in value, f"error at {key!r} in an ok record"
        for k, v in value.items():
            _walk_finite(v, k)
    elif isinstance(value, list):
        for v in value:
            _walk_finite(v, key)


def error_codes(rec):
    """Every error code in a record: each problem of the input's, or each failed method's."""
    found = [e["code"] for e in rec["errors"]] if "error" in rec else []
    for method in ("off_tangent", "tangent"):
        if isinstance(rec.get(method), dict) and "error" in rec[method]:
            found.append(rec[method]["error"]["code"])
    return found


def error_lines(stderr):
    """The diagnostic lines that report an error."""
    return [line for line in stderr.splitlines() if ": error: " in line]


def assert_no_crash(output):
    """Nothing a user should never see: a traceback or the catch-all internal error."""
    assert "Traceback" not in output, output[-2000:]
    assert "internal error" not in output, output[-2000:]


def summary(records: list[dict]) -> str:
    """The CLI's closing stderr line for the JSON ``records`` it wrote: the records of inputs
    that failed (``error``), and the others that are not ok counted by their failed kinds' codes."""
    from collections import Counter

    from grasptwist.cli.diagnostics import summary_line

    kinds = (("off-tangent", "off_tangent"), ("tangent", "tangent"), ("hand", "hand"))
    degenerate = [r for r in records if not r["ok"] and "error" not in r]
    codes = Counter(
        (label, r[key]["error"]["code"])
        for r in degenerate
        for label, key in kinds
        if isinstance(r.get(key), dict) and "error" in r[key]
    )
    return summary_line(len(records), len(degenerate), sum("error" in r for r in records), codes)


def on_a_terminal(args, timeout=120):
    """``grasptwist ARGS`` with stderr on a pseudo-terminal: (exit status, what the terminal got).

    The terminal is read as the command writes (a progress bar redrawn for long enough would
    fill its buffer and stop the command)."""
    import pty

    main, child = pty.openpty()
    proc = subprocess.Popen(entry_point() + [str(a) for a in args], stderr=child)
    os.close(child)
    seen = b""
    while True:
        try:
            chunk = os.read(main, 65536)
        except OSError:  # the command closed its end
            break
        if not chunk:
            break
        seen += chunk
    os.close(main)
    return proc.wait(timeout=timeout), seen
