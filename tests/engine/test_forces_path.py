"""Holding a weight along a path (engine/forces/hold.py): the grip at each pose, and where none exists.

The analytic cases are a tray: three contacts on its underside (the plane z = 0, normals
up, into the object), the centre of mass at height h above their centroid, turned about a
horizontal axis through the origin by theta.  Seen from the tray the fingers must exert
the force ``m g (0, sin theta, cos theta)`` (turning about x) at the centre of mass.
Tangential forces in the plane make no moment about in-plane axes, so the normal forces
alone balance the moment: their centre of pressure is where the force's line meets the
plane, ``h tan(theta)`` from the centroid; and with every tangential force proportional
to its normal force (friction used ``tan(theta)`` everywhere) the yaw moment is zero.
So the tray holds iff ``cos(theta) > 0``, ``|tan(theta)| <= mu`` and the centre of
pressure lies in the contact triangle.
"""

import json
import math

import numpy as np
import pytest

from grasptwist.engine.forces.grasp_map import ForceStatus
from grasptwist.engine.forces.hold import cannot_hold, grip_along, hold_verdicts, hold_wrench, object_weight
from grasptwist.io.grasp import load_grasps
from grasptwist.model import GraspObject, Segment, Shape

TRIANGLE = np.array([[1, 0, 0], [-0.5, 0.75**0.5, 0], [-0.5, -(0.75**0.5), 0]])
UP = np.array([[0.0, 0, 1]] * 3)
G = [0, 0, -9.81]


def turn(axis, duration=2 * math.pi):
    return [Segment(duration, twist=list(axis) + [0, 0, 0])]


SLOW = pytest.mark.slow  # each stretch is some 40 grip solves; one case of each runs by default


@pytest.mark.parametrize(
    "samples, mu",
    [(8, 0.5), pytest.param(5, 1.3, marks=SLOW), pytest.param(33, 0.5, marks=SLOW), pytest.param(8, 1.3, marks=SLOW)],
)
def test_a_tilted_tray_slides_off_at_the_friction_angle(samples, mu):
    times = np.linspace(0, 2 * math.pi, samples)
    (s,) = cannot_hold(TRIANGLE, UP, mu, 1.0, [0, 0, 0], G, turn([1, 0, 0]), times)
    assert s.t_start == pytest.approx(math.atan(mu), abs=1e-6)
    assert s.t_end == pytest.approx(2 * math.pi - math.atan(mu), abs=1e-6)
    assert s.culprit >= 0  # a cone too narrow, not a pull


@SLOW
def test_the_safety_factor_narrows_the_cones():
    (s,) = cannot_hold(TRIANGLE, UP, 0.5, 2.0, [0, 0, 0], G, turn([1, 0, 0]), np.linspace(0, 6, 7), safety=2.0)
    assert s.t_start == pytest.approx(math.atan(0.25), abs=1e-6)


@pytest.mark.parametrize("samples", [7, pytest.param(5, marks=SLOW), pytest.param(13, marks=SLOW)])
@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_a_high_centre_of_mass_tips_over_where_its_line_leaves_the_triangle(samples):
    # Turning about y moves the centre of pressure to (h tan(theta), 0): it leaves the
    # triangle at the vertex x = 1 (theta = atan(1/h)) going one way and at the side x = -1/2
    # (theta = -atan(1/(2h))) the other; friction 2 is never the limit there.  The centre of
    # mass moves with the tray: with it at the centroid instead nothing tips.
    h = 1.0
    (s,) = cannot_hold(TRIANGLE, UP, 2.0, 1.0, [0, 0, h], G, turn([0, 1, 0]), np.linspace(0, 2 * math.pi, samples))
    assert s.t_start == pytest.approx(math.atan(1 / h), abs=1e-6)
    assert s.t_end == pytest.approx(2 * math.pi - math.atan(1 / (2 * h)), abs=1e-6)
    assert s.culprit == -1  # beyond the edge a finger would have to pull
    (low,) = cannot_hold(TRIANGLE, UP, 2.0, 1.0, [0, 0, 0], G, turn([0, 1, 0]), np.linspace(0, 2 * math.pi, 13))
    assert low.t_start == pytest.approx(math.atan(2.0), abs=1e-6)


def test_a_ball_held_at_its_equator_holds_at_every_angle():
    # Force closure (closure friction 0): any wrench is held, however the ball is turned.
    times = np.linspace(0, 2 * math.pi, 17)
    for axis in ([1, 0, 0], [0, 1, 0], [1, 1, 0]):
        axis = np.array(axis) / np.linalg.norm(axis)
        assert cannot_hold(TRIANGLE, -TRIANGLE, 0.5, 1.0, [0, 0, 0], G, turn(axis), times) == ()
        _, g = grip_along(TRIANGLE, -TRIANGLE, 0.5, 1.0, [0, 0, 0], G, turn(axis), times)
        assert g.ok.all()


