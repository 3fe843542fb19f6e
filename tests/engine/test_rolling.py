"""Fingertips that roll without slipping (engine/rolling.py): a closed form on a turning ball, and on
the TriFinger's spin the sliding the plan leaves against what follow's track asks for."""

import numpy as np
import pytest

from grasptwist.engine.hands import track
from grasptwist.engine.kinematics import forward_kinematics
from grasptwist.engine.path import integrate
from grasptwist.engine.rolling import roll
from grasptwist.model import GraspObject, Segment, Shape
from grasptwist.run.placement import read
from places import GRASPS

R, TIP = 0.05, 0.01


def test_spheres_on_slides_roll_round_a_turning_ball_like_planet_gears():
    # a ball turning about z at w: a sphere that never turns rolls on it without slip when its centre
    # moves with the ball's point at the contact, speed w R at radius R + r: it goes round at
    # w R / (R + r), and its contact falls behind on the ball by w t r / (R + r)
    ball = GraspObject(Shape("sphere", np.array([R])), np.eye(4))
    angles = np.radians([0.0, 120.0, 240.0])
    p = R * np.stack((np.cos(angles), np.sin(angles), np.zeros(3)), axis=1)
    w, times = 0.5, np.linspace(0.0, 1.0, 21)
    out = roll(None, None, ball, p, -p / R, np.full(3, TIP), [Segment(1.0, twist=[0, 0, w, 0, 0, 0])], times)
    turned = w * R / (R + TIP) * times[-1]
    expected = (R + TIP) * np.stack((np.cos(angles + turned), np.sin(angles + turned), np.zeros(3)), axis=1)
    np.testing.assert_allclose(out.centers[-1], expected, atol=1e-6)  # RK4, 20 steps: 3e-7
    np.testing.assert_allclose(out.positions[-1].reshape(3, 3), expected - (R + TIP) * p / R, atol=1e-6)
    np.testing.assert_allclose(out.points[-1], expected * R / (R + TIP), atol=1e-6)
    # the rates are the contact's velocity, w z x p, for each slide
    np.testing.assert_allclose(out.rates[-1].reshape(3, 3), np.cross([0, 0, w], out.points[-1]), atol=1e-12)


def _sliding(hand, positions, points, segments, times):
    """How far each tip link's point at the contact slides over the object along a plan, summed over its
    steps: the link's displacement of the point less the object's (first order in the step)."""
    poses = integrate(segments, times)
    frames = [
        np.stack([forward_kinematics(f.screws, f.points, np.eye(4), q[list(f.joint_index)]).tip for q in positions])
        for f in hand.fingers
    ]
    total = np.zeros(3)
    for k in range(len(times) - 1):
        for f in range(3):
            link = frames[f][k + 1] @ np.linalg.inv(frames[f][k])
            body = np.eye(4)
            body[:3, :3] = poses.rotation[k + 1] @ poses.rotation[k].T
            body[:3, 3] = poses.position[k + 1] - body[:3, :3] @ poses.position[k]
            p = np.append(points[k][f], 1.0)
            total[f] += np.linalg.norm((link @ p - body @ p)[:3])
    return total


@pytest.mark.slow  # the URDF hand read, and follow's track beside: 2 s
def test_the_trifinger_spin_rolls_where_follows_track_slides_five_millimetres():
    pytest.importorskip("yourdfpy")
    g = read(str(GRASPS / "trifinger-cube.yaml"))[0]
    spin = [Segment(1.0, twist=[0, 0, 0.5, 0, 0, 0])]
    times = np.linspace(0.0, 1.0, 41)
    radii = np.full(3, 0.01)
    out = roll(g.hand, g.joint_positions, g.object, g.points, g.normals, radii, spin, times)
    # each sphere stays on its face, one radius from it, and its contact moves over the face
    assert np.abs(np.linalg.norm(out.points - out.centers, axis=-1) - 0.01).max() < 1e-6
    rolled = _sliding(g.hand, out.positions, out.points, spin, times)
    assert rolled.max() < 5e-5  # 33 um in all (first order in the step: it halves with the step)
    # follow's track holds the contact fixed on the object: each tip slides r * (the relative turn)
    tracked = track(g.hand, g.joint_positions, g.points, spin, times, normals=g.normals).positions
    poses = integrate(spin, times)
    fixed = g.points @ poses.rotation.transpose(0, 2, 1) + poses.position[:, None]
    assert (_sliding(g.hand, tracked, fixed, spin, times) > 4.5e-3).all()  # 5.0-5.1 mm
