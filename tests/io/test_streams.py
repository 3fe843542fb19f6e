"""Streams through the shell (issue 15 item 5): ``resolve -`` and ``*.jsonl`` read
JSON Lines, ``--twists-from`` reads twists a line at a time, and each line's
records come out before the next line is read.

The line-by-line tests run a real ``python -m grasptwist`` behind a pipe: the
test is the producer, writes one line, and waits (with a deadline, so a hang
fails instead of blocking) for that line's record before writing the next.
"""

from __future__ import annotations

import csv
import json
import os
import select
import signal
import subprocess
import sys
import threading
import time

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from grasptwist.cli import app
from grasptwist.cli.exits import EXIT_USAGE
from grasptwist.io.grasp import read_line, read_twist_line
from grasptwist.io.lines import numbered_batches
from places import ROOT

POLY = ROOT / "grasps" / "polyhedron.yaml"
EX1 = [[1, 0, 0], [-0.5, 0.866, 0], [-0.5, -0.866, 0]]
NORMALS = [[-1, 0.1, 0.2], [0.5, -0.9, 0.1], [0.5, 0.9, 0.3]]


def grasp_line(name=None, **extra) -> str:
    doc = {"contacts": [{"point": p, "normal": n} for p, n in zip(EX1, NORMALS)], "wrist": [0, 0, 1]}
    doc["twists"] = [{"name": "spin", "angular": [0, 0, 1]}]
    if name is not None:
        doc["name"] = name
    return json.dumps({**doc, **extra})


class Filter:
    """``python -m grasptwist ARGS`` with both ends of it as pipes, in its own session."""

    def __init__(self, *args):
        env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
        self.p = subprocess.Popen(
            [sys.executable, "-m", "grasptwist", *map(str, args)],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            env=env,
            start_new_session=True,
        )
        self._pending = b""

    def send(self, line: str) -> None:
        self.p.stdin.write(line.encode() + b"\n")
        self.p.stdin.flush()

    def receive(self, timeout=20.0) -> str:
        """The next line of stdout, or a failure when none comes within ``timeout`` s."""
        deadline = time.monotonic() + timeout
        fd = self.p.stdout.fileno()
        while b"\n" not in self._pending:
            left = deadline - time.monotonic()
            if left <= 0 or not select.select([fd], [], [], left)[0]:
                self.kill()
                pytest.fail(f"no record within {timeout} s of its line (the stream waits for more input)")
            chunk = os.read(fd, 65536)
            if not chunk:
                pytest.fail(f"stdout closed; stderr: {self.p.stderr.read().decode()[-500:]}")
            self._pending += chunk
        line, self._pending = self._pending.split(b"\n", 1)
        return line.decode()

    def finish(self, timeout=20.0) -> tuple[int, str]:
        self.p.stdin.close()
        try:
            self.p.wait(timeout)
        except subprocess.TimeoutExpired:
            self.kill()
            pytest.fail(f"the run did not end within {timeout} s of its input's end")
        return self.p.returncode, self.p.stderr.read().decode()

    def kill(self):
        os.killpg(self.p.pid, signal.SIGKILL)
        self.p.wait()


def invoke(*args, input=None):
    return CliRunner().invoke(app, [str(a) for a in args], input=input)


# --------------------------------------------------------------------------
# Line by line through pipes


