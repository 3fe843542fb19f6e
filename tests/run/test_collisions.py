"""Fingers that must not pass through the object (issue 30 item 5): the TriFinger's links against boxes at
known overlaps, at its cube grasp (no collision), with the cube enlarged (middle links named), along a path;
the fingertip sphere's own contact left out; the warning in records and on stderr; the URDF's collision
geometry read (the visual geometry when it has none)."""

import json
from dataclasses import replace
from importlib.util import find_spec
from pathlib import Path

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from grasptwist.cli import app
from grasptwist.engine.collision import collision_tolerance
from grasptwist.engine.path import Poses
from grasptwist.model import GraspObject, Shape
from hand_grasps import trifinger_cube
from places import ROOT, TESTS

pytestmark = pytest.mark.skipif(
    find_spec("yourdfpy") is None or find_spec("robot_properties_fingers") is None, reason="needs the TriFinger URDF"
)

TRIFINGER = ROOT / "grasps" / "trifinger-cube.yaml"
EDGE = 0.065


def box(size, position):
    pose = np.eye(4)
    pose[:3, 3] = position
    return GraspObject(Shape("box", np.asarray(size, dtype=float)), pose)


def trifinger_file(folder, **changes):
    """The bundled TriFinger grasp at the joint positions of ``hand_grasps`` (each tip sphere's centre
    one radius behind its contact, whatever the bundled file solves for), with ``changes``."""
    doc = yaml.safe_load(TRIFINGER.read_text("utf-8"))
    doc["hand"].pop("seed", None)
    doc["hand"]["joint_positions"] = trifinger_cube()["joint_positions"]
    doc["twists"] = doc["twists"][:1]
    doc.update(changes)
    path = folder / "trifinger.yaml"
    path.write_text(yaml.safe_dump(doc, sort_keys=False), "utf-8")
    return path


@pytest.fixture(scope="module")
def grasp(tmp_path_factory):
    """The TriFinger grasp on its cube, placed, its fingertips 10 mm spheres."""
    from grasptwist.run.placement import read_grasps

    (g,) = read_grasps(trifinger_file(tmp_path_factory.mktemp("trifinger")))
    hand = replace(g.hand, fingers=tuple(replace(f, tip_radius=0.01) for f in g.hand.fingers))
    return replace(g, hand=hand, object=box([EDGE] * 3, [0, 0, EDGE / 2]))


def point_tips(g):
    return replace(g, hand=replace(g.hand, fingers=tuple(replace(f, tip_radius=0.0) for f in g.hand.fingers)))


def lowest(g, link):
    """The lowest vertex of ``link`` at the grasp's joint positions."""
    from grasptwist.engine.collision import link_poses
    from grasptwist.io.urdf_meshes import link_geometry

    geometry = link_geometry(g.hand)
    i = [x.link for x in geometry].index(link)
    p = link_poses(g.hand, geometry, g.joint_positions[None])[0, i]
    v = geometry[i].vertices @ p[:3, :3].T + p[:3, 3]
    return v[np.argmin(v[:, 2])]


def test_the_trifinger_at_its_cube_grasp_does_not_collide(grasp):
    from grasptwist.run.collisions import finger_collisions

    assert finger_collisions(grasp, grasp.joint_positions) == ()
    assert finger_collisions(point_tips(grasp), grasp.joint_positions) == ()  # the spheres touch: 0 deep
    assert finger_collisions(replace(grasp, object=None), grasp.joint_positions) == ()


def test_a_fingertip_through_a_box_is_as_deep_as_the_overlap_and_its_sphere_is_the_contact(grasp):
    from grasptwist.run.collisions import finger_collisions

    # a 2 cm box under finger 1's tip only, its top 4 mm above the tip link's lowest vertex
    low = lowest(grasp, "finger_tip_link_0")
    slab = box([0.02, 0.02, 0.02], low + [0, 0, 0.004 - 0.01])
    (hit,) = finger_collisions(replace(point_tips(grasp), object=slab), grasp.joint_positions)
    assert (hit.finger, hit.link) == ("1", "finger_tip_link_0")
    assert hit.depth == pytest.approx(0.004, abs=1e-12)
    # with its 10 mm sphere, the tip pressed 4 mm in is the contact (its depth is the gap's business), no collision
    assert finger_collisions(replace(grasp, object=slab), grasp.joint_positions) == ()


