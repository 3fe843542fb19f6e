"""The force side (issue 19): manipulating forces, squeezes, the least grip and force closure.

Numbers are checked against LAPACK's pseudo-inverse, against Clarabel (an independent conic
solver on the nine contact-force numbers, tests/conic.py) and against cases worked by hand.
"""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import grasptwist as gt
from conic import closure_friction as clarabel_closure_friction
from conic import least_grip
from grasptwist.engine import formulas
from grasptwist.engine.forces.closure import epsilon_quality
from grasptwist.engine.forces.grasp_map import manipulating_reference, squeeze_directions
from grasptwist.engine.screws import field_at, klein, rigid_motion

EQ = np.array([[1, 0, 0], [-0.5, 0.75**0.5, 0], [-0.5, -(0.75**0.5), 0]])  # a ball's equator, radius 1
EX2 = np.array([[0, 2, 2], [2, 0, 2], [2, 2, 0]], float)  # the paper's Example 2
G = 9.81


def grasps(n, seed, spread=0.35):
    """``n`` grasps of a unit ball near its equator: normals towards the centre, tilted by ``spread``,
    and a wrench of a few newtons and newton-metres."""
    rng = np.random.default_rng(seed)
    angle = rng.uniform(0, 2 * np.pi, (n, 1)) + np.array([0, 2.1, 4.2]) + rng.normal(0, 0.3, (n, 3))
    height = rng.normal(0, 0.3, (n, 3))
    p = np.stack((np.cos(angle), np.sin(angle), height), axis=-1)
    normals = -p + rng.normal(0, spread, (n, 3, 3))
    wrench = np.concatenate((rng.normal(0, 5, (n, 3)), rng.normal(0, 1, (n, 3))), axis=1)
    friction = rng.uniform(0.3, 1.2, (n, 3))
    return p, normals, wrench, friction


def unit(n):
    return n / np.linalg.norm(n, axis=-1, keepdims=True)


def wrench_of(points, forces):
    f = np.asarray(forces)
    return np.concatenate((f.sum(axis=-2), np.cross(points, f).sum(axis=-2)), axis=-1)


# --- manipulating forces and squeezes -----------------------------------------------------


def test_manipulating_forces_are_the_pseudo_inverse_and_make_the_wrench():
    p, _, w, _ = grasps(200, 1)
    p = p * 3 + 5  # away from the origin: the closed form works about the centroid
    r = gt.forces.manipulating_forces(p, w)
    assert (r.status == 0).all()
    ref = manipulating_reference(p, w)
    assert np.abs(r.force - ref).max() <= 1e-12 * np.abs(ref).max()
    assert np.abs(wrench_of(p, r.force) - w).max() <= 1e-9 * np.abs(w).max()


def test_conditioning_is_one_for_an_equilateral_triangle_and_falls_like_the_offset_from_a_line():
    assert gt.forces.manipulating_forces(EQ, np.zeros(6)).conditioning == pytest.approx(1.0, abs=1e-15)
    offsets = np.array([1e-2, 1e-4, 1e-6])
    p = np.zeros((3, 3, 3))
    p[:, 1, 0], p[:, 2, 0], p[:, 2, 1] = 1.0, 2.0, offsets
    c = gt.forces.manipulating_forces(p, np.zeros(6)).conditioning
    assert c / offsets == pytest.approx(np.full(3, c[0] / offsets[0]), rel=1e-3)  # linear in the offset


@pytest.mark.parametrize(
    "points, status, culprit",
    [
        ([[0, 0, 0], [1, 0, 0], [2, 0, 0]], gt.forces.Status.COLLINEAR_CONTACTS, -1),
        ([[0, 0, 0], [1, 0, 0], [1, 0, 0]], gt.forces.Status.COINCIDENT_CONTACTS, 0),
        ([[0, 0, 0], [1, 0, np.nan], [0, 1, 0]], gt.forces.Status.NONFINITE_INPUT, -1),
    ],
    ids=["collinear", "coincident", "nan"],
)
def test_degenerate_contacts_get_a_status_and_nan_never_an_exception(points, status, culprit):
    r = gt.forces.manipulating_forces(points, [1, 0, 0, 0, 0, 1])
    assert (int(r.status), int(r.culprit)) == (status, culprit)
    assert np.isnan(r.force).all()
    g = gt.forces.grip(points, [[1, 0, 0]] * 3, [1, 0, 0, 0, 0, 1], 0.5)
    assert int(g.status) == status and np.isnan(g.force).all()
    assert int(gt.forces.force_closure(points, [[1, 0, 0]] * 3).status) == status


