r"""The grip: the least total normal force that exerts a wrench within the friction cones.

.. math::

    \min_{s \in \mathbb{R}^3}\; \sum_i f_i \cdot n_i \quad \text{s.t.} \quad
    f = G^+ w + \mathrm{squeeze}(s), \qquad |f_i - (f_i \cdot n_i) n_i| \le \frac{\mu_i}{s_f}\, f_i \cdot n_i

a second-order cone program in the three squeezes (``s_f`` the safety factor), solved
for every row together by :mod:`~grasptwist.engine.forces.socp`.  Frictionless grasps
(``mu = 0`` at every contact: the cones are rays) are solved in closed form instead:
``f_i = lambda_i n_i`` with ``sum lambda_i nu_i = w`` (``nu_i`` the normal lines).
Collinear contacts (``rank G = 5``) are solved when the wrench lies in the range of ``G``
(no moment about the contacts' line), over the four internal forces of such a grasp.

**Certificates.**  The dual of the grip is ``max w . lambda`` s.t.
``n_i - G_i^T lambda`` in the dual cone ``K_i* = {z : (mu_i / s_f) |z_t| <= z_n}``
(``G_i^T lambda = lambda_F + lambda_M x p_i``).  The solver's cone multipliers ``z_i``
give ``u_i = F_i^T z_i`` (``F_i`` the cone's frame), and ``lambda`` is the twist whose
field at the contacts is ``n_i - u_i`` (least squares, in closed form about the
centroid).  ``total - w . lambda`` is the duality gap, and ``lambda = d total / d w``.
Where no grip exists, phase I's multipliers give ``y`` with ``y . w > 0`` and
``-G_i^T y`` in ``K_i*``: no forces within the cones have a component along ``y``.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import partial

import numpy as np

from ..checks import check_normals, check_points
from ..degeneracy import DEGENERACY_TOL
from ..screws import cross, dot, norm
from . import closure, compiled, cones, one, set_up, socp
from .grasp_map import (
    GRIP_COLUMNS,
    WRENCH_SCALED_BEYOND,
    ForceStatus,
    _manipulating,
    check_friction,
    check_safety,
    check_torsion,
    check_wrench,
    checked_grip,
    collinear_manipulating,
    collinear_map,
    contact_matrices,
    geometry,
    unit_normals,
    wrench_scales,
)

__all__ = ["Grip", "grip", "wrench_grips", "prepare_grip", "PreparedGrip", "load_words"]

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
        The squeezes along the sides opposite each contact (positive: compression);
        NaN for collinear contacts, whose internal forces are not three squeezes.
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
    dual : (..., 6)
        The wrench's multiplier ``lambda`` (a twist: ``G_i^T lambda = lambda_F + lambda_M x p_i``):
        ``n_i - G_i^T lambda`` lies in contact ``i``'s dual cone
        ``(mu_i / safety) |z_t| <= z_n``, and it is the sensitivity ``d total / d w``.
        NaN where ``status != 0``.
    gap : (...)
        The duality gap ``total_normal_force - w . dual`` (0 at the optimum, to round-off).
    certificate : (..., 6)
        NaN where the grip holds; for ``cannot-hold`` (and collinear contacts asked for a
        moment about their line) a ``y`` with ``y . w > 0`` and ``y . G_i f <= 0`` for
        every admissible ``f`` of every contact: a proof that no grip exists (Farkas).
        Scaled to ``|(y_F, L y_M)| = 1``, ``L`` the largest distance from the contacts'
        centroid to a contact (``load_words`` puts it in words).
    torsion : (..., 3) or None
        With ``torsion=`` given to ``grip``: the torsional moment ``tau_i`` each contact exerts
        about its normal (0 at a point contact; NaN where ``status != 0``); None otherwise.
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
    dual: np.ndarray
    gap: np.ndarray
    certificate: np.ndarray
    torsion: np.ndarray | None = None

    @property
    def ok(self) -> np.ndarray:
        """``status == 0`` per row."""
        return self.status == ForceStatus.OK


def norm_rows(a):
    return np.sqrt(np.einsum("ni,ni->n", a, a))


def _frictionless(nu, w, tol):
    """``f_i = lambda_i n_i`` with ``sum lambda_i nu_i = w``, ``lambda >= 0``, least ``sum lambda``.

    ``nu (n, 3, 6)`` unit normal lines, ``w (n, 6)`` scaled to order one.  Returns
    ``lam (n, 3)`` (NaN where none exists), ``needs_pulling (n)``, ``unmade (n)``, the dual
    ``(n, 6)`` (``nu_i . dual <= 1``, equal where ``lam_i > 0``) and the certificate ``(n, 6)``
    (``nu_i . y <= 0`` for every ``i``, ``w . y > 0``) where it fails.
    """
    k = np.swapaxes(nu, -1, -2)  # (n, 6, 3)
    u, sv, vt = np.linalg.svd(k, full_matrices=False)
    rank3 = sv[:, 2] > tol * sv[:, 0]
    with np.errstate(divide="ignore"):
        inv = np.where(rank3[:, None] | (np.arange(3) < 2), 1 / sv, 0.0)
    pinv_t = np.einsum("nji,ni,nik->njk", u, inv, vt)  # (N^T)^+ = U S^-1 V^T: (n, 6, 3)
    lam0 = np.einsum("nji,nj->ni", pinv_t, w)  # the least-squares lambda
    residual = np.einsum("nij,nj->ni", k, lam0) - w
    made = norm_rows(residual) <= tol * np.maximum(norm_rows(w), 1e-300)
    z = vt[:, 2]  # the null direction when rank 2: a free squeeze along the normals
    z = np.where((z.sum(axis=1) < 0)[:, None], -z, z)
    with np.errstate(divide="ignore", invalid="ignore"):
        low = np.where(z > tol, -lam0 / z, -np.inf)  # lam + t z >= 0 from below
        high = np.where(z < -tol, -lam0 / z, np.inf)
    bound, upper = low.max(axis=1), high.min(axis=1)
    t = np.where(rank3, 0.0, bound)
    lam = np.where(rank3[:, None], lam0, lam0 + t[:, None] * z)
    pushes = np.where(rank3, (lam >= -tol).all(axis=1), (bound <= upper) & np.isfinite(bound))
    lam = np.where((made & pushes)[:, None], np.maximum(lam, 0), np.nan)
    # the dual: nu_i . dual = a_i, a_i = 1 where lam_i > 0; rank 2 needs z . a = 0 (a on the idle one)
    active = lam > tol * np.nanmax(np.abs(lam), axis=1, initial=0.0)[:, None]
    idle = np.argmin(np.where(active, np.inf, -np.abs(z)), axis=1)  # the idle contact with the largest |z|
    rows = np.arange(len(w))
    a = np.ones((len(w), 3))
    with np.errstate(divide="ignore", invalid="ignore"):
        fix = (z.sum(axis=1) - z[rows, idle]) / z[rows, idle]
    a[rows, idle] = np.where(rank3, 1.0, -fix)
    dual = np.einsum("njk,nk->nj", pinv_t, a)
    # the certificates: the unmade part; one negative lambda (rank 3); two bounds that cross (rank 2)
    first = np.argmin(lam0, axis=1)
    b = np.zeros((len(w), 3))
    b[rows, first] = -1.0
    lo, hi = np.argmax(low, axis=1), np.argmin(high, axis=1)
    c = np.zeros((len(w), 3))
    c[rows, lo] -= np.abs(z[rows, hi])
    c[rows, hi] -= np.abs(z[rows, lo])
    flat = (np.abs(z) <= tol) & (lam0 < -tol)  # a contact the free squeeze does not move, pulling
    c = np.where(flat.any(axis=1)[:, None], -flat.astype(float), c)
    y = np.einsum("njk,nk->nj", pinv_t, np.where(rank3[:, None], b, c))
    y = np.where(made[:, None], y, -residual)
    return lam, made & ~pushes, ~made, dual, y


def _twist_through(geo, d):
    """The twist ``lambda (n, 6)`` whose field ``lambda_F + lambda_M x p_i`` is nearest ``d_i`` (least squares):
    :func:`set_up.twist_through`'s numpy twin (``J^-1`` in closed form, as for ``G^+ w``)."""
    out = np.empty((len(d), 6))
    set_up.on_rows("twist_through", geo.centroid, geo.q, geo.m, geo.t[:, None], np.asarray(d, dtype=float), out, len(d))
    return out


