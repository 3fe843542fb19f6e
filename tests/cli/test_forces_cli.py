"""``grasptwist forces`` and check's closure (issue 19 phase 2): records, columns, data sets, errors."""

import csv
import io
import json
import math
import shutil
from pathlib import Path

import numpy as np
import pytest

import grasptwist as gt
from grasptwist.engine.forces.grasp_map import grasp_map, squeeze_forces
from grasptwist.io.grasp import read_grasps
from grasptwist.output.columns import FORCE_CSV_COLUMNS
from hostile import jsonl, run
from places import ROOT

SPHERE = str(ROOT / "grasps/sphere.yaml")
POLYHEDRON = str(ROOT / "grasps/polyhedron.yaml")
P = np.array([[1, 0, 0], [-0.5, 0.75**0.5, 0], [-0.5, -(0.75**0.5), 0]])


def records(*args):
    r, _ = run("forces", *args, "-f", "jsonl")
    return r, jsonl(r.stdout)


def by(recs, grasp, wrench=None):
    (rec,) = [r for r in recs if r.get("grasp") == grasp and (r["wrench"] or {}).get("name") == wrench]
    return rec


def test_the_bundled_ball_is_held_with_m_g_over_mu_as_the_engine_says():
    r, recs = records(SPHERE)
    assert r.exit_code == 0, r.stderr
    hold = by(recs, "sphere-equator", "hold")
    assert hold["wrench"] == {"name": "hold", "wrench": [0.0, 0.0, 9.81, 0.0, 0.0, 0.0]}
    assert hold["friction"] == [0.5, 0.5, 0.5] and hold["units"] == "m" and hold["ok"]
    grip = hold["grip"]
    # m g / mu = 19.62 N, by hand: each finger carries m g / 3 by friction at |f_t| = mu f_n
    assert grip["total_normal_force"] == pytest.approx(19.62, rel=1e-6)
    assert grip["normal_force"] == pytest.approx([6.54] * 3, rel=1e-5)
    assert grip["safety"] == 1.0
    g = read_grasps(SPHERE)[1]
    engine = gt.grip(g.points, g.normals, g.wrenches[-1].wrench, g.friction)
    np.testing.assert_allclose(grip["force"], engine.force, rtol=0, atol=1e-12)
    np.testing.assert_allclose(grip["squeeze"], engine.squeeze, rtol=0, atol=1e-12)
    np.testing.assert_allclose(hold["manipulating"]["force"], [[0, 0, 3.27]] * 3, atol=1e-12)
    f = np.array(grip["force"])
    # the grip exerts the wrench, within every cone, and is manipulating + squeezes
    np.testing.assert_allclose(grasp_map(g.points) @ f.reshape(9), [0, 0, 9.81, 0, 0, 0], atol=1e-9)
    assert all(u <= 0.5 + 1e-9 for u in grip["friction_used"])
    split = np.array(hold["manipulating"]["force"]) + squeeze_forces(g.points, np.array(grip["squeeze"]))
    np.testing.assert_allclose(split, f, atol=1e-12)
    assert hold["closure"] == {
        "force_closure": True,
        "closure_friction": pytest.approx(0, abs=1e-9),
        "epsilon": None,
        "safety": 1.0,
        "contact_model": "point",
    }
    turn = by(recs, "sphere-equator", "turn-z")
    # 0.01 N m about the vertical: |f_t| = 0.01 / (3 r) at each finger, f_n = |f_t| / mu
    assert turn["grip"]["total_normal_force"] == pytest.approx(0.01 / (0.035 * 0.5), rel=1e-5)


def test_a_grasp_without_wrench_gets_one_record_with_its_closure():
    r, recs = records(POLYHEDRON)
    (rec,) = recs
    assert rec["wrench"] is None and rec["manipulating"] is None and rec["grip"] is None
    assert rec["friction"] is None and rec["ok"] and r.exit_code == 0
    # Example 2: tan(phi) with sin(phi) = 1/sqrt(3)
    assert rec["closure"]["closure_friction"] == pytest.approx(1 / math.sqrt(2), abs=1e-6)
    assert rec["closure"]["force_closure"] is None and rec["closure"]["epsilon"] is None


def test_command_line_wrench_friction_safety_and_quality():
    r, recs = records(
        POLYHEDRON, "--wrench", "0,0,1,0,0,0", "--wrench", "1,0,0,0,0,0", "--at", "0,0,1",
        "--wrench-name", "up", "--wrench-name", "push", "--friction", "0.8", "--safety", "1.1", "--quality",
    )  # fmt: skip
    assert r.exit_code == 0, r.stderr
    up, push = recs
    assert up["wrench"]["name"] == "up" and up["friction"] == [0.8] * 3
    # moment about the origin of (1, 0, 0) at (0, 0, 1): (0, 0, 1) x (1, 0, 0) = (0, 1, 0)
    assert push["wrench"]["wrench"] == [1.0, 0.0, 0.0, 0.0, 1.0, 0.0]
    g = read_grasps(POLYHEDRON)[0]
    engine = gt.grip(g.points, g.normals, [1, 0, 0, 0, 1, 0], 0.8, safety=1.1)
    assert push["grip"]["total_normal_force"] == pytest.approx(float(engine.total_normal_force), rel=1e-12)
    assert push["grip"]["safety"] == 1.1
    assert max(push["grip"]["friction_used"]) <= 0.8 / 1.1 + 1e-9
    c = gt.forces.force_closure(g.points, g.normals, 0.8 / 1.1, quality=True)  # judged with mu / safety
    assert up["closure"]["force_closure"] is True and up["closure"]["safety"] == 1.1
    assert up["closure"]["epsilon"] == pytest.approx(float(c.epsilon), rel=1e-9) and up["closure"]["epsilon"] > 0