def test_squeezes_span_the_null_space_and_are_orthogonal_to_the_manipulating_forces():
    p, _, w, _ = grasps(50, 2)
    s = np.random.default_rng(0).normal(size=(50, 3))
    f = gt.forces.squeeze_forces(p, s)
    assert np.abs(wrench_of(p, f)).max() < 1e-13
    assert np.abs(np.einsum("nij,nij->n", f, gt.forces.manipulating_forces(p, w).force)).max() < 1e-12
    # three independent squeezes: the null space of the 6 x 9 grasp map, which has rank 6
    basis = np.stack([gt.forces.squeeze_forces(p, e).reshape(50, 9) for e in np.eye(3)], axis=-1)
    assert (np.linalg.matrix_rank(basis) == 3).all()
    assert (np.linalg.matrix_rank(gt.forces.grasp_map(p)) == 6).all()


def test_a_positive_squeeze_pushes_its_two_fingers_towards_each_other():
    f = gt.forces.squeeze_forces(EQ, [1.0, 0, 0])  # along the side through contacts 2 and 3
    assert np.allclose(f[0], 0)
    assert f[1] @ (EQ[2] - EQ[1]) > 0 and f[2] @ (EQ[1] - EQ[2]) > 0
    assert (np.einsum("ij,ij->i", f, -EQ)[1:] > 0).all()  # inward normals: both fingers push


def test_a_squeeze_half_is_the_wrench_along_sigma_and_does_no_work_on_the_other_basis_twists():
    """Squeeze i's force on contact j is s_i Sigma_i as a wrench: [Sigma_i|Sigma_m] = 0 for every m,
    [Sigma_i|Psi_m] = [Sigma_i|Theta_m] = 0 for m != i; its power on any twist T is s_i [Sigma_i|T]."""
    p, n, _, _ = grasps(30, 3)
    sigma, psi = formulas.sigma_lines(p), formulas.psi_lines(p, p.mean(axis=1) + [0, 0, 1])
    theta = formulas.theta_lines(p, n)
    e = squeeze_directions(p)
    for i in range(3):
        j = (i + 1) % 3
        half = gt.forces.squeeze_forces(p, np.eye(3)[i])[:, j]  # the force on contact j of a unit squeeze i
        wrench = np.concatenate((half, np.cross(p[:, j], half)), axis=-1)
        assert np.abs(wrench - sigma[:, i]).max() < 1e-12
        assert np.abs(e[:, i] - sigma[:, i, :3]).max() < 1e-12
        for m in range(3):
            assert np.abs(klein(sigma[:, i], sigma[:, m])).max() < 1e-12
            products = (klein(sigma[:, i], psi[:, m]), klein(sigma[:, i], theta[:, m]))
            for prod in products:
                assert (np.abs(prod).max() < 1e-12) if m != i else (np.abs(prod).min() > 1e-6)
    twist = np.random.default_rng(1).normal(size=(30, 6))
    f = gt.forces.squeeze_forces(p, [1.0, 0, 0])
    power = np.einsum("nk,nk->n", f[:, 1], field_at(twist, p[:, 1]))
    assert np.abs(power - klein(sigma[:, 0], twist)).max() < 1e-12
    assert np.abs(power + np.einsum("nk,nk->n", f[:, 2], field_at(twist, p[:, 2]))).max() < 1e-12


# --- the least grip ---------------------------------------------------------------------------


def test_a_ball_held_at_its_equator_needs_mg_over_mu_in_total():
    """Each finger carries m g / 3 by friction, so f_n = m g / (3 mu): sum f_n = m g / mu (= 19.62 N for 1 kg,
    mu = 0.5), and no grip does with less, since sum f_n >= sum |f_t| / mu >= m g / mu."""
    g = gt.forces.grip(EQ, -EQ, [0, 0, G, 0, 0, 0], 0.5)
    assert g.total_normal_force == pytest.approx(G / 0.5, rel=1e-9)
    assert g.normal_force == pytest.approx(np.full(3, G / 1.5), rel=1e-6)
    assert g.friction_used == pytest.approx(np.full(3, 0.5), rel=1e-6)
    assert gt.forces.grip(EQ, -EQ, [0, 0, G, 0, 0, 0], 0.5, safety=2).total_normal_force == pytest.approx(
        2 * G / 0.5, rel=1e-9
    )
    assert gt.forces.grip(EQ, -EQ, np.zeros(6), 0.5).total_normal_force == 0.0


