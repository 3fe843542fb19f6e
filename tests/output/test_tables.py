"""Tables and stderr for people (issue 12 items 2, 3, 7): tables that stream,
fit the terminal or ``COLUMNS`` without cutting a vector, a progress bar
that names its command and leaves error lines whole, and warnings counted
instead of flooding.  Terminal behaviour is checked on real processes
writing to a pseudo-terminal of a known width."""

from __future__ import annotations

import fcntl
import io
import os
import pty
import re
import struct
import subprocess
import sys
import termios
from pathlib import Path

import numpy as np
import orjson
import pytest
from typer.testing import CliRunner

from grasptwist.cli import app
from grasptwist.cli.diagnostics import TABLE_HINT_AT, WARNINGS_SHOWN
from grasptwist.output.table import SIZING_ROWS, CheckTableWriter, TableWriter
from grasptwist.results import KINDS
from grasptwist.run.families import COMMANDS
from places import ROOT

POLY = ROOT / "grasps" / "polyhedron.yaml"
SPHERE = ROOT / "grasps" / "sphere.yaml"
EXE = Path(sys.executable).parent / "grasptwist"
COMMAND = [str(EXE)] if EXE.exists() else [sys.executable, "-m", "grasptwist"]
ANSI = re.compile(r"\x1b\[[0-9;?]*[A-Za-z]")
# Example 2's basis screws as the polyhedron's tables print them (4 decimals)
PSI_1 = "(0.0000, 0.7071, 0.7071; 0.0000, 0.0000, 0.0000)"
SIGMA_2 = "(-0.7071, 0.0000, 0.7071; 1.4142, -1.4142, 1.4142)"
THETA_3 = "(0.0000, 0.0000, 1.0000; 2.0000, -2.0000, 0.0000)"


def _env(**extra) -> dict:
    env = {k: v for k, v in os.environ.items() if k not in ("COLUMNS", "NO_COLOR")}
    return {**env, **extra}


def in_terminal(args, columns: int = 80, env=None) -> tuple[int, str]:
    """Run grasptwist with stdout and stderr on a pseudo-terminal ``columns``
    wide; its exit status and everything it showed (``\\r\\n`` as ``\\n``)."""
    main, child = pty.openpty()
    fcntl.ioctl(child, termios.TIOCSWINSZ, struct.pack("HHHH", 40, columns, 0, 0))
    proc = subprocess.Popen(
        COMMAND + [str(a) for a in args], stdin=subprocess.DEVNULL, stdout=child, stderr=child, env=env or _env()
    )
    os.close(child)
    chunks = []
    while True:  # read as it comes: a full terminal buffer would stop the child
        try:
            chunk = os.read(main, 65536)
        except OSError:  # EIO: the child closed the terminal
            break
        if not chunk:
            break
        chunks.append(chunk)
    os.close(main)
    return proc.wait(timeout=60), b"".join(chunks).decode().replace("\r\n", "\n")


def piped(args, **env) -> subprocess.CompletedProcess:
    return subprocess.run(COMMAND + [str(a) for a in args], capture_output=True, text=True, env=_env(**env), timeout=60)


def run(*args, env=None):
    return CliRunner().invoke(app, [str(a) for a in args], env=env)


def assert_fits(text: str, columns: int):
    """Every line of ``text`` is at most ``columns`` wide and holds whole vectors only."""
    for line in ANSI.sub("", text).splitlines():
        assert len(line) <= columns, line
        assert line.count("(") == line.count(")"), f"a vector is cut: {line!r}"


# --------------------------------------------------------------------------
# 12.7 Width: the terminal's, or COLUMNS; vectors never cut


