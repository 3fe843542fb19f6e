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

**Soft-finger contacts** (``torsion=``: ``e_i > 0``, the cone ``|(f_t, tau_i / e_i)| <= mu f_n`` of
:mod:`~grasptwist.engine.forces.cones`) have no planar reduction: the internal forces need not be
coplanar (torsions balance moments).  A grasp is force closure when the grasp map of its contacts'
generalised forces is onto ``R^6`` (``rank B = 6 + `` the coordinates the models hold at zero,
``B = [G'; E]`` of :func:`~grasptwist.engine.forces.cones.cone_grasp`) and some internal force
``g = N x`` lies strictly inside every cone.  The second is phase I of the conic programme
(:func:`~grasptwist.engine.forces.socp.phase_one`) on the internal forces normalised to
``sum_i f_{n,i} = 3``, with each cone's rows ``(sin theta_i n_i, cos theta_i b1_i, cos theta_i b2_i,
cos theta_i / e_i)`` (``theta_i = atan(mu_i)``: rows of order one for any friction, ``inf`` included):
a margin ``r < 0`` is closure.  The least common friction is Dinkelbach's method on
``min_x max_i |(f_t, tau / e)_i| / f_{n,i}`` (:func:`_least_soft_friction`): each step a phase I, 3 to 12
of them where a bisection takes 45; 1000 random grasps in 1.6-2.0 s against Clarabel's bisection's 52-74 s,
within ``3.1e-7`` of it and never above it by more than ``1.2e-11`` (each value is the ratio of an internal
force found, an upper bound on the infimum).  Where the infimum is
0 (two pads pinching a rod, a third pushing from below: any friction closes), it stops below ``1e-6``.

Where a grasp is not force closure with its own friction (``certificate=True``), phase I's
multipliers ``z_i`` (``sum_i A_i^T z_i = alpha c``, ``alpha < 0``) give the wrench
``y = -D^T (B^+)^T (sum_i F_i^T z_i - alpha c_g)`` with ``y . G_i g_i <= 0`` for every admissible ``g_i``
(``c_g = (n_i, 0)``); where ``G`` is not onto, the left singular vector ``y`` of the exerted part of
``G`` with ``y . G g = 0``.  Either way no admissible forces have a positive component along ``y``.

Soft epsilon linearises each ``Q^4`` cone by the inscribed bipyramid: the ``m`` friction edges above
(``tau = 0``) and two torsion edges ``f = n_i``, ``tau_i = +-mu_i e_i`` (the wrenches
``(n_i; (q_i x n_i +- mu_i e_i n_i) / L)``), so a soft contact's wrenches hold its point contact's and
``e = 0`` is the point contact's hull.  A torsion edge's moment over ``L`` is at most ``1e10`` (the force
edges' are of order one): Qhull loses a hull some ``1e13`` across, and edges longer than ``T`` add some
``1.4 / T`` of epsilon (a tripod on a 3 cm ball: 0.1131513071118 from ``e = 1e9`` on, 0.1131513071282 at
``e = 1e11`` uncapped, 0 at ``1e12`` uncapped).  Rows without a soft contact take the point contacts' way
above, bit for bit.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import partial

import numpy as np

from ...extras import require
from ..checks import check_normals, check_points
from ..degeneracy import DEGENERACY_TOL
from ..screws import cross
from . import cones, set_up, socp
from .grasp_map import (
    ForceStatus,
    check_friction,
    check_torsion,
    contact_matrices,
    geometry,
    tangent_bases,
    unit_normals,
)

__all__ = [
    "Closure",
    "check_cone_edges",
    "force_closure",
    "closure_test",
    "epsilon_quality",
    "soft_closure_verdict",
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

#: Rows per chunk of the closure test.
CHUNK = 8192


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
    certificate : (..., 6), or None
        With ``certificate=True``: where the grasp is not force closure with its own friction, a
        wrench ``y`` that no forces within the cones have a positive component along
        (``y . G_i g_i <= 0`` for every admissible ``g_i`` of every contact: ``-G_i^T y`` in each dual
        cone), so the grasp cannot exert ``y`` (nor resist the load ``-y``); scaled to
        ``|(y_F, L y_M)| = 1`` as ``Grip.certificate``.  NaN where it
        is force closure, where the status is a degeneracy, and where the friction is NaN.
    """

    closure_friction: np.ndarray
    force_closure: np.ndarray | None
    epsilon: np.ndarray | None
    status: np.ndarray
    culprit: np.ndarray
    certificate: np.ndarray | None = None


class _Plane:
    """The planar reduction of a batch of grasps (rows ``n``): :func:`set_up.plane_reduction`'s twin, rows first."""

    def __init__(self, points, unit, geo):
        rows = len(points)
        tilt, self.dirs, self.forces = np.empty((rows, 2, 3)), np.empty((rows, 3, 2)), np.empty((rows, 3, 3, 2))
        axes = np.empty((rows, 3, 3))
        set_up.on_rows(
            "plane_reduction", points, unit, geo.m, contact_matrices(geo.e), axes, tilt, self.dirs, self.forces, rows
        )
        self.sin, self.cos = tilt[:, 0], tilt[:, 1]
        self.phi = np.arcsin(np.minimum(self.sin, 1.0))  # each normal's angle to the plane

    def rows(self, cos_beta, sin_beta):
        """The six unit rows ``R (n, 6, 3)`` of the sectors with half-angles ``beta_i`` (``(n, 3)``)."""
        out = np.empty((len(self.dirs), 3, 2, 3))
        sines = (np.broadcast_to(sin_beta, self.cos.shape), np.broadcast_to(cos_beta, self.cos.shape))
        set_up.on_rows("sector_rows", self.dirs, self.forces, *sines, out, len(out))
        return out.reshape(-1, 6, 3)


def closure_test(rows):
    """Whether ``R s > 0`` has a solution, and one (``(n, 6, 3)`` unit rows -> ``(n)`` bool, ``(n, 3)``):
    :func:`set_up.closure_test`'s twin, in chunks of :data:`CHUNK` rows (whose temporaries stay in cache).

    >>> ok, s = closure_test(np.array([np.eye(3).tolist() * 2]))
    >>> bool(ok[0]), s[0].round(4).tolist()
    (True, [0.5774, 0.5774, 0.5774])
    """
    ok = np.empty(len(rows), bool)
    s = np.empty((len(rows), 3))
    test = set_up.twins()["closure_test"]
    for start in range(0, len(rows), CHUNK):
        part = slice(start, start + CHUNK)
        r = np.ascontiguousarray(set_up.lanes(rows[part]))  # lanes in memory: the pairs' rows read whole
        with np.errstate(all="ignore"):
            test(r, np.empty((3, 15, r.shape[-1])), set_up.lanes(s[part]), ok[part], r.shape[-1])
    return ok, s


def _own_rows(plane, limit):
    """The sector rows with each contact's own ``limit_i``, and whether every cone reaches the plane
    (:func:`set_up.own_sectors`' twin: a huge or infinite limit is a half-plane, never ``inf / inf``)."""
    rows = len(plane.cos)
    sin_beta, cos_beta, reach = np.empty((rows, 3)), np.empty((rows, 3)), np.empty(rows, bool)
    set_up.on_rows("own_sectors", np.stack((plane.sin, plane.cos), axis=1), limit, sin_beta, cos_beta, reach, rows)
    return plane.rows(cos_beta, sin_beta), reach


def internal_inside(points, unit, geo, mu):
    """A unit squeeze strictly inside every cone ``mu`` (``(n, 3)``), NaN where there is none:
    :func:`set_up.internal_inside`'s twin.

    ``points (n, 3, 3)``, unit normals, their :func:`~grasptwist.engine.forces.grasp_map.geometry`
    (every row non-degenerate) and ``mu (n, 3)``.
    """
    rows = len(points)
    out = np.empty((rows, 3))
    lanes = (points, unit, geo.m, contact_matrices(geo.e), np.asarray(mu, dtype=float), out)
    set_up.on_rows("internal_inside", *lanes, set_up.inside_workspace(rows), rows)
    return out


def _sector_rows(plane, theta):
    """The six rows of the sectors of the cones of half-angle ``theta`` (``(n, 1)`` or ``(n, 3)``): the bisection's,
    which runs on the angle itself (:func:`set_up.own_sectors` gives these sines from a friction limit, without it)."""
    # sin^2(beta) = (sin^2 theta - sin^2 phi) / cos^2 phi, as a product that keeps small angles exact
    sin_beta = np.sqrt(np.maximum(np.sin(theta - plane.phi) * np.sin(theta + plane.phi), 0)) / plane.cos
    return plane.rows(np.minimum(np.cos(theta) / plane.cos, 1.0), sin_beta)


def _at_theta(plane, theta):
    return closure_test(_sector_rows(plane, theta[:, None]))[0]


def _least_friction(plane):
    """Bisection on ``theta = atan(mu)``: ``(n)`` least common friction, NaN where none."""
    rows = len(plane.cos)
    lo = plane.phi.max(axis=1)
    ends = _at_thetas(plane, np.stack((np.full(rows, _TOP), lo + 1e-9), axis=1))
    some, at_lo = ends[:, 0], ends[:, 1]  # at lo the answer is max tan(phi_i), to 1e-9 rad
    todo = np.flatnonzero(some & ~at_lo)
    a, b = lo[todo], np.full(todo.size, _TOP)
    depth = _AT_ONCE if todo.size <= _FEW else 1
    sub = _subset(plane, todo)
    for done in range(0, BISECTIONS, depth):
        a, b = _halvings(sub, a, b, min(depth, BISECTIONS - done))
    theta = np.where(at_lo, lo, np.nan)
    theta[todo] = b
    theta[~some] = np.nan
    return np.tan(theta)


#: The bisection's upper end: ``atan(MAX_FRICTION)``.
_TOP = float(np.arctan(MAX_FRICTION))

#: Halvings a round of the bisection takes at once for at most :data:`_FEW` rows: the 15 angles 4 halvings
#: could test, in one closure test of 15 lanes a row (a small batch's test costs its call, some 200 numpy
#: calls, not its rows): 12 tests of one grasp instead of 45.
_AT_ONCE, _FEW = 4, 128


def _halvings(plane, a, b, depth):
    """``depth`` halvings of each row's ``[a, b]`` at once, the same brackets as one at a time: the ``2^depth - 1``
    midpoints those halvings could test (:func:`_at_thetas`), then the path the halvings take through them."""
    mids = _midpoints(a, b, depth)
    ok = _at_thetas(plane, mids)
    at, size = np.zeros(len(a), int), mids.shape[1]
    for _ in range(depth):
        node = at + size // 2
        mid, held = mids[np.arange(len(a)), node], ok[np.arange(len(a)), node]
        a, b = np.where(held, a, mid), np.where(held, mid, b)
        at, size = np.where(held, at, node + 1), size // 2
    return a, b


def _at_thetas(plane, thetas):
    """Whether each row is force closure at each of its angles ``thetas (n, k)``: ``(n, k)``.  For up to :data:`_FEW`
    rows in one closure test of each row's plane ``k`` times (a small test costs its call), else a test an angle
    (the planes never copied: memory as one test's)."""
    n, k = thetas.shape
    if k == 1 or n > _FEW:
        return np.stack([_at_theta(plane, thetas[:, j]) for j in range(k)], axis=1)
    return _at_theta(_subset(plane, np.repeat(np.arange(n), k)), thetas.reshape(-1)).reshape(n, k)


def _midpoints(a, b, depth):
    """The midpoints ``0.5 (a + b)`` that ``depth`` halvings of ``[a, b]`` may test, in order: ``(n, 2^depth - 1)``,
    each of its interval's ends (those of the halvings, bit for bit).

    >>> _midpoints(np.array([0.0]), np.array([8.0]), 2).tolist()
    [[2.0, 4.0, 6.0]]
    """
    ends = np.stack((a, b), axis=1)
    for _ in range(depth):
        finer = np.empty((len(a), 2 * ends.shape[1] - 1))
        finer[:, ::2], finer[:, 1::2] = ends, 0.5 * (ends[:, :-1] + ends[:, 1:])
        ends = finer
    return ends[:, 1:-1]


def _subset(plane, rows):
    sub = object.__new__(_Plane)
    sub.__dict__.update({k: v[rows] for k, v in plane.__dict__.items()})
    return sub


#: The coordinates each contact model holds at zero (indexed by ``cones.FRICTIONLESS, POINT, SOFT``):
#: frictionless the tangential force and the torsion, point the torsion, soft none.
_IDLE = np.array([3, 1, 0])

#: The total normal force of the internal forces soft closure is judged on: a grasp well inside the
#: cones reaches phase I's ``START_MARGIN`` (a margin is at most the total's share of one contact).
_TOTAL = 3.0


class _Cones:
    r"""The internal generalised forces of rows of grasps over their contacts' cones (soft closure).

    ``g = N x`` (``N`` the null space of ``B = [G'; E]``,
    :func:`~grasptwist.engine.forces.cones.cone_grasp`), normalised to a total normal force
    ``c . x = 3`` (``c_j = sum_i n_i . f_i`` of column ``j``) by ``x = x_0 + Z t``; at half-angles
    ``theta_i`` cone ``i``'s rows are ``(sin theta_i n_i, cos theta_i b1_i, cos theta_i b2_i,
    cos theta_i e_tau)`` (the cone ``|(f_t, tau / e)| <= tan(theta_i) f_n`` scaled to rows of order one
    for every ``theta`` in ``[0, pi/2]``; a frictionless contact's is the ray ``(n_i, 0, 0, 0)``).
    """

    def __init__(self, setup, rows, unit, model):
        self.setup, self.rows, self.model = cones.ConeGrasp(*(a[rows] for a in setup)), rows, model[rows]
        # every row's null space in the last d columns, a row with fewer internal forces padded with zero
        # columns (directions that move no cone: the interior-point method's ridge holds them still)
        own = 12 - self.setup.rank
        d = int(own.max(initial=0))
        null = self.setup.null[:, :, 12 - d :] * (np.arange(d) >= d - own[:, None])[:, None, :]
        null = null.reshape(-1, 3, 4, d)
        b1, b2 = tangent_bases(unit[rows])
        soft = (self.model == cones.SOFT)[..., None]
        # (n, 3 contacts, 4 rows, d): the normal force, the tangential forces, the torsion over e
        self.R = np.stack(
            (
                np.einsum("nix,nixd->nid", unit[rows], null[:, :, :3]),
                np.einsum("nix,nixd->nid", b1, null[:, :, :3]),
                np.einsum("nix,nixd->nid", b2, null[:, :, :3]),
                np.where(soft, null[:, :, 3], 0.0),
            ),
            axis=2,
        )
        self.null, self.basis = null, (unit[rows], b1, b2)
        c = self.R[:, :, 0].sum(axis=1)  # (n, d)
        length = np.sqrt((c**2).sum(axis=1))
        self.pushes = length > 1e-9  # some internal force has a positive total normal force
        c = c / np.where(self.pushes, length, 1.0)[:, None]
        self.x0 = _TOTAL * c / np.where(self.pushes, length, 1.0)[:, None]
        self.c = c * length[:, None]
        self.Z = np.swapaxes(np.linalg.svd(c[:, None, :])[2][:, 1:], 1, 2)  # (n, d, d - 1): c's complement

    def part(self, rows):
        new = object.__new__(_Cones)
        new.__dict__.update(
            {k: v[rows] if isinstance(v, np.ndarray) else v for k, v in self.__dict__.items() if k != "setup"}
        )
        new.setup = cones.ConeGrasp(*(a[rows] for a in self.setup))
        new.basis = tuple(a[rows] for a in self.basis)
        return new

    def scales(self, theta):
        """Each cone's rows' factors ``(n, 3, 4)`` at half-angles ``theta`` (``(n)`` or ``(n, 3)``)."""
        theta = np.broadcast_to(theta if np.ndim(theta) == 2 else np.asarray(theta)[:, None], self.model.shape)
        rubs = self.model != cones.FRICTIONLESS
        sin, cos = np.where(rubs, np.sin(theta), 1.0), np.where(rubs, np.cos(theta), 0.0)
        return np.stack((sin, cos, cos, cos), axis=-1)

    def phase_one(self, theta, weight=1.0):
        """Phase I at ``theta``, cone ``i``'s rows times ``weight (n, 3)``: ``r (n)`` (``< 0``: an internal force
        strictly inside every cone), ``z (n, 3, 4)`` and the internal force ``x (n, d)`` reached."""
        k = self.scales(theta) * np.asarray(weight)[..., None]
        A = k[..., None] * np.einsum("nikd,nde->nike", self.R, self.Z)
        b = k * np.einsum("nikd,nd->nik", self.R, self.x0)
        t, r, z = socp.phase_one(A, b)
        return np.where(self.pushes, r, np.inf), z, self.x0 + np.einsum("nde,ne->nd", self.Z, t)

    def ratios(self, x):
        """Each contact's ``|(f_t, tau / e)| / f_n`` and ``f_n`` of the internal forces ``x (n, d)``: ``(n, 3)`` twice."""
        g = np.einsum("nikd,nd->nik", self.R, x)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.sqrt((g[..., 1:] ** 2).sum(axis=-1)) / g[..., 0], g[..., 0]

    def certificate(self, theta, z):
        r"""``y (n, 6)`` with ``y . G_i g_i <= 0`` for every admissible ``g_i`` of every contact, from phase I's ``z``.

        Phase I's dual has ``sum_i A_i^T z_i = alpha c`` (``alpha < 0`` where it failed), so
        ``v = sum_i F_i^T z_i - alpha c_g`` (``c_g = (n_i, 0)``) is orthogonal to ``N``, ``v = B^T (y'; .)`` and
        ``y' . G' g = v . g >= 0`` for every admissible ``g``; ``y = -D^T y'``.
        """
        k = self.scales(theta) * z  # (n, 3, 4): the multipliers of the unscaled rows
        unit, b1, b2 = self.basis
        u = np.zeros(z.shape[:2] + (4,))
        u[..., :3] = k[..., :1] * unit + k[..., 1:2] * b1 + k[..., 2:3] * b2
        u[..., 3] = np.where(self.model == cones.SOFT, k[..., 3], 0.0)
        on_x = np.einsum("nikd,nik->nd", self.R, self.scales(theta) * z)
        alpha = np.einsum("nd,nd->n", on_x, self.c) / np.maximum(np.einsum("nd,nd->n", self.c, self.c), 1e-300)
        u[..., :3] -= alpha[:, None, None] * unit
        y = np.einsum("njk,nj->nk", self.setup.pinv, u.reshape(len(u), 12))
        return -_unscaled(self.setup, y)


def _least_soft_friction(group):
    r"""The least common friction of closure over ``group``'s cones ``(n)``, NaN where none up to ``MAX_FRICTION``.

    Dinkelbach's method for the generalised fractional programme ``mu* = min_x max_i |h_i(x)| / f_{n,i}(x)``
    over the internal forces (``h_i = (f_t, tau / e)``; the infimum, attained on the cones' edge): from the
    internal force ``x_k`` phase I reaches at ``mu_k`` (the one with the largest margin, every cone weighted by
    ``1 / f_{n,i}(x_{k-1})``, Crouzeix-Ferland-Schaible's form, which converges superlinearly),
    ``mu_{k+1} = max_i |h_i(x_k)| / f_{n,i}(x_k)``: each ``mu_k`` is the friction some internal force needs, so
    an upper bound on ``mu*``, falling to it; a row stops once a step gains less than ``1e-12`` of it,
    phase I finds no force strictly inside (the margin is 0: ``mu_k = mu*``; weighted, then plain) or
    ``mu_k < 1e-6`` (``_FLOOR``).  Where a vanishing normal force's weight (at most ``1e6`` of the mean,
    ``_WEIGHTS``) stalls phase I or leaves its force outside a cone, the step is the plain margin's.
    """
    mu = np.full(len(group.rows), np.nan)
    r, _, x = group.phase_one(np.full(len(mu), np.arctan(MAX_FRICTION)))
    live = np.flatnonzero(r < 0)
    ratio, fn = group.part(live).ratios(x[live])
    mu[live] = ratio.max(axis=1)
    for _ in range(_STEPS):
        if not live.size:
            break
        sub = group.part(live)
        theta = np.arctan(mu[live])
        mean = fn.mean(axis=1, keepdims=True)
        r, _, x = sub.phase_one(theta, mean / np.maximum(fn, _WEIGHTS * mean))
        # a normal force vanishing at the optimum (as one often does) gives a weight far from one, which can
        # stall phase I or leave it a force just outside a cone: there the plain margin decides
        again = np.flatnonzero(~((r < 0) & (sub.ratios(x)[1] > 0).all(axis=1)))
        if again.size:
            r[again], _, x[again] = sub.part(again).phase_one(theta[again])
        ratio, fn = sub.ratios(x)
        new = np.where((r < 0) & (fn > 0).all(axis=1), ratio.max(axis=1), np.inf)
        gains = new < mu[live] * (1 - 1e-12)
        mu[live[gains]] = new[gains]
        gains &= new > _FLOOR
        live, fn = live[gains], fn[gains]
    return mu


#: A cap on :func:`_least_soft_friction`'s steps (rows take 3 to 12).
_STEPS = 40

#: Dinkelbach's weights ``1 / f_n`` are at most ``1 / _WEIGHTS`` of their mean.
_WEIGHTS = 1e-6

#: A soft closure friction below this stops there (an upper bound: where the infimum is 0, each step only
#: divides it by a few).
_FLOOR = 1e-6


def _unscaled(setup, y):
    """``D^T y'``: a functional on ``w' = (w_F, (w_M - c x w_F) / L)`` as one on ``w``: ``(n, 6) -> (n, 6)``."""
    angular = y[:, 3:] / setup.size[:, None]
    return np.concatenate((y[:, :3] - cross(angular, setup.centroid), angular), axis=1)


def _unreachable(setup):
    """``y (n, 6)`` with ``y . G g = 0`` for every ``g`` the contacts' models exert (rows where ``G`` is not onto).

    ``E``'s rows are orthonormal, so ``P = I - E^T E`` projects on the exerted coordinates; ``y'`` is the
    left singular vector of ``G' P`` with the least singular value (its long columns shortened,
    :func:`~grasptwist.engine.forces.cones.shortened_columns`: the same left null space), ``y = D^T y'``.
    """
    E = setup.grasp[:, 6:]
    exerted = setup.grasp[:, :6] - np.einsum("nij,nkj,nkl->nil", setup.grasp[:, :6], E, E)
    return _unscaled(setup, np.linalg.svd(cones.shortened_columns(exerted)[0])[0][:, :, -1])


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


#: The longest torsion edge of soft epsilon, over ``L`` (module docstring).
_LONGEST = 1e10


def epsilon_quality(points, normals, friction, cone_edges=8, *, torsion=None):
    """Ferrari-Canny epsilon of one grasp (module docstring); 0 when the hull is flat or misses the origin.

    ``(3, 3), (3, 3), (3,)`` -> float; NaN when a friction is infinite (no finite
    pyramid).  ``torsion (3,)``: soft contacts' radii ``e_i``, each ``e_i > 0`` adding its two torsion
    edges (module docstring).  Needs scipy (the ``quality`` extra).

    >>> p = np.array([[1, 0, 0], [-0.5, 0.75**0.5, 0], [-0.5, -(0.75**0.5), 0]])
    >>> round(epsilon_quality(p, -p, [0.5, 0.5, 0.5]), 4), round(epsilon_quality(p, -p, 0.5, torsion=0.1), 4)
    (0.2759, 0.2889)
    """
    spatial = require("scipy.spatial", "Ferrari-Canny epsilon (quality=True, --quality)")
    ConvexHull, QhullError = spatial.ConvexHull, spatial.QhullError  # noqa: N806 - scipy's names

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
    if torsion is not None:  # the soft contacts' torsion edges: f = n_i, tau = +-mu_i e_i
        e = np.broadcast_to(np.asarray(torsion, float), (3,))
        soft = np.flatnonzero(e > 0)
        tau = np.array([[1.0], [-1.0]]) * np.minimum(mu * e / k, _LONGEST * length)[soft]  # (2, s)
        fs = np.broadcast_to(n[soft] / k, tau.shape + (3,))
        moment = np.cross(q[soft], fs) + tau[..., None] * n[soft]
        wrenches = np.vstack((wrenches, np.concatenate((fs, moment / length), axis=-1).reshape(-1, 6)))
    try:
        hull = ConvexHull(np.vstack((np.zeros(6), wrenches)))
    except QhullError:  # the wrenches do not span six dimensions: no closure
        return 0.0
    return float(max(0.0, np.min(-hull.equations[:, -1]))) * k


def force_closure(
    points,
    normals,
    friction=None,
    *,
    torsion=None,
    certificate=False,
    quality=False,
    cone_edges=8,
    tol=DEGENERACY_TOL,
) -> Closure:
    r"""Force closure of each grasp: the least common friction, the verdict with ``friction``, epsilon.

    Parameters
    ----------
    points, normals : (..., 3, 3) arrays
    friction : None, scalar or (..., 3) array
        The grasp's own ``mu_i`` (for ``force_closure`` and ``epsilon``).
    torsion : None, scalar or (..., 3) array
        Soft-finger contacts' torsional radii ``e_i >= 0`` (a length; 0 a point contact), as
        :func:`grasptwist.forces.grip`'s: rows with a soft contact are judged over the
        contacts' cones (module docstring), the others as point contacts, bit for bit.
    certificate : bool
        Also a certificate for each grasp that is not force closure with ``friction`` (needs it):
        ``Closure.certificate``.
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

    Two fingers pinching a rod along its axis and a third pushing up from below lie on one
    line: point contacts exert no moment about it, soft ones (1 cm pads) do, with any friction:

    >>> p, n = [[-0.05, 0, 0], [0.05, 0, 0], [0, 0, 0]], [[1, 0, 0], [-1, 0, 0], [0, 0, 1]]
    >>> force_closure(p, n, 0.5).force_closure.item(), force_closure(p, n, 0.5, torsion=0.01).force_closure.item()
    (False, True)
    """
    p, n = check_points(points), check_normals(normals)
    shape = np.broadcast_shapes(p.shape[:-2], n.shape[:-2])
    mu = e = None
    if friction is not None:
        mu = check_friction(friction)
        shape = np.broadcast_shapes(shape, mu.shape[:-1])
    if torsion is not None:
        e = check_torsion(torsion)
        shape = np.broadcast_shapes(shape, e.shape[:-1])
    if quality and mu is None:
        raise ValueError("quality=True needs the grasp's friction (friction=MU) for the pyramids' edges")
    if certificate and mu is None:
        raise ValueError("certificate=True needs the grasp's friction (friction=MU): closure is judged with it")
    cone_edges = check_cone_edges(cone_edges)
    size = int(np.prod(shape))
    p = np.broadcast_to(p, shape + (3, 3)).reshape(size, 3, 3)
    n = np.broadcast_to(n, shape + (3, 3)).reshape(size, 3, 3)
    mu, e = (
        None if a is None else np.broadcast_to(a if a.ndim else a[None], shape + (3,)).reshape(-1, 3) for a in (mu, e)
    )
    if e is None:
        out = _closure_rows(p, n, mu, quality, cone_edges, tol)
    else:
        out = _with_soft(p, n, mu, e, quality, cone_edges, tol)
    if certificate:
        out["certificate"] = _certificates(p, n, mu, np.zeros((size, 3)) if e is None else e, out, tol)
    return Closure(**{k: None if v is None else v.reshape(shape + v.shape[1:]) for k, v in out.items()})


def _statuses(p, n, tol, mu=None):
    """The contacts' geometry, unit normals and per-row status and culprit before any closure is judged (a NaN
    friction ``mu`` is ``nonfinite-input``, as the grip's)."""
    geo = geometry(p, tol)
    status, culprit = geo.status.copy(), geo.culprit.copy()
    unit, zero, bad = unit_normals(n)
    hit = (status == 0) & zero.any(axis=1)
    status[hit], culprit[hit] = ForceStatus.ZERO_NORMAL, np.argmax(zero, axis=1)[hit]
    if mu is not None:
        bad = bad | np.isnan(mu).any(axis=1)
    status[(status == 0) & bad] = ForceStatus.NONFINITE_INPUT
    return geo, unit, status, culprit


def _closure_rows(p, n, mu, quality, edges, tol):
    geo, unit, status, culprit = _statuses(p, n, tol, mu)
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
    return {
        "closure_friction": friction,
        "force_closure": closes,
        "epsilon": _epsilons(p, n, unit, mu, None, closes, edges) if quality else None,
        "status": status,
        "culprit": culprit,
    }


def _epsilons(p, n, unit, mu, e, closes, edges):
    """Epsilon of each row: 0 outside force closure, NaN where the contacts are not finite."""
    epsilon = np.where(np.isfinite(p).all(axis=(1, 2)) & np.isfinite(n).all(axis=(1, 2)), 0.0, np.nan)
    for r in np.flatnonzero(closes):
        epsilon[r] = epsilon_quality(p[r], unit[r], mu[r], edges, torsion=None if e is None else e[r])
    return epsilon


def _with_soft(p, n, mu, e, quality, edges, tol):
    """:func:`force_closure`'s fields with torsional radii ``e (n, 3)``: the rows with a soft contact (or a NaN
    ``e``) over the contacts' cones, the others as point contacts (:func:`_closure_rows`, bit for bit)."""
    soft = (e > 0).any(axis=1) | np.isnan(e).any(axis=1)
    point, soft = np.flatnonzero(~soft), np.flatnonzero(soft)
    out = {}
    for rows, rule in ((point, _closure_rows), (soft, partial(_soft_rows, e=e[soft]))):
        done = rule(p[rows], n[rows], None if mu is None else mu[rows], quality, edges, tol)
        for name, v in done.items():
            if v is None:
                out[name] = None
                continue
            out.setdefault(name, np.zeros((len(p),) + v.shape[1:], v.dtype))[rows] = v
    return out


def _soft_rows(p, n, mu, quality, edges, tol, *, e):
    r"""Closure over the contacts' cones (rows with a soft contact): ``rank G = 6`` (of the models'
    generalised forces) and phase I's margin of an internal force inside every cone, bisected on ``theta``."""
    geo, unit, status, culprit = _statuses(p, n, tol, mu)
    line = status == ForceStatus.COLLINEAR_CONTACTS
    status[line] = 0  # a soft contact's torsion may make the moment the line cannot
    odd = np.isnan(e).any(axis=1) | (False if mu is None else np.isnan(mu).any(axis=1))
    status[(status == 0) & odd] = ForceStatus.NONFINITE_INPUT
    friction = np.full(len(p), np.nan)
    closes = None if mu is None else np.zeros(len(p), bool)
    rows = np.flatnonzero(status == 0)
    if rows.size:
        with np.errstate(all="ignore"):
            model = cones.contact_models(np.ones((rows.size, 3)), e[rows])  # soft or point, any common mu
            spans, groups = _groups(p[rows], unit[rows], e[rows], model)
            for k, group in groups:
                friction[rows[k]] = _least_soft_friction(group)
            none = np.isnan(friction[rows])
            line_only = none & line[rows] & ~spans
            status[rows[none]] = np.where(line_only[none], ForceStatus.COLLINEAR_CONTACTS, ForceStatus.NO_CLOSURE)
            culprit[rows[none]] = np.where(line_only[none], culprit[rows[none]], -1)
            if mu is not None:
                closes[rows] = _own_closure(p[rows], unit[rows], mu[rows], e[rows])[0] & ~none
    return {
        "closure_friction": friction,
        "force_closure": closes,
        "epsilon": _epsilons(p, n, unit, mu, e, closes, edges) if quality else None,
        "status": status,
        "culprit": culprit,
    }


def _groups(p, unit, e, model):
    """Whether each row's ``G`` is onto ``(n)``, and ``(rows, _Cones)`` for the rows where it is (none or one)."""
    setup = cones.cone_grasp(p, unit, np.ones(e.shape), e, model)
    spans = setup.rank == 6 + _IDLE[model].sum(axis=1)
    k = np.flatnonzero(spans)
    return spans, [(k, _Cones(setup, k, unit, model))] if k.size else []


def _own_closure(p, unit, mu, e):
    """Force closure with each contact's own ``mu_i`` over the cones ``(n)``, and where it fails a certificate
    ``(n, 6)`` (:meth:`_Cones.certificate`, or :func:`_unreachable` where ``G`` is not onto)."""
    closes, y = np.zeros(len(p), bool), np.full((len(p), 6), np.nan)
    known = ~np.isnan(mu).any(axis=1)
    rows = np.flatnonzero(known)
    model = cones.contact_models(mu[rows], e[rows])
    spans, groups = _groups(p[rows], unit[rows], e[rows], model)
    theta = np.arctan(mu[rows])
    for k, group in groups:
        r, z, _ = group.phase_one(theta[k])
        closes[rows[k]] = r < 0
        fail = np.flatnonzero(~(r < 0))
        y[rows[k[fail]]] = group.part(fail).certificate(theta[k[fail]], z[fail])
    if (~spans).any():
        out = np.flatnonzero(~spans)
        setup = cones.cone_grasp(p[rows[out]], unit[rows[out]], np.ones((out.size, 3)), e[rows[out]], model[out])
        y[rows[out]] = _unreachable(setup)
    return closes, y


def soft_closure_verdict(points, normals, friction, torsion, tol=DEGENERACY_TOL):
    """Whether each grasp is force closure with its own friction over the contacts' cones, without its least
    friction (one phase I, as :func:`force_closure`'s soft rows' ``force_closure`` less its ``~none``; a
    synthesis's filter): ``(n, 3, 3), (n, 3, 3), (n, 3), (n, 3) -> (n)`` bool, False where a status is not 0.

    >>> p, n = [[[-0.05, 0, 0], [0.05, 0, 0], [0, 0, 0]]], [[[1, 0, 0], [-1, 0, 0], [0, 0, 1]]]
    >>> soft_closure_verdict(p, n, np.full((1, 3), 0.5), np.full((1, 3), 0.01)).tolist()
    [True]
    """
    p, n = np.asarray(points, float), np.asarray(normals, float)
    e = np.asarray(torsion, float)
    _, unit, status, _ = _statuses(p, n, tol)
    status[status == ForceStatus.COLLINEAR_CONTACTS] = 0
    closes = np.zeros(len(p), bool)
    rows = np.flatnonzero((status == 0) & ~np.isnan(e).any(axis=1))
    if rows.size:
        with np.errstate(all="ignore"):
            closes[rows] = _own_closure(p[rows], unit[rows], np.asarray(friction, float)[rows], e[rows])[0]
    return closes


def _certificates(p, n, mu, e, out, tol):
    """:attr:`Closure.certificate` of every row (NaN where it is force closure or its status is not 0)."""
    geo, unit, _, _ = _statuses(p, n, tol)
    y = np.full((len(p), 6), np.nan)
    rows = np.flatnonzero(
        ~out["force_closure"] & np.isin(out["status"], (0, ForceStatus.NO_CLOSURE, ForceStatus.COLLINEAR_CONTACTS))
    )
    if rows.size:
        with np.errstate(all="ignore"):
            y[rows] = _own_closure(p[rows], unit[rows], mu[rows], e[rows])[1]
            size = geo.size[rows]
            length = np.sqrt((y[rows, :3] ** 2).sum(axis=1) + size**2 * (y[rows, 3:] ** 2).sum(axis=1))
            y[rows] /= length[:, None]
    return y


def _subset_geo(geo, rows):
    return type(geo)(*(a[rows] for a in geo))
