r"""The interior-point method's iteration, written once for the numpy path and the compiled one.

One iteration of the method :mod:`~grasptwist.engine.forces.socp` describes (Mehrotra's
predictor-corrector with Nesterov-Todd scaling, 0.99 of the way to the cones' edge, its
stopping rules) on many rows, in *lane form*: each array's last axis is the rows, and each
loop ``for ln in range(width):`` does one row's straight-line arithmetic on the elements
``[..., ln]``.  numba compiles these functions as they are
(:mod:`~grasptwist.engine.forces.kernel`: rows in 32 lanes, refilled as they finish); numpy
runs their *twins* (:mod:`~grasptwist.engine.forces._twin`: each lane loop's body on all
rows at once, :func:`socp._iterate`), and one row alone goes through their *float twins*
(the same source on nested lists of Python floats, :mod:`~grasptwist.engine.forces.one`).
So the three share every formula: a new cone size ``k`` (a ray ``k = 1``, ``Q^3``, a soft
contact's ``Q^4``) or a new number of cones or unknowns is the same source.

A row's arrays (``K`` cones of ``k`` components, ``d`` unknowns, ``width`` rows):
``a (K, k, d, width)`` (cone ``m``'s ``A_m``), ``b (K, k, width)``, ``c (d, width)``, the
unknowns ``x (d, width)``, the multipliers ``z (K, k, width)``, and ``P (K, d, d, width)``
(:func:`newton_part`).  :func:`step` moves ``x`` and ``z`` in place and says which rows
are done; a row is done when its step is not finite (round-off at the cones' edge: it
stays where it is, still inside), its gap is closed with a feasible dual (phase II, and
phase I), or (phase I) its margin ``r = x[d - 1] <= -START_MARGIN`` or its dual bound is
above 0 (infeasible).  The iterations' cap is the caller's (:data:`ITERATIONS`).

Branches on a row's numbers are choices (``a if c else b``), so the numpy twin computes both
sides: division by zero and ``inf - inf`` happen on rows that then discard them (numpy's
error model, which the kernel compiles with).  In Python floats a division by zero raises
where numpy gives ``inf`` or NaN, which ends the step as its not being finite does: the float
twin's caller stops the row where it is.  Of numpy the functions use only its calls on one
number that :data:`_twin.SCALAR` knows.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    *("GAP", "START_MARGIN", "RESIDUAL", "ITERATIONS", "EDGE"),
    *("workspace", "newton_part", "step", "spd_solve", "widened", "lanes", "every"),
]

#: A row stops once its duality gap is below this times ``1 + |c^T x|``.
GAP = 1e-10

#: Phase I stops a row whose every cone holds ``t - |z| >= START_MARGIN`` (of the row's scale).
START_MARGIN = 0.5

#: A dual residual below this (of the rows' order-one scale) counts as feasible.
RESIDUAL = 1e-9

#: The iterations' cap; rows need 10-25.
ITERATIONS = 60

#: The fraction of the way to the cones' edge a step goes.
EDGE = 0.99


#: ``for m in every(K):`` is ``range(K)`` whose iterations are independent (each cone's, or each component's,
#: own): numba loops over it, the numpy twin (:mod:`~grasptwist.engine.forces._twin`) runs them at once.
every = range


def workspace(d, K, k, width):
    """The arrays :func:`step` works in, for ``width`` rows: a tuple of views of five allocations.

    >>> [w.shape for w in workspace(3, 2, 3, 5)][:3]
    [(3, 5), (2, 3, 5), (2, 3, 5)]
    """
    cones, each, unknowns = np.empty((9, K, k, width)), np.empty((6, K, width)), np.empty((3, d, width))
    matrices, lanes = np.empty((2, d, d, width)), np.empty((3, width))
    return (
        unknowns[0],  # res: c - sum_m A_m^T z_m
        cones[0],  # y = A x + b
        cones[1],  # v: the scaling's, W = beta (2 v v^T - J)
        each[0],  # beta
        each[1],  # 1 / beta^2
        cones[2],  # lambda = W z
        each[2],  # sqrt(y^T J y)
        each[3],  # sqrt(z^T J z)
        np.empty((K, d, width)),  # A_m^T J w_m
        matrices[0],  # the Newton matrix
        matrices[1],  # its copy, eliminated
        cones[3],  # u, then W^-1 dy
        cones[4],  # W^-1 u, then W dz
        cones[5],  # the right-hand side
        cones[6],  # lambda o lambda
        unknowns[1],  # the Newton system's right-hand side
        unknowns[2],  # dx
        cones[7],  # dy
        cones[8],  # dz
        lanes[0],  # mu
        lanes[1],  # the step to the cones' edge
        lanes[2],  # sigma
        each[4],  # a number per cone, to be summed over the cones
        each[5],  # another
    )


def newton_part(a, P, d, K, k, width):
    """``P_m[i, j] = A_m[:, i]^T J A_m[:, j]``: the part of the Newton matrix that stays (``J = diag(1, -1, ..)``).

    >>> a = np.array([[[[2.0]], [[1.0]]]])  # one cone (2, 1) . x
    >>> P = np.empty((1, 1, 1, 1)); newton_part(a, P, 1, 1, 2, 1); P[0, 0, 0].tolist()
    [3.0]
    """
    for m in every(K):
        for i in range(d):
            for j in range(d):
                for ln in range(width):
                    t = a[m, 0, i, ln] * a[m, 0, j, ln]
                    for q in range(1, k):
                        t -= a[m, q, i, ln] * a[m, q, j, ln]
                    P[m, i, j, ln] = t


def _cone_sum(u, K, ln):
    """``sum_m u[m, ln]``: a sum over the cones."""
    s = u[0, ln]
    for m in range(1, K):
        s += u[m, ln]
    return s


def _column(a, u, m, j, k, ln):
    """``A_m[:, j]^T u_m``: cone ``m``'s part of column ``j`` of ``A^T u``."""
    t = a[m, 0, j, ln] * u[m, 0, ln]
    for i in range(1, k):
        t += a[m, i, j, ln] * u[m, i, ln]
    return t


