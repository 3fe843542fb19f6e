r"""The grip: the least total normal force that exerts a wrench within the friction cones.

.. math::

    \min_{s \in \mathbb{R}^3}\; \sum_i f_i \cdot n_i \quad \text{s.t.} \quad
    f = G^+ w + \mathrm{squeeze}(s), \qquad |f_i - (f_i \cdot n_i) n_i| \le \frac{\mu_i}{s_f}\, f_i \cdot n_i

a second-order cone program in the three squeezes (``s_f`` the safety factor), solved
for every row together by :mod:`~grasptwist.engine.forces.socp`.  Frictionless grasps
(``mu = 0`` at every contact: the cones are rays) are solved in closed form instead:
``f_i = lambda_i n_i`` with ``sum lambda_i nu_i = w`` (``nu_i`` the normal lines).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..checks import check_normals, check_points
from ..degeneracy import DEGENERACY_TOL
from ..screws import cross, dot, norm
from . import closure, socp
from .grasp_map import (
    ForceStatus,
    _manipulating,
    check_friction,
    check_safety,
    check_wrench,
    contact_matrices,
    geometry,
    squeeze_forces,
    tangent_bases,
)

__all__ = ["Grip", "grip", "cone_rows"]

#: Rows solved together: enough for numpy's per-call cost to be noise, few enough for the
#: solver's temporaries to stay in the CPU cache.
CHUNK = 8192

#: A wrench reproduced to this, relative to the forces' size, counts as made (frictionless grasps).
RESIDUAL_TOL = 1e-9


@dataclass(frozen=True, eq=False)
class Grip:
    """The least-total-normal-force grip of a batch of (grasp, wrench, friction) rows.

    Attributes
    ----------
    force : (..., 3, 3)
        ``f = manipulating + squeeze_forces(squeeze)``, row ``i`` the force contact
        ``i`` exerts on the object.  NaN where ``status != 0``.
    manipulating : (..., 3, 3)
        ``G^+ w`` (NaN only for degenerate contacts).
    squeeze : (..., 3)
        The squeezes along the sides opposite each contact (positive: compression).
    normal_force, tangential_force : (..., 3)
        ``f_i . n_i`` and ``|f_i - (f_i . n_i) n_i|``.
    friction_used : (...,  3)
        ``tangential_force / normal_force``; at most ``friction / safety``.
    total_normal_force : (...)
        The objective, ``sum_i f_i . n_i``.
    safety : float
    conditioning : (...)
        As :class:`~grasptwist.engine.forces.grasp_map.ManipulatingForces`.
    status, culprit : (...) int8
        :class:`~grasptwist.forces.Status`; for
        ``cannot-hold`` the culprit is the contact whose cone is too narrow, or
        -1 when the wrench needs pulling
        (:func:`~grasptwist.forces.status_message`).
    """

    force: np.ndarray
    manipulating: np.ndarray
    squeeze: np.ndarray
    normal_force: np.ndarray
    tangential_force: np.ndarray
    friction_used: np.ndarray
    total_normal_force: np.ndarray
    safety: float
    conditioning: np.ndarray
    status: np.ndarray
    culprit: np.ndarray

    @property
    def ok(self) -> np.ndarray:
        """``status == 0`` per row."""
        return self.status == ForceStatus.OK


def _frictionless(nu, w, tol):
    """``f_i = lambda_i n_i`` with ``sum lambda_i nu_i = w``, ``lambda >= 0``, least ``sum lambda``.

    ``nu (n, 3, 6)`` unit normal lines, ``w (n, 6)`` scaled to order one.  Returns
    ``lam (n, 3)`` (NaN where none exists), ``needs_pulling (n)``, ``culprit (n)``.
    """
    k = np.swapaxes(nu, -1, -2)  # (n, 6, 3)
    u, sv, vt = np.linalg.svd(k, full_matrices=False)
    rank3 = sv[:, 2] > tol * sv[:, 0]
    with np.errstate(divide="ignore"):
        inv = np.where(rank3[:, None] | (np.arange(3) < 2), 1 / sv, 0.0)
    lam = np.einsum("nji,nj,nkj,nk->ni", vt, inv, u, w)  # the least-squares lambda
    made = norm_rows(np.einsum("nij,nj->ni", k, lam) - w) <= tol * np.maximum(norm_rows(w), 1e-300)
    z = vt[:, 2]  # the null direction when rank 2: a free squeeze along the normals
    z = np.where((z.sum(axis=1) < 0)[:, None], -z, z)
    with np.errstate(divide="ignore", invalid="ignore"):
        bound = np.where(z > tol, -lam / z, -np.inf).max(axis=1)  # lam + t z >= 0 from below
        upper = np.where(z < -tol, -lam / z, np.inf).min(axis=1)
    t = np.where(rank3, 0.0, bound)
    lam = np.where(rank3[:, None], lam, lam + t[:, None] * z)
    pushes = np.where(rank3, (lam >= -tol).all(axis=1), (bound <= upper) & np.isfinite(bound))
    lam = np.where((made & pushes)[:, None], np.maximum(lam, 0), np.nan)
    return lam, made & ~pushes, ~made


def norm_rows(a):
    return np.sqrt(np.einsum("ni,ni->n", a, a))


def grip(points, normals, wrench, friction, safety=1.0, *, tol=DEGENERACY_TOL) -> Grip:
    r"""The finger forces that exert ``wrench`` with the least total normal force, inside every cone.

    Parameters
    ----------
    points, normals : (..., 3, 3) arrays
        Contacts and their normals (into the object; any non-zero length).
    wrench : (..., 6) array
        ``(force; moment about the origin)`` the fingers must exert on the object
        (to hold a weight ``m g``: ``(-m g; -c x m g)``, ``c`` the centre of mass).
    friction : scalar or (..., 3) array
        ``mu_i`` per contact (last axis), ``>= 0``, ``inf`` for no limit.
    safety : float
        ``s >= 1``: the forces keep within ``mu_i / s``.
    tol : float
        Degeneracy tolerance of the contacts (as the twist engine's).

    Returns
    -------
    Grip

    Examples
    --------
    A 1 kg ball held at its equator with ``mu = 0.5``: each finger carries a third
    of the weight by friction, ``f_n = m g / (3 mu)``, in total ``m g / mu``:

    >>> p = [[1, 0, 0], [-0.5, 0.75**0.5, 0], [-0.5, -(0.75**0.5), 0]]
    >>> n = -np.array(p)
    >>> g = grip(p, n, [0, 0, 9.81, 0, 0, 0], 0.5)
    >>> round(float(g.total_normal_force), 6), g.friction_used.round(6).tolist()
    (19.62, [0.5, 0.5, 0.5])
    """
    p, n, w = check_points(points), check_normals(normals), check_wrench(wrench)
    mu = check_friction(friction)
    s_f = check_safety(safety)
    shape = np.broadcast_shapes(p.shape[:-2], n.shape[:-2], w.shape[:-1], mu.shape[:-1])
    p, n, w = (np.broadcast_to(a, shape + a.shape[-t:]) for a, t in ((p, 2), (n, 2), (w, 1)))
    mu = np.broadcast_to(mu if mu.ndim else mu[None], shape + (3,))
    size = int(np.prod(shape))
    flat = [a.reshape((size,) + a.shape[len(shape) :]) for a in (p, n, w, mu)]
    out = _grip_rows(*flat, s_f, tol)
    out = {k: v.reshape(shape + v.shape[1:]) for k, v in out.items()}
    return Grip(safety=s_f, **out)


def _grip_rows(p, n, w, mu, s_f, tol):
    rows = len(p)
    geo = geometry(p, tol)
    status, culprit = geo.status.copy(), geo.culprit.copy()
    with np.errstate(all="ignore"):
        length = norm(n)
        unit = n / length[..., None]
        fm = _manipulating(geo, w)
    zero = ~(length > 0)
    todo = status == 0
    hit = todo & zero.any(axis=1)
    status[hit], culprit[hit] = ForceStatus.ZERO_NORMAL, np.argmax(zero, axis=1)[hit]
    bad = ~(np.isfinite(n).all(axis=(1, 2)) & np.isfinite(w).all(axis=1) & ~np.isnan(mu).any(axis=1))
    status[(status == 0) & bad] = ForceStatus.NONFINITE_INPUT
    frictionless = (mu == 0).all(axis=1)
    status[(status == 0) & (mu == 0).any(axis=1) & ~frictionless] = ForceStatus.MIXED_FRICTIONLESS

    squeeze = np.full((rows, 3), np.nan)
    scale = np.abs(fm).max(axis=(1, 2))
    still = (status == 0) & (scale == 0)  # no wrench: no force at all is the least
    squeeze[still] = 0.0

    rest = np.flatnonzero((status == 0) & (scale > 0) & ~frictionless)
    if rest.size:
        for start in range(0, rest.size, CHUNK):  # chunks whose temporaries stay in cache
            part = rest[start : start + CHUNK]
            limit = mu[part] / s_f
            inside = closure.internal_inside(p[part], unit[part], geometry(p[part], tol), limit)
            squeeze[part], fail, blame = _solve(
                geo.e[part], unit[part], fm[part] / scale[part, None, None], limit, inside
            )
            squeeze[part] *= scale[part, None]
            status[part[fail]], culprit[part[fail]] = ForceStatus.CANNOT_HOLD, blame[fail]

    bare = np.flatnonzero((status == 0) & (scale > 0) & frictionless)
    if bare.size:
        nu = np.concatenate((unit[bare], cross(p[bare], unit[bare])), axis=-1)
        lam, pulling, unmade = _frictionless(nu, w[bare] / scale[bare, None], tol)
        fail = pulling | unmade
        ft = norm(fm[bare] - dot(fm[bare], unit[bare])[..., None] * unit[bare])
        status[bare[fail]] = ForceStatus.CANNOT_HOLD
        culprit[bare[fail]] = np.where(pulling, -1, np.argmax(ft, axis=1))[fail]
        f = lam[..., None] * unit[bare] * scale[bare, None, None]
        # the squeezes of these forces: project f - G^+ w on the squeeze directions
        squeeze[bare] = _squeezes_of(geo.e[bare], f - fm[bare])

    ok = status == 0
    squeeze[~ok] = np.nan
    with np.errstate(all="ignore"):
        force = fm + squeeze_forces(p, squeeze)
        fn = dot(force, unit)
        ft = norm(force - fn[..., None] * unit)
        return {
            "force": force,
            "manipulating": fm,
            "squeeze": squeeze,
            "normal_force": fn,
            "tangential_force": ft,
            "friction_used": ft / fn,
            "total_normal_force": fn.sum(axis=-1),
            "conditioning": geo.conditioning,
            "status": status,
            "culprit": culprit,
        }


def _squeezes_of(e, internal):
    """The squeezes ``s`` with ``squeeze_forces(s) = internal`` (least squares over the 9 numbers)."""
    m = contact_matrices(e).reshape(len(e), 9, 3)
    return (np.linalg.pinv(m) @ internal.reshape(len(e), 9)[..., None])[..., 0]


def cone_rows(e, unit, fm, kappa):
    """The cones ``y_i = A_i s + b_i`` of the grip in the squeezes: ``y_i = (n.f_i, kappa_i b1.f_i, kappa_i b2.f_i)``.

    ``kappa_i = safety / mu_i`` (0 for infinite friction).  Returns ``A (n, 3, 3, 3)``,
    ``b (n, 3, 3)`` and the objective ``c (n, 3)`` (``sum_i n_i . f_i`` minus a constant).
    """
    b1, b2 = tangent_bases(unit)
    frame = np.stack((unit, kappa[..., None] * b1, kappa[..., None] * b2), axis=-2)  # (n, 3 contacts, 3, 3)
    m = contact_matrices(e)  # (n, 3, 3, 3): contact, xyz, squeeze
    A = frame @ m
    b = np.einsum("nikx,nix->nik", frame, fm)
    return A, b, A[:, :, 0, :].sum(axis=1)


def _solve(e, unit, fm, limit, inside):
    """The grip's squeezes for rows scaled to order one; failing rows and their culprits.

    ``inside (n, 3)``: a squeeze strictly inside every cone (NaN where the grasp is not
    force closure with ``limit``); far enough along it is a start for phase II, so
    phase I runs only for the other rows.
    """
    with np.errstate(divide="ignore"):
        kappa = np.where(np.isinf(limit), 0.0, 1 / limit)
    A, b, c = cone_rows(e, unit, fm, kappa)
    x = np.zeros((len(e), 3))
    r = np.full(len(e), -1.0)
    closing = ~np.isnan(inside).any(axis=1)
    if closing.any():
        y = np.einsum("nmkd,nd->nmk", A[closing], inside[closing])
        depth = y[..., 0] - np.sqrt(y[..., 1] ** 2 + y[..., 2] ** 2)  # > 0: strictly inside
        reach = np.abs(b[closing, :, 0]) + np.sqrt(b[closing, :, 1] ** 2 + b[closing, :, 2] ** 2)
        x[closing] = ((socp.START_MARGIN + reach) / depth).max(axis=1)[:, None] * inside[closing]
    other = np.flatnonzero(~closing)
    if other.size:
        x[other], r[other] = socp.phase_one(A[other], b[other])
    fail = ~(r < 0)
    s = np.full((len(e), 3), np.nan)
    good = np.flatnonzero(~fail)
    if good.size:
        s[good] = socp.minimise(A[good], b[good], c[good], x[good])
    blame = np.full(len(e), -1, np.int8)
    bad = np.flatnonzero(fail)
    if bad.size:
        y = np.einsum("nmkd,nd->nmk", A[bad], x[bad]) + b[bad]
        blame[bad] = np.argmax(np.sqrt(y[..., 1] ** 2 + y[..., 2] ** 2) - y[..., 0], axis=1)
        # Pulling: infeasible even with unlimited friction (half-spaces n.f >= 0).  When the
        # squeezes reach every pattern of normal forces (an invertible 3 x 3 map) it never is.
        normal = A[bad, :, 0, :]
        scale = np.prod(np.linalg.norm(normal, axis=-1), axis=-1)
        maybe = np.flatnonzero(~(np.abs(np.linalg.det(normal)) > 1e-9 * scale))
        if maybe.size:
            rows = bad[maybe]
            A0, b0, _ = cone_rows(e[rows], unit[rows], fm[rows], np.zeros((rows.size, 3)))
            _, r0 = socp.phase_one(A0, b0)
            blame[rows] = np.where(r0 < 0, blame[rows], -1)
    return s, fail, blame