def test_the_grip_along_a_path_makes_the_hold_wrench_at_each_pose_with_gravity_fixed():
    rng = np.random.default_rng(3)
    com = np.array([0.1, -0.2, 0.3])
    path = [Segment(1.0, twist=[0.4, -0.3, 0.9, 0.1, 0.2, 0.0]), Segment(0.5, twist=[0, 1, 0, 0, 0, 0.1], frame="body")]
    times = np.sort(rng.uniform(0, 1.5, 20))
    poses, g = grip_along(TRIANGLE, -TRIANGLE + [0, 0, 0.2], 0.8, 2.0, com, G, path, times)
    assert g.ok.all()
    c = np.einsum("tij,j->ti", poses.rotation, com) + poses.position  # the centre of mass moves
    weight = 2.0 * np.array(G)
    points = np.einsum("tij,kj->tki", poses.rotation, TRIANGLE) + poses.position[:, None]
    np.testing.assert_allclose(g.force.sum(axis=1), np.broadcast_to(-weight, (20, 3)), atol=1e-9)
    np.testing.assert_allclose(np.cross(points, g.force).sum(axis=1), -np.cross(c, weight), atol=1e-9)
    assert (g.friction_used <= 0.8 * (1 + 1e-9)).all()
    assert g.status.dtype.kind == "i" and set(g.status.tolist()) == {ForceStatus.OK}


def test_hold_wrench_is_the_loaders_hold():
    (equator,) = [g for g in load_grasps("grasps/sphere.yaml") if g.name == "sphere-equator"]
    (hold,) = [w for w in equator.wrenches if w.name == "hold"]
    np.testing.assert_allclose(hold_wrench(equator.mass, equator.center_of_mass, equator.gravity), hold.wrench)
    # carried by a pose: the weight's force is unchanged, its moment is about the moved centre
    r = np.array([[0.0, -1, 0], [1, 0, 0], [0, 0, 1]])
    w = hold_wrench(2.0, [1, 0, 0], [0, 0, -10], r, [0, 0, 5])
    np.testing.assert_allclose(w, [0, 0, 20, 20, 0, 0], atol=1e-12)  # c = (0, 1, 5): -c x (0, 0, -20)


TRAY = """\
name: tray
units: m
contacts:
  - {name: a, point: [1, 0, 0], normal: [0, 0, 1]}
  - {name: b, point: [-0.5, 0.8660254037844386, 0], normal: [0, 0, 1]}
  - {name: c, point: [-0.5, -0.8660254037844386, 0], normal: [0, 0, 1]}
friction: 0.5
mass: 1
center_of_mass: [0, 0, 0]
paths:
  - name: tilt
    segments:
      - angular: [1, 0, 0]
        duration: 6.283185307179586
"""


def follow_json(tmp_path, text, *args):
    from typer.testing import CliRunner

    from grasptwist.cli import app

    path = tmp_path / "g.yaml"
    path.write_text(text)
    result = CliRunner().invoke(app, ["follow", str(path), "-f", "jsonl", "--method", "tangent", *args])
    return result, [json.loads(line) for line in result.stdout.splitlines()]


def test_follow_carries_the_grip_per_sample_and_the_cannot_hold_stretches_in_its_summary(tmp_path):
    result, recs = follow_json(tmp_path, TRAY, "--samples", "4")
    *samples, summary = recs
    assert result.exit_code == 1  # the tray drops its weight: the path fails, as a degeneracy does
    held = samples[0]["grip"]
    assert held["normal_force"] == pytest.approx([9.81 / 3] * 3) and held["safety"] == 1.0
    assert held["total_normal_force"] == pytest.approx(9.81)
    assert samples[1]["grip"]["error"] == {  # t = 2 pi / 3: tilted past the vertical
        "code": "cannot-hold",
        "message": "the wrench needs a finger to pull (no pushing forces make it, whatever the friction)",
    }
    (stretch,) = summary["summary"]["cannot_hold"]
    assert stretch["t_start"] == pytest.approx(math.atan(0.5), abs=1e-6)
    assert stretch["t_end"] == pytest.approx(2 * math.pi - math.atan(0.5), abs=1e-6)
    assert stretch["reason"] == "friction" and stretch["culprit"] in ("a", "b", "c")
    assert summary["summary"]["hold_unjudged"] == []  # the grip has its verdict everywhere
    assert summary["ok"] is False
    assert "error: cannot hold the weight from t = 0.463648 to t = 5.819538" in result.stderr


def test_follow_without_a_mass_or_a_friction_has_no_grip_fields(tmp_path):
    for drop in ("friction: 0.5\n", "mass: 1\ncenter_of_mass: [0, 0, 0]\n"):
        result, recs = follow_json(tmp_path, TRAY.replace(drop, ""))
        assert result.exit_code == 0
        assert all("grip" not in r for r in recs[:-1])
        assert "cannot_hold" not in recs[-1]["summary"] and "hold_unjudged" not in recs[-1]["summary"]