def _w_inv(v, beta, u, out, m, k, ln):
    """``out_m = W_m^-1 u_m = (2 J v (J v)^T u - J u) / beta`` for one lane (``out`` may be ``u``)."""
    t = v[m, 0, ln] * u[m, 0, ln]
    for i in range(1, k):
        t -= v[m, i, ln] * u[m, i, ln]
    t = 2 * t
    out[m, 0, ln] = (t * v[m, 0, ln] - u[m, 0, ln]) / beta[m, ln]
    for i in range(1, k):
        out[m, i, ln] = (u[m, i, ln] - t * v[m, i, ln]) / beta[m, ln]


def _w_mul(v, beta, u, out, m, k, ln):
    """``out_m = W_m u_m = beta (2 v v^T u - J u)`` for one lane (``out`` may be ``u``)."""
    t = v[m, 0, ln] * u[m, 0, ln]
    for i in range(1, k):
        t += v[m, i, ln] * u[m, i, ln]
    t = 2 * t
    out[m, 0, ln] = beta[m, ln] * (t * v[m, 0, ln] - u[m, 0, ln])
    for i in range(1, k):
        out[m, i, ln] = beta[m, ln] * (t * v[m, i, ln] + u[m, i, ln])


def _residual(a, c, z, res, each, d, K, k, width):
    """``res = c - sum_m A_m^T z_m``: what the dual equalities miss."""
    for j in range(d):
        for m in every(K):
            for ln in range(width):
                each[m, ln] = _column(a, z, m, j, k, ln)
        for ln in range(width):
            res[j, ln] = c[j, ln] - _cone_sum(each, K, ln)


