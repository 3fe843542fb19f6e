"""Inverse kinematics at the front (issue 23): grasp files without joint_positions are solved from
``hand.seed``, unreachable fingers are located errors, and every output shows the joint positions
and tip errors the joint rates are at (records, CSV, npz, tables, follow)."""

import csv
import io
import json
import re
from importlib.util import find_spec

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from grasptwist.cli import app
from grasptwist.engine import hands
from grasptwist.engine.degeneracy import Status
from grasptwist.engine.ik import IK_TOL, hand_ik
from grasptwist.output.follow_table import FollowTable
from grasptwist.output.numbers import fmt_figure
from grasptwist.run.placement import read_grasps
from places import ROOT

TRIFINGER = ROOT / "grasps" / "trifinger-cube.yaml"
THREE = ROOT / "grasps" / "three-finger-hand.yaml"
INVALID = ROOT / "tests" / "invalid_grasps"
urdf = pytest.mark.skipif(
    find_spec("yourdfpy") is None or find_spec("robot_properties_fingers") is None, reason="needs the TriFinger URDF"
)


def run(*args):
    return CliRunner().invoke(app, [str(a) for a in args])


def jsonl(*args):
    result = run(*args, "-f", "jsonl")
    return [json.loads(line) for line in result.stdout.splitlines()]


#: The bundled TriFinger grasp's joint positions, as once typed into its file (each fingertip
#: sphere's centre one radius behind its contact); the run solves them now.
FILE_POSITIONS = dict(
    zip(
        [
            f"finger_{j}_joint_{f}"
            for f in (0, 120, 240)
            for j in ("base_to_upper", "upper_to_middle", "middle_to_lower")
        ],
        [0.181390037, 0.5904426439, -1.4828803827, 0.19893411, 0.5545414034, -1.3054491805]
        + [0.2399650693, 0.5570307797, -1.2184725163],
    )
)


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    """The folder of the grasp files the tests write, one for the module: a URDF hand's link meshes, their
    hulls and clusters are kept per URDF and grasp folder (run/collisions.py), as a folder's grasps share
    them; a folder per test cost each test 0.04-0.1 s of CPU reading and hulling the same meshes again."""
    return tmp_path_factory.mktemp("ik")


def without_positions(folder, name, seed=None, **contacts):
    """The bundled TriFinger grasp (with ``seed``; contact ``i`` moved) as ``name``.yaml in ``folder``,
    and the positions once typed."""
    doc = yaml.safe_load(TRIFINGER.read_text("utf-8"))
    file_positions = FILE_POSITIONS
    if seed is not None:
        doc["hand"]["seed"] = seed
    for i, point in contacts.items():
        doc["contacts"][int(i[1:])]["point"] = point
    path = folder / f"{name}.yaml"
    path.write_text(yaml.safe_dump(doc, sort_keys=False), "utf-8")
    return path, file_positions


def tips(hand, q):
    """Each finger's tip link origin at joint positions ``q`` by forward kinematics, ``(..., 3, 3)``."""
    return np.stack([s.tip[..., :3, 3] for s in hands.finger_states(hand, q)], axis=-2)


@urdf
def test_a_grasp_without_joint_positions_puts_each_tip_on_its_contact(folder):
    """Each tip link's origin, its fingertip sphere's centre, one radius (10 mm) behind its contact."""
    path, _ = without_positions(folder, "solved")
    (g,) = read_grasps(path)
    lengths = np.array([f.length for f in g.hand.fingers])
    distance = np.linalg.norm(tips(g.hand, g.joint_positions) - (g.points - 0.01 * g.normals), axis=-1)
    assert (distance <= IK_TOL * lengths).all(), distance
    assert lengths == pytest.approx([0.382036] * 3, abs=1e-6)
    # the configuration the joint rates are at is in the record, with its tip errors
    (rec, _) = jsonl("resolve", path)
    fingers = rec["hand"]["fingers"]
    assert [q for f in fingers for q in f["joint_positions"]] == g.joint_positions.tolist()
    assert [f["tip_error"] for f in fingers] == pytest.approx(distance.tolist(), abs=1e-15)
    assert all(f["within_limits"] for f in fingers) and rec["hand"]["ok"]


