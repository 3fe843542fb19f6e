"""Soft-finger contacts (issue 39): ``|(f_t, tau_n / e)| <= mu f_n``, over the contacts' cones
(engine/forces/cones.py), held to Clarabel on the same conic programme (tests/conic.py)."""

import warnings

import numpy as np
import pytest

import grasptwist as gt
from conic import least_soft_grip
from grasptwist.engine.forces import compiled
from grasptwist.engine.forces.grasp_map import check_torsion

EQ = np.array([[1, 0, 0], [-0.5, 0.75**0.5, 0], [-0.5, -(0.75**0.5), 0]])
LINE = np.array([[-0.05, 0, 0], [0.05, 0, 0], [0, 0, 0.0]])  # three contacts on the x axis
ACROSS = np.array([[1, 0, 0], [-1, 0, 0], [0, 0, 1.0]])  # two pinch along the line, the third pushes up


def grasps(n, seed):
    """Three contacts near a unit ball's equator, tilted normals, a few newtons and newton-metres, and
    torsional radii up to 0.3 (a fifth of them 0: soft and point contacts mixed)."""
    rng = np.random.default_rng(seed)
    angle = rng.uniform(0, 2 * np.pi, (n, 1)) + np.array([0, 2.1, 4.2]) + rng.normal(0, 0.3, (n, 3))
    p = np.stack((np.cos(angle), np.sin(angle), rng.normal(0, 0.3, (n, 3))), axis=-1)
    normals = -p + rng.normal(0, 0.35, (n, 3, 3))
    wrench = np.concatenate((rng.normal(0, 5, (n, 3)), rng.normal(0, 1, (n, 3))), axis=1)
    friction = rng.uniform(0.3, 1.2, (n, 3))
    torsion = rng.uniform(0, 0.3, (n, 3)) * (rng.uniform(size=(n, 3)) < 0.8)
    return p, normals, wrench, friction, torsion


def _dual_cone_excess(p, n, e, limit, v_f, v_tau):
    """``limit |(v_t, e v_tau)| - v_n`` per contact (``<= 0``: in the soft cone's dual)."""
    unit = n / np.linalg.norm(n, axis=-1, keepdims=True)
    vn = np.einsum("...ix,...ix->...i", v_f, unit)
    vt = v_f - vn[..., None] * unit
    return limit * np.sqrt((vt**2).sum(axis=-1) + (e * v_tau) ** 2) - vn


def _field(lam, p, n):
    """``G_i^T lambda``: ``(lambda_F + lambda_M x p_i, n_i . lambda_M)`` for each contact."""
    unit = n / np.linalg.norm(n, axis=-1, keepdims=True)
    forces = lam[..., None, :3] + np.cross(lam[..., None, 3:], p)
    return forces, np.einsum("...ix,...x->...i", unit, lam[..., 3:])


def test_check_torsion():
    assert check_torsion(0.01).tolist() == 0.01
    for bad, message in ((-1, "finite length >= 0"), (np.inf, "finite length >= 0"), ([[0.1, 0.1]], "one per contact")):
        with pytest.raises(ValueError, match=message):
            check_torsion(bad)


@pytest.mark.parametrize("path", ["numpy", pytest.param("compiled", marks=pytest.mark.slow)])
def test_zero_torsion_is_point_contacts_bit_for_bit(path, monkeypatch):
    p, n, w, mu, _ = grasps(200, 41)
    if path == "compiled":
        pytest.importorskip("numba")
        monkeypatch.setitem(compiled._state, "on", True)
    point = gt.grip(p, n, w, mu, safety=1.2)
    zero = gt.grip(p, n, w, mu, safety=1.2, torsion=0.0)
    assert point.torsion is None and (zero.torsion[zero.ok] == 0).all() and np.isnan(zero.torsion[~zero.ok]).all()
    assert 0.3 < point.ok.mean() < 0.95
    np.testing.assert_array_equal(zero.status, point.status)
    if path == "compiled":  # the same code on the same rows, but once, after a long slow run, the two calls
        # differed as the compiled and numpy paths do (forces in the 8th digit): held here to that contract
        np.testing.assert_allclose(zero.total_normal_force, point.total_normal_force, rtol=1e-9)
        np.testing.assert_allclose(zero.force, point.force, rtol=1e-6, atol=1e-6 * np.nanmax(np.abs(point.force)))
        return
    for name in ("force", "squeeze", "total_normal_force", "friction_used", "dual", "gap", "certificate"):
        np.testing.assert_array_equal(getattr(zero, name), getattr(point, name))