def _scaling(a, b, x, z, y, v, beta, scale, lam, ys, zs, G, d, K, k, width):
    """``y = A x + b`` and each cone's Nesterov-Todd scaling: the point ``w`` with ``W z = W^-1 y = lambda``,
    ``W = beta (2 v v^T - J)``, ``v = (w + e) / sqrt(2 (w_0 + 1))``, ``beta = sqrt(|y| / |z|)`` (the cone's own
    norms ``|y| = sqrt(y^T J y)``, kept for :func:`_approach`), ``1 / beta^2`` and ``G_m = A_m^T J w_m``."""
    for m in every(K):
        for i in every(k):
            for ln in range(width):
                t = b[m, i, ln]
                for j in range(d):
                    t += a[m, i, j, ln] * x[j, ln]
                y[m, i, ln] = t
        for ln in range(width):
            yy = y[m, 0, ln] * y[m, 0, ln]
            zz = z[m, 0, ln] * z[m, 0, ln]
            yz = y[m, 0, ln] * z[m, 0, ln]
            for i in range(1, k):
                yy -= y[m, i, ln] * y[m, i, ln]
                zz -= z[m, i, ln] * z[m, i, ln]
                yz += y[m, i, ln] * z[m, i, ln]
            sy, sz = np.sqrt(yy), np.sqrt(zz)
            ys[m, ln], zs[m, ln] = sy, sz
            twice = 2 * np.sqrt((1 + yz / (sy * sz)) / 2)
            w0 = (y[m, 0, ln] / sy + z[m, 0, ln] / sz) / twice
            r = np.sqrt(2 * (w0 + 1))
            v[m, 0, ln] = (w0 + 1) / r
            for j in range(d):
                G[m, j, ln] = a[m, 0, j, ln] * w0
            for i in range(1, k):
                wi = (y[m, i, ln] / sy - z[m, i, ln] / sz) / twice
                v[m, i, ln] = wi / r
                for j in range(d):
                    G[m, j, ln] -= a[m, i, j, ln] * wi
            bt = np.sqrt(sy / sz)
            beta[m, ln] = bt
            scale[m, ln] = 1 / (bt * bt)
            _w_mul(v, beta, z, lam, m, k, ln)


def _newton(G, P, scale, H, each, d, K, width):
    """The Newton matrix ``H = sum_m (2 G_m G_m^T - P_m) / beta_m^2`` plus ``1e-14`` of its largest diagonal
    (a ridge for the directions that move no cone)."""
    for i in range(d):
        for j in range(i + 1):
            for m in every(K):
                for ln in range(width):
                    each[m, ln] = (2 * G[m, i, ln] * G[m, j, ln] - P[m, i, j, ln]) * scale[m, ln]
            for ln in range(width):
                h = _cone_sum(each, K, ln)
                H[i, j, ln] = h
                H[j, i, ln] = h
    for ln in range(width):
        top = H[0, 0, ln]
        for i in range(1, d):
            top = np.maximum(top, H[i, i, ln])
        for i in range(d):
            H[i, i, ln] += 1e-14 * top


def _centre(y, z, lam, square, rhs, mu, each, K, k, width):
    """``lambda o lambda`` (``(|lambda|^2, 2 lambda_0 lambda_1, ..)``), the predictor's right-hand side, its
    negative, and ``mu = y . z / K``."""
    for m in every(K):
        for ln in range(width):
            t = lam[m, 0, ln] * lam[m, 0, ln]
            s = y[m, 0, ln] * z[m, 0, ln]
            for i in range(1, k):
                t += lam[m, i, ln] * lam[m, i, ln]
                s += y[m, i, ln] * z[m, i, ln]
            square[m, 0, ln] = t
            rhs[m, 0, ln] = -t
            each[m, ln] = s
            for i in range(1, k):
                square[m, i, ln] = 2 * lam[m, 0, ln] * lam[m, i, ln]
                rhs[m, i, ln] = -square[m, i, ln]
    for ln in range(width):
        mu[ln] = _cone_sum(each, K, ln) / K


def spd_solve(H, g, out, d, width):
    """``out = H^-1 g`` by elimination without pivoting, ``H (d, d, width)`` symmetric positive definite and
    ``g (d, width)`` overwritten.

    >>> H, g, out = np.array([[[4.0], [2.0]], [[2.0], [3.0]]]), np.array([[2.0], [1.0]]), np.empty((2, 1))
    >>> spd_solve(H, g, out, 2, 1); out[:, 0].tolist()
    [0.5, 0.0]
    """
    for q in range(d):
        for i in range(q + 1, d):
            for ln in range(width):
                f = H[i, q, ln] / H[q, q, ln]
                for j in range(q + 1, d):
                    H[i, j, ln] -= f * H[q, j, ln]
                g[i, ln] -= f * g[q, ln]
    for i in range(d - 1, -1, -1):
        for ln in range(width):
            t = g[i, ln]
            for j in range(i + 1, d):
                t -= H[i, j, ln] * out[j, ln]
            out[i, ln] = t / H[i, i, ln]


