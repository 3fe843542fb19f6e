"""SE(3) exp/log, adjoints and rotations against pytransform3d, at every angle."""

import numpy as np
import pytest

pt = pytest.importorskip("pytransform3d.transformations")
pr = pytest.importorskip("pytransform3d.rotations")

from grasp_gen import rotation  # noqa: E402
from grasptwist.engine import se3  # noqa: E402


def twists(rng, n):
    """Random twists with |omega| < pi, in four kinds: general, pure translations,
    angles within 1e-12..1e-2 of pi, and angles of 1e-12..1e-2 (both series thresholds' sides)."""
    v = rng.normal(size=(n, 6))
    axis = v[:, :3] / np.linalg.norm(v[:, :3], axis=1, keepdims=True)
    kind = np.arange(n) % 4
    angle = np.select(
        [kind == 0, kind == 1, kind == 2],
        [rng.uniform(0, np.pi, n), 0.0, np.pi - 10 ** rng.uniform(-12, -2, n)],
        10 ** rng.uniform(-12, -1.5, n),
    )
    v[:, :3] = axis * angle[:, None]
    return v


def test_exp_matches_pytransform3d_on_random_twists():
    v = twists(np.random.default_rng(0), 400)
    r, x = se3.exp(v)  # one batched call
    for i in range(len(v)):
        h = pt.transform_from_exponential_coordinates(v[i])
        np.testing.assert_allclose(r[i], h[:3, :3], rtol=0, atol=2e-15)
        np.testing.assert_allclose(x[i], h[:3, 3], rtol=0, atol=4e-15 * np.abs(v[i]).max())


def test_log_inverts_exp_to_round_off_even_near_pi():
    v = twists(np.random.default_rng(1), 400)
    back = se3.log(*se3.exp(v))
    err = np.abs(back - v).max(axis=1) / np.abs(v).max(axis=1)
    assert err.max() < 3e-15
    for i in range(0, len(v), 7):  # and agrees with pytransform3d (whose own log loses ~1e-10 near pi)
        ref = pt.exponential_coordinates_from_transform(pt.transform_from_exponential_coordinates(v[i]))
        np.testing.assert_allclose(back[i], ref, rtol=0, atol=3e-10 * np.abs(v[i]).max())


def test_log_of_pure_translations_and_half_turns():
    rng = np.random.default_rng(2)
    x = rng.normal(size=(5, 3))
    np.testing.assert_array_equal(se3.log(np.eye(3), x), np.concatenate((np.zeros((5, 3)), x), axis=1))
    # exactly pi: the axis is defined up to sign, and either reproduces the pose
    r = se3.rotvec_to_matrix(np.pi * np.array([[1.0, 0, 0], [0, 0.6, 0.8], [0, -0.6, 0.8]]))
    v = se3.log(r, x[:3])
    np.testing.assert_allclose(np.linalg.norm(v[:, :3], axis=1), np.pi, rtol=1e-15)
    r2, x2 = se3.exp(v)
    np.testing.assert_allclose(r2, r, atol=2e-15)
    np.testing.assert_allclose(x2, x[:3], atol=1e-14)


def test_exp_of_a_time_is_the_screw_motion_for_that_time():
    rng = np.random.default_rng(3)
    v = rng.normal(size=6)
    t = np.array([0.0, 0.5, 2.0, 7.0])
    r, x = se3.exp(v, t)
    r2, x2 = se3.exp(v[None] * t[:, None])
    np.testing.assert_allclose(r, r2, atol=1e-15)
    np.testing.assert_allclose(x, x2, atol=1e-14)
    np.testing.assert_array_equal(r[0], np.eye(3))
    # exp((s + t) V) = exp(s V) exp(t V): a constant twist's motion composes
    rc, xc = se3.compose(r[1], x[1], r[2], x[2])
    r3, x3 = se3.exp(v, 2.5)
    np.testing.assert_allclose(rc, r3, atol=1e-14)
    np.testing.assert_allclose(xc, x3, atol=1e-14)


def test_rows_are_bit_for_bit_the_same_in_any_batch():
    v = twists(np.random.default_rng(4), 64)
    r, x = se3.exp(v)
    r1, x1 = se3.exp(v[17])
    np.testing.assert_array_equal(r[17], r1)
    np.testing.assert_array_equal(x[17], x1)
    np.testing.assert_array_equal(se3.log(r, x)[17], se3.log(r1, x1))


