r"""The grip compiled by numba (imported only through :mod:`~grasptwist.engine.forces.compiled`,
which loads it at the first grip).

:func:`grip_rows` does for each row what the numpy path does for the rows it solves by cones:
the set-up (the geometry and ``G^+ w``, the cones, a squeeze inside them and the start it gives,
the culprit of a row that cannot hold, the dual twist: :mod:`~grasptwist.engine.forces.set_up`'s
source compiled, each row's arrays a lane of width 1, whose numpy twins the numpy path runs), the interior-point
method of :mod:`~grasptwist.engine.forces.socp` (its iteration is
:mod:`~grasptwist.engine.forces.ipm`'s source compiled, whose numpy twin the numpy path runs:
Mehrotra's predictor-corrector with Nesterov-Todd scaling, 0.99 of the way to the cones' edge,
the same stopping rules; phase I, dual polish and culprits, the polish's scalar pieces
:mod:`~grasptwist.engine.forces.one`'s functions, compiled), the facial reduction of a grip on the cones' edge (:func:`_on_the_edge`, in
closed form), then the dual or the certificate and the figures.  The numpy path stays
the reference: ``tests/engine/test_forces.py`` holds the two to the same verdicts and totals to
``1e-9``.  A row of the method is ``A[m, k, j]`` (cone ``m``, component ``k``, unknown ``j``),
``b[m, k]``, ``c[j]``; ``d`` unknowns, ``K`` cones.  numpy's error model: a division by zero
is ``inf`` or NaN, which ends a row's iterations as a non-finite step does in numpy.

It goes through a chunk of rows in passes: set-up (each row), phase I and phase II (the rows
that need them in step, :data:`_LANES` at a time, :func:`_iterate`), finish (each row).  A row
keeps its own iterations and stopping, and its answer is the same to the last bit in any order or
company; alone (fewer rows than lanes: :func:`_iterate` compiled for one lane) to round-off
(``test_the_compiled_grip_answers_each_row_as_alone``).
"""

from __future__ import annotations

import math
import types
from itertools import accumulate

import numpy as np
from numba import literally, njit

from . import ipm, one, set_up
from .grasp_map import GRIP_COLUMNS
from .ipm import ITERATIONS as _ITERATIONS

__all__ = ["grip_rows", "WIDTH", "iterate_rows", "polish_rows"]

# no reference counting (numba's runtime) in the arithmetic: its atomic increments and decrements
# on every array passed or sliced were a fifth of a row's time; the workspaces are allocated by
# the functions that need the runtime (_ALLOC; _iterate, whose own arrays are passed to nothing)
_JIT = {"cache": True, "error_model": "numpy", "fastmath": {"arcp", "contract"}, "_nrt": False}
_ALLOC = {"cache": True}


def _compiled(functions, **options):
    """numba's compile of functions that call each other (:mod:`~grasptwist.engine.forces.ipm`'s lane form):
    each one's globals hold the others compiled, and LLVM inlines each into its callers (``forceinline``:
    numba's own inlining of so many bodies took minutes to compile)."""
    namespace = dict(functions[0].__globals__)
    out = {}
    for f in functions:
        twin = types.FunctionType(f.__code__, namespace, f.__name__, f.__defaults__, f.__closure__)
        namespace[f.__name__] = out[f.__name__] = njit(**options, forceinline=True)(twin)
    return out


# the interior-point method's iteration is ipm.py's source, compiled (the numpy path runs its twin); the
# facial reduction's and the dual polish's scalar pieces are one.py's functions, compiled
_ipm = _compiled(ipm.LANE_FORM, **_JIT)
_step, _newton_part, _spd_solve, _widened = _ipm["step"], _ipm["newton_part"], _ipm["spd_solve"], _ipm["widened"]
_workspace = njit(**_ALLOC, inline="always")(ipm.workspace)
_least_on_line, _dual_polish = (njit(**_JIT)(f) for f in (one.least_on_line, one.dual_polish))

# the set-up is set_up.py's source, compiled (the numpy path runs its twin), each row's arrays a lane of width 1
_set = _compiled(set_up.LANE_FORM, **_JIT)
_cross, _contact_geometry, _squeeze_directions = _set["_cross"], _set["contact_geometry"], _set["squeeze_directions"]
_unit_normals, _manipulating, _twist_through = _set["unit_normals"], _set["manipulating"], _set["twist_through"]
_cone_frames, _squeeze_map, _cone_rows = _set["cone_frames"], _set["squeeze_map"], _set["cone_rows"]
_internal_inside, _start_lanes, _culprit = _set["internal_inside"], _set["start"], _set["culprit"]
_inside_workspace = njit(**_ALLOC, inline="always")(set_up.inside_workspace)