def _direction(a, lam, v, beta, rhs, res, H, U, WU, g, Hw, dx, dy, dz, each, d, K, k, width):
    """The Newton direction: ``lambda o (W dz + W^-1 dy) = rhs``, ``dy = A dx``, ``sum_m A_m^T dz_m = res``.

    ``u = lambda \\ rhs`` (the Jordan product's inverse), then ``H dx = sum_m A_m^T W_m^-1 u_m - res``
    and ``dz = W^-1 (u - W^-1 dy)``."""
    for m in every(K):
        for ln in range(width):
            ll = lam[m, 0, ln] * lam[m, 0, ln]
            lr = lam[m, 0, ln] * rhs[m, 0, ln]
            for i in range(1, k):
                ll -= lam[m, i, ln] * lam[m, i, ln]
                lr -= lam[m, i, ln] * rhs[m, i, ln]
            u0 = lr / ll
            U[m, 0, ln] = u0
            for i in range(1, k):
                U[m, i, ln] = (rhs[m, i, ln] - u0 * lam[m, i, ln]) / lam[m, 0, ln]
            _w_inv(v, beta, U, WU, m, k, ln)
    for j in range(d):
        for m in every(K):
            for ln in range(width):
                each[m, ln] = _column(a, WU, m, j, k, ln)
        for ln in range(width):
            g[j, ln] = _cone_sum(each, K, ln) - res[j, ln]
            for i in range(d):
                Hw[j, i, ln] = H[j, i, ln]
    spd_solve(Hw, g, dx, d, width)
    for m in every(K):
        for i in every(k):
            for ln in range(width):
                t = a[m, i, 0, ln] * dx[0, ln]
                for j in range(1, d):
                    t += a[m, i, j, ln] * dx[j, ln]
                dy[m, i, ln] = t
        for ln in range(width):
            _w_inv(v, beta, dy, dz, m, k, ln)
            for i in every(k):
                dz[m, i, ln] = U[m, i, ln] - dz[m, i, ln]
            _w_inv(v, beta, dz, dz, m, k, ln)


def _approach(x, d, s, m, k, ln):
    """How fast ``x_m + alpha d_m`` nears its cone's edge: the step ``1 / t`` reaches it where ``t > 0``.

    ``t = -lambda_min``, ``lambda_min = rho_0 - |rho_1|`` the smaller eigenvalue of ``d`` seen from ``x``
    (``P(x^{-1/2}) d`` in the cone's Jordan algebra): with ``xi = x / s``, ``delta = d / s``,
    ``s = sqrt(x^T J x)``, ``rho_0 = xi^T J delta``, ``rho_1 = delta_1 - (rho_0 + delta_0) / (xi_0 + 1) xi_1``.
    No difference of near-equal squares, so a ray (``k = 1``, or a half-space's cone ``(t, 0, ..)``)
    stops exactly at its apex."""
    rho = (x[m, 0, ln] / s) * (d[m, 0, ln] / s)
    for i in range(1, k):
        rho -= (x[m, i, ln] / s) * (d[m, i, ln] / s)
    f = (rho + d[m, 0, ln] / s) / (x[m, 0, ln] / s + 1)
    e = 0.0
    for i in range(1, k):
        t = d[m, i, ln] / s - f * (x[m, i, ln] / s)
        e += t * t
    return np.sqrt(e) - rho


def edge(y, z, dy, dz, ys, zs, out, rate_y, rate_z, K, k, width):
    """The longest step along ``(dy, dz)`` that keeps every ``y_m`` and ``z_m`` in its cone: ``1 / max t`` of
    :func:`_approach`'s rates (``inf``: none limits it; a NaN rate is no limit); ``rate_y, rate_z (K, width)``
    workspaces."""
    for m in every(K):
        for ln in range(width):
            rate_y[m, ln] = _approach(y, dy, ys[m, ln], m, k, ln)
            rate_z[m, ln] = _approach(z, dz, zs[m, ln], m, k, ln)
    for ln in range(width):
        top = 0.0
        for m in range(K):
            top = rate_y[m, ln] if rate_y[m, ln] > top else top
            top = rate_z[m, ln] if rate_z[m, ln] > top else top
        out[ln] = 1 / top if top > 0 else np.inf