def test_quaternions_and_rotation_vectors_match_pytransform3d():
    rng = np.random.default_rng(5)
    q = rng.normal(size=(200, 4))
    q[:50, 0] = 10 ** rng.uniform(-14, -3, 50)  # near half turns (w ~ 0)
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    r = se3.quaternion_to_matrix(3.0 * q)  # any length
    back = se3.matrix_to_quaternion(r)
    canonical = np.where(q[:, :1] < 0, -q, q)
    np.testing.assert_allclose(back, canonical, atol=1e-15)
    rotvec = rng.normal(size=(200, 3)) * 2
    rv = se3.rotvec_to_matrix(rotvec)
    for i in range(0, 200, 3):
        np.testing.assert_allclose(r[i], pr.matrix_from_quaternion(q[i]), atol=2e-15)
        ref = pr.quaternion_from_matrix(r[i])
        np.testing.assert_allclose(back[i], ref if ref[0] >= 0 else -ref, atol=1e-12)
        np.testing.assert_allclose(rv[i], pr.matrix_from_compact_axis_angle(rotvec[i]), atol=2e-15)


def test_adjoint_matches_pytransform3d_and_carries_body_twists_to_space_ones():
    rng = np.random.default_rng(6)
    r, x = rotation(rng), rng.normal(size=3)
    np.testing.assert_allclose(se3.adjoint(r, x), pt.adjoint_from_transform(pt.transform_from(r, x)), atol=1e-15)
    # H exp(V_b t) = exp((Ad_H V_b) t) H
    vb = rng.normal(size=6)
    vs = se3.adjoint(r, x) @ vb
    left = se3.compose(r, x, *se3.exp(vb, 0.7))
    right = se3.compose(*se3.exp(vs, 0.7), r, x)
    np.testing.assert_allclose(left[0], right[0], atol=1e-14)
    np.testing.assert_allclose(left[1], right[1], atol=1e-14)


def test_inverse_transform_and_compose():
    rng = np.random.default_rng(7)
    r, x = rotation(rng), rng.normal(size=3)
    ri, xi = se3.inverse(r, x)
    p = rng.normal(size=(4, 3))
    np.testing.assert_allclose(se3.transform(ri, xi, se3.transform(r, x, p)), p, atol=1e-14)
    np.testing.assert_allclose(se3.transform(r, x, p), p @ r.T + x, atol=1e-14)
    rc, xc = se3.compose(r, x, ri, xi)
    np.testing.assert_allclose(rc, np.eye(3), atol=1e-15)
    np.testing.assert_allclose(xc, 0, atol=1e-15)


@pytest.mark.parametrize(
    ("call", "name"),
    [
        (lambda: se3.exp([0, 0, 1]), "twist"),
        (lambda: se3.log(np.eye(3), [0, 0]), "translation"),
        (lambda: se3.quaternion_to_matrix([1, 0, 0]), "quaternion"),
        (lambda: se3.rotvec_to_matrix(np.zeros((3, 2))), "rotvec"),
        (lambda: se3.adjoint(np.eye(2), [0, 0, 0]), "rotation"),
    ],
)
def test_wrong_shapes_raise_value_errors_naming_the_argument(call, name):
    with pytest.raises(ValueError, match=f"^{name} must have shape"):
        call()


def test_rpy_to_matrix_is_yaw_pitch_roll_about_the_fixed_axes_row_by_row():
    rpy = np.random.default_rng(7).uniform(-4, 4, (2, 5, 3))
    got = se3.rpy_to_matrix(rpy)
    for (i, j), (r, p, y) in zip(np.ndindex(2, 5), rpy.reshape(-1, 3), strict=True):
        c, s = np.cos, np.sin
        rx = np.array([[1, 0, 0], [0, c(r), -s(r)], [0, s(r), c(r)]])
        ry = np.array([[c(p), 0, s(p)], [0, 1, 0], [-s(p), 0, c(p)]])
        rz = np.array([[c(y), -s(y), 0], [s(y), c(y), 0], [0, 0, 1]])
        np.testing.assert_allclose(got[i, j], rz @ ry @ rx, rtol=0, atol=1e-15)
        assert np.array_equal(got[i, j], se3.rpy_to_matrix([r, p, y]))  # a row's bits whatever its batch
    with pytest.raises(ValueError, match=r"rpy must have shape \(\.\.\., 3\)"):
        se3.rpy_to_matrix([0.0, 1.0])
