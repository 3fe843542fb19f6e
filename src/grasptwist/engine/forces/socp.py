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

Every array is components-first (each number of each row one array over the rows), and each
Newton step solves its 3 x 3 (4 x 4) systems by elimination on those arrays.
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

#: Phase I keeps the squeezes within this (of the row's scale): without a bound an infeasible
#: row whose cones share a boundary direction drifts along it without end.
BOX = 1e6

#: Phase I stops a row whose every cone holds ``t - |z| >= START_MARGIN`` (of the row's scale).
START_MARGIN = 0.5


def _cones(A, b, x):
    """``y = A x + b (3 cones, 3, n)`` and ``q = t^2 - |z|^2 (3, n)``, components-first."""
    y = b + A[:, :, 0] * x[0]
    for j in range(1, len(x)):
        y = y + A[:, :, j] * x[j]
    return y, y[:, 0] ** 2 - y[:, 1] ** 2 - y[:, 2] ** 2


def _inside(y, q):
    return (q > 0).all(axis=0) & (y[:, 0] > 0).all(axis=0)


def _spd_solve(h, g):
    """``h^-1 g`` for symmetric positive definite ``h (d, d, n)``, ``g (d, n)``: elimination without
    pivoting, each entry an array over the rows."""
    d = len(g)
    h = [[h[i, j] for j in range(d)] for i in range(d)]
    g = [g[i] for i in range(d)]
    for k in range(d):
        for i in range(k + 1, d):
            f = h[i][k] / h[k][k]
            for j in range(k + 1, d):
                h[i][j] = h[i][j] - f * h[k][j]
            g[i] = g[i] - f * g[k]
    x = [None] * d
    for i in reversed(range(d)):
        v = g[i]
        for j in range(i + 1, d):
            v = v - h[i][j] * x[j]
        x[i] = v / h[i][i]
    return np.stack(x)


def _centre(A, b, c, x, tau, bounded, done=_ROUGH):
    """Damped Newton on ``tau c^T x + barrier`` until every row is centred (in place on ``x``).

    Components-first: ``A (3 cones, 3, d, n)``, ``b (3, 3, n)``, ``c, x (d, n)``.  Each step
    works on the rows not yet centred only.  In phase I (``bounded``) a row also stops
    once its margin ``-r`` reaches ``START_MARGIN``: a grasp in force closure has no
    phase-I minimum (squeezing harder widens every margin without end), and that
    margin is all phase II needs.
    """
    d = len(x)
    P = (A[:, :, :, None] * (_J[None, :, None, None, None] * A[:, :, None, :])).sum(axis=1)  # A_m^T J A_m
    rows = np.arange(x.shape[1])
    if bounded:
        rows = rows[x[-1] > -START_MARGIN]
    for _ in range(_NEWTON_CAP):
        if not rows.size:
            break
        a, bb, xx = A[..., rows], b[..., rows], x[:, rows]
        y, q = _cones(a, bb, xx)
        u = y * _J[None, :, None] / q[:, None]
        w = (a * u[:, :, None]).sum(axis=1)  # (3, d, n): A_m^T u_m
        grad = tau * c[:, rows] - 2 * w.sum(axis=0)
        hess = (P[..., rows] * (-2 / q)[:, None, None]).sum(axis=0) + 4 * (w[:, :, None] * w[:, None, :]).sum(axis=0)
        if bounded:  # -log(r + 1) keeps phase I's r above -1, -log(R^2 - |s|^2) the squeezes within R
            gap = xx[-1] + 1
            grad[-1] -= 1 / gap
            hess[-1, -1] += 1 / gap**2
            room = BOX**2 - (xx[:-1] ** 2).sum(axis=0)
            grad[:-1] += 2 * xx[:-1] / room
            for i in range(d - 1):
                hess[i, i] += 2 / room
                for j in range(d - 1):
                    hess[i, j] += 4 * xx[i] * xx[j] / room**2
        # a ridge far below round-off, for directions that move no cone (a zero Hessian column)
        ridge = 1e-14 * np.abs(np.stack([hess[i, i] for i in range(d)])).max(axis=0)
        for i in range(d):
            hess[i, i] += ridge
        dx = _spd_solve(hess, -grad)
        lam2 = np.maximum(-(grad * dx).sum(axis=0), 0)
        lam = np.sqrt(lam2)
        step = np.where(lam > 0.25, 1 / (1 + lam), 1.0)
        for _halving in range(8):  # a safeguard against round-off at the cones' edge
            trial = xx + step * dx
            ok = _inside(*_cones(a, bb, trial))
            if bounded:
                ok &= (trial[-1] > -1) & ((trial[:-1] ** 2).sum(axis=0) < BOX**2)
            if ok.all():
                break
            step = np.where(ok, step, step / 2)
        x[:, rows] = np.where(ok, trial, xx)
        going = (lam2 > done) & ok
        if bounded:
            going &= x[-1, rows] > -START_MARGIN
        rows = rows[going]
    return x


def _layout(A, b):
    """``(n, 3, 3, d)``, ``(n, 3, 3)`` -> components-first ``(3, 3, d, n)``, ``(3, 3, n)``."""
    return np.ascontiguousarray(np.moveaxis(A, 0, -1)), np.ascontiguousarray(np.moveaxis(b, 0, -1))


def phase_one(A, b):
    """A strictly feasible ``x`` per row and the margin ``r`` reached (``r < 0``: feasible).

    ``A (n, 3, 3, d)``, ``b (n, 3, 3)`` -> ``x (n, d)``, ``r (n)``.  With ``r < 0``
    every cone holds ``t_m - |z_m| >= -r > 0`` at ``x``.  A row leaves once it is
    decided: ``r <= -START_MARGIN``, or centred with ``r`` further than the duality
    gap from 0 on either side (phase I's barrier has parameter 7: ``7 / tau``, with
    room for rough centring).
    """
    n, _, _, d = A.shape
    wide = np.concatenate((A, np.zeros((n, 3, 3, 1))), axis=-1)
    wide[:, :, 0, d] = 1.0  # t_m + r
    wide, bc = _layout(wide, b)
    over = np.sqrt(b[..., 1] ** 2 + b[..., 2] ** 2) - b[..., 0]
    x = np.zeros((d + 1, n))
    x[d] = np.maximum(over.max(axis=-1) + 1, 0.0)
    c = np.zeros((d + 1, n))
    c[d] = 1.0
    rows = np.arange(n)
    for tau in _TAUS:
        if not rows.size:
            break
        xx = x[:, rows]
        _centre(wide[..., rows], bc[..., rows], c[:, rows], xx, tau, bounded=True)
        x[:, rows] = xx
        r = xx[d]
        rows = rows[(r > -START_MARGIN) & (np.abs(r) <= 10 / tau)]
    return x[:d].T, x[d]


def minimise(A, b, c, x):
    """Follow the central path from the strictly feasible ``x (n, d)`` to ``TAU_END``; returns ``x (n, d)``."""
    A, b = _layout(A, b)
    x, c = np.ascontiguousarray(x.T), np.ascontiguousarray(c.T)
    for tau in _TAUS:
        _centre(A, b, c, x, tau, bounded=False, done=_DONE if tau == _TAUS[-1] else _ROUGH)
    return x.T
