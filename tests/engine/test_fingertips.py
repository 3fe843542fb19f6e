"""Fingertips with a radius (engine/fingertips.py): centres, gaps, where the tip touches, the
radius of a collision mesh, and fingertips rolling along paths against closed forms."""

import numpy as np
import pytest

from grasptwist.engine.fingertips import SPHERE_VERTICES, sphere_radius, tip_centers, tip_contacts
from grasptwist.engine.hands import tip_poses, track
from grasptwist.engine.ik import home_tips
from grasptwist.engine.se3 import rotvec_to_matrix
from grasptwist.model import Finger, Hand, Joint
from grasptwist.path import Segment


def finger(name, kinds, axes, points, first, radius):
    """A finger given inline: joints ``kinds`` along ``axes`` through ``points`` (at home)."""
    axes, points = np.array(axes, float), np.array(points, float)
    prismatic = np.array([k == "prismatic" for k in kinds])
    screws = np.hstack(
        (np.where(prismatic[:, None], 0.0, axes), np.where(prismatic[:, None], axes, np.cross(points, axes)))
    )
    joints = tuple(Joint(f"{name}{k}", kind, None, None, None, None) for k, kind in enumerate(kinds))
    return Finger(name, None, joints, screws, points, None, 10.0, tuple(range(first, first + len(kinds))), radius)


def cartesian(name, first, radius):
    """Three slides along x, y, z: its tip never turns."""
    return finger(name, ["prismatic"] * 3, np.eye(3), np.zeros((3, 3)), first, radius)


def hand(*fingers):
    return Hand(tuple(fingers), tuple(j.name for f in fingers for j in f.joints), None, None)


def turned(axis_point, rotvec, points, normals):
    """Contacts and normals carried by a rotation ``rotvec`` about a line through ``axis_point``."""
    r = rotvec_to_matrix(rotvec)
    return (np.asarray(points) - axis_point) @ r.T + axis_point, np.asarray(normals) @ r.T


def angle(a, b):
    return np.arctan2(np.linalg.norm(np.cross(a, b), axis=-1), np.sum(a * b, axis=-1))


def test_centres_sit_one_radius_behind_the_contacts_along_the_inward_normal():
    points = np.array([[1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0]])
    normals = np.array([[-2.0, 0, 0], [0, -1.0, 0], [0, 0, -3.0]])  # any length: made unit
    np.testing.assert_array_equal(
        tip_centers(points, normals, [0.5, 0.0, 0.25]), [[1.5, 0, 0], [0, 1, 0], [0, 0, 1.25]]
    )
    assert tip_centers(points, normals, np.zeros(3)) is points  # point tips: nothing to move


def test_gap_is_signed_and_contact_is_in_the_tip_frame():
    """A sphere of radius 1 whose centre is 1.5 above a floor has a gap of 0.5; 0.75 above, it is
    0.25 into it; turned a quarter turn about z, the floor is still below it (the tip's -z)."""
    pose = np.tile(np.eye(4), (3, 1, 1))
    pose[:, 2, 3] = [1.5, 0.75, 1.0]
    pose[2, :3, :3] = rotvec_to_matrix([0, 0, np.pi / 2])
    got = tip_contacts(pose, np.zeros((3, 3)), [[0, 0, -1.0]] * 3, np.ones(3))
    np.testing.assert_allclose(got.gap, [0.5, -0.25, 0.0], rtol=0, atol=1e-15)
    np.testing.assert_allclose(got.contact, [[0, 0, -1.0]] * 3, rtol=0, atol=1e-15)


def hemisphere(radius, n=400, seed=1):
    u = np.random.default_rng(seed).normal(size=(n, 3))
    u[:, 2] = -np.abs(u[:, 2])
    return radius * u / np.linalg.norm(u, axis=1, keepdims=True)


@pytest.mark.parametrize(
    ("vertices", "want"),
    [
        (hemisphere(0.01), 0.01),
        # a hemisphere on a cylinder (the TriFinger's tip): the vertices above it are farther away
        (np.vstack((hemisphere(0.01), [[0.01 * np.cos(a), 0.01 * np.sin(a), 0.02] for a in range(32)])), 0.01),
        (hemisphere(0.01).astype(np.float32), 0.01),  # an STL's single precision is within the tolerance
        # equidistant vertices that are no sphere: a cube's corners, a cylinder's two rims
        (np.array(np.meshgrid([-1.0, 1], [-1.0, 1], [-1.0, 1])).reshape(3, -1).T, None),
        (np.array([[np.cos(a), np.sin(a), z] for a in range(32) for z in (-1.0, 1.0)]), None),
        (hemisphere(0.01, n=SPHERE_VERTICES - 1), None),  # too few to tell
        (np.vstack((hemisphere(0.01), [[0.0, 0.0, 0.009]])), None),  # something 10 % inside it
        (np.vstack((hemisphere(0.01), [[0.0, 0.0, 0.0099]])), 0.01),  # a chord's 1 %: a closed cap's rim
        (hemisphere(0.01) + [0.0, 0.0, 0.001], None),  # a sphere about another point: its cap is not equidistant
        (np.zeros((0, 3)), None),
        (np.full((20, 3), np.nan), None),
    ],
    ids=["hemisphere", "tip", "float32", "cube", "cylinder", "few", "inside", "chord", "offset", "empty", "nan"],
)
def test_sphere_radius_of_a_mesh(vertices, want):
    got = sphere_radius(vertices)
    assert got == (None if want is None else pytest.approx(want, rel=1e-6))


