"""Joint rates in every output: CSV qdot columns, npz arrays, data sets with --hand."""

import csv
import io
import json
from importlib.util import find_spec

import numpy as np
import pytest
from typer.testing import CliRunner

import grasptwist as gt
from grasptwist import hand
from grasptwist.cli import app
from grasptwist.output.columns import CSV_COLUMNS
from grasptwist.output.follow_table import FollowTable
from places import ROOT

THREE = ROOT / "grasps" / "three-finger-hand.yaml"
TRIFINGER = ROOT / "grasps" / "trifinger-cube.yaml"
urdf_only = pytest.mark.skipif(find_spec("yourdfpy") is None, reason="needs the urdf extra")


def run(*args):
    return CliRunner().invoke(app, [str(a) for a in args])


def jsonl(*args):
    return [json.loads(line) for line in run(*args, "-f", "jsonl").stdout.splitlines()]


def rec_points(path):
    return [c["point"] for c in jsonl("resolve", path)[0]["contacts"]]


def test_csv_of_a_hand_grasp_has_its_joint_columns():
    result = run("resolve", THREE, "-f", "csv")
    assert result.exit_code == 0
    rows = list(csv.reader(io.StringIO(result.stdout)))
    header, (row,) = rows[0], rows[1:]
    joints = [f"qdot_{f}_{f}.{k}" for f in ("east", "west", "south") for k in (1, 2, 3)]
    positions = [name.replace("qdot_", "q_", 1) for name in joints]
    fingers = ("east", "west", "south")
    centres = [f"tip_center_{f}_{a}" for f in fingers for a in "xyz"]
    where = [f"tip_gap_{f}" for f in fingers] + [f"tip_contact_{f}_{a}" for f in fingers for a in "xyz"]
    assert header == CSV_COLUMNS + joints + positions + centres + where + ["hand_error"]
    # point tips (no tip_radius): each centre is its contact, touching it (gap 0)
    assert [float(row[header.index(name)]) for name in centres] == [x for c in rec_points(THREE) for x in c]
    assert [float(row[header.index(f"tip_gap_{f}")]) for f in fingers] == [0.0] * 3
    (rec,) = jsonl("resolve", THREE)
    want = [r for f in rec["hand"]["fingers"] for r in f["joint_rates"]]
    assert [float(row[header.index(name)]) for name in joints] == want
    # inline joints are given at their configuration: every joint at 0, each tip on its contact
    assert [float(row[header.index(name)]) for name in positions] == [0.0] * 9
    assert [(f["joint_positions"], f["tip_error"], f["within_limits"]) for f in rec["hand"]["fingers"]] == [
        ([0.0, 0.0, 0.0], 0.0, True)
    ] * 3
    assert want == pytest.approx([-0.14, 0.015, 0.105, 0.14, 0.01, -0.09, -0.1, 0.21, -0.61], abs=1e-12)


def test_csv_of_a_folder_keeps_the_fixed_header():
    result = run("resolve", ROOT / "grasps", "-f", "csv")
    assert result.stdout.splitlines()[0].split(",") == CSV_COLUMNS


def test_npz_of_a_hand_grasp(tmp_path):
    out = tmp_path / "out.npz"
    assert run("resolve", THREE, "-f", "npz", "-o", out).exit_code == 0
    with np.load(out) as d:
        assert d["joint_names"].tolist() == [f"{f}.{k}" for f in ("east", "west", "south") for k in (1, 2, 3)]
        np.testing.assert_allclose(
            d["joint_rates"], [[-0.14, 0.015, 0.105, 0.14, 0.01, -0.09, -0.1, 0.21, -0.61]], atol=1e-12
        )
        assert d["finger_rank"].tolist() == [[3, 3, 3]]
        assert d["finger_residual"].max() < 1e-12
        np.testing.assert_allclose(d["finger_conditioning"], [[0.381966] * 3], atol=1e-6)
        np.testing.assert_allclose(d["velocity_limit_ratio"], [0.61 / 3])  # south.3, limit 3
        assert d["hand_status"].tolist() == [0]


@pytest.fixture(scope="module")
def trifinger():
    return hand.load_urdf_hand(
        "package://robot_properties_fingers/urdf/pro/trifingerpro.urdf",
        ["finger_tip_link_0", "finger_tip_link_120", "finger_tip_link_240"],
    )