#: Rows the interior-point method takes in step, each in a lane (the last axis of its workspace): the
#: divisions and roots of independent rows overlap and vectorise, where one row's wait on each other.
_LANES = 32

#: The most unknowns and cones a row has: phase I's three squeezes and a margin, four cones.
_D, _K = 4, 4

# The kernel's rows: three squeezes, three cones of three components (phase I: one more squeeze and cone).
# _iterate is compiled for these sizes and its width as constants (numba's literally; its loops unrolled).
_SQUEEZES, _CONES, _COMPONENTS = 3, 3, 3


@njit(**(_JIT | {"_nrt": True}))
def _iterate(A, b, c, x, z, order, phase_one, d, K, k, width):
    """``socp._iterate`` (``phase_one``: its leaving rule, else phase II's) on the rows ``order`` of
    ``A (R, K, k, d)``, ``b (R, K, k)``, ``c (R, d)``; their ``x (R, d)``, ``z (R, K, k)`` in place.

    The rows go through lanes (:func:`ipm.step`'s arrays, the last axis) in step, a row a lane; a lane
    whose row has finished (by its own count and rules, exactly as alone) takes the next.  Nothing mixes
    lanes, so a row's answer is the same in any company; an empty lane's numbers are never read.  Its
    arrays are its own, their shapes constants (``d, K, k, width`` literal), so the lanes' loops of
    :func:`ipm.step`, inlined, vectorise.
    """
    a, P = np.empty((K, k, d, width)), np.empty((K, d, d, width))
    bl, zl, cl, xl = np.empty((K, k, width)), np.empty((K, k, width)), np.empty((d, width)), np.empty((d, width))
    row, it, done = np.empty(width, np.int64), np.empty(width, np.int64), np.empty(width, np.bool_)
    last = np.empty(width, np.int64)
    work = _workspace(d, K, k, width)
    for ln in range(width):
        row[ln], last[ln] = -1, -1
    taken = 0
    while True:
        busy = 0
        for ln in range(width):
            if row[ln] < 0 and taken < order.size:
                r = order[taken]
                taken += 1
                row[ln], it[ln] = r, 0
                for m in range(K):
                    for i in range(k):
                        bl[m, i, ln], zl[m, i, ln] = b[r, m, i], z[r, m, i]
                        for j in range(d):
                            a[m, i, j, ln] = A[r, m, i, j]
                for j in range(d):
                    cl[j, ln], xl[j, ln] = c[r, j], x[r, j]
                _newton_part(a[:, :, :, ln : ln + 1], P[:, :, :, ln : ln + 1], d, K, k, 1)
            busy += row[ln] >= 0
        if busy == 0:
            return
        _step(a, bl, cl, xl, zl, P, phase_one, work, done, d, K, k, width)
        for ln in range(width):
            if row[ln] < 0:  # an empty lane keeps its last row's end (stepping on, it would near 0 and slow down)
                r = last[ln]
                if r >= 0:
                    for j in range(d):
                        xl[j, ln] = x[r, j]
                    for m in range(K):
                        for i in range(k):
                            zl[m, i, ln] = z[r, m, i]
                continue
            it[ln] += 1
            if done[ln] or it[ln] >= _ITERATIONS:
                r = row[ln]
                for j in range(d):
                    x[r, j] = xl[j, ln]
                for m in range(K):
                    for i in range(k):
                        z[r, m, i] = zl[m, i, ln]
                row[ln], last[ln] = -1, r


@njit(**_JIT)
def _in_lanes(A, b, c, x, z, order, phase_one, d, K, k):
    """:func:`_iterate` on the rows ``order``: in :data:`_LANES` lanes where they fill them, else one at a time
    (the lanes' loops compiled for a constant width: a row alone pays no vector code's set-up)."""
    d, K, k = literally(d), literally(K), literally(k)
    if order.size < _LANES:
        _iterate(A, b, c, x, z, order, phase_one, d, K, k, 1)
    else:
        _iterate(A, b, c, x, z, order, phase_one, d, K, k, _LANES)


