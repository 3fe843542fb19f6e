"""``follow`` with a hand: joint positions integrated along the path, and the hand's events.

Two hands are built here as URDFs (the form that carries joint position limits):

* ``turntable``: every finger's first joint turns about the z axis through the
  origin, then two slides (radial, vertical) reach its contact.  Turning the
  object about that axis at rate ``w`` is followed exactly by the first joint
  alone (its column of the Jacobian is the contact's velocity, and the
  Jacobian is invertible), so ``q_1(t) = w t``: a first joint with upper limit
  ``u`` leaves it at ``t = u / w``.
* ``flat``: finger 1 turns about the x axis through the origin, then slides
  along x and y; at its contact ``(1, y, 0)`` the Jacobian's columns are
  ``(0, 0, y), (1, 0, 0), (0, 1, 0)``, so its conditioning is ``|y|`` and it
  loses rank at ``y = 0``.  Fingers 2 and 3 are Cartesian (conditioning 1).
  Sliding the object along -y at 0.5 from ``y = 0.5`` makes ``y = 0.5 (1 - t)``:
  the warning (``|y| < 1e-3``) starts at ``t = 0.998``, the rank is lost at ``t = 1``
  (``|y| <= 1e-9``).
"""

import csv
import io
import json
import math

import numpy as np
import pytest
from typer.testing import CliRunner

from docs_blocks import ROOT, blocks, commands, pattern
from grasptwist.cli import app
from grasptwist.engine.kinematics import forward_kinematics
from grasptwist.io.grasp import read_grasps
from grasptwist.output.follow_table import FollowTable
from places import GRASPS

pytest.importorskip("yourdfpy")

HAND = GRASPS / "three-finger-hand.yaml"


def run(*args):
    return CliRunner().invoke(app, [str(a) for a in args])


def jsonl(text):
    return [json.loads(line) for line in text.splitlines()]


def _joint(name, parent, child, kind, axis, xyz=(0, 0, 0), limit=(-3.0, 3.0)):
    return (
        f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="{" ".join(map(str, xyz))}"/><axis xyz="{" ".join(map(str, axis))}"/>'
        f'<limit lower="{limit[0]}" upper="{limit[1]}" effort="1" velocity="5"/></joint>'
    )


def _urdf(fingers):
    """A URDF of three fingers on a palm: per finger ``(name, [(kind, axis, limit)], contact)``; the
    joints sit at the origin and the tip link at the contact (all joints at 0)."""
    links, joints = ['<link name="palm"/>'], []
    for name, chain, contact in fingers:
        parent = "palm"
        for k, (kind, axis, limit) in enumerate(chain):
            child = f"{name}_l{k}"
            links.append(f'<link name="{child}"/>')
            joints.append(_joint(f"{name}_j{k}", parent, child, kind, axis, limit=limit))
            parent = child
        links.append(f'<link name="{name}_tip"/>')
        joints.append(
            f'<joint name="{name}_fix" type="fixed"><parent link="{parent}"/><child link="{name}_tip"/>'
            f'<origin xyz="{" ".join(map(str, contact))}"/></joint>'
        )
    return '<robot name="test">' + "".join(links + joints) + "</robot>"


def _grasp(tmp_path, fingers, normals, path, radius=0.0):
    """The grasp file of a URDF hand whose tips touch their contacts, or, with ``radius``, spheres
    of that radius about the tips do: the contacts ``radius`` along the normal from the tips."""
    (tmp_path / "hand.urdf").write_text(_urdf(fingers))
    contacts = "".join(
        f"  - {{point: {(np.array(c) + radius * np.array(json.loads(n))).tolist()}, normal: {n}}}\n"
        for (_, _, c), n in zip(fingers, normals)
    )
    tips = "".join(f"    - {{name: {name}, tip: {name}_tip}}\n" for name, _, _ in fingers)
    # at joint positions 0 each tip link is where _urdf puts it (else the loader would solve them)
    home = "".join(f"    {name}_j{k}: 0\n" for name, chain, _ in fingers for k in range(len(chain))) if radius else ""
    home = "  joint_positions:\n" + home if home else ""
    doc = f"wrist: [0, 0, 3]\ncontacts:\n{contacts}hand:\n  urdf: hand.urdf\n{home}  fingers:\n{tips}paths:\n{path}"
    (tmp_path / "g.yaml").write_text(doc)
    return tmp_path / "g.yaml"


FREE = (-3.0, 3.0)
SPIN = "  - name: spin\n    segments:\n      - {angular: [0, 0, 0.5], duration: 2}\n"
SLIDE = "  - name: slide\n    segments:\n      - {linear: [0, -0.5, 0], duration: 1.5}\n"


def _turntable(upper):
    contacts = [(1.0, 0.3, 0.4), (-1.0, -0.2, -0.1), (0.2, -1.0, -0.5)]
    return [
        (
            f"f{i}",
            [("revolute", (0, 0, 1), (-3.0, u)), ("prismatic", (c[0], c[1], 0), FREE), ("prismatic", (0, 0, 1), FREE)],
            c,
        )
        for i, (c, u) in enumerate(zip(contacts, upper))
    ]


