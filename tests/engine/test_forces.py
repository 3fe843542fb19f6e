"""The force side (issue 19): manipulating forces, squeezes, the least grip and force closure.

Numbers are checked against LAPACK's pseudo-inverse, against Clarabel (an independent conic
solver on the nine contact-force numbers, tests/conic.py) and against cases worked by hand.
"""

import contextlib
import importlib.util
import os
import subprocess
import sys
import types
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import grasptwist as gt
from conic import closure_friction as clarabel_closure_friction
from conic import least_grip
from grasptwist.engine import formulas
from grasptwist.engine.forces import compiled
from grasptwist.engine.forces.closure import check_cone_edges, epsilon_quality, first_edges
from grasptwist.engine.forces.grasp_map import checked_grip, manipulating_reference, squeeze_directions
from grasptwist.engine.forces.hold import grip_along
from grasptwist.engine.screws import field_at, klein, rigid_motion
from grasptwist.model import Segment

EQ = np.array([[1, 0, 0], [-0.5, 0.75**0.5, 0], [-0.5, -(0.75**0.5), 0]])  # a ball's equator, radius 1
EX2 = np.array([[0, 2, 2], [2, 0, 2], [2, 2, 0]], float)  # the paper's Example 2
G = 9.81
# the bundled ball's tripod (grasps/sphere.yaml): force closure above mu = 0.4663
TRIPOD = np.array([[0.0, 0.031721, -0.014792], [-0.027471, -0.01586, -0.014792], [0.027471, -0.01586, -0.014792]])
TRIPOD_N = np.array([[0.0, -0.906305, 0.422624], [0.784886, 0.453143, 0.422629], [-0.784886, 0.453143, 0.422629]])


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


@pytest.fixture
def compiled_path(monkeypatch):
    """The grip compiled (numba, when installed), which conftest.py switches off for the default run."""
    pytest.importorskip("numba")
    monkeypatch.setitem(compiled._state, "on", True)


# over a second: docs/reference/development.md, Test time (numba compiles its kernel once per process, ~16 s cold)
COMPILED = pytest.param("compiled", marks=pytest.mark.slow)


@pytest.fixture(params=["numpy", COMPILED])
def grip_path(request):
    """Each grip of the test on the numpy path (the reference), then compiled (numba, with ``-m slow``)."""
    if request.param == "numpy":
        with compiled.numpy_path():
            yield request.param
    else:
        request.getfixturevalue("compiled_path")
        yield request.param


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
    # a moment about x: about the collinear contacts' line, which no finger force makes
    r = gt.forces.manipulating_forces(points, [1, 0, 0, 1, 0, 1])
    assert (int(r.status), int(r.culprit)) == (status, culprit)
    assert np.isnan(r.force).all()
    g = gt.grip(points, [[1, 0, 0]] * 3, [1, 0, 0, 1, 0, 1], 0.5)
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
    g = gt.grip(EQ, -EQ, [0, 0, G, 0, 0, 0], 0.5)
    assert g.total_normal_force == pytest.approx(G / 0.5, rel=1e-9)
    assert g.normal_force == pytest.approx(np.full(3, G / 1.5), rel=1e-6)
    assert g.friction_used == pytest.approx(np.full(3, 0.5), rel=1e-6)
    assert gt.grip(EQ, -EQ, [0, 0, G, 0, 0, 0], 0.5, safety=2).total_normal_force == pytest.approx(
        2 * G / 0.5, rel=1e-9
    )
    assert gt.grip(EQ, -EQ, np.zeros(6), 0.5).total_normal_force == 0.0


@pytest.mark.parametrize("count", [40, pytest.param(3000, marks=pytest.mark.slow)])
def test_the_least_grip_equals_clarabels_and_holds(count, grip_path):
    p, n, w, mu = grasps(count, 4)
    g = gt.grip(p, n, w, mu, safety=1.2)
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
    g = gt.grip(EQ, -EQ, [*EQ[0], 0, 0, 0], 0.0)
    assert g.ok and g.total_normal_force == pytest.approx(2.0, rel=1e-12)
    assert g.normal_force == pytest.approx([0, 1, 1], abs=1e-12)
    lift = gt.grip(EQ, -EQ, [0, 0, G, 0, 0, 0], 0.0)
    assert int(lift.status) == gt.forces.Status.CANNOT_HOLD and int(lift.culprit) >= 0
    mixed = gt.grip(EQ, -EQ, [0, 0, G, 0, 0, 0], [0.0, 0.5, 0.5])
    assert int(mixed.status) == gt.forces.Status.MIXED_FRICTIONLESS


def test_cannot_hold_says_which_cone_or_that_the_wrench_needs_pulling():
    # fingers under a tray (normals up): pressing the tray down needs them to pull
    down = gt.grip(EQ, [[0, 0, 1]] * 3, [0, 0, -1, 0, 0, 0], 0.5)
    assert (int(down.status), int(down.culprit)) == (gt.forces.Status.CANNOT_HOLD, -1)
    assert "pull" in gt.forces.status_message(down.status, down.culprit)
    # Example 2 below its closure friction cannot lift the polyhedron off the three faces' common corner
    far = gt.grip(EX2, np.eye(3), [-1, -1, -1, 0, 0, 0], 0.3)
    assert int(far.status) == gt.forces.Status.CANNOT_HOLD and int(far.culprit) >= 0
    assert least_grip(EX2, np.eye(3), [-1, -1, -1, 0, 0, 0], 0.3)[0] is None
    assert "cone at contact" in gt.forces.status_message(far.status, far.culprit)


def test_a_batch_gives_each_row_what_it_gives_alone():
    p, n, w, mu = grasps(6, 5)
    g = gt.grip(p, n, w, mu)
    for k in range(6):
        one = gt.grip(p[k], n[k], w[k], mu[k])
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
    a, b = gt.grip(p, n, w, mu), gt.grip(p2, n2, w2, mu)
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
    with pytest.raises(ValueError, match=r"^cone_edges must be an integer from 3 to 64, got 2$"):
        gt.forces.force_closure(EQ, -EQ, 0.5, quality=True, cone_edges=2)


@pytest.mark.parametrize("value", [2, 65, 10**9, 3.5, float("nan"), float("inf"), True, "8", None])
def test_check_cone_edges(value):
    with pytest.raises(ValueError, match=r"^cone_edges must be an integer from 3 to 64, got "):
        check_cone_edges(value)
    assert check_cone_edges(64) == 64 and check_cone_edges(3.0) == 3


def test_the_most_cone_edges_is_public_where_the_forces_guide_names_it():
    edges = gt.forces.MAX_CONE_EDGES
    assert edges == 64 and check_cone_edges(edges) == edges
    with pytest.raises(ValueError, match=rf"^cone_edges must be an integer from 3 to {edges}, got {edges + 1}$"):
        check_cone_edges(edges + 1)


# --- antipodal, coplanar and coincident contacts; huge friction; overflow (issues 26, 27) --------

ANTIPODAL = np.array([[0.03, 0, 0], [-0.03, 0, 0], [0, 0.03, 0.01]])  # the next contact on the normal's line
ANTIPODAL_N = np.array([[-1.0, 0, 0], [1, 0, 0], [0, -1, 0]])