@njit(**(_JIT | {"_nrt": True}))
def iterate_rows(A, b, c, x, z, phase_one):
    """:func:`socp._iterate` (``phase_one``: its leaving rule, else phase II's) on all the rows of
    ``A (n, K, k, d)``, ``b (n, K, k)``, ``c (n, d)``, from ``x (n, d)`` and ``z (n, K, k)``, moved in place.

    :func:`socp.phase_one`, :func:`~socp.minimise` (and so the soft contacts' grip,
    :mod:`~grasptwist.engine.forces.cones`, and every other programme set up in numpy) run their
    iterations here where numba is on: :func:`_iterate` with the sizes as numbers, not literal,
    so one compile (some 20 s on a fresh install, :func:`compiled.iteration`) serves every
    ``(d, K, k)``, at about 1.7 times the time of a literal size's unrolled loops
    (:func:`_in_lanes`, a compile per size).  :data:`_LANES` lanes where the rows fill them,
    else one.
    """
    n, K, k, d = A.shape
    _iterate(A, b, c, x, z, np.arange(n), phase_one, d, K, k, _LANES if n >= _LANES else 1)


@njit(**(_JIT | {"_nrt": True}))
def polish_rows(A, b, c, s, z):
    """:func:`socp.dual_polish` on all the rows (:func:`one.dual_polish` each): ``z (n, K, k)`` in place,
    from ``A (n, K, k, d)``, ``b (n, K, k)``, ``c (n, d)`` and the optimum ``s (n, d)``."""
    n, K, k, d = A.shape
    omega, h, dz = np.empty(K), np.empty((d, d + 1)), np.empty((K, k))
    for r in range(n):
        _dual_polish(A[r], b[r], c[r], s[r], z[r], omega, h, dz)


@njit(**_JIT)
def _rays(A, b, ray_a, ray_b):
    """A row's cones with no friction limit into ``ray_a``, ``ray_b`` (lanes of width 1): their tangential rows 0."""
    for m in range(3):
        for k in range(3):
            ray_b[m, k, 0] = b[m, k, 0] if k == 0 else 0.0
            for j in range(3):
                ray_a[m, k, j, 0] = A[m, k, j, 0] if k == 0 else 0.0


@njit(**_JIT)
def _start(A, b, inside, c, x):
    """``grip._solve``'s objective ``c`` (the normal forces' sum) and, where the contacts are in force
    closure (``inside`` finite), its start ``x`` (:func:`set_up.start`; the row's arrays lanes of width 1);
    whether there is one (else phase I finds it)."""
    for j in range(3):
        c[j] = A[0, 0, j, 0] + A[1, 0, j, 0] + A[2, 0, j, 0]
    if math.isnan(inside[0, 0]):
        return False
    _start_lanes(A, b, inside, x, 3, 1)
    return not math.isnan(x[0, 0])


@njit(**_JIT)
def _bare(z, m, top):
    """Whether phase I's multiplier ``z_m`` is strictly inside its cone: contact ``m`` carries nothing."""
    return z[m, 0] - math.hypot(z[m, 1], z[m, 2]) > 1e-6 * top


@njit(**_JIT)
def _on_the_edge(A, b, M, fm, scale, frame, z, s, zk, h, res, delta, line_a, line_b):
    """``grip._on_the_edge`` for a kernel row (three squeezes) in closed form; False leaves the row to numpy.

    Phase I's ``z`` says which contacts are bare.  Their forces ``fm_m / scale + M_m s = 0`` give the
    squeezes ``s0`` (least squares by the normal equations; one bare contact ``i`` leaves squeeze ``i``,
    which moves no force at ``i``, free and 0 in ``s0``, as ``lstsq``'s least norm).  One bare contact:
    ``s0 + t e_i`` is a line through the two other cones, each holding on an interval of ``t``
    (:func:`_line_in_cone`); the least total is at the end the objective falls towards, and the cone
    ending there carries the only multiplier, ``z = c / (a^T J y) J y``.  Two bare contacts: ``s0``,
    where the third cone must hold.  Into ``s (3)`` and the kept cones' multipliers ``zk (3, 3)``.
    """
    top = _top(z)
    for m in range(3):
        if not _kappa(frame, m) > 0:  # no friction limit: the cones are half-spaces (numpy's)
            return False
    count, free = 0, -1
    for i in range(3):
        res[i, 0] = 0.0
        for j in range(3):
            h[i, j, 0] = 0.0
    for m in range(3):
        for k in range(3):
            zk[m, k] = 0.0
        if _bare(z, m, top):
            count += 1
            free = m
            for i in range(3):
                for k in range(3):
                    res[i, 0] -= M[m, k, i] * fm[m, k] / scale
                    for j in range(3):
                        h[i, j, 0] += M[m, k, i] * M[m, k, j]
    if count == 0 or count == 3:
        return False
    if count == 1:
        h[free, free, 0] = 1.0  # squeeze `free` is no unknown of the bare contact's force: 0 in s0
    _spd_solve(h, res, delta, 3, 1)
    for m in range(3):
        if _bare(z, m, top):
            for k in range(3):
                if (
                    not abs(
                        fm[m, k] / scale
                        + M[m, k, 0] * delta[0, 0]
                        + M[m, k, 1] * delta[1, 0]
                        + M[m, k, 2] * delta[2, 0]
                    )
                    <= 1e-9
                ):
                    return False
    for j in range(3):
        s[j] = delta[j, 0]
    kept = 0
    for m in range(3):
        if _bare(z, m, top):
            continue
        for k in range(3):
            line_a[kept, k] = A[m, k, free]
            line_b[kept, k] = b[m, k] + A[m, k, 0] * s[0] + A[m, k, 1] * s[1] + A[m, k, 2] * s[2]
        if count == 2:  # no freedom left: the kept cone holds at s0, its multiplier 0 closes the gap
            y0, y1, y2 = line_b[0, 0], line_b[0, 1], line_b[0, 2]
            return y0 >= math.hypot(y1, y2) - 1e-12 * max(abs(y0), abs(y1), abs(y2))
        kept += 1
    t, m, coef = _least_on_line(line_a, line_b, 2)
    if m < 0:
        return False
    s[free] += t
    m = m + (m >= free)  # the kept cones' m-th
    y0 = b[m, 0] + A[m, 0, 0] * s[0] + A[m, 0, 1] * s[1] + A[m, 0, 2] * s[2]
    y1 = b[m, 1] + A[m, 1, 0] * s[0] + A[m, 1, 1] * s[1] + A[m, 1, 2] * s[2]
    y2 = b[m, 2] + A[m, 2, 0] * s[0] + A[m, 2, 1] * s[1] + A[m, 2, 2] * s[2]
    zk[m, 0], zk[m, 1], zk[m, 2] = coef * y0, -coef * y1, -coef * y2
    return True