@pytest.mark.parametrize("command", ["resolve", "basis"])
@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_a_table_on_an_80_column_terminal_keeps_every_vector_on_one_line(command):
    code, shown = in_terminal([command, POLY])
    assert code == 0
    assert "\x1b[1m" in shown  # a terminal: colour
    table = ANSI.sub("", shown)
    assert_fits(table.split("1 record: all ok")[0], 80)
    for vector in (PSI_1, SIGMA_2, THETA_3):
        assert vector in table
    # the columns that did not fit come in a part of their own, the first column again
    assert re.search(r"^  i   Psi_i", table, re.M)


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_columns_sets_the_width_of_a_piped_table_and_no_columns_means_no_limit():
    narrow = piped(["resolve", POLY], COLUMNS="80").stdout
    assert_fits(narrow, 80)
    assert PSI_1 in narrow and THETA_3 in narrow
    # the title's twist goes on its own line rather than being cut
    assert narrow.splitlines()[:2] == [
        "polyhedron (grasps/polyhedron.yaml)".replace("grasps/polyhedron.yaml", str(POLY)),
        "  twist diagonal-spin = (0.5774, 0.5774, 0.5774; 0.0000, 0.0000, 0.0000)",
    ]
    wide = run("resolve", POLY, env={"COLUMNS": "400"}).stdout
    assert re.search(r"^  contact +point +normal \(unit\) +velocity T\(p_i\) +normal velocity$", wide, re.M)
    assert run("resolve", POLY, env={"COLUMNS": None}).stdout == wide  # not a terminal, no COLUMNS: no limit
    assert max(len(line) for line in wide.splitlines()) > 120


def test_digits_and_order_still_shape_the_table():
    r = run("resolve", POLY, "--digits", "2", "--order", "v-omega", env={"COLUMNS": "100"})
    assert r.exit_code == 0
    assert "(screws as (v; omega))" in r.stdout.splitlines()[0]
    assert "(0.00, 0.00, 0.00; 0.00, 0.71, 0.71)" in r.stdout  # Psi_1, its halves swapped
    assert_fits(r.stdout, 100)


# --------------------------------------------------------------------------
# 12.7 The progress bar: names its command, leaves error lines whole


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_the_bar_names_the_command_and_error_lines_are_never_wrapped(tmp_path):
    long_name = "a-grasp-file-whose-name-alone-is-wider-than-the-terminal-it-is-checked-on.yaml"
    (tmp_path / long_name).write_text("contacts: [\n")
    (tmp_path / "poly.yaml").write_text(POLY.read_text())
    out = tmp_path / "out.jsonl"
    code, shown = in_terminal(["check", tmp_path, "-f", "jsonl", "-o", out])
    assert code == 1
    assert "grasptwist check" in shown and "resolving" not in shown
    error = f"{tmp_path / long_name}:2:1: error: yaml-syntax: invalid YAML: did not find expected node content"
    assert len(error) > 80
    # one line, however wide (after the bar's carriage return, on a line of its own)
    assert error in [line.rsplit("\r", 1)[-1] for line in ANSI.sub("", shown).split("\n")]
    assert shown.endswith("2 records: 0 with a degenerate method, 1 input failed\n")
    assert len(out.read_text().splitlines()) == 2


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_no_bar_when_the_table_itself_is_on_the_terminal(tmp_path):
    for name in ("a.yaml", "b.yaml"):
        (tmp_path / name).write_text(POLY.read_text())
    code, shown = in_terminal(["check", tmp_path])
    assert code == 0 and "grasptwist check" not in shown and "━" not in shown
    assert shown.count("ok (0.707)") == 2


# --------------------------------------------------------------------------
# 12.2 Tables stream, in constant memory, and point to the machine formats


def _check_record(i: int) -> bytes:
    return orjson.dumps(
        {
            "file": "rows.npz",
            "grasp": str(i),
            "off_tangent": {"conditioning": 0.5},
            "tangent": {"error": {"code": "normals-rank-deficient", "message": "rank < 3"}, "conditioning": 0.0},
            "warnings": [],
            "ok": False,
        }
    )


