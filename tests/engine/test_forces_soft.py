"""Soft-finger contacts (issue 39): ``|(f_t, tau_n / e)| <= mu f_n``, over the contacts' cones
(engine/forces/cones.py), held to Clarabel on the same conic programme (tests/conic.py)."""

import contextlib
import warnings

import numpy as np
import pytest

import grasptwist as gt
from conic import closure_friction as clarabel_closure_friction
from conic import closure_margin, least_soft_grip, soft_grasp_map
from grasptwist.engine.forces import compiled
from grasptwist.engine.forces.closure import epsilon_quality
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
    # a prepared grasp with torsion 0 takes the point contacts' way too (it had set up the cones at every call)
    for k in np.flatnonzero(point.ok)[:2].tolist() + np.flatnonzero(~point.ok)[:1].tolist():
        prepared = gt.prepare_grip(p[k], n[k], mu[k], safety=1.2, torsion=0.0)
        g, alone = prepared.grip(w[k]), gt.prepare_grip(p[k], n[k], mu[k], safety=1.2).grip(w[k])
        assert not prepared._soft and bool(g.ok) == point.ok[k]
        np.testing.assert_array_equal(g.torsion, np.zeros(3) if g.ok else np.full(3, np.nan))
        for name in ("force", "total_normal_force", "dual", "certificate", "status"):
            np.testing.assert_array_equal(getattr(g, name), getattr(alone, name))


def _on(path, monkeypatch):
    """The grip's numpy path, or the compiled one (numba, which conftest.py switches off for the default run)."""
    if path == "numpy":
        return compiled.numpy_path()
    pytest.importorskip("numba")
    monkeypatch.setitem(compiled._state, "on", True)
    return contextlib.nullcontext()


# over a second: numba compiles the kernel and socp's iterations once per process where its cache is cold
PATHS = [(100, "numpy"), pytest.param(1000, "numpy", marks=pytest.mark.slow)]
PATHS.append(pytest.param(1000, "compiled", marks=pytest.mark.slow))


@pytest.mark.parametrize(("count", "path"), PATHS)
def test_soft_grips_equal_clarabels_and_their_certificates_verify(count, path, monkeypatch):
    """Random grasps, soft and point contacts mixed: the verdict and the total to 1e-6 of Clarabel's on the same
    programme; every held row's dual puts each ``(n_i, 0) - G_i^T lambda`` in its dual cone with the gap closed,
    every cannot-hold row's ``y`` has ``y . w > 0`` and ``-G_i^T y`` in every dual cone (Farkas)."""
    p, n, w, mu, e = grasps(count, 43)
    with _on(path, monkeypatch):
        g = gt.grip(p, n, w, mu, safety=1.3, torsion=e)
    refs = [least_soft_grip(p[i], n[i], w[i], mu[i], e[i], 1.3)[0] for i in range(count)]
    decided = np.array([r is None or r == r for r in refs])  # Clarabel's numerical errors: the certificates below
    assert decided.mean() >= 0.99
    held = g.ok
    clarabel_held = np.array([r is not None for r in refs])
    assert (held == clarabel_held)[decided].all() and 0.3 < held.mean() < 0.95
    both = held & decided
    np.testing.assert_allclose(g.total_normal_force[both], np.array([refs[i] for i in np.flatnonzero(both)]), rtol=1e-6)
    _verified(g, p, n, w, mu / 1.3, e)


def _verified(g, p, n, w, limit, e):
    """The grip's forces and torsions make the wrench within their cones, its dual and certificates verify."""
    held = g.ok
    made = np.concatenate(
        (
            g.force.sum(axis=1),
            (np.cross(p, g.force) + g.torsion[..., None] * n / np.linalg.norm(n, axis=-1)[..., None]).sum(axis=1),
        ),
        axis=1,
    )
    np.testing.assert_allclose(made[held], w[held], atol=1e-8 * np.abs(w).max())
    assert (g.friction_used[held] <= limit[held] * (1 + 1e-7)).all()
    forces, torsions = _field(g.dual, p, n)
    unit = n / np.linalg.norm(n, axis=-1, keepdims=True)
    total = g.total_normal_force[held]
    excess = _dual_cone_excess(p, n, e, limit, unit - forces, -torsions)[held]
    assert (excess <= 1e-6 * total[:, None]).all()  # as the point contacts' (test_forces.py)
    assert np.median(np.abs(g.gap[held]) / total) < 1e-9 and (np.abs(g.gap[held]) <= 1e-4 * total).all()
    y = g.certificate[~held]
    forces, torsions = _field(y, p[~held], n[~held])
    assert (np.einsum("ni,ni->n", y, w[~held]) > 0).all()
    assert (_dual_cone_excess(p[~held], n[~held], e[~held], limit[~held], -forces, -torsions) <= 1e-6).all()