def test_cannot_hold_is_a_failed_record_with_its_reason(tmp_path):
    tray = tmp_path / "tray.yaml"
    tray.write_text(
        "friction: 0.5\nwrenches: [{name: pull, force: [0, 0, -1]}]\ncontacts:\n"
        + "".join(f"  - {{point: {p.tolist()}, normal: [0, 0, 1]}}\n" for p in P)
    )
    r, recs = records(tray)
    (rec,) = recs
    assert r.exit_code == 1 and not rec["ok"]
    assert rec["grip"]["error"]["code"] == "cannot-hold"
    assert "needs a finger to pull" in rec["grip"]["error"]["message"]
    assert f"{tray}: grasp 'tray', wrench 'pull': error: grip: cannot-hold: " in r.stderr
    # the proof: y . w > 0, and no finger pushing up (f_z >= 0, in its cone) has y . G f > 0
    y = np.array(rec["grip"]["error"]["certificate"])
    assert y @ [0, 0, -1, 0, 0, 0] > 0 and np.abs(y[3:]).max() < 1e-9 and y[2] < 0
    assert "; it cannot resist a force along (0, 0, 1) with a moment (0, 0, 0) about the origin" in r.stderr


def test_a_held_record_carries_its_dual_and_gap():
    _, recs = records(SPHERE)
    grip = by(recs, "sphere-equator", "hold")["grip"]
    # one more newton of lift costs 1 / mu = 2 N of grip: the dual is d total / d w
    assert grip["dual"][:3] == pytest.approx([0, 0, 2], abs=1e-6) and abs(grip["gap"]) < 1e-8


def test_collinear_contacts_hold_a_push_along_a_normal_at_its_contact(tmp_path):
    """Issue 26, item 2.6: three contacts on a line; the third pushes up at its own point alone."""
    line = tmp_path / "line.yaml"
    line.write_text(
        "friction: 0.5\ncontacts:\n  - {point: [-0.05, 0, 0], normal: [1, 0, 0]}\n"
        "  - {point: [0.05, 0, 0], normal: [-1, 0, 0]}\n  - {point: [0, 0, 0], normal: [0, 0, 1]}\n"
    )
    r, recs = records(line, "--wrench", "0,0,1,0,0,0", "--at", "0,0,0")
    (rec,) = recs
    assert r.exit_code == 0 and rec["ok"], r.stderr
    assert rec["grip"]["total_normal_force"] == pytest.approx(1.0, rel=1e-8)
    r, recs = records(line, "--wrench", "0,0,0,1,0,0")  # a moment about the line itself
    assert r.exit_code == 1 and recs[0]["grip"]["error"]["code"] == "collinear-contacts"
    y = np.array(recs[0]["grip"]["error"]["certificate"])
    assert y[3] > 0 and np.abs(y @ grasp_map(np.array([[-0.05, 0, 0], [0.05, 0, 0], [0, 0, 0]]))).max() < 1e-9


def test_a_wrench_without_friction_has_no_grip_and_says_so():
    r, recs = records(POLYHEDRON, "--wrench", "0,0,1,0,0,0")
    (rec,) = recs
    assert rec["grip"] is None and rec["manipulating"]["force"] and rec["ok"]
    assert rec["warnings"] == [
        "grip skipped: the grasp has no friction (give 'friction:' in the file or --friction MU)"
    ]


def test_a_folder_with_one_bad_file_reports_it_and_the_rest(tmp_path):
    shutil.copy(SPHERE, tmp_path / "a.yaml")
    shutil.copy(ROOT / "tests/invalid_grasps/zero-mass.yaml", tmp_path / "b.yaml")
    r, recs = records(tmp_path)
    assert r.exit_code == 1
    assert [rec.get("grasp") for rec in recs] == ["sphere-tripod", "sphere-equator", "sphere-equator", None]
    assert recs[-1]["error"]["code"] == "invalid-mass" and (recs[-1]["error"]["line"], recs[-1]["error"]["column"]) == (
        4,
        7,
    )
    assert f"{tmp_path / 'b.yaml'}:4:7: error: invalid-mass: mass: must be > 0, got 0.0" in r.stderr


def test_json_lines_from_standard_input():
    line = json.dumps(
        {"name": "ball", "friction": 0.5, "contacts": [{"point": p.tolist(), "normal": (-p).tolist()} for p in P]}
    )
    r, _ = run("forces", "-", "--wrench", "0,0,9.81,0,0,0", "-f", "jsonl", input=line + "\n")
    (rec,) = jsonl(r.stdout)
    assert rec["grip"]["total_normal_force"] == pytest.approx(19.62, rel=1e-9)


@pytest.mark.parametrize(
    "args, message",
    [
        (["--wrench", "0,0,1,0,0"], "needs 6 finite comma-separated numbers"),
        (["--wrench-name", "a"], "got 1 names for 0 wrenches"),
        (["--at", "0,0,1"], "applies to --wrench"),
        (["--friction", "-1"], "--friction"),
        (["--safety", "0.5"], "--safety"),
        (["--cone-edges", "2"], "--cone-edges"),
    ],
)
def test_bad_options_are_usage_errors(args, message):
    r, _ = run("forces", POLYHEDRON, *args)
    assert r.exit_code == 2 and r.stdout == "" and message in r.stderr