def _corrector(y, z, dy, dz, v, beta, square, rhs, mu, step, sigma, each, p, q, K, k, width):
    """Mehrotra's corrected right-hand side from the predictor ``(dy, dz)`` and its step: the centring
    weight ``sigma = (mu_aff / mu)^3`` and ``rhs = -lambda o lambda - (W^-1 dy) o (W dz) + sigma mu e``."""
    for m in every(K):
        for ln in range(width):
            st = np.minimum(1.0, step[ln])
            s = (y[m, 0, ln] + st * dy[m, 0, ln]) * (z[m, 0, ln] + st * dz[m, 0, ln])
            for i in range(1, k):
                s += (y[m, i, ln] + st * dy[m, i, ln]) * (z[m, i, ln] + st * dz[m, i, ln])
            each[m, ln] = s
    for ln in range(width):
        ratio = np.minimum(np.maximum(_cone_sum(each, K, ln) / K / mu[ln], 0.0), 1.0)
        sigma[ln] = ratio * ratio * ratio  # not ** 3: numpy's power on arrays and Python's differ in the last bit
    for m in every(K):
        for ln in range(width):
            _w_inv(v, beta, dy, p, m, k, ln)
            _w_mul(v, beta, dz, q, m, k, ln)
            t = p[m, 0, ln] * q[m, 0, ln]
            for i in range(1, k):
                t += p[m, i, ln] * q[m, i, ln]
            rhs[m, 0, ln] = -square[m, 0, ln] - t + sigma[ln] * mu[ln]
            for i in range(1, k):
                rhs[m, i, ln] = -square[m, i, ln] - (p[m, 0, ln] * q[m, i, ln] + q[m, 0, ln] * p[m, i, ln])


def _update(c, x, z, y, dx, dy, dz, res, step, done, each, phase_one, d, K, k, width):
    """The step 0.99 of the way to the edge (none where it is not finite), and which rows are done: the
    gap below ``GAP`` of ``1 + |c^T x|`` with the dual residual gone (``|res| (1 - step) <= RESIDUAL``),
    or in phase I (``phase_one``; the margin ``r`` is ``x[d - 1]``) ``r <= -START_MARGIN`` or the dual
    objective above ``RESIDUAL (1 + sum |x|)``."""
    for ln in range(width):
        st = np.minimum(1.0, EDGE * step[ln])
        good = np.isfinite(st)
        for j in range(d):
            good = good & np.isfinite(dx[j, ln])
        for m in range(K):
            for i in range(k):
                good = good & np.isfinite(dz[m, i, ln])
        step[ln] = st if good else 0.0
        done[ln] = good
    for m in every(K):
        for ln in range(width):
            s = 0.0
            for i in range(k):
                z[m, i, ln] += step[ln] * (dz[m, i, ln] if done[ln] else 0.0)
                s += (y[m, i, ln] + step[ln] * dy[m, i, ln]) * z[m, i, ln]
            each[m, ln] = s
    for ln in range(width):
        st, good = step[ln], done[ln]
        obj, size, big = 0.0, 1.0, 0.0
        for j in range(d):
            x[j, ln] += st * (dx[j, ln] if good else 0.0)
            obj += c[j, ln] * x[j, ln]
            size += np.abs(x[j, ln])
            big = np.maximum(big, np.abs(res[j, ln]))
        gap = _cone_sum(each, K, ln)
        dual = obj - gap if big * (1 - st) <= RESIDUAL else -np.inf
        closed = (gap <= GAP * (1 + np.abs(obj))) & (dual > -np.inf)
        found = (x[d - 1, ln] <= -START_MARGIN) | (dual > RESIDUAL * size)
        done[ln] = np.logical_not(good) | closed | (phase_one & found)


