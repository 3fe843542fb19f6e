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

Only differences of points enter the tests and amplitudes, and every
degeneracy measure is a ratio of like quantities, so verdicts do not depend
on the grasp's scale or position.  Coordinates must stay within about
1e-150..1e150 in size (squares of lengths are formed); a row whose numbers
overflow gets the status ``overflow``.

Speed: rows are processed in chunks of :data:`CHUNK` whose temporaries stay
in the CPU cache, in a components-first layout (``(contact, xyz, row)``) so
that every numpy call runs over contiguous memory.  Results are views of
that layout with the documented shapes.  All arithmetic is element-wise: a
row's numbers do not depend on the batch or chunk it is in.

The tangent method is degenerate exactly when some normal lies in the
contacts' plane (``m . n_i = 0``): a normal line set of rank < 3, a
``Theta_i`` that is not unique, and ``[Theta_i|Sigma_i] = 0`` each imply it.
So the engine gates on ``m . n_i`` and then names the specific condition.

A degenerate grasp never raises: its row gets a
:class:`~grasptwist.engine.degeneracy.Status` and NaN amplitudes, while every other
row is computed exactly as it would be alone.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from functools import cached_property
from math import prod
from typing import NamedTuple

import numpy as np

from .degeneracy import DEGENERACY_TOL, IN_PLANE_TOL, Status
from .screws import field_at, norm

__all__ = [
    "OffTangentResult",
    "TangentResult",
    "decompose_off_tangent",
    "decompose_tangent",
    "contact_velocities",
]

_J = [1, 2, 0]  # j = i + 1 (mod 3)
_K = [2, 0, 1]  # k = i + 2 (mod 3)

#: Rows per chunk: small enough for a chunk's temporaries to stay in cache,
#: large enough that numpy's per-call overhead is noise.
CHUNK = 8192


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
    inputs = {"points": _checked(points, (3, 3), "points"), "twist": _checked(twist, (6,), "twist")}
    return _chunked(_velocity_rows, inputs, {"velocity": (3, 3)}, None)["velocity"]


def _index(a, i):
    return None if a is None else a[i]


@dataclass(frozen=True, eq=False)
class _Result:
    """What both results share: per-row status, conditioning and inputs, row
    access and the lazily computed residual.

    Attributes
    ----------
    status, culprit : (...) int8
        :class:`~grasptwist.engine.degeneracy.Status` of each row and the contact it
        is about (0..2, or -1).
    conditioning : (...)
        The method's dimensionless conditioning figure (see each result).
    points, twist : (..., 3, 3), (..., 6)
        The inputs, broadcast to the batch shape.
    """

    status: np.ndarray
    culprit: np.ndarray
    conditioning: np.ndarray
    points: np.ndarray
    twist: np.ndarray

    @property
    def ok(self) -> np.ndarray:
        """``status == 0`` per row."""
        return self.status == Status.OK

    def row(self, i):
        """Row ``i`` (an index into the leading axis) as a result of the same type."""
        r = type(self)(**{f.name: _index(getattr(self, f.name), i) for f in fields(self)})
        if "residual" in self.__dict__:  # carry a residual already computed for the batch
            r.__dict__["residual"] = self.__dict__["residual"][i]
        return r

    @cached_property
    def residual(self) -> np.ndarray:
        """``max_i |R(p_i)| / max_i |T(p_i)|``, ``R`` = the sum of the components minus ``T``.

        Computed on first access from the returned screws and amplitudes;
        NaN in failed rows, 0 for the zero twist.
        """
        with np.errstate(all="ignore"):  # failed rows hold NaN, overflowed ones inf
            r = sum(a.sum(axis=-2) for a in self.components()) - self.twist
            err = np.max(norm(field_at(r[..., None, :], self.points)), axis=-1)
            ref = np.max(norm(field_at(self.twist[..., None, :], self.points)), axis=-1)
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
    conditioning : (...)
        ``min_i |[Sigma_i|Psi_i]| / size`` (dimensionless; size = longest
        side of the contact triangle).

    ``status``, ``culprit``, ``points``, ``twist`` and ``residual`` are as in
    every result (``_Result``).
    """

    sigma: np.ndarray
    psi: np.ndarray
    sigma_psi: np.ndarray
    x: np.ndarray
    y: np.ndarray

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
    conditioning : (...)
        The smaller of ``min_i |[Theta_i|Sigma_i]| / size`` and of
        ``min_i |sin|`` of the angle between normal ``i`` and the contacts'
        plane; both go to 0 at every degenerate grasp.

    ``status``, ``culprit``, ``points``, ``twist`` and ``residual`` are as in
    every result (``_Result``).
    """

    theta: np.ndarray
    sigma: np.ndarray
    theta_sigma: np.ndarray
    alpha: np.ndarray
    beta: np.ndarray
    normal_velocity: np.ndarray
    in_tangent_planes: np.ndarray

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


