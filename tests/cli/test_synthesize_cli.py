"""``grasptwist synthesize`` (issue 31): records, formats, the grasp file every command reads back, failures."""

import csv
import io
import re

import numpy as np
import pytest

from grasptwist.io.grasp import read_grasps
from hostile import jsonl, on_a_terminal, run
from places import GRASPS

SPHERE = GRASPS / "sphere.yaml"  # two balls: 'sphere-tripod' has no friction or mass, 'sphere-equator' both
FAST = ("--candidates", "120", "-n", "2")


def test_records_carry_every_score_and_the_grasp_file_is_read_back_by_every_command(tmp_path):
    found = tmp_path / "found.yaml"
    r, _ = run("synthesize", SPHERE, "--friction", "0.5", "--mass", "1", *FAST, "-o", found, "-f", "jsonl")
    assert r.exit_code == 0, r.stderr
    recs = jsonl(r.stdout)
    assert [(x["grasp"], x["rank"]) for x in recs] == [
        (g, k) for g in ("sphere-tripod", "sphere-equator") for k in (1, 2)
    ]
    rec = recs[2]
    assert set(rec) >= {"rank", "contacts", "scores", "search"}
    assert set(rec["contacts"][0]) == {"name", "point", "normal", "surface_distance"}
    assert rec["contacts"][0]["name"] == "thumb" and rec["contacts"][0]["surface_distance"] < 1e-12
    assert set(rec["scores"]["total_normal_force"]) == {"hold", "turn-z"}  # --mass replaces the file's weight
    assert rec["scores"]["epsilon"] is None and rec["scores"]["closure_friction"] < 0.5
    assert set(rec["scores"]["conditioning"]) == {"off_tangent", "tangent"}
    assert rec["search"]["seed"] == 0 and 110 < rec["search"]["candidates"] <= 120
    assert "candidates scored in" in r.stderr
    grasps = read_grasps(found)
    assert [g.name for g in grasps] == ["sphere-tripod-1", "sphere-tripod-2", "sphere-equator-1", "sphere-equator-2"]
    np.testing.assert_allclose(grasps[2].points, [c["point"] for c in rec["contacts"]], rtol=1e-15)
    assert grasps[2].object is not None and float(grasps[2].friction[0]) == 0.5
    forces, _ = run("forces", found, "-f", "jsonl")
    assert forces.exit_code == 0, forces.stderr
    held = [x for x in jsonl(forces.stdout) if x["grasp"] == "sphere-equator-1" and x["wrench"]["name"] == "hold"]
    assert held[0]["grip"]["total_normal_force"] == pytest.approx(rec["scores"]["total_normal_force"]["hold"])
    resolved, _ = run("resolve", found, "--twist", "0,0,1,0,0,0", "-f", "jsonl")
    assert resolved.exit_code == 0 and len(jsonl(resolved.stdout)) == 4, resolved.stderr


def test_csv_has_a_row_per_grasp_and_the_table_names_them():
    r, _ = run("synthesize", SPHERE, "--friction", "0.5", "--mass", "1", *FAST, "-f", "csv")
    assert r.exit_code == 0, r.stderr
    rows = list(csv.DictReader(io.StringIO(r.stdout)))
    assert [row["rank"] for row in rows] == ["1", "2", "1", "2"]
    assert float(rows[0]["total_normal_force"]) > 0 and rows[0]["ok"] == "true"
    table, _ = run("synthesize", SPHERE, "--friction", "0.5", "--mass", "1", *FAST)
    assert "grasp 'sphere-equator'" in table.stdout and "#2  total normal force: hold" in table.stdout


def test_no_feasible_grasp_is_one_record_with_the_tightest_constraint_and_exit_1():
    r, _ = run("synthesize", SPHERE, "--friction", "0", "--mass", "1", *FAST, "-f", "jsonl")
    assert r.exit_code == 1
    recs = jsonl(r.stdout)
    assert len(recs) == 2 and not any(x["ok"] for x in recs)
    err = recs[1]["error"]
    assert err["code"] == "no-grasp" and err["constraint"] == "force_closure" and err["needed"] == 0.0
    assert re.search(r"sphere.yaml:\d+: error: no-grasp: grasp 'sphere-equator': no feasible grasp in \d+ ", r.stderr)