def test_csv_columns_and_values():
    r, _ = run("forces", SPHERE, ROOT / "tests/invalid_grasps/zero-mass.yaml", "-f", "csv")
    rows = list(csv.DictReader(io.StringIO(r.stdout)))
    head = r.stdout.splitlines()[0].split(",")
    assert head == FORCE_CSV_COLUMNS
    assert head[:5] == ["file", "grasp", "wrench", "ok", "error"]
    for stem in ("fm1_x", "fm3_z", "f1_x", "f3_z", "squeeze1", "squeeze3", "fn1", "fn3", "ft1", "ft3",
                 "friction_used1", "friction_used3", "total_normal_force", "grip_error", "force_closure",
                 "closure_friction", "epsilon", "f_x", "m_z", "mu1", "mu3"):  # fmt: skip
        assert stem in head
    tripod, turn, hold, bad = rows
    assert (tripod["wrench"], tripod["fm1_x"], tripod["total_normal_force"], tripod["mu1"]) == ("", "", "", "")
    assert float(tripod["closure_friction"]) == pytest.approx(0.4663, abs=1e-4) and tripod["force_closure"] == ""
    assert hold["wrench"] == "hold" and float(hold["f_z"]) == 9.81 and hold["mu2"] == "0.5"
    assert float(hold["total_normal_force"]) == pytest.approx(19.62, rel=1e-6)
    assert float(hold["fm1_z"]) == pytest.approx(3.27) and float(hold["fn3"]) == pytest.approx(6.54, rel=1e-5)
    assert (hold["ok"], hold["grip_error"], hold["force_closure"], hold["epsilon"]) == ("true", "", "true", "")
    assert bad["ok"] == "false" and bad["error"].startswith("invalid-mass: ")


def test_npz_and_parquet_data_sets_in_and_out(tmp_path):
    pytest.importorskip("pyarrow")
    import pyarrow as pa
    import pyarrow.parquet as pq

    from grasptwist.io.parquet import grasp_table

    grasps = np.stack([P, 2 * P])
    np.savez(tmp_path / "in.npz", points=grasps, normals=-grasps, wrench=[0, 0, 9.81, 0, 0, 0], friction=[0.5, 0.25])
    t = grasp_table(grasps, -grasps)
    for name, values in zip(
        ("f_x", "f_y", "f_z", "m_x", "m_y", "m_z"), np.array([[0, 0, 9.81, 0, 0, 0], [0, 0, 1, 0, 0, 0]]).T
    ):
        t = t.append_column(name, pa.array(values.astype(float)))
    for k, mu in enumerate(([0.5, 0.1], [0.5, 0.1], [0.5, 0.2]), 1):
        t = t.append_column(f"mu{k}", pa.array(mu))
    pq.write_table(t, tmp_path / "in.parquet")
    r, _ = run("forces", tmp_path / "in.npz", tmp_path / "in.parquet", "-f", "npz", "-o", tmp_path / "out.npz")
    assert r.exit_code == 0, r.stderr
    z = np.load(tmp_path / "out.npz")
    np.testing.assert_allclose(z["total_normal_force"][:2], [19.62, 39.24], rtol=1e-6)
    assert (
        z["wrench"].shape == (4, 6) and z["force"].shape == (4, 3, 3) and z["friction"][3].tolist() == [0.1, 0.1, 0.2]
    )
    assert z["grip_status"].tolist()[:2] == [0, 0] and list(z["status_legend"][[0, 20]]) == ["ok", "cannot-hold"]
    engine = gt.grip(P, -P, [0, 0, 1, 0, 0, 0], [0.1, 0.1, 0.2])
    assert z["total_normal_force"][3] == pytest.approx(float(engine.total_normal_force), rel=1e-12)
    r, _ = run("forces", tmp_path / "in.npz", "-f", "parquet", "-o", tmp_path / "out.parquet")
    out = pq.read_table(tmp_path / "out.parquet")
    statuses = ["manipulating_status", "grip_status"]
    assert [c for c in out.column_names if c not in statuses] == FORCE_CSV_COLUMNS
    assert [c for c in out.column_names if c in statuses] == statuses
    assert out.column("fn1").to_pylist() == pytest.approx([6.54, 13.08], rel=1e-5)
    assert out.column("epsilon").to_pylist() == [None, None]


def test_a_table_labels_every_number_with_its_units():
    r, _ = run("forces", SPHERE, "--digits", "2")
    text = r.stdout
    for label in (
        "manipulating force (N)",
        "grip force (N)",
        "normal (N)",
        "tangential (N)",
        "friction used",
        "of mu/s",
    ):
        assert label in text
    assert "wrench hold = force (0.00, 0.00, 9.81) N; moment (0.00, 0.00, 0.00) N m" in text
    assert "total normal force 19.62 N (safety 1)" in text and "100%" in text
    assert "closure: force closure - (no friction); closure friction 0.47" in text


def test_check_reports_closure_friction_beside_the_methods():
    r, _ = run("check", POLYHEDRON, SPHERE, "-f", "jsonl")
    poly, tripod, equator = jsonl(r.stdout)
    assert poly["closure_friction"] == pytest.approx(1 / math.sqrt(2), abs=1e-9)  # Example 2
    assert "force_closure" not in poly and "force_closure" not in tripod
    assert equator["force_closure"] is True and equator["closure_friction"] == pytest.approx(0, abs=1e-9)
    table, _ = run("check", POLYHEDRON)
    head, *rows = [line for line in table.stdout.splitlines() if line.strip() and "─" not in line]
    assert "closure mu" in head and "0.707" in rows[0]


# --- units, antipodal pairs, safety, huge friction, overflow, bad options and data sets (issues 26, 27)

MM = """name: mm
units: mm
friction: 0.5
mass: 1
center_of_mass: [5, 0, 100]
contacts:
  - {point: [35, 0, 0], normal: [-1, 0, 0]}
  - {point: [-17.5, 30.31, 0], normal: [0.5, -0.866, 0]}
  - {point: [-17.5, -30.31, 0], normal: [0.5, 0.866, 0]}
"""
ANTIPODAL = """name: antipodal
friction: 0.6
contacts:
  - {point: [0.03, 0, 0], normal: [-1, 0, 0]}
  - {point: [-0.03, 0, 0], normal: [1, 0, 0]}
  - {point: [0, 0.03, 0.01], normal: [0, -1, 0]}
wrenches: [{name: up, force: [0, 0, 1]}]
"""


