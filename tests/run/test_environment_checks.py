"""The fingers of a given grasp against the world and against each other (issue 37, items 1-3): the
TriFinger on its table with its exact clearance, a box through a link reported with its depth (checked
against every vertex of the link's mesh), fingertip spheres overlapping by their exact depth, the
warnings in records and on stderr, the environment read from a file and from --table, and
``gt.synthesize`` checking what the command line checks."""

import json
from dataclasses import replace
from importlib.util import find_spec

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

import grasptwist as gt
from grasptwist.cli import app
from grasptwist.engine.collision import link_poses
from grasptwist.io.urdf_meshes import link_geometry
from grasptwist.model import Environment, Obstacle
from grasptwist.run.collisions import hand_checks_along, with_collisions
from places import GRASPS, ROOT

needs_trifinger = pytest.mark.skipif(
    find_spec("yourdfpy") is None or find_spec("robot_properties_fingers") is None, reason="needs the TriFinger URDF"
)
TRIFINGER = ROOT / "grasps" / "trifinger-cube.yaml"


@pytest.fixture(scope="module")
def placed():
    """The bundled TriFinger grasp, placed on its cube on its table."""
    (g,) = gt.read_grasps(TRIFINGER)
    return gt.place_grasp(g)


@needs_trifinger
def test_the_trifinger_on_its_table_keeps_its_lowest_fingertip_5_mm_above_it(placed):
    g = placed
    overlaps, hits, clearance = hand_checks_along(g)
    # the lowest contact is 15 mm up a side face: its 10 mm sphere's bottom 5 mm above the table
    assert overlaps == [()] and hits == [()] and clearance.tolist() == [pytest.approx(0.005, abs=1e-9)]
    assert g.environment.table_height == 0.0 and g.warnings == ()


@needs_trifinger
def test_a_box_through_a_finger_link_is_reported_with_its_deepest_vertexs_depth(placed):
    g = placed
    geometry = link_geometry(g.hand, folder=TRIFINGER.parent)
    (lower,) = [i for i, link in enumerate(geometry) if link.link == "finger_lower_link_0"]
    pose = link_poses(g.hand, geometry, g.joint_positions[None])[0, lower]
    v = geometry[lower].vertices @ pose[:3, :3].T + pose[:3, 3]
    # a slab whose top face is 4 mm above the lowest vertex of the link, far from everything else
    top = v[:, 2].min() + 0.004
    centre = v[np.argmin(v[:, 2])]
    slab = Obstacle(np.array([0.02, 0.02, 0.1]), np.eye(4))
    slab.pose.flags.writeable = True
    slab.pose[:3, 3] = [centre[0], centre[1], top - 0.05]
    inside = (np.abs(v[:, :2] - centre[:2]) <= 0.01).all(axis=1)
    deepest = float(top - v[inside, 2].min())  # every vertex of the mesh: 4 mm
    env = Environment(0.0, (slab,))
    _, (hits,), _ = hand_checks_along(replace(g, environment=env))
    (hit,) = [h for h in hits if h.link == "finger_lower_link_0"]
    assert hit.finger == "1" and hit.obstacle == "box 1"
    # the link's merged convex hull keeps its vertices to within 0.5 mm (HULL_MERGE)
    assert -hit.distance == pytest.approx(deepest, abs=5e-4) and deepest == pytest.approx(0.004)
    warned = with_collisions(replace(g, environment=env, warnings=())).warnings
    assert any(w.startswith("finger-hits-environment: finger 1's link 'finger_lower_link_0' is 0.00") for w in warned)