def test_the_cube_enlarged_so_the_middle_links_pass_through_names_them(grasp):
    from grasptwist.run.collisions import finger_collisions

    big = replace(grasp, object=box([0.2] * 3, [0, 0, 0.1]))
    found = finger_collisions(big, grasp.joint_positions)
    middle = {(c.finger, c.link) for c in found if "middle" in c.link}
    assert middle == {("1", "finger_middle_link_0"), ("2", "finger_middle_link_120"), ("3", "finger_middle_link_240")}
    assert [c.depth for c in found] == sorted((c.depth for c in found), reverse=True)
    assert min(c.depth for c in found) > collision_tolerance(big.object)
    # finger 1's lower link: from 2 cm below the original grasp's top plane the cube grew 3.5 cm up and out
    assert next(c.depth for c in found if c.link == "finger_lower_link_0") > 0.05


def test_a_path_sample_that_pushes_the_cube_into_a_finger_collides_there_only(grasp):
    from grasptwist.run.collisions import PathCollisions

    # three samples, the fingers held still: the cube where it is, then 3 mm into finger 1, then back
    moved = np.zeros((3, 3))
    moved[1] = [0.003, 0.0, 0.0]  # finger 1 touches face +x: the cube pushes 3 mm into its sphere and links
    poses = Poses(np.arange(3.0), np.zeros(3, int), np.broadcast_to(np.eye(3), (3, 3, 3)), moved, np.zeros((3, 6)))
    q = np.broadcast_to(grasp.joint_positions, (3, len(grasp.joint_positions)))
    along = PathCollisions(point_tips(grasp))
    said, clearance = along.at(q, poses)
    assert [bool(w) for w in said] == [False, True, False]
    # the hand held still above the bundled file's table: its tip link's lowest hull vertex 5 mm up
    assert clearance == pytest.approx([0.005] * 3, abs=5e-4)
    # the tip mesh's deepest vertex along +x is 0.02 mm inside its 10 mm sphere
    assert said[1][0].startswith("finger-collides: finger 1's link 'finger_tip_link_0' is 0.00298 inside the object")
    depth, count, first = along.seen["finger-collides", "1", "finger_tip_link_0"]
    assert 0.00297 < depth <= 0.003 and (count, first) == (1, 1.0)
    assert along.at(q[:1], Poses(*(a[:1] for a in poses)))[0] is None  # the cube where it is: none
    (line,) = along.warnings(3)
    assert line == (
        "finger-collides: finger 1's link 'finger_tip_link_0' goes up to 0.00298 inside the object "
        "at 1 of 3 samples, from t = 1"
    )


def run(*args):
    return CliRunner().invoke(app, [str(a) for a in args])


def test_a_column_through_the_fingers_is_a_warning_in_the_records_and_on_stderr(tmp_path):
    # the cube's faces continued 30 cm up: the contacts stay on them, the upper and middle links cross them
    path = trifinger_file(tmp_path, object={"box": [EDGE, EDGE, 0.3], "pose": {"position": [0, 0, 0.15]}})
    result = run("resolve", path, "-f", "jsonl")
    (rec,) = [json.loads(line) for line in result.stdout.splitlines()]
    said = [w for w in rec["warnings"] if w.startswith("finger-collides")]
    assert rec["ok"] and len(said) >= 4
    assert "finger-collides: finger 2's link 'finger_upper_link_120' is 0.0148 inside the object" in said
    lines = [line for line in result.stderr.splitlines() if "finger-collides" in line]
    assert lines[0] == f"{path}: grasp 'trifinger-cube', twist 'spin': warning: {said[0]}"
    assert len(lines) == len(said)
    for command in (("forces", "--friction", "0.5"), ("check",)):  # their records carry them too
        (rec,) = [json.loads(line) for line in run(*command, path, "-f", "jsonl").stdout.splitlines()]
        assert [w for w in rec["warnings"] if w.startswith("finger-collides")] == said


