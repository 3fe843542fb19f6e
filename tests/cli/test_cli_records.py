"""What a new user meets on the command line: a method asked for that cannot
run, normals given outward, self-contained records (the wrist in every
format, --twist-name).  Exit codes and stderr are checked on the installed
command (a real subprocess); output contents in process, which is quicker."""

import csv
import io
import json
from types import SimpleNamespace

import numpy as np
import pytest

import grasptwist as gt
from grasptwist.engine.degeneracy import outward_normals_warning
from grasptwist.io.grasp import load_grasps
from hostile import jsonl, run, run_installed
from places import GRASPS

# Example 1's cylinder with its normals tilted out of the contacts' plane (so the tangent method resolves)
INWARD = """\
name: cyl
{wrist}contacts:
  - {{point: [1, 0, 0], normal: [-1, 0, 0.3]}}
  - {{point: [-0.5, 0.866, 0], normal: [0.5, -0.866, 0.2]}}
  - {{point: [-0.5, -0.866, 0], normal: [0.5, 0.866, 0.1]}}
twists:
  - {{name: spin, screw: [0, 0, 1, 0, 0, 0]}}
"""
NO_WRIST = gt.status_message(gt.Status.NO_WRIST)
SKIPPED = f"off-tangent skipped: no-wrist: {NO_WRIST}"
#: Every normal of ``outward.yaml`` points away from the other contacts.
OUTWARD = outward_normals_warning([True] * 3)


@pytest.fixture
def files(tmp_path):
    (tmp_path / "wrist.yaml").write_text(INWARD.format(wrist="wrist: [0, 0, 1]\n"))
    (tmp_path / "nowrist.yaml").write_text(INWARD.format(wrist=""))
    outward = INWARD.format(wrist="wrist: [0, 0, 1]\n").replace("[-1, 0, 0.3]", "[1, 0, 0.3]")
    outward = outward.replace("[0.5, -0.866, 0.2]", "[-0.5, 0.866, 0.2]").replace(
        "[0.5, 0.866, 0.1]", "[-0.5, -0.866, 0.1]"
    )
    (tmp_path / "outward.yaml").write_text(outward)
    return tmp_path


def in_process(*args):
    """``grasptwist ARGS`` run in this process, shaped as :func:`run_installed`'s result."""
    r, seconds = run(*args)
    return SimpleNamespace(returncode=r.exit_code, stdout=r.stdout, stderr=r.stderr), seconds


def where(path, twist="spin"):
    return f"{path}: grasp 'cyl'" + (f", twist '{twist}'" if twist else "")


# --------------------------------------------------------------------------
# A method asked for by name that cannot run fails; under both it is a warning.


def test_off_tangent_asked_for_on_a_grasp_without_wrist_fails_with_no_wrist(files):
    path = files / "nowrist.yaml"
    p, _ = run_installed("resolve", path, "--method", "off-tangent", "-f", "jsonl")
    assert p.returncode == 1
    [rec] = jsonl(p.stdout)
    assert rec["ok"] is False and rec["wrist"] is None and rec["warnings"] == []
    assert rec["off_tangent"] == {"error": {"code": "no-wrist", "message": NO_WRIST}}
    assert p.stderr.splitlines() == [
        f"{where(path)}: error: off-tangent: no-wrist: {NO_WRIST}",
        "1 record: 1 with a degenerate method (off-tangent: 1 no-wrist), 0 inputs failed",
    ]
    # the same in CSV, and in npz as the status no-wrist
    p, _ = in_process("resolve", path, "--method", "off-tangent", "-f", "csv")
    [row] = csv.DictReader(io.StringIO(p.stdout))
    assert p.returncode == 1 and row["ok"] == "false" and row["off_tangent_error"] == f"no-wrist: {NO_WRIST}"
    assert row["x1"] == row["y3"] == ""
    out = files / "r.npz"
    p, _ = in_process("resolve", path, "--method", "off-tangent", "-f", "npz", "-o", out)
    with np.load(out) as z:
        assert p.returncode == 1 and z["status_legend"][z["off_tangent_status"][0]] == "no-wrist"
        assert np.isnan(z["x"]).all()