def test_each_grasp_line_is_answered_before_the_next_is_written():
    run = Filter("resolve", "-", "-f", "jsonl")
    run.send(grasp_line("first"))
    rec = json.loads(run.receive())
    assert (rec["grasp"], rec["twist"]["name"], rec["ok"]) == ("first", "spin", True)
    assert rec["off_tangent"]["y"] == pytest.approx([-0.4714045, -0.4714045, -0.4714045], abs=1e-4)
    run.send("")  # a blank line: no record, but it counts
    run.send('{"contacts": [1, 2]')  # not even JSON: its error, with its line number
    err = json.loads(run.receive())
    assert err["ok"] is False and err["error"]["code"] == "yaml-syntax" and err["error"]["line"] == 3
    run.send(grasp_line())  # unnamed: named after its line
    assert json.loads(run.receive())["grasp"] == "<stdin>#4"
    code, stderr = run.finish()
    assert code == 1  # a line failed; the others are all out
    assert (
        "<stdin>:3:" in stderr
        and "error: yaml-syntax" in stderr
        and "3 records: 0 with a degenerate method, 1 input failed" in stderr
    )


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_each_twist_line_is_answered_before_the_next_is_written_as_csv():
    run = Filter("resolve", POLY, "--twists-from", "-", "-f", "csv")
    run.send("[0, 0, 1, 0, 0, 0]")
    header = run.receive().split(",")
    row = dict(zip(header, *csv.reader([run.receive()])))
    assert (row["twist"], row["twist3"], row["ok"]) == ("1", "1.0", "true")
    run.send('{"name": "lift", "linear": [0, 0, 2]}')
    row = dict(zip(header, *csv.reader([run.receive()])))
    assert (row["twist"], row["twist6"], row["v1_z"]) == ("lift", "2.0", "2.0")
    run.send("[0, 0, 1]")
    row = dict(zip(header, *csv.reader([run.receive()])))
    assert row["ok"] == "false" and row["error"].startswith("vector-length: screw: expected 6 numbers, got 3")
    assert run.finish()[0] == 1


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_a_stop_signal_ends_a_waiting_stream_cleanly(signum):
    run = Filter("resolve", "-", "-f", "jsonl")
    run.send(grasp_line("a"))
    run.receive()  # it is up, and now waits for the next line
    os.killpg(run.p.pid, signum)
    try:
        run.p.wait(20)
    except subprocess.TimeoutExpired:
        run.kill()
        pytest.fail("a stop signal did not end a stream waiting for input")
    stderr = run.p.stderr.read().decode()
    assert run.p.returncode == 128 + signum
    assert stderr.splitlines() == [f"grasptwist: stopped by {signal.Signals(signum).name}"]


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_standard_input_has_no_size_limit_only_its_lines_have():
    big = "x" * 5000  # names this long make 220 lines more than 1 MiB
    lines = [grasp_line(f"{big}{i}") for i in range(220)]
    lines[100] = grasp_line("too long", units="y" * 20_000)  # a line past --max-bytes, passed over
    lines[150] = "[1, 2, 3]"
    assert sum(len(line) + 1 for line in lines) > 1 << 20
    run = Filter("resolve", "-", "-f", "jsonl", "--max-bytes", "10000", "-q")
    threading.Thread(target=lambda: (run.p.stdin.write("\n".join(lines).encode() + b"\n"), run.p.stdin.close())).start()
    out = run.p.stdout.read().decode().splitlines()
    run.p.wait(20)
    assert len(out) == 220 and run.p.returncode == 1
    recs = [json.loads(line) for line in out]
    assert [r["error"]["code"] for r in recs if not r["ok"]] == ["too-large", "not-a-mapping"]
    assert [r["error"]["line"] for r in recs if not r["ok"]] == [101, 151]
    assert recs[219]["grasp"] == f"{big}219" and recs[219]["ok"]


# --------------------------------------------------------------------------
# Files and in-process runs


def test_a_jsonl_file_reads_a_grasp_per_line_and_goes_on_after_a_bad_one(tmp_path):
    path = tmp_path / "grasps.JSONL"
    path.write_text(f'{grasp_line("a")}\n{{"contacts": []}}\n\n{grasp_line()}\n')
    r = invoke("resolve", path, "-f", "jsonl")
    recs = [json.loads(line) for line in r.stdout.splitlines()]
    assert r.exit_code == 1 and [rec["ok"] for rec in recs] == [True, False, True]
    assert recs[1]["error"] == {
        "code": "contact-count",
        "message": "contacts: expected exactly 3 contacts, got 0",
        "line": 2,
        "column": 14,
    }
    assert recs[2]["grasp"] == "grasps#4"


def test_twists_from_a_file_pair_each_twist_with_every_grasp_in_twist_order(tmp_path):
    twists = tmp_path / "twists.jsonl"
    twists.write_text(
        '[0, 0, 1, 0, 0, 0]\n{"name": "bad", "angular": [0, 0, 1], "linear": [0, 0, "1"]}\n{"screw": [0, 0, 0, 0, 0, 1]}\n'
    )
    other = tmp_path / "other.jsonl"
    other.write_text(grasp_line("other") + "\n")
    r = invoke("resolve", POLY, other, "--twists-from", twists, "-f", "jsonl", "-q")
    recs = [json.loads(line) for line in r.stdout.splitlines()]
    assert r.exit_code == 1
    assert [(rec.get("grasp"), rec.get("twist", {}).get("name")) for rec in recs] == [
        ("polyhedron", "1"),
        ("other", "1"),
        (None, None),
        ("polyhedron", "3"),
        ("other", "3"),
    ]
    assert recs[2]["error"]["code"] == "not-a-number" and recs[2]["error"]["line"] == 2
    assert recs[2]["file"] == str(twists)


