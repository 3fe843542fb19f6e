"""Which fingers each component moves, and the rotation-about-the-wrist verdict, on random grasps."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import grasptwist as gt
from grasp_gen import grasps, rotation
from grasptwist.engine.judgements import about_wrist, active, off_tangent_moves, outward_contacts, tangent_moves

N = 300


@pytest.fixture(scope="module")
def batch():
    rng = np.random.default_rng(11)
    points, normals, wrist, twist = grasps(rng, N)
    return points, gt.screws.direction(normals), wrist, twist


def fingers(moves):
    return [np.flatnonzero(c).tolist() for c in moves]


def test_a_twist_made_of_one_component_moves_only_its_fingers(batch):
    points, normals, wrist, _ = batch
    basis = gt.decompose_off_tangent(points, wrist, np.zeros(6))
    off = gt.decompose_off_tangent(points, wrist, 2.5 * basis.sigma[:, 1])
    assert {tuple(map(tuple, fingers(m))) for m in off_tangent_moves(off.x, off.y)} == {((), (1,), (), (), (), ())}
    off = gt.decompose_off_tangent(points, wrist, -0.3 * basis.psi[:, 2])
    assert {tuple(map(tuple, fingers(m))) for m in off_tangent_moves(off.x, off.y)} == {((), (), (), (), (), (0, 1))}
    tangent = gt.decompose_tangent(points, normals, np.zeros(6))
    tan = gt.decompose_tangent(points, normals, 0.7 * tangent.theta[:, 0])
    moves = tangent_moves(tan.alpha, tan.beta, tan.normal_velocity, tan.in_tangent_planes)
    assert {tuple(map(tuple, fingers(m))) for m in moves} == {((1, 2), (), (), (), (), ())}


def test_no_sigma_component_is_active_exactly_when_the_twist_is_in_the_tangent_planes(batch):
    points, normals, _, twist = batch
    basis = gt.decompose_tangent(points, normals, np.zeros(6))
    in_planes = np.einsum("ni,nij->nj", np.random.default_rng(2).normal(size=(N, 3)), basis.theta)
    # half the rows slide in their tangent planes, half do not; one is the zero twist
    t = np.where(np.arange(N)[:, None] % 2 == 0, in_planes, twist)
    t[1] = 0.0
    tan = gt.decompose_tangent(points, normals, t)
    assert tan.ok.all() and tan.in_tangent_planes.sum() == N // 2 + 1  # the zero twist is in its planes too
    moves = tangent_moves(tan.alpha, tan.beta, tan.normal_velocity, tan.in_tangent_planes)
    np.testing.assert_array_equal(moves[:, 3:].any(axis=(1, 2)), ~tan.in_tangent_planes)
    # a Sigma component moves its own finger only; a Theta component the two others
    np.testing.assert_array_equal(moves[:, 3:] & ~np.eye(3, dtype=bool), False)
    np.testing.assert_array_equal(moves[:, :3] & np.eye(3, dtype=bool), False)
    assert not moves[1].any()  # the zero twist moves nothing


def test_about_the_wrist_means_the_wrist_does_not_move(batch):
    points, _, wrist, twist = batch
    omega = twist[:, :3]
    spin = np.concatenate([omega, -np.cross(omega, wrist)], axis=1)  # T(c) = 0: a rotation about the wrist
    off = gt.decompose_off_tangent(points, wrist, spin)
    assert about_wrist(off.x, off.y).all()
    assert not off_tangent_moves(off.x, off.y)[:, :3].any()  # no Sigma part
    off = gt.decompose_off_tangent(points, wrist, spin + [0, 0, 0, 1e-3, 0, 0])  # the wrist slides a little
    assert not about_wrist(off.x, off.y).any()
    assert not about_wrist(np.zeros(3), np.zeros(3))  # the zero twist is no rotation


def test_judgements_do_not_depend_on_scale_or_position(batch):
    points, normals, wrist, twist = batch
    twist = twist.copy()
    twist[::3, :3] = 0.0  # translations: only some components act
    off = gt.decompose_off_tangent(points, wrist, twist)
    tan = gt.decompose_tangent(points, normals, twist)
    moved = [
        off_tangent_moves(off.x, off.y),
        tangent_moves(tan.alpha, tan.beta, tan.normal_velocity, tan.in_tangent_planes),
    ]
    scale, offset = 1e-4, np.array([3.0, -2.0, 7.0])
    # the same motion seen in a frame scaled by 1e-4 and moved: omega stays, v is scaled and shifted
    t = np.concatenate([twist[:, :3], scale * twist[:, 3:] - np.cross(offset, twist[:, :3])], axis=1)
    off = gt.decompose_off_tangent(points * scale + offset, wrist * scale + offset, t)
    tan = gt.decompose_tangent(points * scale + offset, normals, t)
    np.testing.assert_array_equal(off_tangent_moves(off.x, off.y), moved[0])
    np.testing.assert_array_equal(
        tangent_moves(tan.alpha, tan.beta, tan.normal_velocity, tan.in_tangent_planes), moved[1]
    )


def test_a_failed_row_moves_nothing():
    nan = np.full(3, np.nan)
    assert not off_tangent_moves(nan, nan).any() and not about_wrist(nan, nan)
    assert not tangent_moves(nan, nan, nan, False).any()
    assert active([np.nan, 1.0]).tolist() == [False, False]  # NaN in a row: its maximum is unknown


def test_normals_leaning_inward_are_not_outward(batch):
    points, normals, _, _ = batch  # each normal within 60 degrees of centroid - p_i
    assert not outward_contacts(points, normals).any()
    assert not outward_contacts(points, normals, center=points.mean(axis=1)).any()


def _sphere(seed, scale, shift, n=20):
    """``n`` grasps of three points on a sphere (a convex object), its centre, and the outward unit normals."""
    rng = np.random.default_rng(seed)
    centre = rng.normal(size=3)
    on = gt.screws.unit(rng.normal(size=(n, 3, 3)))
    return rng, (centre + on) * scale + shift, centre * scale + shift, on


@settings(max_examples=50, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([1e-6, 1.0, 1e6]), st.floats(-1e3, 1e3))
def test_on_a_sphere_each_reversed_normal_is_named_at_any_scale_and_place(seed, scale, shift):
    rng, points, centre, on = _sphere(seed, scale, shift)
    # a convex object: the inward normal -on_i has every other point and the centre on its inner side
    for center in (None, np.broadcast_to(centre, (20, 3))):
        assert not outward_contacts(points, -on, center).any()
        assert outward_contacts(points, on, center).all()
        # one normal reversed (issue 26: the judgement was of all three at once): that contact alone
        which = rng.integers(0, 3, 20)
        one = -on.copy()
        one[np.arange(20), which] *= -1
        np.testing.assert_array_equal(outward_contacts(points, one, center), np.arange(3) == which[:, None])


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_the_verdicts_do_not_change_under_a_rigid_motion(seed):
    rng = np.random.default_rng(seed)
    points, normals, _, _ = grasps(rng, 200)
    normals = np.where(rng.random((200, 3, 1)) < 0.3, -normals, normals)  # some reversed
    center = points.mean(axis=1) + rng.normal(size=(200, 3)) * 0.3
    center[::3] = np.nan  # rows without a centre of mass: judged by the other contacts
    r, t = rotation(rng), rng.normal(size=3) * 10
    for c in (None, center):
        before = outward_contacts(points, normals, c)
        moved = outward_contacts(points @ r.T + t, normals @ r.T, None if c is None else c @ r.T + t)
        np.testing.assert_array_equal(moved, before)
        assert before.any() and not before.all()


def test_the_centre_of_mass_decides_where_given_the_other_contacts_elsewhere():
    # a cube's three faces, the normal at the south face reversed (issue 26's grasp)
    p = np.array([[0.03, 0.005, 0], [-0.03, 0, 0.005], [0, -0.03, 0.01]])
    n = np.array([[-1.0, 0, 0], [1, 0, 0], [0, -1, 0]])
    assert outward_contacts(p, n).tolist() == [False, False, True]
    assert outward_contacts(p, n, [0.0, 0, 0]).tolist() == [False, False, True]
    # a centre of mass beyond the south and east faces (an odd object): south is then inward, east not
    assert outward_contacts(p, n, [0.1, -0.1, 0]).tolist() == [True, False, False]
    assert outward_contacts(p, n, [[np.nan] * 3]).tolist() == [[False, False, True]]


def test_a_normal_at_right_angles_or_nan_is_not_outward():
    p = np.array([[1.0, 0, 0], [-0.5, 0.866, 0], [-0.5, -0.866, 0]])
    up = np.array([[0.0, 0, 1], p[1], p[2]])  # contact 1's normal is perpendicular to every p_j - p_1
    assert outward_contacts(p, p).all() and outward_contacts(p, up).tolist() == [False, True, True]
    assert outward_contacts(p, up, [0.0, 0, 0]).tolist() == [False, True, True]
    assert not outward_contacts(p, np.full((3, 3), np.nan)).any()
    assert not outward_contacts(p, -p, p[0]).any()  # a centre of mass at contact 1: no direction there


def test_reversed_normals_change_only_the_sign_of_the_normal_velocities(batch):
    # what the README promises a user whose normals get the outward-normals warning
    points, normals, _, twist = batch
    inward, outward = gt.decompose_tangent(points, normals, twist), gt.decompose_tangent(points, -normals, twist)
    for name in ("theta", "alpha", "beta", "conditioning", "in_tangent_planes", "status"):
        np.testing.assert_allclose(getattr(outward, name), getattr(inward, name), rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(outward.normal_velocity, -inward.normal_velocity, rtol=1e-12, atol=1e-12)