@pytest.mark.slow  # over a second: numba compiles the kernel and socp's iterations once per process (cold cache)
def test_the_compiled_soft_grip_follows_the_numpy_path(monkeypatch):
    """Issue 39, item 1: where numba is on, the soft rows' iterations run compiled (kernel.iterate_rows,
    kernel.polish_rows): on 300 random grasps, soft and point contacts mixed, the same verdicts and culprits
    as the numpy path, totals to 1e-9, and its duals and certificates verify."""
    p, n, w, mu, e = grasps(300, 47)
    with compiled.numpy_path():
        reference = gt.grip(p, n, w, mu, safety=1.3, torsion=e)
    with _on("compiled", monkeypatch):
        g = gt.grip(p, n, w, mu, safety=1.3, torsion=e)
        assert compiled.iteration() is not None
    assert (g.status == reference.status).all() and (g.culprit == reference.culprit).all()
    assert 0.3 < g.ok.mean() < 0.95 and (g.status == gt.forces.Status.CANNOT_HOLD).any()
    np.testing.assert_allclose(g.total_normal_force, reference.total_normal_force, rtol=1e-9)
    top = np.nanmax(np.abs(reference.force))
    np.testing.assert_allclose(g.force, reference.force, rtol=1e-6, atol=1e-6 * top)
    _verified(g, p, n, w, mu / 1.3, e)


BALL = 0.03 * np.stack(  # three contacts 20 deg below a 3 cm ball's equator
    [
        np.cos(np.radians(20)) * np.cos(np.radians([90, 210, 330])),
        np.cos(np.radians(20)) * np.sin(np.radians([90, 210, 330])),
        np.full(3, -np.sin(np.radians(20))),
    ],
    axis=1,
)


@pytest.mark.parametrize("e", [1e6, 1e8, 1e12])
def test_a_torsional_radius_far_above_the_grasps_size_grips_and_closes(e):
    """A soft contact's torsion column of ``B`` is ``(e / L) n``: at ``e / L`` of 3e7 and more it dwarfed the forces'
    columns, so the round-off of its size made the wrench look unmade (collinear-contacts, NaN forces, from
    ``e = 1e6``) and at 1e12 cut the rank (no closure); ``B``'s columns are now scaled to unit length first.
    The tripod's lift and turn is Clarabel's soft grip; its closure friction is the tan 20 deg of the lift, as
    with ``e = 1 cm``; a rod pinched along its axis holds a weight 1 cm beside it with both pads soft; epsilon
    grows with ``e`` towards its limit."""
    w = np.array([0, 0, 9.81, 0.01, 0, 0])
    with compiled.numpy_path():
        g = gt.grip(BALL[None], -BALL[None], w[None], 0.5, torsion=e)
        rod = gt.grip(LINE, ACROSS, [0, 0, 9.81, 0.0981, 0, 0], 0.5, torsion=[e, e, 0])
    assert g.ok.all() and rod.ok
    reference = least_soft_grip(BALL, -BALL, w, 0.5, e)[0]
    assert float(g.total_normal_force[0]) == pytest.approx(reference, rel=1e-9)
    if e < 1e12:  # the dual's e mu |n_i . lambda_M| <= n_i . (n_i - lambda_F - ...): at 1e12, below its round-off
        _verified(g, BALL[None], -BALL[None], w[None], np.full((1, 3), 0.5), np.full((1, 3), e))
    rod_reference = least_soft_grip(LINE, ACROSS, [0, 0, 9.81, 0.0981, 0, 0], 0.5, [e, e, 0])[0]
    assert float(rod.total_normal_force) == pytest.approx(rod_reference, rel=1e-9)
    assert rod.torsion[0] - rod.torsion[1] == pytest.approx(0.0981, rel=1e-9)
    c = gt.forces.force_closure([BALL, LINE], [-BALL, ACROSS], 0.5, torsion=[[e] * 3, [e, e, 0]], quality=True)
    assert c.status.tolist() == [0, 0] and c.force_closure.all()
    assert float(c.closure_friction[0]) == pytest.approx(np.tan(np.radians(20)), rel=1e-9)
    # epsilon's torsion edges are capped (closure.py): Qhull lost the hull of e = 1e12's (epsilon 0)
    assert float(c.epsilon[0]) == pytest.approx(epsilon_quality(BALL, -BALL, 0.5, torsion=1e6), rel=1e-6)
    assert float(c.epsilon[0]) > epsilon_quality(BALL, -BALL, 0.5, torsion=1e3) > 0.113


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