def test_two_fingertip_spheres_of_an_inline_hand_overlap_by_their_exact_depth():
    (g,) = gt.read_grasps(GRASPS / "three-finger-hand.yaml")
    hand = replace(g.hand, fingers=tuple(replace(f, tip_radius=0.3) for f in g.hand.fingers))
    # contacts 1 and 2 moved to faces +x and +y near their shared edge: sphere centres (1.3, 0.8, 0.4) and
    # (0.8, 1.3, 0.4), 0.5 sqrt(2) apart, overlapping by 0.6 - 0.7071 < 0: apart; then nearer the edge
    p = np.array([[1.0, 0.9, 0.4], [0.9, 1.0, 0.4], [0.2, -1.0, -0.5]])
    n = np.array([[-1.0, 0, 0], [0, -1.0, 0], [0, 1.0, 0]])
    overlaps, _, clearance = hand_checks_along(replace(g, hand=hand, points=p, normals=n))
    (o,) = overlaps[0]
    gap = np.hypot(1.3 - 0.9, 1.3 - 0.9)
    assert (o.finger, o.other_finger) == ("1", "2") and o.depth == pytest.approx(0.6 - gap, abs=1e-12)
    assert clearance is None  # no environment
    said = with_collisions(replace(g, hand=hand, points=p, normals=n)).warnings
    assert (
        f"fingers-collide: finger 1's link 'fingertip' and finger 2's link 'fingertip' overlap by {0.6 - gap:.3g}"
        in said
    )


def test_a_contact_on_the_face_that_rests_on_the_table_is_warned_with_its_distance(tmp_path):
    doc = {
        "object": {"box": [0.065, 0.065, 0.065], "pose": {"position": [0, 0, 0.0325]}},
        "contacts": [{"point": [0.0325, 0.015, 0.045]}, {"point": [-0.0325, 0, 0.0005]}, {"point": [0, 0.01, 0]}],
        "environment": {"table": {"height": 0}},
    }
    path = tmp_path / "on-table.yaml"
    path.write_text(yaml.safe_dump(doc), "utf-8")
    result = CliRunner().invoke(app, ["resolve", str(path), "--twist", "0,0,1,0,0,0", "-f", "json"])
    (rec,) = json.loads(result.stdout)
    said = [w for w in rec["warnings"] if w.startswith("finger-hits-environment")]
    assert said == [
        "finger-hits-environment: contact 3 is 0 from the table, within the clearance 0.001",
        "finger-hits-environment: contact 2 is 0.0005 from the table, within the clearance 0.001",
    ]
    assert "warning: finger-hits-environment: contact 3 is 0 from the table" in result.stderr


@needs_trifinger
def test_clearance_from_the_command_line_warns_the_fingertip_nearer_than_it():
    args = ["resolve", str(TRIFINGER), "-f", "json", "--clearance", "0.006"]
    result = CliRunner().invoke(app, args)
    rec = json.loads(result.stdout)[0]
    said = [w for w in rec["warnings"] if w.startswith("finger-hits-environment")]
    assert said == [
        "finger-hits-environment: finger 3's link 'finger_tip_link_240' is 0.005 from the table, within the clearance 0.006"
    ]


def test_table_from_the_command_line_reads_into_every_grasp_and_an_object_below_it_is_an_error():
    from grasptwist.io.grasp import READING

    reading = replace(READING, table=-1.0, clearance=0.01)
    (g,) = gt.read_grasps(GRASPS / "three-finger-hand.yaml", reading=reading)
    assert (g.environment.table_height, g.environment.clearance, g.environment.boxes) == (-1.0, 0.01, ())
    (err,) = gt.read_grasps(GRASPS / "three-finger-hand.yaml", reading=replace(READING, table=-0.5))
    assert err.code == "object-below-table" and "goes 0.5 below the table at z = -0.5" in err.message


def test_a_files_environment_is_read_and_its_mistakes_located(tmp_path):
    text = (GRASPS / "three-finger-hand.yaml").read_text("utf-8")
    good = text + (
        "environment:\n  table: {height: -1}\n  boxes:\n    - {size: [1, 2, 3], pose: {position: [5, 0, 0]}}\n"
        "  clearance: 0.05\n"
    )
    (g,) = gt.read_grasps(good.encode(), file="x.yaml")
    env = g.environment
    assert env.table_height == -1.0 and env.clearance == 0.05 and env.boxes[0].size.tolist() == [1, 2, 3]
    assert env.boxes[0].pose[:3, 3].tolist() == [5, 0, 0] and env.line == text.count("\n") + 2
    end = text.count("\n")
    for bad, codes, line in (
        ("environment:\n  boxes: [{size: [1, 0, 3]}]\n", ["invalid-size"], end + 2),
        ("environment:\n  clearance: -1\n", ["invalid-clearance"], end + 2),
        ("environment:\n  table: {z: 0}\n", ["missing-key", "unknown-key"], end + 2),
        ("environment: [1]\n", ["not-a-mapping"], end + 1),
    ):
        errors = gt.read_grasps((text + bad).encode(), file="x.yaml")
        assert [e.code for e in errors] == codes and {e.line for e in errors} == {line}, bad