def _twist_through_line(cmap, d):
    """:func:`_twist_through` for collinear contacts (rank 5), through the SVD of ``D G``."""
    coef = np.einsum("nji,nj->ni", cmap.v, d.reshape(-1, 9)) / cmap.s
    lam = np.einsum("nji,ni->nj", cmap.u, coef)
    lam[:, 3:] /= cmap.size[:, None]
    return lam


def _unit(y, size):
    """``y`` scaled to ``|(y_F, L y_M)| = 1`` (``L`` the grasp's size: force and moment parts compare)."""
    with np.errstate(all="ignore"):
        length = np.sqrt(dot(y[:, :3], y[:, :3]) + size**2 * dot(y[:, 3:], y[:, 3:]))
        return y / length[:, None]


def load_words(certificate, points) -> str:
    r"""The load a ``cannot-hold`` grip cannot resist, in words, from its certificate ``y``.

    The load ``(-y_F; -L^2 y_M)`` (``L`` the largest distance from the contacts' centroid
    to a contact) has ``y . load < 0``: the fingers, whose wrenches all have
    ``y . G f <= 0``, cannot balance it.  Its force is of order one and its moment of
    order ``L``: a force with a lever arm on the grasp's scale.

    >>> load_words([0, 0, 1, 0, 0, 0], [[1, 0, 0], [-0.5, 0.75**0.5, 0], [-0.5, -(0.75**0.5), 0]])
    'cannot resist a force along (0, 0, -1) with a moment (0, 0, 0) about the origin'
    """
    y = np.asarray(certificate, dtype=float)
    p = np.asarray(points, dtype=float)
    size = np.sqrt(((p - p.mean(axis=0)) ** 2).sum(axis=1).max())
    load = -np.concatenate((y[:3], size**2 * y[3:]))
    load = np.round(load / np.sqrt(y[:3] @ y[:3] + size**2 * (y[3:] @ y[3:])), 3) + 0.0  # + 0.0: no -0
    force, moment = (", ".join(f"{v:.3g}" for v in part) for part in (load[:3], load[3:]))
    return f"cannot resist a force along ({force}) with a moment ({moment}) about the origin"