@urdf
def test_the_tip_error_is_measured_to_the_spheres_centre_not_the_contact(folder):
    """Given joint positions a little off: each finger's tip_error is its tip link origin's distance
    from ``p - r n`` (what the docs say), not from the contact ``p``."""
    doc = yaml.safe_load(TRIFINGER.read_text("utf-8"))
    moved = dict(
        FILE_POSITIONS, finger_upper_to_middle_joint_120=FILE_POSITIONS["finger_upper_to_middle_joint_120"] + 0.05
    )
    doc["hand"]["joint_positions"] = moved
    path = folder / "one-joint-moved.yaml"
    path.write_text(yaml.safe_dump(doc, sort_keys=False), "utf-8")
    (g,) = read_grasps(path)
    at = tips(g.hand, g.joint_positions)
    to_target = np.linalg.norm(at - (g.points - 0.01 * g.normals), axis=-1)
    to_contact = np.linalg.norm(at - g.points, axis=-1)
    (rec, _) = jsonl("resolve", path)
    errors = [f["tip_error"] for f in rec["hand"]["fingers"]]
    assert errors == pytest.approx(to_target.tolist(), rel=1e-9, abs=1e-12)
    assert errors[0] < 1e-8 and errors[2] < 1e-8 and 0.005 < errors[1] < 0.05  # the moved finger only
    assert to_contact[0] == pytest.approx(0.01, abs=1e-8)  # the contact is one radius away


@urdf
def test_the_seed_is_where_the_solution_starts(folder):
    """The elbow-down solution the file's positions hold (each sphere centre one radius inside its
    contact) from a seed there; the same as the engine's hand_ik from that seed."""
    path, file_positions = without_positions(folder, "unseeded", seed=None)
    seed = {k: round(v, 1) for k, v in FILE_POSITIONS.items()}
    seeded, _ = without_positions(folder, "seeded", seed=seed)
    (g,) = read_grasps(seeded)
    want = hand_ik(g.hand, g.points - 0.01 * g.normals, seed=[seed[name] for name in g.hand.joint_names])
    np.testing.assert_array_equal(g.joint_positions, want.positions)
    # the file's positions are 1 cm (the sphere's radius) from the contacts: the solution is near them
    assert np.abs(g.joint_positions - list(file_positions.values())).max() < 0.1


@urdf
def test_an_unknown_seed_joint_is_located(folder):
    path, _ = without_positions(folder, "unknown-seed", seed={"no_such_joint": 0.5})
    (err,) = read_grasps(path)
    assert err.code == "unknown-joint"
    assert err.message.startswith("hand.seed.no_such_joint: not a joint of the hand's fingers")


@urdf
@pytest.mark.parametrize(
    ("fixture", "code", "match"),
    [
        ("hand-unreachable.yaml", "unreachable", r"finger 1 cannot reach its contact: .* no closer than ([0-9.]+) "),
        ("hand-outside-limits.yaml", "outside-limits", r"finger 1 reaches its contact only with a joint outside"),
    ],
)
def test_a_finger_that_cannot_reach_fails_the_grasp_at_its_tip(fixture, code, match):
    (err,) = read_grasps(INVALID / fixture)
    assert (err.code, err.line, err.column) == (code, 13, 24)  # the finger's tip
    found = re.search(match, err.message.removeprefix("hand.fingers[0].tip: "))
    assert found, err.message
    if code == "unreachable":  # the distance is the engine's tip error, 0.9 m out less the finger's reach
        doc = yaml.safe_load((INVALID / fixture).read_text("utf-8"))
        (g,) = read_grasps(TRIFINGER)
        seed = [doc["hand"]["seed"].get(name, 0.0) for name in g.hand.joint_names]
        points = np.array([c["point"] for c in doc["contacts"]])
        normals = np.array([c["normal"] for c in doc["contacts"]])
        solved = hand_ik(g.hand, points - 0.01 * normals, seed=seed)  # the centres, 10 mm behind
        assert Status(int(solved.status[0])) == Status.UNREACHABLE
        assert float(found.group(1)) == pytest.approx(solved.tip_error[0], rel=1e-4)  # printed to 4 digits
        # the least distance within the limits is 0.7260517 (a 70^3 grid of the joints refined by scipy's
        # L-BFGS-B, at the limits of the first two joints): the iteration stalls within 2e-5 of it
        assert 0.7260517 <= solved.tip_error[0] < 0.7260517 * (1 + 2e-5)