def test_gt_synthesize_puts_the_command_lines_checks_on_a_hand(monkeypatch):
    import grasptwist.run.grasp_search as search

    (g,) = gt.read_grasps(GRASPS / "three-finger-hand.yaml")
    seen = {}
    monkeypatch.setattr(search, "solve", lambda problem: seen.update(problem=problem))
    tips = gt.hand.home_tips(g.hand, g.points)
    up = [[0, 0, 1.0, 0, 0, 0]]  # the object has no mass: a wrench to hold
    gt.synthesize(g.object, 0.8, hand=g.hand, tips=tips, environment=Environment(-1.0), wrenches=up, hold=False)
    hand = seen["problem"].hand
    assert hand.environment.table_height == -1.0 and hand.clearance == 0.001 and hand.hulls is not None


def test_gt_synthesize_of_a_grasp_takes_its_files_object_hand_environment_and_wrist(monkeypatch):
    """``gt.synthesize(g.object, mu, hand=g.hand)`` ignored the file's table; a ``Grasp`` brings it."""
    import grasptwist.run.grasp_search as search

    (g,) = gt.read_grasps(GRASPS / "three-finger-hand.yaml")
    g = replace(g, environment=Environment(-1.5), wrist=np.array([0.0, 0, 3.0]))
    seen = {}
    monkeypatch.setattr(search, "solve", lambda problem: seen.update(problem=problem))
    gt.synthesize(g, 0.8, count=1, wrenches=[[0, 0, 1.0, 0, 0, 0]])  # its object has no mass
    tips = gt.hand.home_tips(g.hand, g.points)  # the inline tips at home on the file's contacts (tip radius 0)
    p = seen["problem"]
    assert p.object is g.object and p.environment is g.environment and p.wrist.tolist() == [0, 0, 3.0]
    assert p.hand.environment.table_height == -1.5 and p.hand.hand is g.hand
    np.testing.assert_allclose(p.hand.tips, tips, atol=1e-12)
    gt.synthesize(g, 0.8, environment=Environment(-2.0), wrist=None, wrenches=[[0, 0, 1.0, 0, 0, 0]])  # given wins
    assert seen["problem"].environment.table_height == -2.0 and seen["problem"].wrist is None
    with pytest.raises(gt.InputError, match="has no object to search") as raised:
        gt.synthesize(replace(g, object=None), 0.8)
    assert raised.value.code == "no-object"


@pytest.mark.slow  # the default run's 40 s: development.md, Test time
def test_a_grasp_files_table_keeps_gt_synthesizes_contacts_off_it(tmp_path):
    doc = {"object": {"box": [0.065, 0.065, 0.065], "pose": {"position": [0, 0, 0.0325]}, "mass": 0.1}}
    doc["contacts"] = [{"point": [0.0325, 0, 0.03]}, {"point": [-0.0325, 0.01, 0.03]}, {"point": [0, 0.0325, 0.04]}]
    doc["environment"] = {"table": {"height": 0}, "clearance": 0.01}
    path = tmp_path / "cube.yaml"
    path.write_text(yaml.safe_dump(doc), "utf-8")
    (g,) = gt.read_grasps(path)
    s = gt.synthesize(g, 0.8, count=2, candidates=800, loads="weight")  # the table's test: the weight is enough
    assert len(s.points) == 2 and (s.points[..., 2] >= 0.01 - 1e-12).all()  # never the face on the table


