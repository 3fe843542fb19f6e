r"""A batched primal-dual interior-point method for small second-order cone programs: many rows at once.

Each row is the problem

.. math:: \min_x\; c^T x \quad \text{s.t.} \quad y_m = A_m x + b_m \in Q^k = \{(t, z) : t \ge |z|\},\; m = 1 .. K

with ``x`` of a few numbers (the grip's squeezes, a soft contact's torsions, and phase I's
margin), and its dual ``max -sum_m b_m^T z_m`` s.t. ``sum_m A_m^T z_m = c``, ``z_m in Q^k``; the
duality gap is ``sum_m y_m . z_m``.  The cones have ``k`` components (a ray ``k = 1``, ``Q^3``,
``Q^4``); a smaller cone is padded with components that stay zero, and a half-space
``a^T x + h >= 0`` is the cone ``(a^T x + h, 0, 0)``.

Both phases start strictly inside the cones, primal and dual; phase II's dual start is
feasible too (phase I's leaves a residual in the dual equalities, which every step shrinks by
its length).  Each iteration is Mehrotra's predictor-corrector with
Nesterov-Todd scaling (the scaling point ``w`` with ``W z = W^{-1} y = lambda``, one per cone,
``W = beta (2 v v^T - J)``): an affine step ``lambda o v = -lambda o lambda``, the centring
weight ``sigma = (mu_aff / mu)^3``, then the corrected step, 0.99 of the way to the cones' edge
(in closed form per cone).  The Newton system is the d x d
``H dx = sum_m (W_m^{-1} A_m)^T W_m^{-1} v_m``, solved by elimination on arrays over the rows.
A row leaves once its gap is below ``GAP`` of its objective's scale (``1 + |c^T x|``): the
rows are scaled by their caller to order one, so the objective is then that close to the
optimum.  It takes 10-25 iterations a row, about a third of the Newton steps of a barrier
method with damped steps.  The iteration is written once, in
:mod:`~grasptwist.engine.forces.ipm` (its lane form, which numba compiles); where numba is on
(:func:`compiled.iteration`) this module's functions hand their rows to that compiled source
(:func:`kernel.iterate_rows`, :func:`kernel.polish_rows`), else they run its numpy twin
(:mod:`~grasptwist.engine.forces._twin`), the reference, over all the rows still iterating,
gathering out those that are done, and a few rows (:data:`ALONE`) through the float twin of
:mod:`~grasptwist.engine.forces.one`, a row at a time (numpy's cost per call is then all there is).

**Phase I** finds a strictly feasible point by minimising ``r`` with the cones widened to
``t_m + r >= |z_m|`` and ``r >= -1``, from ``x = 0`` and an ``r`` that makes the start
feasible, and a dual start that is feasible in ``r``'s column only (the residual of the
squeezes' columns shrinks step by step).  A row is decided once ``r <= -START_MARGIN``
(feasible, with room), its dual objective (a lower bound on ``r``, once the residual is
gone) is above 0 (infeasible: ``cannot-hold``), or its gap has closed (the sign of ``r``
decides).  An infeasible row whose cones share a boundary direction has ``r -> 0`` only
far along it: it stops at the cap with ``r > 0``.

The public functions take rows first (``A (n, K, k, d)``); the iteration's arrays are
rows last, as :mod:`~grasptwist.engine.forces.ipm` keeps its lanes: ``A (K, k, d, n)``,
``z (K, k, n)``, ``x (d, n)``.
"""

from __future__ import annotations

import contextlib
import functools

import numpy as np

from . import compiled, ipm, one
from .ipm import GAP, ITERATIONS, START_MARGIN

__all__ = ["GAP", "START_MARGIN", "phase_one", "minimise", "dual_polish"]


@functools.cache
def _twins():
    """:mod:`~grasptwist.engine.forces.ipm`'s numpy twins (made at the first solve, not at import: some 20 ms)."""
    from ._twin import twins  # ast and inspect: not at start-up

    return twins(ipm.LANE_FORM)