@pytest.mark.parametrize("count", [100, pytest.param(1000, marks=pytest.mark.slow)])
def test_soft_grips_equal_clarabels_and_their_certificates_verify(count):
    """Random grasps, soft and point contacts mixed: the verdict and the total to 1e-6 of Clarabel's on the same
    programme; every held row's dual puts each ``(n_i, 0) - G_i^T lambda`` in its dual cone with the gap closed,
    every cannot-hold row's ``y`` has ``y . w > 0`` and ``-G_i^T y`` in every dual cone (Farkas)."""
    p, n, w, mu, e = grasps(count, 43)
    with compiled.numpy_path():
        g = gt.grip(p, n, w, mu, safety=1.3, torsion=e)
    refs = [least_soft_grip(p[i], n[i], w[i], mu[i], e[i], 1.3)[0] for i in range(count)]
    decided = np.array([r is None or r == r for r in refs])  # Clarabel's numerical errors: the certificates below
    assert decided.mean() >= 0.99
    held = g.ok
    clarabel_held = np.array([r is not None for r in refs])
    assert (held == clarabel_held)[decided].all() and 0.3 < held.mean() < 0.95
    both = held & decided
    np.testing.assert_allclose(g.total_normal_force[both], np.array([refs[i] for i in np.flatnonzero(both)]), rtol=1e-6)
    # the forces and torsions make the wrench, within their cones
    made = np.concatenate(
        (
            g.force.sum(axis=1),
            (np.cross(p, g.force) + g.torsion[..., None] * n / np.linalg.norm(n, axis=-1)[..., None]).sum(axis=1),
        ),
        axis=1,
    )
    np.testing.assert_allclose(made[held], w[held], atol=1e-8 * np.abs(w).max())
    assert (g.friction_used[held] <= mu[held] / 1.3 * (1 + 1e-7)).all()
    forces, torsions = _field(g.dual, p, n)
    unit = n / np.linalg.norm(n, axis=-1, keepdims=True)
    total = g.total_normal_force[held]
    excess = _dual_cone_excess(p, n, e, mu / 1.3, unit - forces, -torsions)[held]
    assert (excess <= 1e-6 * total[:, None]).all()  # as the point contacts' (test_forces.py)
    assert np.median(np.abs(g.gap[held]) / total) < 1e-9 and (np.abs(g.gap[held]) <= 1e-4 * total).all()
    y = g.certificate[~held]
    forces, torsions = _field(y, p[~held], n[~held])
    assert (np.einsum("ni,ni->n", y, w[~held]) > 0).all()
    assert (_dual_cone_excess(p[~held], n[~held], e[~held], mu[~held] / 1.3, -forces, -torsions) <= 1e-6).all()