def test_yaml_on_standard_input_is_still_a_grasp_file():
    r = invoke("resolve", "-", "-f", "jsonl", input="\n" + POLY.read_text() + "---\n" + POLY.read_text())
    assert (
        r.exit_code == 0 and len(r.stdout.splitlines()) == r.stdout.count('"file":"<stdin>","grasp":"polyhedron') == 2
    )


def test_twists_from_conflicts_are_usage_errors():
    r = invoke("resolve", POLY, "--twist", "0,0,1,0,0,0", "--twists-from", "-")
    assert r.exit_code == EXIT_USAGE and "give twists by --twist or by --twists-from, not both" in r.stderr
    r = invoke("resolve", "-", "--twists-from", "-")
    assert r.exit_code == EXIT_USAGE and "standard input can be read only once" in r.stderr


def test_a_line_is_placed_in_the_stream_and_named_after_it():
    (grasp,) = read_line(grasp_line().encode(), file="feed.jsonl", line=12)
    assert (grasp.name, grasp.line, grasp.document, grasp.twists[0].line) == ("feed#12", 12, 11, 12)
    (error,) = read_line(b'{"contacts": [], "contacts": []}', file="feed.jsonl", line=3, max_bytes=10)
    assert (error.code, error.line, str(error)) == (
        "too-large",
        3,
        "feed.jsonl:3: the line is longer than the size limit of 10 bytes",
    )


def test_a_twist_line_is_checked_as_a_grasp_files_twist():
    t = read_twist_line(b'{"name": "s", "screw": [1, 0, 0, 0, 0, 0]}', file="-", line=2)
    assert (t.name, t.screw.tolist(), t.line) == ("s", [1.0, 0.0, 0.0, 0.0, 0.0, 0.0], 2)
    errors = read_twist_line(b'{"angular": [0, 0], "at": 1}', file="t.jsonl", line=9)
    assert [str(e) for e in errors] == [
        "t.jsonl:9:13: angular: expected 3 numbers, got 2",
        "t.jsonl:9:27: at: expected 3 numbers, got the number 1",
    ]
    (error,) = read_twist_line(b'{"angular": [1e308, 0, 0], "at": [0, 1e308, 0]}', file="-", line=1)
    assert (error.code, error.line) == ("non-finite", 1)
    (error,) = read_twist_line(b'"spin"', file="-", line=4)
    assert error.code == "not-a-mapping" and error.message.startswith("expected a twist [wx, wy, wz, vx, vy, vz]")


@settings(max_examples=50, deadline=None)
@given(
    st.lists(
        st.one_of(st.floats(allow_nan=False, allow_infinity=False), st.integers(-(2**63), 2**63 - 1)),
        min_size=6,
        max_size=6,
    )
)
def test_a_plain_array_line_reads_as_the_same_twist_written_as_a_screw_mapping(values):
    text = json.dumps(values)
    plain = read_twist_line(text.encode(), file="-", line=1)  # a plain array: the quick way
    general = read_twist_line(f'{{"screw": {text}}}'.encode(), file="-", line=1)  # the loader's general path
    assert plain.screw.tobytes() == general.screw.tobytes() and plain.name == general.name == "1"


class Chunks:
    """A stream whose ``read1`` hands out given pieces, as a pipe does."""

    def __init__(self, pieces):
        self.pieces = list(pieces)

    def read1(self, n):
        return self.pieces.pop(0) if self.pieces else b""