@pytest.mark.parametrize("command, cli", [("check", run_installed), ("basis", in_process)])
@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_check_and_basis_fail_an_off_tangent_asked_for_without_wrist_and_warn_under_both(files, command, cli):
    path = files / "nowrist.yaml"
    p, _ = cli(command, path, "--method", "off-tangent", "-f", "jsonl")
    [rec] = jsonl(p.stdout)
    assert p.returncode == 1 and rec["ok"] is False
    assert rec["off_tangent"]["error"] == {"code": "no-wrist", "message": NO_WRIST}
    assert p.stderr.splitlines() == [
        f"{where(path, None)}: error: off-tangent: no-wrist: {NO_WRIST}",
        "1 record: 1 with a degenerate method (off-tangent: 1 no-wrist), 0 inputs failed",
    ]
    p, _ = cli(command, path, "-f", "jsonl")
    [rec] = jsonl(p.stdout)
    assert p.returncode == 0 and rec["ok"] is True and rec["off_tangent"] is None and rec["warnings"] == [SKIPPED]
    assert rec["tangent"]["conditioning"] == pytest.approx(0.0995058864995588, rel=1e-12)
    assert p.stderr.splitlines() == [f"{where(path, None)}: warning: {SKIPPED}", "1 record: all ok"]


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_under_both_the_skip_is_a_warning_and_the_tangent_result_stays(files):
    path = files / "nowrist.yaml"
    p, _ = run_installed("resolve", path, "-f", "jsonl")
    [rec] = jsonl(p.stdout)
    assert p.returncode == 0 and rec["ok"] is True and rec["off_tangent"] is None and rec["warnings"] == [SKIPPED]
    with_wrist = jsonl(in_process("resolve", files / "wrist.yaml", "-f", "jsonl")[0].stdout)[0]
    assert rec["tangent"] == with_wrist["tangent"] and with_wrist["warnings"] == []
    assert p.stderr.splitlines() == [f"{where(path)}: warning: {SKIPPED}", "1 record: all ok"]
    out = files / "r.npz"
    p, _ = run_installed("resolve", path, "-f", "npz", "-o", out)
    with np.load(out) as z:  # skipped: -1, as before
        assert p.returncode == 0 and z["off_tangent_status"].tolist() == [-1] and z["tangent_status"].tolist() == [0]
    assert p.stderr.splitlines() == [f"{where(path)}: warning: {SKIPPED}", "1 record: all ok"]


# --------------------------------------------------------------------------
# Outward normals: a warning with its code, for every command.


@pytest.mark.parametrize("command, cli", [("resolve", run_installed), ("check", in_process), ("basis", in_process)])
def test_outward_normals_get_a_warning_inward_ones_none(files, command, cli):
    path = files / "outward.yaml"
    p, _ = cli(command, path, "-f", "jsonl")
    [rec] = jsonl(p.stdout)
    assert p.returncode == 0 and rec["ok"] is True
    assert rec["warnings"] == [OUTWARD] and rec["warnings"][0].startswith(
        "outward-normals: the normals at contacts 1, "
    )
    twist = "spin" if command == "resolve" else None
    assert p.stderr.splitlines() == [f"{where(path, twist)}: warning: {OUTWARD}", "1 record: all ok"]
    p, _ = in_process(command, files / "wrist.yaml", "-f", "jsonl")
    assert p.returncode == 0 and jsonl(p.stdout)[0]["warnings"] == [] and p.stderr == "1 record: all ok\n"


def test_outward_normals_warn_in_csv_and_npz_runs_too(files):
    for fmt in ("csv", "npz"):
        p, _ = in_process("resolve", files / "outward.yaml", "-f", fmt, "-o", files / f"r.{fmt}")
        assert p.returncode == 0 and f"warning: {OUTWARD}" in p.stderr


# issue 26: a cube held on three faces, the normal at the south face reversed; it went unnoticed,
# and forces reported force closure with that finger pulling
CUBE = """\
name: cube
units: m
wrist: [0, 0, 0.2]
friction: 0.6
{weight}contacts:
  - {{name: east, point: [0.03, 0.005, 0], normal: [-1, 0, 0]}}
  - {{name: west, point: [-0.03, 0, 0.005], normal: [1, 0, 0]}}
  - {{name: south, point: [0, -0.03, 0.01], normal: [0, {sign}1, 0]}}
twists:
  - {{name: spin, angular: [0, 0, 1]}}
wrenches:
  - {{name: push, force: [0, 0, -1]}}
"""