def decompose_off_tangent(points, wrist, twist, *, tol=DEGENERACY_TOL, bases=True) -> OffTangentResult:
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
        Relative tolerance of the degeneracy tests (see :mod:`grasptwist.engine.degeneracy`).
    bases : bool
        False leaves out the basis screws (``sigma``, ``psi`` are None, and
        so cannot give components or a residual): a third less work and
        memory when only amplitudes and statuses are wanted.

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
    inputs = {
        "points": _checked(points, (3, 3), "points"),
        "wrist": _checked(wrist, (3,), "wrist"),
        "twist": _checked(twist, (6,), "twist"),
    }
    out = _chunked(_off_tangent_rows, inputs, _without_bases(_OFF_TANGENT_OUT, bases), tol)
    return OffTangentResult(**{**dict.fromkeys(_BASES & _OFF_TANGENT_OUT.keys()), **out})


def decompose_tangent(points, normals, twist, *, tol=DEGENERACY_TOL, bases=True) -> TangentResult:
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
    bases : bool
        False leaves out the basis screws (``theta``, ``sigma`` are None),
        as for :func:`decompose_off_tangent`.

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
    inputs = {
        "points": _checked(points, (3, 3), "points"),
        "normals": _checked(normals, (3, 3), "normals"),
        "twist": _checked(twist, (6,), "twist"),
    }
    out = _chunked(_tangent_rows, inputs, _without_bases(_TANGENT_OUT, bases), tol)
    return TangentResult(**{**dict.fromkeys(_BASES & _TANGENT_OUT.keys()), **out})


# --- the row kernels ----------------------------------------------------------
# Arrays here are components-first: a point set is (contact, xyz, row), a
# vector (xyz, row), a per-contact number (contact, row).

_OFF_TANGENT_OUT = {
    "sigma": (3, 6),
    "psi": (3, 6),
    "sigma_psi": (3,),
    "x": (3,),
    "y": (3,),
    "status": (),
    "culprit": (),
    "conditioning": (),
}
_TANGENT_OUT = {
    "theta": (3, 6),
    "sigma": (3, 6),
    "theta_sigma": (3,),
    "alpha": (3,),
    "beta": (3,),
    "normal_velocity": (3,),
    "in_tangent_planes": (),
    "status": (),
    "culprit": (),
    "conditioning": (),
}
_DTYPES = {"status": np.int8, "culprit": np.int8, "in_tangent_planes": bool}
_BASES = {"sigma", "psi", "theta"}


def _without_bases(spec, bases):
    return spec if bases else {k: v for k, v in spec.items() if k not in _BASES}


_TRAILING = {"points": (3, 3), "normals": (3, 3), "wrist": (3,), "twist": (6,)}


class _Triangle(NamedTuple):
    """The contacts' triangle for a chunk of rows."""

    side: np.ndarray  # (3, 3, n) U_i = p_k - p_j
    side_len: np.ndarray  # (3, n)
    unit_side: np.ndarray  # (3, 3, n) direction of Sigma_i
    size: np.ndarray  # (n,) longest side
    m: np.ndarray  # (3, n) (p_2 - p_1) x (p_3 - p_1)
    m_len: np.ndarray  # (n,)
    checks: list  # the failure checks of the triangle, in order


