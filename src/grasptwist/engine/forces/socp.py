r"""A batched barrier method for small second-order cone programs: many rows at once, no loop over rows.

Each row is the problem

.. math:: \min_x\; c^T x \quad \text{s.t.} \quad y_m = A_m x + b_m \in Q^3 = \{(t, z) : t \ge |z|\},\; m = 1, 2, 3

with ``x`` of 3 (or 4) numbers: the grip's three squeezes.  The barrier
``-sum_m log(t_m^2 - |z_m|^2)`` is self-concordant with parameter 2 per cone, so

* a *damped Newton* step of length ``1 / (1 + lambda)`` (``lambda`` the Newton
  decrement) never leaves the cones and needs no line search: every row takes the
  same arithmetic, which is what lets numpy run them together;
* after centring at ``tau`` the objective is within ``6 / tau`` of the optimum.

**Phase I** finds a strictly feasible point by minimising ``r`` with the cones widened
to ``t_m + r >= |z_m|`` and ``r >= -1``, from ``x = 0`` and an ``r`` that makes the
start feasible: a row whose ``r`` ends below 0 has an interior point, one whose ``r``
stays above the duality gap has none (``cannot-hold``).  **Phase II** then follows the
central path from there, ``tau = 1, 100, ..., TAU_END``, centring roughly
(``lambda^2 < 0.01``) on the way and a little closer (``1e-4``) at the end.  The rows are scaled by their
caller so that the numbers are of order one (the wrench's manipulating forces), so
``TAU_END = 1e10`` leaves a gap of ``6e-10`` of that scale.

Each Newton step solves one 3 x 3 (4 x 4) system per row with ``numpy.linalg.solve``
over the stacked rows.
"""

from __future__ import annotations

import numpy as np

__all__ = ["TAU_END", "phase_one", "minimise"]

#: The last barrier weight: the objective ends within ``6 / TAU_END`` of the optimum.
TAU_END = 1e10

_TAUS = np.array([1.0, 1e2, 1e4, 1e6, 1e8, 1e10])
_NEWTON_CAP = 40  # per weight; a centred row needs 3-6 after a tenfold increase
# Squared Newton decrement below which a row counts as centred at the last weight: the objective is
# then within (6 + lambda sqrt(6)) / tau of the optimum (self-concordance), so a rough centre does.
_DONE = 1e-4
_ROUGH = 1e-2  # enough centring on the way (the next weight's steps start from near the path)
_J = np.array([1.0, -1.0, -1.0])

#: Phase I stops a row whose every cone holds ``t - |z| >= START_MARGIN`` (of the row's scale).
START_MARGIN = 0.5


def _cones(A, b, x):
    y = (A @ x[:, None, :, None])[..., 0] + b
    q = y[..., 0] ** 2 - y[..., 1] ** 2 - y[..., 2] ** 2
    return y, q


def _inside(y, q):
    return (q > 0).all(axis=-1) & (y[..., 0] > 0).all(axis=-1)


def _centre(A, b, c, x, tau, bounded, done=_ROUGH):
    """Damped Newton on ``tau c^T x + barrier`` until every row is centred (in place on ``x``).

    Each step works on the rows not yet centred only.  In phase I (``bounded``) a row
    also stops once its margin ``-r`` reaches ``START_MARGIN``: a grasp in force
    closure has no phase-I minimum (squeezing harder widens every margin without
    end), and that margin is all phase II needs.
    """
    P = np.swapaxes(A, -1, -2) @ (_J[:, None] * A)  # A_m^T J A_m
    eye = np.eye(A.shape[-1])
    rows = np.arange(len(x))
    if bounded:
        rows = rows[x[:, -1] > -START_MARGIN]
    for _ in range(_NEWTON_CAP):
        if not rows.size:
            break
        a, bb, xx = A[rows], b[rows], x[rows]
        y, q = _cones(a, bb, xx)
        u = y * _J / q[..., None]
        w = (u[:, :, None, :] @ a)[:, :, 0, :]  # A_m^T u_m
        grad = tau * c[rows] - 2 * w.sum(axis=1)
        hess = (-2 / q)[:, :, None, None] * P[rows]
        hess = hess.sum(axis=1) + 4 * (np.swapaxes(w, -1, -2) @ w)
        if bounded:  # -log(r + 1) keeps phase I's r above -1
            gap = xx[:, -1] + 1
            grad[:, -1] -= 1 / gap
            hess[:, -1, -1] += 1 / gap**2
        # a ridge far below round-off, for directions that move no cone (a zero Hessian column)
        hess += 1e-14 * np.abs(np.diagonal(hess, axis1=1, axis2=2)).max(axis=1)[:, None, None] * eye
        dx = np.linalg.solve(hess, -grad[..., None])[..., 0]
        lam2 = np.maximum(-(grad * dx).sum(axis=1), 0)
        lam = np.sqrt(lam2)
        step = np.where(lam > 0.25, 1 / (1 + lam), 1.0)
        for _halving in range(8):  # a safeguard against round-off at the cones' edge
            trial = xx + step[:, None] * dx
            ok = _inside(*_cones(a, bb, trial))
            if bounded:
                ok &= trial[:, -1] > -1
            if ok.all():
                break
            step = np.where(ok, step, step / 2)
        x[rows] = np.where(ok[:, None], trial, xx)
        going = (lam2 > done) & ok
        if bounded:
            going &= x[rows, -1] > -START_MARGIN
        rows = rows[going]
    return x


def phase_one(A, b):
    """A strictly feasible ``x`` per row and the margin ``r`` reached (``r < 0``: feasible).

    ``A (n, 3, 3, d)``, ``b (n, 3, 3)`` -> ``x (n, d)``, ``r (n)``.  With ``r < 0``
    every cone holds ``t_m - |z_m| >= -r > 0`` at ``x``.  A row leaves once it is
    decided: ``r <= -START_MARGIN``, or centred with ``r`` further than the duality
    gap ``7 / tau`` from 0 on either side (phase I's barrier has parameter 7).
    """
    n, _, _, d = A.shape
    wide = np.concatenate((A, np.zeros((n, 3, 3, 1))), axis=-1)
    wide[:, :, 0, d] = 1.0  # t_m + r
    over = np.sqrt(b[..., 1] ** 2 + b[..., 2] ** 2) - b[..., 0]
    x = np.zeros((n, d + 1))
    x[:, d] = np.maximum(over.max(axis=-1) + 1, 0.0)
    c = np.zeros((n, d + 1))
    c[:, d] = 1.0
    rows = np.arange(n)
    for tau in _TAUS:
        if not rows.size:
            break
        xx = x[rows]
        _centre(wide[rows], b[rows], c[rows], xx, tau, bounded=True)
        x[rows] = xx
        r = xx[:, d]
        rows = rows[(r > -START_MARGIN) & (np.abs(r) <= 10 / tau)]  # 7 / tau, with room for rough centring
    return x[:, :d], x[:, d]


def minimise(A, b, c, x):
    """Follow the central path from the strictly feasible ``x`` to ``TAU_END``; returns ``x (n, d)``."""
    x = x.copy()
    for tau in _TAUS:
        _centre(A, b, c, x, tau, bounded=False, done=_DONE if tau == _TAUS[-1] else _ROUGH)
    return x