def test_an_antipodal_pair_has_an_epsilon_that_turns_with_the_grasp_and_never_raises_in_a_batch():
    c = gt.forces.force_closure(ANTIPODAL, ANTIPODAL_N, 0.6, quality=True)
    assert c.status == 0 and c.force_closure and c.epsilon > 0.05
    # the pyramids' first edges follow the grasp: a rigid motion leaves epsilon as it is
    q, _ = np.linalg.qr(np.random.default_rng(3).normal(size=(3, 3)))
    rot = q * np.sign(np.linalg.det(q))
    moved = gt.forces.force_closure(ANTIPODAL @ rot.T + [1, -2, 0.5], ANTIPODAL_N @ rot.T, 0.6, quality=True)
    assert moved.epsilon == pytest.approx(float(c.epsilon), rel=1e-9)
    # the first edge of contact 1 points at contact 3 (its next contact lies on its normal's line)
    b1 = first_edges(ANTIPODAL, ANTIPODAL_N)
    np.testing.assert_allclose(b1[0], unit(np.array([0, 0.03, 0.01])), atol=1e-15)
    # one such row among many: every row computed, each as alone
    p, n, _, mu = grasps(30, 5)
    p[17], n[17], mu[17] = ANTIPODAL, ANTIPODAL_N, 0.6
    batch = gt.forces.force_closure(p, n, mu, quality=True)
    assert batch.epsilon[17] == pytest.approx(float(c.epsilon), rel=1e-12)
    assert np.isfinite(batch.epsilon).all() and (batch.status[batch.force_closure] == 0).all()