def test_a_check_table_is_written_as_its_records_come_in_fixed_columns():
    buf = io.BytesIO()
    w = CheckTableWriter(buf, contributions=COMMANDS["check"].contributions)
    for i in range(SIZING_ROWS + 500):
        w.write(_check_record(i))
    lines = buf.getvalue().decode().splitlines()
    assert len(lines) == 3 + SIZING_ROWS + 500  # blank, header, rule, every row so far: nothing held back
    w.close()
    rows = lines[3:]
    tangent = lines[1].index("   tangent") + 3
    assert all(row[tangent:].startswith("normals-rank-deficient") for row in rows)
    others = ["-"] * (len([k for k in KINDS if k.check_fields]) - 2)  # checked kinds the record does not hold
    # "-": the record has no closure_friction (the closure mu column)
    assert rows[0].split() == ["ok", "(0.5)", "normals-rank-deficient", *others, "-", "rows.npz", "0"]
    assert "hand" not in lines[1]  # a kind with nothing to check (the hand) has no column
    assert lines[1].split("   ")[:2] == [
        "  off-tangent (conditioning)",
        "tangent (conditioning)",
    ]  # what ok's number is

    assert rows[-1].split()[-1] == str(SIZING_ROWS + 499)  # the grasp is last: a longer name shifts nothing


def _rows_npz(path: Path, n: int, wrist_offset: float = 1.0) -> Path:
    """``n`` copies of Example 2's polyhedron; the wrist ``wrist_offset`` off the contacts' plane."""
    points = np.tile([[0.0, 2, 2], [2, 0, 2], [2, 2, 0]], (n, 1, 1))
    wrist = np.tile(np.full(3, 4 / 3) + wrist_offset / np.sqrt(3), (n, 1))
    np.savez(path, points=points, normals=np.tile(np.eye(3), (n, 1, 1)), wrist=wrist, twist=[0, 0, 1, 0, 0, 0.0])
    return path


def test_a_long_table_points_to_the_machine_formats_once(tmp_path):
    hint = f"grasptwist: hint: more than {TABLE_HINT_AT} records: -f json, jsonl, csv, npz or parquet"
    r = run("resolve", _rows_npz(tmp_path / "many.npz", TABLE_HINT_AT + 1))
    assert r.exit_code == 0 and r.stderr.count(hint) == 1
    assert r.stdout.count("twist twist = (0.0000, 0.0000, 1.0000; 0.0000, 0.0000, 0.0000)") == TABLE_HINT_AT + 1
    assert hint not in run("resolve", _rows_npz(tmp_path / "few.npz", TABLE_HINT_AT)).stderr
    assert "hint" not in run("resolve", tmp_path / "many.npz", "-q").stderr
    assert "hint" not in run("resolve", tmp_path / "many.npz", "-f", "jsonl").stderr
    assert "hint: more than 50 records: -f json or jsonl " in run("check", tmp_path / "many.npz").stderr


# --------------------------------------------------------------------------
# 12.3 Warnings: the first few, then a count by kind


@pytest.fixture
def noisy(tmp_path) -> list[Path]:
    """Two data sets: 25 grasps whose wrist nearly lies in the contacts' plane (an
    off-tangent warning each), then 10 cylinders whose normals are nearly
    coplanar (a tangent warning each)."""
    _rows_npz(tmp_path / "a.npz", 25, wrist_offset=1e-4)
    angles = np.deg2rad([0, 120, 240])
    points = np.stack([np.cos(angles), np.sin(angles), np.zeros(3)], 1)
    normals = -points + [0, 0, 1e-4]
    np.savez(
        tmp_path / "b.npz",
        points=np.tile(points, (10, 1, 1)),
        normals=np.tile(normals, (10, 1, 1)),
        wrist=np.tile([0, 0, 1.0], (10, 1)),
        twist=[0, 0, 1, 0, 0, 0.0],
    )
    return [tmp_path / "a.npz", tmp_path / "b.npz"]


def test_warnings_summary_prints_the_first_then_counts_the_rest_by_kind(noisy):
    r = run("resolve", *noisy, "-f", "jsonl")
    lines = r.stderr.splitlines()
    assert r.exit_code == 0 and len(r.stdout.splitlines()) == 35
    assert [line for line in lines if ": warning: " in line] == lines[:WARNINGS_SHOWN]
    assert all("off-tangent basis is nearly degenerate (conditioning 5.3e-05 < 0.001)" in x for x in lines[:20])
    assert lines[WARNINGS_SHOWN:] == [
        "grasptwist: 15 more warnings not shown (--warnings all): "
        "10 tangent basis is nearly degenerate, 5 off-tangent basis is nearly degenerate",
        "35 records: all ok",
    ]