@njit(**_JIT)
def _edge_dual(q, g, unit, frame, z, zk, y, out):
    """``grip._edge_dual`` in closed form: the least-norm twist ``lambda`` whose field at the kept contacts is
    ``n_m - u_m`` (``u_m = F_m^T zk_m``), plus ``alpha y`` enough for the bare contacts' dual cones.

    Two kept contacts ``i, j`` (``v = p_i - p_j``, ``r = d_i - d_j``): ``lambda_M = v x r / |v|^2 + a v``,
    ``lambda_F = mean(d) - lambda_M x mean(p)``, ``a`` the least norm's; one kept contact ``i``:
    ``lambda_M = p_i x d_i / (1 + |p_i|^2)``, ``lambda_F = d_i - lambda_M x p_i``."""
    top, kept, first, last = _top(z), 0, -1, -1
    for m in range(3):
        if not _bare(z, m, top):
            kept += 1
            first = m if first < 0 else first
            last = m
    d0, d1, d2 = _rest(unit, frame, zk, first)
    e0, e1, e2 = _rest(unit, frame, zk, last)
    pi0, pi1, pi2 = q[first, 0] + g[0], q[first, 1] + g[1], q[first, 2] + g[2]
    if kept == 1:
        m0, m1, m2 = _cross(pi0, pi1, pi2, d0, d1, d2)
        pp = 1 + pi0 * pi0 + pi1 * pi1 + pi2 * pi2
        m0, m1, m2 = m0 / pp, m1 / pp, m2 / pp
        c0, c1, c2 = _cross(m0, m1, m2, pi0, pi1, pi2)
        f0, f1, f2 = d0 - c0, d1 - c1, d2 - c2
    else:
        pj0, pj1, pj2 = q[last, 0] + g[0], q[last, 1] + g[1], q[last, 2] + g[2]
        v0, v1, v2 = pi0 - pj0, pi1 - pj1, pi2 - pj2
        vv = v0 * v0 + v1 * v1 + v2 * v2
        m0, m1, m2 = _cross(v0, v1, v2, d0 - e0, d1 - e1, d2 - e2)
        m0, m1, m2 = m0 / vv, m1 / vv, m2 / vv
        a0, a1, a2 = (pi0 + pj0) / 2, (pi1 + pj1) / 2, (pi2 + pj2) / 2
        c0, c1, c2 = _cross(m0, m1, m2, a0, a1, a2)
        f0, f1, f2 = (d0 + e0) / 2 - c0, (d1 + e1) / 2 - c1, (d2 + e2) / 2 - c2
        w0, w1, w2 = _cross(v0, v1, v2, a0, a1, a2)
        along = (f0 * w0 + f1 * w1 + f2 * w2) / (w0 * w0 + w1 * w1 + w2 * w2 + vv)
        m0, m1, m2 = m0 + along * v0, m1 + along * v1, m2 + along * v2
        f0, f1, f2 = f0 - along * w0, f1 - along * w1, f2 - along * w2
    out[0], out[1], out[2], out[3], out[4], out[5] = f0, f1, f2, m0, m1, m2
    alpha = 0.0
    for m in range(3):
        if not _bare(z, m, top):
            continue
        pm0, pm1, pm2 = q[m, 0] + g[0], q[m, 1] + g[1], q[m, 2] + g[2]
        c0, c1, c2 = _cross(m0, m1, m2, pm0, pm1, pm2)
        need = -_margin(unit[m, 0] - f0 - c0, unit[m, 1] - f1 - c1, unit[m, 2] - f2 - c2, unit[m], _kappa(frame, m))
        c0, c1, c2 = _cross(y[3], y[4], y[5], pm0, pm1, pm2)
        gain = _margin(-y[0] - c0, -y[1] - c1, -y[2] - c2, unit[m], _kappa(frame, m))
        alpha = max(alpha, max(need, 0.0) / gain)
    for k in range(6):
        out[k] += alpha * y[k]