def test_moments_carry_the_files_length_unit_and_gravity_is_in_metres_per_second_squared(tmp_path):
    (tmp_path / "mm.yaml").write_text(MM)
    (tmp_path / "bare.yaml").write_text(MM.replace("units: mm\n", ""))
    r, recs = records(tmp_path / "mm.yaml")
    (rec,) = recs
    # 1 kg: 9.81 N whatever the length unit (gravity is not converted); the moment -c x m g in N mm
    assert rec["units"] == "mm" and rec["wrench"]["wrench"] == pytest.approx([0, 0, 9.81, 0, -49.05, 0], abs=1e-12)
    table, _ = run("forces", tmp_path / "mm.yaml", "--digits", "2")
    assert "wrench hold = force (0.00, 0.00, 9.81) N; moment (0.00, -49.05, 0.00) N mm" in table.stdout
    table, _ = run("forces", tmp_path / "bare.yaml", "--digits", "2")
    assert "moment (0.00, -49.05, 0.00) N length" in table.stdout


def test_an_antipodal_pair_beside_a_good_file_gives_both_their_records_with_epsilon(tmp_path):
    (tmp_path / "a.yaml").write_text(ANTIPODAL)
    shutil.copy(SPHERE, tmp_path / "b.yaml")
    r, recs = records(tmp_path, "--quality")
    assert r.exit_code == 0, r.stderr
    assert [rec["grasp"] for rec in recs] == ["antipodal", "sphere-tripod", "sphere-equator", "sphere-equator"]
    anti = recs[0]
    assert anti["ok"] and anti["closure"]["force_closure"] is True and anti["closure"]["epsilon"] > 0.05
    f = np.array(anti["grip"]["force"])
    np.testing.assert_allclose(grasp_map(np.array([c["point"] for c in anti["contacts"]])) @ f.reshape(9),
                               [0, 0, 1, 0, 0, 0], atol=1e-9)  # fmt: skip


def test_antipodal_and_coincident_contacts_through_forces_and_check(tmp_path):
    (tmp_path / "a.yaml").write_text(ANTIPODAL)
    r, _ = run("check", tmp_path / "a.yaml", "-f", "jsonl")
    (rec,) = jsonl(r.stdout)
    # the contacts' plane has the normal (0, 1, -3) / sqrt(10): the third normal leaves it at
    # sin(phi) = 1 / sqrt(10), so the least friction is tan(phi) = 1/3 (the pair squeezes within it)
    assert rec["force_closure"] is True and rec["closure_friction"] == pytest.approx(1 / 3, abs=1e-9)
    (tmp_path / "same.yaml").write_text(ANTIPODAL.replace("[-0.03, 0, 0]", "[0.03, 0, 0]"))
    r, (rec,) = records(tmp_path / "same.yaml", "--quality")
    assert r.exit_code == 1 and "internal error" not in r.stderr
    assert rec["grip"]["error"]["code"] == rec["manipulating"]["error"]["code"] == "coincident-contacts"
    assert rec["closure"] == {
        "force_closure": False,
        "closure_friction": None,
        "epsilon": 0.0,
        "safety": 1.0,
        "contact_model": "point",
    }


def test_closure_is_judged_with_the_friction_the_safety_factor_leaves():
    # the tripod closes above mu = 0.4663: with mu 0.6 it does, with 0.6 / 2 it does not
    for safety, closes in (("1", True), ("2", False)):
        r, (rec, *_) = records(SPHERE, "--friction", "0.6", "--safety", safety)
        assert rec["closure"]["force_closure"] is closes and rec["closure"]["safety"] == float(safety)
        assert rec["closure"]["closure_friction"] == pytest.approx(0.4663, abs=1e-4)
    table, _ = run("forces", SPHERE, "--friction", "0.6", "--safety", "2", "--digits", "2")
    assert "closure (with mu/2): force closure no; closure friction 0.47" in table.stdout


def test_huge_and_infinite_friction_close_a_grasp_whose_closure_friction_is_finite(tmp_path):
    for mu in ("1e200", "inf"):
        r, (rec, *_) = records(SPHERE, "--friction", mu)
        assert r.exit_code == 0 and rec["closure"]["force_closure"] is True, mu
    (tmp_path / "f.yaml").write_text(Path(SPHERE).read_text().split("---")[0] + "friction: 1e200\n")
    r, (rec,) = records(tmp_path / "f.yaml")
    assert rec["friction"] == [1e200] * 3 and rec["closure"]["force_closure"] is True


def test_an_infinite_friction_is_null_in_a_record_and_inf_in_a_table(tmp_path, monkeypatch):
    monkeypatch.delenv("COLUMNS", raising=False)  # not a terminal: the table in one part, rows whole
    r, recs = records(SPHERE, "--friction", "inf")
    assert r.exit_code == 0 and [rec["friction"] for rec in recs] == [[None] * 3] * 3  # no infinity in JSON
    hold = by(recs, "sphere-equator", "hold")
    assert hold["ok"] and hold["grip"]["total_normal_force"] < 1e-9  # no limit: the weight hangs on friction alone
    flat, _ = run("forces", SPHERE, "--friction", "inf", "-f", "csv")
    assert [[row[f"mu{i}"] for i in (1, 2, 3)] for row in csv.DictReader(io.StringIO(flat.stdout))] == [["inf"] * 3] * 3
    table, _ = run("forces", SPHERE, "--friction", "inf", "--digits", "2")
    assert table.exit_code == 0 and "internal error" not in table.stderr, table.stderr
    rows = [
        line.split() for line in table.stdout.splitlines() if line.split()[:1] in (["thumb"], ["index"], ["middle"])
    ]
    assert len(rows) == 9 and all(row[1] == "inf" for row in rows)  # mu, for the closure-only record too
    assert [row[-1] for row in rows[3:]] == ["0%"] * 6  # no share of an unlimited friction is used
    (tmp_path / "f.yaml").write_text(Path(SPHERE).read_text().split("---")[0] + "friction: .inf\n")
    r, (rec,) = records(tmp_path / "f.yaml")  # a file's numbers are finite: no limit is --friction inf
    assert r.exit_code == 1 and rec["error"]["code"] == "non-finite" and rec["error"]["line"] == 47  # the line added
    assert rec["error"]["message"] == "friction: expected a finite number, got .inf"


