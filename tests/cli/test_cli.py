"""The command line through typer's CliRunner and the installed entry point."""

import csv
import io
import json
import os
import subprocess
import sys
from pathlib import Path

import jsonschema
import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

import grasptwist as gt
from grasptwist.cli import app
from grasptwist.io.grasp import grasp_schema
from grasptwist.output.columns import CSV_COLUMNS
from grasptwist.output.writers import JsonArray
from hostile import on_a_terminal, run_installed

# Example 2's polyhedron, with a wrist off the contacts' plane x + y + z = 4
POLY = """\
name: poly
units: m
wrist: [0, 0, 0]
contacts:
  - {name: thumb, point: [0, 2, 2], normal: [2, 0, 0]}
  - {name: index, point: [2, 0, 2], normal: [0, 1, 0]}
  - {name: middle, point: [2, 2, 0], normal: [0, 0, 1]}
twists:
  - {name: spin, angular: [0.5773502691896258, 0.5773502691896258, 0.5773502691896258], linear: [0, 0, 0]}
  - {name: lift, screw: [0, 0, 0, 0, 0, 1]}
"""
POINTS = np.array([[0, 2, 2], [2, 0, 2], [2, 2, 0]], float)
WRIST = np.zeros(3)
TWISTS = np.array([[1, 1, 1, 0, 0, 0] / np.sqrt([3, 3, 3, 1, 1, 1]), [0, 0, 0, 0, 0, 1]])
# Example 1's cylinder with radial normals: the tangent method is degenerate (rank 2)
CYL = """\
wrist: [0, 0, 1]
contacts:
  - {point: [1, 0, 0], normal: [-1, 0, 0]}
  - {point: [-0.5, 0.866, 0], normal: [0.5, -0.866, 0]}
  - {point: [-0.5, -0.866, 0], normal: [0.5, 0.866, 0]}
twists:
  - {name: spin-z, screw: [0, 0, 1, 0, 0, 0]}
"""


@pytest.fixture
def files(tmp_path):
    (tmp_path / "poly.yaml").write_text(POLY)
    (tmp_path / "cyl.yaml").write_text(CYL)
    return tmp_path


def run(*args, input=None, env=None):
    return CliRunner().invoke(app, [str(a) for a in args], input=input, env=env)


def no_nan(text):
    def refuse(name):
        raise AssertionError(f"{name} in JSON output")

    return json.loads(text, parse_constant=refuse)


def test_json_records_match_the_engine(files):
    r = run("resolve", files / "poly.yaml", "--json")
    assert r.exit_code == 0, r.stderr
    recs = no_nan(r.stdout)
    assert [x["twist"]["name"] for x in recs] == ["spin", "lift"]
    off = gt.decompose_off_tangent(POINTS, WRIST, TWISTS)
    tan = gt.decompose_tangent(POINTS, np.eye(3), TWISTS)
    for i, rec in enumerate(recs):
        assert rec["ok"] is True and rec["units"] == "m" and rec["grasp"] == "poly"
        assert list(rec) == [
            "file",
            "grasp",
            "units",
            "twist",
            "contacts",
            "wrist",
            "contact_velocity",
            "clearance",
            "off_tangent",
            "tangent",
            "warnings",
            "ok",
        ]
        assert rec["wrist"] == [0.0, 0.0, 0.0]
        assert [c["name"] for c in rec["contacts"]] == ["thumb", "index", "middle"]
        assert rec["contacts"][0]["normal"] == [1.0, 0.0, 0.0]  # normalised on load
        assert rec["off_tangent"]["x"] == off.x[i].tolist() and rec["off_tangent"]["y"] == off.y[i].tolist()
        assert rec["off_tangent"]["sigma"] == off.sigma[i].tolist()
        assert rec["tangent"]["alpha"] == tan.alpha[i].tolist() and rec["tangent"]["beta"] == tan.beta[i].tolist()
        assert rec["contact_velocity"] == gt.contact_velocities(POINTS, TWISTS[i]).tolist()
    np.testing.assert_allclose(recs[0]["tangent"]["alpha"], [0.57735] * 3, atol=1e-5)
    assert recs[0]["tangent"]["in_tangent_planes"] is True and recs[1]["tangent"]["in_tangent_planes"] is False
    assert r.stderr.strip().splitlines()[-1] == "2 records: all ok"