@needs_trifinger
def test_the_trifinger_picture_draws_its_table(placed):
    from grasptwist.plot.scene import grasp_scene

    (table,) = grasp_scene(placed).of_kind("table")
    assert table.label == "table z = 0" and (table.corners[:, 2] == 0).all()


@needs_trifinger
@pytest.mark.slow
def test_twenty_trifinger_grasps_on_its_table_put_no_finger_below_it_nor_into_each_other():
    # 0.5.0, without the table: 7 of these 20 put a fingertip sphere 6 to 10 mm below the floor,
    # 10 had two fingers into each other (0.3 to 12.9 mm)
    args = ["synthesize", str(TRIFINGER), "-n", "20", "--friction", "0.8", "--mass", "0.094", "-f", "jsonl"]
    result = CliRunner().invoke(app, [*args, "--seconds", "3000"])
    records = [json.loads(line) for line in result.stdout.splitlines()]
    assert len(records) == 20 and all(r["ok"] for r in records)
    assert min(r["clearance"] for r in records) >= 0.001
    assert min(c["tip_center"][2] for r in records for c in r["contacts"]) >= 0.011  # radius + clearance
    (g,) = gt.read_grasps(TRIFINGER)
    for r in records:
        q = np.array([r["joint_positions"][name] for name in g.hand.joint_names])
        p = np.array([c["point"] for c in r["contacts"]])
        n = np.array([c["normal"] for c in r["contacts"]])
        overlaps, hits, clearance = hand_checks_along(replace(g, points=p, normals=n, joint_positions=q))
        assert overlaps == [()] and hits == [()] and clearance[0] == pytest.approx(r["clearance"])


def test_synthesize_on_a_table_from_the_command_line_reports_each_clearance_and_writes_the_table_back(tmp_path):
    doc = {"object": {"box": [0.065, 0.065, 0.065], "mass": 0.094}, "friction": 0.8}
    path = tmp_path / "cube.yaml"
    path.write_text(yaml.safe_dump(doc), "utf-8")
    found = tmp_path / "found.yaml"
    args = ["synthesize", str(path), "-n", "1", "--candidates", "500", "--table", "-0.0325", "--clearance", "0.004"]
    args += ["--loads", "weight"]  # the table's test: the weight is enough
    result = CliRunner().invoke(app, [*args, "-f", "jsonl", "-o", str(found)])
    records = [json.loads(line) for line in result.stdout.splitlines()]
    assert [r["ok"] for r in records] == [True]
    for r in records:  # without a hand, the contacts' least height above the table
        lowest = min(c["point"][2] for c in r["contacts"]) + 0.0325
        assert r["clearance"] == pytest.approx(lowest, abs=1e-15) and lowest >= 0.004
    back = gt.read_grasps(found)
    assert [(g.environment.table_height, g.environment.clearance) for g in back] == [(-0.0325, 0.004)]
    csv = CliRunner().invoke(app, [*args, "-f", "csv"]).stdout.splitlines()
    column = csv[0].split(",").index("clearance")
    assert [float(line.split(",")[column]) for line in csv[1:]] == pytest.approx([r["clearance"] for r in records])


@needs_trifinger
def test_resolve_and_forces_records_carry_the_grasps_clearance_and_none_without_an_environment():
    (spin, _) = json.loads(CliRunner().invoke(app, ["resolve", str(TRIFINGER), "-f", "json"]).stdout)
    assert spin["clearance"] == pytest.approx(0.005, abs=1e-9)  # the lowest fingertip sphere's bottom
    args = ["forces", str(TRIFINGER), "--friction", "0.8", "--wrench", "0,0,1,0,0,0", "-f", "json"]
    (held,) = json.loads(CliRunner().invoke(app, args).stdout)
    assert held["clearance"] == spin["clearance"]
    csv = CliRunner().invoke(app, ["resolve", str(GRASPS / "box-edge.yaml"), "-f", "csv"]).stdout.splitlines()
    column = csv[0].split(",").index("clearance")
    assert {line.split(",")[column] for line in csv[1:]} == {""}  # no environment