def _flat():
    cartesian = [("prismatic", a, FREE) for a in ((1, 0, 0), (0, 1, 0), (0, 0, 1))]
    return [
        ("f0", [("revolute", (1, 0, 0), FREE), ("prismatic", (1, 0, 0), FREE), ("prismatic", (0, 1, 0), FREE)], (1.0, 0.5, 0.0)),
        ("f1", cartesian, (-1.0, 0.3, 0.2)),
        ("f2", cartesian, (0.1, -1.0, -0.3)),
    ]  # fmt: skip


NORMALS = ["[-1, 0, 0]", "[1, 0, 0]", "[0, 1, 0]"]


@pytest.mark.parametrize("samples", [2])
@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_the_first_joint_limit_exit_is_located_where_the_turntable_puts_it(tmp_path, samples):
    # the object turns at 0.5: the first joints are at 0.5 t; finger f1's leaves 0.6 at t = 1.2, f0's 0.9 at 1.8
    g = _grasp(tmp_path, _turntable([0.9, 0.6, 3.0]), NORMALS, SPIN)
    r = run("follow", g, "--samples", samples, "-f", "jsonl")
    assert r.exit_code == 1, r.output
    *recs, summary = jsonl(r.stdout)
    hand = summary["summary"]["hand"]
    assert hand["joint_limit"]["finger"] == "f1" and hand["joint_limit"]["joint"] == "f1_j0"
    assert abs(hand["joint_limit"]["t"] - 1.2) < 1e-9
    exits = [f["joint_limit"] for f in hand["fingers"]]
    assert exits[0]["joint"] == "f0_j0" and abs(exits[0]["t"] - 1.8) < 1e-9 and exits[2] is None
    assert not summary["ok"] and [f["rank_loss"] for f in hand["fingers"]] == [None] * 3
    for rec in recs:  # the first joints at 0.5 t, the slides still
        np.testing.assert_allclose(
            [q for f in rec["joint_positions"] for q in f], [0.5 * rec["t"], 0, 0] * 3, atol=1e-12
        )
        np.testing.assert_allclose([f["joint_rates"] for f in rec["hand"]["fingers"]], [[0.5, 0, 0]] * 3, atol=1e-12)
    assert "error: hand: joint 'f1_j0' of finger 2 leaves its position limits at t = 1.200000" in r.stderr
    # the table says it in words (it writes what the records hold: no second run)
    table = io.BytesIO()
    writer = FollowTable(table)
    for rec in [*recs, summary]:
        writer.write(rec)
    assert "  hand: joint 'f1_j0' of finger 2 leaves its position limits at t = 1.2000\n" in table.getvalue().decode()


def test_the_summary_tip_error_is_the_largest_of_the_samples(tmp_path):
    # sphere tips: every sample's tip link origin is the radius, 0.01, from its contact; the summary
    # said the tracker's drift instead (5e-9), contradicting the records it sums up (issue 26)
    g = _grasp(tmp_path, _turntable([3.0] * 3), NORMALS, SPIN, radius=0.01)
    r = run("follow", g, "--samples", 2, "-f", "jsonl")
    assert r.exit_code == 0, r.output
    *recs, summary = jsonl(r.stdout)
    samples = np.array([[f["tip_error"] for f in rec["hand"]["fingers"]] for rec in recs])
    np.testing.assert_allclose(samples, 0.01, rtol=1e-6)
    assert [f["tip_error"] for f in summary["summary"]["hand"]["fingers"]] == samples.max(axis=0).tolist()


@pytest.mark.parametrize("samples", [3])
@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_the_rank_loss_and_the_conditioning_warning_are_located_between_samples(tmp_path, samples):
    g = _grasp(tmp_path, _flat(), NORMALS, SLIDE)
    r = run("follow", g, "--samples", samples, "-f", "jsonl")
    *recs, summary = jsonl(r.stdout)
    f0, f1, f2 = summary["summary"]["hand"]["fingers"]
    assert abs(f0["rank_loss"] - 1) < 1e-8  # |y| = 0.5 (1 - t) <= 1e-9 from t = 1 - 2e-9
    assert abs(f0["first_warning"] - 0.998) < 1e-9  # |y| < 1e-3
    assert f1["rank_loss"] is f1["first_warning"] is f2["rank_loss"] is None
    assert f0["tip_error"] < 1e-12 and not summary["ok"]
    for rec in recs:  # only the y slide moves: q = (0, 0, -0.5 t)
        np.testing.assert_allclose(rec["joint_positions"][0], [0, 0, -0.5 * rec["t"]], atol=1e-12)
        assert rec["hand"]["fingers"][0]["conditioning"] == pytest.approx(abs(0.5 * (1 - rec["t"])), abs=1e-12)
    assert "finger 1 loses rank (its Jacobian) at t = 1.000000" in r.stderr
    assert "warning: hand: finger 1: conditioning below 0.001 from t = 0.998000" in r.stderr