def test_jsonl_is_one_compact_record_per_line_equal_to_json(files):
    lines = run("resolve", files / "poly.yaml", "-f", "jsonl").stdout.splitlines()
    assert len(lines) == 2 and all(" " not in line for line in lines)
    assert [no_nan(line) for line in lines] == no_nan(run("resolve", files / "poly.yaml", "--json").stdout)


def test_csv_has_the_documented_columns_and_full_precision(files):
    r = run("resolve", files / "poly.yaml", "-f", "csv")
    rows = list(csv.DictReader(io.StringIO(r.stdout)))
    assert list(rows[0]) == CSV_COLUMNS and len(rows) == 2
    off = gt.decompose_off_tangent(POINTS, WRIST, TWISTS)
    tan = gt.decompose_tangent(POINTS, np.eye(3), TWISTS)
    for i, row in enumerate(rows):
        assert [float(row[f"x{k}"]) for k in (1, 2, 3)] == off.x[i].tolist()
        assert [float(row[f"beta{k}"]) for k in (1, 2, 3)] == tan.beta[i].tolist()
        assert row["ok"] == "true" and row["error"] == ""
    assert rows[1]["in_tangent_planes"] == "false" and float(rows[1]["v3_z"]) == 1.0


def test_order_v_omega_swaps_every_six_vector(files):
    a = no_nan(run("resolve", files / "poly.yaml", "--json").stdout)[0]
    b = no_nan(run("resolve", files / "poly.yaml", "--json", "--order", "v-omega").stdout)[0]
    swap = lambda s: s[3:] + s[:3]  # noqa: E731
    assert b["twist"]["screw"] == swap(a["twist"]["screw"])
    assert b["off_tangent"]["psi"] == [swap(s) for s in a["off_tangent"]["psi"]]
    assert b["tangent"]["theta"] == [swap(s) for s in a["tangent"]["theta"]]
    assert b["tangent"]["alpha"] == a["tangent"]["alpha"]


def test_twist_option_replaces_the_files_twists_and_at_moves_its_reference(files):
    r = run("resolve", files / "poly.yaml", "--twist", "0,0,1,0,0,0", "--at", "1,0,0", "--json")
    [rec] = no_nan(r.stdout)
    # the point (1,0,0) is still: v_origin = 0 + omega x (0 - at) = (0, -1, 0)
    assert rec["twist"] == {"name": "0,0,1,0,0,0", "screw": [0.0, 0.0, 1.0, 0.0, -1.0, 0.0]}
    r = run("resolve", files / "poly.yaml", "--twist", "1,0,0,0,0,0", "--twist", "0,1,0,0,0,0", "--json")
    assert [rec["twist"]["screw"] for rec in no_nan(r.stdout)] == [[1, 0, 0, 0, 0, 0], [0, 1, 0, 0, 0, 0]]


def test_stdin(files):
    r = run("resolve", "-", "--json", input=POLY)
    recs = no_nan(r.stdout)
    assert r.exit_code == 0 and recs[0]["file"] == "<stdin>" and len(recs) == 2


def test_a_degenerate_method_fails_its_record_but_keeps_the_other(files):
    r = run("resolve", files / "cyl.yaml", "--json")
    assert r.exit_code == 1
    [rec] = no_nan(r.stdout)
    assert rec["ok"] is False
    assert rec["tangent"] == {
        "error": {"code": "normals-rank-deficient", "message": gt.status_message(gt.Status.NORMALS_RANK_DEFICIENT)}
    }
    np.testing.assert_allclose(rec["off_tangent"]["y"], [-0.4714] * 3, atol=1e-4)
    assert "cyl.yaml: grasp 'cyl', twist 'spin-z': error: tangent: normals-rank-deficient:" in r.stderr


