"""The engine against the paper (the corrected values of README, "Conventions"),
its formulas as written (grasptwist.engine.formulas), an independent 6x6
solve, the reciprocity identities, rigid motions and random grasps."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import grasptwist as gt
from grasp_gen import grasps, rotation
from grasptwist.engine import formulas, screws

EX1 = np.array([[1, 0, 0], [-0.5, 0.866, 0], [-0.5, -0.866, 0]], float)
EX1_WRIST = np.array([0, 0, 1.0])
EX2 = np.array([[0, 2, 2], [2, 0, 2], [2, 2, 0]], float)
EX2_NORMALS = np.eye(3)
R2 = np.sqrt(0.5)

seeds = st.integers(0, 2**32 - 1)
scales = st.sampled_from([1e-3, 1e-2, 1.0, 1e2, 1e3])


# --- the paper's examples, corrected values (README, "Conventions") ----------


def test_example_1_basis_screws_eq16_eq17_and_products_eq18():
    r = gt.decompose_off_tangent(EX1, EX1_WRIST, np.zeros(6))
    np.testing.assert_allclose(
        r.sigma, [[0, -1, 0, 0, 0, 0.5], [0.866, 0.5, 0, 0, 0, 0.5], [-0.866, 0.5, 0, 0, 0, 0.5]], atol=1e-4
    )
    np.testing.assert_allclose(
        r.psi,
        [
            [R2, 0, -R2, 0, R2, 0],
            [-0.3536, 0.6124, -0.7071, -0.6124, -0.3536, 0],
            [-0.3536, -0.6124, -0.7071, 0.6124, -0.3536, 0],
        ],
        atol=1e-4,
    )
    np.testing.assert_allclose(r.sigma_psi, [-1.0607] * 3, atol=1e-4)
    off_diagonal = screws.klein(r.sigma[:, None, :], r.psi[None, :, :])[~np.eye(3, dtype=bool)]
    np.testing.assert_allclose(off_diagonal, 0, atol=1e-12)


@pytest.mark.parametrize(
    "twist, x, y",
    [
        ([0, -1, 0, 0, 0, 0.5], [1, 0, 0], [0, 0, 0]),  # 1a: T = Sigma_1
        ([0, 0, 1, 0, 0, 0], [0, 0, 0], [-0.4714, -0.4714, -0.4714]),  # 1b: spin about z
        ([0, 0, 0, 0, 0, 1], [0.6667, 0.6667, 0.6667], [0, 0, 0]),  # 1c: lift along z
    ],
    ids=["1a", "1b", "1c"],
)
def test_example_1_amplitudes(twist, x, y):
    r = gt.decompose_off_tangent(EX1, EX1_WRIST, twist)
    assert r.status == gt.Status.OK
    np.testing.assert_allclose(r.x, x, atol=1e-4)
    np.testing.assert_allclose(r.y, y, atol=1e-4)
    sx, sy = r.components()
    np.testing.assert_allclose(sx.sum(0) + sy.sum(0), twist, atol=1e-12)


def test_example_1c_products_with_psi():
    # [T|Psi_i] = -0.7071 for the unit Psi (the paper's 0.668 is for another scaling)
    r = gt.decompose_off_tangent(EX1, EX1_WRIST, np.zeros(6))
    np.testing.assert_allclose(screws.klein([0, 0, 0, 0, 0, 1.0], r.psi), [-0.7071] * 3, atol=1e-4)


def test_example_2_theta_sigma_and_alpha():
    t = np.array([1, 1, 1, 0, 0, 0]) / np.sqrt(3)
    r = gt.decompose_tangent(EX2, EX2_NORMALS, t)
    assert r.status == gt.Status.OK
    np.testing.assert_allclose(r.theta, [[1, 0, 0, 0, 2, -2], [0, 1, 0, -2, 0, 2], [0, 0, 1, 2, -2, 0]], atol=1e-12)
    np.testing.assert_allclose(
        r.sigma,
        [
            [0, R2, -R2, -1.4142, 1.4142, 1.4142],
            [-R2, 0, R2, 1.4142, -1.4142, 1.4142],
            [R2, -R2, 0, 1.4142, 1.4142, -1.4142],
        ],
        atol=1e-4,
    )
    np.testing.assert_allclose(r.alpha, [0.5774] * 3, atol=1e-4)
    np.testing.assert_allclose(r.beta, 0, atol=1e-12)
    np.testing.assert_allclose(r.normal_velocity, 0, atol=1e-12)
    assert r.in_tangent_planes
    np.testing.assert_allclose(r.theta_sigma, [np.sqrt(2)] * 3, atol=1e-12)


def test_example_2_second_approach_splits_each_contact_velocity():
    t = np.array([1, 1, 1, 0, 0, 0]) / np.sqrt(3)
    r = gt.decompose_tangent(EX2, EX2_NORMALS, t)
    theta_v, sigma_v = r.contact_split()
    v = gt.contact_velocities(EX2, t)
    np.testing.assert_allclose(theta_v.sum(axis=1) + sigma_v, v, atol=1e-12)
    # p1 is moved by Theta_2 and Theta_3 only, within its tangent plane x = 0
    np.testing.assert_allclose(theta_v[0, 0], 0, atol=1e-12)
    np.testing.assert_allclose(theta_v[0, 1], [0, 0, 2 / np.sqrt(3)], atol=1e-12)  # Theta_2(p1) = (0, 0, 2)
    np.testing.assert_allclose(theta_v[..., 0][0], 0, atol=1e-12)


def test_tangent_method_resolves_an_out_of_plane_twist_with_beta():
    # lifting the polyhedron along z keeps contacts 1 and 2 (normals x, y) in their
    # tangent planes; contact 3 (normal z) must leave its plane: beta_3 alone.
    # Sigma_3(p_3) = m / |U_3| = (4, 4, 4) / sqrt(8), so beta_3 Sigma_3(p_3) . n_3 = 1 gives 1/sqrt(2).
    t = np.array([0, 0, 0, 0, 0, 1.0])
    r = gt.decompose_tangent(EX2, EX2_NORMALS, t)
    np.testing.assert_allclose(r.normal_velocity, [0, 0, 1], atol=1e-12)
    assert not r.in_tangent_planes
    np.testing.assert_allclose(r.beta, [0, 0, 1 / np.sqrt(2)], rtol=1e-15, atol=1e-15)
    np.testing.assert_allclose(r.alpha, [-0.5, 0.5, 0], rtol=1e-15, atol=1e-15)
    a, b = r.components()
    np.testing.assert_allclose(a.sum(0) + b.sum(0), t, atol=1e-12)


def test_contact_velocities_example_1b():
    v = gt.contact_velocities(EX1, [0, 0, 1, 0, 0, 0])
    np.testing.assert_allclose(v, [[0, 1, 0], [-0.866, -0.5, 0], [0.866, -0.5, 0]], atol=1e-12)


# --- random grasps -------------------------------------------------------------


def _solve(points, normals, wrist, twist):
    """Both decompositions by numpy.linalg.solve of ``[basis] a = T`` on the bases of
    formulas.py: a check of eqs. 14 and 27 that uses no Klein product."""
    sigma = formulas.sigma_lines(points)
    psi = formulas.psi_lines(points, wrist)
    theta = formulas.theta_lines(points, normals)
    off = np.linalg.solve(np.swapaxes(np.concatenate([sigma, psi], -2), -1, -2), twist[..., None])[..., 0]
    tan = np.linalg.solve(np.swapaxes(np.concatenate([theta, sigma], -2), -1, -2), twist[..., None])[..., 0]
    return off, tan


def _near(got, want, tol):
    """``|got - want| <= tol`` everywhere (``tol`` broadcasts, e.g. one per row)."""
    err = np.abs(got - want)
    assert np.all(err <= tol), np.max(err / tol)


def _close_relative(a, b, ref, rtol):
    """|a - b| <= rtol * max|ref| per row (rows of amplitudes share one scale)."""
    scale = np.max(np.abs(ref), axis=-1, keepdims=True)
    assert np.all(np.abs(a - b) <= rtol * scale), np.max(np.abs(a - b) / scale)


@settings(max_examples=12, deadline=None)
@given(seeds, scales, st.booleans())
def test_the_engine_computes_the_papers_formulas(seed, scale, moved):
    """The closed forms of the kernels against formulas.py, row by row, on a few
    hundred random grasps at every scale, optionally moved far from the origin."""
    rng = np.random.default_rng(seed)
    points, normals, wrist, twist = grasps(rng, 300, scale=scale)
    if moved:
        rot, shift = rotation(rng, 300), rng.normal(size=(300, 3)) * 20 * scale
        points = np.einsum("gij,gkj->gki", rot, points) + shift[:, None]
        normals = np.einsum("gij,gkj->gki", rot, normals)
        wrist = np.einsum("gij,gj->gi", rot, wrist) + shift
        twist = screws.rigid_motion(twist, rot, shift)
    off = gt.decompose_off_tangent(points, wrist, twist)
    tan = gt.decompose_tangent(points, normals, twist)
    assert off.ok.all()
    good = tan.ok & (tan.conditioning > gt.CONDITION_WARNING)
    assert good.mean() > 0.8  # the filter may drop a few near-degenerate normals, not hide a bug
    reach = np.max(np.abs(points), axis=(-1, -2))[:, None, None]  # moments p x d scale with it
    size = np.max(np.linalg.norm(points - points[:, [1, 2, 0]], axis=-1), axis=-1)[:, None]

    sigma, psi = formulas.sigma_lines(points), formulas.psi_lines(points, wrist)
    theta = formulas.theta_lines(points, normals)
    every = slice(None)
    for got, want, rows in ((off.sigma, sigma, every), (off.psi, psi, every), (tan.theta, theta, good)):
        _near(got[rows, :, :3], want[rows, :, :3], 1e-12)  # unit directions
        _near(got[rows, :, 3:], want[rows, :, 3:], 1e-12 * reach[rows])
    np.testing.assert_array_equal(tan.sigma, off.sigma)
    _near(off.sigma_psi, screws.klein(sigma, psi), 1e-12 * size)
    _near(tan.theta_sigma[good], screws.klein(theta, sigma)[good], 1e-12 * size[good])

    x, y = formulas.off_tangent_amplitudes(sigma, psi, twist)
    _close_relative(np.c_[off.x, off.y], np.c_[x, y], np.c_[x, y], 1e-9)
    alpha, beta = formulas.tangent_amplitudes(theta, sigma, twist)
    _close_relative(np.c_[tan.alpha, tan.beta][good], np.c_[alpha, beta][good], np.c_[alpha, beta][good], 1e-8)
    nv = formulas.normal_velocities(points, normals, twist)
    speed = np.max(np.linalg.norm(gt.contact_velocities(points, twist), axis=-1), -1, keepdims=True)
    _near(tan.normal_velocity, nv, 1e-12 * speed)


@settings(max_examples=25, deadline=None)
@given(seeds, scales)
def test_reconstruction_and_independent_solve_on_random_grasps(seed, scale):
    rng = np.random.default_rng(seed)
    points, normals, wrist, twist = grasps(rng, 50, scale=scale)
    off = gt.decompose_off_tangent(points, wrist, twist)
    tan = gt.decompose_tangent(points, normals, twist)
    assert off.ok.all()
    good = tan.ok & (tan.conditioning > gt.CONDITION_WARNING)
    assert good.mean() > 0.8
    ref_off, ref_tan = _solve(points, normals, wrist, twist)
    _close_relative(np.concatenate([off.x, off.y], -1), ref_off, ref_off, 1e-8)
    amp = np.concatenate([tan.alpha, tan.beta], -1)[good]
    _close_relative(amp, ref_tan[good], ref_tan[good], 1e-8)

    # reconstruction, relative to the twist's size in the grasp's own units
    def rel_err(parts):
        recon = sum(p.sum(axis=-2) for p in parts)
        err = gt.contact_velocities(points, recon - twist)
        ref = gt.contact_velocities(points, twist)
        return np.max(np.linalg.norm(err, axis=-1), -1) / np.max(np.linalg.norm(ref, axis=-1), -1)

    assert np.all(rel_err(off.components()) < 1e-9)
    assert np.all(rel_err(tan.components())[good] < 1e-9)
    # a residual grows as the conditioning falls (seed 634080 at 1e-3: 7.6e-12 at conditioning 1.1e-5, their
    # product 3.4e-16): tight where the grasp is well conditioned, backward stable everywhere
    well = off.conditioning > gt.CONDITION_WARNING
    assert np.all(off.residual[well] < 1e-12) and np.all(off.residual * off.conditioning < 1e-13)
    assert np.all(tan.residual[good] < 1e-9)


@settings(max_examples=20, deadline=None)
@given(seeds)
def test_reciprocity_identities_and_which_contacts_move(seed):
    rng = np.random.default_rng(seed)
    points, normals, wrist, twist = grasps(rng, 20)
    off = gt.decompose_off_tangent(points, wrist, twist)
    tan = gt.decompose_tangent(points, normals, twist)
    good = tan.ok
    offdiag = ~np.eye(3, dtype=bool)
    size = np.max(np.linalg.norm(points - points[:, [1, 2, 0]], axis=-1), -1)[:, None]
    pairs = lambda a, b: screws.klein(a[:, :, None, :], b[:, None, :, :])[:, offdiag]  # noqa: E731
    for a, b in [(off.sigma, off.psi), (off.sigma, off.sigma), (off.psi, off.psi)]:
        assert np.all(np.abs(pairs(a, b)) < 1e-12 * size)
    assert np.all(np.abs(pairs(tan.theta, tan.sigma)[good]) < 1e-12 * size[good])
    # Sigma_i moves only p_i; Psi_i fixes p_i and the wrist; Theta_i fixes p_i and slides p_j, p_k
    at = screws.field_at(off.sigma[:, :, None, :], points[:, None, :, :])  # [grasp, screw i, contact]
    speed = np.linalg.norm(at, axis=-1)
    assert np.all(speed[:, offdiag] < 1e-12 * size) and np.all(np.diagonal(speed, axis1=1, axis2=2) > 1e-3 * size)
    psi_at = screws.field_at(off.psi, points)
    assert np.all(np.linalg.norm(psi_at, axis=-1) < 1e-12 * size)
    assert np.all(np.linalg.norm(screws.field_at(off.psi, wrist[:, None, :]), axis=-1) < 1e-12 * size)
    theta_at = screws.field_at(tan.theta[:, :, None, :], points[:, None, :, :])
    unit_n = normals / np.linalg.norm(normals, axis=-1, keepdims=True)
    normal_speed = np.einsum("gijx,gjx->gij", theta_at, unit_n)
    assert np.all(np.linalg.norm(np.diagonal(theta_at, axis1=1, axis2=2), axis=1)[good] < 1e-12 * size[good])
    assert np.all(np.abs(normal_speed[good]) < 1e-12 * size[good, :, None])


@settings(max_examples=20, deadline=None)
@given(seeds)
def test_amplitudes_are_invariant_under_a_rigid_motion(seed):
    rng = np.random.default_rng(seed)
    points, normals, wrist, twist = grasps(rng, 20)
    rot = rotation(rng, 20)
    shift = rng.normal(size=(20, 3)) * 5
    move = lambda p: np.einsum("gij,g...j->g...i", rot, p) + shift.reshape(20, *([1] * (p.ndim - 2)), 3)  # noqa: E731
    moved_twist = screws.rigid_motion(twist, rot, shift)
    a = gt.decompose_off_tangent(points, wrist, twist)
    b = gt.decompose_off_tangent(move(points), move(wrist[:, None])[:, 0], moved_twist)
    _close_relative(np.c_[a.x, a.y], np.c_[b.x, b.y], np.c_[a.x, a.y], 1e-9)
    np.testing.assert_allclose(a.conditioning, b.conditioning, rtol=1e-9)
    c = gt.decompose_tangent(points, normals, twist)
    d = gt.decompose_tangent(move(points), np.einsum("gij,gkj->gki", rot, normals), moved_twist)
    good = c.ok & (c.conditioning > gt.CONDITION_WARNING)
    _close_relative(np.c_[c.alpha, c.beta][good], np.c_[d.alpha, d.beta][good], np.c_[c.alpha, c.beta][good], 1e-8)
    np.testing.assert_allclose(c.normal_velocity[good], d.normal_velocity[good], atol=1e-9 * np.abs(twist).max())


@settings(max_examples=10, deadline=None)
@given(seeds, st.sampled_from([1e-3, 1e3]))
def test_scaling_the_grasp_changes_no_verdict_and_no_amplitude(seed, factor):
    rng = np.random.default_rng(seed)
    points, normals, wrist, twist = grasps(rng, 20)
    # push some rows toward degeneracy so that verdicts and warnings are exercised
    wrist[:5] = points[:5].mean(1) + np.cross(points[:5, 1] - points[:5, 0], points[:5, 2] - points[:5, 0]) * 1e-7
    wrist[5:7] = points[5:7].mean(1)
    scaled = twist * np.r_[np.ones(3), factor * np.ones(3)]
    a = gt.decompose_off_tangent(points, wrist, twist)
    b = gt.decompose_off_tangent(points * factor, wrist * factor, scaled)
    np.testing.assert_array_equal(a.status, b.status)
    np.testing.assert_allclose(a.conditioning, b.conditioning, rtol=1e-6, atol=1e-14)  # degenerate rows: noise
    np.testing.assert_allclose(a.x[a.ok], b.x[b.ok], rtol=1e-6)
    c = gt.decompose_tangent(points, normals, twist)
    d = gt.decompose_tangent(points * factor, normals, scaled)
    np.testing.assert_array_equal(c.status, d.status)
    np.testing.assert_allclose(c.alpha[c.ok], d.alpha[d.ok], rtol=1e-6)


def test_far_from_origin_grasp_keeps_its_digits():
    t = np.array([0, 0, 1, 0, 0, 0.0])
    near = gt.decompose_off_tangent(EX1, EX1_WRIST, t)
    shift = np.array([1e6, -2e6, 3e6])
    moved_t = screws.rigid_motion(t, np.eye(3), shift)
    far = gt.decompose_off_tangent(EX1 + shift, EX1_WRIST + shift, moved_t)
    np.testing.assert_allclose(far.y, near.y, atol=1e-8)
    assert far.conditioning == pytest.approx(near.conditioning, rel=1e-9)


# --- shapes and broadcasting ---------------------------------------------------


def test_one_grasp_many_twists_and_many_grasps_one_twist():
    twists = np.random.default_rng(1).normal(size=(7, 6))
    r = gt.decompose_off_tangent(EX1, EX1_WRIST, twists)
    assert r.x.shape == (7, 3) and r.sigma.shape == (7, 3, 6) and r.status.shape == (7,)
    for i, t in enumerate(twists):
        np.testing.assert_array_equal(r.x[i], gt.decompose_off_tangent(EX1, EX1_WRIST, t).x)
    many = np.stack([EX2, EX2 + 1, EX2 * 2])
    s = gt.decompose_tangent(many, EX2_NORMALS, [1, 0, 0, 0, 0, 0])
    assert s.alpha.shape == (3, 3) and s.theta.shape == (3, 3, 6) and s.in_tangent_planes.shape == (3,)
    assert gt.contact_velocities(many[:, None], twists).shape == (3, 7, 3, 3)


def test_wrong_shapes_are_rejected_at_the_boundary():
    with pytest.raises(ValueError, match=r"points must have shape \(\.\.\., 3, 3\), got \(3, 2\)"):
        gt.decompose_off_tangent(np.zeros((3, 2)), EX1_WRIST, np.zeros(6))
    with pytest.raises(ValueError, match="twist"):
        gt.decompose_tangent(EX2, EX2_NORMALS, np.zeros(5))


def test_without_bases_the_amplitudes_and_verdicts_are_the_same():
    rng = np.random.default_rng(4)
    points, normals, wrist, twist = grasps(rng, 30)
    wrist[0] = points[0].mean(0)
    for full, lean in (
        (gt.decompose_off_tangent(points, wrist, twist), gt.decompose_off_tangent(points, wrist, twist, bases=False)),
        (gt.decompose_tangent(points, normals, twist), gt.decompose_tangent(points, normals, twist, bases=False)),
    ):
        assert lean.sigma is None and lean.row(3).sigma is None
        for name in ("status", "culprit", "conditioning"):
            np.testing.assert_array_equal(getattr(lean, name), getattr(full, name))
        amplitudes = (
            ("x", "y")
            if isinstance(full, gt.OffTangentResult)
            else ("alpha", "beta", "normal_velocity", "in_tangent_planes")
        )
        for name in amplitudes:
            np.testing.assert_array_equal(getattr(lean, name), getattr(full, name))


def test_row_picks_a_row_of_a_batch_and_says_so_plainly_on_a_single_result():
    twists = np.array([[0, 0, 1, 0, 0, 0], [0, 0, 0, 0, 0, 1.0]])
    batch = gt.decompose_off_tangent(EX1, EX1_WRIST, twists)
    for i, twist in enumerate(twists):
        one = gt.decompose_off_tangent(EX1, EX1_WRIST, twist)
        np.testing.assert_array_equal(batch.row(i).y, one.y)
        with pytest.raises(ValueError, match=r"row\(0\): this result is for one grasp and one twist"):
            one.row(0)
    np.testing.assert_allclose(batch.row(1).x, [2 / 3] * 3, atol=1e-4)
    with pytest.raises(ValueError, match="one grasp and one twist"):
        gt.decompose_tangent(EX2, EX2_NORMALS, twists[0]).row(0)


def test_components_without_the_bases_is_a_clear_error_and_with_them_sum_to_the_twist():
    points = np.array([[1, 0, 0], [-0.5, 0.75**0.5, 0], [-0.5, -(0.75**0.5), 0]])
    normals = -points + [0, 0, 0.3]
    twist = np.array([0.1, 0.2, 0.3, 0.4, 0.5, 0.6])
    for amplitudes_only, full in (
        (
            gt.decompose_off_tangent(points, [0, 0, 1], twist, bases=False),
            gt.decompose_off_tangent(points, [0, 0, 1], twist),
        ),
        (gt.decompose_tangent(points, normals, twist, bases=False), gt.decompose_tangent(points, normals, twist)),
    ):
        with pytest.raises(ValueError, match=r"^components need the basis screws: decompose with bases=True"):
            amplitudes_only.components()
        a, b = full.components()
        np.testing.assert_allclose(a.sum(-2) + b.sum(-2), twist, atol=1e-12)