def grip(points, normals, wrench, friction, *, safety=1.0, torsion=None, tol=DEGENERACY_TOL) -> Grip:
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
    safety : float, keyword-only
        ``s >= 1``: the forces keep within ``mu_i / s``.
    torsion : None, scalar or (..., 3) array, keyword-only
        Soft-finger contacts: ``e_i`` (a length, ``>= 0``), the torsional radius of contact ``i``, which
        then also exerts a moment ``tau_i`` about its normal within ``|(f_t, tau / e)| <= (mu / s) f_n``
        (the contacts' cones: docs/guide/forces.md).  ``0`` (or None) is a point contact.
    tol : float
        Degeneracy tolerance of the contacts (as the twist engine's).

    Returns
    -------
    Grip
        With the optimum's certificate (``dual``, ``gap``) or the proof that none exists
        (``certificate``).

    Examples
    --------
    A 1 kg ball held at its equator with ``mu = 0.5``: each finger carries a third
    of the weight by friction, ``f_n = m g / (3 mu)``, in total ``m g / mu``; the
    dual says that one more newton of lift costs ``1 / mu = 2`` N of grip:

    >>> p = [[1, 0, 0], [-0.5, 0.75**0.5, 0], [-0.5, -(0.75**0.5), 0]]
    >>> n = -np.array(p)
    >>> g = grip(p, n, [0, 0, 9.81, 0, 0, 0], 0.5)
    >>> round(float(g.total_normal_force), 6), g.friction_used.round(6).tolist()
    (19.62, [0.5, 0.5, 0.5])
    >>> round(float(g.dual[2]), 6), bool(abs(g.gap) < 1e-8)
    (2.0, True)
    """
    p, n, w = check_points(points), check_normals(normals), check_wrench(wrench)
    mu = check_friction(friction)
    s_f = check_safety(safety)
    e = None if torsion is None else check_torsion(torsion)
    shape = np.broadcast_shapes(p.shape[:-2], n.shape[:-2], w.shape[:-1], mu.shape[:-1])
    if e is not None:
        shape = np.broadcast_shapes(shape, e.shape[:-1])
    p, n, w = (np.broadcast_to(a, shape + a.shape[-t:]) for a, t in ((p, 2), (n, 2), (w, 1)))
    mu = np.broadcast_to(mu if mu.ndim else mu[None], shape + (3,))
    size = int(np.prod(shape))
    flat = [a.reshape((size,) + a.shape[len(shape) :]) for a in (p, n, mu, w)]
    if e is None:
        return _grip_of(flat, s_f, tol, shape)
    e = np.broadcast_to(e if e.ndim else e[None], shape + (3,)).reshape(size, 3)
    return _with_soft(flat, e, s_f, tol, shape)


def wrench_grips(points, normals, wrenches, friction, *, safety=1.0, torsion=None, tol=DEGENERACY_TOL):
    """Every row's grip of every wrench: ``total_normal_force`` and ``ok``, both ``(N, W)``.

    ``points, normals (N, 3, 3)``, ``wrenches (W, 6)``, ``friction`` scalar, ``(N,)`` or ``(N, 3)``;
    ``safety``, ``torsion``, ``tol`` as :func:`grip`'s.  One :func:`grip` of the rows times the wrenches,
    :data:`CHUNK` grips at a time (a call a wrench would pay the numpy path's cost per call, ~0.6 ms
    a step whatever the rows, ``W`` times; the blocks bound the memory).

    >>> p = np.array([[[1, 0, 0], [-0.5, 0.75**0.5, 0], [-0.5, -(0.75**0.5), 0]]])
    >>> total, ok = wrench_grips(p, -p, [[0, 0, 9.81, 0, 0, 0], [0, 0, 0, 0, 0, 1.0]], 0.5)
    >>> total.round(6).tolist(), ok.tolist()
    ([[19.62, 2.0]], [[True, True]])
    """
    p, n = np.asarray(points, float), np.asarray(normals, float)
    w = np.asarray(wrenches, float).reshape(-1, 6)
    mu = np.asarray(friction, float)
    mu = np.broadcast_to(mu[:, None] if mu.ndim == 1 else mu, (len(p), 3))
    total, ok = np.full((len(p), len(w)), np.nan), np.zeros((len(p), len(w)), bool)
    step = max(CHUNK // max(len(w), 1), 1)  # no wrenches: (N, 0), every row holds them all
    for at in range(0, len(p), step):  # no rows: no grip (an empty batch)
        rows = slice(at, at + step)
        g = grip(p[rows, None], n[rows, None], w, mu[rows, None], safety=safety, torsion=torsion, tol=tol)
        total[rows], ok[rows] = g.total_normal_force, g.ok
    return total, ok


def _with_soft(rows, e, s_f, tol, shape):
    """The :class:`Grip` of ``rows`` with torsional radii ``e (n, 3)``: rows with a soft contact (``e > 0``,
    ``mu > 0``; NaN ``e``: ``nonfinite-input``) over the contacts' cones (:mod:`cones`), the others as
    point contacts, bit for bit what :func:`grip` gives them without ``torsion``."""
    if not len(e):
        return replace(_no_rows(s_f, shape), torsion=np.empty(shape + (3,)))
    mu = rows[2]
    soft = _with_soft_contact(mu, e)
    if not soft.any():  # point contacts all: their grip, with no torsion (its cost, not the cones' split)
        g = _grip_of(rows, s_f, tol, shape)
        return replace(g, torsion=_point_torsion(g.ok))
    k = wrench_scales(rows[3])
    if k is not None:  # as _grip_of: solved scaled by a power of two, the grip scaled back
        return _scaled_back(_with_soft((*rows[:3], rows[3] / k[:, None]), e, s_f, tol, shape), k, shape)
    point = np.flatnonzero(~soft)
    g = _grip_of([a[point] for a in rows], s_f, tol, (point.size,))
    fields = {name: getattr(g, name) for name, _ in GRIP_COLUMNS + (("status", 1), ("culprit", 1))}
    out = {name: np.empty((len(e),) + v.shape[1:], v.dtype) for name, v in fields.items()}
    for name, v in fields.items():
        out[name][point] = v
    out["torsion"] = np.full((len(e), 3), np.nan)
    out["torsion"][point] = _point_torsion(g.ok)
    rest = np.flatnonzero(soft)
    if rest.size:
        for name, v in _soft_rows(*(a[rest] for a in rows), e[rest], s_f, tol).items():
            out[name][rest] = v
    return checked_grip(Grip(safety=s_f, **{k: v.reshape(shape + v.shape[1:]) for k, v in out.items()}))


def _with_soft_contact(mu, e):
    """``(...)`` whether a grasp of frictions and torsional radii ``(..., 3)`` has a soft contact (``e > 0`` with
    friction; a NaN ``e``, the cones' way's ``nonfinite-input``): its grip goes over the contacts' cones."""
    return (((e > 0) & (mu > 0)) | np.isnan(e)).any(axis=-1)


def _point_torsion(ok):
    """The torsions of point contacts' grips ``(..., 3)``: none exerted (0) where held, NaN where not."""
    return np.where(np.asarray(ok)[..., None], np.zeros(3), np.nan)


def _soft_rows(p, n, mu, w, e, s_f, tol):
    """The grip's fields for rows with soft contacts, over the contacts' cones (:func:`cones.cone_solve`)."""
    geo = geometry(p, tol)
    status, culprit = geo.status.copy(), geo.culprit.copy()
    status[status == ForceStatus.COLLINEAR_CONTACTS] = 0  # a soft contact's torsion may make what the line cannot
    unit, zero, bad = unit_normals(n)
    hit = (status == 0) & zero.any(axis=1)
    status[hit], culprit[hit] = ForceStatus.ZERO_NORMAL, np.argmax(zero, axis=1)[hit]
    bad |= np.isnan(mu).any(axis=1) | np.isnan(e).any(axis=1) | ~np.isfinite(w).all(axis=1)
    status[(status == 0) & bad] = ForceStatus.NONFINITE_INPUT
    rows = len(p)
    force, torsion = np.full((rows, 3, 3), np.nan), np.full((rows, 3), np.nan)
    dual, certificate = np.full((rows, 6), np.nan), np.full((rows, 6), np.nan)
    todo = np.flatnonzero(status == 0)
    model = cones.contact_models(mu, e)
    if todo.size:
        with np.errstate(all="ignore"):
            setup = cones.cone_grasp(p[todo], unit[todo], mu[todo] / s_f, e[todo], model[todo])
            out = cones.cone_solve(setup, w[todo])
        force[todo], torsion[todo], dual[todo] = out["force"], out["torsion"], out["dual"]
        certificate[todo] = out["certificate"]
        status[todo[out["unmade"]]] = ForceStatus.COLLINEAR_CONTACTS
        status[todo[out["fail"]]] = ForceStatus.CANNOT_HOLD
        culprit[todo[out["fail"]]] = out["blame"][out["fail"]]
    ok = status == 0
    force[~ok], torsion[~ok], dual[~ok] = np.nan, np.nan, np.nan
    with np.errstate(all="ignore"):
        fm = _manipulating(geo, w)
        fn = dot(force, unit)
        ft = norm(force - fn[..., None] * unit)
        rubbing = np.where(model == cones.SOFT, np.hypot(ft, torsion / np.where(e > 0, e, 1.0)), ft)
        total = fn.sum(axis=-1)
        return {
            "force": force,
            "manipulating": fm,
            "squeeze": np.full((rows, 3), np.nan),
            "normal_force": fn,
            "tangential_force": ft,
            "friction_used": rubbing / fn,
            "total_normal_force": total,
            "conditioning": geo.conditioning,
            "status": status,
            "culprit": culprit,
            "dual": dual,
            "gap": total - np.einsum("ni,ni->n", w, dual),
            "certificate": _unit(certificate, geo.size),
            "torsion": torsion,
        }


#: The grip's fields that scale with the wrench (the grip is positively homogeneous in it:
#: ``grip(k w) = k grip(w)`` for ``k > 0``); the others (``friction_used``, ``dual``,
#: ``certificate``, ``conditioning``) do not change.
LINEAR_FIELDS = ("force", "manipulating", "squeeze", "normal_force", "tangential_force", "total_normal_force", "gap")


def _grip_of(rows, s_f, tol, shape, prepared=None):
    """The :class:`Grip` of ``rows = (p, n, mu, w)`` flat over rows, shaped ``shape``.

    Compiled (:mod:`~grasptwist.engine.forces.compiled`) where numba is there: the kernel takes
    the rows it can, the numpy path (``prepared``, else a :class:`_Prepared` of those rows) the others.
    A wrench beyond ``grasp_map.WRENCH_SCALED_BEYOND`` is solved scaled (``wrench_scales``) and its
    grip scaled back, so that only a grip that is itself beyond a double is ``nonfinite-result``.
    """
    if not len(rows[0]):  # both paths index a first row
        return _no_rows(s_f, shape)
    k = wrench_scales(rows[3])
    if k is not None:
        return _scaled_back(_grip_of((*rows[:3], rows[3] / k[:, None]), s_f, tol, shape, prepared), k, shape)
    fast = compiled.kernel()
    if fast is None:
        out = (prepared or _Prepared(*rows[:3], s_f, tol)).solve(rows[3])
        return checked_grip(Grip(safety=s_f, **{k: v.reshape(shape + v.shape[1:]) for k, v in out.items()}))
    p, n, mu = (compiled.read_only(a) for a in rows[:3])
    limit = compiled.read_only(np.broadcast_to(mu / s_f, (len(p), 3)))
    w = np.array(rows[3], dtype=float, order="C")
    return _compiled_grip(fast, (p, n, limit, w), s_f, tol, shape, lambda rest: (p[rest], n[rest], mu[rest]))


def _scaled_back(g, k, shape):
    """The grip ``g`` of wrenches divided by ``k (n)``, as the grip of the wrenches (:data:`LINEAR_FIELDS`, and
    the torsions, times ``k``)."""
    k = k.reshape(shape)
    names = LINEAR_FIELDS if g.torsion is None else LINEAR_FIELDS + ("torsion",)
    with np.errstate(over="ignore", invalid="ignore"):
        scaled = {f: getattr(g, f) * k.reshape(k.shape + (1,) * (getattr(g, f).ndim - k.ndim)) for f in names}
    return checked_grip(replace(g, **scaled))


def _compiled_grip(fast, rows, s_f, tol, shape, others):
    """The :class:`Grip` of :func:`kernel.grip_rows` on ``rows = (p, n, limit, w)`` (C-contiguous floats).

    The rows it leaves go to the numpy path, on the grasps ``others(rest) = (p, n, mu)``.  Every
    field is a view of one array the kernel filled.
    """
    size = len(rows[0])
    numbers = np.empty((size, fast.WIDTH))
    codes = np.empty((size, 3), np.int8)
    fast.grip_rows(*rows, tol, numbers, codes)
    out, at = {}, 0
    for name, width in GRIP_COLUMNS:
        out[name] = numbers[:, at : at + width]
        at += width
    out["status"], out["culprit"] = codes[:, :1], codes[:, 1:2]
    rest = np.flatnonzero(codes[:, 2] == 0) if size > 1 or not codes[0, 2] else ()
    if len(rest):
        more = _Prepared(*others(rest), s_f, tol).solve(rows[3][rest])
        for name, value in more.items():
            out[name][rest] = value.reshape(len(rest), -1)
    g = Grip(safety=s_f, **{k: v.reshape(shape + _TAILS[v.shape[1]]) for k, v in out.items()})
    return checked_grip(g) if len(rest) else g


_TAILS = {1: (), 3: (3,), 6: (6,), 9: (3, 3)}


def _no_rows(s_f, shape):
    """The :class:`Grip` of an empty batch: every field with ``shape`` and its own trailing shape."""
    fields = {name: np.empty(shape + _TAILS[width]) for name, width in GRIP_COLUMNS}
    return Grip(safety=s_f, status=np.empty(shape, np.int8), culprit=np.empty(shape, np.int8), **fields)


def _views():
    """``(name, index, shape or None)`` of one row's fields in :func:`kernel.grip_rows`' numbers
    (``[at, ...]``: a 0-d view of one number, the cheapest there is)."""
    out, at = [], 0
    for name, width in GRIP_COLUMNS:
        index = (at, Ellipsis) if width == 1 else slice(at, at + width)
        out.append((name, index, (3, 3) if width == 9 else None))
        at += width
    return tuple(out)


_VIEWS = _views()


class PreparedGrip:
    """One grasp with its friction and safety, ready to grip any number of wrenches (:func:`~grasptwist.forces.prepare_grip`).

    Attributes
    ----------
    points, normals, friction : arrays
        The grasp (read-only), ``friction`` broadcast to ``(3,)``.
    safety : float
    """

    def __init__(self, points, normals, friction, safety, tol, torsion=None):
        self.points, self.normals, self.friction, self.safety = points, normals, friction, safety
        self.torsion = torsion
        # point contacts all (torsion 0, or no friction where it is not): the point contacts' fast way
        self._soft = torsion is not None and bool(_with_soft_contact(friction, torsion))
        self._prepared = _Prepared(points[None], normals[None], friction[None], safety, tol)
        self._rows = (compiled.read_only(points[None]), compiled.read_only(normals[None]), friction[None])
        self._limit = compiled.read_only(friction[None] / safety)
        self._tol = float(tol)

    def grip(self, wrench) -> Grip:
        """The same :class:`Grip` as ``grip(points, normals, wrench, friction, safety=safety)``.

        ``wrench (..., 6)``: any number of wrenches on this grasp.
        """
        w = check_wrench(wrench)
        if self._soft:  # soft contacts: the cones' way, set up per call (numpy)
            return grip(
                self.points, self.normals, w, self.friction, safety=self.safety, torsion=self.torsion, tol=self._tol
            )
        g = self._point_grip(w)
        return g if self.torsion is None else replace(g, torsion=_point_torsion(g.ok))

    def _point_grip(self, w):
        """:meth:`grip` of point contacts."""
        rows = w.reshape(-1, 6)
        k = len(rows)
        fast = compiled.kernel()
        # a control loop's call; a wrench to scale first (wrench_scales' bounds, tested here on one
        # number: the array form costs half this call) goes the general way
        low, high = WRENCH_SCALED_BEYOND
        largest = float(np.abs(rows).max()) if w.ndim == 1 else 0.0
        if fast is not None and w.ndim == 1 and (largest == 0 or low <= largest <= high):
            numbers = np.empty((1, fast.WIDTH))
            codes = np.empty((1, 3), np.int8)
            fast.grip_rows(self._rows[0], self._rows[1], self._limit, rows, self._tol, numbers, codes)  # w: a copy
            if codes[0, 2]:
                flat, codes = numbers[0], codes[0]
                fields = {name: flat[at] if tail is None else flat[at].reshape(tail) for name, at, tail in _VIEWS}
                fields.update(status=codes[0, ...], culprit=codes[1, ...], safety=self.safety)
                g = object.__new__(Grip)  # the frozen dataclass's __init__ was a tenth of the call
                g.__dict__.update(fields)
                return g
        prepared = self._prepared if k == 1 else self._prepared.repeat(k)
        grasp = (self._rows if k == 1 else tuple(np.repeat(a, k, axis=0) for a in self._rows)) + (rows,)
        return _grip_of(grasp, self.safety, self._prepared.tol, w.shape[:-1], prepared)


def prepare_grip(points, normals, friction, *, safety=1.0, torsion=None, tol=DEGENERACY_TOL) -> PreparedGrip:
    """One grasp's part of :func:`~grasptwist.forces.grip` done once, for a control loop whose wrench changes.

    ``points, normals (3, 3)``, ``friction`` scalar or ``(3,)``.  The checks, and on the numpy
    path the geometry, the cones' frames, the squeezes' map and an internal force inside every
    cone, do not depend on the wrench; ``.grip(wrench)`` does the rest and gives what
    :func:`~grasptwist.forces.grip` gives.  Compiled (numba), one wrench is one row of the kernel, whose
    wrench-free part is a small share of its time; the prepared form saves the checks and
    the conversions around it.  With ``torsion`` (soft contacts, as :func:`~grasptwist.forces.grip`'s),
    ``.grip(wrench)`` is that grip, its set-up done per call for now.

    >>> p = [[1, 0, 0], [-0.5, 0.75**0.5, 0], [-0.5, -(0.75**0.5), 0]]
    >>> hand = prepare_grip(p, -np.array(p), 0.5, safety=2)
    >>> round(float(hand.grip([0, 0, 9.81, 0, 0, 0]).total_normal_force), 6)
    39.24
    """
    p, n = check_points(points), check_normals(normals)
    if p.shape != (3, 3) or n.shape != (3, 3):
        raise ValueError(f"prepare_grip takes one grasp: points and normals (3, 3), got {p.shape} and {n.shape}")
    mu = np.broadcast_to(check_friction(friction), (3,)) if np.ndim(friction) <= 1 else None
    if mu is None:
        raise ValueError(f"prepare_grip takes one grasp: friction a scalar or (3,), got {np.shape(friction)}")
    e = None if torsion is None else check_torsion(torsion)
    if e is not None and np.ndim(e) > 1:
        raise ValueError(f"prepare_grip takes one grasp: torsion a scalar or (3,), got {np.shape(e)}")
    e = None if e is None else np.broadcast_to(e, (3,)).astype(float)
    return PreparedGrip(
        np.ascontiguousarray(p), np.ascontiguousarray(n), mu.astype(float), check_safety(safety), tol, e
    )


class _Prepared:
    """The wrench-free part of the grip of ``n`` rows: statuses, cones, squeeze maps, starts."""

    def __init__(self, p, n, mu, s_f, tol):
        self.p, self.mu, self.s_f, self.tol = p, mu, s_f, tol
        geo = self.geo = geometry(p, tol)
        status, culprit = geo.status.copy(), geo.culprit.copy()
        line = status == ForceStatus.COLLINEAR_CONTACTS
        status[line] = 0  # solved below when the wrench has no moment about the line
        self.unit, zero, bad = unit_normals(n)
        hit = (status == 0) & zero.any(axis=1)
        status[hit], culprit[hit] = ForceStatus.ZERO_NORMAL, np.argmax(zero, axis=1)[hit]
        status[(status == 0) & (bad | np.isnan(mu).any(axis=1))] = ForceStatus.NONFINITE_INPUT
        self.frictionless = (mu == 0).all(axis=1)
        status[(status == 0) & (mu == 0).any(axis=1) & ~self.frictionless] = ForceStatus.MIXED_FRICTIONLESS
        status[line & (status == 0) & self.frictionless] = ForceStatus.COLLINEAR_CONTACTS  # not solved there
        self.status, self.culprit = status, culprit
        self.line = line & (status == 0)
        self.plane = np.flatnonzero((status == 0) & ~self.line & ~self.frictionless)
        self.lines = np.flatnonzero(self.line)
        self.cmap = collinear_map(p[self.lines], geo.size[self.lines]) if self.lines.size else None
        self.bare = np.flatnonzero((status == 0) & self.frictionless & ~self.line)
        # the cones and the squeezes' (internal forces') map of the rows with friction
        rows = np.concatenate((self.plane, self.lines))
        limit = mu[rows] / s_f
        self.frame = np.empty((rows.size, 3, 3, 3))
        set_up.on_rows("cone_frames", self.unit[rows], limit, self.frame, rows.size)
        self.inside = closure.internal_inside(
            p[self.plane], self.unit[self.plane], _rows(geo, self.plane), limit[: self.plane.size]
        )
        self.maps = (contact_matrices(geo.e[self.plane]), _line_matrices(self.cmap))
        self.one = _one_row(self.frame, self.maps[0], self.inside) if len(p) == 1 and self.plane.size else None

    def repeat(self, k):
        """This one grasp as ``k`` rows (for ``k`` wrenches)."""
        new = object.__new__(_Prepared)
        new.__dict__.update(self.__dict__)
        many = {"p", "mu", "unit", "status", "culprit", "frictionless", "line"}
        for name in many:
            new.__dict__[name] = np.repeat(getattr(self, name), k, axis=0)
        new.geo = type(self.geo)(*(np.repeat(a, k, axis=0) for a in self.geo))
        for name in ("plane", "lines", "bare"):
            new.__dict__[name] = np.arange(k) if getattr(self, name).size else np.arange(0)
        new.frame = np.repeat(self.frame, k, axis=0)
        new.inside = np.repeat(self.inside, k, axis=0)
        new.maps = tuple(None if m is None else np.repeat(m, k, axis=0) for m in self.maps)
        new.cmap = None if self.cmap is None else type(self.cmap)(*(np.repeat(a, k, axis=0) for a in self.cmap))
        new.one = None
        return new

    def solve(self, w):
        """The grip's columns for wrenches ``w (n, 6)``, one per row."""
        geo, p, unit = self.geo, self.p, self.unit
        rows = len(p)
        status, culprit = self.status.copy(), self.culprit.copy()
        status[(status == 0) & ~np.isfinite(w).all(axis=1)] = ForceStatus.NONFINITE_INPUT
        with np.errstate(all="ignore"):
            fm = _manipulating(geo, w)
        force = np.full((rows, 3, 3), np.nan)
        squeeze = np.full((rows, 3), np.nan)
        dual = np.full((rows, 6), np.nan)
        certificate = np.full((rows, 6), np.nan)
        if self.lines.size:
            lf, made, y = collinear_manipulating(self.cmap, w[self.lines])
            fm[self.lines] = lf
            out = self.lines[~made & (status[self.lines] == 0)]
            status[out], certificate[out] = ForceStatus.COLLINEAR_CONTACTS, y[~made & (status[self.lines] == 0)]
        scale = np.abs(fm).max(axis=(1, 2))
        still = (status == 0) & (scale == 0)  # no wrench: no force at all is the least
        force[still], dual[still] = 0.0, 0.0
        squeeze[still & ~self.line] = 0.0
        groups = ((self.plane, 0, self.maps[0], False), (self.lines, self.plane.size, self.maps[1], True))
        for group, k, maps, on_line in groups:
            todo = np.flatnonzero((status[group] == 0) & (scale[group] > 0))
            for start in range(0, todo.size, CHUNK):  # chunks whose temporaries stay in cache
                part = todo[start : start + CHUNK]
                r = group[part]
                frame, m = self.frame[k + part], maps[part]
                inside = np.full((part.size, 4), np.nan) if on_line else self.inside[part]
                if self.one is not None:  # one grasp: numpy's cost per call is all there is, so floats
                    s, z, fail, blame = _solve_floats(self.one, _cones(frame, m, fm[r], scale[r])[1])
                else:
                    s, z, fail, blame = _solve(frame, m, fm[r], scale[r], inside)
                force[r] = fm[r] + scale[r, None, None] * np.einsum("nixl,nl->nix", m, s)
                u = np.einsum("nikx,nik->nix", frame, z)  # the cones' multipliers as forces' duals
                if on_line:
                    through = partial(_twist_through_line, _rows(self.cmap, part))
                else:
                    through = partial(_twist_through, _rows(geo, r))
                    squeeze[r] = scale[r, None] * s
                # phase II's multipliers: the twist through n_i - u_i; phase I's (fail): -G_i^T y = u_i
                dual[r], y = through(unit[r] - u), -through(u)
                status[r[fail]], culprit[r[fail]] = ForceStatus.CANNOT_HOLD, blame[fail]
                certificate[r[fail]] = y[fail]
                # on the edge of what the fingers can exert (y . w = 0): the contacts y forbids carry nothing
                with np.errstate(over="ignore"):  # a huge wrench: its row is nonfinite-result, not a warning
                    held = np.einsum("ni,ni->n", y, w[r]) > _EDGE_OF_HOLD * norm(y) * norm(w[r])
                edge = np.flatnonzero(fail & ~held)
                for i in edge:
                    found = _on_the_edge(frame[i], m[i], fm[r[i]] / scale[r[i]], z[i])
                    if found is None:
                        continue
                    s_i, z_i, bare = found
                    force[r[i]] = fm[r[i]] + scale[r[i]] * (m[i] @ s_i)
                    if not on_line:
                        squeeze[r[i]] = scale[r[i]] * s_i
                    dual[r[i]] = _edge_dual(frame[i], p[r[i]], unit[r[i]], z_i, y[i], bare)
                    status[r[i]], culprit[r[i]], certificate[r[i]] = 0, -1, np.nan
        todo = self.bare[(status[self.bare] == 0) & (scale[self.bare] > 0)]
        if todo.size:
            nu = np.concatenate((unit[todo], cross(p[todo], unit[todo])), axis=-1)
            lam, pulling, unmade, lam_dual, y = _frictionless(nu, w[todo] / scale[todo, None], self.tol)
            fail = pulling | unmade
            ft = norm(fm[todo] - dot(fm[todo], unit[todo])[..., None] * unit[todo])
            status[todo[fail]] = ForceStatus.CANNOT_HOLD
            culprit[todo[fail]] = np.where(pulling, -1, np.argmax(ft, axis=1))[fail]
            certificate[todo[fail]] = y[fail]
            force[todo] = lam[..., None] * unit[todo] * scale[todo, None, None]
            dual[todo] = lam_dual
            # the squeezes of these forces: project f - G^+ w on the squeeze directions
            squeeze[todo] = _squeezes_of(geo.e[todo], force[todo] - fm[todo])
        ok = status == 0
        force[~ok], squeeze[~ok], dual[~ok] = np.nan, np.nan, np.nan
        certificate = _unit(certificate, geo.size)
        with np.errstate(all="ignore"):
            fn = dot(force, unit)
            ft = norm(force - fn[..., None] * unit)
            total = fn.sum(axis=-1)
            return {
                "force": force,
                "manipulating": fm,
                "squeeze": squeeze,
                "normal_force": fn,
                "tangential_force": ft,
                "friction_used": ft / fn,
                "total_normal_force": total,
                "conditioning": geo.conditioning,
                "status": status,
                "culprit": culprit,
                "dual": dual,
                "gap": total - np.einsum("ni,ni->n", w, dual),
                "certificate": certificate,
            }


def _one_row(frame, m, inside):
    """What :func:`one.solve` needs of one grasp's row (with friction, not collinear), as lists of floats."""
    A, _, c = _cones(frame, m, np.zeros((1, 3, 3)), np.ones(1))
    A_list = A[0].tolist()
    return {
        "A": A_list,
        "c": c[0].tolist(),
        "P": one.newton_matrices(A_list),
        "inside": None if np.isnan(inside[0]).any() else inside[0].tolist(),
        "rays": _rays(A)[0].tolist(),
    }


def _solve_floats(row, b):
    """:func:`_solve` for one row through :func:`one.solve`, with :func:`_solve`'s shapes (``b (1, 3, 3)``: its
    :func:`_cones`)."""
    b = b[0].tolist()
    s, z, fail, blame = one.solve(row["A"], b, row["c"], row["P"], row["inside"], row["rays"])
    return np.array([s]), np.array([z]), np.array([fail]), np.array([blame], np.int8)


#: A certificate with ``y . w`` at most this of ``|y| |w|`` proves nothing: the wrench is on the edge.
_EDGE_OF_HOLD = 1e-8


def _dual_cone_margin(v, frame):
    """``v_n - (mu/s) |v_t|`` per contact (``> 0``: inside the dual cone), ``v (3, 3)`` in xyz."""
    kappa = np.linalg.norm(frame[:, 1], axis=-1)
    vn = dot(v, frame[:, 0])
    return vn - np.linalg.norm(v - vn[:, None] * frame[:, 0], axis=-1) / kappa


def _on_the_edge(frame, m, fm, z):
    r"""The grip of one row whose phase I ended on the edge (``r -> 0``, its ``y . w = 0``): facial reduction.

    Phase I's multipliers ``z_i`` give ``-G_i^T y``; where that lies strictly inside the
    dual cone, ``0 = y . w = -sum_i u_i . f_i`` forces ``f_i = 0``.  The other contacts'
    cones are then solved over the internal forces that leave those contacts bare: where these
    are a line (one bare contact, as a rule), in closed form (:func:`one.least_on_line`, which
    the compiled kernel's own reduction, ``kernel._on_the_edge``, shares).  Returns
    the internal-force coordinates and the kept cones' multipliers (``(3, 3)``, zero at
    the bare contacts), or None (no contact is forced bare, infinite friction, or the
    smaller problem has no strictly feasible point either).
    """
    if not (np.linalg.norm(frame[:, 1], axis=-1) > 0).all():
        return None
    bare = z[:, 0] - np.hypot(z[:, 1], z[:, 2]) > 1e-6 * np.abs(z).max()
    if not bare.any() or bare.all():
        return None
    d = m.shape[-1]
    mz, rhs = m[bare].reshape(-1, d), -fm[bare].reshape(-1)
    s0 = np.linalg.lstsq(mz, rhs, rcond=None)[0]
    if np.abs(mz @ s0 - rhs).max() > 1e-9 * max(np.abs(fm).max(), 1.0):
        return None
    _, sv, vt = np.linalg.svd(mz)
    free = vt[int((sv > 1e-12 * sv[0]).sum()) :].T  # (d, d'): internal forces that leave the bare contacts bare
    kept = ~bare
    A = frame[kept] @ m[kept]  # (k, 3, d)
    b = np.einsum("ikx,ix->ik", frame[kept], fm[kept] + m[kept] @ s0)
    multipliers = np.zeros((3, 3))
    if not free.shape[1]:
        if not (b[:, 0] >= np.hypot(b[:, 1], b[:, 2]) - 1e-12 * np.abs(b).max()).all():
            return None
        return s0, multipliers, bare  # one grip only: every kept cone's multiplier 0 closes the gap
    if free.shape[1] == 1:  # a line through the kept cones (one bare contact, as a rule): its least in closed form
        line = (A @ free)[..., 0]
        t, m, coef = one.least_on_line(line.tolist(), b.tolist(), len(b))
        if m < 0:
            return None
        y = line[m] * t + b[m]
        multipliers[np.flatnonzero(kept)[m]] = coef * y * [1, -1, -1]
        return s0 + free[:, 0] * t, multipliers, bare
    # more freedom (a rank-deficient bare contact): the method in floats
    reduced, b = (A @ free).tolist(), b.tolist()
    x, r, _ = one.phase_one(reduced, b)
    if not r < 0:
        return None
    t, zk = one.minimise(reduced, b, np.sum([a[0] for a in reduced], axis=0).tolist(), x, one.newton_matrices(reduced))
    multipliers[kept] = zk
    return s0 + free @ np.array(t), multipliers, bare


def _edge_dual(frame, p, unit, z, y, bare):
    """The dual of an edge row: the kept contacts' twist, plus enough of ``y`` for the bare contacts' cones.

    ``n_i - G_i^T lambda`` must lie in every dual cone; ``-G_i^T y`` is strictly inside at a
    bare contact and on the edge at a kept one, and ``y . w = 0``: adding ``alpha y`` keeps
    the kept cones and the objective and, ``alpha`` large enough, brings in the bare ones.
    """
    u = np.einsum("ikx,ik->ix", frame, z)
    rows = np.concatenate([np.hstack((np.eye(3), -_skew(q))) for q in p])  # G_i^T: lambda -> lambda_F + lambda_M x p_i
    kept = np.repeat(~bare, 3)
    lam = np.linalg.lstsq(rows[kept], (unit - u).reshape(-1)[kept], rcond=None)[0]
    need = -_dual_cone_margin(unit - (rows @ lam).reshape(3, 3), frame)[bare]
    gain = _dual_cone_margin((rows @ -y).reshape(3, 3), frame)[bare]
    return lam + np.max(np.maximum(need, 0) / gain) * y


def _skew(q):
    return np.array([[0, -q[2], q[1]], [q[2], 0, -q[0]], [-q[1], q[0], 0]])


def _rows(named, rows):
    """A NamedTuple of arrays over rows, at ``rows``."""
    return type(named)(*(a[rows] for a in named))


def _line_matrices(cmap):
    """The internal forces of collinear contacts as ``M (n, 3, 3, 4)`` (contact, xyz, column), or None."""
    if cmap is None:
        return None
    return cmap.null.reshape(-1, 3, 3, 4)


def _squeezes_of(e, internal):
    """The squeezes ``s`` with ``squeeze_forces(s) = internal`` (least squares over the 9 numbers)."""
    m = contact_matrices(e).reshape(len(e), 9, 3)
    return (np.linalg.pinv(m) @ internal.reshape(len(e), 9)[..., None])[..., 0]


def _cones(frame, m, fm, scale):
    """``A = F M``, ``b = F f_m / scale`` and ``c = sum_i A_i[0]`` from the cones' frames ``F`` and the internal
    forces' map ``M``: :func:`set_up.cone_rows`' numpy twin."""
    rows, d = len(fm), m.shape[-1]
    A, b = np.empty((rows, 3, 3, d)), np.empty((rows, 3, 3))
    set_up.on_rows("cone_rows", frame, m, fm, scale, A, b, d, rows)
    return A, b, A[:, :, 0, :].sum(axis=1)


def _rays(a):
    """The cones' rows ``A (n, 3, 3, d)`` or ``b (n, 3, 3)`` with no friction limit: their tangential rows 0."""
    out = a.copy()
    out[:, :, 1:] = 0.0
    return out


def _solve(frame, m, fm, scale, inside):
    """The grip's internal-force coordinates for rows scaled to order one (``fm / scale``), the cones'
    multipliers, failing rows and their culprits.

    ``inside (n, d)``: internal-force coordinates strictly inside every cone (NaN where
    the grasp is not force closure with its limit); far enough along it is a start for
    phase II, so phase I runs only for the other rows.  The multipliers ``z (n, 3, 3)`` are
    phase II's where the grip exists, phase I's (a proof that none does) where it fails.
    """
    A, b, c = _cones(frame, m, fm, scale)
    n, d = len(fm), m.shape[-1]
    x = np.zeros((n, d))
    r = np.full(n, -1.0)
    z = np.zeros((n, 3, 3))
    closing = np.flatnonzero(~np.isnan(inside).any(axis=1))
    if closing.size:
        start = x[closing]
        set_up.on_rows("start", A[closing], b[closing], inside[closing], start, d, closing.size)
        x[closing] = start
    other = np.flatnonzero(np.isnan(x).any(axis=1) | np.isnan(inside).any(axis=1))
    if other.size:
        x[other], r[other], z[other] = socp.phase_one(A[other], b[other])
    fail = ~(r < 0)
    s = np.full((n, d), np.nan)
    good = np.flatnonzero(~fail)
    if good.size:
        s[good], z[good] = socp.minimise(A[good], b[good], c[good], x[good])
        z[good] = socp.dual_polish(A[good], b[good], c[good], s[good], z[good])
    blame = np.full(n, -1, np.int8)
    bad = np.flatnonzero(fail)
    if bad.size:
        # the cone each leaves furthest, and whether it may be infeasible even with unlimited friction
        # (half-spaces n.f >= 0: pulling), which it cannot be where the squeezes reach every normal force
        culprit, pulling = np.empty(bad.size, np.int64), np.empty(bad.size, bool)
        set_up.on_rows("culprit", A[bad], b[bad], x[bad], culprit, pulling, d, bad.size)
        blame[bad] = culprit
        maybe = np.flatnonzero(pulling)
        if maybe.size:
            rows = bad[maybe]
            r0 = socp.phase_one(_rays(A[rows]), _rays(b[rows]))[1]
            blame[rows] = np.where(r0 < 0, blame[rows], -1)
    return s, z, fail, blame