def test_method_selection_and_a_grasp_without_wrist(files):
    rec = no_nan(run("resolve", files / "poly.yaml", "--method", "off-tangent", "--json").stdout)[0]
    assert "tangent" not in rec and "x" in rec["off_tangent"]
    (files / "nowrist.yaml").write_text(POLY.replace("wrist: [0, 0, 0]\n", ""))
    r = run("resolve", files / "nowrist.yaml", "--json")
    rec = no_nan(r.stdout)[0]
    # under the default --method both the off-tangent method is skipped, with a warning
    assert r.exit_code == 0 and rec["off_tangent"] is None and rec["ok"] is True and rec["wrist"] is None
    skipped = "off-tangent skipped: no-wrist: " + gt.status_message(gt.Status.NO_WRIST)
    assert rec["warnings"] == [skipped]
    np.testing.assert_allclose(rec["tangent"]["alpha"], [0.57735] * 3, atol=1e-5)  # the other method as ever
    assert f"{files / 'nowrist.yaml'}: grasp 'poly', twist 'spin': warning: {skipped}" in r.stderr.splitlines()
    rec = no_nan(run("resolve", files / "poly.yaml", "--method", "tangent", "--json").stdout)[0]
    assert "off_tangent" not in rec


def test_a_grasp_without_twists_says_how_to_give_one(files):
    (files / "still.yaml").write_text(POLY.split("twists:")[0])
    r = run("resolve", files / "still.yaml", "--json")
    assert r.exit_code == 1
    [rec] = no_nan(r.stdout)
    assert rec["ok"] is False and rec["error"]["code"] == "no-twist" and "--twist" in rec["error"]["message"]
    assert run("resolve", files / "still.yaml", "--twist", "0,0,1,0,0,0").exit_code == 0


def test_a_folder_with_bad_files_reports_each_once_and_keeps_every_good_record(files):
    sub = files / "sub"
    sub.mkdir()
    (sub / "poly2.yml").write_text(POLY.replace("name: poly", "name: poly2"))
    (files / "broken.yaml").write_text("contacts: [\n")
    (sub / "two.yaml").write_text(POLY.replace("  - {name: middle, point: [2, 2, 0], normal: [0, 0, 1]}\n", ""))
    (files / "notes.txt").write_text("not a grasp")
    r = run("resolve", files, "-f", "jsonl")
    assert r.exit_code == 1
    recs = [no_nan(line) for line in r.stdout.splitlines()]
    files_seen = [Path(x["file"]).name for x in recs]
    assert files_seen == ["broken.yaml", "cyl.yaml", "poly.yaml", "poly.yaml", "poly2.yml", "poly2.yml", "two.yaml"]
    errors = [line for line in r.stderr.splitlines() if ": error: " in line]
    assert len(errors) == 3  # broken, two contacts, the degenerate cylinder
    assert any(line.startswith(f"{files / 'broken.yaml'}:2:1: error: ") for line in errors), errors
    good = [x for x in recs if x.get("grasp") == "poly"]
    alone = no_nan(run("resolve", files / "poly.yaml", "--json").stdout)
    assert good == alone
    assert r.stderr.strip().splitlines()[-1] == (
        "7 records: 1 with a degenerate method (tangent: 1 normals-rank-deficient), 2 inputs failed"
    )


def test_exit_codes_and_usage_errors(files):
    assert run("resolve", files / "poly.yaml").exit_code == 0
    assert run("resolve", files / "cyl.yaml").exit_code == 1
    r = run("resolve", files / "missing.yaml")
    assert r.exit_code == 1 and f"{files / 'missing.yaml'}: error: read-error: cannot read: no such file" in r.stderr
    for bad in (["--twist", "1,2,3"], ["--twist", "a,b,c,d,e,f"], ["--at", "1,2,3"], ["--format", "xml"], ["--bogus"]):
        r = run("resolve", files / "poly.yaml", *bad)
        assert r.exit_code == 2, (bad, r.output)
        assert "Traceback" not in r.output