def _numbers(x):
    if isinstance(x, dict):
        return [n for v in x.values() for n in _numbers(v)]
    if isinstance(x, list):
        return [n for v in x for n in _numbers(v)]
    return [x]


def test_an_overflowing_result_is_a_nonfinite_result_record_never_ok_with_nulls(tmp_path):
    # a moment of 1.7e308 N m on fingers 3 cm from the centre: forces near 2e309 N, beyond a double
    r, recs = records(SPHERE, "--friction", "0.5", "--wrench", "0,0,0,0,0,1.7e308", "--wrench", "0,0,0,0,0,0")
    assert r.exit_code == 1
    big, still = recs[:2]
    assert not big["ok"] and big["grip"]["error"]["code"] == big["manipulating"]["error"]["code"] == "nonfinite-result"
    assert still["ok"] and still["grip"]["friction_used"] == [0.0] * 3  # no force uses no friction
    (tmp_path / "heavy.yaml").write_text(
        ANTIPODAL.replace("wrenches: [{name: up, force: [0, 0, 1]}]", "mass: 1.5e307\ncenter_of_mass: [0, 0, 0]")
    )
    r, (heavy,) = records(tmp_path / "heavy.yaml")
    assert r.exit_code == 1 and heavy["grip"]["error"]["code"] == "nonfinite-result" and not heavy["ok"]
    assert "nonfinite-result: the result overflows double precision" in r.stderr
    # 1e300 kg: a grip of some 1e301 N is still a double, and an ok record of finite numbers
    (tmp_path / "heavy.yaml").write_text((tmp_path / "heavy.yaml").read_text().replace("1.5e307", "1e300"))
    r, (heavy,) = records(tmp_path / "heavy.yaml")
    assert r.exit_code == 0 and heavy["ok"] and 1e300 < heavy["grip"]["total_normal_force"] < 1e303
    _, recs = records(SPHERE, "--friction", "0.5", "--wrench", "1e300,0,0,0,0,0", "--wrench", "0,0,9.81,0,0,0")
    for rec in recs:  # an ok record holds only finite numbers
        assert not rec["ok"] or None not in _numbers({k: rec[k] for k in ("manipulating", "grip", "wrench")})


@pytest.mark.parametrize(
    "args, message",
    [
        (["--friction", "nan"], "Invalid value for '--friction': must be a number >= 0 (inf: no limit), got nan"),
        (["--safety", "nan"], "Invalid value for '--safety': safety must be a finite number >= 1, got nan"),
        (["--safety", "inf"], "Invalid value for '--safety': safety must be a finite number >= 1, got inf"),
        (["--quality", "--cone-edges", "1000000000"], "cone_edges must be an integer from 3 to 64, got 1000000000"),
    ],
)
def test_absurd_option_values_are_usage_errors(args, message):
    r, _ = run("forces", SPHERE, *args)
    assert r.exit_code == 2 and r.stdout == "" and message in " ".join(r.stderr.split())


def test_one_friction_for_every_row_of_an_npz(tmp_path):
    grasps = np.stack([P, 2 * P])
    np.savez(
        tmp_path / "in.npz", points=grasps, normals=-grasps, wrench=[0, 0, 9.81, 0, 0, 0], friction=np.float64(0.5)
    )
    r, recs = records(tmp_path / "in.npz")
    assert r.exit_code == 0, r.stderr
    assert [rec["friction"] for rec in recs] == [[0.5] * 3] * 2
    assert [rec["grip"]["total_normal_force"] for rec in recs] == pytest.approx([19.62] * 2, rel=1e-6)


def test_a_negative_friction_in_a_data_set_is_its_row_s_error_and_the_other_rows_keep_theirs(tmp_path):
    # issue 36: the rest of the block lost its records (one bad-dataset record for rows 1 to the end)
    grasps = np.stack([P, 2 * P, 3 * P, 4 * P])
    np.savez(tmp_path / "neg.npz", points=grasps, normals=-grasps, friction=[0.5, -1.0, 0.5, -2.0])
    np.savez(tmp_path / "good.npz", points=grasps[[0, 2]], normals=-grasps[[0, 2]], friction=[0.5, 0.5])
    r, recs = records(tmp_path / "neg.npz", SPHERE)
    assert r.exit_code == 1
    mine = [rec for rec in recs if rec["file"] == str(tmp_path / "neg.npz")]
    assert [rec.get("grasp") for rec in mine] == ["0", None, "2", None]
    assert [(rec["error"]["code"], rec["error"]["message"]) for rec in mine if not rec["ok"]] == [
        ("invalid-friction", "friction: row 1: -1.0 must be >= 0"),
        ("invalid-friction", "friction: row 3: -2.0 must be >= 0"),
    ]
    _, alone = records(tmp_path / "good.npz")
    assert [rec["closure"] for rec in mine if rec["ok"]] == [rec["closure"] for rec in alone]
    assert [rec["grasp"] for rec in recs if rec["file"] == SPHERE] == [
        "sphere-tripod",
        "sphere-equator",
        "sphere-equator",
    ]


def test_a_negative_mu_in_a_parquet_data_set_is_one_error_record(tmp_path):
    pytest.importorskip("pyarrow")
    import pyarrow as pa
    import pyarrow.parquet as pq

    from grasptwist.io.parquet import grasp_table

    grasps = np.stack([P, 2 * P])
    pq.write_table(grasp_table(grasps, -grasps).append_column("mu", pa.array([0.5, -2.0])), tmp_path / "neg.parquet")
    r, recs = records(tmp_path / "neg.parquet", POLYHEDRON)
    assert r.exit_code == 1 and [rec.get("grasp") for rec in recs] == ["0", None, "polyhedron"]
    assert recs[1]["error"]["message"] == "friction: row 1: -2.0 must be >= 0"


