"""The paper's two decompositions of an object twist, on batches of grasps.

* :func:`decompose_off_tangent` -- Proposition 1 (eqs. 8-14): ``T = sum x_i
  Sigma_i + sum y_i Psi_i``, where ``Sigma_i`` (the line ``p_j p_k``) moves
  only contact ``i`` and ``Psi_i`` (the line from the wrist ``c`` through
  ``p_i``) keeps contact ``i`` fixed.
* :func:`decompose_tangent` -- Proposition 2 (eqs. 19-27) and the extension
  of NOTES.md: ``T = sum alpha_i Theta_i + sum beta_i Sigma_i``, where
  ``Theta_i`` keeps contact ``i`` fixed and the other two sliding in their
  tangent planes.  ``beta = 0`` exactly when ``T`` moves every contact in its
  tangent plane.
* :func:`contact_velocities` -- ``T(p_i)``.

Shapes: ``points`` and ``normals`` are ``(..., 3, 3)`` (contact, xyz),
``wrist`` is ``(..., 3)``, ``twist`` is ``(..., 6)`` as ``(omega; v)`` with
``v`` the velocity of the frame origin.  Leading shapes broadcast, so one
grasp can take many twists or many grasps one twist.  Indices ``(i, j, k)``
run cyclically over ``(0, 1, 2), (1, 2, 0), (2, 0, 1)``.

How it is computed
------------------
Eqs. 14 and 27 divide Klein products.  For a unit line ``L`` through ``a``
along ``d``, ``[T|L] = d . T(a)``; with ``U_i = p_k - p_j`` (the side
opposite contact ``i``), ``E_i = p_i - c`` and ``m = (p_2 - p_1) x (p_3 - p_1)``
(twice the contacts' area, normal to their plane), the products reduce to
closed forms that need no 6-vector algebra:

* ``[Sigma_i|Psi_i] = D / (|U_i| |E_i|)`` with ``D = m . (p_1 - c)``, the same
  ``D`` for every ``i``, so
  ``x_i = |U_i| E_i . T(p_i) / D`` and ``y_i = |E_i| U_i . T(p_j) / D``;
* ``Sigma_i(p_i) = m / |U_i|``, so ``[Theta_i|Sigma_i] = w^_i . m / |U_i|``
  and ``alpha_i = U_i . T(p_j) / (w^_i . m)``;
* every ``Theta_j`` and ``Sigma_j`` (``j != i``) keeps ``p_i`` in its tangent
  plane, so the normal velocity ``T(p_i) . n_i`` is ``beta_i Sigma_i(p_i) . n_i``:
  ``beta_i = |U_i| T(p_i) . n_i / (m . n_i)``.

Differences of points are divided by the grasp's extent ``s`` before any
product, so degeneracy tests are free of scale and position and coordinates
like 1e200 do not overflow.  All arithmetic is element-wise: a row's numbers
do not depend on the batch it is in.

The tangent method is degenerate exactly when some normal lies in the
contacts' plane (``m . n_i = 0``): a normal line set of rank < 3, a
``Theta_i`` that is not unique, and ``[Theta_i|Sigma_i] = 0`` each imply it.
So the engine gates on ``m . n_i`` and then names the specific condition.

A degenerate grasp never raises: its row gets a
:class:`~grasptwist.degeneracy.Status` and NaN amplitudes, while every other
row is computed exactly as it would be alone.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from functools import cached_property
from typing import NamedTuple

import numpy as np

from .degeneracy import DEGENERACY_TOL, IN_PLANE_TOL, Status
from .screws import cross, dot, field_at, norm

__all__ = [
    "OffTangentResult",
    "TangentResult",
    "decompose_off_tangent",
    "decompose_tangent",
    "contact_velocities",
]

_J = [1, 2, 0]  # j = i + 1 (mod 3)
_K = [2, 0, 1]  # k = i + 2 (mod 3)


def contact_velocities(points, twist):
    """Velocities ``T(p_i) = v + omega x p_i`` of the three contacts.

    Parameters
    ----------
    points : (..., 3, 3) array
    twist : (..., 6) array, ``(omega; v)``

    Returns
    -------
    (..., 3, 3) array, row ``i`` the velocity of contact ``i``.

    >>> contact_velocities([[1.0, 0, 0], [0, 1, 0], [0, 0, 1]], [0, 0, 1.0, 0, 0, 0]).tolist()
    [[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 0.0]]
    """
    points = _checked(points, (3, 3), "points")
    twist = _checked(twist, (6,), "twist")
    return field_at(twist[..., None, :], points)


class _Result:
    """What both results share: row access and the lazily computed residual."""

    @property
    def ok(self) -> np.ndarray:
        """``status == 0`` per row."""
        return self.status == Status.OK

    def row(self, i):
        """Row ``i`` (an index into the leading axis) as a result of the same type."""
        r = type(self)(**{f.name: getattr(self, f.name)[i] for f in fields(self)})
        if "residual" in self.__dict__:  # carry a residual already computed for the batch
            r.__dict__["residual"] = self.__dict__["residual"][i]
        return r

    @cached_property
    def residual(self) -> np.ndarray:
        """``max_i |R(p_i)| / max_i |T(p_i)|``, ``R`` = the sum of the components minus ``T``.

        Computed on first access from the returned screws and amplitudes;
        NaN in failed rows, 0 for the zero twist.
        """
        r = sum(a.sum(axis=-2) for a in self.components()) - self.twist
        err = np.max(norm(field_at(r[..., None, :], self.points)), axis=-1)
        ref = np.max(norm(field_at(self.twist[..., None, :], self.points)), axis=-1)
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(ref > 0, err / np.where(ref > 0, ref, 1.0), err)


@dataclass(frozen=True, eq=False)
class OffTangentResult(_Result):
    """Proposition 1 for a batch: ``T = sum x_i Sigma_i + sum y_i Psi_i``.

    Attributes
    ----------
    sigma, psi : (..., 3, 6)
        Unit basis lines.  ``Sigma_i`` passes through ``p_j`` along
        ``p_k - p_j``; ``Psi_i`` passes through ``p_i`` along ``p_i - c``.
    sigma_psi : (..., 3)
        ``[Sigma_i | Psi_i]`` (eq. 14's denominators; a length).
    x, y : (..., 3)
        Amplitudes, eq. 14.  NaN where ``status != 0``.
    status, culprit : (...) int8
        :class:`~grasptwist.degeneracy.Status` and the contact it is about.
    conditioning : (...)
        ``min_i |[Sigma_i|Psi_i]| / size`` (dimensionless; size = longest
        side of the contact triangle).
    points, twist : (..., 3, 3), (..., 6)
        The inputs, for :attr:`residual`.
    residual : (...)
        See :attr:`_Result.residual`.
    """

    sigma: np.ndarray
    psi: np.ndarray
    sigma_psi: np.ndarray
    x: np.ndarray
    y: np.ndarray
    status: np.ndarray
    culprit: np.ndarray
    conditioning: np.ndarray
    points: np.ndarray
    twist: np.ndarray

    def components(self):
        """The component twists ``(x_i Sigma_i, y_i Psi_i)``, each ``(..., 3, 6)``."""
        return self.x[..., None] * self.sigma, self.y[..., None] * self.psi


@dataclass(frozen=True, eq=False)
class TangentResult(_Result):
    """Proposition 2 and its extension: ``T = sum alpha_i Theta_i + sum beta_i Sigma_i``.

    Attributes
    ----------
    theta : (..., 3, 6)
        Unit lines through ``p_i`` along ``w_i = (n_j x p_i p_j) x (n_k x p_i p_k)``
        (eq. 22): twists that fix ``p_i`` and slide ``p_j``, ``p_k`` in their
        tangent planes.
    sigma : (..., 3, 6)
        The same ``Sigma_i`` as :class:`OffTangentResult`.
    theta_sigma : (..., 3)
        ``[Theta_i | Sigma_i]`` (eq. 27's denominators).
    alpha : (..., 3)
        Tangent amplitudes, eq. 27.
    beta : (..., 3)
        Off-plane remainder amplitudes, ``beta_i = [R|Theta_i]/[Sigma_i|Theta_i]``
        with ``R = T - sum alpha_i Theta_i`` (NOTES.md).  Zero when ``T``
        keeps every contact in its tangent plane.
    normal_velocity : (..., 3)
        ``[T | nu_i] = T(p_i) . n_i`` with unit normals.
    in_tangent_planes : (...) bool
        Every normal velocity is zero to ``IN_PLANE_TOL`` relative to the
        contacts' speeds: ``T`` is realisable by tangent sliding alone.
    status, culprit : (...) int8
        As in :class:`OffTangentResult`.
    conditioning : (...)
        The smaller of ``min_i |[Theta_i|Sigma_i]| / size`` and of
        ``min_i |sin|`` of the angle between normal ``i`` and the contacts'
        plane; both go to 0 at every degenerate grasp.
    points, twist : (..., 3, 3), (..., 6)
        The inputs, for :attr:`residual` and :meth:`contact_split`.
    """

    theta: np.ndarray
    sigma: np.ndarray
    theta_sigma: np.ndarray
    alpha: np.ndarray
    beta: np.ndarray
    normal_velocity: np.ndarray
    in_tangent_planes: np.ndarray
    status: np.ndarray
    culprit: np.ndarray
    conditioning: np.ndarray
    points: np.ndarray
    twist: np.ndarray

    def components(self):
        """The component twists ``(alpha_i Theta_i, beta_i Sigma_i)``, each ``(..., 3, 6)``."""
        return self.alpha[..., None] * self.theta, self.beta[..., None] * self.sigma

    def contact_split(self):
        """Each contact's velocity split by the screws that move it (the paper's second approach).

        ``Theta_i`` and ``Sigma_j`` (``j != i``) leave ``p_i`` fixed, so
        ``T(p_i) = sum_{j != i} alpha_j Theta_j(p_i) + beta_i Sigma_i(p_i)``.

        Returns
        -------
        theta_velocity : (..., 3, 3, 3)
            ``[..., i, j, :] = alpha_j Theta_j(p_i)``, zero for ``j == i``;
            each lies in the tangent plane at ``p_i``.
        sigma_velocity : (..., 3, 3)
            ``[..., i, :] = beta_i Sigma_i(p_i)``, normal to the contact plane.
        """
        theta_at = field_at(self.theta[..., None, :, :], self.points[..., :, None, :])
        sigma_at = field_at(self.sigma, self.points)
        return self.alpha[..., None, :, None] * theta_at, self.beta[..., None] * sigma_at


class _Contacts(NamedTuple):
    """The contact triangle of a batch of grasps, in units of its extent ``s``."""

    scale: np.ndarray  # (...) s: the largest coordinate difference between contacts
    side: np.ndarray  # (..., 3, 3) U_i / s, side i = p_k - p_j
    side_len: np.ndarray  # (..., 3) |U_i| / s
    size: np.ndarray  # (...) longest side / s
    m: np.ndarray  # (..., 3) m / s^2, twice the area, normal to the plane
    sigma: np.ndarray  # (..., 3, 6) Sigma_i
    status: np.ndarray  # (...) non-finite / coincident / collinear
    culprit: np.ndarray  # (...)


def decompose_off_tangent(points, wrist, twist, *, tol=DEGENERACY_TOL) -> OffTangentResult:
    """Resolve ``twist`` on the off-tangent basis (Proposition 1).

    ``x_i = [T|Psi_i] / [Sigma_i|Psi_i]``, ``y_i = [T|Sigma_i] / [Sigma_i|Psi_i]``
    (eq. 14), valid when the wrist is off the contacts' plane.

    Parameters
    ----------
    points : (..., 3, 3) array
    wrist : (..., 3) array
        The point ``c`` (centre of the wrist's spherical joint).
    twist : (..., 6) array, ``(omega; v)`` with ``v`` at the origin.
    tol : float
        Relative tolerance of the degeneracy tests (see :mod:`grasptwist.degeneracy`).

    Returns
    -------
    OffTangentResult

    Examples
    --------
    Paper Example 1b, a spin about z (NOTES.md's corrected values):

    >>> p = [[1, 0, 0], [-0.5, 0.866, 0], [-0.5, -0.866, 0]]
    >>> r = decompose_off_tangent(p, [0, 0, 1], [0, 0, 1, 0, 0, 0])
    >>> np.round(r.y, 4).tolist(), bool(np.allclose(r.x, 0))
    ([-0.4714, -0.4714, -0.4714], True)
    """
    points = _checked(points, (3, 3), "points")
    wrist = _checked(wrist, (3,), "wrist")
    twist = _checked(twist, (6,), "twist")
    g = _contacts(points, tol)
    with np.errstate(all="ignore"):
        s = g.scale[..., None]
        e = (points - wrist[..., None, :]) / s[..., None]  # E_i / s
        e_len = norm(e)
        d = dot(g.m, e[..., 0, :])  # D / s^3, one for all i
        conditioning = np.min(np.abs(d[..., None]) / (g.side_len * e_len), axis=-1) / g.size
        grasp_status, culprit = _first_failure(
            g,
            (~np.isfinite(wrist).all(axis=-1), Status.NONFINITE_INPUT, -1),
            (~(conditioning > tol), Status.WRIST_COPLANAR, -1),
        )
        speed = field_at(twist[..., None, :], points) / s[..., None]  # T(p_i) / s
        x = g.side_len * dot(e, speed) / d[..., None]
        y = e_len * dot(g.side, speed[..., _J, :]) / d[..., None]
        psi = _line(points, e / e_len[..., None])
        sigma_psi = s * d[..., None] / (g.side_len * e_len)
    status, culprit = _row_status(grasp_status, culprit, twist, (x, y))
    shape = status.shape
    return OffTangentResult(
        sigma=_spread(g.sigma, shape + (3, 6)),
        psi=_spread(psi, shape + (3, 6)),
        sigma_psi=_spread(sigma_psi, shape + (3,)),
        x=_failed_to_nan(x, status),
        y=_failed_to_nan(y, status),
        status=status,
        culprit=culprit,
        conditioning=_spread(conditioning, shape),
        points=_spread(points, shape + (3, 3)),
        twist=_spread(twist, shape + (6,)),
    )


def decompose_tangent(points, normals, twist, *, tol=DEGENERACY_TOL) -> TangentResult:
    """Resolve ``twist`` on the tangent basis ``Theta`` plus the off-plane ``Sigma``.

    ``alpha_i = [T|Sigma_i] / [Theta_i|Sigma_i]`` (eq. 27) and
    ``beta_i = [T - sum alpha_j Theta_j | Theta_i] / [Sigma_i|Theta_i]``, so
    that ``sum alpha_i Theta_i + sum beta_i Sigma_i = T`` for any twist.

    Parameters
    ----------
    points : (..., 3, 3) array
    normals : (..., 3, 3) array
        Surface normals at the contacts, any non-zero length (normalised here).
    twist : (..., 6) array, ``(omega; v)`` with ``v`` at the origin.
    tol : float
        Relative tolerance of the degeneracy tests.

    Returns
    -------
    TangentResult

    Examples
    --------
    Paper Example 2 (``alpha = 0.5774`` each, no off-plane part):

    >>> p = [[0, 2, 2], [2, 0, 2], [2, 2, 0]]
    >>> r = decompose_tangent(p, np.eye(3), [0.57735, 0.57735, 0.57735, 0, 0, 0])
    >>> np.round(r.alpha, 4).tolist(), np.round(r.beta, 4).tolist(), bool(r.in_tangent_planes)
    ([0.5774, 0.5774, 0.5774], [0.0, 0.0, 0.0], True)
    """
    points = _checked(points, (3, 3), "points")
    normals = _checked(normals, (3, 3), "normals")
    twist = _checked(twist, (6,), "twist")
    g = _contacts(points, tol)
    with np.errstate(all="ignore"):
        s = g.scale[..., None]
        n_len = norm(normals)
        n = normals / n_len[..., None]
        # eq. 21-22 with p_i p_j = U_k and p_i p_k = -U_j
        a = cross(g.side[..., _K, :], n[..., _J, :])
        b = cross(n[..., _K, :], g.side[..., _J, :])
        w = cross(a, b)
        w_len = norm(w)
        w_unit = w / w_len[..., None]
        wm = dot(w_unit, g.m[..., None, :])  # w^_i . m / s^2
        mn = dot(g.m[..., None, :], n)  # m . n_i / s^2
        plane_sine = np.abs(mn) / norm(g.m)[..., None]
        theta_sigma_rel = np.abs(wm) / (g.side_len * g.size[..., None])
        conditioning = np.minimum(np.min(theta_sigma_rel, axis=-1), np.min(plane_sine, axis=-1))
        degenerate = ~(conditioning > tol)
        uniqueness = np.minimum(
            np.minimum(norm(a) / g.side_len[..., _K], norm(b) / g.side_len[..., _J]), w_len / (norm(a) * norm(b))
        )
        grasp_status, culprit = _first_failure(
            g,
            (~np.isfinite(normals).all(axis=(-2, -1)), Status.NONFINITE_INPUT, -1),
            (~(n_len > 0).all(axis=-1), Status.ZERO_NORMAL, np.argmin(n_len, axis=-1)),
            (degenerate & _rank_deficient(points, n, g, degenerate, tol), Status.NORMALS_RANK_DEFICIENT, -1),
            (degenerate & ~(uniqueness > tol).all(axis=-1), Status.THETA_NOT_UNIQUE, np.argmin(uniqueness, axis=-1)),
            (degenerate & ~(theta_sigma_rel > tol).all(axis=-1), Status.THETA_SIGMA_ZERO, np.argmin(theta_sigma_rel, axis=-1)),
            (degenerate, Status.NORMAL_IN_CONTACT_PLANE, np.argmin(plane_sine, axis=-1)),
        )
        velocity = field_at(twist[..., None, :], points)
        normal_velocity = dot(velocity, n)
        alpha = dot(g.side, velocity[..., _J, :]) / (s * wm)
        beta = g.side_len * normal_velocity / (s * mn)
        theta = _line(points, w_unit)
        # Round-off in v + omega x p scales with |v| + |omega||p|, not with the result.
        slack = IN_PLANE_TOL * np.max(norm(twist[..., None, 3:]) + norm(twist[..., None, :3]) * norm(points), axis=-1)
        in_planes = np.max(np.abs(normal_velocity), axis=-1) <= slack
        theta_sigma = s * wm / g.side_len
    status, culprit = _row_status(grasp_status, culprit, twist, (alpha, beta))
    shape = status.shape
    return TangentResult(
        theta=_spread(theta, shape + (3, 6)),
        sigma=_spread(g.sigma, shape + (3, 6)),
        theta_sigma=_spread(theta_sigma, shape + (3,)),
        alpha=_failed_to_nan(alpha, status),
        beta=_failed_to_nan(beta, status),
        normal_velocity=_failed_to_nan(normal_velocity, status),
        in_tangent_planes=in_planes & (status == Status.OK),
        status=status,
        culprit=culprit,
        conditioning=_spread(conditioning, shape),
        points=_spread(points, shape + (3, 3)),
        twist=_spread(twist, shape + (6,)),
    )


def _contacts(points, tol) -> _Contacts:
    """The contact triangle and its degeneracies.

    Contacts coincide when the shortest side is ``<= tol`` times the longest;
    they are collinear when twice the area is ``<= tol`` times the longest
    side squared (a height ``<= tol`` times the size).
    """
    side = points[..., _K, :] - points[..., _J, :]
    with np.errstate(all="ignore"):
        scale = np.max(np.abs(side), axis=(-2, -1))
        side = side / scale[..., None, None]
        side_len = norm(side)
        size = np.max(side_len, axis=-1)
        m = cross(side[..., 1, :], side[..., 2, :])
        status = np.select(
            [
                ~np.isfinite(points).all(axis=(-2, -1)),
                ~(np.min(side_len, axis=-1) > tol * size),
                ~(norm(m) > tol * size * size),
            ],
            [Status.NONFINITE_INPUT, Status.COINCIDENT_CONTACTS, Status.COLLINEAR_CONTACTS],
            Status.OK,
        ).astype(np.int8)
        # The pair that coincides is opposite the shortest side; the contact
        # between the other two is opposite the longest.
        culprit = np.select(
            [status == Status.COINCIDENT_CONTACTS, status == Status.COLLINEAR_CONTACTS],
            [np.argmin(side_len, axis=-1), np.argmax(side_len, axis=-1)],
            -1,
        ).astype(np.int8)
        sigma = _line(points[..., _J, :], side / side_len[..., None])
    return _Contacts(scale, side, side_len, size, m, sigma, status, culprit)


def _line(p, d):
    """Unit lines ``(d; p x d)`` for unit directions ``d``: ``(..., 3) x2 -> (..., 6)``."""
    return np.concatenate((d, cross(p, d)), axis=-1)


def _rank_deficient(points, n, g: _Contacts, rows, tol):
    """Whether the normal lines ``nu_i = (n_i; p_i x n_i)`` have rank < 3, tested
    only in ``rows`` (False elsewhere) since it costs more than the rest.

    Gram-Schmidt on the three 6-vectors, taken about ``p_1`` in units of
    ``s``: the product of the orthogonalised lengths over the original ones
    is in ``[0, 1]`` and accurate to round-off even near 0.
    """
    out = np.zeros(rows.shape, dtype=bool)
    if not rows.any():
        return out
    shape = rows.shape
    q = np.broadcast_to((points - points[..., :1, :]) / g.scale[..., None, None], shape + (3, 3))[rows]
    nu = _line(q, np.broadcast_to(n, shape + (3, 3))[rows])
    r1, r2, r3 = nu[..., 0, :], nu[..., 1, :], nu[..., 2, :]
    u1 = r1 / _len6(r1)[..., None]
    r2o = r2 - _dot6(r2, u1)[..., None] * u1
    u2 = r2o / _len6(r2o)[..., None]
    r3o = r3 - _dot6(r3, u1)[..., None] * u1 - _dot6(r3, u2)[..., None] * u2
    out[rows] = ~(_len6(r2o) * _len6(r3o) / (_len6(r2) * _len6(r3)) > tol)
    return out


def _dot6(a, b):
    return dot(a[..., :3], b[..., :3]) + dot(a[..., 3:], b[..., 3:])


def _len6(a):
    return np.sqrt(_dot6(a, a))


def _first_failure(g: _Contacts, *checks):
    """Status and culprit of each grasp: the triangle's own, else the first
    failing ``(mask, status, culprit)`` check, in order."""
    masks = [g.status != Status.OK] + [m for m, _, _ in checks]
    shape = np.broadcast_shapes(*(np.shape(m) for m in masks))
    status = np.select(masks, [g.status] + [s for _, s, _ in checks], Status.OK)
    culprit = np.select(masks, [g.culprit] + [c for _, _, c in checks], -1)
    return np.broadcast_to(status, shape).astype(np.int8), np.broadcast_to(culprit, shape).astype(np.int8)


def _row_status(grasp_status, culprit, twist, outputs):
    """Per-(grasp, twist) status: the grasp's, a non-finite twist, or an
    overflow that left a non-finite number in an otherwise good row."""
    twist_bad = ~np.isfinite(twist).all(axis=-1)
    shape = np.broadcast_shapes(grasp_status.shape, twist_bad.shape)
    status = np.where((grasp_status == Status.OK) & twist_bad, Status.NONFINITE_INPUT, grasp_status)
    finite = np.ones(shape, dtype=bool)
    for out in outputs:
        finite &= np.isfinite(out).all(axis=-1)
    status = np.where((status == Status.OK) & ~finite, Status.OVERFLOW, status)
    culprit = np.where(status == grasp_status, culprit, -1)
    return np.broadcast_to(status, shape).astype(np.int8), np.broadcast_to(culprit, shape).astype(np.int8)


def _failed_to_nan(a, status):
    """A copy of ``a`` with NaN in the rows whose status is not OK."""
    bad = status != Status.OK
    return np.where(bad.reshape(bad.shape + (1,) * (np.ndim(a) - bad.ndim)), np.nan, a)


def _spread(a, shape):
    """Broadcast a per-grasp array to the full (grasp, twist) batch shape (a view)."""
    return np.broadcast_to(a, shape)


def _checked(a, trailing, name):
    """``a`` as a float array whose shape ends in ``trailing`` (checked once, here)."""
    a = np.asarray(a, dtype=float)
    if a.ndim < len(trailing) or a.shape[a.ndim - len(trailing) :] != trailing:
        want = "(..., " + ", ".join(map(str, trailing)) + ")"
        raise ValueError(f"{name} must have shape {want}, got {a.shape}")
    return a