# --- force closure, epsilon and certificates with soft contacts -------------------------------------------


def _closure_grasps(n, seed):
    """:func:`grasps` spread wider (a third of them not closure at their own friction)."""
    p, normals, _, friction, torsion = grasps(n, seed)
    rng = np.random.default_rng(seed + 1)
    return p, normals + rng.normal(0, 0.4, normals.shape), friction, torsion


def test_zero_torsion_closure_is_point_contacts_bit_for_bit():
    """``torsion=0`` (and rows of a mixed batch without a soft contact) take the point contacts' way."""
    p, n, mu, e = _closure_grasps(16, 51)
    e[::2] = 0.0
    point = gt.forces.force_closure(p, n, mu)
    zero = gt.forces.force_closure(p, n, mu, torsion=0.0)
    mixed = gt.forces.force_closure(p, n, mu, torsion=e)
    assert 0.2 < point.force_closure.mean() < 0.9 and zero.certificate is None
    for name in ("closure_friction", "force_closure", "status", "culprit"):
        np.testing.assert_array_equal(getattr(zero, name), getattr(point, name))
        np.testing.assert_array_equal(getattr(mixed, name)[::2], getattr(point, name)[::2])
    pytest.importorskip("scipy")
    few = slice(0, 3)
    quality = gt.forces.force_closure(p[few], n[few], mu[few], quality=True)
    np.testing.assert_array_equal(
        gt.forces.force_closure(p[few], n[few], mu[few], torsion=0.0, quality=True).epsilon, quality.epsilon
    )


@pytest.mark.parametrize(("count", "path"), [(3, "numpy")] + PATHS[1:])
def test_soft_closure_friction_equals_clarabels_bisection(count, path, monkeypatch):
    """The least common friction of closure, soft and point contacts mixed, to 1e-6 of Clarabel's bisection on
    the same conic programme (with numpy's rank of the forces' and torsions' grasp map), and never above the
    point contacts' (a soft cone holds the point cone)."""
    p, n, _, e = _closure_grasps(count, 53)
    with _on(path, monkeypatch):
        soft = gt.forces.force_closure(p, n, torsion=e).closure_friction
    ref = np.array([clarabel_closure_friction(p[k], n[k], torsion=e[k]) for k in range(count)])
    assert (np.isnan(ref) == np.isnan(soft)).all() and np.isfinite(ref).mean() >= 0.6
    ok = np.isfinite(ref)
    np.testing.assert_allclose(soft[ok], ref[ok], rtol=1e-6)
    point = gt.forces.force_closure(p, n).closure_friction
    assert (soft[ok] <= point[ok] * (1 + 1e-9)).all() and (soft[ok] < point[ok] * (1 - 1e-3)).any()


@pytest.mark.parametrize(("count", "path"), [(24, "numpy")] + PATHS[1:])
def test_soft_closure_verdicts_equal_clarabels_and_their_certificates_verify(count, path, monkeypatch):
    """With each grasp's own friction: force closure where Clarabel's margin over the internal forces is positive
    (and the grasp map onto); elsewhere a certificate ``y`` that no forces within the cones reach
    (``-G_i^T y`` in every dual cone, ``y != 0``: the grasp cannot exert ``y``)."""
    p, n, mu, e = _closure_grasps(count, 55)
    with _on(path, monkeypatch):
        c = gt.forces.force_closure(p, n, mu, torsion=e, certificate=True)
    margin = np.array([closure_margin(p[k], n[k], mu[k], e[k]) for k in range(count)])
    onto = np.array([np.linalg.matrix_rank(soft_grasp_map(p[k], n[k], e[k])) == 6 for k in range(count)])
    clear = np.abs(margin) > 1e-7  # Clarabel decides: a margin of 0 is the cones' edge
    assert (c.force_closure == ((margin > 0) & onto))[clear].all() and 0.2 < c.force_closure.mean() < 0.9
    assert np.isnan(c.certificate[c.force_closure]).all()
    y = c.certificate[~c.force_closure]
    assert np.isfinite(y).all()
    forces, torsions = _field(y, p[~c.force_closure], n[~c.force_closure])
    excess = _dual_cone_excess(
        p[~c.force_closure], n[~c.force_closure], e[~c.force_closure], mu[~c.force_closure], -forces, -torsions
    )
    assert (excess <= 1e-9).all()