def test_two_soft_contacts_resist_a_moment_about_their_line_that_point_contacts_cannot():
    """Three contacts on a line (two pinching along it, one pushing up): point contacts exert no moment about the
    line (collinear-contacts); soft pinching fingers twist about their normals, which lie along it."""
    w = [0, 0, 1.0, 0.004, 0, 0]  # lift 1 N, turn 4 mN m about the x axis
    with compiled.numpy_path():
        point = gt.grip(LINE, ACROSS, w, 0.5)
        soft = gt.grip(LINE, ACROSS, w, 0.5, torsion=[0.01, 0.01, 0])
    assert int(point.status) == gt.forces.Status.COLLINEAR_CONTACTS
    assert point.certificate @ w > 0
    reference, forces, torsions = least_soft_grip(LINE, ACROSS, w, 0.5, [0.01, 0.01, 0])
    assert soft.ok and float(soft.total_normal_force) == pytest.approx(reference, rel=1e-6)
    np.testing.assert_allclose(soft.torsion, torsions, atol=1e-6)
    assert soft.torsion[0] - soft.torsion[1] == pytest.approx(0.004, rel=1e-9)  # tau n about x, n_1 = -x
    assert soft.torsion[2] == 0.0
    # a wider twist needs a harder pinch: |tau| <= e mu f_n at each pinching finger
    assert soft.normal_force[0] * 0.01 * 0.5 >= abs(soft.torsion[0]) * (1 - 1e-9)


def test_a_prepared_grasp_with_soft_contacts_grips_as_grip_does():
    w = [[0, 0, 1.0, 0.004, 0, 0], [0, 0, 1.0, -0.002, 0, 0]]
    hand = gt.prepare_grip(LINE, ACROSS, 0.5, torsion=[0.01, 0.01, 0])
    with compiled.numpy_path():
        g = gt.grip(LINE, ACROSS, w, 0.5, torsion=[0.01, 0.01, 0])
        np.testing.assert_array_equal(hand.grip(w).total_normal_force, g.total_normal_force)
    assert float(hand.grip(w[0]).total_normal_force) == float(g.total_normal_force[0]) and g.ok.all()
    with pytest.raises(ValueError, match=r"torsion a scalar or \(3,\)"):
        gt.prepare_grip(LINE, ACROSS, 0.5, torsion=[[0.01] * 3] * 2)


def test_odd_rows_with_soft_contacts_get_statuses_never_warnings():
    """Wrenches near 1e300 and 1e-200 solved scaled (the grip is homogeneous in the wrench), an empty batch,
    NaN torsion or wrench, coincident contacts, a frictionless contact beside soft ones, infinite friction."""
    w = np.array([0, 0, 9.81, 0, 0, 0.981])
    with compiled.numpy_path(), warnings.catch_warnings():
        warnings.simplefilter("error")
        scaled = gt.grip(EQ, -EQ, [w * 1e300 / 9.81, w * 1e-200, w], 0.5, torsion=0.01)
        empty = gt.grip(np.zeros((2, 0, 3, 3)), np.zeros((2, 0, 3, 3)), np.zeros((2, 0, 6)), 0.5, torsion=0.01)
        p = np.stack([EQ] * 5)
        p[2, 1] = p[2, 0]
        odd = gt.grip(
            p,
            -EQ,
            [w, [0, 0, np.nan, 0, 0, 0], w, w, w],
            [[0.5] * 3, [0.5] * 3, [0.5] * 3, [0, 0.5, 0.5], [np.inf] * 3],
            torsion=[[np.nan, 0.01, 0.01]] + [[0.01] * 3] * 4,
        )
    assert scaled.ok.all()
    np.testing.assert_allclose(
        scaled.total_normal_force / [1e300 / 9.81, 1e-200, 1], scaled.total_normal_force[2], rtol=1e-9
    )
    assert empty.status.shape == (2, 0) and empty.torsion.shape == (2, 0, 3)
    code = gt.forces.Status
    assert odd.status.tolist() == [code.NONFINITE_INPUT, code.NONFINITE_INPUT, code.COINCIDENT_CONTACTS, 0, 0]
    assert odd.torsion[3, 0] == 0 and abs(odd.force[3, 0] @ [1, 0, 0]) == pytest.approx(np.linalg.norm(odd.force[3, 0]))
    assert float(odd.total_normal_force[4]) == pytest.approx(0, abs=1e-9)  # no limit: friction alone holds it