@pytest.mark.parametrize("weight", ["", "mass: 0.1\ncenter_of_mass: [0, 0, 0]\n"], ids=["contacts", "centre"])
@pytest.mark.parametrize("command", ["check", "resolve", "forces"])
def test_one_reversed_normal_is_named_by_every_command(tmp_path, command, weight):
    path = tmp_path / "cube.yaml"
    path.write_text(CUBE.format(weight=weight, sign="-"))
    p, _ = in_process(command, path, "-f", "jsonl")
    recs = jsonl(p.stdout)
    expected = outward_normals_warning([False, False, True], ("east", "west", "south"), center=bool(weight))
    assert expected.startswith("outward-normals: the normal at contact south points away from the ")
    assert ("centre of mass" in expected) == bool(weight)
    assert p.returncode == 0 and all(rec["warnings"][0] == expected for rec in recs)
    lines = [line for line in p.stderr.splitlines() if "outward-normals" in line]
    assert len(lines) == len(recs) and all(line.endswith(f"warning: {expected}") for line in lines)
    path.write_text(CUBE.format(weight=weight, sign=""))  # the same grasp, the normal into the cube
    p, _ = in_process(command, path, "-f", "jsonl")
    assert p.returncode == 0 and "outward-normals" not in p.stdout + p.stderr


# --------------------------------------------------------------------------
# Self-contained records: the wrist in every format, twists named on the command line.


def test_every_format_carries_the_wrist(files):
    paths = [files / "wrist.yaml", files / "nowrist.yaml"]
    p, _ = in_process("resolve", *paths, "-f", "jsonl")
    assert [r["wrist"] for r in jsonl(p.stdout)] == [[0.0, 0.0, 1.0], None]
    p, _ = in_process("resolve", *paths, "-f", "csv")
    header, *rows = list(csv.reader(io.StringIO(p.stdout)))
    at = header.index("twist6") + 1
    assert header[at : at + 4] == ["c_x", "c_y", "c_z", "v1_x"]
    assert [row[at : at + 3] for row in rows] == [["0.0", "0.0", "1.0"], ["", "", ""]]
    out = files / "r.npz"
    in_process("resolve", *paths, "-f", "npz", "-o", out)
    with np.load(out) as z:
        assert z["wrist"].shape == (2, 3)
        np.testing.assert_array_equal(z["wrist"], [[0, 0, 1], [np.nan] * 3])
    p, _ = in_process("basis", *paths, "-f", "jsonl")
    assert [r["wrist"] for r in jsonl(p.stdout)] == [[0.0, 0.0, 1.0], None]


def test_a_data_set_s_wrist_rows_reach_the_records(files):
    [grasp] = load_grasps(str(files / "wrist.yaml"))
    data = files / "set.npz"
    np.savez(
        data,
        points=np.stack([grasp.points] * 2),
        normals=np.stack([grasp.normals] * 2),
        wrist=np.array([[0.5, 0, 1], [np.nan] * 3]),
    )
    p, _ = in_process("resolve", data, "--twist", "0,0,1,0,0,0", "--method", "tangent", "-f", "jsonl")
    assert p.returncode == 0 and [r["wrist"] for r in jsonl(p.stdout)] == [[0.5, 0.0, 1.0], None]
    # a wrist column gives every row a wrist: NaN there is a bad input, not a grasp without one
    p, _ = in_process("resolve", data, "--twist", "0,0,1,0,0,0", "-f", "csv")
    rows = list(csv.DictReader(io.StringIO(p.stdout)))
    assert [(r["c_x"], r["c_z"], r["ok"]) for r in rows] == [("0.5", "1.0", "true"), ("", "", "false")]
    assert rows[1]["off_tangent_error"].startswith("nonfinite-input: ")
    # a data set without one: the records say null, and off-tangent is skipped with a warning
    np.savez(data, points=np.stack([grasp.points] * 2), normals=np.stack([grasp.normals] * 2))
    p, _ = in_process("resolve", data, "--twist", "0,0,1,0,0,0", "-f", "jsonl")
    recs = jsonl(p.stdout)
    assert (
        p.returncode == 0
        and [(r["wrist"], r["off_tangent"], r["warnings"]) for r in recs] == [(None, None, [SKIPPED])] * 2
    )


def test_twist_names_pair_with_twists_in_order(files):
    path = files / "wrist.yaml"
    p, _ = in_process(
        "resolve", path, "--twist", "0,0,1,0,0,0", "--twist-name", "spin-z", "--twist", "0,0,0,0,0,1",
        "--twist-name", "lift", "-f", "jsonl",
    )  # fmt: skip
    recs = jsonl(p.stdout)
    assert p.returncode == 0 and [(r["twist"]["name"], r["twist"]["screw"]) for r in recs] == [
        ("spin-z", [0.0, 0.0, 1.0, 0.0, 0.0, 0.0]),
        ("lift", [0.0, 0.0, 0.0, 0.0, 0.0, 1.0]),
    ]
    p, _ = in_process("resolve", path, "--twist", "0, 0, 1, 0, 0, 0", "-f", "csv")
    assert [r["twist"] for r in csv.DictReader(io.StringIO(p.stdout))] == ["0,0,1,0,0,0"]  # unnamed: as written


