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

Numerics: every basis is built in the grasp's own frame (origin at the
contacts' centroid, lengths divided by the grasp's half-extent ``s``) and
mapped back at the end.  Amplitudes do not change under that map (it sends
unit lines to unit lines), the degeneracy tests become scale and position
free, and coordinates like 1e200 do not overflow.

A degenerate grasp never raises: its row gets a :class:`~grasptwist.degeneracy.Status`
and NaN amplitudes, while every other row is computed exactly as it would
be alone (all arithmetic is element-wise).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from .degeneracy import DEGENERACY_TOL, IN_PLANE_TOL, Status
from .screws import cross, dot, field_at, klein, line_through, norm, screw

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


@dataclass(frozen=True)
class OffTangentResult:
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
    residual : (...)
        ``max_i |R(p_i)| / max_i |T(p_i)|`` for ``R`` the reconstruction
        minus ``T``, in the grasp's frame.
    """

    sigma: np.ndarray
    psi: np.ndarray
    sigma_psi: np.ndarray
    x: np.ndarray
    y: np.ndarray
    status: np.ndarray
    culprit: np.ndarray
    conditioning: np.ndarray
    residual: np.ndarray

    @property
    def ok(self) -> np.ndarray:
        """``status == 0`` per row."""
        return self.status == Status.OK

    def components(self):
        """The component twists ``(x_i Sigma_i, y_i Psi_i)``, each ``(..., 3, 6)``."""
        return self.x[..., None] * self.sigma, self.y[..., None] * self.psi


@dataclass(frozen=True)
class TangentResult:
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
    points : (..., 3, 3)
        The contacts, kept for :meth:`contact_split`.
    status, culprit, conditioning, residual
        As in :class:`OffTangentResult`; conditioning is
        ``min_i |[Theta_i|Sigma_i]| / size``.
    """

    theta: np.ndarray
    sigma: np.ndarray
    theta_sigma: np.ndarray
    alpha: np.ndarray
    beta: np.ndarray
    normal_velocity: np.ndarray
    in_tangent_planes: np.ndarray
    points: np.ndarray
    status: np.ndarray
    culprit: np.ndarray
    conditioning: np.ndarray
    residual: np.ndarray

    @property
    def ok(self) -> np.ndarray:
        """``status == 0`` per row."""
        return self.status == Status.OK

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