def _triangle(p) -> _Triangle:
    """Sides, area vector and the degeneracy checks of the contact triangle.

    Contacts coincide when the shortest side is ``<= tol`` times the longest;
    they are collinear when twice the area is ``<= tol`` times the longest
    side squared (a height ``<= tol`` times the size).
    """
    side = p[_K] - p[_J]
    side_len = np.sqrt(_dot(side, side))
    size = _max3(side_len)
    unit_side = side / side_len[:, None]
    # m from unit sides: no fourth powers of lengths, so no under- or overflow
    m = _cross(unit_side[1], unit_side[2])
    area_scale = side_len[1] * side_len[2]
    m_len = np.sqrt(_dot(m, m)) * area_scale
    m *= area_scale
    finite = np.isfinite(p).all(axis=(0, 1))
    checks = [
        (lambda tol: ~finite, Status.NONFINITE_INPUT, None),
        (lambda tol: ~np.isfinite(size * size), Status.OVERFLOW, None),
        # the pair that coincides is opposite the shortest side
        (
            lambda tol: ~(_min3(side_len) > tol * size),
            Status.COINCIDENT_CONTACTS,
            lambda rows: np.argmin(side_len[:, rows], 0),
        ),
        # the contact between the other two is opposite the longest side
        (
            lambda tol: ~(m_len > tol * size * size),
            Status.COLLINEAR_CONTACTS,
            lambda rows: np.argmax(side_len[:, rows], 0),
        ),
    ]
    return _Triangle(side, side_len, unit_side, size, m, m_len, checks)


def _velocity_rows(ins, out, tol):
    out["velocity"][...] = _velocity(ins["twist"], ins["points"])


def _off_tangent_rows(ins, out, tol):
    """Proposition 1 on one chunk (see the module docstring for the formulas)."""
    p, c, t = ins["points"], ins["wrist"], ins["twist"]
    tri = _triangle(p)
    e = p - c  # E_i, (3, 3, n)
    e_len = np.sqrt(_dot(e, e))
    d = _dot(tri.m, e[0])  # D, the same for every i
    le = tri.side_len * e_len
    conditioning = np.abs(d) / (_max3(le) * tri.size)
    v = _velocity(t, p)
    x = tri.side_len * _dot(e, v) / d
    y = e_len * _dot(tri.side, v[_J]) / d
    e /= e_len[:, None]
    if "sigma" in out:
        _put_lines(out["sigma"], p[_J], tri.unit_side)
        _put_lines(out["psi"], p, e)
    out["sigma_psi"][...] = d / le
    out["conditioning"][...] = conditioning
    checks = tri.checks + [
        (lambda tol: ~np.isfinite(c).all(axis=0), Status.NONFINITE_INPUT, None),
        (lambda tol: ~(conditioning > tol), Status.WRIST_COPLANAR, None),
    ]
    _settle(out, checks, t, tol, x=x, y=y)