def test_two_soft_contacts_close_a_grasp_on_a_line_that_point_contacts_cannot():
    """Two fingers pinching a rod along its axis, a third pushing up: point contacts exert no moment about the
    line (collinear-contacts, a certificate along that moment); soft pads close with any friction, one pad
    alone too, and their epsilon (the inscribed bipyramids) is positive where the point contacts' is 0."""
    point = gt.forces.force_closure(LINE, ACROSS, 0.5, certificate=True, quality=True)
    assert int(point.status) == gt.forces.Status.COLLINEAR_CONTACTS and not point.force_closure
    np.testing.assert_allclose(point.certificate, [0, 0, 0, 20, 0, 0], atol=1e-9)  # |L y_M| = 1, L = 0.05
    assert float(point.epsilon) == 0
    for e in ([0.01, 0.01, 0], [0.01, 0, 0]):
        soft = gt.forces.force_closure(LINE, ACROSS, 0.5, torsion=e, quality=True)
        assert int(soft.status) == 0 and soft.force_closure and float(soft.closure_friction) < 1e-6
        assert float(soft.epsilon) > 0.01
    lying = gt.forces.force_closure(LINE, [[0, 0, 1]] * 3, 0.5, torsion=0.01, certificate=True)
    assert int(lying.status) == gt.forces.Status.COLLINEAR_CONTACTS  # normals across the line: no such torsion
    np.testing.assert_allclose(np.abs(lying.certificate), [0, 0, 0, 20, 0, 0], atol=1e-9)


def test_soft_epsilon_holds_the_point_contacts():
    """A soft contact's wrenches hold its point contact's, so its epsilon is never smaller; ``e = 0`` is equal."""
    pytest.importorskip("scipy")
    p, n, mu, e = _closure_grasps(8, 57)
    point = gt.forces.force_closure(p, n, mu, quality=True).epsilon
    soft = gt.forces.force_closure(p, n, mu, torsion=np.maximum(e, 0.05), quality=True).epsilon
    assert (soft >= point - 1e-12).all() and (soft > point * 1.01).any() and (point > 0).sum() >= 2


def test_odd_closure_rows_with_soft_contacts():
    """NaN torsion or friction is nonfinite-input (a friction as the grip says since a trial: it had been ok, no
    closure); a certificate needs a friction; coincident contacts keep their status."""
    p = np.stack([EQ] * 3)
    p[1, 1] = p[1, 0]
    c = gt.forces.force_closure(
        p, -EQ, [0.5, 0.5, np.nan], torsion=[[np.nan, 0.01, 0.01], [0.01] * 3, [0.01] * 3], certificate=True
    )
    code = gt.forces.Status
    assert c.status.tolist() == [code.NONFINITE_INPUT, code.COINCIDENT_CONTACTS, code.NONFINITE_INPUT]
    assert not c.force_closure.any() and np.isnan(c.certificate).all()
    with pytest.raises(ValueError, match="certificate=True needs the grasp's friction"):
        gt.forces.force_closure(EQ, -EQ, certificate=True)
    with pytest.raises(ValueError, match="torsion must be a finite length"):
        gt.forces.force_closure(EQ, -EQ, torsion=-0.01)


# --- synthesis over the soft cones ----------------------------------------------------------------------------

LATITUDE = np.radians(20)
TRIPOD = np.stack(
    [
        np.cos(LATITUDE) * np.cos(np.radians([90, 210, 330])),
        np.cos(LATITUDE) * np.sin(np.radians([90, 210, 330])),
        np.full(3, np.sin(LATITUDE)),
    ],
    axis=1,
)