#: The most rows :func:`_iterate` takes one at a time in Python floats: a step of the numpy twin costs some
#: 600 us whatever the rows (700 calls of numpy on a few numbers), the float twin's some 75 us a row; a
#: grip of 12 rows took 13.6 ms so against 16.2 ms, one of 16 rows 18.1 against 18.8, of 24 27.6 against 26.8.
ALONE = 12


def _one_row(A, b, c, x, z, r, phase_one):
    """Row ``r`` of :func:`_iterate`'s arrays (``A (K, k, d)``, ``b (K, k)``, ``c (d)`` its own) through the
    float twin, its ``x[:, r]`` and ``z[..., r]`` moved in place."""
    rows = A.tolist()
    xr, zr = x[:, r].tolist(), z[..., r].tolist()
    one.iterate(rows, b.tolist(), c.tolist(), xr, zr, one.newton_matrices(rows), phase_one)
    x[:, r], z[..., r] = xr, zr


@np.errstate(divide="ignore", invalid="ignore", over="ignore")
def _iterate(A, b, c, x, z, phase_one):
    """Mehrotra steps (:func:`ipm.step`'s twin) on the rows of ``(A, b, c)`` from the strictly feasible primal
    ``x (d, n)`` and the dual ``z (K, k, n)`` inside the cones (in place), until each row is done (phase I's
    rules where ``phase_one``) or the cap.  A row that is done leaves the arrays (gathered only when some
    leave: none do for the first 7 or so steps).  Up to :data:`ALONE` rows go one at a time through the float
    twin (:func:`one.iterate`), each as it would alone."""
    K, k, d, n = A.shape
    if n <= ALONE:
        for r in range(n):
            _one_row(A[..., r], b[..., r], c[:, r], x, z, r, phase_one)
        return x
    P = np.empty((K, d, d, n))
    lane = _twins()
    lane["newton_part"](A, P, d, K, k, n)
    rows = np.arange(n)
    a, bb, cc, xx, zz = A, b, c, x.copy(), z.copy()
    for _ in range(ITERATIONS):
        if not rows.size:
            break
        done = np.empty(rows.size, bool)
        lane["step"](a, bb, cc, xx, zz, P, phase_one, ipm.workspace(d, K, k, rows.size), done, d, K, k, rows.size)
        x[:, rows], z[..., rows] = xx, zz
        if done.any():
            stay = ~done
            rows, a, bb, cc, xx, zz, P = (
                rows[stay],
                a[..., stay],
                bb[..., stay],
                cc[:, stay],
                xx[:, stay],
                zz[..., stay],
                P[..., stay],
            )
    return x


def _iterated(A, b, c, x, z, phase_one):
    """:func:`_iterate` on rows first: ``A (n, K, k, d)``, ``b (n, K, k)``, ``c (n, d)`` from ``x (n, d)``,
    ``z (n, K, k)``; returns the new ``x`` and ``z``.  Compiled where numba is on
    (:func:`kernel.iterate_rows`, :mod:`~grasptwist.engine.forces.ipm`'s source too), else this
    module's numpy twin, the reference."""
    x, z = np.array(x, float, order="C"), np.array(z, float, order="C")  # copies, moved in place
    module = compiled.iteration()
    if module is not None:
        A, b, c = (_plain(a) for a in (A, b, c))
        module.iterate_rows(A, b, c, x, z, bool(phase_one))
        return x, z
    lanes = np.ascontiguousarray(A.transpose(1, 2, 3, 0)), np.ascontiguousarray(b.transpose(1, 2, 0))
    x, z = np.ascontiguousarray(x.T), np.ascontiguousarray(z.transpose(1, 2, 0))
    x = _iterate(*lanes, np.ascontiguousarray(c.T), x, z, phase_one)
    return x.T, z.transpose(2, 0, 1)


def _plain(a):
    """``a`` as the compiled functions take it, in their one signature: C-contiguous writable floats."""
    return np.require(a, float, ("C", "W"))