@njit(**_JIT)
def _margin(v0, v1, v2, n, kappa):
    """``v_n - |v_t| / kappa`` (``kappa = 1 / limit``): ``> 0`` inside the dual cone (``grip._dual_cone_margin``)."""
    vn = v0 * n[0] + v1 * n[1] + v2 * n[2]
    t0, t1, t2 = v0 - vn * n[0], v1 - vn * n[1], v2 - vn * n[2]
    return vn - math.sqrt(t0 * t0 + t1 * t1 + t2 * t2) / kappa


@njit(**_JIT)
def _top(z):
    """The largest ``|z_mk|``."""
    top = 0.0
    for m in range(3):
        for k in range(3):
            top = max(top, abs(z[m, k]))
    return top


@njit(**_JIT)
def _kappa(frame, m):
    """``|F_m[1]| = 1 / limit``: the cone's slope (0: no friction limit)."""
    return math.sqrt(frame[m, 1, 0] ** 2 + frame[m, 1, 1] ** 2 + frame[m, 1, 2] ** 2)


@njit(**_JIT)
def _rest(unit, frame, zk, m):
    """``n_m - F_m^T zk_m``: what the dual twist's field must be at a kept contact."""
    return (
        unit[m, 0] - (frame[m, 0, 0] * zk[m, 0] + frame[m, 1, 0] * zk[m, 1] + frame[m, 2, 0] * zk[m, 2]),
        unit[m, 1] - (frame[m, 0, 1] * zk[m, 0] + frame[m, 1, 1] * zk[m, 1] + frame[m, 2, 1] * zk[m, 2]),
        unit[m, 2] - (frame[m, 0, 2] * zk[m, 0] + frame[m, 1, 2] * zk[m, 1] + frame[m, 2, 2] * zk[m, 2]),
    )


# where each of grasp_map.GRIP_COLUMNS starts, and the row's width
_F, _FM, _S, _FN, _FT, _USED, _TOTAL, _COND, _DUAL, _GAP, _CERT, WIDTH = accumulate(
    (w for _, w in GRIP_COLUMNS), initial=0
)

#: A row's stage between the passes: left to numpy; no wrench (no force); phase I to find a start; phase
#: II from a start; cannot hold (phase I found none).
_SKIP, _NONE, _OPEN, _HOLD, _FAIL = range(5)

#: Rows set up at a time: the passes keep some 2 kB a row between them.
_CHUNK = 2048