@pytest.mark.parametrize("count", [40, pytest.param(3000, marks=pytest.mark.slow)])
def test_the_least_grip_equals_clarabels_and_holds(count):
    p, n, w, mu = grasps(count, 4)
    g = gt.forces.grip(p, n, w, mu, safety=1.2)
    refs = [least_grip(p[k], n[k], w[k], mu[k], 1.2)[0] for k in range(count)]
    solved = np.array([r is not None for r in refs])
    assert ((g.status == 0) == solved).all() and solved.sum() >= count / 2
    ref = np.array([r for r in refs if r is not None])
    assert np.abs(g.total_normal_force[solved] / ref - 1).max() < 1e-6
    ok = g.ok
    assert np.abs(wrench_of(p[ok], g.force[ok]) - w[ok]).max() <= 1e-9 * np.abs(w).max()
    assert (g.friction_used[ok] <= mu[ok] / 1.2 * (1 + 1e-9)).all() and (g.normal_force[ok] > 0).all()
    assert (
        np.abs(g.force - g.manipulating - gt.forces.squeeze_forces(p, g.squeeze))[ok].max()
        < 1e-12 * np.abs(g.force[ok]).max()
    )
    assert g.safety == 1.2


def test_frictionless_contacts_hold_only_what_the_normals_make():
    """With mu = 0 each finger pushes along its normal: on the equator (normals n_i = -p_i, n_1 + n_2 + n_3 = 0)
    the force -n_1 is made by fingers 2 and 3 alone (n_2 + n_3 = -n_1), sum f_n = 2; a lift needs friction."""
    g = gt.forces.grip(EQ, -EQ, [*EQ[0], 0, 0, 0], 0.0)
    assert g.ok and g.total_normal_force == pytest.approx(2.0, rel=1e-12)
    assert g.normal_force == pytest.approx([0, 1, 1], abs=1e-12)
    lift = gt.forces.grip(EQ, -EQ, [0, 0, G, 0, 0, 0], 0.0)
    assert int(lift.status) == gt.forces.Status.CANNOT_HOLD and int(lift.culprit) >= 0
    mixed = gt.forces.grip(EQ, -EQ, [0, 0, G, 0, 0, 0], [0.0, 0.5, 0.5])
    assert int(mixed.status) == gt.forces.Status.MIXED_FRICTIONLESS


def test_cannot_hold_says_which_cone_or_that_the_wrench_needs_pulling():
    # fingers under a tray (normals up): pressing the tray down needs them to pull
    down = gt.forces.grip(EQ, [[0, 0, 1]] * 3, [0, 0, -1, 0, 0, 0], 0.5)
    assert (int(down.status), int(down.culprit)) == (gt.forces.Status.CANNOT_HOLD, -1)
    assert "pull" in gt.forces.status_message(down.status, down.culprit)
    # Example 2 below its closure friction cannot lift the polyhedron off the three faces' common corner
    far = gt.forces.grip(EX2, np.eye(3), [-1, -1, -1, 0, 0, 0], 0.3)
    assert int(far.status) == gt.forces.Status.CANNOT_HOLD and int(far.culprit) >= 0
    assert least_grip(EX2, np.eye(3), [-1, -1, -1, 0, 0, 0], 0.3)[0] is None
    assert "cone at contact" in gt.forces.status_message(far.status, far.culprit)


def test_a_batch_gives_each_row_what_it_gives_alone():
    p, n, w, mu = grasps(6, 5)
    g = gt.forces.grip(p, n, w, mu)
    for k in range(6):
        one = gt.forces.grip(p[k], n[k], w[k], mu[k])
        assert int(one.status) == g.status[k]
        if one.ok:
            assert one.total_normal_force == pytest.approx(g.total_normal_force[k], rel=1e-8)


# --- force closure ------------------------------------------------------------------------------


