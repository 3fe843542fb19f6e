"""Each contact's surface_distance in every format, and the normal-disagrees warning (issue 30)."""

import csv
import io
import json

import numpy as np
import pytest
from typer.testing import CliRunner

from grasptwist.cli import app

# A cube of edge 2 at the origin; contact 1 is 0.02 outside its face, contact 2's normal 14 degrees off.
GRASP = """\
name: cube
object: {box: [2, 2, 2]}
contacts:
  - {point: [1.02, 0.2, 0.3]}
  - {point: [-1, -0.4, 0.1], normal: [1, 0.25, 0]}
  - {point: [0.1, -1, 0.5]}
twists: [{angular: [0, 0, 1]}]
friction: 0.5
wrenches: [{force: [0, 0, 1]}]
"""
PLAIN = """\
name: plain
contacts:
  - {point: [1.0, 0.3, 0.4], normal: [-1, 0, 0]}
  - {point: [-1.0, -0.2, -0.1], normal: [1, 0, 0]}
  - {point: [0.2, -1.0, -0.5], normal: [0, 1, 0]}
twists: [{angular: [0, 0, 1]}]
"""
# located where the file gives that normal, named as the file's errors name a contact (issue 30's user)
WARNING = (
    "normal-disagrees: contacts[1].normal (line 5, column 38) is 14.0 degrees from the object's surface normal "
    "there (more than 10): check it, or leave it out to take the surface's"
)


@pytest.fixture
def files(tmp_path):
    (tmp_path / "cube.yaml").write_text(GRASP)
    (tmp_path / "plain.yaml").write_text(PLAIN)
    return tmp_path


def run(*args):
    return CliRunner().invoke(app, [str(a) for a in args])


def test_jsonl_records_carry_each_contacts_distance_and_the_warning(files):
    result = run("resolve", files, "-f", "jsonl", "--method", "off-tangent")
    assert result.exit_code == 1  # the plain grasp has no wrist: off-tangent fails there
    cube, plain = (json.loads(line) for line in result.stdout.splitlines())
    np.testing.assert_allclose([c["surface_distance"] for c in cube["contacts"]], [0.02, 0, 0], atol=1e-15)
    assert [c["surface_distance"] for c in plain["contacts"]] == [None, None, None]
    assert cube["warnings"] == [WARNING] and plain["warnings"] != [WARNING]
    assert f"cube.yaml: grasp 'cube', twist '1': warning: {WARNING}" in result.stderr


def test_basis_and_forces_records_carry_them_too(files):
    (basis,) = [json.loads(line) for line in run("basis", files / "cube.yaml", "-f", "jsonl").stdout.splitlines()]
    assert basis["contacts"][0]["surface_distance"] == pytest.approx(0.02) and WARNING in basis["warnings"]
    result = run("forces", files / "cube.yaml", "-f", "jsonl")
    (forces,) = [json.loads(line) for line in result.stdout.splitlines()]
    assert forces["contacts"][0]["surface_distance"] == pytest.approx(0.02) and WARNING in forces["warnings"]


def test_csv_columns_are_empty_without_an_object(files):
    result = run("resolve", files, "-f", "csv", "--method", "tangent")
    rows = list(csv.DictReader(io.StringIO(result.stdout)))
    names = ["surface_distance1", "surface_distance2", "surface_distance3"]
    assert [float(rows[0][n]) for n in names] == pytest.approx([0.02, 0, 0], abs=1e-15)
    assert [rows[1][n] for n in names] == ["", "", ""]


def test_npz_keeps_nan_rows_without_an_object(files, tmp_path):
    out = tmp_path / "out.npz"
    assert run("resolve", files, "-f", "npz", "-o", out, "--method", "tangent").exit_code == 0
    with np.load(out) as data:
        distance = data["surface_distance"]
    np.testing.assert_allclose(distance[0], [0.02, 0, 0], atol=1e-15)
    assert np.isnan(distance[1]).all()


def test_records_by_template_write_the_same_distances(files):
    """Blocks of four rows or more go by a JSON template (output/json_rows.py): rows with and
    without an object, and a warned one, each as the record builder writes it."""
    twists = "twists: [" + ", ".join(f"{{angular: [0, 0, {k}]}}" for k in range(1, 6)) + "]\n"
    for name in ("cube", "plain"):
        path = files / f"{name}.yaml"
        path.write_text(path.read_text().replace("twists: [{angular: [0, 0, 1]}]\n", twists))
    near = GRASP.replace("name: cube", "name: near").replace("0.25, 0", "0.01, 0")  # 0.6 degrees off: no warning
    (files / "near.yaml").write_text(near.replace("twists: [{angular: [0, 0, 1]}]\n", twists))
    result = run("resolve", files, "-f", "jsonl", "--method", "tangent")
    records = [json.loads(line) for line in result.stdout.splitlines()]
    assert [r["grasp"] for r in records] == ["cube"] * 5 + ["near"] * 5 + ["plain"] * 5
    for r in records:
        distances = [c["surface_distance"] for c in r["contacts"]]
        if r["grasp"] == "plain":
            assert distances == [None, None, None] and r["warnings"] == []
        else:
            np.testing.assert_allclose(distances, [0.02, 0, 0], atol=1e-15)
            assert r["warnings"] == ([WARNING] if r["grasp"] == "cube" else [])


def test_a_paths_summary_carries_the_grasps_warnings_as_read(files):
    """The object's pose and normals are the grasp's, not a sample's: follow's summary says them once."""
    text = GRASP.replace(
        "object: {box: [2, 2, 2]}", "object: {box: [2, 2, 2], pose: {rotvec: [0, 0, 6.283185307179586]}}"
    )
    (files / "cube.yaml").write_text(text + "paths: [{segments: [{duration: 1, angular: [0, 0, 1]}]}]\n")
    result = run("follow", files / "cube.yaml", "--samples", 2, "--method", "tangent", "-f", "jsonl")
    summary = json.loads(result.stdout.splitlines()[-1])
    assert summary["warnings"] == [
        "rotation-over-pi: rotation of 6.28319 (rotvec [0, 0, 6.28319], line 2, column 41) is over pi: "
        "rotations are in radians (this one is a turn of 0.0 degrees)",  # 2 pi: a whole turn
        WARNING,
    ]