@pytest.mark.parametrize(
    "args, message, installed",
    [
        (["--twist", "0,0,1,0,0,0", "--twist-name", "a", "--twist-name", "b"], "got 2 names for 1 twists", True),
        (["--twist-name", "a"], "got 1 names for 0 twists", False),
        (["--twist", "0,0,1,0,0,0", "--twist-name", " "], "a name is a non-empty line of printable text", False),
    ],
)
def test_twist_names_that_do_not_pair_are_a_usage_error(files, args, message, installed):
    p, _ = (run_installed if installed else in_process)("resolve", files / "wrist.yaml", *args)
    assert p.returncode == 2 and p.stdout == "" and message in p.stderr and "--twist-name" in p.stderr


def test_plot_help_says_how_to_install_matplotlib_from_a_clone():
    p, _ = run_installed("plot", "--help")
    text = " ".join(p.stdout.split())  # as one line, however the help is wrapped
    assert p.returncode == 0 and "from a clone, pip install -e '.[plot]'" in text and "grasptwist[plot]" not in text


def test_follow_fails_an_off_tangent_asked_for_without_wrist_as_resolve_does(files):
    args = ("follow", files / "nowrist.yaml", "--twist", "0,0,1,0,0,0", "--duration", "1", "--samples", "2")
    p, _ = in_process(*args, "--method", "off-tangent", "-f", "jsonl")
    samples = [r for r in map(json.loads, p.stdout.splitlines()) if "t" in r]
    assert p.returncode == 1 and [r["t"] for r in samples] == [0.0, 1.0]
    assert all(r["off_tangent"] == {"error": {"code": "no-wrist", "message": NO_WRIST}} for r in samples)
    assert not any(r["ok"] for r in samples)
    p, _ = in_process(*args, "-f", "jsonl")
    samples = [r for r in map(json.loads, p.stdout.splitlines()) if "t" in r]
    assert p.returncode == 0 and all(r["off_tangent"] is None and r["warnings"] == [SKIPPED] for r in samples)


# --------------------------------------------------------------------------
# Issue 23: --select picks a file's own twists by name


def test_select_picks_the_files_twists_by_name_in_the_order_given():
    p, _ = in_process("resolve", GRASPS / "cylinder.yaml", "--select", "lift-z", "--select", "spin-z", "-f", "jsonl")
    recs = jsonl(p.stdout)
    assert [r["twist"]["name"] for r in recs] == ["lift-z", "spin-z"]
    every = {
        r["twist"]["name"]: r for r in jsonl(in_process("resolve", GRASPS / "cylinder.yaml", "-f", "jsonl")[0].stdout)
    }
    assert recs == [every["lift-z"], every["spin-z"]]  # the same records as without --select


def test_a_grasp_without_a_selected_twist_is_one_failed_record_listing_its_twists(tmp_path):
    (tmp_path / "a.yaml").write_text((GRASPS / "cylinder.yaml").read_text())
    (tmp_path / "b.yaml").write_text((GRASPS / "polyhedron.yaml").read_text())
    p, _ = in_process("resolve", tmp_path, "--select", "spin-z", "--method", "off-tangent", "-f", "jsonl")
    good, bad = jsonl(p.stdout)
    assert p.returncode == 1 and (good["ok"], good["twist"]["name"]) == (True, "spin-z")
    assert bad["ok"] is False and bad["error"]["code"] == "unknown-twist"
    assert bad["error"]["message"] == "grasp 'polyhedron' has no twist 'spin-z' (its twists: 'diagonal-spin')"
    assert p.stderr.splitlines() == [
        f"{tmp_path / 'b.yaml'}:17:1: error: unknown-twist: {bad['error']['message']}",
        "2 records: 0 with a degenerate method, 1 input failed",
    ]


@pytest.mark.parametrize(
    "args, message",
    [
        (["--twist", "0,0,1,0,0,0"], "--twist and --twists-from replace them: give one"),
        (["--twists-from", "-"], "--twist and --twists-from replace them: give one"),
    ],
)
def test_select_with_twists_of_ones_own_is_a_usage_error(args, message):
    p, _ = in_process("resolve", GRASPS / "cylinder.yaml", "--select", "spin-z", *args)
    assert p.returncode == 2 and p.stdout == "" and message in " ".join(p.stderr.split())


def test_select_on_a_data_set_is_a_usage_error(tmp_path):
    p, _ = in_process("resolve", tmp_path / "rows.npz", "--select", "spin-z")
    assert p.returncode == 2 and "a data set's are not named" in p.stderr