@njit(**_JIT)
def _set_up(r, p, n, limit, w, tol, o, codes, lane, q, mv, g, sizes, unit, fm, frame, M, A, b, inside, work):
    """Row ``r``'s set-up pass: its geometry, ``G^+ w``, cones and a squeeze inside them
    (:mod:`~grasptwist.engine.forces.set_up`'s functions on its arrays, lanes of width 1; ``lane``: its inputs
    and scratch) into the arrays given (``o``: its row of ``out``); ``(stage, scale)``, the stage one of
    :data:`_SKIP`, :data:`_NONE`, :data:`_OPEN`."""
    pl, nl, ll, wl, e, side, scale1, omega = lane
    codes[r, 0], codes[r, 1], codes[r, 2] = 0, -1, 0
    plain = True
    for i in range(3):
        for k in range(3):
            pl[i, k, 0], nl[i, k, 0] = p[r, i, k], n[r, i, k]
            plain = plain and math.isfinite(p[r, i, k]) and math.isfinite(n[r, i, k])
        ll[i, 0] = limit[r, i]
        plain = plain and limit[r, i] > 0  # NaN and 0 (frictionless, mixed) to numpy
    for k in range(6):
        wl[k, 0] = w[r, k]
        plain = plain and math.isfinite(w[r, k])
    if not plain:
        return _SKIP, 0.0
    # geometry (grasp_map.geometry): degenerate rows (coincident, collinear, a zero normal) to numpy
    _contact_geometry(pl, g, q, mv, sizes, 1)
    _squeeze_directions(pl, e, side, 1)
    _unit_normals(nl, unit, 1)
    t = sizes[0, 0]
    plain = t > 0 and sizes[2, 0] > tol
    for i in range(3):
        plain = plain and side[i, 0] > tol * math.sqrt(t) and not math.isnan(unit[i, 0, 0])
    if not plain:
        return _SKIP, 0.0
    _manipulating(g, q, mv, sizes, wl, fm, omega, 1)
    scale = 0.0
    for i in range(3):
        for k in range(3):
            o[_FM + 3 * i + k] = fm[i, k, 0]
            scale = max(scale, abs(fm[i, k, 0]))
            plain = plain and math.isfinite(fm[i, k, 0])
    if not plain:  # overflow: nonfinite-result, said by the numpy path
        return _SKIP, 0.0
    o[_COND] = sizes[2, 0]
    for k in range(6):
        o[_CERT + k] = math.nan
    if scale == 0:  # no wrench: no force at all is the least
        for k in range(6):
            o[_DUAL + k] = 0.0
        return _NONE, scale
    # the cones, the squeezes' map and the method's rows; a squeeze strictly inside them
    scale1[0] = scale
    _cone_frames(unit, ll, frame, 1)
    _squeeze_map(e, M, 1)
    _cone_rows(frame, M, fm, scale1, A, b, 3, 1)
    _internal_inside(pl, unit, mv, M, ll, inside, work, 1)
    return _OPEN, scale


@njit(**_JIT)
def _finish(r, w, o, codes, fail, blame, q, mv, g, sizes, unit, fm, frame, M, scale, s, z, dl, twist, A, b, work):
    """Row ``r``'s last pass: the dual or the certificate (``z``: the multipliers of phase II or of a
    failed phase I), the forces of the squeezes ``s`` and their figures into ``o`` (its row of ``out``).

    Its set-up arrays are lanes of width 1 (:func:`_set_up`'s), seen here without the lane axis; ``dl (3, 3, 1)``
    and ``twist (6, 1)``: the dual twist's lanes."""
    lam, d = twist[:, 0], dl[:, :, 0]
    dual = (g, q, mv, sizes, dl, twist)
    q, g, unit, fm = q[:, :, 0], g[:, 0], unit[:, :, 0], fm[:, :, 0]
    frame, M = frame[:, :, :, 0], M[:, :, :, 0]
    if scale:
        # the multipliers as forces' duals; the dual twist through n_i - u_i, phase I's y through -u_i
        for i in range(3):
            for k in range(3):
                d[i, k] = frame[i, 0, k] * z[i, 0] + frame[i, 1, k] * z[i, 1] + frame[i, 2, k] * z[i, 2]
        if fail:
            _twist_through(*dual, 1)
            for k in range(6):
                lam[k] = -lam[k]
            yw, yy, ww = 0.0, 0.0, 0.0
            for k in range(6):
                yw += lam[k] * w[r, k]
                yy += lam[k] * lam[k]
                ww += w[r, k] * w[r, k]
            if yw > 1e-8 * math.sqrt(yy) * math.sqrt(ww):  # grip._EDGE_OF_HOLD
                length = math.sqrt(
                    lam[0] ** 2 + lam[1] ** 2 + lam[2] ** 2 + sizes[1, 0] * (lam[3] ** 2 + lam[4] ** 2 + lam[5] ** 2)
                )
                for k in range(6):
                    o[_CERT + k] = lam[k] / length
                    o[_DUAL + k] = math.nan
            else:  # on the edge of what the fingers exert: the facial reduction, else the row is numpy's
                h, res, delta, zk, line_a, line_b = work
                if not _on_the_edge(A, b, M, fm, scale, frame, z, s, zk, h, res, delta, line_a, line_b):
                    return
                _edge_dual(q, g, unit, frame, z, zk, lam, o[_DUAL : _DUAL + 6])
                fail = False
        else:
            for i in range(3):
                for k in range(3):
                    d[i, k] = unit[i, k] - d[i, k]
            _twist_through(*dual, 1)
            for k in range(6):
                o[_DUAL + k] = lam[k]
    codes[r, 0], codes[r, 1] = (20, blame) if fail else (0, -1)
    # the forces and their figures (grip._Prepared.solve, grasp_map.checked_grip)
    top, total, finite = 0.0, 0.0, True
    for i in range(3):
        for k in range(3):
            f = fm[i, k] + scale * (M[i, k, 0] * s[0] + M[i, k, 1] * s[1] + M[i, k, 2] * s[2]) if scale else 0.0
            o[_F + 3 * i + k] = math.nan if fail else f
            top = max(top, abs(f))
        o[_S + i] = math.nan if fail else scale * s[i]
    for i in range(3):
        fn = 0.0
        for k in range(3):
            fn += o[_F + 3 * i + k] * unit[i, k]
        ft2 = 0.0
        for k in range(3):
            tk = o[_F + 3 * i + k] - fn * unit[i, k]
            ft2 += tk * tk
        ft = math.sqrt(ft2)
        o[_FN + i], o[_FT + i] = fn, ft
        o[_USED + i] = 0.0 if not fail and ft <= 1e-12 * top else ft / fn
        total += fn
        finite = finite and math.isfinite(fn) and math.isfinite(ft) and math.isfinite(o[_USED + i])
    o[_TOTAL] = total
    finite = finite and math.isfinite(total)
    gap = total
    for k in range(6):
        gap -= w[r, k] * o[_DUAL + k]
        finite = finite and math.isfinite(o[_DUAL + k])
    o[_GAP] = gap
    codes[r, 2] = 1 if fail or (finite and math.isfinite(gap)) else 0