def test_example_2_closes_above_one_over_root_two():
    """The projected normals meet at the contacts' centroid and each normal makes atan(1/sqrt(2)) with the
    contacts' plane x + y + z = 4: the cones reach the plane only for mu > tan(phi) = 1/sqrt(2)."""
    c = gt.forces.force_closure(EX2, np.eye(3), friction=[[0.7], [0.71]])
    assert c.closure_friction == pytest.approx(np.full(2, 0.5**0.5), rel=1e-12)
    assert c.force_closure.tolist() == [False, True]


@pytest.mark.parametrize("count", [10, pytest.param(300, marks=pytest.mark.slow)])
def test_closure_friction_equals_clarabels(count):
    p, n, _, _ = grasps(count, 6, spread=0.6)
    c = gt.forces.force_closure(p, n)
    ref = np.array([clarabel_closure_friction(p[k], n[k]) for k in range(count)])
    assert (np.isnan(ref) == np.isnan(c.closure_friction)).all() and np.isfinite(ref).sum() >= 0.6 * count
    ok = np.isfinite(ref)
    assert np.abs(c.closure_friction[ok] / ref[ok] - 1).max() < 1e-6


def test_a_normal_in_the_contacts_plane_is_ideal_for_closure_but_degenerate_for_the_tangent_method():
    """Normals in the contacts' plane meeting at one point (a ball's equator) close with any mu > 0, but the
    tangent method cannot move a contact along such a normal; normals at right angles to the plane are the
    tangent method's best case and never close (internal forces lie in the plane)."""
    twist = [0, 0, 1, 0, 0, 0]
    assert gt.forces.force_closure(EQ, -EQ).closure_friction <= 1e-12
    # three coplanar normal lines through one point: rank 2, the first of the in-plane failures it checks
    assert int(gt.decompose_tangent(EQ, -EQ, twist).status) == gt.Status.NORMALS_RANK_DEFICIENT
    up = [[0, 0, 1]] * 3
    tangent = gt.decompose_tangent(EQ, up, twist)
    assert int(tangent.status) == gt.Status.OK and float(tangent.conditioning) > 0.5
    c = gt.forces.force_closure(EQ, up, friction=10.0)
    assert (int(c.status), int(c.culprit)) == (gt.forces.Status.NO_CLOSURE, 0)
    assert np.isnan(c.closure_friction) and not c.force_closure


def test_two_fingers_squeezing_with_the_third_idle_is_not_closure():
    # contact 3's normal is steep (tan phi = 3): below mu = 3 only contacts 1 and 2 can squeeze
    n = -EQ.copy()
    n[2] = unit(n[2] + [0, 0, 3])
    assert gt.forces.force_closure(EQ, n).closure_friction == pytest.approx(3.0, rel=1e-9)


def test_epsilon_is_zero_outside_closure_and_grows_with_friction():
    c = gt.forces.force_closure(EX2, np.eye(3), friction=[[0.6], [0.8], [1.2]], quality=True)
    assert c.epsilon[0] == 0 and 0 < c.epsilon[1] < c.epsilon[2]
    assert epsilon_quality(EQ, -EQ, [0.0] * 3) == 0.0  # flat hull (Qhull's error): no closure


def test_every_figure_is_unchanged_by_rigid_motions_and_scaling():
    p, n, w, mu = grasps(8, 7)
    rng = np.random.default_rng(8)
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    rot = q * np.sign(np.linalg.det(q))
    shift, scale = rng.normal(size=3) * 10, 7.5
    p2 = scale * p @ rot.T + shift
    n2 = n @ rot.T
    w2 = rigid_motion(np.concatenate((w[:, :3], w[:, 3:] * scale), axis=1), rot, shift)  # (force; moment) as (omega; v)
    a, b = gt.forces.grip(p, n, w, mu), gt.forces.grip(p2, n2, w2, mu)
    assert (a.status == b.status).all() and a.ok.sum() >= 6
    ok = a.ok
    assert np.abs(b.total_normal_force[ok] / a.total_normal_force[ok] - 1).max() < 1e-6
    assert np.abs(b.manipulating - a.manipulating @ rot.T)[ok].max() < 1e-9 * np.abs(a.manipulating).max()
    assert np.abs(b.conditioning - a.conditioning).max() < 1e-12
    ca = gt.forces.force_closure(p, n, mu, quality=True)
    cb = gt.forces.force_closure(p2, n2, mu, quality=True)
    assert np.abs(cb.closure_friction / ca.closure_friction - 1).max() < 1e-9
    assert (ca.force_closure == cb.force_closure).all()
    assert np.abs(cb.epsilon - ca.epsilon).max() < 1e-9