def phase_one(A, b):
    """A strictly feasible ``x`` per row, the margin ``r`` reached (``r < 0``: feasible) and the dual.

    ``A (n, K, k, d)``, ``b (n, K, k)`` -> ``x (n, d)``, ``r (n)``, ``z (n, K, k)``.  With
    ``r < 0`` every cone holds ``t_m - |z_m| >= -r > 0`` at ``x``.  Where ``r > 0`` the cones'
    dual ``z_m`` (inside ``Q^k``, ``sum_m A_m^T z_m = 0`` to the residual) has
    ``-sum_m b_m . z_m > 0``: a proof that no ``x`` puts every ``A_m x + b_m`` in its cone
    (Farkas).
    """
    n, K, k, d = A.shape
    wide, bw, z = np.empty((n, K + 1, k, d + 1)), np.empty((n, K + 1, k)), np.empty((n, K + 1, k))
    c, x = np.empty((n, d + 1)), np.empty((n, d + 1))
    with np.errstate(all="ignore"):
        _twins()["widened"](*(ipm.lanes(a) for a in (A, b, wide, bw, c, x, z)), d, K, k, n)
    x, z = _iterated(wide, bw, c, x, z, True)
    return np.ascontiguousarray(x[:, :d]), x[:, d], np.ascontiguousarray(z[:, :K])


def minimise(A, b, c, x):
    """The optimum from the strictly feasible ``x (n, d)``; returns ``x (n, d)`` and the dual ``z (n, K, k)``.

    ``A (n, K, k, d)``, ``b (n, K, k)``, ``c (n, d)`` with ``c = sum_m A_m^T e`` (``e = (1, 0,
    0)``: the objective is the sum of the cones' first components, as the grip's is), so
    ``z_m = e`` is a strictly feasible dual start.  The dual stays feasible
    (``sum_m A_m^T z_m = c`` to round-off); the gap ``sum_m y_m . z_m`` is below ``GAP``
    of the objective's scale where a row closed.
    """
    z = np.zeros(A.shape[:3])
    z[..., 0] = 1.0
    return _iterated(A, b, c, x, z, False)


def dual_polish(A, b, c, s, z):
    """``z`` moved to ``sum_m A_m^T z_m = c`` again (the solver keeps it to round-off of its large final steps).

    The correction ``dz_m = omega_m A_m delta`` with ``omega_m = |z_m| / |y_m|`` goes to the cones
    whose multipliers carry the optimum (``y_m`` on the edge, ``z_m`` large), not to idle ones
    (``z_m`` near 0), so every ``z_m`` stays in its cone to round-off.  Compiled where numba is on
    (:func:`kernel.polish_rows`: :func:`one.dual_polish`, by elimination without pivoting).
    """
    module = compiled.iteration()
    if module is not None:
        z = np.array(z, float, order="C")
        module.polish_rows(*(_plain(a) for a in (A, b, c, s)), z)
        return z
    y = np.einsum("nmkd,nd->nmk", A, s) + b
    res = c - np.einsum("nmkd,nmk->nd", A, z)
    omega = np.linalg.norm(z, axis=-1) / np.maximum(np.linalg.norm(y, axis=-1), 1e-300)
    h = np.einsum("nm,nmkd,nmke->nde", omega, A, A)
    with np.errstate(all="ignore"):
        delta = _solved(h + 1e-300 * np.eye(A.shape[-1]), res)
        dz = omega[..., None] * np.einsum("nmkd,nd->nmk", A, delta)
    return np.where(np.isfinite(dz).all(axis=(1, 2))[:, None, None], z + dz, z)


def _solved(h, res):
    """``h^-1 res`` row by row, NaN for a row whose ``h`` LAPACK finds exactly singular (every cone
    idle: nothing to polish there).  Which rows are exactly singular depends on the processor's
    kernel (OpenBLAS rounds differently), and one such row fails a batched solve whole.

    >>> _solved(np.array([[[2.0, 0], [0, 2]], [[0.0, 0], [0, 0]]]), np.ones((2, 2))).tolist()
    [[0.5, 0.5], [nan, nan]]
    """
    try:
        return np.linalg.solve(h, res[..., None])[..., 0]
    except np.linalg.LinAlgError:
        delta = np.full(res.shape, np.nan)
        for i in range(len(h)):
            with contextlib.suppress(np.linalg.LinAlgError):
                delta[i] = np.linalg.solve(h[i], res[i])
        return delta