class _Frame(NamedTuple):
    """A batch of grasps in their own frame: ``p = centroid + scale * q``."""

    centroid: np.ndarray  # (..., 3)
    scale: np.ndarray  # (...)
    q: np.ndarray  # (..., 3, 3)
    size: np.ndarray  # (...) longest side of the triangle q
    sigma: np.ndarray  # (..., 3, 6) Sigma_i in the frame
    status: np.ndarray  # (...) coincident / collinear / non-finite
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
    f = _frame(points, tol)
    with np.errstate(all="ignore"):
        c = (wrist - f.centroid) / f.scale[..., None]
        psi = line_through(f.q, f.q - c[..., None, :])
        sigma_psi = klein(f.sigma, psi)
        conditioning = np.min(np.abs(sigma_psi), axis=-1) / f.size
        grasp_status, culprit = _first_failure(
            f,
            (~np.isfinite(wrist).all(axis=-1), Status.NONFINITE_INPUT, -1),
            (~(conditioning > tol), Status.WRIST_COPLANAR, -1),
        )
        t = _into_frame(twist, f)[..., None, :]
        x = klein(t, psi) / sigma_psi
        y = klein(t, f.sigma) / sigma_psi
        residual = _residual(t[..., 0, :], f.q, (x, f.sigma), (y, psi))
    status, culprit = _row_status(grasp_status, culprit, twist, (x, y, residual))
    shape = status.shape
    return OffTangentResult(
        sigma=_spread(_out_of_frame(f.sigma, f), shape + (3, 6)),
        psi=_spread(_out_of_frame(psi, f), shape + (3, 6)),
        sigma_psi=_spread(sigma_psi * f.scale[..., None], shape + (3,)),
        x=_failed_to_nan(x, status),
        y=_failed_to_nan(y, status),
        status=status,
        culprit=culprit,
        conditioning=_spread(conditioning, shape),
        residual=_failed_to_nan(residual, status),
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
    f = _frame(points, tol)
    with np.errstate(all="ignore"):
        n_len = norm(normals)
        n = normals / n_len[..., None]
        theta, uniqueness = _theta(f.q, n)
        theta_sigma = klein(theta, f.sigma)
        conditioning = np.min(np.abs(theta_sigma), axis=-1) / f.size
        grasp_status, culprit = _first_failure(
            f,
            (~np.isfinite(normals).all(axis=(-2, -1)), Status.NONFINITE_INPUT, -1),
            (~(n_len > 0).all(axis=-1), Status.ZERO_NORMAL, np.argmin(n_len, axis=-1)),
            (~(_normal_lines_volume(f.q, n) > tol), Status.NORMALS_RANK_DEFICIENT, -1),
            (~(uniqueness > tol).all(axis=-1), Status.THETA_NOT_UNIQUE, np.argmin(uniqueness, axis=-1)),
            (~(conditioning > tol), Status.THETA_SIGMA_ZERO, np.argmin(np.abs(theta_sigma), axis=-1)),
        )
        t = _into_frame(twist, f)[..., None, :]
        alpha = klein(t, f.sigma) / theta_sigma
        rest = t[..., 0, :] - _combine(alpha, theta)
        beta = klein(rest[..., None, :], theta) / theta_sigma
        residual = _residual(t[..., 0, :], f.q, (alpha, theta), (beta, f.sigma))
        speed = field_at(twist[..., None, :], points)
        normal_velocity = dot(speed, n)
        # Round-off in v + omega x p scales with |v| + |omega||p|, not with the result.
        slack = IN_PLANE_TOL * np.max(norm(twist[..., None, 3:]) + norm(twist[..., None, :3]) * norm(points), axis=-1)
        in_planes = np.max(np.abs(normal_velocity), axis=-1) <= slack
    status, culprit = _row_status(grasp_status, culprit, twist, (alpha, beta, residual))
    shape = status.shape
    return TangentResult(
        theta=_spread(_out_of_frame(theta, f), shape + (3, 6)),
        sigma=_spread(_out_of_frame(f.sigma, f), shape + (3, 6)),
        theta_sigma=_spread(theta_sigma * f.scale[..., None], shape + (3,)),
        alpha=_failed_to_nan(alpha, status),
        beta=_failed_to_nan(beta, status),
        normal_velocity=_failed_to_nan(normal_velocity, status),
        in_tangent_planes=in_planes & (status == Status.OK),
        points=_spread(points, shape + (3, 3)),
        status=status,
        culprit=culprit,
        conditioning=_spread(conditioning, shape),
        residual=_failed_to_nan(residual, status),
    )


def _theta(q, n):
    """Unit ``Theta_i`` (eq. 22) in the frame, and how unique each is.

    ``w_i`` must be orthogonal to ``a = p_i p_j x n_j`` and ``b = p_i p_k x n_k``
    (eq. 21).  Crossing the *unit* ``a`` and ``b`` keeps ``w_i`` accurate
    at any scale; the null space of ``(a; b)`` is a single line exactly when
    ``a`` and ``b`` are non-zero and not parallel, so uniqueness is the least
    of ``|a|/|p_i p_j|``, ``|b|/|p_i p_k|`` and ``|a^ x b^|`` (sines, 0..1).
    """
    r_j = q[..., _J, :] - q
    r_k = q[..., _K, :] - q
    a = cross(r_j, n[..., _J, :])
    b = cross(r_k, n[..., _K, :])
    a_len, b_len = norm(a), norm(b)
    w = cross(a / a_len[..., None], b / b_len[..., None])
    uniqueness = np.minimum(np.minimum(a_len / norm(r_j), b_len / norm(r_k)), norm(w))
    return line_through(q, w), uniqueness


def _normal_lines_volume(q, n):
    """How far the normal lines ``nu_i = (n_i; q_i x n_i)`` are from rank < 3.

    Gram-Schmidt on the three 6-vectors: the product of the orthogonalised
    lengths over the product of the original lengths, in ``[0, 1]``; accurate
    to round-off even near 0, unlike a Gram determinant.
    """
    nu = line_through(q, n)
    r1, r2, r3 = nu[..., 0, :], nu[..., 1, :], nu[..., 2, :]
    u1 = r1 / _len6(r1)[..., None]
    r2o = r2 - _dot6(r2, u1)[..., None] * u1
    u2 = r2o / _len6(r2o)[..., None]
    r3o = r3 - _dot6(r3, u1)[..., None] * u1 - _dot6(r3, u2)[..., None] * u2
    return _len6(r2o) * _len6(r3o) / (_len6(r2) * _len6(r3))


def _dot6(a, b):
    return dot(a[..., :3], b[..., :3]) + dot(a[..., 3:], b[..., 3:])


def _len6(a):
    return np.sqrt(_dot6(a, a))


def _frame(points, tol) -> _Frame:
    """Move a batch of grasps into its own frame and test the contacts.

    The frame has its origin at the centroid and unit length ``s`` = the
    largest coordinate offset of a contact from it (no squares, so 1e200
    coordinates do not overflow).  Contacts coincide when the shortest side
    of their triangle is ``<= tol`` times the longest; they are collinear
    when twice the triangle's area is ``<= tol`` times the longest side
    squared (a height ``<= tol`` times the size).
    """
    centroid = (points[..., 0, :] + points[..., 1, :] + points[..., 2, :]) / 3
    offset = points - centroid[..., None, :]
    with np.errstate(all="ignore"):
        scale = np.max(np.abs(offset), axis=(-2, -1))
        q = offset / scale[..., None, None]
        side = q[..., _K, :] - q[..., _J, :]  # side i is opposite contact i, from p_j to p_k
        side_len = norm(side)
        size = np.max(side_len, axis=-1)
        twice_area = norm(cross(q[..., 1, :] - q[..., 0, :], q[..., 2, :] - q[..., 0, :]))
        status = np.select(
            [
                ~np.isfinite(points).all(axis=(-2, -1)),
                ~(np.min(side_len, axis=-1) > tol * size),
                ~(twice_area > tol * size * size),
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
        sigma = line_through(q[..., _J, :], side)
    return _Frame(centroid, scale, q, size, sigma, status, culprit)


def _first_failure(frame: _Frame, *checks):
    """Status and culprit of each grasp: the frame's own, else the first
    failing ``(mask, status, culprit)`` check, in order."""
    masks = [frame.status != Status.OK] + [m for m, _, _ in checks]
    shape = np.broadcast_shapes(*(np.shape(m) for m in masks))
    status = np.select(masks, [frame.status] + [s for _, s, _ in checks], Status.OK)
    culprit = np.select(masks, [frame.culprit] + [c for _, _, c in checks], -1)
    return np.broadcast_to(status, shape).astype(np.int8), np.broadcast_to(culprit, shape).astype(np.int8)


def _row_status(grasp_status, culprit, twist, outputs):
    """Per-(grasp, twist) status: the grasp's, a non-finite twist, or an
    overflow that left a non-finite number in an otherwise good row."""
    twist_bad = ~np.isfinite(twist).all(axis=-1)
    shape = np.broadcast_shapes(grasp_status.shape, twist_bad.shape)
    status = np.where((grasp_status == Status.OK) & twist_bad, Status.NONFINITE_INPUT, grasp_status)
    finite = np.ones(shape, dtype=bool)
    for out in outputs:
        finite &= np.isfinite(out).all(axis=-1) if out.ndim > len(shape) else np.isfinite(out)
    status = np.where((status == Status.OK) & ~finite, Status.OVERFLOW, status)
    culprit = np.where(status == grasp_status, culprit, -1)
    return np.broadcast_to(status, shape).astype(np.int8), np.broadcast_to(culprit, shape).astype(np.int8)


def _into_frame(twist, f: _Frame):
    """``(omega; v)`` at the origin -> ``(omega; T(centroid) / s)`` in the frame."""
    omega = twist[..., :3]
    return screw(omega, (twist[..., 3:] + cross(omega, f.centroid)) / f.scale[..., None])


def _out_of_frame(s, f: _Frame):
    """Inverse of :func:`_into_frame` for ``(..., 3, 6)`` screws: ``v = s v' + g x omega``."""
    omega = s[..., :3]
    return screw(omega, f.scale[..., None, None] * s[..., 3:] + cross(f.centroid[..., None, :], omega))


def _combine(amplitude, basis):
    """``sum_i amplitude_i basis_i``: ``(..., 3), (..., 3, 6) -> (..., 6)``."""
    a = amplitude[..., None]
    return a[..., 0, :] * basis[..., 0, :] + a[..., 1, :] * basis[..., 1, :] + a[..., 2, :] * basis[..., 2, :]


def _residual(t, q, *parts):
    """``max_i |R(q_i)| / max_i |T(q_i)|``, ``R`` = sum of the parts minus ``T``."""
    r = sum(_combine(a, b) for a, b in parts) - t
    err = np.max(norm(field_at(r[..., None, :], q)), axis=-1)
    ref = np.max(norm(field_at(t[..., None, :], q)), axis=-1)
    return np.where(ref > 0, err / np.where(ref > 0, ref, 1.0), err)


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
    if a.shape[a.ndim - len(trailing) :] != trailing or a.ndim < len(trailing):
        want = "(..., " + ", ".join(map(str, trailing)) + ")"
        raise ValueError(f"{name} must have shape {want}, got {a.shape}")
    return a