@pytest.mark.slow  # the default run's 40 s: development.md, Test time
def test_where_the_grip_fails_otherwise_the_weight_is_unjudged_not_held():
    # a full turn about x (the tray slides off between atan(mu) and 2 pi - atan(mu)), then a
    # spin at 1e300 rad/s, whose pose overflows at once: cannot-hold and unjudged, each located
    path = turn([1, 0, 0]) + [Segment(1.0, twist=[0, 0, 1e300, 0, 0, 0])]
    times = np.linspace(0, 2 * math.pi + 1, 9)
    with np.errstate(over="ignore", invalid="ignore"):
        (falls,), (unknown,) = hold_verdicts(TRIANGLE, UP, 0.5, 1.0, [0, 0, 0], G, path, times)
        assert cannot_hold(TRIANGLE, UP, 0.5, 1.0, [0, 0, 0], G, path, times) == (falls,)
        _, g = grip_along(TRIANGLE, UP, 0.5, 1.0, [0, 0, 0], G, path, times[-2:])
    assert falls.t_start == pytest.approx(math.atan(0.5), abs=1e-6)
    assert falls.t_end == pytest.approx(2 * math.pi - math.atan(0.5), abs=1e-6)
    assert unknown.status == ForceStatus.NONFINITE_POSE and unknown.t_end == 2 * math.pi + 1
    assert unknown.t_start == pytest.approx(2 * math.pi, abs=1e-6)
    assert g.status.tolist() == [ForceStatus.NONFINITE_POSE] * 2  # the grip itself says why
    # degenerate contacts: no grip anywhere, so no verdict anywhere (and no stretch it cannot hold)
    same = np.array([TRIANGLE[0], TRIANGLE[0], TRIANGLE[2]])
    assert hold_verdicts(same, UP, 0.5, 1.0, [0, 0, 0], G, turn([1, 0, 0]), times[:3]) == (
        (),
        ((0.0, 2 * math.pi, ForceStatus.COINCIDENT_CONTACTS),),
    )


CUBE = """\
name: cube-mm
units: mm
contacts:
  - {name: tx, point: [30, 5, -5], normal: [-1, 0, 0]}
  - {name: ty, point: [-5, 30, 5], normal: [0, -1, 0]}
  - {name: tz, point: [5, -5, 30], normal: [0, 0, -1]}
friction: 0.8
mass: 0.2
center_of_mass: [0, 0, 0]
"""


def test_follow_never_says_the_weight_is_held_where_the_pose_overflows(tmp_path):
    args = ["--twist", "0,0,1e308,0,0,0", "--duration", "1", "--samples", "3"]
    result, recs = follow_json(tmp_path, CUBE, *args)
    *samples, summary = recs
    assert result.exit_code == 1 and summary["ok"] is False
    assert [r["grip"].get("error", {}).get("code") for r in samples] == [None, "nonfinite-pose", "nonfinite-pose"]
    assert summary["summary"]["cannot_hold"] == []
    (unknown,) = summary["summary"]["hold_unjudged"]
    assert unknown == {"t_start": pytest.approx(0, abs=1e-9), "t_end": 1.0, "code": "nonfinite-pose"}
    line = "cannot judge whether the weight is held from t = 0.000000 to t = 1.000000: the grip fails there (nonfinite-pose)"
    assert f"g.yaml: grasp 'cube-mm', path 'command-line': error: {line}" in result.stderr
    from typer.testing import CliRunner

    from grasptwist.cli import app

    table = CliRunner().invoke(app, ["follow", str(tmp_path / "g.yaml"), *args])
    assert table.exit_code == 1 and "held all along" not in table.stdout
    summary_lines = table.stdout.split("summary:")[1].splitlines()
    assert summary_lines[-1] == f"  {line.replace('000000', '0000')}"


def test_an_object_s_weight_is_its_mass_or_density_times_volume_at_its_centre():
    pose = np.eye(4)
    pose[:3, 3] = [0.0, 0.5, 0.0]
    box = GraspObject(Shape("box", np.array([0.1, 0.2, 0.5])), pose, density=1000.0)  # 0.01 m^3: 10 kg
    w = object_weight(box, [0.0, 0.0, -10.0])
    assert w.mass == pytest.approx(10.0, rel=1e-12)
    np.testing.assert_allclose(w.center_of_mass, [0.0, 0.5, 0.0], atol=1e-15)
    # lifted by 100 N along z, whose line is 0.5 m along y: a moment of 0.5 x 100 about x
    np.testing.assert_allclose(w.wrench, [0, 0, 100.0, 50.0, 0, 0], rtol=1e-12, atol=1e-12)
    assert object_weight(GraspObject(box.shape, pose), [0.0, 0.0, -10.0]) is None