@urdf
def test_the_table_labels_positions_and_tip_errors(folder, monkeypatch):
    monkeypatch.setenv("COLUMNS", "200")  # one part: narrower, the table splits its columns
    path, _ = without_positions(folder, "table")
    (g,) = read_grasps(path)
    out = run("resolve", path, "--twist", "0,0,0.5,0,0,0").stdout
    header = next(line for line in out.splitlines() if "position" in line and "tip error" in line)
    assert header.split()[:5] == ["finger", "in", "hand", "joint", "position"]
    row = next(line for line in out.splitlines() if "finger_middle_to_lower_joint_120" in line)
    assert float(row.split()[1]) == pytest.approx(g.joint_positions[5], abs=5e-5)


@urdf
def test_a_data_set_solved_by_ik_carries_its_positions_in_every_format(tmp_path):
    (g,) = read_grasps(TRIFINGER)
    rng = np.random.default_rng(7)
    q = rng.uniform([-0.3, 0.1, -2.5] * 3, [0.9, 1.4, -0.3] * 3, size=(6, 9))
    normals = rng.normal(size=(6, 3, 3))
    normals /= np.linalg.norm(normals, axis=-1, keepdims=True)
    points = tips(g.hand, q) + 0.01 * normals  # the fingertip spheres (radius 10 mm) touch them
    data = tmp_path / "rows.npz"
    np.savez(data, points=points, normals=normals, twist=[0, 0, 0.5, 0, 0, 0])
    hand_file = tmp_path / "trifinger.yaml"
    fingers = "".join(f"    - {{name: '{f.name}', tip: {f.tip}}}\n" for f in g.hand.fingers)
    hand_file.write_text(f"hand:\n  urdf: {g.hand.source}\n  fingers:\n{fingers}", "utf-8")
    out = tmp_path / "out.npz"
    assert run("resolve", data, "--hand", hand_file, "-f", "npz", "-o", out).exit_code == 0
    with np.load(out) as d:
        solved, tip_error, within = d["joint_positions"], d["tip_error"], d["within_limits"]
    lengths = np.array([f.length for f in g.hand.fingers])
    assert solved.shape == (6, 9)
    assert (np.linalg.norm(tips(g.hand, solved) - (points - 0.01 * normals), axis=-1) <= IK_TOL * lengths).all()
    assert (tip_error <= IK_TOL * lengths).all() and within.all()
    rows = list(csv.DictReader(io.StringIO(run("resolve", data, "--hand", hand_file, "-f", "csv").stdout)))
    names = [f"q_{f.name}_{j.name}" for f in g.hand.fingers for j in f.joints]
    np.testing.assert_array_equal([[float(r[n]) for n in names] for r in rows], solved)
    recs = jsonl("resolve", data, "--hand", hand_file)
    np.testing.assert_array_equal(
        [[q for f in r["hand"]["fingers"] for q in f["joint_positions"]] for r in recs], solved
    )


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_follow_shows_each_samples_positions_and_tip_errors():
    recs = jsonl("follow", THREE, "--samples", "5")
    assert len(recs) == 6
    samples = [r for r in recs if "t" in r]
    (summary,) = [r for r in recs if "summary" in r]
    for s in samples:  # the hand's own positions are the sample's (as the path record gives them)
        assert [f["joint_positions"] for f in s["hand"]["fingers"]] == s["joint_positions"]
    worst = [max(s["hand"]["fingers"][f]["tip_error"] for s in samples) for f in range(3)]
    tracked = [f["tip_error"] for f in summary["summary"]["hand"]["fingers"]]
    # the summary's is the tracker's own error at the samples: the same distance, computed apart
    assert worst == pytest.approx(tracked, rel=1e-6, abs=1e-15)
    assert samples[0]["hand"]["fingers"][0]["tip_error"] == 0.0 and max(worst) < 1e-6
    out = io.BytesIO()  # the table of these records (one path run: a hand's integration costs seconds)
    writer = FollowTable(out)
    for rec in recs:
        writer.write(rec)
    lines = [line for line in out.getvalue().decode().splitlines() if line.lstrip().startswith("hand  finger")]
    assert len(lines) == 5
    last = samples[-1]["hand"]["fingers"][2]
    q = " ".join(f"{v:.4f}" for v in last["joint_positions"])
    want = f"finger 3: q {q}, tip error {fmt_figure(last['tip_error'])}"  # noise-sized errors print '< 1e-12'
    assert lines[-1].endswith(want), lines[-1]