def test_output_file_is_written_whole_or_not_at_all(files, monkeypatch):
    out = files / "out.json"
    assert run("resolve", files / "poly.yaml", "--json", "-o", out).exit_code == 0
    assert len(no_nan(out.read_text())) == 2
    out.unlink()
    assert run("resolve", files / "poly.yaml", "--twist", "1,2", "-o", out).exit_code == 2
    assert not out.exists()

    def explode(self, encoded):
        real(self, encoded)  # half the output is on disk when the run fails
        raise RuntimeError("disk on fire")

    real = JsonArray.write
    monkeypatch.setattr(JsonArray, "write", explode)
    r = run("resolve", files / "poly.yaml", "--json", "-o", out)
    assert r.exit_code == 1 and "internal error: RuntimeError: disk on fire" in r.stderr
    assert "Traceback" not in r.output
    assert sorted(p.name for p in files.iterdir()) == ["cyl.yaml", "poly.yaml"]  # no partial or temporary file


def test_table_rounds_to_digits_and_has_no_colour_off_a_terminal(files):
    r = run("resolve", files / "poly.yaml", "--digits", "3")
    assert r.exit_code == 0
    assert "0.577" in r.stdout and "0.5774" not in r.stdout
    assert "\x1b[" not in r.stdout
    assert "verdict: tangent sliding alone realises this twist" in r.stdout
    r = run("resolve", files / "poly.yaml", env={"NO_COLOR": "1"})
    assert "\x1b[" not in r.stdout + r.stderr


def test_basis_shows_the_products_of_eq18(files):
    r = run("basis", files / "cyl.yaml", "--method", "off-tangent", "--json")
    [rec] = no_nan(r.stdout)
    np.testing.assert_allclose(np.diag(rec["off_tangent"]["sigma_psi"]), [-1.0607] * 3, atol=1e-4)
    np.testing.assert_allclose(np.array(rec["off_tangent"]["sigma_psi"])[~np.eye(3, dtype=bool)], 0, atol=1e-12)
    table = run("basis", files / "poly.yaml").stdout
    assert "[Theta_i | Sigma_j]" in table and "1.4142" in table


def test_check_reports_without_resolving(files):
    r = run("check", files, "--json")
    assert r.exit_code == 1
    recs = {Path(x["file"]).name: x for x in no_nan(r.stdout)}
    assert recs["poly.yaml"]["ok"] is True and recs["poly.yaml"]["tangent"]["conditioning"] == pytest.approx(0.5)
    assert recs["cyl.yaml"]["tangent"]["error"]["code"] == "normals-rank-deficient"
    assert run("check", files / "poly.yaml").exit_code == 0


def test_schema_prints_the_loaders_json_schema_which_accepts_a_grasp_and_refuses_two_contacts(files):
    r = run("schema")
    assert r.exit_code == 0
    schema = no_nan(r.stdout)
    assert schema == grasp_schema()  # what the loader enforces (and test_grasp_file checks against fixtures)
    jsonschema.Draft202012Validator.check_schema(schema)
    validator = jsonschema.Draft202012Validator(schema)
    assert validator.is_valid(yaml.safe_load(POLY))
    two = yaml.safe_load(POLY.replace("  - {name: middle, point: [2, 2, 0], normal: [0, 0, 1]}\n", ""))
    assert [e.validator for e in validator.iter_errors(two)] == ["minItems"]
    assert run("schema", "-o", files / "s.json").exit_code == 0
    assert (files / "s.json").read_text() == r.stdout