@njit(**_ALLOC)
def grip_rows(p, n, limit, w, tol, out, codes):
    """The whole grip of the rows numpy's :class:`grip._Prepared` solves by cones (three distinct,
    non-collinear contacts, friction at each).

    ``out (n, WIDTH)``: the fields of :data:`grasp_map.GRIP_COLUMNS`; ``codes (n, 3)`` int8: status,
    culprit, plain.  ``plain = 0`` leaves a row to the numpy path: any other kind of row, a
    non-finite number (input, or an overflow on the way), a wrench on the edge of what the fingers
    exert.  ``limit (n, 3)`` is ``mu / safety``.
    """
    rows = min(p.shape[0], _CHUNK)
    _grip_rows(p, n, limit, w, tol, out, codes, _chunk(rows), _grip_workspace())


@njit(**_ALLOC)
def _chunk(rows):
    """What the passes keep of each of ``rows`` rows: geometry, ``G^+ w``, cones, both phases' problems and answers,
    a squeeze inside the cones, sizes (``t``, the largest ``|q_i|^2``, the conditioning; the scale), stage,
    culprit, and the rows of each phase.  Each row's arrays are lanes of width 1 (a trailing axis), as
    :mod:`~grasptwist.engine.forces.set_up`'s and :func:`ipm.widened` write them; the method sees them
    without it (one reshape of the chunk: a row's reshape costs 14 ns)."""
    f, i = np.empty, np.int64
    return (
        (
            f((rows, 3, 3, 1)),
            f((rows, 3, 1)),
            f((rows, 3, 1)),
            f((rows, 3, 3, 1)),
            f((rows, 3, 3, 1)),
            f((rows, 3, 3, 3, 1)),
        ),
        (
            f((rows, 3, 3, 3, 1)),
            f((rows, 3, 3, 3, 1)),
            f((rows, 3, 3, 1)),
            f((rows, 3)),
            f((rows, 3, 1)),
            f((rows, 3, 3)),
        ),
        (f((rows, _K, 3, _D, 1)), f((rows, _K, 3, 1)), f((rows, _D, 1)), f((rows, _D, 1)), f((rows, _K, 3, 1))),
        f((rows, 3, 1)),
        (f((rows, 3, 1)), f(rows)),
        (np.empty(rows, i), np.empty(rows, i), np.empty(rows, i), np.empty(rows, i), np.empty(rows, i)),
    )


@njit(**_ALLOC)
def _grip_workspace():
    """One row's scratch arrays, lanes of width 1: its inputs and the set-up's (``p, n, limit, w, e``, the sides,
    the scale, omega), :func:`set_up.internal_inside`'s, the dual twist's ``d`` and twist; :func:`_dual_polish`'s,
    :func:`_on_the_edge`'s, :func:`set_up.culprit`'s and the rays' cones."""
    f = np.empty
    return (
        (f((3, 3, 1)), f((3, 3, 1)), f((3, 1)), f((6, 1)), f((3, 3, 1)), f((3, 1)), f(1), f((3, 1))),
        _inside_workspace(1),
        f((3, 3, 1)),
        f((6, 1)),
        (np.empty(3), np.empty((3, 3, 1)), np.empty((3, 1)), np.empty((3, 1)), np.empty((3, 3))),
        (np.empty((2, 3)), np.empty((2, 3)), np.empty((3, 4))),
        (np.empty(1, np.int64), np.empty(1, np.bool_), f((3, 3, 3, 1)), f((3, 3, 1))),
    )