def roll(h, points, normals, segments, times):
    """Track the hand and measure its tips at the samples: (track, centres(t), gap, contact)."""
    radii = np.array([f.tip_radius for f in h.fingers])
    home = tip_centers(points, normals, radii)
    t = track(h, None, points, segments, times, normals=normals, steps=1)  # the samples are polished: few steps do
    return t, tip_poses(h, t.positions, home_tips(h, home)), radii


def test_a_sphere_on_a_tilting_plane_keeps_its_centre_at_height_r_and_rolls_by_the_relative_turn():
    """The plane z = 0 (the object below it: normals -z) tilts about the x axis through the origin
    by theta = 0.6 t.  Each contact stays on the plane, so the centre of a tip of radius r stays
    r above it: ``c(t) = p(t) + r R(t) e_z``.  A Cartesian finger's tip does not turn, so where it
    touches turns by the plane's whole rotation, ``u = R_x(theta) (-e_z)``; finger 3 turns about
    x by its own first joint ``q_1``, so its contact turns by the relative rotation ``theta - q_1``."""
    r = 0.05
    turning = finger("t", ["revolute", "prismatic", "prismatic"], np.eye(3)[[0, 1, 2]], np.zeros((3, 3)), 6, r)
    h = hand(cartesian("a", 0, r), cartesian("b", 3, r), turning)
    points = np.array([[0.3, 0.2, 0.0], [-0.4, 0.1, 0.0], [0.1, -0.5, 0.0]])
    normals = np.tile([0.0, 0.0, -1.0], (3, 1))
    times = np.linspace(0.0, 1.0, 3)
    t, poses, radii = roll(h, points, normals, [Segment(1.0, twist=[0.6, 0, 0, 0, 0, 0])], times)
    for k, theta in enumerate(0.6 * times):
        p, n = turned(np.zeros(3), [theta, 0, 0], points, normals)
        centres = poses[k, :, :3, 3]
        np.testing.assert_allclose(centres, p - r * n, rtol=0, atol=1e-14)
        np.testing.assert_allclose(np.sum((centres - p) * -n, axis=-1), r, rtol=0, atol=1e-14)  # height r
        touch = tip_contacts(poses[k], p, n, radii)
        np.testing.assert_allclose(touch.gap, 0.0, rtol=0, atol=1e-14)
        want = [0.0, np.sin(theta), -np.cos(theta)]
        np.testing.assert_allclose(touch.contact[:2], [want, want], rtol=0, atol=1e-14)
        q1 = t.positions[k, 6]
        relative = theta - q1
        np.testing.assert_allclose(touch.contact[2], [0.0, np.sin(relative), -np.cos(relative)], rtol=0, atol=1e-12)
        assert angle(touch.contact[0], [0, 0, -1.0]) == pytest.approx(theta, abs=1e-12)
    assert abs(t.positions[-1, 6]) > 0.01  # the third finger did turn (its contact a different angle)


def test_a_fingertip_on_a_turning_cube_face_rolls_by_the_turn():
    """A 65 mm cube turning about its vertical axis by 0.5 rad: a Cartesian fingertip (r = 10 mm)
    on each of three side faces stays tangent to its face (gap 0 to round-off), its centre at
    ``R (p - r n)``, and the contact's place on the tip turns by exactly the cube's turn."""
    r = 0.01
    h = hand(cartesian("a", 0, r), cartesian("b", 3, r), cartesian("c", 6, r))
    points = np.array([[0.0325, 0.015, 0.045], [0.005, -0.0325, 0.025], [-0.0325, 0.0, 0.015]])
    normals = np.array([[-1.0, 0, 0], [0, 1.0, 0], [1.0, 0, 0]])
    times = np.linspace(0.0, 1.0, 3)
    _, poses, radii = roll(h, points, normals, [Segment(1.0, twist=[0, 0, 0.5, 0, 0, 0])], times)
    for k, theta in enumerate(0.5 * times):
        p, n = turned(np.zeros(3), [0, 0, theta], points, normals)
        touch = tip_contacts(poses[k], p, n, radii)
        np.testing.assert_allclose(touch.gap, 0.0, rtol=0, atol=1e-15)
        np.testing.assert_allclose(poses[k, :, :3, 3], p - r * n, rtol=0, atol=1e-15)
        np.testing.assert_allclose(angle(touch.contact, normals), theta, rtol=0, atol=1e-12)


def test_normals_are_needed_for_a_radius():
    h = hand(cartesian("a", 0, 0.1), cartesian("b", 3, 0.0), cartesian("c", 6, 0.0))
    with pytest.raises(ValueError, match=r"normals: needed for fingertips with a radius"):
        track(h, None, np.eye(3), [Segment(1.0, twist=[0, 0, 1.0, 0, 0, 0])], [0.0, 1.0])