@pytest.mark.parametrize("command", ["resolve", "basis", "check", "schema", "plot"])
def test_every_help_has_an_example(command):
    r = run(command, "--help")
    assert r.exit_code == 0 and ("grasptwist " + command) in r.stdout


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_installed_entry_point_in_a_subprocess(files):
    exe = Path(sys.executable).parent / "grasptwist"
    cmd = [str(exe)] if exe.exists() else [sys.executable, "-m", "grasptwist"]
    env = {k: v for k, v in os.environ.items() if k != "NO_COLOR"}
    p = subprocess.run(
        cmd + ["resolve", "-", "--json"], input=POLY, capture_output=True, text=True, env=env, timeout=60
    )
    assert p.returncode == 0, p.stderr
    assert len(no_nan(p.stdout)) == 2 and p.stderr == "2 records: all ok\n"
    p = subprocess.run(
        cmd + ["resolve", str(files / "cyl.yaml"), "-f", "csv"], capture_output=True, text=True, timeout=60
    )
    assert p.returncode == 1 and "Traceback" not in p.stderr
    assert list(csv.reader(io.StringIO(p.stdout)))[1][3] == "false"
    # stderr is a pipe here: no progress bar and no colour (the terminal's are in the next test)
    assert (
        "grasptwist resolve" not in p.stderr
        and "\x1b[" not in p.stderr
        and p.stderr.endswith(
            "1 record: 1 with a degenerate method (tangent: 1 normals-rank-deficient), 0 inputs failed\n"
        )
    )


def test_two_workers_write_exactly_what_one_writes(files):
    from grasptwist.run.pipeline import TUNING

    more = TUNING.files_per_group * TUNING.min_groups  # just enough groups for the pool
    for i in range(more):
        (files / f"more{i:03}.yaml").write_text(POLY.replace("name: poly", f"name: poly{i}"))
    (files / "more005.yaml").write_text("contacts: [\n")  # a bad file among them
    one = run("resolve", files, "-f", "jsonl", "-j", "1")
    two = run("resolve", files, "-f", "jsonl", "-j", "2")
    assert two.exit_code == one.exit_code == 1
    assert two.stdout == one.stdout and two.stderr == one.stderr
    assert len(one.stdout.splitlines()) == 2 + 1 + 2 * (more - 1) + 1  # poly, cyl, good files x 2 twists, the bad one


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_a_progress_bar_on_a_terminal(files):
    out = files / "out.jsonl"
    code, seen = on_a_terminal(["resolve", files, "-f", "jsonl", "-o", out], timeout=60)
    assert code == 1 and b"grasptwist resolve" in seen and b"3 records: 1 with a degenerate method" in seen
    assert len(out.read_text().splitlines()) == 3