@njit(**_JIT)
def _grip_rows(p, n, limit, w, tol, out, codes, chunk, gw):
    """:func:`grip_rows` a chunk of rows at a time, in passes: set-up, phase I (then phase I on the rays,
    for a culprit), phase II, finish; the phases' rows in step (:func:`_iterate`)."""
    (q, mv, g, unit, fm, frame), (M, A, b, c, x, z), (wide, bw, cw, xw, zw), inside, (sizes, scale), lists = chunk
    stage, blame, one, two, again = lists
    # the method's view of the rows' lanes (one reshape each, of the whole chunk)
    A4, b4, x2, cw2, xw2 = (
        A.reshape(A.shape[:4]),
        b.reshape(b.shape[:3]),
        x.reshape(x.shape[:2]),
        cw.reshape(cw.shape[:2]),
        xw.reshape(xw.shape[:2]),
    )
    wide4, bw3, zw3 = wide.reshape(wide.shape[:4]), bw.reshape(bw.shape[:3]), zw.reshape(zw.shape[:3])
    lane, inside_work, d, lam, (omega, h, res, delta, dz), (line_a, line_b, polish), (who, pulling, ray_a, ray_b) = gw
    for first in range(0, p.shape[0], _CHUNK):  # no rows: no chunk
        rows = min(_CHUNK, p.shape[0] - first)
        ones, twos, agains = 0, 0, 0
        for i in range(rows):
            r = first + i
            stage[i], scale[i] = _set_up(
                r,
                p,
                n,
                limit,
                w,
                tol,
                out[r],
                codes,
                lane,
                q[i],
                mv[i],
                g[i],
                sizes[i],
                unit[i],
                fm[i],
                frame[i],
                M[i],
                A[i],
                b[i],
                inside[i],
                inside_work,
            )
            blame[i] = -1
            if stage[i] == _NONE:
                x2[i, 0], x2[i, 1], x2[i, 2] = 0.0, 0.0, 0.0
            elif stage[i] == _OPEN:
                if _start(A[i], b[i], inside[i], c[i], x[i]):
                    stage[i], two[twos] = _HOLD, i
                    twos += 1
                else:
                    _widened(A[i], b[i], wide[i], bw[i], cw[i], xw[i], zw[i], 3, 3, 3, 1)
                    one[ones] = i
                    ones += 1
        _in_lanes(wide4, bw3, cw2, xw2, zw3, one[:ones], True, _D, _K, _COMPONENTS)
        for k in range(ones):
            i = one[k]
            for j in range(3):
                x2[i, j] = xw2[i, j]
            if xw2[i, 3] < 0:
                stage[i], two[twos] = _HOLD, i
                twos += 1
                continue
            stage[i] = _FAIL
            for m in range(3):
                for j in range(3):
                    z[i, m, j] = zw3[i, m, j]
            _culprit(A[i], b[i], x[i], who, pulling, 3, 1)
            blame[i] = who[0]
            if pulling[0]:
                _rays(A[i], b[i], ray_a, ray_b)
                _widened(ray_a, ray_b, wide[i], bw[i], cw[i], xw[i], zw[i], 3, 3, 3, 1)
                again[agains] = i
                agains += 1
            for j in range(3):
                x2[i, j] = math.nan
        _in_lanes(wide4, bw3, cw2, xw2, zw3, again[:agains], True, _D, _K, _COMPONENTS)
        for k in range(agains):
            if not xw2[again[k], 3] < 0:
                blame[again[k]] = -1
        for k in range(twos):
            for m in range(3):
                z[two[k], m, 0], z[two[k], m, 1], z[two[k], m, 2] = 1.0, 0.0, 0.0
        _in_lanes(A4, b4, c, x2, z, two[:twos], False, _SQUEEZES, _CONES, _COMPONENTS)
        for i in range(rows):
            if stage[i] == _SKIP:
                continue
            if stage[i] == _HOLD:
                _dual_polish(A4[i], b4[i], c[i], x2[i], z[i], omega, polish, dz)
            r = first + i
            _finish(
                r,
                w,
                out[r],
                codes,
                stage[i] == _FAIL,
                blame[i],
                q[i],
                mv[i],
                g[i],
                sizes[i],
                unit[i],
                fm[i],
                frame[i],
                M[i],
                scale[i],
                x2[i],
                z[i],
                d,
                lam,
                A4[i],
                b4[i],
                (h, res, delta, dz, line_a, line_b),
            )