def test_a_urdf_without_collision_geometry_falls_back_to_its_visual_geometry(tmp_path):
    from grasptwist import hand
    from grasptwist.io.urdf_meshes import link_geometry

    source = (TESTS / "corpus" / "urdf" / "hand.urdf").read_text()
    a3 = '<link name="a3"><{0}><origin xyz="0 0 -0.025"/><geometry><box size="0.01 0.02 0.05"/></geometry></{0}></link>'
    b3 = '<link name="b3"><visual><geometry><sphere radius="0.01"/></geometry></visual></link>'
    for kind, links in (("collision", ["a3"]), ("visual", ["a3", "b3"])):
        text = source.replace('<link name="a3"/>', a3.format(kind)).replace('<link name="b3"/>', b3)
        (tmp_path / "h.urdf").write_text(text)
        toy = hand.load_urdf_hand("h.urdf", ["a_tip", "b_tip"], folder=tmp_path)
        geometry = link_geometry(toy, folder=tmp_path)
        # with collision geometry, a link with only a visual one is left out
        assert [g.link for g in geometry] == links
        (a,) = [g for g in geometry if g.link == "a3"]
        assert (a.finger, a.joints, len(a.vertices)) == (0, 3, 8)
        # the box's centre at home: 25 mm down the a3 frame, which is the tip's less its 10 mm, 50 mm offset
        a3_frame = toy.fingers[0].tip_pose @ np.array([[1, 0, 0, -0.01], [0, 1, 0, 0], [0, 0, 1, 0.05], [0, 0, 0, 1.0]])
        assert a.vertices.mean(axis=0) == pytest.approx(a3_frame[:3, :3] @ [0, 0, -0.025] + a3_frame[:3, 3], abs=1e-15)


def test_a_hand_mesh_that_cannot_be_read_fails_its_grasp_located(grasp, monkeypatch):
    from grasptwist.model import InputError
    from grasptwist.run import collisions

    def unreadable(hand, folder=None, max_bytes=None):
        raise InputError("read-error", "mesh 'prox-sim.stl': cannot read: no such file", hand.source)

    monkeypatch.setattr(collisions, "link_geometry", unreadable)
    monkeypatch.setattr(collisions, "_GEOMETRY", {})
    error = collisions.with_collisions(grasp)
    assert isinstance(error, InputError)
    # at the grasp file's urdf key, the URDF named in the message
    lines = Path(grasp.file).read_text("utf-8").splitlines()
    line = next(i for i, row in enumerate(lines, 1) if row.lstrip().startswith("urdf:"))
    column = lines[line - 1].index("urdf:") + len("urdf: ") + 1
    assert (error.code, error.file, error.line, error.column) == ("read-error", grasp.file, line, column)
    assert error.message == f"hand.urdf: {grasp.hand.source}: mesh 'prox-sim.stl': cannot read: no such file"
    bare = replace(grasp, hand=replace(grasp.hand, urdf_at=None))  # a hand read in Python: at the document
    assert (collisions.with_collisions(bare).line, collisions.with_collisions(bare).column) == (grasp.line, None)
    assert collisions.with_collisions(replace(grasp, object=None)) is not None  # nothing to read: no error


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_follow_names_the_links_through_the_object_per_sample_and_in_its_summary(tmp_path):
    path = trifinger_file(tmp_path, object={"box": [EDGE, EDGE, 0.3], "pose": {"position": [0, 0, 0.15]}})
    result = run("follow", path, "--twist", "0,0,0.5,0,0,0", "--duration", "1", "--samples", "3", "-f", "jsonl")
    *samples, summary = [json.loads(line) for line in result.stdout.splitlines()]
    assert [s["t"] for s in samples] == [0.0, 0.5, 1.0]
    first = [w for w in samples[0]["warnings"] if w.startswith("finger-collides")]
    assert "finger-collides: finger 2's link 'finger_upper_link_120' is 0.0148 inside the object" in first
    said = [w for w in summary["warnings"] if w.startswith("finger-collides")]
    assert said[0].endswith("at 3 of 3 samples, from t = 0")
    stderr = [line.split(": warning: ", 1)[1] for line in result.stderr.splitlines() if "finger-collides" in line]
    assert stderr == said  # samples are counted, not told: the summary's lines