@settings(max_examples=60, deadline=None)
@given(
    st.lists(st.sampled_from([b"", b" ", b"ab", b"abcdefgh", b"abcdefghijkl", b"x" * 30]), max_size=12),
    st.lists(st.integers(1, 40), min_size=1, max_size=20),
    st.integers(1, 5),
)
def test_lines_are_the_same_however_the_stream_is_cut(lines, cuts, per_batch):
    data = b"\n".join(lines)
    pieces, at = [], 0
    for k in cuts * (len(data) // sum(cuts) + 1):
        pieces.append(data[at : at + k])
        at += k
    pieces = [p for p in pieces if p]
    batches = list(numbered_batches(Chunks(pieces), 10, per_batch))
    got = [entry for batch in batches for entry in batch]
    want = [(i, line if len(line) <= 10 else line[:11]) for i, line in enumerate(lines, 1) if line.strip()]
    assert got == want and all(0 < len(b) <= per_batch for b in batches)


class Repeated:
    """A stream whose ``read1`` hands out ``piece`` ``times`` times, then ``tail``."""

    def __init__(self, piece, times, tail):
        self.piece, self.times, self.tail = piece, times, tail

    def read1(self, n):
        if self.times:
            self.times -= 1
            return self.piece
        tail, self.tail = self.tail, b""
        return tail


@pytest.mark.parametrize("max_bytes", [1 << 30, 1 << 20])
def test_a_long_line_in_small_pieces_is_assembled_once(max_bytes):
    # 16 MiB in 65,536 pieces: adding each piece to the line so far (0.3, quadratic) copies 550 GB,
    # minutes of work; joined once it is 16 MiB of copying (bench/faults.py times a 50 MB line)
    piece, times = b"x" * 256, 1 << 16
    batches = list(numbered_batches(Repeated(piece, times, b"\n[1]\n"), max_bytes, 64))
    (n, line), last = (entry for batch in batches for entry in batch)
    assert n == 1 and last == (2, b"[1]")
    assert line == (piece * times if max_bytes > len(piece) * times else piece * (max_bytes // 256) + b"x")


@pytest.mark.parametrize(
    ("stream", "json_lines"),
    [
        (Repeated(b" \n" * 128, 1 << 16, b'{"a": 1}'), True),  # 16 MiB of blanks first, looked at once each
        (Chunks([b"\xef", b"\xbb\xbf \n", b"{}"]), True),  # a BOM cut by the pipe
        (Chunks([b"\xef\xbb\xbf", b"name: x"]), False),
        (Chunks([b"\xefx{"]), False),  # not a BOM: a YAML file (whose decoding then refuses it)
    ],
)
def test_stdin_is_sniffed_past_any_blanks_and_a_bom(stream, json_lines):
    from grasptwist.io.lines import _sniff

    assert _sniff(stream, 1 << 30)[0] is json_lines


def test_a_streams_failed_rows_follow_the_warnings_rule_and_a_missing_stream_is_always_said(tmp_path):
    from grasptwist.cli.diagnostics import WARNINGS_SHOWN

    coincident = [{"point": EX1[0], "normal": n} for n in NORMALS[:2]] + [{"point": EX1[2], "normal": NORMALS[2]}]
    lines = [grasp_line(f"g{k}", contacts=coincident) for k in range(24)] + [grasp_line("fine")]
    (tmp_path / "rows.jsonl").write_text("\n".join(lines) + "\n")
    args = ["resolve", str(tmp_path / "rows.jsonl"), str(tmp_path / "gone.jsonl"), "-f", "jsonl", "--method", "tangent"]
    said = {m: CliRunner().invoke(app, [*args, "--warnings", m]) for m in ("all", "summary", "none")}
    assert said["all"].stdout == said["summary"].stdout == said["none"].stdout  # records unchanged
    gone = [line for line in said["all"].stderr.splitlines() if "gone.jsonl" in line]
    assert len(gone) == 1 and ": error: read-error: " in gone[0]
    rows = [line for line in said["all"].stderr.splitlines() if ": error: tangent: coincident-contacts" in line]
    assert len(rows) == 24 and rows[0].startswith(f"{tmp_path / 'rows.jsonl'}: grasp 'g0'")
    closing = "26 records: 24 with a degenerate method (tangent: 24 coincident-contacts), 1 input failed"
    summary = said["summary"].stderr.splitlines()
    assert summary == rows[:WARNINGS_SHOWN] + gone + [
        f"grasptwist: {24 - WARNINGS_SHOWN} more row errors not shown (--warnings all): 4 tangent coincident-contacts",
        closing,
    ]
    assert said["none"].stderr.splitlines() == gone + [closing]