def test_synthesis_scores_hold_friction_and_verification_use_the_soft_cones_when_asked():
    """Three fingers above a unit ball's equator lift it and turn it about a horizontal axis: the scores' totals are
    Clarabel's soft grips, below the point contacts'; the hold friction of the lift is the point contacts'
    (tan 20 deg); the verified grip's dual lies in the soft dual cones."""
    from grasptwist.engine.synthesis.robustness import hold_friction
    from grasptwist.engine.synthesis.scores import score_triples
    from grasptwist.engine.synthesis.verify import verified

    w = np.array([[0, 0, 9.81, 0, 0, 0], [0, 0, 9.81, 0.5, 0, 0]])
    with compiled.numpy_path():
        point = score_triples(TRIPOD[None], -TRIPOD[None], w, 0.8, methods=("off_tangent",))
        soft = score_triples(TRIPOD[None], -TRIPOD[None], w, 0.8, methods=("off_tangent",), torsion=0.2)
        assert soft.failed.tolist() == [-1] == point.failed.tolist()
        refs = [least_soft_grip(TRIPOD, -TRIPOD, wrench, 0.8, 0.2)[0] for wrench in w]
        np.testing.assert_allclose(soft.total_normal_force[0], refs, rtol=1e-6)
        assert soft.total_normal_force[0, 1] < point.total_normal_force[0, 1] * 0.999
        # torsions about the normals cannot lift: tan 20 deg, to the 12 halvings' 0.8 / 2^12 (the soft grip, with no
        # facial reduction, is cannot-hold within about 1e-5 of the edge, where the point contacts' is exact)
        lift = hold_friction(TRIPOD[None], -TRIPOD[None], w[:1], 0.8, steps=12, torsion=0.2)
        assert float(lift[0]) == pytest.approx(np.tan(LATITUDE), abs=0.8 / 2**12)
        g = verified(TRIPOD, -TRIPOD, w[1], 0.8, 1.0, torsion=0.2)
    assert g is not None and float(g.total_normal_force) == pytest.approx(refs[1], rel=1e-6)


def test_a_search_with_soft_contacts_needs_friction():
    from grasptwist.engine.synthesis.checks import check_search_torsion

    assert check_search_torsion(None, 0.0) is None and check_search_torsion(0.01, 0.5) == 0.01
    for torsion, friction, message in (
        (0.0, 0.5, "finite length > 0"),
        (np.inf, 0.5, "finite length > 0"),
        (0.01, 0.0, "need friction > 0"),
    ):
        with pytest.raises(ValueError, match=message):
            check_search_torsion(torsion, friction)


def test_a_weight_off_the_line_of_the_contacts_is_held_along_a_path_by_soft_pads_alone():
    """follow's grip of the weight (grip_along, hold_verdicts): a rod pinched along its axis whose centre of mass lies
    1 cm beside it needs a moment about the line, which point contacts cannot make (unjudged: collinear-contacts)
    and soft pads can, at every sample of a lift; the follow record says so."""
    from grasptwist.engine.forces.hold import grip_along, hold_verdicts
    from grasptwist.output.follow_records import grip_record
    from grasptwist.path import Segment

    weight = (LINE, ACROSS, 0.5, 1.0, [0, 0.01, 0], [0, 0, -9.81], [Segment(1.0, twist=[0, 0, 0, 0, 0, 0.1])])
    times = [0.0, 0.5, 1.0]
    with compiled.numpy_path():
        point = grip_along(*weight, times)[1]
        soft = grip_along(*weight, times, torsion=[0.01, 0.01, 0])[1]
        falls, unjudged = hold_verdicts(*weight, times, torsion=[0.01, 0.01, 0])
    assert (point.status == gt.forces.Status.COLLINEAR_CONTACTS).all() and soft.ok.all()
    assert falls == () and unjudged == ()
    reference = least_soft_grip(LINE, ACROSS, [0, 0, 9.81, 0.0981, 0, 0], 0.5, [0.01, 0.01, 0])[0]
    np.testing.assert_allclose(soft.total_normal_force, reference, rtol=1e-6)  # a lift: the same wrench all along
    np.testing.assert_allclose(soft.torsion[:, 0] - soft.torsion[:, 1], 0.0981, rtol=1e-9)
    record = grip_record(soft, 0)
    assert record["contact_model"] == "soft" and record["torsion"] == pytest.approx(soft.torsion[0].tolist())
    assert "contact_model" not in grip_record(grip_along(EQ, -EQ, 0.5, *weight[3:], times)[1], 0)


def test_soft_closure_of_a_batch_whose_rows_close_and_do_not():
    """A review: soft closure friction of a batch with a row that phase I finds no internal force for, beside one it
    does, raised a shape mismatch (every row's cones paired with the live rows' forces); each row is now its own,
    as alone."""
    none = np.array([[-1.0, 0, 0]] * 3)  # every normal the same way: no internal force inside the cones
    both = gt.forces.force_closure([EQ, EQ], [-EQ, none], torsion=0.01).closure_friction
    alone = [float(gt.forces.force_closure(EQ, n, torsion=0.01).closure_friction) for n in (-EQ, none)]
    np.testing.assert_array_equal(both, alone)
    assert np.isnan(both[1]) and 0 <= both[0] < 1e-3