def _tangent_rows(ins, out, tol):
    """Proposition 2 and the off-plane rest on one chunk (formulas in the module docstring)."""
    p, t = ins["points"], ins["twist"]
    tri = _triangle(p)
    n_len = np.sqrt(_dot(ins["normals"], ins["normals"]))
    n = ins["normals"] / n_len[:, None]
    # eqs. 21-22 with p_i p_j along U_k and p_i p_k along -U_j; unit sides keep
    # |w| free of the grasp's size (no underflow) and |a|, |b| sines
    a = _cross(tri.unit_side[_K], n[_J])
    b = _cross(n[_K], tri.unit_side[_J])
    w = _cross(a, b)
    w_len = np.sqrt(_dot(w, w))
    w /= w_len[:, None]
    wm = _dot(w, tri.m)
    mn = _dot(tri.m, n)
    plane_sine = np.abs(mn) / tri.m_len
    theta_sigma = np.abs(wm) / (tri.side_len * tri.size)
    conditioning = np.minimum(_min3(theta_sigma), _min3(plane_sine))
    v = _velocity(t, p)
    nv = _dot(v, n)
    alpha = _dot(tri.side, v[_J]) / wm
    beta = tri.side_len * nv / mn
    if "theta" in out:
        _put_lines(out["theta"], p, w)
        _put_lines(out["sigma"], p[_J], tri.unit_side)
    out["theta_sigma"][...] = wm / tri.side_len
    out["normal_velocity"][...] = nv
    out["conditioning"][...] = conditioning
    # Round-off in v + omega x p scales with |v| + |omega||p|, not with the result.
    reach = np.sqrt(_dot(t[3:], t[3:])) + np.sqrt(_dot(t[:3], t[:3])) * np.sqrt(_dot(p, p))
    out["in_tangent_planes"][...] = _max3(np.abs(nv)) <= IN_PLANE_TOL * _max3(reach)

    def uniqueness(rows):
        """Sines that vanish when eq. 22's two constraints do not fix one axis."""
        a_len, b_len = np.sqrt(_dot(a[..., rows], a[..., rows])), np.sqrt(_dot(b[..., rows], b[..., rows]))
        return np.minimum(np.minimum(a_len, b_len), w_len[:, rows] / (a_len * b_len))

    degenerate = ~(conditioning > tol)
    checks = tri.checks + [
        (lambda tol: ~np.isfinite(ins["normals"]).all(axis=(0, 1)), Status.NONFINITE_INPUT, None),
        (lambda tol: ~(n_len > 0).all(axis=0), Status.ZERO_NORMAL, lambda rows: np.argmin(n_len[:, rows], 0)),
        (
            _subset(degenerate, lambda rows: _rank_deficient(p[..., rows], n[..., rows], tri.size[rows], tol)),
            Status.NORMALS_RANK_DEFICIENT,
            None,
        ),
        (
            _subset(degenerate, lambda rows: ~(uniqueness(rows) > tol).all(axis=0)),
            Status.THETA_NOT_UNIQUE,
            lambda rows: np.argmin(uniqueness(rows), 0),
        ),
        (
            _subset(degenerate, lambda rows: ~(theta_sigma[:, rows] > tol).all(axis=0)),
            Status.THETA_SIGMA_ZERO,
            lambda rows: np.argmin(theta_sigma[:, rows], 0),
        ),
        (lambda tol: degenerate, Status.NORMAL_IN_CONTACT_PLANE, lambda rows: np.argmin(plane_sine[:, rows], 0)),
    ]
    _settle(out, checks, t, tol, alpha=alpha, beta=beta, normal_velocity=nv)
    out["in_tangent_planes"][out["status"] != Status.OK] = False  # unknown where the method failed


def _subset(candidates, test):
    """A check that runs ``test`` only on the candidate rows (it costs more than the rest)."""

    def mask(tol):
        hit = np.zeros(candidates.shape, dtype=bool)
        rows = np.flatnonzero(candidates)
        if rows.size:
            hit[rows] = test(rows)
        return hit

    return mask


def _rank_deficient(p, n, size, tol):
    """Whether the normal lines ``nu_i = (n_i; p_i x n_i)`` have rank < 3.

    Gram-Schmidt on the three 6-vectors, taken about ``p_1`` in units of the
    size: the product of the orthogonalised lengths over the original ones is
    in ``[0, 1]`` and accurate to round-off even near 0.
    """
    nu = np.concatenate((n, _cross((p - p[0]) / size, n)), axis=1)  # (contact, 6, rows)
    r1, r2, r3 = nu
    u1 = r1 / np.sqrt((r1 * r1).sum(0))
    r2o = r2 - (r2 * u1).sum(0) * u1
    u2 = r2o / np.sqrt((r2o * r2o).sum(0))
    r3o = r3 - (r3 * u1).sum(0) * u1 - (r3 * u2).sum(0) * u2
    volume = np.sqrt((r2o * r2o).sum(0) * (r3o * r3o).sum(0) / ((r2 * r2).sum(0) * (r3 * r3).sum(0)))
    return ~(volume > tol)