ROD = (
    "friction: 0.5\ncontacts:\n  - {point: [-0.05, 0, 0], normal: [1, 0, 0], model: soft, torsion: 0.01}\n"
    "  - {point: [0.05, 0, 0], normal: [-1, 0, 0], model: soft, torsion: 0.01}\n"
    "  - {point: [0, 0, 0], normal: [0, 0, 1], model: point}\nwrenches:\n  - wrench: [0, 0, 1, 0.004, 0, 0]\n"
)  # the forces guide's rod: two soft pads pinching along x, a point contact from below, a twist about x


def test_soft_pads_twist_a_rod_point_contacts_cannot_and_contact_point_makes_them_points(tmp_path):
    """Issue 39: a grasp file's soft contacts; the grip record says its contact model and each torsion. With a
    soft contact the record's ok is its grip's (the point contacts' G^+ w a warning); --contact's default is the
    files' contacts, and --contact point makes a file's soft contacts points."""
    rod = tmp_path / "rod.yaml"
    rod.write_text(ROD)
    r, (rec,) = records(rod)
    # soft pads close the line with any friction: the closure record says its model
    assert rec["closure"]["force_closure"] is True and rec["closure"]["contact_model"] == "soft"
    assert rec["closure"]["closure_friction"] < 1e-6
    # the manipulating forces are the point contacts' split (G^+ w), which the line still lacks: null and a
    # warning, not the record's failure: the soft grip holds, the record is ok (exit 0, no error line)
    assert rec["manipulating"] is None and "error" not in rec["grip"] and rec["ok"] is True and r.exit_code == 0
    assert rec["warnings"] == [
        "manipulating: collinear-contacts: the contacts are collinear, so no finger forces make a moment about "
        "their line (rank G < 6) (G^+ w of point contacts, not the soft ones': the record's ok is its grip's)"
    ]
    assert "error:" not in r.stderr and "1 record: all ok" in r.stderr
    points, normals = [[-0.05, 0, 0], [0.05, 0, 0], [0, 0, 0]], [[1, 0, 0], [-1, 0, 0], [0, 0, 1]]
    engine = gt.grip(points, normals, [0, 0, 1, 0.004, 0, 0], 0.5, torsion=[0.01, 0.01, 0])
    assert rec["grip"]["contact_model"] == "soft" and rec["grip"]["squeeze"] is None
    assert rec["grip"]["total_normal_force"] == pytest.approx(float(engine.total_normal_force), rel=1e-12)
    assert rec["grip"]["total_normal_force"] == pytest.approx(1.6928203230, rel=1e-9)  # the guide's 1.6928 N
    assert rec["grip"]["torsion"] == pytest.approx([0.002, -0.002, 0], abs=1e-9)
    # --contact point: every contact a point contact, which cannot twist the rod (as before: not ok, exit 1)
    r, (point,) = records(rod, "--contact", "point")
    assert r.exit_code == 1 and point["ok"] is False and point["grip"]["error"]["code"] == "collinear-contacts"
    assert point["closure"]["force_closure"] is False and point["closure"]["contact_model"] == "point"
    assert point["manipulating"]["error"]["code"] == "collinear-contacts"  # point contacts: an error, as before
    # check's closure too: the file's soft pads close the line, --contact point does not
    (rec,) = jsonl(run("check", rod, "-f", "jsonl", "--contact", "point")[0].stdout)
    assert rec["force_closure"] is False and "contact_model" not in rec  # as a point file's record
    assert "[default: the files' (model: soft, else point)]" in " ".join(run("forces", "--help")[0].stdout.split())
    _, recs = records(SPHERE)  # point contacts say so, with no torsion
    grip = by(recs, "sphere-equator", "hold")["grip"]
    assert grip["contact_model"] == "point" and grip["torsion"] == [0.0, 0.0, 0.0]


def test_a_soft_grip_s_table_says_soft_and_its_torsions_and_csv_leaves_its_squeezes_empty(tmp_path):
    """--contact soft --torsion E makes every contact soft; the table says so where point contacts' says their
    squeezes, and CSV leaves a cell that does not apply empty (never nan) and says each row's contact_model."""
    line = tmp_path / "line.yaml"  # the rod's contacts, all points
    line.write_text(ROD.replace("model: soft, torsion: 0.01", "model: point"))
    r, _ = run("forces", line, "--contact", "soft", "--torsion", "0.01", "--digits", "3")
    shown = " ".join(r.stdout.split())  # as wide as the terminal: lines may wrap
    assert r.exit_code == 0 and "closure (soft contacts): force closure yes" in shown
    assert "total normal force 1.693 N (safety 1); soft contacts, torsions (0.002, -0.002, 0.000) N length" in shown
    assert "collinear contacts)" not in shown
    rod = tmp_path / "rod.yaml"
    rod.write_text(ROD)
    r, _ = run("forces", rod, "-f", "csv")
    (cell,) = csv.DictReader(io.StringIO(r.stdout))
    assert list(cell)[-1] == "contact_model" and cell["contact_model"] == "soft" and cell["ok"] == "true"
    assert [cell[f"squeeze{i}"] for i in (1, 2, 3)] == ["", "", ""] and cell["grip_error"] == ""
    assert cell["fm1_x"] == "" and float(cell["total_normal_force"]) == pytest.approx(1.6928203230, rel=1e-9)
    # point contacts on a line lifted: no three squeezes either, an empty cell (not nan)
    r, _ = run("forces", line, "--wrench", "0,0,1,0,0,0", "-f", "csv")
    (cell,) = csv.DictReader(io.StringIO(r.stdout))
    assert cell["contact_model"] == "point" and cell["ok"] == "true" and float(cell["total_normal_force"]) > 0
    assert "nan" not in r.stdout and [cell[f"squeeze{i}"] for i in (1, 2, 3)] == ["", "", ""]