@urdf_only
def test_a_data_set_with_joint_positions_and_a_hand_file(tmp_path, trifinger):
    rng = np.random.default_rng(3)
    n = 40
    q = rng.uniform([-0.3, 0.1, -2.5] * 3, [0.9, 1.4, -0.3] * 3, size=(n, 9))
    states = hand.finger_states(trifinger, q)
    points = np.stack([s.tip[:, :3, 3] for s in states], axis=1)  # each contact at its tip link's origin
    normals = rng.normal(size=(n, 3, 3))
    twist = np.array([0.2, -0.1, 0.5, 0.01, 0.0, 0.02])
    data = tmp_path / "rows.npz"
    np.savez(data, points=points, normals=normals, twist=twist, joint_positions=q)
    hand_file = tmp_path / "hand.yaml"
    fingers = "".join(f"    - {{tip: {f.tip}}}\n" for f in trifinger.fingers)
    hand_file.write_text(f"hand:\n  urdf: {trifinger.source}\n  fingers:\n{fingers}", "utf-8")
    out = tmp_path / "out.npz"
    result = run("resolve", data, "--hand", hand_file, "-f", "npz", "-o", out)
    assert result.exit_code in (0, 1), result.stderr
    with np.load(out) as d:
        assert d["joint_names"].tolist() == list(trifinger.joint_names)
        rates = d["joint_rates"]
        for f, s in enumerate(states):
            # an independent least-squares solve on the Jacobian at each row
            jac = gt.hand.finger_jacobian(s.screws, points[:, f])
            velocity = twist[3:] + np.cross(twist[:3], points[:, f])
            want = np.stack([np.linalg.lstsq(j, v, rcond=None)[0] for j, v in zip(jac, velocity)])
            np.testing.assert_allclose(rates[:, 3 * f : 3 * f + 3], want, atol=1e-9)
        assert d["finger_rank"].shape == (n, 3) and d["velocity_limit_ratio"].shape == (n,)
    # JSON records of the same rows hold the same numbers
    recs = jsonl("resolve", data, "--hand", hand_file)
    assert [r for f in recs[7]["hand"]["fingers"] for r in f["joint_rates"]] == pytest.approx(
        rates[7].tolist(), abs=1e-15
    )


def test_joint_positions_need_a_hand_that_fits(tmp_path):
    data = tmp_path / "rows.npz"
    np.savez(data, points=np.eye(3)[None], normals=np.eye(3)[None], twist=np.zeros(6), joint_positions=np.zeros((1, 2)))
    result = run("resolve", data, "-f", "jsonl")
    assert result.exit_code == 1
    assert "bad-dataset: joint_positions: give the hand they belong to with --hand FILE.yaml" in result.stderr
    hand_file = tmp_path / "hand.yaml"
    joints = "      joints: [{axis: [0, 0, 1], point: [0, 0, 0]}]\n"
    hand_file.write_text(
        "hand:\n  fingers:\n" + f"    - name: a\n{joints}    - name: b\n{joints}    - name: c\n{joints}"
    )
    result = run("resolve", data, "--hand", hand_file, "-f", "jsonl")
    assert "bad-dataset: joint_positions: 2 columns, but the hand has 3 joints (a.1, b.1, c.1)" in result.stderr


def test_a_bad_hand_file_is_a_usage_error_naming_its_place(tmp_path):
    hand_file = tmp_path / "hand.yaml"
    hand_file.write_text("hand:\n  fingers: 3\n")
    result = run("resolve", ROOT / "grasps" / "polyhedron.yaml", "--hand", hand_file)
    assert result.exit_code == 2
    assert f"not-a-list: {hand_file}:2:12: hand.fingers: expected a list, got the number 3" in result.stderr


def test_the_plot_scene_draws_each_finger_joint_axis():
    from grasptwist.io.grasp import load_grasps
    from grasptwist.plot.scene import grasp_scene

    (g,) = load_grasps(THREE)
    # a cube holding the whole hand: framed on the contacts, the knuckles' axes would be cut away
    axes = grasp_scene(g, g.twists[0], extent=(np.zeros(3), 10.0)).of_kind("joint-axis")
    assert [s.label for s in axes] == list(g.hand.joint_names)
    east_2 = axes[1]  # about y through the knuckle (2, 0.3, 2.4)
    np.testing.assert_allclose((east_2.start + east_2.end) / 2, [2.0, 0.3, 2.4])
    direction = east_2.end - east_2.start
    np.testing.assert_allclose(direction / np.linalg.norm(direction), [0, 1, 0], atol=1e-15)
    size = np.linalg.norm(g.points[0] - g.points[1])  # the contact triangle's longest side, sqrt(4.5)
    assert np.linalg.norm(direction) == pytest.approx(0.24 * size)


