r"""Force closure: the least common friction that gives it, with a grasp's own friction, and epsilon.

A three-finger grasp with point contacts is *force closure* when ``rank G = 6`` and some
internal force (squeezes, :func:`~grasptwist.engine.forces.grasp_map.squeeze_forces`)
lies strictly inside every friction cone, so that every finger pushes.

**The planar reduction.**  Internal forces lie in the contacts' plane (three forces in
equilibrium with zero resultant are coplanar and concurrent).  With ``nu`` the plane's
unit normal and ``sin(phi_i) = |n_i . nu|``, cone ``i`` meets the plane in the sector of
half-angle ``beta_i`` about the projected normal ``m_i``, where

.. math:: \tan\beta_i = \mu_i' = \sqrt{\mu^2 \cos^2\phi_i - \sin^2\phi_i}, \qquad
          \cos\beta_i = \frac{\cos\theta}{\cos\phi_i} \quad (\mu = \tan\theta),

empty unless ``mu > tan(phi_i)``.  A force ``a`` is strictly inside the sector when
``a . (sin(beta) m -+ cos(beta) m_perp) > 0``: for a given ``mu`` force closure is six
strict homogeneous linear inequalities ``R s > 0`` in the three squeezes.  Their closed
cone is pointed, so it has an interior point exactly when the sum of its extreme rays
(among ``+-(r_a x r_b)`` for the 15 pairs of rows) satisfies all six strictly.  The least
common ``mu`` is found by bisection on ``theta = atan(mu)`` between ``max_i phi_i`` and
``pi/2`` (45 halvings, every row at once).

**Epsilon** (Ferrari-Canny): each cone an ``m``-sided pyramid of edges
``n_i + mu_i (cos(2 pi k/m) b1_i + sin(2 pi k/m) b2_i)`` (normal component 1; ``b1_i`` the
tangent towards the next contact, or towards the other one when the next lies on the
normal's line, so the pyramids turn with the grasp), each edge
the wrench ``(f; (p_i - g) x f / L)`` with ``g`` the contacts' centroid and ``L`` the
largest distance from ``g`` to a contact (so epsilon is a force, in units of the normal
force, unchanged by rigid motions and by scaling); the radius of the largest ball about
the origin inside the hull of those ``3 m`` wrenches and the origin (Qhull, through
``scipy.spatial.ConvexHull``, one grasp at a time).  The wrenches are divided by the
largest ``mu_i`` (when above 1) before the hull and the radius multiplied back, so a huge
friction gives a finite epsilon; an infinite one has no finite pyramid (epsilon NaN).
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import combinations

import numpy as np

from ..checks import check_normals, check_points
from ..degeneracy import DEGENERACY_TOL
from ..screws import cross, dot, norm
from .grasp_map import ForceStatus, check_friction, contact_matrices, geometry, tangent_bases, unit_normals

__all__ = [
    "Closure",
    "check_cone_edges",
    "force_closure",
    "closure_test",
    "epsilon_quality",
    "BISECTIONS",
    "MAX_FRICTION",
    "MAX_CONE_EDGES",
]

#: Halvings of ``atan(mu)``: ``pi/2 / 2**45 = 4.5e-14`` rad.
BISECTIONS = 45

#: A grasp that needs more common friction than this has none (``closure_friction`` NaN).
MAX_FRICTION = 1e7

#: The most edges a friction pyramid of epsilon may have: Qhull's time grows steeply with
#: them (one grasp: 0.2 s at 32 edges, 2 s at 64, 30 s at 128 on a 2-core machine).
MAX_CONE_EDGES = 64

#: A first pyramid edge towards a contact whose offset is within this (relative) of the
#: normal's line would point along round-off: the other contact's direction is taken.
_ON_LINE = 1e-6

_PAIRS = np.array(list(combinations(range(6), 2)))

#: Rows per chunk of the closure test.
CHUNK = 8192
_STRICT = 1e-12  # margins of unit rows and directions below this are not strict


@dataclass(frozen=True, eq=False)
class Closure:
    """Force closure of a batch of grasps.

    Attributes
    ----------
    closure_friction : (...)
        The least ``mu``, the same at every contact, above which the grasp is force
        closure; NaN where none exists (``status`` says why).
    force_closure : (...) bool, or None
        With the grasp's own ``friction`` (None when none was given).
    epsilon : (...), or None
        Ferrari-Canny's epsilon with the grasp's own friction (``quality=True``); 0
        outside force closure.
    status, culprit : (...) int8
        :class:`~grasptwist.forces.Status`; ``no-closure`` with
        the contact whose normal is at right angles to the contacts' plane, or -1.
    """

    closure_friction: np.ndarray
    force_closure: np.ndarray | None
    epsilon: np.ndarray | None
    status: np.ndarray
    culprit: np.ndarray


class _Plane:
    """The planar reduction of a batch of grasps (rows ``n``)."""

    def __init__(self, points, unit, geo):
        nu = geo.m / norm(geo.m)[:, None]
        x = points[:, 1] - points[:, 0]
        x = x / norm(x)[:, None]
        y = cross(nu, x)
        self.sin = np.abs(dot(unit, nu[:, None, :]))
        self.cos = np.sqrt(np.maximum(1 - self.sin**2, 0))
        self.phi = np.arcsin(np.minimum(self.sin, 1.0))  # each normal's angle to the plane
        proj = unit - dot(unit, nu[:, None, :])[..., None] * nu[:, None, :]
        m2 = np.stack((dot(proj, x[:, None, :]), dot(proj, y[:, None, :])), axis=-1)
        self.m = m2 / np.linalg.norm(m2, axis=-1, keepdims=True)  # (n, 3, 2)
        self.perp = np.stack((-self.m[..., 1], self.m[..., 0]), axis=-1)
        mats = contact_matrices(geo.e)  # (n, 3, 3 xyz, 3 squeezes)
        self.M = np.stack(
            (np.einsum("nixl,nx->nil", mats, x), np.einsum("nixl,nx->nil", mats, y)), axis=-2
        )  # (n, 3, 2, 3)

    def rows(self, cos_beta, sin_beta):
        """The six unit rows ``R (n, 6, 3)`` of the sectors with half-angles ``beta_i``."""
        plus = sin_beta[..., None] * self.m - cos_beta[..., None] * self.perp
        minus = sin_beta[..., None] * self.m + cos_beta[..., None] * self.perp
        v = np.stack((plus, minus), axis=-2)  # (n, 3, 2 edges, 2 xy)
        r = (self.M[:, :, None, 0, :] * v[..., 0, None] + self.M[:, :, None, 1, :] * v[..., 1, None]).reshape(-1, 6, 3)
        return r / np.linalg.norm(r, axis=-1, keepdims=True)


def closure_test(rows):
    """Whether ``R s > 0`` has a solution, and one (``(n, 6, 3)`` unit rows -> ``(n)`` bool, ``(n, 3)``).

    Candidates ``+-(r_a x r_b)``; those inside the closed cone are its extreme rays and
    their sum is an interior point if there is any.  Computed components-first in
    chunks of :data:`CHUNK` rows (the 6 x 15 products of a chunk stay in cache).

    >>> ok, s = closure_test(np.array([np.eye(3).tolist() * 2]))
    >>> bool(ok[0]), s[0].round(4).tolist()
    (True, [0.5774, 0.5774, 0.5774])
    """
    ok = np.empty(len(rows), bool)
    s = np.empty((len(rows), 3))
    for start in range(0, len(rows), CHUNK):
        part = slice(start, start + CHUNK)
        ok[part], s[part] = _closure_chunk(np.ascontiguousarray(np.moveaxis(rows[part], 0, -1)))
    return ok, s


def _closure_chunk(r):
    """:func:`closure_test` on components-first rows ``(6, 3, n)``."""
    a, b = r[_PAIRS[:, 0]], r[_PAIRS[:, 1]]  # (15, 3, n)
    c = np.stack(
        (
            a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1],
            a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2],
            a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0],
        )
    )  # (3, 15, n)
    length = np.sqrt(c[0] ** 2 + c[1] ** 2 + c[2] ** 2)
    with np.errstate(invalid="ignore", divide="ignore"):
        c /= length
    d = r[:, 0, None] * c[0] + r[:, 1, None] * c[1] + r[:, 2, None] * c[2]  # (6, 15, n)
    real = length > _STRICT
    sign = ((d >= -_STRICT).all(axis=0) & real).astype(float) - ((d <= _STRICT).all(axis=0) & real)
    s = (np.nan_to_num(c) * sign).sum(axis=1)  # (3, n): the sum of the extreme rays found
    s_len = np.sqrt(s[0] ** 2 + s[1] ** 2 + s[2] ** 2)
    with np.errstate(invalid="ignore", divide="ignore"):
        s /= s_len
        ok = (s_len > _STRICT) & ((r[:, 0] * s[0] + r[:, 1] * s[1] + r[:, 2] * s[2]) > _STRICT).all(axis=0)
    return ok, s.T


def _own_rows(plane, mu):
    """The sector rows with each contact's own ``mu_i``, and whether every cone reaches the plane.

    Through the angles ``theta_i = atan(mu_i)``, so a huge or infinite ``mu_i`` is a
    sector of half-angle up to a right angle (a half-plane), never ``inf / inf``.
    """
    theta = np.arctan(mu)
    return _sector_rows(plane, theta), (theta > plane.phi).all(axis=1) & ~np.isnan(mu).any(axis=1)


def internal_inside(points, unit, geo, mu):
    """A unit squeeze strictly inside every cone ``mu`` (``(n, 3)``), NaN where there is none.

    ``points (n, 3, 3)``, unit normals, their :func:`~grasptwist.engine.forces.grasp_map.geometry`
    (every row non-degenerate) and ``mu (n, 3)``.
    """
    with np.errstate(all="ignore"):
        plane = _Plane(points, unit, geo)
        rows, reach = _own_rows(plane, mu)
        ok, s = closure_test(rows)
    return np.where((ok & reach & (plane.cos > 0).all(axis=1))[:, None], s, np.nan)


def _sector_rows(plane, theta):
    """The six rows of the sectors of the cones of half-angle ``theta`` (``(n, 1)`` or ``(n, 3)``)."""
    # sin^2(beta) = (sin^2 theta - sin^2 phi) / cos^2 phi, as a product that keeps small angles exact
    sin_beta = np.sqrt(np.maximum(np.sin(theta - plane.phi) * np.sin(theta + plane.phi), 0)) / plane.cos
    return plane.rows(np.minimum(np.cos(theta) / plane.cos, 1.0), sin_beta)


def _at_theta(plane, theta):
    return closure_test(_sector_rows(plane, theta[:, None]))[0]


def _least_friction(plane):
    """Bisection on ``theta = atan(mu)``: ``(n)`` least common friction, NaN where none."""
    rows = len(plane.cos)
    lo = plane.phi.max(axis=1)
    hi = np.full(rows, np.arctan(MAX_FRICTION))
    some = _at_theta(plane, hi)
    at_lo = _at_theta(plane, lo + 1e-9)  # then the answer is max tan(phi_i), to 1e-9 rad
    todo = np.flatnonzero(some & ~at_lo)
    a, b = lo[todo], hi[todo]
    sub = _subset(plane, todo)
    for _ in range(BISECTIONS):
        mid = 0.5 * (a + b)
        ok = _at_theta(sub, mid)
        a, b = np.where(ok, a, mid), np.where(ok, mid, b)
    theta = np.where(at_lo, lo, np.nan)
    theta[todo] = b
    theta[~some] = np.nan
    return np.tan(theta)


def _subset(plane, rows):
    sub = object.__new__(_Plane)
    sub.__dict__.update({k: v[rows] for k, v in plane.__dict__.items()})
    return sub


def check_cone_edges(cone_edges) -> int:
    """The edges of each friction pyramid of epsilon: an integer from 3 to ``MAX_CONE_EDGES`` (64).

    >>> check_cone_edges(8)
    8
    >>> check_cone_edges(1000000000)
    Traceback (most recent call last):
    ValueError: cone_edges must be an integer from 3 to 64, got 1000000000
    """
    number = isinstance(cone_edges, (int, np.integer, float, np.floating)) and not isinstance(cone_edges, bool)
    # the range first: NaN and infinity fail it before int() sees them
    if not (number and 3 <= cone_edges <= MAX_CONE_EDGES and cone_edges == int(cone_edges)):
        raise ValueError(f"cone_edges must be an integer from 3 to {MAX_CONE_EDGES}, got {cone_edges!r}")
    return int(cone_edges)


def first_edges(points, normals):
    """The unit tangent ``b1_i`` of each pyramid's first edge: ``(3, 3), (3, 3) unit -> (3, 3)``.

    Towards the next contact (so that the pyramids turn with the grasp); when the next
    contact lies on the normal's line (an antipodal pair), towards the other one; when
    both do, any tangent.  Any tangent is a valid first edge: the choice only turns the
    pyramid about its normal.

    >>> p = np.array([[1.0, 0, 0], [-1, 0, 0], [0, 1, 0]])
    >>> (first_edges(p, -p) + 0.0).tolist()
    [[0.0, 1.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]]
    """
    p, n = np.asarray(points, float), np.asarray(normals, float)
    choices = []
    for other in ([1, 2, 0], [2, 0, 1]):
        d = p[other] - p
        t = d - np.einsum("ij,ij->i", d, n)[:, None] * n
        with np.errstate(invalid="ignore", divide="ignore"):
            choices.append((np.linalg.norm(t, axis=1) > _ON_LINE * np.linalg.norm(d, axis=1), t))
    (next_ok, towards_next), (other_ok, towards_other) = choices
    b1 = np.where(next_ok[:, None], towards_next, np.where(other_ok[:, None], towards_other, tangent_bases(n)[0]))
    return b1 / np.linalg.norm(b1, axis=1, keepdims=True)


def epsilon_quality(points, normals, friction, cone_edges=8):
    """Ferrari-Canny epsilon of one grasp (module docstring); 0 when the hull is flat or misses the origin.

    ``(3, 3), (3, 3), (3,)`` -> float; NaN when a friction is infinite (no finite
    pyramid).  Needs scipy (the ``quality`` extra).

    >>> p = np.array([[1, 0, 0], [-0.5, 0.75**0.5, 0], [-0.5, -(0.75**0.5), 0]])
    >>> round(epsilon_quality(p, -p, [0.5, 0.5, 0.5]), 4)
    0.2759
    """
    from scipy.spatial import ConvexHull, QhullError

    p = np.asarray(points, float)
    n = np.asarray(normals, float)
    n = n / np.linalg.norm(n, axis=-1, keepdims=True)
    mu = np.broadcast_to(np.asarray(friction, float), (3,))
    if not np.isfinite(mu).all():
        return float("nan")
    b1 = first_edges(p, n)
    b2 = np.cross(n, b1)
    angle = 2 * np.pi * np.arange(cone_edges) / cone_edges
    # edges divided by k (the radius is multiplied back): a huge mu stays within range
    k = max(1.0, float(mu.max()))
    f = n[:, None, :] / k + (mu / k)[:, None, None] * (
        np.cos(angle)[:, None] * b1[:, None, :] + np.sin(angle)[:, None] * b2[:, None, :]
    )
    q = p - p.mean(axis=0)
    length = np.linalg.norm(q, axis=1).max()
    wrenches = np.concatenate((f, np.cross(q[:, None, :], f) / length), axis=-1).reshape(-1, 6)
    try:
        hull = ConvexHull(np.vstack((np.zeros(6), wrenches)))
    except QhullError:  # the wrenches do not span six dimensions: no closure
        return 0.0
    return float(max(0.0, np.min(-hull.equations[:, -1]))) * k


def force_closure(points, normals, friction=None, *, quality=False, cone_edges=8, tol=DEGENERACY_TOL) -> Closure:
    r"""Force closure of each grasp: the least common friction, the verdict with ``friction``, epsilon.

    Parameters
    ----------
    points, normals : (..., 3, 3) arrays
    friction : None, scalar or (..., 3) array
        The grasp's own ``mu_i`` (for ``force_closure`` and ``epsilon``).
    quality : bool
        Also compute Ferrari-Canny's ``epsilon`` (needs ``friction`` and scipy;
        one Qhull call per grasp).
    cone_edges : int
        Edges of each friction pyramid for ``epsilon`` (3 to ``MAX_CONE_EDGES`` (64)).
    tol : float
        Degeneracy tolerance of the contacts.

    Returns
    -------
    Closure

    Examples
    --------
    The paper's Example 2 (a polyhedron touched on three perpendicular faces) is force
    closure above ``mu = 1/sqrt(2)``: the projected normals meet at the contacts'
    centroid, and each normal makes ``atan(1/sqrt(2))`` with the contacts' plane:

    >>> c = force_closure([[0, 2, 2], [2, 0, 2], [2, 2, 0]], np.eye(3), friction=0.8)
    >>> round(float(c.closure_friction), 12), bool(c.force_closure)
    (0.707106781187, True)
    """
    p, n = check_points(points), check_normals(normals)
    shape = np.broadcast_shapes(p.shape[:-2], n.shape[:-2])
    mu = None
    if friction is not None:
        mu = check_friction(friction)
        shape = np.broadcast_shapes(shape, mu.shape[:-1])
        mu = np.broadcast_to(mu if mu.ndim else mu[None], shape + (3,)).reshape(-1, 3)
    if quality and mu is None:
        raise ValueError("quality=True needs the grasp's friction (friction=MU) for the pyramids' edges")
    cone_edges = check_cone_edges(cone_edges)
    size = int(np.prod(shape))
    p = np.broadcast_to(p, shape + (3, 3)).reshape(size, 3, 3)
    n = np.broadcast_to(n, shape + (3, 3)).reshape(size, 3, 3)
    out = _closure_rows(p, n, mu, quality, cone_edges, tol)
    return Closure(**{k: None if v is None else v.reshape(shape) for k, v in out.items()})


def _closure_rows(p, n, mu, quality, edges, tol):
    geo = geometry(p, tol)
    status, culprit = geo.status.copy(), geo.culprit.copy()
    unit, zero, bad = unit_normals(n)
    hit = (status == 0) & zero.any(axis=1)
    status[hit], culprit[hit] = ForceStatus.ZERO_NORMAL, np.argmax(zero, axis=1)[hit]
    status[(status == 0) & bad] = ForceStatus.NONFINITE_INPUT
    friction = np.full(len(p), np.nan)
    closes = None if mu is None else np.zeros(len(p), bool)
    rows = np.flatnonzero(status == 0)
    if rows.size:
        with np.errstate(all="ignore"):
            plane = _Plane(p[rows], unit[rows], _subset_geo(geo, rows))
            perpendicular = plane.cos <= tol
            friction[rows] = np.where(perpendicular.any(axis=1), np.nan, _least_friction(plane))
            none = np.isnan(friction[rows])
            status[rows[none]] = ForceStatus.NO_CLOSURE
            culprit[rows[none]] = np.where(perpendicular.any(axis=1), np.argmax(perpendicular, axis=1), -1)[none]
            if mu is not None:
                own, reach = _own_rows(plane, mu[rows])
                closes[rows] = reach & closure_test(own)[0] & ~none
    epsilon = None
    if quality:
        epsilon = np.where(np.isfinite(p).all(axis=(1, 2)) & np.isfinite(n).all(axis=(1, 2)), 0.0, np.nan)
        for r in np.flatnonzero(closes):
            epsilon[r] = epsilon_quality(p[r], unit[r], mu[r], edges)
    return {
        "closure_friction": friction,
        "force_closure": closes,
        "epsilon": epsilon,
        "status": status,
        "culprit": culprit,
    }


def _subset_geo(geo, rows):
    return type(geo)(*(a[rows] for a in geo))