@pytest.mark.parametrize(
    "args, message",
    [
        (["--contact", "soft"], "--contact soft needs --torsion E"),
        (["--torsion", "0.01"], "give --contact soft too"),
        (["--contact", "point", "--torsion", "0.01"], "give --contact soft too"),
        (["--contact", "soft", "--torsion", "0"], "must be a finite length > 0"),
        (["--contact", "soft", "--torsion", "nan"], "must be a finite length > 0"),
        (["--contact", "hard", "--torsion", "0.01"], "--contact"),
    ],
)
def test_soft_contact_options_are_usage_errors_when_half_given(args, message):
    r, _ = run("forces", SPHERE, *args)
    assert r.exit_code == 2 and message in r.stderr and not r.stdout


def test_soft_contacts_from_a_grasp_file_and_their_errors_located(tmp_path):
    """A contact's model: soft with torsion: E (issue 39); half of it, or a bad value, is a located error."""
    good = tmp_path / "soft.yaml"
    good.write_text(ROD)  # its grip and records: test_soft_pads_twist_a_rod_point_contacts_cannot_...
    (grasp,) = read_grasps(good)
    assert grasp.torsion.tolist() == [0.01, 0.01, 0.0]
    cases = {
        "model: soft": "missing-key: contacts[0].torsion",
        "torsion: 0.01": "missing-key: contacts[0].model",
        "model: point, torsion: 0.01": "conflicting-keys: contacts[0].model: a torsion is a soft contact's",
        "model: hard, torsion: 0.01": "invalid-contact-model: contacts[0].model: must be point or soft, got 'hard'",
        "model: soft, torsion: 0": "invalid-torsion: contacts[0].torsion: must be a length > 0",
        "model: soft, torsion: 0.01, friction: 0": "invalid-torsion: contacts[0].torsion: a soft contact needs friction",
    }
    # every soft contact without friction is located, as every bad torsion is
    both = tmp_path / "both.yaml"
    both.write_text(
        "friction: 0\ncontacts:\n  - {point: [-0.05, 0, 0], normal: [1, 0, 0], model: soft, torsion: 0.01}\n"
        "  - {point: [0.05, 0, 0], normal: [-1, 0, 0], model: soft, torsion: 0.01}\n"
        "  - {point: [0, 0, 0], normal: [0, 0, 1]}\n"
    )
    r, _ = run("forces", both)
    assert r.exit_code == 1 and "both.yaml:3:" in r.stderr and "both.yaml:4:" in r.stderr, r.stderr
    assert "contacts[0].torsion: a soft contact needs friction" in r.stderr and "contacts[1].torsion" in r.stderr
    assert "contacts[2]" not in r.stderr  # a point contact needs none
    # the same where every contact gives its own friction and the grasp none (a trial: it had been solved as
    # mixed-frictionless, and all three soft ones as cannot-hold)
    own = tmp_path / "own.yaml"
    own.write_text(
        "contacts:\n  - {point: [-0.05, 0, 0], normal: [1, 0, 0], model: soft, torsion: 0.01, friction: 0}\n"
        "  - {point: [0.05, 0, 0], normal: [-1, 0, 0], friction: 0.5}\n  - {point: [0, 0, 0], normal: [0, 0, 1], friction: 0.5}\n"
    )
    r, _ = run("forces", own)
    assert r.exit_code == 1 and "own.yaml:2:" in r.stderr and "contacts[0].torsion: a soft contact needs" in r.stderr
    assert not r.stdout
    for keys, message in cases.items():
        bad = tmp_path / "bad.yaml"
        bad.write_text(
            f"friction: 0.5\ncontacts:\n  - {{point: [-0.05, 0, 0], normal: [1, 0, 0], {keys}}}\n"
            "  - {point: [0.05, 0, 0], normal: [-1, 0, 0]}\n  - {point: [0, 0, 0], normal: [0, 0, 1]}\n"
        )
        r, _ = run("forces", bad)
        assert r.exit_code == 1 and "bad.yaml:3:" in r.stderr and message in r.stderr, r.stderr


def test_check_judges_closure_with_soft_contacts_and_says_the_model(tmp_path):
    """Issue 39: check's closure with a grasp file's soft contacts, or --contact soft --torsion E for every contact;
    soft records say their contact_model (point grasps' are as before: tests/golden/check.jsonl); soft needs friction."""
    line = tmp_path / "line.yaml"
    line.write_text(
        "friction: 0.5\ncontacts:\n  - {point: [-0.05, 0, 0], normal: [1, 0, 0], model: soft, torsion: 0.01}\n"
        "  - {point: [0.05, 0, 0], normal: [-1, 0, 0], model: soft, torsion: 0.01}\n"
        "  - {point: [0, 0, 0], normal: [0, 0, 1]}\n"
    )
    (rec,) = jsonl(run("check", line, "-f", "jsonl")[0].stdout)
    assert rec["force_closure"] is True and rec["contact_model"] == "soft" and rec["closure_friction"] < 1e-6
    soft = jsonl(run("check", SPHERE, "-f", "jsonl", "--contact", "soft", "--torsion", "0.005")[0].stdout)
    assert [s["contact_model"] for s in soft] == ["soft", "soft"]
    tripod = read_grasps(SPHERE)[0]
    expected = gt.forces.force_closure(tripod.points, tripod.normals, torsion=0.005).closure_friction
    assert soft[0]["closure_friction"] == pytest.approx(float(expected), rel=1e-12)
    point = gt.forces.force_closure(tripod.points, tripod.normals).closure_friction  # golden/check.jsonl's
    assert soft[0]["closure_friction"] <= float(point)
    r, _ = run("forces", SPHERE, "--contact", "soft", "--torsion", "0.01", "--friction", "0")
    assert r.exit_code == 2 and "soft contacts need friction" in r.stderr and not r.stdout


class _LongLoad:
    """``threading.Timer`` for a load that outlasts the notice's time: ``start()`` says the notice at once;
    ``started`` counts the timers started (none: no notice could come)."""

    started: list = []

    def __init__(self, interval, function):
        self.function, self.daemon = function, False

    def start(self):
        self.started.append(self.function)
        self.function()

    def cancel(self):
        pass