@pytest.mark.parametrize("command", ["resolve", "basis", "check"])
def test_warnings_all_none_and_quiet(noisy, command):
    every = run(command, *noisy, "-f", "jsonl", "--warnings", "all").stderr.splitlines()
    assert len(every) == 36 and sum(": warning: " in x for x in every) == 35
    assert run(command, *noisy, "-f", "jsonl", "--warnings", "none").stderr == "35 records: all ok\n"
    assert run(command, *noisy, "-f", "jsonl", "-q").stderr == ""
    assert run(command, *noisy, "--warnings", "sometimes").exit_code == 2


def test_a_renderer_may_return_rich_groups_and_renderables():
    from rich.console import Group
    from rich.panel import Panel
    from rich.text import Text

    from grasptwist.output.table import Grid, TableWriter

    buf = io.BytesIO()
    w = TableWriter(buf, width=40)
    grid = Grid()
    grid.add_column("joint")
    grid.add_column("rate", justify="right")
    grid.add_row("[/]knuckle", "0.2500")
    lines = []
    w.add(lines, Group(Text("hand: joint rates", style="bold"), grid))
    assert [line for line in lines if line] == [
        "hand: joint rates",
        "  joint          rate",
        " " + "─" * 21,
        "  [/]knuckle   0.2500",
    ]
    w.add(lines, Panel(grid))  # rich draws it, the grid inside too
    panel = buf.getvalue().decode()
    assert "│   [/]knuckle   0.2500" in panel and max(len(x) for x in panel.splitlines()) == 40


# --------------------------------------------------------------------------
# Issue 23: one naming of fingers (by contact), in sentences that agree in number

HAND = ROOT / "grasps" / "three-finger-hand.yaml"


def test_every_line_names_a_finger_by_its_contact_and_the_hand_table_shows_the_hands_name_once():
    out = run("resolve", HAND, env={"COLUMNS": "300"}).stdout
    prose = [line for line in out.splitlines() if "finger" in line and not line.startswith(" ")]
    assert "finger 3 is moved by: off-tangent Sigma_3 Psi_1 Psi_2; tangent Theta_1 Theta_2 Sigma_3" in prose
    assert "off-tangent: Sigma part: fingers 1, 2 and 3 each move alone, about the line through the other two." in prose
    assert any(
        line.startswith("verdict: not realisable by tangent sliding alone: fingers 1, 2 and 3 must") for line in prose
    )
    assert not any(name in line for line in prose for name in ("east", "west", "south"))
    (row,) = [line.split() for line in out.splitlines() if "south.1" in line]
    assert row[:3] == ["3", "south", "south.1"]  # finger (its contact), the hand's name, the joint


def test_verdicts_use_the_contacts_names_and_agree_in_number():
    from grasptwist.output.table import OffTangentTable, TangentTable

    names = ["thumb", "index", "middle"]
    one = {"moves": [[0], [], [], [], [], []], "about_wrist": False}  # Sigma_1 alone
    two = {"moves": [[], [], [], [1, 2], [0, 2], []], "about_wrist": False}  # Psi_1 and Psi_2
    assert OffTangentTable.verdict(one, names) == [
        "off-tangent: Sigma part: finger thumb moves alone, about the line through the other two."
    ]
    assert OffTangentTable.verdict(two, names)[0].startswith(
        "off-tangent: Psi part: fingers thumb and index are each held fixed in turn while"
    )
    off = {"in_tangent_planes": False, "moves": [[], [], [], [], [1], []]}  # beta_2 Sigma_2
    assert TangentTable.verdict(off, names) == [
        "verdict: not realisable by tangent sliding alone: finger index must also move off its tangent plane "
        "(the beta_i Sigma_i part)."
    ]


# --------------------------------------------------------------------------
# Issue 26.1: what people read never shows digits below round-off, which differ from CPU to CPU