def _rows(tmp_path, trifinger, n=30, seed=4):
    """A TriFinger data set: contacts one fingertip radius (10 mm) beyond the tip links' origins,
    along their normals, at random joint positions within the limits, and a hand file of the TriFinger."""
    rng = np.random.default_rng(seed)
    q = rng.uniform([-0.3, 0.1, -2.5] * 3, [0.9, 1.4, -0.3] * 3, size=(n, 9))
    normals = rng.normal(size=(n, 3, 3))
    normals /= np.linalg.norm(normals, axis=-1, keepdims=True)
    points = np.stack([s.tip[:, :3, 3] for s in hand.finger_states(trifinger, q)], axis=1) + 0.01 * normals
    hand_file = tmp_path / "trifinger.yaml"
    fingers = "".join(f"    - {{tip: {f.tip}}}\n" for f in trifinger.fingers)
    hand_file.write_text(f"hand:\n  urdf: {trifinger.source}\n  fingers:\n{fingers}", "utf-8")
    return q, points, normals, hand_file


@urdf_only
def test_a_data_set_row_whose_contact_is_off_its_finger_fails(tmp_path, trifinger):
    """Issue 23: a contact moved 0.9 m from its finger-tip in an npz is contact-off-finger, as in a
    grasp file, not ok with joint rates of a configuration that does not touch it."""
    q, points, normals, hand_file = _rows(tmp_path, trifinger, n=3)
    points[1, 0, 0] += 0.9
    data = tmp_path / "rows_far.npz"
    np.savez(data, points=points, normals=normals, twist=[0, 0, 0.5, 0, 0, 0], joint_positions=q)
    recs = jsonl("resolve", data, "--hand", hand_file)
    assert [r["hand"]["ok"] for r in recs] == [True, False, True]
    assert not recs[1]["ok"]
    assert recs[1]["hand"]["error"]["code"] == "contact-off-finger"
    assert recs[1]["hand"]["error"]["message"].startswith("contact 1 is farther from its finger's tip")


@urdf_only
def test_a_data_set_without_joint_positions_is_solved_by_inverse_kinematics(tmp_path, trifinger):
    """Without joint_positions the rows' joint positions are solved, not zeros: the joint rates are
    the ones at the configurations the contacts came from (each the only one within the limits
    near home), and a contact no finger reaches is unreachable."""
    q, points, normals, hand_file = _rows(tmp_path, trifinger)
    twist = np.array([0.2, -0.1, 0.5, 0.01, 0.0, 0.02])
    given, solved = tmp_path / "given.npz", tmp_path / "solved.npz"
    np.savez(given, points=points, normals=normals, twist=twist, joint_positions=q)
    far = points.copy()
    far[5, 2] = [0.0, 0.0, 1.5]  # 1.5 m above the table: beyond every finger
    np.savez(solved, points=far, normals=normals, twist=twist)
    want, got = jsonl("resolve", given, "--hand", hand_file), jsonl("resolve", solved, "--hand", hand_file)
    for i, (a, b) in enumerate(zip(want, got)):
        if i == 5:
            assert b["hand"]["error"]["code"] == "unreachable" and not b["ok"]
            assert b["hand"]["error"]["message"].startswith("finger 3's tip cannot reach its contact")
            continue
        assert b["hand"]["ok"], b["hand"]
        rates = [r for f in b["hand"]["fingers"] for r in f["joint_rates"]]
        assert rates == pytest.approx([r for f in a["hand"]["fingers"] for r in f["joint_rates"]], abs=1e-7)


def test_the_follow_table_gives_a_rounded_tips_gap():
    """Under each sample, a finger with a tip radius shows its gap (a penetration negative); a
    point tip shows none."""
    out = io.BytesIO()
    finger = {"contact": "1", "joint_positions": [0.5], "within_limits": True, "tip_error": 0.0}
    fingers = [{**finger, "tip_radius": 0.01, "tip_gap": -0.001272}, {**finger, "tip_radius": 0.0, "tip_gap": 0.0}]
    FollowTable(out)._hand_line({"fingers": fingers})
    line = out.getvalue().decode()
    assert "finger 1: q 0.5000, tip error < 1e-12, tip gap -0.00127;" in line and line.count("tip gap") == 1