def step(a, b, c, x, z, P, phase_one, work, done, d, K, k, width):
    """One Mehrotra iteration on every row: ``x``, ``z`` moved in place, ``done`` (bool, per row) set.

    ``work``: :func:`workspace`'s arrays; ``P``: :func:`newton_part`'s.  The predictor (the affine step
    ``lambda o (W dz + W^-1 dy) = -lambda o lambda``), the centring weight, the corrector through the
    same Newton matrix, and the step 0.99 of the way to the cones' edge (:func:`edge`, in closed form)."""
    res, y, v, beta, scale, lam, ys, zs, G, H, Hw, U = work[:12]
    WU, rhs, square, g, dx, dy, dz, mu, to_edge, sigma, each, other = work[12:]
    _residual(a, c, z, res, each, d, K, k, width)
    _scaling(a, b, x, z, y, v, beta, scale, lam, ys, zs, G, d, K, k, width)
    _newton(G, P, scale, H, each, d, K, width)
    _centre(y, z, lam, square, rhs, mu, each, K, k, width)
    _direction(a, lam, v, beta, rhs, res, H, U, WU, g, Hw, dx, dy, dz, each, d, K, k, width)
    edge(y, z, dy, dz, ys, zs, to_edge, each, other, K, k, width)
    _corrector(y, z, dy, dz, v, beta, square, rhs, mu, to_edge, sigma, each, U, WU, K, k, width)
    _direction(a, lam, v, beta, rhs, res, H, U, WU, g, Hw, dx, dy, dz, each, d, K, k, width)
    edge(y, z, dy, dz, ys, zs, to_edge, each, other, K, k, width)
    _update(c, x, z, y, dx, dy, dz, res, to_edge, done, each, phase_one, d, K, k, width)


def widened(A, b, wide, bw, c, x, z, d, K, k, width):
    """Phase I's problem of rows ``A (K, k, d, width)``, ``b (K, k, width)``: each cone widened by the margin ``r``,
    the last of ``d + 1`` unknowns (``t_m + r >= |z_m|``), and ``r + 1 >= 0`` a cone of its own, into ``wide
    (K + 1, k, d + 1, width)``, ``bw (K + 1, k, width)``; the objective ``c = e_r`` and the start: ``x = 0`` but
    ``r``, which clears every cone by 1 (or is 0), and ``z = 0.25 e`` (the dual, feasible in ``r``'s column).

    >>> A, b = np.array([[[[1.0]], [[0.0]]]]), np.array([[[-1.0], [0.5]]])  # one cone: (s - 1, 0.5)
    >>> wide, bw, z = np.empty((2, 2, 2, 1)), np.empty((2, 2, 1)), np.empty((2, 2, 1))
    >>> c, x = np.empty((2, 1)), np.empty((2, 1))
    >>> widened(A, b, wide, bw, c, x, z, 1, 1, 2, 1); x[:, 0].tolist(), wide[:, 0, 1, 0].tolist()
    ([0.0, 2.5], [1.0, 1.0])
    """
    for m in range(K):
        for j in range(d):
            for i in every(k):
                for ln in range(width):
                    wide[m, i, j, ln] = A[m, i, j, ln]
        for i in every(k):
            for ln in range(width):
                wide[m, i, d, ln] = 0.0
                bw[m, i, ln] = b[m, i, ln]
    for j in range(d + 1):
        for i in every(k):
            for ln in range(width):
                wide[K, i, j, ln] = 0.0
    for i in every(k):
        for ln in range(width):
            bw[K, i, ln] = 0.0
    for m in every(K + 1):
        for i in every(k):
            for ln in range(width):
                z[m, i, ln] = 0.0
    for ln in range(width):
        over = -np.inf
        for m in range(K):
            t = 0.0
            for i in range(1, k):
                t += b[m, i, ln] * b[m, i, ln]
            over = np.maximum(over, np.sqrt(t) - b[m, 0, ln])
        for m in range(K + 1):
            wide[m, 0, d, ln] = 1.0  # t_m + r, and r + 1
            z[m, 0, ln] = 0.25
        bw[K, 0, ln] = 1.0
        for j in range(d):
            x[j, ln] = 0.0
            c[j, ln] = 0.0
        x[d, ln] = np.maximum(over + 1, 0.0)
        c[d, ln] = 1.0


def lanes(a):
    """A row-major array's view in lane form, its rows last (``np.moveaxis(a, 0, -1)``, without its checks: a
    tenth of its cost on the small arrays of one grasp).

    >>> lanes(np.zeros((5, 3, 2))).shape
    (3, 2, 5)
    """
    return a.transpose((*range(1, a.ndim), 0))


#: The lane-form functions, in the order their twins are made (callers may call any of them).
LANE_FORM = (_cone_sum, _column, _w_inv, _w_mul, _residual, _scaling, _newton, _centre, spd_solve, _direction)
LANE_FORM += (_approach, edge, _corrector, _update, step, newton_part, widened)