def test_figures_under_the_noise_floor_print_as_under_it_and_zero_has_no_sign():
    from grasptwist.output.numbers import fmt_figure, fmt_number, fmt_vector

    assert fmt_figure(3e-16, 2) == fmt_figure(6.1e-16, 2) == fmt_figure(0.0, 2) == fmt_figure(-0.0, 2) == "< 1e-12"
    assert fmt_figure(-4e-17) == "< 1e-12"
    assert fmt_figure(2.5e-12, 2) == "2.5e-12"  # above the floor: the figure itself
    assert fmt_figure(0.32375) == "0.324"
    assert fmt_number(-0.0, 4) == fmt_number(-4e-17, 4) == "0.0000"
    assert fmt_number(-0.00005001, 4) == "-0.0001"
    assert fmt_vector([-0.0, 1e-17, -1e-17], 4) == "(0.0000, 0.0000, 0.0000)"


def test_huge_numbers_print_in_exponent_form_and_the_rest_as_before():
    from grasptwist.output.numbers import EXPONENT_FROM, fmt_number, fmt_vector

    assert fmt_number(1e300, 4) == "1.0000e+300" and fmt_number(-9.81e300, 2) == "-9.81e+300"
    assert fmt_number(12.5, 4) == "12.5000" and fmt_number(-0.0, 4) == "0.0000"
    assert fmt_number(999999.5, 1) == "999999.5" and fmt_number(EXPONENT_FROM, 1) == "1.0e+06"
    assert fmt_number(float("inf"), 4) == "inf" and fmt_number(-float("inf"), 4) == "-inf"
    assert fmt_vector([0, -0.0, 9.81e300], 4) == "(0.0000, 0.0000, 9.8100e+300)"
    assert fmt_vector([1e7, 0, 0, -0.0, 0, 2], 1) == "(1.0e+07, 0.0, 0.0; 0.0, 0.0, 2.0)"


def test_tables_and_stderr_lines_show_huge_values_in_exponent_form(tmp_path):
    (tmp_path / "heavy.yaml").write_text(SPHERE.read_text().replace("\nmass: 1\n", "\nmass: 1e300\n"))
    r = run("forces", tmp_path / "heavy.yaml")
    assert "wrench hold = force (0.0000, 0.0000, 9.8100e+300) N" in r.stdout
    r = run("forces", SPHERE, "--friction", "1e300")
    (row, *_) = [line.split() for line in r.stdout.splitlines() if line.split()[:1] == ["thumb"]]
    assert row[1] == "1.0000e+300"
    r = run("follow", tmp_path / "heavy.yaml", "--twist", "0,0,1,0,0,0", "--duration", "9e297", "--samples", "3")
    lines = r.stdout.splitlines()
    last = lines.index("summary: duration 9.0000e+297, 3 samples") - 1
    assert lines[last].startswith("9.0000e+297    0")  # the last sample's time
    assert "to t = 9.000000e+297: " in r.stderr
    # nothing in fixed point as many digits long as the number is large
    assert not re.search(r"\d{12}", r.stdout + r.stderr), re.search(r"\d{12}", r.stdout + r.stderr)


def _hand_table(record: dict) -> str:
    buf = io.BytesIO()
    w = TableWriter(buf, color=False, width=300)  # whatever COLUMNS says: one part, rows whole
    w.write(orjson.dumps(record))
    w.close()
    return buf.getvalue().decode()


def test_a_table_is_the_same_whatever_the_round_off():
    # one record as two processors could compute it: the same but for the digits under the noise
    rec = orjson.loads(run("resolve", HAND, "-f", "json").stdout)[0]
    assert [f["tip_error"] for f in rec["hand"]["fingers"]] == [0.0, 0.0, 0.0]  # an inline hand: on its contacts
    other = orjson.loads(orjson.dumps(rec))
    for f, noise in zip(other["hand"]["fingers"], (3e-16, 6.1e-16, -0.0)):
        f["residual"] += noise
        f["tip_error"] = noise
        f["joint_positions"] = [-0.0 if q == 0 else q for q in f["joint_positions"]]  # a zero come out -0.0
    assert other != rec
    ours, theirs = _hand_table(rec), _hand_table(other)
    assert ours == theirs
    (row,) = [line.split() for line in ours.splitlines() if "south.1" in line]
    # residual, conditioning, tip error: no digits under the noise
    assert row[-5:] == ["<", "1e-12", "0.382", "<", "1e-12"]
    assert "-0.0000" not in ours