# --- validators ----------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "value, message",
    [
        ([0, 0, 1], r"^wrench must have shape \(\.\.\., 6\), got \(3,\)$"),
        (["a"] * 6, r"^wrench must hold real numbers, got dtype <U1$"),
        ([[1.0] * 6, [1.0]], r"^wrench must be real numbers, got a ragged nested sequence$"),
        ([True] * 6, r"^wrench must hold real numbers, got booleans$"),
    ],
)
def test_check_wrench(value, message):
    with pytest.raises(ValueError, match=message):
        gt.forces.check_wrench(value)


@pytest.mark.parametrize(
    "value, message",
    [
        ([0.5, -0.1, 0.5], r"^friction must be >= 0, got -0\.1$"),
        ([[0.5, 0.5]], r"^friction must broadcast to \(\.\.\., 3\) \(one per contact\), got \(1, 2\)$"),
        ([1j], r"^friction must hold real numbers, got complex numbers$"),
    ],
)
def test_check_friction(value, message):
    with pytest.raises(ValueError, match=message):
        gt.forces.check_friction(value)


@pytest.mark.parametrize("value", [0.99, float("nan"), float("inf"), "x", True, None])
def test_check_safety(value):
    with pytest.raises(ValueError, match=r"^safety must be a finite number >= 1, got "):
        gt.forces.check_safety(value)


def test_force_closure_arguments():
    with pytest.raises(ValueError, match=r"^quality=True needs the grasp's friction"):
        gt.forces.force_closure(EQ, -EQ, quality=True)
    with pytest.raises(ValueError, match=r"^cone_edges must be an integer >= 3, got 2$"):
        gt.forces.force_closure(EQ, -EQ, 0.5, quality=True, cone_edges=2)


# --- properties -------------------------------------------------------------------------------------


@settings(max_examples=10, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), spread=st.floats(0.0, 1.0), safety=st.floats(1.0, 3.0))
def test_any_grip_found_makes_the_wrench_within_every_cone_and_beats_no_clarabel_grip(seed, spread, safety):
    p, n, w, mu = grasps(4, seed, spread)
    g = gt.forces.grip(p, n, w, mu, safety)
    for k in range(4):
        ref, _ = least_grip(p[k], n[k], w[k], mu[k], safety)
        assert g.ok[k] == (ref is not None)
        if ref is not None:
            assert g.total_normal_force[k] == pytest.approx(ref, rel=1e-6)
            assert np.abs(wrench_of(p[k], g.force[k]) - w[k]).max() <= 1e-9 * np.abs(w[k]).max()
            assert (g.friction_used[k] <= mu[k] / safety * (1 + 1e-9)).all()


def test_the_interior_point_step_stops_at_the_cones_edge_even_for_a_ray():
    from grasptwist.engine.forces.socp import _edge

    rng = np.random.default_rng(7)
    x = rng.normal(size=(3, 1, 500))
    x[0] = np.hypot(x[1], x[2]) + rng.uniform(0.01, 1, (1, 500))
    d = 3 * rng.normal(size=(3, 1, 500))
    alpha = _edge(x, d)
    hit = np.isfinite(alpha)
    y = x[:, 0, hit] + alpha[hit] * d[:, 0, hit]
    np.testing.assert_allclose(y[0], np.hypot(y[1], y[2]), atol=1e-9)  # on the boundary
    far = x[:, 0, ~hit] + 1e6 * d[:, 0, ~hit]
    assert hit.any() and (~hit).any() and (far[0] >= np.hypot(far[1], far[2]) - 1e-6).all()  # never leaves
    # a half-space's cone (t, 0, 0): stopped exactly at t = 0, where a difference of squares loses it
    ray = _edge(np.array([[[0.3]], [[0.0]], [[0.0]]]), np.array([[[-0.7]], [[0.0]], [[0.0]]]))
    assert ray[0] == pytest.approx(0.3 / 0.7, rel=1e-15)