def _settle(out, checks, twist, tol, **amplitudes):
    """Status and culprit per row from the checks in order (first failure wins),
    then a non-finite twist, then overflow; amplitudes of failed rows become NaN."""
    n = twist.shape[-1]
    status = out["status"]
    culprit = out["culprit"]
    status[...] = Status.OK
    culprit[...] = -1
    checks = checks + [(lambda tol: ~np.isfinite(twist).all(axis=0), Status.NONFINITE_INPUT, None)]
    for mask, code, blame in checks:
        rows = np.flatnonzero(mask(tol) & (status == Status.OK))
        if rows.size:
            status[rows] = code
            if blame is not None:
                culprit[rows] = blame(rows)
    finite = np.ones(n, dtype=bool)
    for a in amplitudes.values():
        finite &= np.isfinite(a).all(axis=0)
    status[(status == Status.OK) & ~finite] = Status.OVERFLOW
    failed = status != Status.OK
    for name, a in amplitudes.items():
        a[:, failed] = np.nan
        out[name][...] = a


def _chunked(rows_kernel, inputs, spec, tol):
    """Run ``rows_kernel`` over the broadcast batch in cache-sized chunks.

    Inputs are flattened to ``(N, ...)``; each chunk is handed to the kernel
    components-first and the kernel writes into components-first outputs,
    which come back as ``(batch..., ...)`` views.  The broadcast inputs
    ``points`` and ``twist`` are returned too.
    """
    shape = np.broadcast_shapes(*(a.shape[: a.ndim - len(_TRAILING[k])] for k, a in inputs.items()))
    n = prod(shape)
    full = {k: np.broadcast_to(a, shape + _TRAILING[k]) for k, a in inputs.items()}
    flat = {k: a.reshape((n,) + _TRAILING[k]) for k, a in full.items()}
    out = {k: np.empty(comp + (n,), dtype=_DTYPES.get(k, float)) for k, comp in spec.items()}
    with np.errstate(all="ignore"):
        for start in range(0, n, CHUNK):
            part = slice(start, min(start + CHUNK, n))
            rows_kernel(
                {k: np.ascontiguousarray(np.moveaxis(a[part], 0, -1)) for k, a in flat.items()},
                {k: o[..., part] for k, o in out.items()},
                tol,
            )
    result = {k: np.moveaxis(o, -1, 0).reshape(shape + spec[k]) for k, o in out.items()}
    result.update(points=full["points"], twist=full["twist"])
    return result


# --- components-first vector algebra ------------------------------------------


def _dot(a, b):
    """Dot product over axis -2 of ``(..., 3, n)`` arrays."""
    return a[..., 0, :] * b[..., 0, :] + a[..., 1, :] * b[..., 1, :] + a[..., 2, :] * b[..., 2, :]


def _cross(a, b, out=None):
    """Cross product over axis -2 of ``(..., 3, n)`` arrays (into ``out`` if given)."""
    if out is None:
        out = np.empty(np.broadcast_shapes(a.shape, b.shape))
    a0, a1, a2 = a[..., 0, :], a[..., 1, :], a[..., 2, :]
    b0, b1, b2 = b[..., 0, :], b[..., 1, :], b[..., 2, :]
    np.multiply(a1, b2, out=out[..., 0, :])
    out[..., 0, :] -= a2 * b1
    np.multiply(a2, b0, out=out[..., 1, :])
    out[..., 1, :] -= a0 * b2
    np.multiply(a0, b1, out=out[..., 2, :])
    out[..., 2, :] -= a1 * b0
    return out


def _velocity(t, p):
    """``T(p_i) = v + omega x p_i`` for ``t (6, n)``, ``p (3, 3, n)``."""
    v = _cross(t[:3], p)
    v += t[3:]
    return v


def _put_lines(out, p, d):
    """Write unit lines ``(d; p x d)`` into ``out (3, 6, n)``."""
    out[:, :3] = d
    _cross(p, d, out=out[:, 3:])


def _max3(a):
    return np.maximum(np.maximum(a[0], a[1]), a[2])


def _min3(a):
    return np.minimum(np.minimum(a[0], a[1]), a[2])


def _checked(a, trailing, name):
    """``a`` as a float array whose shape ends in ``trailing`` (checked once, here)."""
    a = np.asarray(a, dtype=float)
    if a.ndim < len(trailing) or a.shape[a.ndim - len(trailing) :] != trailing:
        want = "(..., " + ", ".join(map(str, trailing)) + ")"
        raise ValueError(f"{name} must have shape {want}, got {a.shape}")
    return a