def test_what_a_new_user_ran_into(files, tmp_path):
    # -o into a folder that does not exist: a usage error naming the user's path, before any work
    r = run("resolve", files / "poly.yaml", "--json", "-o", tmp_path / "missing" / "o.json")
    assert r.exit_code == 2 and f"cannot write {tmp_path / 'missing' / 'o.json'}: no folder" in r.output
    # an --at that makes the origin velocity overflow: a usage error, no numpy warning
    r = run("resolve", files / "poly.yaml", "--twist", "1e300,0,0,0,0,0", "--at", "0,1e300,1e300")
    assert r.exit_code == 2 and "the velocity of the origin overflows" in r.output and "Warning" not in r.output
    # basis and check offer only the formats they write
    assert run("basis", files / "poly.yaml", "-f", "csv").exit_code == 2
    assert run("check", files / "poly.yaml", "-f", "npz").exit_code == 2
    # --extra-point at only means something for .npy rows
    assert run("resolve", files / "poly.yaml", "--extra-point", "at").exit_code == 2
    # -h, and one record is one record
    assert run("resolve", "-h").exit_code == 0
    r = run("resolve", files / "poly.yaml", "--twist", "0,0,1,0,0,0", "-f", "jsonl")
    assert r.stderr.splitlines()[-1] == "1 record: all ok"
    # zeros are written without a sign
    assert b"-0.0" not in run("resolve", files / "cyl.yaml", "--method", "off-tangent", "--json").stdout_bytes
    # stdin is read once
    r = run("resolve", "-", "-", "-f", "jsonl", input=POLY)
    assert r.exit_code == 1 and "-: error: read-error: cannot read: standard input can be read only once" in r.stderr


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_a_reader_that_goes_away_ends_the_run_quietly_with_141(files):
    exe = Path(sys.executable).parent / "grasptwist"
    cmd = [str(exe)] if exe.exists() else [sys.executable, "-m", "grasptwist"]
    big = files / "big"
    big.mkdir()
    for i in range(300):
        (big / f"g{i:03d}.yaml").write_text(POLY)
    p = subprocess.Popen(cmd + ["resolve", str(big), "-f", "jsonl"], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    p.stdout.readline()
    p.stdout.close()  # like `| head -1`
    err = p.stderr.read()
    assert p.wait(timeout=60) == 141 and b"Traceback" not in err and b"Exception ignored" not in err


@pytest.mark.parametrize(
    "args, line",
    [
        (
            ["resolve", "x.yaml", "--twist", "1,2"],
            "Invalid value for --twist: needs 6 finite comma-separated numbers, got '1,2'",
        ),
        (["resolve", "x.yaml", "--bogus"], "No such option: --bogus"),
        (["follow", "x.yaml", "--samples", "1"], "Invalid value for '--samples': 1 is not in the range 2<=x<=1000000."),
    ],
    ids=["bad-value", "unknown-option", "out-of-range"],
)
def test_a_usage_error_is_one_line_and_exit_2(args, line):
    done, _ = run_installed(*args)
    command = f"grasptwist {args[0]}"
    assert (done.returncode, done.stdout, done.stderr) == (2, "", f"grasptwist: error: {line} (see '{command} -h')\n")


def test_the_tests_build_the_command_line_once_and_run_it_a_context_a_call():
    # tests/conftest.py: typer's CliRunner built the click group of every command at each invoke (10 ms)
    import typer.testing

    assert typer.testing._get_command(app) is typer.testing._get_command(app)
    first, again = run("check", "--bogus"), run("resolve", "--twist", "1,2", "x.yaml")
    assert (first.exit_code, again.exit_code) == (2, 2)  # the second call knows nothing of the first's
    assert "--bogus" in first.stderr and "--bogus" not in again.stderr and "--twist" in again.stderr


def test_no_command_prints_the_help_on_stdout_and_succeeds():
    done, _ = run_installed()  # so that `grasptwist | less` shows it
    assert (done.returncode, done.stderr) == (0, "")
    assert done.stdout.startswith("Usage: grasptwist [OPTIONS] COMMAND") and "resolve" in done.stdout


@pytest.mark.parametrize(
    ("text", "limit"),
    [("1e8", 100_000_000), ("4096", 4096), ("1", 1), ("2.5e3", 2500)],
)
def test_max_bytes_takes_a_whole_number_in_exponent_form_too(tmp_path, text, limit):
    grasp = tmp_path / "g.yaml"
    grasp.write_text(POLY)
    r = run("resolve", grasp, "-f", "json", "--max-bytes", text)
    if grasp.stat().st_size <= limit:
        assert r.exit_code == 0 and [rec["ok"] for rec in json.loads(r.stdout)] == [True, True]
    else:
        assert r.exit_code == 1 and json.loads(r.stdout)[0]["error"]["code"] == "too-large"


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("0", "expected a whole number of bytes, at least 1, got '0'"),
        ("1.5", "expected a whole number of bytes, at least 1, got '1.5'"),
        ("-3", "expected a whole number of bytes, at least 1, got '-3'"),
        ("nan", "expected a whole number of bytes, at least 1, got 'nan'"),
        ("lots", "expected a whole number of bytes (e.g. 1048576 or 1e6), got 'lots'"),
    ],
)
def test_max_bytes_refuses_what_is_no_byte_count(text, message):
    r = run("resolve", "-", "--max-bytes", text, input=POLY)
    assert r.exit_code == 2 and message in " ".join(r.stderr.split())