@urdf
def test_a_hand_files_seed_is_refused_not_dropped(tmp_path):
    (g,) = read_grasps(TRIFINGER)
    hand_file = tmp_path / "trifinger.yaml"
    fingers = "".join(f"    - {{tip: {f.tip}}}\n" for f in g.hand.fingers)
    hand_file.write_text(
        f"hand:\n  urdf: {g.hand.source}\n  seed: {{finger_upper_to_middle_joint_0: 0.5}}\n  fingers:\n{fingers}",
        "utf-8",
    )
    result = run("resolve", TRIFINGER, "--hand", hand_file)
    assert result.exit_code == 2
    assert "conflicting-keys" in result.stderr and "hand.seed: only in a grasp file" in " ".join(result.stderr.split())


def given(folder, name, **moved):
    """The bundled TriFinger grasp at the positions once typed, joints ``moved`` by so many radians, as
    ``name``.yaml in ``folder``."""
    doc = yaml.safe_load(TRIFINGER.read_text("utf-8"))
    doc["hand"]["joint_positions"] = {j: q + moved.get(j, 0.0) for j, q in FILE_POSITIONS.items()}
    path = folder / f"{name}.yaml"
    path.write_text(yaml.safe_dump(doc, sort_keys=False), "utf-8")
    return path


@urdf
def test_given_positions_that_leave_a_tip_off_its_contact_are_warned_of(folder):
    # the trial's: finger 0's joints moved ~0.2 rad said 'all ok' with its tip 47 mm off; now a warning
    # past 1% of the finger's length (3.8 mm), in the record and on stderr, naming finger, distance, tolerance
    path = given(folder, "tip-off", finger_upper_to_middle_joint_0=0.2)
    (g,) = read_grasps(path)
    off = np.linalg.norm(tips(g.hand, g.joint_positions) - (g.points - 0.01 * g.normals), axis=-1)
    assert off[0] > 0.02 and off[1] < 1e-4 and off[2] < 1e-4  # the moved finger only
    want = f"tip-off-contact: finger 1's tip link 'finger_tip_link_0' is {off[0]:.3g} from where its contact puts it"
    assert [w[: len(want)] for w in g.warnings] == [want]
    assert "over the tolerance 0.00382 (1% of the finger's length)" in g.warnings[0]
    result = run("check", path)
    assert result.exit_code == 0 and f"warning: {want}" in result.stderr  # a warning: the exit status stays 0
    (rec, _) = jsonl("resolve", path)
    assert [w[: len(want)] for w in rec["warnings"]] == [want]


@urdf
def test_positions_typed_to_a_few_decimals_or_just_off_are_not_warned_of(folder):
    # the positions once typed (tips 1e-5 m off) and a joint moved 0.005 rad (2.4 mm, under 3.8 mm)
    for moved in ({}, {"finger_upper_to_middle_joint_120": 0.005}):
        (g,) = read_grasps(given(folder, "typed", **moved))
        off = np.linalg.norm(tips(g.hand, g.joint_positions) - (g.points - 0.01 * g.normals), axis=-1)
        assert off.max() < 0.0038 and g.warnings == (), (off, g.warnings)
    assert off.max() > 0.001  # the moved joint moved its tip


@urdf
def test_a_data_set_s_rows_off_their_contacts_are_warned_of_each(tmp_path):
    (g,) = read_grasps(TRIFINGER)
    q = np.tile(g.joint_positions, (3, 1))
    q[1, 1] += 0.2  # row 1: finger 0's middle joint moved
    points = np.repeat(g.points[None], 3, axis=0)
    data = tmp_path / "rows.npz"
    np.savez(
        data,
        points=points,
        normals=np.repeat(g.normals[None], 3, axis=0),
        twist=[0, 0, 0.5, 0, 0, 0],
        joint_positions=q,
        wrist=np.tile(g.wrist, (3, 1)),
    )
    hand_file = tmp_path / "trifinger.yaml"
    fingers = "".join(f"    - {{name: '{f.name}', tip: {f.tip}}}\n" for f in g.hand.fingers)
    hand_file.write_text(f"hand:\n  urdf: {g.hand.source}\n  fingers:\n{fingers}", "utf-8")
    off = np.linalg.norm(tips(g.hand, q[1])[0] - (g.points[0] - 0.01 * g.normals[0]))
    recs = jsonl("resolve", data, "--hand", hand_file)
    assert [len(r["warnings"]) for r in recs] == [0, 1, 0] and all(r["ok"] for r in recs)
    assert recs[1]["warnings"][0].startswith(f"tip-off-contact: finger 1's tip link 'finger_tip_link_0' is {off:.3g} ")