def test_antipodal_coplanar_and_coincident_contacts_through_every_force_function():
    lift = [0, 0, 1.0, 0, 0, 0]
    m = gt.forces.manipulating_forces(ANTIPODAL, lift)
    np.testing.assert_allclose(gt.forces.grasp_map(ANTIPODAL) @ m.force.reshape(9), lift, atol=1e-12)
    g = gt.grip(ANTIPODAL, ANTIPODAL_N, lift, 0.6)
    assert g.status == 0 and (g.friction_used <= 0.6 + 1e-9).all()
    np.testing.assert_allclose(gt.forces.grasp_map(ANTIPODAL) @ g.force.reshape(9), lift, atol=1e-9)
    # coplanar: the normals in the contacts' plane (the ball's equator)
    c = gt.forces.force_closure(EQ, -EQ, 0.5, quality=True)
    assert c.status == 0 and c.closure_friction == pytest.approx(0, abs=1e-9) and c.epsilon > 0
    # coincident: a status, NaN numbers and epsilon 0, never an exception
    same = np.array([[1.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    c = gt.forces.force_closure(same, -same, 0.5, quality=True)
    assert (int(c.status), int(c.culprit), float(c.epsilon), bool(c.force_closure)) == (2, 2, 0.0, False)
    assert gt.grip(same, -same, lift, 0.5).status == 2 == gt.forces.manipulating_forces(same, lift).status
    _, held = grip_along(ANTIPODAL, ANTIPODAL_N, 0.6, 0.1, [0, 0, 0], [0, 0, -G], [Segment(1.0, twist=[0] * 6)], [0, 1])
    assert held.status.tolist() == [0, 0]


def test_huge_and_infinite_friction_mean_what_they_say():
    # the ball's tripod closes above mu = 0.4663; every friction above it closes it, however large
    tripod = gt.forces.force_closure(TRIPOD, TRIPOD_N, [[0.3], [0.5], [10], [1e200], [np.inf]], quality=True)
    assert tripod.force_closure.tolist() == [False, True, True, True, True]
    assert tripod.closure_friction == pytest.approx([0.46632] * 5, abs=1e-5)
    # epsilon grows like mu (the pyramids' tangential wrenches): per unit of mu the same at 1e10 and 1e200
    big = gt.forces.force_closure(TRIPOD, TRIPOD_N, 1e10, quality=True).epsilon
    assert tripod.epsilon[3] / 1e200 == pytest.approx(float(big) / 1e10, rel=1e-6)
    assert np.isnan(tripod.epsilon[4])  # an infinite cone has no finite pyramid
    g = gt.grip(TRIPOD, TRIPOD_N, [[0, 0, G, 0, 0, 0]] * 2, [[1e200], [np.inf]])
    assert g.status.tolist() == [0, 0] and g.total_normal_force[0] == pytest.approx(g.total_normal_force[1], rel=1e-6)


def test_an_overflowing_result_is_a_status_never_an_ok_row_with_infinity():
    # a moment of 1e308 N m on fingers 1 mm from the centre: forces of 3e310 N, beyond a double
    m = gt.forces.manipulating_forces(EQ / 1000, [[0, 0, 0, 0, 0, 1e308], [0, 0, G, 0, 0, 0]])
    assert m.status.tolist() == [9, 0] and np.isnan(m.force[0]).all() and np.isfinite(m.force[1]).all()
    assert gt.forces.status_message(9).startswith("the result overflows double precision")
    g = checked_grip(
        gt.grip(EQ, -EQ, [[0, 0, 1e308, 0, 0, 0], [0, 0, G, 0, 0, 0], [0] * 6, [0, 0, G * 1e300] + [0] * 3], 0.5)
    )
    assert g.status.tolist() == [9, 0, 0, 0] and np.isnan(g.total_normal_force[0])  # 2e308 is beyond a double
    assert g.total_normal_force[1] == pytest.approx(2 * G) and g.friction_used[2].tolist() == [0.0] * 3
    # a huge grip that is still a double is solved scaled: no overflow of the solver's squares
    assert g.total_normal_force[3] == pytest.approx(2 * G * 1e300, rel=1e-9) and g.dual[3] == pytest.approx(g.dual[1])
    _, held = grip_along(EQ, -EQ, 0.5, 1e307, [0, 0, 0], [0, 0, -G], [Segment(1.0, twist=[0] * 6)], [0])
    assert held.status.tolist() == [9]


@pytest.mark.parametrize("scale", [1e-200, 1e-100, 1e120, 1e155, 1e300, 1e307])
def test_the_grip_scales_with_the_wrench_over_the_whole_range_of_doubles(scale, grip_path):
    """grip(k w) = k grip(w): wrenches beyond 1e100 (or below 1e-100) are solved scaled by a power of two."""
    p, n, w, mu = grasps(30, 8)
    w = w / np.abs(w).max(axis=1, keepdims=True)
    one, big = gt.grip(p, n, w, mu, safety=1.2), gt.grip(p, n, scale * w, mu, safety=1.2)
    assert (big.status == one.status).all() and one.ok.sum() >= 10
    ok = one.ok
    np.testing.assert_allclose(big.total_normal_force[ok] / scale, one.total_normal_force[ok], rtol=1e-9)
    np.testing.assert_allclose(big.force[ok] / scale, one.force[ok], rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(big.dual[ok], one.dual[ok], rtol=1e-6, atol=1e-9)
    hand = gt.prepare_grip(p[0], n[0], mu[0], safety=1.2)
    assert float(hand.grip(scale * w[0]).total_normal_force) == pytest.approx(
        float(big.total_normal_force[0]), rel=1e-9, nan_ok=True
    )


# --- properties -------------------------------------------------------------------------------------


@settings(max_examples=10, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), spread=st.floats(0.0, 1.0), safety=st.floats(1.0, 3.0))
def test_any_grip_found_makes_the_wrench_within_every_cone_and_beats_no_clarabel_grip(seed, spread, safety):
    p, n, w, mu = grasps(4, seed, spread)
    g = gt.grip(p, n, w, mu, safety=safety)
    with compiled.numpy_path():
        reference = gt.grip(p, n, w, mu, safety=safety)
    assert (g.status == reference.status).all()
    for k in range(4):
        ref, _ = least_grip(p[k], n[k], w[k], mu[k], safety)
        assert g.ok[k] == (ref is not None)
        if ref is not None:
            assert g.total_normal_force[k] == pytest.approx(ref, rel=1e-6)
            assert np.abs(wrench_of(p[k], g.force[k]) - w[k]).max() <= 1e-9 * np.abs(w[k]).max()
            assert (g.friction_used[k] <= mu[k] / safety * (1 + 1e-9)).all()


def _edge(x, d):
    """The longest step along ``d (k, n)`` from ``x (k, n)`` in the cone: ``ipm.edge``'s numpy twin on one cone."""
    from grasptwist.engine.forces import socp

    x, d = x[None], d[None]
    s = np.sqrt(x[:, 0] ** 2 - (x[:, 1:] ** 2).sum(axis=1))
    out = np.empty(x.shape[-1])
    with np.errstate(divide="ignore"):
        socp._twins()["edge"](x, x, d, d, s, s, out, np.empty_like(s), np.empty_like(s), 1, x.shape[1], None)
    return out


def test_the_interior_point_step_stops_at_the_cones_edge_even_for_a_ray():
    rng = np.random.default_rng(7)
    x = rng.normal(size=(3, 500))
    x[0] = np.hypot(x[1], x[2]) + rng.uniform(0.01, 1, 500)
    d = 3 * rng.normal(size=(3, 500))
    alpha = _edge(x, d)
    hit = np.isfinite(alpha)
    y = x[:, hit] + alpha[hit] * d[:, hit]
    np.testing.assert_allclose(y[0], np.hypot(y[1], y[2]), atol=1e-9)  # on the boundary
    far = x[:, ~hit] + 1e6 * d[:, ~hit]
    assert hit.any() and (~hit).any() and (far[0] >= np.hypot(far[1], far[2]) - 1e-6).all()  # never leaves
    # a half-space's cone (t, 0, 0): stopped exactly at t = 0, where a difference of squares loses it
    ray = _edge(np.array([[0.3], [0.0], [0.0]]), np.array([[-0.7], [0.0], [0.0]]))
    assert ray[0] == pytest.approx(0.3 / 0.7, rel=1e-15)
    assert _edge(np.array([[0.3]]), np.array([[-0.7]]))[0] == pytest.approx(0.3 / 0.7, rel=1e-15)  # a ray, k = 1


# --- certificates, the prepared grip, collinear contacts (issue 29, issue 26 item 2.6) ---------------


def _field(lam, p):
    """``G_i^T lambda = lambda_F + lambda_M x p_i`` for every contact: ``(n, 6), (n, 3, 3) -> (n, 3, 3)``."""
    return lam[:, None, :3] + np.cross(lam[:, None, 3:], p)


def _dual_cone_excess(z, n, limit):
    """``limit |z_t| - z_n`` per contact (``<= 0``: in the dual cone)."""
    zn = np.einsum("nij,nij->ni", z, n)
    return limit * np.linalg.norm(z - zn[..., None] * n, axis=-1) - zn


@pytest.mark.parametrize("seed", [11, 12, 13])
def test_every_grip_carries_a_certificate_that_numpy_alone_verifies(seed, grip_path):
    """Held: n_i - G_i^T dual in the dual cone and total - w . dual = gap near 0 (weak duality makes the total
    optimal); cannot-hold: y . w > 0 and -G_i^T y in the dual cone (no admissible forces have a component along y)."""
    p, n, w, mu = grasps(400, seed)
    g = gt.grip(p, n, w, mu, safety=1.3)
    u, limit = unit(n), mu / 1.3
    ok, bad = g.ok, g.status == gt.forces.Status.CANNOT_HOLD
    assert ok.sum() > 100 and bad.sum() > 50 and (ok | bad).all()
    assert np.isnan(g.certificate[ok]).all() and np.isfinite(g.dual[ok]).all() and np.isnan(g.dual[bad]).all()
    total = g.total_normal_force[ok]
    assert (_dual_cone_excess(u[ok] - _field(g.dual[ok], p[ok]), u[ok], limit[ok]) <= 1e-6 * total[:, None]).all()
    assert np.abs(g.gap[ok] - (total - np.einsum("ni,ni->n", w[ok], g.dual[ok]))).max() < 1e-9 * total.max()
    assert np.median(np.abs(g.gap[ok]) / total) < 1e-9 and (np.abs(g.gap[ok]) <= 1e-4 * total).all()
    y = g.certificate[bad]
    size = np.linalg.norm(p - p.mean(axis=1, keepdims=True), axis=-1).max(axis=1)[bad, None]
    assert np.linalg.norm(np.concatenate((y[:, :3], size * y[:, 3:]), axis=1), axis=1) == pytest.approx(1, rel=1e-12)
    assert (np.einsum("ni,ni->n", y, w[bad]) > 0).all()
    assert (_dual_cone_excess(-_field(y, p[bad]), u[bad], limit[bad]) <= 1e-6).all()


def test_the_dual_is_the_grips_sensitivity_to_the_wrench():
    p, n, w, mu = grasps(60, 14)
    g = gt.grip(p, n, w, mu)
    dw = np.random.default_rng(15).normal(size=(60, 6)) * 1e-6
    moved = gt.grip(p, n, w + dw, mu)
    both = g.ok & moved.ok
    predicted = np.einsum("ni,ni->n", g.dual[both], dw[both])
    change = moved.total_normal_force[both] - g.total_normal_force[both]
    assert both.sum() > 20
    assert np.abs(change - predicted).max() < 1e-3 * np.abs(dw).max() * np.abs(g.dual[both]).max()


def test_the_equator_ball_needs_one_over_mu_more_grip_per_newton_of_lift():
    g = gt.grip(EQ, -EQ, [0, 0, G, 0, 0, 0], 0.5)
    assert g.dual[:3] == pytest.approx([0, 0, 2.0], abs=1e-6) and abs(float(g.gap)) < 1e-8


def test_a_tray_pushed_down_is_refused_with_the_upward_load_it_cannot_resist():
    down = gt.grip(EQ, [[0, 0, 1]] * 3, [0, 0, -1, 0, 0, 0], 0.5)
    y = down.certificate
    assert y @ [0, 0, -1, 0, 0, 0] > 0 and np.isnan(down.dual).all()
    assert (
        gt.engine.forces.grip.load_words(y, EQ)
        == "cannot resist a force along (0, 0, 1) with a moment (0, 0, 0) about the origin"
    )


def test_frictionless_grips_carry_certificates_too():
    held = gt.grip(EQ, -EQ, [*EQ[0], 0, 0, 0], 0.0)  # rank 2 normal lines, contact 1 idle
    assert float(held.gap) == pytest.approx(0.0, abs=1e-9)
    nu = np.concatenate((-EQ, np.cross(EQ, -EQ)), axis=1)
    assert (nu @ held.dual <= 1 + 1e-9).all()
    lift = gt.grip(EQ, -EQ, [0, 0, G, 0, 0, 0], 0.0)  # out of the normals' span
    assert lift.certificate @ [0, 0, G, 0, 0, 0] > 0 and (nu @ lift.certificate <= 1e-12).all()
    up = [[0, 0, 1.0]] * 3  # a tray on three finger-tips: rank 3 normal lines, pressing it down needs pulling
    pull = gt.grip(EQ, up, [0, 0, -1, 0, 0, 0], 0.0)
    assert (int(pull.status), int(pull.culprit)) == (gt.forces.Status.CANNOT_HOLD, -1)
    lines = np.concatenate((up, np.cross(EQ, up)), axis=1)
    assert pull.certificate @ [0, 0, -1, 0, 0, 0] > 0 and (lines @ pull.certificate <= 1e-12).all()


def test_safety_is_keyword_only():
    with pytest.raises(TypeError):
        gt.grip(EQ, -EQ, [0, 0, G, 0, 0, 0], 0.5, 2.0)


def test_a_prepared_grip_gives_what_grip_gives(grip_path):
    p, n, w, mu = grasps(30, 16)
    for k in range(6):
        hand = gt.prepare_grip(p[k], n[k], mu[k], safety=1.2)
        many = hand.grip(w)
        direct = gt.grip(p[k], n[k], w, mu[k], safety=1.2)
        one = hand.grip(w[k])
        assert (many.status == direct.status).all() and int(one.status) == direct.status[k]
        for name in ("total_normal_force", "force", "dual", "certificate"):
            # the same solver on the same rows; batches of other shapes may round their last bits otherwise
            np.testing.assert_allclose(getattr(many, name), getattr(direct, name), rtol=1e-7, atol=1e-9)
            np.testing.assert_allclose(getattr(one, name), getattr(direct, name)[k], rtol=1e-7, atol=1e-9)
        held = many.ok  # the gap is round-off: both near 0, not equal
        assert (np.abs(many.gap[held]) < 1e-6 * many.total_normal_force[held]).all()


@pytest.mark.parametrize(
    "args, message",
    [
        ((np.zeros((2, 3, 3)), np.ones((2, 3, 3)), 0.5), r"^prepare_grip takes one grasp: points and normals \(3, 3\)"),
        ((EQ, -EQ, [[0.5] * 3] * 2), r"^prepare_grip takes one grasp: friction a scalar or \(3,\), got \(2, 3\)$"),
    ],
)
def test_prepare_grip_arguments(args, message):
    with pytest.raises(ValueError, match=message):
        gt.prepare_grip(*args)


LINE = np.array([[-0.05, 0, 0], [0.05, 0, 0], [0, 0, 0.0]])  # three contacts on the x axis
ACROSS = np.array([[1, 0, 0], [-1, 0, 0], [0, 0, 1.0]])  # two squeeze along the line, the third pushes up


def test_collinear_contacts_exert_every_wrench_in_the_grasp_maps_range():
    """Issue 26, item 2.6: a push along the third contact's normal, at that contact, is held by that finger
    alone (1 N of normal force); a moment about the contacts' line is not in G's range, and its certificate
    says so (y . w > 0, y . G f = 0 for every f)."""
    push = np.concatenate(([0, 0, 1.0], np.cross(LINE[2], [0, 0, 1.0])))
    g = gt.grip(LINE, ACROSS, push, 0.5)
    assert g.ok and float(g.total_normal_force) == pytest.approx(1.0, rel=1e-8)
    assert np.abs(wrench_of(LINE, g.force) - push).max() < 1e-9 and np.isnan(g.squeeze).all()
    assert abs(float(g.gap)) < 1e-8 and int(gt.forces.manipulating_forces(LINE, push).status) == 0
    twist = gt.grip(LINE, ACROSS, [0, 0, 0, 0.01, 0, 0], 0.5)
    assert int(twist.status) == gt.forces.Status.COLLINEAR_CONTACTS
    y = twist.certificate
    assert y @ [0, 0, 0, 0.01, 0, 0] > 0 and np.abs(y @ gt.forces.grasp_map(LINE)).max() < 1e-12


def test_collinear_contacts_agree_with_clarabel():
    rng = np.random.default_rng(17)
    normals = unit(ACROSS + rng.normal(0, 0.3, (20, 3, 3)))
    forces = rng.normal(size=(20, 3, 3))
    w = wrench_of(LINE, forces)  # in the range of G by construction
    g = gt.grip(LINE, normals, w, 0.8)
    for k in range(20):
        ref, _ = least_grip(LINE, normals[k], w[k], 0.8)
        assert g.ok[k] == (ref is not None)
        if ref is not None:
            assert float(g.total_normal_force[k]) == pytest.approx(ref, rel=1e-6)
    assert g.ok.any()


def test_one_grasp_in_floats_follows_the_batched_solver_step_for_step():
    """One grasp goes through engine/forces/one.py (Python floats), a batch through socp.py (numpy): the
    same method, so the same verdicts, culprits, optimum and certificates, on held and refused rows alike."""
    p, n, w, mu = grasps(40, 18)
    with compiled.numpy_path():
        batch = gt.grip(p, n, w, mu, safety=1.4)
    assert batch.ok.sum() >= 10 and (~batch.ok).sum() >= 10
    for k in range(40):
        with compiled.numpy_path():
            one = gt.grip(p[k], n[k], w[k], mu[k], safety=1.4)
        assert (int(one.status), int(one.culprit)) == (batch.status[k], batch.culprit[k])
        for name in ("total_normal_force", "force"):
            np.testing.assert_allclose(getattr(one, name), getattr(batch, name)[k], rtol=1e-7, atol=1e-9)
        # multipliers are as well conditioned as the optimum is sharp: the proofs are what must hold (above)
        for name in ("dual", "certificate"):
            np.testing.assert_allclose(getattr(one, name), getattr(batch, name)[k], rtol=1e-4, atol=1e-6)


@pytest.mark.parametrize(
    "points",
    [EQ, np.array([[0, 0, 0], [0.05, 0, 0], [0.1, 0, 0.0]])],
    ids=["tray", "rod-end"],
)
def test_a_wrench_on_the_edge_of_what_the_fingers_exert_is_held(points):
    """A push along the third finger's normal, at that finger, with every normal up: only that finger can
    make it, the other two carry exactly nothing (no grip strictly inside the cones exists, so phase I alone
    cannot decide).  Phase I's multipliers say which contacts are bare; the rest is solved without them."""
    up = np.array([[0, 0, 1.0]] * 3)
    w = np.concatenate((up[2], np.cross(points[2], up[2])))
    g = gt.grip(points, up, w, 0.5)
    assert g.ok and float(g.total_normal_force) == pytest.approx(1.0, rel=1e-9)
    np.testing.assert_allclose(g.force, [[0, 0, 0], [0, 0, 0], [0, 0, 1]], atol=1e-9)
    assert (_dual_cone_excess(up[None] - _field(g.dual[None], points[None]), up[None], 0.5) <= 1e-9).all()
    assert abs(float(g.gap)) < 1e-9 and np.isnan(g.certificate).all()
    with compiled.numpy_path():
        one = gt.prepare_grip(points, up, 0.5).grip(w)  # the floats path too
    assert one.ok and float(one.total_normal_force) == pytest.approx(1.0, rel=1e-9)


def test_collinear_frictionless_contacts_stay_unsolved_and_a_batch_of_odd_rows_never_warns():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        g = gt.grip(
            np.stack((LINE, LINE, LINE, EQ)),
            np.stack((ACROSS, ACROSS, [[0, 0, 0.0]] * 3, [[0, 0, 1.0]] * 3)),
            [[0, 0, 1, 0, 0, 0], [0, 0, np.nan, 0, 0, 0], [0, 0, 1, 0, 0, 0], [0, 0, -1, 0, 0, 0]],
            np.array([[0.0] * 3, [0.5] * 3, [0.5] * 3, [np.inf] * 3]),
        )
    assert g.status.tolist() == [
        gt.forces.Status.COLLINEAR_CONTACTS,
        gt.forces.Status.NONFINITE_INPUT,
        gt.forces.Status.ZERO_NORMAL,
        gt.forces.Status.CANNOT_HOLD,
    ]
    assert np.isnan(g.certificate[:3]).all() and g.certificate[3] @ [0, 0, -1, 0, 0, 0] > 0


def test_contacts_whose_spread_overflows_are_an_overflow_not_coincident():
    """Finite contacts near 1e300 apart: their size overflows, which once read as coincident contacts."""
    p = np.array([[1, 0, 0], [-0.5, 0.75**0.5, 0], [-0.5, -(0.75**0.5), 0]])
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # and quietly: no numpy warning reaches a library caller
        m = gt.forces.manipulating_forces(1e300 * p, [0, 0, 1, 0, 0, 0])
        g = gt.grip(1e300 * p, -p, [0, 0, 1, 0, 0, 0], 0.5)
        c = gt.forces.force_closure(1e300 * p, -p, 0.5, quality=True)
    code = gt.forces.Status.NONFINITE_RESULT
    assert (int(m.status), int(m.culprit), int(g.status), int(c.status)) == (code, -1, code, code)
    assert np.isnan(m.force).all() and np.isnan(m.conditioning)
    # the same grasp at a sane scale is fine
    assert int(gt.forces.manipulating_forces(p, [0, 0, 1, 0, 0, 0]).status) == 0


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time (numba's compile)
def test_the_compiled_grip_follows_the_numpy_path(compiled_path):
    """numba's kernel (engine/forces/kernel.py) is the numpy path's method step for step: the same verdicts and
    culprits, totals to 1e-9, forces to their sharpness; the rows it leaves (degenerate, collinear, frictionless,
    non-finite, on the edge) go to the numpy path within the same batch."""
    from grasptwist.engine.forces import kernel

    p, n, w, mu = grasps(300, 19)
    p[:3], n[:3], mu[:3] = LINE, ACROSS, 0.5  # collinear, and a wrench with a moment about the line
    mu[3] = 0.0  # frictionless
    mu[4, 0] = 0.0  # mixed
    w[5, 2] = np.nan
    w[6] = 0.0  # no wrench: no force
    n[7, 1] = 0.0  # a zero normal
    p[8, 1] = p[8, 0]  # coincident
    w[9] = [0, 0, 1e308, 0, 0, 1e308]  # solved scaled by a power of two, on the numpy path
    with compiled.numpy_path():
        reference = gt.grip(p, n, w, mu, safety=1.3)
    g = gt.grip(p, n, w, mu, safety=1.3)
    codes = np.empty((300, 3), np.int8)
    kernel.grip_rows(p, n, mu / 1.3, w, 1e-9, np.empty((300, kernel.WIDTH)), codes)
    assert codes[:10, 2].tolist() == [0, 0, 0, 0, 0, 0, 1, 0, 0, 0] and codes[10:, 2].mean() > 0.9  # not the odd ones
    assert (g.status == reference.status).all() and (g.culprit == reference.culprit).all()
    assert g.ok.sum() > 100 and (g.status == gt.forces.Status.CANNOT_HOLD).sum() > 50 and not g.ok[9]
    ok = reference.ok
    np.testing.assert_allclose(g.total_normal_force[ok], reference.total_normal_force[ok], rtol=1e-9, atol=0)
    np.testing.assert_allclose(g.force, reference.force, rtol=1e-6, atol=1e-6 * np.abs(reference.force[ok]).max())
    for name in ("manipulating", "conditioning", "squeeze", "normal_force", "friction_used", "certificate"):
        np.testing.assert_allclose(getattr(g, name), getattr(reference, name), rtol=1e-5, atol=1e-6)
    np.testing.assert_allclose(g.dual, reference.dual, rtol=1e-4, atol=1e-4)
    for name in ("force", "dual", "certificate", "gap", "total_normal_force"):
        assert (np.isnan(getattr(g, name)) == np.isnan(getattr(reference, name))).all()
    hand = gt.prepare_grip(p[20], n[20], mu[20], safety=1.3)  # a control loop's call: its own short way
    with compiled.numpy_path():
        alone = hand.grip(w[20])
    fast = hand.grip(w[20])
    for name in ("force", "dual", "status", "culprit", "total_normal_force", "gap", "squeeze", "certificate"):
        a, b = getattr(fast, name), getattr(alone, name)
        assert (type(a), a.shape, a.dtype) == (type(b), b.shape, b.dtype)
    assert fast.total_normal_force == pytest.approx(float(alone.total_normal_force), rel=1e-9)


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time (numba's compile)
def test_the_compiled_grip_answers_each_row_as_alone(compiled_path):
    """The kernel solves rows in step, 32 lanes and 2048 rows a chunk (engine/forces/kernel.py): a row's answer,
    to the last bit, is the same in any order, whatever its neighbours' iterations; alone (one lane, compiled
    apart) it has the same verdict and total to round-off."""
    from grasptwist.engine.forces import kernel

    p, n, w, mu = grasps(2500, 23)  # two chunks, both phases full of lanes
    limit = np.ascontiguousarray(np.broadcast_to(mu / 1.5, (2500, 3)))

    def rows(index):
        out, codes = np.empty((len(index), kernel.WIDTH)), np.empty((len(index), 3), np.int8)
        kernel.grip_rows(p[index], n[index], limit[index], w[index], 1e-9, out, codes)
        return np.nan_to_num(out, nan=7.0), codes

    out, codes = rows(np.arange(2500))
    assert 0.2 < (codes[:, 0] == 0).mean() < 0.95 and codes[:, 2].all()  # held and cannot-hold, none to numpy
    assert rows(np.arange(0))[0].shape == (0, kernel.WIDTH)  # no rows: no chunk
    order = np.random.default_rng(5).permutation(2500)
    again, codes_again = rows(order)
    assert (again == out[order]).all() and (codes_again == codes[order]).all()
    for i in (0, 1, 2, 1000, 2499):
        alone, code = rows(np.array([i]))
        assert (code[0] == codes[i]).all()
        assert alone[0, kernel._TOTAL] == pytest.approx(out[i, kernel._TOTAL], rel=1e-12, abs=0)


@pytest.mark.slow  # over a second: numba's first load (a compile where its cache is cold)
def test_grips_of_any_array_flags_share_one_compiled_signature():
    """numba loads (or compiles) one function per signature and an array's writeable flag is part of it:
    read-only and writable grasps and wrenches, one friction or one per contact, a prepared grip, all
    call the kernel with one signature (each more was 50 ms of a process's start); soft grips and closure,
    socp's compiled iterations with one each (each more would be a compile of some 20 s)."""
    pytest.importorskip("numba")
    code = """if True:
        import numpy as np, grasptwist as gt
        from grasptwist.engine.forces import compiled
        p = np.array({p}); n = -p; w = np.array([[0, 0, 1.0, 0, 0, 0]] * 2)
        gt.grip(p, n, w, 0.5)
        for a in (p, n, w):
            a.flags.writeable = False
        gt.grip(p, n, w, [0.5, 0.6, 0.7])
        gt.grip(p[None].repeat(2, 0), n[None].repeat(2, 0), w, np.full((2, 3), 0.5))
        gt.forces.prepare_grip(p, n, 0.5).grip(w[0])
        signatures = compiled.kernel().grip_rows.signatures
        assert len(signatures) == 1, signatures
        gt.grip(p, n, w, 0.5, torsion=0.01)  # socp's iterations, compiled apart: one signature each too
        gt.forces.force_closure(p, n, torsion=[0.01, 0.0, 0.02])
        for f in (compiled.kernel().iterate_rows, compiled.kernel().polish_rows):
            assert len(f.signatures) == 1, f.signatures
    """
    env = dict(os.environ, GRASPTWIST_NUMBA="1")
    done = subprocess.run([sys.executable, "-c", code.format(p=EQ.tolist())], capture_output=True, text=True, env=env)
    assert done.returncode == 0, done.stderr


def test_importing_grasptwist_imports_no_numba():
    """The compiled kernel is loaded on the first grip, never at import (the CLI's start-up stays short)."""
    code = "import sys, grasptwist, grasptwist.cli; assert 'numba' not in sys.modules, 'numba imported'"
    assert subprocess.run([sys.executable, "-c", code], capture_output=True, text=True).returncode == 0
    # GRASPTWIST_NUMBA=0: the numpy path, numba never loaded even by a grip
    code = "import sys, grasptwist as gt; gt.grip(*{args}); assert 'numba' not in sys.modules, 'numba imported'"
    args = (EQ.tolist(), (-EQ).tolist(), [0, 0, 1, 0, 0, 0], 0.5)
    env = dict(os.environ, GRASPTWIST_NUMBA="0")
    done = subprocess.run([sys.executable, "-c", code.format(args=args)], capture_output=True, text=True, env=env)
    assert done.returncode == 0, done.stderr


@pytest.mark.parametrize(("torsion", "what"), [(None, "grip"), (0.01, "iteration")])  # kernel(), iteration()
def test_a_numba_that_cannot_load_the_kernel_leaves_the_numpy_path_with_a_warning(torsion, what, monkeypatch):
    import grasptwist.engine.forces as package

    monkeypatch.setitem(sys.modules, "grasptwist.engine.forces.kernel", None)  # the import fails
    monkeypatch.delattr(package, "kernel", raising=False)  # (as it does where numba was never loaded)
    monkeypatch.setattr(compiled, "_state", {"on": True, "module": None})
    monkeypatch.setattr(importlib.util, "find_spec", lambda name: object())  # as if numba were installed
    with pytest.warns(UserWarning, match=rf"^the compiled {what} is unavailable \(.*\); the numpy path is used$"):
        g = gt.grip(EQ, -EQ, [0, 0, G, 0, 0, 0], 0.5, torsion=torsion)
    assert g.total_normal_force == pytest.approx(G / 0.5, rel=1e-9)
    assert compiled.kernel() is None and compiled.iteration() is None


def test_iterations_that_cannot_load_leave_socp_on_the_numpy_path_with_a_warning(monkeypatch):
    """compiled.iteration (socp's iterations compiled, at their first use) that fails to compile or load: one
    warning, then the numpy twin for the process, the same grip."""

    def fails(*args):
        raise OSError("no directory numba may cache in")

    module = types.SimpleNamespace(iterate_rows=fails, polish_rows=fails)
    monkeypatch.setattr(compiled, "_state", {"on": True, "module": module, "grip": True})
    monkeypatch.setattr(importlib.util, "find_spec", lambda name: object())  # as if numba were installed
    with pytest.warns(UserWarning, match=r"^the compiled iteration is unavailable \(.*\); the numpy path is used$"):
        g = gt.grip(EQ, -EQ, [0, 0, G, 0, 0, 0], 0.5, torsion=0.01)
    assert float(g.total_normal_force) == pytest.approx(G / 0.5, rel=1e-9)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert compiled.iteration() is None and compiled.kernel() is module


def test_socps_compiled_iterations_load_once_inside_the_first_load_watch(monkeypatch):
    """A fresh install compiles socp's iterations (some 20 s) at their first use: inside hooks.first_load (the
    command line's notice), once a process, and apart from the grip's kernel (a soft grip alone never compiles
    it); later calls go straight to the compiled functions."""
    from grasptwist.engine import hooks
    from grasptwist.engine.forces import socp

    watched, calls = [], []

    @contextlib.contextmanager
    def watch():
        watched.append("open")
        yield
        watched.append("closed")

    module = types.SimpleNamespace(
        iterate_rows=lambda *a: calls.append(("iterate", watched[-1])),
        polish_rows=lambda *a: calls.append(("polish", watched[-1])),
    )
    state = {"on": True, "module": module}  # the kernel's module imported, its grip not loaded
    monkeypatch.setattr(compiled, "_state", state)
    monkeypatch.setattr(importlib.util, "find_spec", lambda name: object())  # as if numba were installed
    A, b = np.zeros((2, 1, 3, 1)), np.ones((2, 1, 3))
    with hooks.watching_first_load(watch):
        socp.phase_one(A, b)
        socp.minimise(A, b, np.ones((2, 1)), np.zeros((2, 1)))
    assert watched == ["open", "closed"] and "grip" not in state
    assert calls == [("iterate", "open"), ("polish", "open"), ("iterate", "closed"), ("iterate", "closed")]


def test_a_first_load_inside_another_runs_in_the_outer_watch_alone():
    """A search's warm-up loads the grip's kernel and socp's iterations (each its own first load) inside one
    first load: one watch, so the command line says once that it compiles; after it, a first load watches anew."""
    from grasptwist.engine import hooks

    opened = []

    @contextlib.contextmanager
    def watch():
        opened.append(len(opened))
        yield

    with hooks.watching_first_load(watch):
        with hooks.first_load():
            with hooks.first_load():
                pass
            with hooks.first_load():
                pass
        assert opened == [0]
        with hooks.first_load():
            pass
    assert opened == [0, 1]


def test_an_infinite_wrench_beside_a_huge_one_keeps_its_status_and_the_huge_one_is_solved():
    """wrench_scales leaves an infinite row unscaled (once, as the grip recursed on it forever)."""
    g = gt.grip(EQ, -EQ, [[0, 0, np.inf, 0, 0, 0], [0, 0, G * 1e300, 0, 0, 0]], 0.5)
    assert g.status.tolist() == [gt.forces.Status.NONFINITE_INPUT, 0]
    assert g.total_normal_force[1] == pytest.approx(2 * G * 1e300, rel=1e-9)


@pytest.mark.parametrize("batch", [(0,), (2, 0)])
def test_an_empty_batch_grips_to_empty_fields(batch):
    g = gt.grip(np.zeros(batch + (3, 3)), np.zeros(batch + (3, 3)), np.zeros(batch + (6,)), 0.5)
    assert g.status.shape == g.total_normal_force.shape == batch
    assert g.force.shape == batch + (3, 3) and g.dual.shape == batch + (6,)
    hand = gt.prepare_grip(EQ, -EQ, 0.5)  # and a prepared grasp's (issue 36: it indexed a first row)
    g = hand.grip(np.zeros(batch + (6,)))
    assert g.status.shape == g.total_normal_force.shape == batch and g.force.shape == batch + (3, 3)


@pytest.mark.parametrize("length", [1e-200, 1e-150, 1e-30, 1.0, 1e30, 1e150, 1e200, 1e300])
def test_the_grip_and_closure_answer_the_same_for_normals_of_any_finite_length(length, grip_path):
    """Issue 35: normals of length 1e200 overflowed their squares (unit normals of zero: cannot-hold for a grasp
    that holds at G / mu); 1e-200 underflowed them (zero-normal).  Scaled by a power of two first, every length
    gives the same grip (to the rounding of ``length * n``; to the last bit for a power of two)."""
    w = [0, 0, G, 0, 0, 0]
    tilted = TRIPOD_N * np.array([[1.0], [3.0], [0.5]])  # lengths differing by contact too
    with compiled.numpy_path():
        reference = gt.grip(TRIPOD, tilted, w, 0.7)
        assert (gt.grip(TRIPOD, 2.0**-700 * tilted, w, 0.7).force == reference.force).all()
    g = gt.grip(TRIPOD, length * tilted, w, 0.7)
    assert g.ok and float(g.total_normal_force) == pytest.approx(float(reference.total_normal_force), rel=1e-12)
    np.testing.assert_allclose(g.force, reference.force, rtol=1e-9, atol=1e-12)
    hand = gt.prepare_grip(TRIPOD, length * tilted, 0.7)
    assert float(hand.grip(w).total_normal_force) == pytest.approx(float(reference.total_normal_force), rel=1e-12)
    c = gt.forces.force_closure(TRIPOD, length * tilted, 0.7)
    assert bool(c.force_closure) and float(c.closure_friction) == pytest.approx(0.4663, abs=1e-4)


def test_nan_normals_are_nonfinite_input_and_a_zero_one_beside_finite_ones_zero_normal(grip_path):
    """Issue 36: NaN normals read as zero-normal in the grip and force_closure (the twist methods say nonfinite)."""
    n = np.stack((-EQ, -EQ, -EQ, -EQ))
    n[0, 1, 2] = np.nan
    n[1, 2] = np.inf
    n[2, 0] = 0.0
    g = gt.grip(EQ, n, [0, 0, G, 0, 0, 0], 0.5)
    c = gt.forces.force_closure(EQ, n, 0.5)
    code = gt.forces.Status
    expected = [code.NONFINITE_INPUT, code.NONFINITE_INPUT, code.ZERO_NORMAL, 0]
    assert g.status.tolist() == c.status.tolist() == expected
    assert g.culprit[2] == c.culprit[2] == 0
    assert int(gt.prepare_grip(EQ, n[0], 0.5).grip([0, 0, G, 0, 0, 0]).status) == code.NONFINITE_INPUT


def _turned(angle):
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]]) @ np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


@pytest.mark.parametrize("mu", [0.5, np.inf])
def test_a_finger_pressing_across_the_contacts_plane_needs_pulling_in_any_frame(grip_path, mu):
    """A review: contact 0 presses along the contacts' plane's normal, and the wrench pulls the object off it,
    which no pushing forces make.  Axis-aligned that contact's normal row is exactly 0; turned it was 1e-16,
    and the pulling test called it regular (culprit 0, "cone too narrow"; the two paths disagreed once they
    shared the test, by round-off).  set_up.cone_rows takes such round-off as the 0 it is: -1 in every frame,
    and on 20 random turned grasps of that kind the verdicts and least totals of scipy's linear programme (with
    infinite friction; four rows had been "ok" with squeezes of 1e15 that miss the wrench)."""
    up = np.array([0, 0, 1.0])
    for rot in (np.eye(3), _turned(0.7), _turned(2.1)):
        p = EQ @ rot.T
        n = np.array([up, -EQ[1], -EQ[2]]) @ rot.T
        g = gt.grip(p, n, np.r_[-(rot @ up), 0, 0, 0], mu)
        assert (int(g.status), int(g.culprit)) == (gt.forces.Status.CANNOT_HOLD, -1)
    if mu < np.inf:
        return
    linprog = pytest.importorskip("scipy.optimize").linprog
    rng = np.random.default_rng(5)
    held = 0
    for _ in range(20):
        rot = _turned(rng.uniform(0, 6))
        p = (EQ + rng.normal(0, 0.1, (3, 3))) @ rot.T
        n = np.array([np.cross(p[1] - p[0], p[2] - p[0]), -p[1], -p[2]])
        u, w = n / np.linalg.norm(n, axis=1)[:, None], rng.normal(size=6)
        g = gt.grip(p, n, w, mu)
        G = np.concatenate([np.vstack((np.eye(3), np.cross(q, np.eye(3)).T)) for q in p], axis=1)  # f -> (f; p x f)
        pushing = np.kron(np.eye(3), np.ones((1, 3))) * -np.concatenate(u)  # -n_i . f_i <= 0
        lp = linprog(np.concatenate(u), A_ub=pushing, b_ub=np.zeros(3), A_eq=G, b_eq=w, bounds=[(None, None)] * 9)
        assert (int(g.status) == 0) == (lp.status == 0)
        if lp.status == 0:
            held += 1
            assert float(g.total_normal_force) == pytest.approx(lp.fun, rel=1e-6, abs=1e-9)
    assert 5 <= held <= 15


@pytest.mark.parametrize("rows", [3, 300, 600])
def test_the_closure_bisection_takes_the_same_halvings_four_at_a_time(rows):
    """closure._least_friction takes four halvings a round for up to 128 rows to bisect (one closure test of the 15
    midpoints they could test): the same brackets, bit for bit, as one halving at a time, which it does above."""
    from grasptwist.engine.forces import closure

    rng = np.random.default_rng(rows)
    angle = rng.uniform(0, 2 * np.pi, (rows, 1)) + np.array([0, 2.1, 4.2]) + rng.normal(0, 0.3, (rows, 3))
    p = np.stack((np.cos(angle), np.sin(angle), rng.normal(0, 0.3, (rows, 3))), axis=-1)
    n = -p + rng.normal(0, 0.3, (rows, 3, 3))
    from grasptwist.engine.forces.grasp_map import geometry, unit_normals

    plane = closure._Plane(p, unit_normals(n)[0], geometry(p))
    lo, top = plane.phi.max(axis=1), np.full(rows, np.arctan(closure.MAX_FRICTION))
    one = np.flatnonzero(closure._at_theta(plane, top) & ~closure._at_theta(plane, lo + 1e-9))
    a, b = lo[one], top[one]
    for _ in range(closure.BISECTIONS):  # the halvings one at a time, as before
        mid = 0.5 * (a + b)
        ok = closure._at_theta(closure._subset(plane, one), mid)
        a, b = np.where(ok, a, mid), np.where(ok, mid, b)
    least = closure._least_friction(plane)
    assert one.size > 0 and (one.size > closure._FEW) == (rows == 600)
    np.testing.assert_array_equal(least[one], np.tan(b))


def test_a_nan_friction_is_nonfinite_input_in_force_closure_as_in_the_grip():
    """A trial: force_closure with a NaN friction had said ok, closure friction 0 and no closure, where the grip says
    nonfinite-input; with point contacts and soft ones, one NaN of three frictions or all."""
    mu = np.array([[np.nan, 0.5, 0.5], [np.nan] * 3, [0.5] * 3])
    code = gt.forces.Status.NONFINITE_INPUT
    for torsion in (None, 0.01):
        c = gt.forces.force_closure(EQ, -EQ, mu, torsion=torsion)
        g = gt.grip(EQ, -EQ, [0, 0, G, 0, 0, 0], mu, torsion=torsion)
        assert c.status.tolist() == g.status.tolist() == [code, code, 0]
        assert np.isnan(c.closure_friction[:2]).all() and not c.force_closure[:2].any() and c.force_closure[2]
    # collinear contacts, whose soft closure is judged apart (a review: it had been ok, closure friction 1e-6)
    line = np.array([[-1.0, 0, 0], [0, 0, 0], [1, 0, 0]])
    c = gt.forces.force_closure(line, [[1.0, 0, 0], [0, 1, 0], [-1, 0, 0]], [np.nan, 0.5, 0.5], torsion=0.01)
    assert int(c.status) == code and np.isnan(c.closure_friction)


def _kernel_as_python():
    """engine/forces/kernel.py's own source run by Python and numpy: numba replaced by a stub whose ``njit``
    returns the function it is given (as ``NUMBA_DISABLE_JIT`` would, without loading numba)."""
    import importlib.util
    import types

    import grasptwist.engine.forces as package

    stub = types.ModuleType("numba")
    stub.njit = lambda *args, **kwargs: args[0] if args and callable(args[0]) else (lambda f: f)
    stub.literally = lambda value: value
    saved = sys.modules.get("numba")
    sys.modules["numba"] = stub
    try:
        path = os.path.join(package.__path__[0], "kernel.py")
        spec = importlib.util.spec_from_file_location("grasptwist.engine.forces._kernel_as_python", path)
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
    finally:
        if saved is None:
            del sys.modules["numba"]
        else:
            sys.modules["numba"] = saved
    return module


def _edge_rows():
    """Grips on the cones' edge (no internal force strictly inside every cone): a weight whose line passes
    through two fingers' line (the third bare), the same on a tilted grasp and with the normals leant along
    x (the squeeze between the two moves no normal force: a flat total, the centre), a push along one finger
    (two bare).  No normal lies in the contacts' plane (Python's 0 / 0 in the kernel's source)."""
    up = np.array([[0, 0, 1.0]] * 3) - 0.2 * EQ
    p = np.stack((0.05 * EQ, 0.05 * EQ + [0.01, 0.02, 0.3], 0.05 * EQ, EQ))
    n = np.stack((up, up + [[0.1, 0, 0], [0, 0.1, 0], [0, 0, 0]], [[0.2, 0, 1.0]] * 3, up))
    lines = ((p[0, 1] + p[0, 2]) / 2, (p[1, 0] + p[1, 1]) / 2, (p[2, 1] + p[2, 2]) / 2)
    w = [np.concatenate(([0, 0, 9.81], np.cross(c, [0, 0, 9.81]))) for c in lines]
    w.append(np.concatenate((n[3, 2], np.cross(p[3, 2], n[3, 2]))))
    return p, n, np.array(w), np.full((4, 3), 0.7)


def test_the_compiled_grips_source_follows_the_numpy_path_in_the_default_run():
    """Issue 39, item 8: the kernel numba compiles (the path every [fast] install takes) held to the numpy path
    without a compile: its own source, run as Python, on held and cannot-hold rows, a row it leaves to numpy (a
    NaN wrench) and a row with no wrench; the same verdicts and culprits, totals to 1e-9 (the slow tests compile
    it; Python's floats raise on 0 / 0 where numba's error model gives NaN, so no degenerate row here)."""
    kernel = _kernel_as_python()
    p, n, w, mu = (np.concatenate(pair) for pair in zip(grasps(10, 19), _edge_rows()))
    w[0, 2] = np.nan
    w[1] = 0.0
    limit = np.ascontiguousarray(np.broadcast_to(mu / 1.3, (14, 3)))
    out, codes = np.empty((14, kernel.WIDTH)), np.empty((14, 3), np.int8)
    with np.errstate(all="ignore"):  # numba's error model is numpy's: a 0 / 0 is NaN, quietly
        kernel.grip_rows(p, n, limit, w, 1e-9, out, codes)
    with compiled.numpy_path():
        reference = gt.grip(p, n, w, mu, safety=1.3)
    plain = codes[:, 2] == 1
    assert plain.tolist() == [False] + [True] * 13  # the NaN row goes to numpy; the edge's rows are the kernel's
    assert (codes[plain, 0] == reference.status[plain]).all() and (codes[plain, 1] == reference.culprit[plain]).all()
    assert 2 <= reference.ok[plain].sum() <= 10 and reference.ok[10:].all()
    # the edge's facial reduction in closed form, the same as numpy's: its multipliers too
    np.testing.assert_allclose(out[10:, kernel._DUAL : kernel._DUAL + 6], reference.dual[10:], rtol=1e-9, atol=1e-12)
    assert (np.abs(out[10:, kernel._GAP]) < 1e-9 * out[10:, kernel._TOTAL]).all()
    total = out[:, kernel._TOTAL]
    np.testing.assert_allclose(total[plain], reference.total_normal_force[plain], rtol=1e-9, atol=0)
    forces = out[:, kernel._F : kernel._F + 9].reshape(-1, 3, 3)
    held = plain & reference.ok
    np.testing.assert_allclose(forces[held], reference.force[held], rtol=1e-6, atol=1e-6)


def test_the_compiled_iterations_source_follows_the_numpy_twin_on_soft_rows(monkeypatch):
    """Issue 39, item 1: where numba is on, socp's iterations (the soft contacts' phase I, phase II, dual polish
    and the rays' phase I for a culprit; the soft closure's phase I) run in kernel.iterate_rows and
    kernel.polish_rows.  Their own source run as Python, held to socp's numpy twin without a compile: soft,
    point and frictionless contacts mixed (other numbers of unknowns), held and cannot-hold rows, the same
    verdicts and culprits, forces, torsions, duals and certificates to 1e-12."""
    kernel = _kernel_as_python()
    calls = []
    iterate, polish = kernel.iterate_rows, kernel.polish_rows
    monkeypatch.setattr(kernel, "iterate_rows", lambda *a: calls.append(a[0].shape[1:]) or iterate(*a))
    monkeypatch.setattr(kernel, "polish_rows", lambda *a: calls.append("polish") or polish(*a))
    p, n, w, mu = grasps(6, 3)
    e = np.array([[0.01, 0.01, 0.01], [0.02, 0.0, 0.01], [0.0, 0.0, 0.05]] * 2)
    mu[2, 0] = 0.0  # a frictionless contact beside a soft one
    with compiled.numpy_path():
        reference = gt.grip(p, n, w, mu, safety=1.3, torsion=e)
        closure = gt.forces.force_closure(p[:2], n[:2], torsion=e[:2]).closure_friction
    monkeypatch.setattr(compiled, "_state", {"on": True, "module": kernel, "iteration": True})
    with np.errstate(all="ignore"):  # numba's error model is numpy's: a 0 / 0 is NaN, quietly
        g = gt.grip(p, n, w, mu, safety=1.3, torsion=e)
        # (K, k, d): all-soft phase I and II, a point contact's fewer unknowns, the rays' phase I (k = 1)
        assert {(4, 4, 7), (3, 4, 6), (3, 4, 5), (4, 1, 5), "polish"} <= set(calls)
        calls.clear()
        np.testing.assert_allclose(gt.forces.force_closure(p[:2], n[:2], torsion=e[:2]).closure_friction, closure)
        assert calls
    assert g.status.tolist() == reference.status.tolist() and g.culprit.tolist() == reference.culprit.tolist()
    assert 2 <= g.ok.sum() <= 4 and g.culprit[~g.ok].min() >= 0
    scale = np.abs(w).max()
    for name in ("force", "torsion", "total_normal_force", "dual", "certificate", "gap"):
        np.testing.assert_allclose(getattr(g, name), getattr(reference, name), rtol=1e-12, atol=1e-12 * scale)


def test_epsilon_without_scipy_says_how_to_install_it(monkeypatch):
    """A trial's finding: quality=True without scipy had raised a bare ModuleNotFoundError."""
    from grasptwist import extras

    found = extras.import_module
    monkeypatch.setattr(extras, "import_module", lambda name: _hidden(name, found))
    with pytest.raises(extras.MissingExtra, match=r"epsilon .* needs scipy: pip install scipy .*'\.\[quality\]'"):
        gt.forces.force_closure(EQ, -EQ, 0.5, quality=True)


def _hidden(name, found):
    if name.partition(".")[0] == "scipy":
        raise ImportError("No module named 'scipy'")
    return found(name)