def test_a_first_grip_that_compiles_long_is_said_once_on_stderr_and_not_with_quiet(monkeypatch):
    """A fresh install's first grip compiles numba's kernel (about a minute): forces says so, as synthesize does,
    through the kernel's first load (engine.hooks), here a load that outlasts the notice's time."""
    import threading

    from grasptwist.engine import hooks
    from grasptwist.engine.forces import compiled

    loads = []

    def kernel():  # the first load, watched as the real one is, then the numpy path
        if not loads:
            loads.append(True)
            with hooks.first_load():
                pass

    monkeypatch.setattr(threading, "Timer", _LongLoad)
    monkeypatch.setattr(_LongLoad, "started", [])
    monkeypatch.setattr(compiled, "kernel", kernel)
    r, recs = records(SPHERE, "-j", "1")
    assert r.exit_code == 0 and recs, r.stderr
    assert r.stderr.count("compiling the grip's numba kernels, once per install") == 1
    assert "--seconds" not in r.stderr  # synthesize's budget is no part of forces
    loads.clear()
    r, _ = records(SPHERE, "-j", "1", "-q")
    assert r.exit_code == 0 and "compiling" not in r.stderr and len(_LongLoad.started) == 1  # -q: no timer


def test_one_command_says_its_compile_once_however_many_first_loads_it_has(monkeypatch, capsys):
    """A fresh install's forces run of point and soft grasps loads the grip's kernel, then the soft contacts'
    iterations (compiled apart): the command's notices (diagnostics.compile_notices) say one line."""
    import threading

    from grasptwist.cli import diagnostics

    monkeypatch.setattr(threading, "Timer", _LongLoad)
    monkeypatch.setattr(_LongLoad, "started", [])
    notices = diagnostics.compile_notices(False)
    for _ in range(2):
        with notices():
            pass
    said = [line for line in capsys.readouterr().err.splitlines() if "compiling" in line]
    assert len(said) == 1 and said[0].startswith("grasptwist: compiling the grip's numba kernels")
    assert len(_LongLoad.started) == 1  # the second load's timer never started


def test_the_kernels_first_load_runs_inside_the_callers_watch(monkeypatch):
    """compiled.kernel() loads the kernel and makes its first grip inside engine.hooks.first_load (a fake kernel
    module here: no numba)."""
    import contextlib
    import sys
    import types

    from grasptwist.engine import hooks
    from grasptwist.engine.forces import compiled

    fake = types.ModuleType("grasptwist.engine.forces.kernel")
    monkeypatch.setitem(sys.modules, "grasptwist.engine.forces.kernel", fake)
    monkeypatch.setattr(compiled, "_state", {"on": True, "module": None})
    events = []
    monkeypatch.setattr(compiled, "_first_grip", lambda module: events.append("first grip"))

    @contextlib.contextmanager
    def watch():
        events.append("watch on")
        yield
        events.append("watch off")

    with hooks.watching_first_load(watch):
        assert compiled.kernel() is fake and compiled.kernel() is fake  # loaded once
    assert events == ["watch on", "first grip", "watch off"]


def test_threads_that_need_the_kernel_at_once_load_it_once(monkeypatch):
    """A second thread that needs the kernel while the first loads it waits for that load (a Dask worker's
    threads), and neither loads it again (a fake kernel module: no numba)."""
    import sys
    import threading
    import types

    from grasptwist.engine.forces import compiled

    fake = types.ModuleType("grasptwist.engine.forces.kernel")
    monkeypatch.setitem(sys.modules, "grasptwist.engine.forces.kernel", fake)
    monkeypatch.setattr(compiled, "_state", {"on": True, "module": None})
    loads, entered, release, got = [], threading.Event(), threading.Event(), []

    def first_grip(module):  # the first thread's load, held open until the second thread has come
        loads.append(threading.current_thread().name)
        entered.set()
        release.wait(10)

    monkeypatch.setattr(compiled, "_first_grip", first_grip)
    threads = [threading.Thread(target=lambda: got.append(compiled.kernel()), name=f"t{i}") for i in range(2)]
    threads[0].start()
    assert entered.wait(10)
    threads[1].start()
    threads[1].join(0.3)  # without the lock it would be loading again by now
    release.set()
    for t in threads:
        t.join(10)
    assert loads == ["t0"] and got == [fake, fake]


@pytest.mark.parametrize(
    ("args", "module", "what"),
    [
        (("forces", SPHERE, "--contact", "soft", "--torsion", "0.01", "--quality"), "scipy", "--quality"),
        (("synthesize", SPHERE, "--friction", "0.5", "--quality"), "scipy", "--quality"),
        (("synthesize", SPHERE, "--friction", "0.5", "--objective", "epsilon"), "scipy", "--objective epsilon"),
        (("synthesize", SPHERE, "--friction", "0.5", "--simulate"), "mujoco", "--simulate"),
    ],
    ids=["forces-quality", "synthesize-quality", "synthesize-epsilon", "synthesize-simulate"],
)
def test_an_option_whose_extra_is_missing_is_one_line_and_exit_2(monkeypatch, args, module, what):
    """A trial's finding: these had ended in a traceback (the extra was required while typer parsed the
    command, outside the command's one place for ways to end); now one line, as -f parquet's and simulate's."""
    from grasptwist import extras

    found = extras.import_module

    def missing(name):
        if name.partition(".")[0] == module:
            raise ImportError(f"No module named {module!r}")
        return found(name)

    monkeypatch.setattr(extras, "import_module", missing)
    r, _ = run(*args)
    lines = r.stderr.splitlines()
    assert r.exit_code == 2 and r.stdout == ""
    assert lines == [
        f"grasptwist: error: {what} needs {module}: pip install {extras.EXTRAS[module][0]} "
        f"(from a clone of grasptwist: pip install -e '.[{extras.EXTRAS[module][1]}]')"
    ]