def _tips(grasp, rec):
    """Each finger's tip point by forward kinematics at a sample's joint positions (an inline finger's
    tip point is its contact at the start, carried by the chain's motion)."""
    tips = []
    for finger, start, q in zip(grasp.hand.fingers, grasp.points, rec["joint_positions"]):
        home = np.eye(4)
        home[:3, 3] = start
        tips.append(forward_kinematics(finger.screws, finger.points, home, q).tip[:3, 3])
    return np.array(tips)


@pytest.mark.parametrize("samples", [3])
@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_the_bundled_hand_keeps_its_tips_on_the_moving_contacts(samples):
    (grasp,) = read_grasps(HAND)
    size = max(np.linalg.norm(grasp.points[i] - grasp.points[j]) for i, j in ((0, 1), (1, 2), (0, 2)))
    r = run("follow", HAND, "--samples", samples, "--method", "off-tangent", "-f", "jsonl")
    assert r.exit_code == 0, r.output
    *recs, summary = jsonl(r.stdout)
    table = io.BytesIO()
    writer = FollowTable(table)
    for rec in [*recs, summary]:
        writer.write(rec)
    # the docs' excerpt of this command's output (its console block runs with -m slow): the table
    # written from these records (the table writes what the records hold), then the summary line
    shown = [c for b in blocks(ROOT / "docs/guide/paths.md") if b.lang == "console" for c in commands(b)]
    (expected,) = [c.expected for c in shown if c.args[:2] == ["follow", "grasps/three-finger-hand.yaml"]]
    assert pattern(expected).fullmatch(table.getvalue().decode() + f"{len(recs) + 1} records: all ok\n")
    assert len(recs) == samples * len(grasp.paths)
    worst = 0.0
    for rec in recs:
        moved = np.array([c["point"] for c in rec["contacts"]])
        worst = max(worst, float(np.abs(_tips(grasp, rec) - moved).max()))
    assert worst < 1e-6 * size
    assert max(f["tip_error"] for f in summary["summary"]["hand"]["fingers"]) < 1e-6 * size
    # a sample's hand object is resolve's at its joint positions: its rates move each tip with its contact
    rec = recs[-1]
    twist = np.array(rec["twist"]["screw"])
    for finger, f, q in zip(grasp.hand.fingers, rec["hand"]["fingers"], rec["joint_positions"]):
        s = forward_kinematics(finger.screws, finger.points, None, q).screws
        p = np.array(rec["contacts"][grasp.hand.fingers.index(finger)]["point"])
        velocity = sum(rate * (sc[3:] + np.cross(sc[:3], p)) for rate, sc in zip(f["joint_rates"], s))
        np.testing.assert_allclose(velocity, twist[3:] + np.cross(twist[:3], p), atol=1e-12)


def test_a_grasp_without_a_hand_has_no_hand_fields():
    *recs, summary = jsonl(run("follow", GRASPS / "cylinder.yaml", "--samples", 2, "-f", "jsonl").stdout)
    assert "hand" not in summary["summary"] and "joint_positions" not in recs[0] and "hand" not in recs[0]
    assert set(summary["summary"]["min_conditioning"]) == {"off_tangent", "tangent"}
    assert math.isfinite(summary["summary"]["duration"])


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_csv_carries_resolves_joint_columns_and_the_joint_positions(tmp_path):
    g = _grasp(tmp_path, _turntable([3.0, 3.0, 3.0]), NORMALS, SPIN)
    rows = list(csv.DictReader(io.StringIO(run("follow", g, "--samples", 3, "-f", "csv").stdout)))
    assert [float(r["q_f1_f1_j0"]) for r in rows] == pytest.approx([0, 0.5, 1.0], abs=1e-12)  # 0.5 t
    assert [float(r["qdot_f2_f2_j0"]) for r in rows] == pytest.approx([0.5] * 3, abs=1e-12)
    assert [float(r["q_f2_f2_j1"]) for r in rows] == pytest.approx([0] * 3, abs=1e-12)


@pytest.mark.slow  # a second follow with a hand (seconds); the CSV above has the same columns
def test_npz_carries_resolves_joint_arrays_and_the_joint_positions(tmp_path):
    g = _grasp(tmp_path, _turntable([3.0, 3.0, 3.0]), NORMALS, SPIN)
    assert run("follow", g, "--samples", 3, "-f", "npz", "-o", tmp_path / "o.npz").exit_code == 0
    with np.load(tmp_path / "o.npz") as d:
        np.testing.assert_allclose(d["joint_positions"], np.outer([0, 0.5, 1.0], [1, 0, 0] * 3), atol=1e-12)
        np.testing.assert_allclose(d["joint_rates"], np.tile([0.5, 0, 0], (3, 3)), atol=1e-12)
        assert d["joint_names"].tolist()[:3] == ["f0_j0", "f0_j1", "f0_j2"]