def test_a_file_without_object_or_friction_is_an_error_of_its_own(tmp_path):
    plain = tmp_path / "plain.yaml"
    plain.write_text(
        "contacts:\n  - {point: [1, 0, 0], normal: [-1, 0, 0]}\n  - {point: [0, 1, 0], normal: [0, -1, 0]}\n"
        "  - {point: [0, 0, 1], normal: [0, 0, -1]}\n"
    )
    r, _ = run("synthesize", plain, SPHERE, *FAST, "-f", "jsonl")
    assert r.exit_code == 1
    codes = [x["error"]["code"] for x in jsonl(r.stdout) if not x["ok"]]
    assert codes[:2] == ["no-object", "no-friction"]  # the tripod ball: no friction (nor mass)
    assert "error: no-object: grasp" in r.stderr and "Traceback" not in r.stderr


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (("--seconds", "0"), "seconds must be a positive finite number"),
        (("--min-conditioning", "2"), "min_conditioning must be a number from 0 to 1"),
        (("--mass", "-1"), "must be a finite number > 0"),
        (("--objective", "speed"), "speed"),
    ],
)
def test_bad_options_are_usage_errors(args, message):
    r, _ = run("synthesize", SPHERE, *args)
    assert r.exit_code == 2 and message in r.stderr


def test_a_grasp_file_that_cannot_be_written_is_refused_before_any_search(tmp_path):
    r, _ = run("synthesize", SPHERE, "-o", tmp_path / "missing" / "found.yaml")
    assert r.exit_code == 2 and "no folder" in r.stderr and "candidates scored" not in r.stderr
    r, _ = run("synthesize", SPHERE, "-o", SPHERE)
    assert r.exit_code == 2 and "it is the input" in r.stderr


@pytest.mark.slow  # over a second (pyarrow's import): docs/reference/development.md, Test time
def test_parquet_has_the_csv_columns(tmp_path):
    pq = pytest.importorskip("pyarrow.parquet")
    r, _ = run(
        "synthesize", SPHERE, "--friction", "0.5", "--mass", "1", *FAST, "-f", "parquet", "-o", tmp_path / "g.parquet"
    )
    assert r.exit_code == 0, r.stderr
    table = pq.read_table(tmp_path / "g.parquet")
    assert table.num_rows == 4 and table.column("rank").to_pylist() == [1, 2, 1, 2]
    assert table.column("epsilon").null_count == 4  # not asked for


def test_follow_reads_the_grasp_file_back(tmp_path):
    found = tmp_path / "found.yaml"
    r, _ = run("synthesize", SPHERE, "--friction", "0.5", "--mass", "1", *FAST, "-o", found, "-q")
    assert r.exit_code == 0, r.stderr
    follow, _ = run("follow", found, "--twist", "0,0,1,0,0,0", "--duration", "1", "--samples", "2", "-f", "jsonl")
    # two samples and a summary (its first_warning null: none) per grasp
    assert follow.exit_code == 0 and len(follow.stdout.splitlines()) == 4 * 3, follow.stderr


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_plot_draws_a_grasp_found(tmp_path):
    pytest.importorskip("matplotlib")
    found = tmp_path / "found.yaml"
    run("synthesize", SPHERE, "--friction", "0.5", "--mass", "1", *FAST, "-o", found, "-q")
    r, _ = run("plot", found, "-o", tmp_path / "g.png")
    assert r.exit_code == 0, r.stderr
    assert (tmp_path / "g.png").stat().st_size > 1000


@pytest.mark.slow  # over a second (trimesh's and libigl's imports): docs/reference/development.md, Test time
def test_a_mesh_file_with_the_command_line_s_friction_and_mass(tmp_path):
    trimesh = pytest.importorskip("trimesh")
    pytest.importorskip("igl")
    trimesh.creation.icosphere(subdivisions=1, radius=0.04).export(tmp_path / "ball.stl")
    found = tmp_path / "found.yaml"
    r, _ = run(
        "synthesize", tmp_path / "ball.stl", "--friction", "0.5", "--mass", "0.2", *FAST, "-o", found, "-f", "jsonl"
    )
    assert r.exit_code == 0, r.stderr
    (rec, *_) = jsonl(r.stdout)
    assert rec["grasp"] == "ball" and rec["scores"]["closure_friction"] < 0.5
    assert rec["scores"]["total_normal_force"]["hold"] >= 0.2 * 9.81 / np.sqrt(1.25) * (1 - 1e-9)
    (first, *_) = read_grasps(found)  # the mesh named beside the new file
    assert first.object.shape.kind == "mesh" and first.mass == pytest.approx(0.2)
    r, _ = run("synthesize", tmp_path / "ball.stl", *FAST)
    assert r.exit_code == 1 and "no-friction" in r.stderr


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_a_progress_bar_on_a_terminal_for_one_object(tmp_path):
    args = ["synthesize", SPHERE, "--friction", "0.5", "--mass", "1", "--candidates", "30000", "-n", "1"]
    code, seen = on_a_terminal([*args, "-o", tmp_path / "r.jsonl", "-f", "jsonl"])
    assert code == 0 and b"grasptwist synthesize" in seen and b"candidates scored in" in seen
    assert len((tmp_path / "r.jsonl").read_text().splitlines()) == 2
