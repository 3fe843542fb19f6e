r"""Contact models as cones: what each contact can exert, and the grip over any mix of them.

A contact's generalised force is ``g_i = (f_i, tau_i / e_i)`` (the force, and the torsion
about its normal divided by the torsional radius ``e_i``: a force, so that the four numbers
compare and the cone's rows are all of order ``1 / mu``).
A contact model says which of them it can exert (the others are held at zero) and the
cone ``C_i g_i in K_i`` that bounds them, ``mu`` the friction over the safety factor:

=================  =====================  ==============================================
model              exerts                 cone
=================  =====================  ==============================================
frictionless       ``f = f_n n``          the ray ``f_n >= 0`` (``K = R_+``)
point (``Q^3``)    ``f``                  ``|f_t| <= mu f_n``
soft (``Q^4``)     ``f, tau``             ``|(f_t, tau / e)| <= mu f_n``, ``e`` the torsional radius
=================  =====================  ==============================================

Every cone is stored as ``4`` rows over the ``4`` coordinates, padded with zero rows: a
cone ``(t, z)`` with a component always zero is the same cone (and the interior-point
method keeps that component at zero: :mod:`~grasptwist.engine.forces.socp`).

The grip is then one programme for any mix: with ``E`` the rows that hold the models'
unused coordinates at zero, ``w' = D w`` the wrench about the contacts' centroid with its
moment divided by ``L`` and ``B = [G'; E]`` (``G'`` the grasp map of ``g``),

.. math:: \min_s \sum_i n_i \cdot f_i \quad\text{s.t.}\quad g = B^+ (w'; 0) + N s,\quad C_i g_i \in K_i

``N`` the null space of ``B``; the set-up (``B``, its pseudo-inverse and null space, by
SVD) is done once per grasp in numpy, on ``B``'s long columns scaled to unit length (:func:`shortened_columns`:
a torsion column ``(e_i / L) n_i`` dwarfs the forces' for a large ``e``, and the rank, the null space
and whether ``w`` is made would otherwise follow the round-off of its size).  The dual ``lambda = D^T lambda'`` with
``B^T (lambda'; .) = c - sum_i C_i^T z_i`` (``c_i = (n_i, 0)``), and a failed row's
certificate ``y = -D^T y'`` with ``B^T (y'; .) = sum_i C_i^T z_i`` (phase I's ``z``).

:func:`~grasptwist.engine.forces.grip.grip` sends here the rows with a soft contact (``torsion=``);
rows of point or frictionless contacts keep their own way (the squeezes in closed form, the
compiled kernel), so ``torsion=0`` is point contacts to the last bit.  The set-up and the finish
here are numpy; the interior-point iterations (:mod:`~grasptwist.engine.forces.socp`'s phase I,
phase II, dual polish) run compiled from :mod:`~grasptwist.engine.forces.ipm`'s source where
numba is on (:func:`compiled.iteration`), its numpy twin otherwise.  There is no facial
reduction: a grip that exists only on the cones' edge (no internal force strictly inside
them) is ``cannot-hold`` here.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..screws import cross
from . import socp
from .grasp_map import tangent_bases

__all__ = [
    "FRICTIONLESS",
    "POINT",
    "SOFT",
    "contact_models",
    "ConeGrasp",
    "cone_grasp",
    "cone_solve",
    "shortened_columns",
]

#: The contact models' codes (``contact_models``).
FRICTIONLESS, POINT, SOFT = 0, 1, 2

_SIZE = 4  # a contact's coordinates, and its cone's rows padded

#: Rows of the exerted coordinates: which of (f . n, f . b1, f . b2, tau) a model exerts.
_EXERTS = np.array([[1, 0, 0, 0], [1, 1, 1, 0], [1, 1, 1, 1]], bool)


def contact_models(friction, torsion):
    """Each contact's model: frictionless where ``mu = 0``, soft where also ``e > 0``, else point.

    ``(n, 3), (n, 3) -> (n, 3)`` int8.  Torsional friction is friction: ``mu = 0`` is frictionless whatever ``e``.

    >>> contact_models(np.array([[0.5, 0.0, 0.5]]), np.array([[0.01, 0.01, 0.0]])).tolist()
    [[2, 0, 1]]
    """
    return np.where(friction == 0, FRICTIONLESS, np.where(torsion > 0, SOFT, POINT)).astype(np.int8)


class ConeGrasp(NamedTuple):
    """The wrench-free part of the grip of ``n`` grasps over contact cones (:func:`cone_grasp`)."""

    frame: np.ndarray  # (n, 3, 4, 4): contact, cone row, coordinate (f in the world, tau / e)
    pinv: np.ndarray  # (n, 12, 6): g = pinv w' (generalised forces that make w', shortened_columns)
    null: np.ndarray  # (n, 12, 12): C^-1 times B C^-1's right singular vectors, the null space N last
    rank: np.ndarray  # (n,): B's rank (N has 12 - rank columns)
    grasp: np.ndarray  # (n, 18, 12): B
    torsion: np.ndarray  # (n, 3): e, 0 where the contact is not soft
    model: np.ndarray  # (n, 3)
    centroid: np.ndarray  # (n, 3)
    size: np.ndarray  # (n,) L


def _frames(unit, limit, model):
    """The cones' rows ``C_i (n, 3, 4, 4)``, and the contacts' bases ``(n, 3, 4, 4)`` (rows ``n, b1, b2``
    and the torsion's)."""
    b1, b2 = tangent_bases(unit)
    with np.errstate(divide="ignore", invalid="ignore"):
        kappa = np.where(np.isinf(limit), 0.0, 1 / limit)
    twist = np.where(model == SOFT, kappa, 0.0)
    frame = np.zeros(unit.shape[:2] + (_SIZE, _SIZE))
    frame[..., 0, :3] = unit
    rubs = (model != FRICTIONLESS)[..., None]
    frame[..., 1, :3] = np.where(rubs, kappa[..., None] * b1, 0.0)
    frame[..., 2, :3] = np.where(rubs, kappa[..., None] * b2, 0.0)
    frame[..., 3, 3] = twist
    basis = np.zeros_like(frame)
    basis[..., :3, :3] = np.stack((unit, b1, b2), axis=-2)
    basis[..., 3, 3] = 1.0
    return frame, basis


def cone_grasp(points, unit, limit, torsion, model) -> ConeGrasp:
    """The set-up of :func:`cone_solve` for ``n`` grasps, once in numpy: ``points, unit (n, 3, 3)``, ``limit``
    (``mu / safety``), ``torsion`` (``e``) and ``model`` ``(n, 3)``."""
    p = np.asarray(points, float)
    centroid = p.mean(axis=1)
    q = p - centroid[:, None]
    size = np.sqrt((q**2).sum(axis=-1).max(axis=-1))
    size = np.where(size > 0, size, 1.0)
    frame, basis = _frames(unit, limit, model)
    lever = np.where(model == SOFT, torsion, 0.0) / size[:, None]  # tau_i n_i / L = (e_i / L) (tau_i / e_i) n_i
    grasp = np.zeros((len(p), 6 + 3 * _SIZE, 3 * _SIZE))  # B = [G'; E]
    for i in range(3):
        cols = slice(_SIZE * i, _SIZE * i + 3)
        grasp[:, :3, cols] = np.eye(3)
        grasp[:, 3:6, cols] = _skew(q[:, i] / size[:, None])  # (q_i / L) x f
        grasp[:, 3:6, _SIZE * i + 3] = lever[:, i, None] * unit[:, i]
        idle = ~_EXERTS[model[:, i]]  # (n, 4): the coordinates the model holds at zero
        grasp[:, 6 + _SIZE * i : 6 + _SIZE * (i + 1), _SIZE * i : _SIZE * (i + 1)] = basis[:, i] * idle[..., None]
    short, c = shortened_columns(grasp)
    u, s, vt = np.linalg.svd(short, full_matrices=False)  # u (n, 18, 12), vt (n, 12, 12)
    rank = (s > 1e-12 * s[:, :1]).sum(axis=1)
    with np.errstate(divide="ignore"):
        inv = np.where(np.arange(s.shape[1]) < rank[:, None], 1 / s, 0.0)
    # the first six columns of X = C^-1 (B C^-1)^+, and the null space C^-1 N_s
    pinv = np.einsum("nij,ni,nki->njk", vt, inv, u[:, :6]) / c[..., None]
    null = np.swapaxes(vt, 1, 2) / c[..., None]
    e = np.where(model == SOFT, torsion, 0.0)
    return ConeGrasp(frame, pinv, null, rank, grasp, e, model, centroid, size)


def shortened_columns(b):
    r"""``(B C^{-1}, c)``: ``b (n, m, k)`` with its columns longer than one scaled to unit length, and the factors
    ``c = max(|B_j|, 1)`` ``(n, k)``.

    A soft contact's torsion column of ``B`` is ``(e_i / L) n_i``, any length against the forces' order-one
    columns: ranks, null spaces and pseudo-inverses are taken of ``B C^{-1}`` (whose singular values then
    mean the same however large ``e``) and mapped back, ``X = C^{-1} (B C^{-1})^+`` (``B X`` projects onto
    ``B``'s range, as ``B B^+`` does) and ``N = C^{-1} N_s``.  A short column is kept: lengthened, the null
    space's torsion ``tau / e`` would grow by ``L / e`` against the cones' rows of order ``1 / mu``.

    >>> b, c = shortened_columns(np.array([[[3.0, 0.5], [4.0, 0.0]]]))
    >>> b.tolist(), c.tolist()
    ([[[0.6, 0.5], [0.8, 0.0]]], [[5.0, 1.0]])
    """
    c = np.maximum(np.sqrt((b**2).sum(axis=-2)), 1.0)
    return b / c[..., None, :], c


def _skew(v):
    """``[v]_x`` with ``[v]_x f = v x f``: ``(n, 3) -> (n, 3, 3)``."""
    out = np.zeros(v.shape[:-1] + (3, 3))
    out[..., 0, 1], out[..., 0, 2] = -v[..., 2], v[..., 1]
    out[..., 1, 0], out[..., 1, 2] = v[..., 2], -v[..., 0]
    out[..., 2, 0], out[..., 2, 1] = -v[..., 1], v[..., 0]
    return out


def _scaled(setup, w):
    """``w' = D w``: the moment about the centroid, divided by ``L``: ``(n, 6) -> (n, 6)``."""
    moment = (w[:, 3:] - cross(setup.centroid, w[:, :3])) / setup.size[:, None]
    return np.concatenate((w[:, :3], moment), axis=1)


def _unscaled(setup, lam):
    """``D^T lambda'``: a multiplier of ``w'`` as one of ``w`` (``lambda . w = lambda' . w'``)."""
    angular = lam[:, 3:] / setup.size[:, None]
    return np.concatenate((lam[:, :3] - cross(angular, setup.centroid), angular), axis=1)


#: A wrench whose part outside the grasp map's range is above this (of its size) cannot be made.
_UNMADE = 1e-9


def cone_solve(setup: ConeGrasp, w):
    """The grip over the contacts' cones for wrenches ``w (n, 6)``.

    Returns ``force (n, 3, 3)``, ``torsion (n, 3)`` (``tau_i``), ``dual (n, 6)``, ``certificate (n, 6)``
    (unnormalised), ``fail`` (no grip within the cones), ``unmade`` (no forces at all make ``w``:
    collinear point contacts asked for a moment about their line) and ``blame (n)`` (the cone too
    narrow, or -1: the wrench needs pulling), NaN where they do not apply.

    A ball held at its equator, soft fingers (``e = 1 cm``): a lift needs ``m g / mu`` as with point
    contacts, and a turn about the vertical the fingers' torsions cannot make (their normals are
    horizontal) costs what it costs point contacts:

    >>> p = np.array([[[1, 0, 0], [-0.5, 0.75**0.5, 0], [-0.5, -(0.75**0.5), 0]]])
    >>> setup = cone_grasp(p, -p, np.full((1, 3), 0.5), np.full((1, 3), 0.01), np.full((1, 3), SOFT))
    >>> out = cone_solve(setup, np.array([[0, 0, 9.81, 0, 0, 0]]))
    >>> round(float(np.einsum("mx,mx->", out["force"][0], -p[0])), 6), (out["torsion"].round(9) + 0.0).tolist()
    (19.62, [[0.0, 0.0, 0.0]])
    """
    n = len(w)
    ws = _scaled(setup, w)
    # the part of (w'; 0) outside B's range: y' . w' = |y'|^2 > 0 and y' . G' g = 0 for every g B allows
    g0 = np.einsum("njk,nk->nj", setup.pinv, ws)
    outside = ws - np.einsum("nij,nj->ni", setup.grasp[:, :6], g0)
    scale = np.abs(ws).max(axis=1)
    unmade = np.sqrt((outside**2).sum(axis=1)) > _UNMADE * np.maximum(np.sqrt((ws**2).sum(axis=1)), 1e-300)
    out = {
        "force": np.full((n, 3, 3), np.nan),
        "torsion": np.full((n, 3), np.nan),
        "dual": np.full((n, 6), np.nan),
        "certificate": np.where(unmade[:, None], _unscaled(setup, outside), np.nan),
        "fail": np.zeros(n, bool),
        "unmade": unmade,
        "blame": np.full(n, -1, np.int8),
    }
    still = ~unmade & (scale == 0)
    out["force"][still], out["torsion"][still], out["dual"][still] = 0.0, 0.0, 0.0
    for d in np.unique(12 - setup.rank):
        rows = np.flatnonzero(~unmade & (scale > 0) & (setup.rank == 12 - d))
        if rows.size:
            _solve_rows(setup, ws[rows] / scale[rows, None], scale[rows], rows, int(d), out)
    return out


def _solve_rows(setup, ws, scale, rows, d, out):
    """:func:`cone_solve` on ``rows``, whose ``B`` has ``d`` internal forces, ``ws`` scaled to order one."""
    frame = setup.frame[rows]
    null = setup.null[rows][:, :, 12 - d :].reshape(-1, 3, _SIZE, d)
    g0 = np.einsum("njk,nk->nj", setup.pinv[rows], ws).reshape(-1, 3, _SIZE)
    A = frame @ null  # (n, 3, 4, d)
    b = np.einsum("nmkc,nmc->nmk", frame, g0)
    c = A[:, :, 0, :].sum(axis=1)
    x, r, z = socp.phase_one(A, b)
    fail = ~(r < 0)
    good = np.flatnonzero(~fail)
    s = np.full((len(rows), d), np.nan)
    if good.size:
        s[good], z[good] = socp.minimise(A[good], b[good], c[good], x[good])
        z[good] = socp.dual_polish(A[good], b[good], c[good], s[good], z[good])
    g = g0 + (null @ s[:, None, :, None])[..., 0] if d else g0
    # the coordinates a model holds at zero are zero, not round-off: no torsion but a soft contact's, and a
    # frictionless contact's force along its normal
    model = setup.model[rows]
    g = g * scale[:, None, None]
    g[..., 3] = np.where(model == SOFT, g[..., 3], 0.0)
    normal = frame[:, :, 0, :3]
    along = np.einsum("nmx,nmx->nm", g[..., :3], normal)[..., None] * normal
    g[..., :3] = np.where((model == FRICTIONLESS)[..., None], along, g[..., :3])
    u = np.einsum("nmkc,nmk->nmc", frame, z).reshape(-1, 3 * _SIZE)  # the cones' multipliers on g
    cost = np.zeros_like(frame[:, :, 0])
    cost[..., :3] = frame[:, :, 0, :3]  # c_i = (n_i, 0): the objective on g
    pinv = setup.pinv[rows]
    lam = np.einsum("njk,nj->nk", pinv, cost.reshape(-1, 3 * _SIZE) - u)
    y = -np.einsum("njk,nj->nk", pinv, u)
    grip = rows[good]
    out["force"][grip] = g[good, :, :3]
    out["torsion"][grip] = g[good, :, 3] * setup.torsion[grip]
    out["dual"][grip] = _unscaled(_at(setup, grip), lam[good])
    bad = np.flatnonzero(fail)
    if bad.size:
        out["fail"][rows[bad]] = True
        out["certificate"][rows[bad]] = _unscaled(_at(setup, rows[bad]), y[bad])
        cone = np.einsum("nmkd,nd->nmk", A[bad], x[bad]) + b[bad]
        blame = np.argmax(np.sqrt((cone[..., 1:] ** 2).sum(axis=-1)) - cone[..., 0], axis=1)
        rays = socp.phase_one(A[bad][:, :, :1], b[bad][:, :, :1])[1]  # unlimited friction: n . f >= 0 alone
        out["blame"][rows[bad]] = np.where(rays < 0, blame, -1)


def _at(setup, rows):
    return ConeGrasp(*(a[rows] for a in setup))
