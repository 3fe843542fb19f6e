"""Following an object path: poses, the moving grasp, and the degeneracies on the way.

The model
---------
A path is a list of :class:`~grasptwist.model.Segment`, each held for its
``duration``: a constant twist in the ``space`` frame (the fixed grasp
frame) or the ``body`` frame (moving with the object, coincident with the
grasp frame at ``t = 0``), or a pose target reached by the constant body
twist ``log(H_k^-1 H_target) / duration`` (a screw motion).  The object's
pose ``H(t) = (R(t), x(t))`` is its rigid motion from the start (identity at
``t = 0``); within segment ``k``, started at ``t_k`` in pose ``H_k``,

.. math::

    H(t) = H_k \\exp([V_b] (t - t_k)) = \\exp([V_s] (t - t_k)) H_k,
    \\qquad V_s = \\mathrm{Ad}_{H_k} V_b,

exact to round-off (the SE(3) exponential of :mod:`.se3`, never Euler
steps).  ``V_s`` is the instantaneous space twist, constant along the
segment.  Contacts are fixed on the object and the wrist on the palm:
contact ``i`` is at ``R p_i + x`` with normal ``R n_i``, the wrist stays at
``c``.  Each time is resolved by the engine on the moved grasp.

Which degeneracies a path can meet
----------------------------------
Moving contacts and normals together by one rigid motion changes none of
the quantities built from them alone: the sides of the contact triangle
and its area, the angles between the normals and the contacts' plane
(``m . n_i`` with ``m`` and ``n_i`` rotated alike), and the lines
``Sigma_i``, ``Theta_i`` and the normal lines, which move by the adjoint, so
that their Klein products and ranks are unchanged.  Hence coincident or
collinear contacts, and every condition of the tangent method (and its
conditioning figure) are the same all along a path: the tangent method is
degenerate for the whole path or never.  The wrist is the one thing that
does not move with the object.  Seen from the object it moves by the
inverse motion, so ``[Sigma_i|Psi_i] = D / (|U_i| |E_i|)`` with

.. math:: D(t) = m(t) \\cdot (p_1(t) - c) = m_0 \\cdot (p_1 - c_b(t)),
          \\qquad c_b(t) = H(t)^{-1} c

changes, and ``wrist-coplanar`` (``D = 0``) is the only condition that can
start or stop along a path.

Finding its zeros whatever the sampling
---------------------------------------
Within a segment the wrist, seen from the object, follows the inverse screw
motion: a helix.  Its velocity ``u = dc_b/dt`` turns with the rotation,
``u(tau) = exp(-[omega_b] tau) u_0``, so ``dD/dt = -m_0 . u`` is a constant
plus a sinusoid in the angle ``theta tau`` and its zeros are in closed form
(:func:`_turning_points`).  Between those times and the segment ends ``D``
is monotone: each zero of ``D`` there is a single sign change, and each
local minimum of ``|D|`` is at one of them.  The analysis evaluates the
engine's own conditioning figure, signed by ``[Sigma_1|Psi_1]``, at these
nodes (and at any given sample times), then

* locates every sign change by bisection (all brackets at once, one
  batched engine call per step) to ``1e-10`` of the segment's duration;
* treats a node whose conditioning is at or below ``DEGENERACY_TOL`` as
  inside a degenerate zone (a tangential zero is found so: at its node),
  whose ends it locates by the same bisection.

A zone around a sign change narrower than ``sqrt(DEGENERACY_TOL)`` times the
segment's duration is a transversal crossing, reported at its root
(``t_start = t_end``): a zero of slope ``s'`` is below the tolerance over
only ``2 DEGENERACY_TOL / |s'|``.  Other zones (a tangential zero, whose
zone is ``~sqrt(DEGENERACY_TOL)`` wide, or a stretch with the wrist kept in
the plane) are reported by their ends.  ``|D|`` is monotone between nodes;
the conditioning divides it by a slowly varying length, so tests near the
tolerance can be off by that length's relative change over ~1e-9 of a
segment, which is negligible.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace
from typing import NamedTuple

import numpy as np

from ..model import Segment  # noqa: F401 - the doctests' paths
from . import se3
from .decompose import OffTangentResult, TangentResult, contact_velocities, decompose_off_tangent, decompose_tangent
from .degeneracy import CONDITION_WARNING, DEGENERACY_TOL, Status
from .screws import cross, dot, norm, rigid_motion
from .segments import check_segments

__all__ = [
    "METHODS",
    "Poses",
    "FollowResult",
    "Crossing",
    "PathDegeneracies",
    "integrate",
    "follow",
    "pose_overflowed",
    "overflowing",
    "degeneracies",
]

#: Method names, as the command line spells them.
METHODS = ("off-tangent", "tangent")

#: Bisection stops at brackets this fraction of the segment's duration: ten
#: times finer than the 1e-9 promised, so the bracket's midpoint is well within.
_PRECISION = 1e-10


#: Moved grasps are built this many rows (time x grasp) at a time, to bound temporaries.
_ROWS = 1 << 18

_GOLDEN = (math.sqrt(5) - 1) / 2


class Poses(NamedTuple):
    """The object's pose and twist at given times (``...`` the shape of the times).

    Attributes
    ----------
    time : (...) array
    segment : (...) int array
        Index of the segment each time falls in (a time on a boundary
        belongs to the segment that starts there; the path's end to the last).
    rotation : (..., 3, 3) array
    position : (..., 3) array
        The pose ``(R, x)``: a point ``p`` of the object at the start is at ``R p + x``.
    twist : (..., 6) array
        The instantaneous space twist ``(omega; v)``, ``v`` the velocity of
        the object's point at the grasp frame's origin.
    """

    time: np.ndarray
    segment: np.ndarray
    rotation: np.ndarray
    position: np.ndarray
    twist: np.ndarray


@dataclass(frozen=True, eq=False)
class FollowResult:
    """A batch of grasps followed along a path: shapes lead with the times' shape, then the grasps'.

    Attributes
    ----------
    poses : Poses
        Poses and space twists, ``(T...)``.
    points, normals : (T..., G..., 3, 3) arrays
        The moved contacts ``R p_i + x`` and normals ``R n_i``.
    wrist : (G..., 3) array or None
        The wrist, fixed.
    velocities : (T..., G..., 3, 3) array
        The contacts' velocities ``T(p_i)`` under the instantaneous twist.
    off_tangent : OffTangentResult or None
        The engine's Proposition 1 on every moved grasp (None without a
        wrist or when not asked for).
    tangent : TangentResult or None
        The engine's Proposition 2 on every moved grasp (None when not asked for).
    overflowed : (T..., G...) bool array
        Where the pose overflows double precision (``pose_overflowed``):
        both results say ``nonfinite-pose`` there.
    """

    poses: Poses
    points: np.ndarray
    normals: np.ndarray
    wrist: np.ndarray | None
    velocities: np.ndarray
    off_tangent: OffTangentResult | None
    tangent: TangentResult | None
    overflowed: np.ndarray


class Crossing(NamedTuple):
    """A stretch of a path where a method is degenerate.

    Attributes
    ----------
    method : str
        ``"off-tangent"`` or ``"tangent"``.
    code : str
        The engine's status code, e.g. ``"wrist-coplanar"``.
    t_start, t_end : float
        Where the method's conditioning is at or below ``DEGENERACY_TOL``;
        equal for a transversal crossing (its instant).
    culprit : int
        The contact the condition is about (0..2), or -1 for the grasp as a whole.
    """

    method: str
    code: str
    t_start: float
    t_end: float
    culprit: int


@dataclass(frozen=True, eq=False)
class PathDegeneracies:
    """What a path does to a grasp's conditioning.

    Attributes
    ----------
    duration : float
        The path's total duration.
    crossings : tuple of Crossing
        Every degenerate stretch, ordered by ``t_start``.
    min_conditioning : dict
        Per method (``"off-tangent"``, ``"tangent"``), ``(value, t)``: the
        smallest conditioning along the path and a time it is reached.
    warning_start : dict
        Per method, the first time its conditioning is below
        ``CONDITION_WARNING``, or None.
    """

    duration: float
    crossings: tuple[Crossing, ...]
    min_conditioning: dict
    warning_start: dict

    @property
    def first_warning(self) -> tuple[str, float] | None:
        """``(method, t)`` of the earliest warning of any method, or None."""
        started = [(t, m) for m, t in self.warning_start.items() if t is not None]
        return None if not started else min(started)[::-1]


# --- segments and poses ----------------------------------------------------------


class _Plan(NamedTuple):
    """A checked path: per segment its start, duration, start pose and constant twists."""

    start: np.ndarray  # (K,) start times
    duration: np.ndarray  # (K,)
    end: float  # total duration
    rotation: np.ndarray  # (K, 3, 3) pose at each segment's start
    position: np.ndarray  # (K, 3)
    body: np.ndarray  # (K, 6) body twist
    space: np.ndarray  # (K, 6) space twist (constant along the segment too)

    def index(self, t):
        """The segment of each time: the one starting at or before it (the last one for the end)."""
        return np.clip(np.searchsorted(self.start, t, side="right") - 1, 0, len(self.start) - 1)


def _plan(segments) -> _Plan:
    segments = check_segments(segments)
    n = len(segments)
    duration = np.array([s.duration for s in segments])
    ends = np.cumsum(duration)
    rotation, position = np.empty((n, 3, 3)), np.empty((n, 3))
    body, space = np.empty((n, 6)), np.empty((n, 6))
    r, x = np.eye(3), np.zeros(3)
    for k, s in enumerate(segments):
        rotation[k], position[k] = r, x
        if s.twist is None:
            body[k] = se3.log(*se3.compose(*se3.inverse(r, x), s.rotation, s.position)) / s.duration
        elif s.frame == "body":
            body[k] = s.twist
        else:
            body[k] = rigid_motion(s.twist, *se3.inverse(r, x))
        # a space twist is kept as given rather than mapped there and back
        space[k] = s.twist if s.twist is not None and s.frame == "space" else rigid_motion(body[k], r, x)
        if s.twist is None:  # the segment is defined by its end: no round-off carried on
            r, x = s.rotation, s.position
        else:
            r, x = se3.compose(r, x, *se3.exp(body[k], s.duration))
    return _Plan(ends - duration, duration, float(ends[-1]), rotation, position, body, space)


def _times(times, end):
    t = np.asarray(times, dtype=float)
    if not np.isfinite(t).all() or (t.size and (t.min() < 0 or t.max() > end)):
        raise ValueError(f"times must be finite and within the path, 0 <= t <= {end!r}")
    return t


def _poses(plan, t, k=None) -> Poses:
    """Poses at times ``t``, in segments ``k`` (default: each time's own; a time on a boundary
    can be taken as the end of the segment before)."""
    k = plan.index(t) if k is None else k
    r, x = se3.compose(plan.rotation[k], plan.position[k], *se3.exp(plan.body[k], t - plan.start[k]))
    return Poses(t, k, r, x, plan.space[k])


def integrate(segments, times) -> Poses:
    """The object's pose and space twist at the given times, by the SE(3) exponential.

    .. math:: H(t) = H_k \\exp([V_b] (t - t_k)), \\qquad t_k \\le t < t_{k+1}

    Parameters
    ----------
    segments : sequence of Segment
    times : array-like, any shape ``(...)``
        Times within the path, ``0 <= t <= sum of durations``.

    Returns
    -------
    Poses
        ``rotation (..., 3, 3)``, ``position (..., 3)``, space ``twist (..., 6)``,
        ``segment (...)``.

    Examples
    --------
    A quarter turn about z, then a lift by 1 in the body frame:

    >>> path = [Segment(np.pi / 2, twist=[0, 0, 1, 0, 0, 0]), Segment(1.0, twist=[0, 0, 0, 0, 0, 1], frame="body")]
    >>> p = integrate(path, [np.pi / 2, np.pi / 2 + 1])
    >>> p.position.round(12).tolist(), p.segment.tolist()
    ([[0.0, 0.0, 0.0], [0.0, 0.0, 1.0]], [1, 1])
    """
    plan = _plan(segments)
    return _poses(plan, _times(times, plan.end))


def follow(points, normals, wrist, segments, times, *, method="both", bases=False) -> FollowResult:
    """Move a batch of grasps along a path and resolve each time's twist on them.

    Contact ``i`` is at ``R(t) p_i + x(t)`` with normal ``R(t) n_i``; the
    wrist stays at ``c``; the twist resolved is the instantaneous space twist.
    The engine (:func:`~grasptwist.decompose_off_tangent`,
    :func:`~grasptwist.decompose_tangent`,
    :func:`~grasptwist.contact_velocities`) runs once on all times and grasps.

    Parameters
    ----------
    points, normals : (G..., 3, 3) arrays
        The grasps at ``t = 0``.
    wrist : (G..., 3) array or None
    segments : sequence of Segment
    times : (T...) array-like
    method : str
        ``"both"``, ``"off-tangent"`` or ``"tangent"``.
    bases : bool
        Passed to the engine: False (the default) leaves the basis screws
        out, which is most of the memory of a long path.

    Returns
    -------
    FollowResult
        Shapes ``(T..., G..., ...)``.

    Examples
    --------
    The paper's Example 1 turning about the x axis: ``[Sigma_i|Psi_i]``
    changes sign as the contacts' plane passes the wrist at ``t = pi/2``:

    >>> p = [[1, 0, 0], [-0.5, 0.866, 0], [-0.5, -0.866, 0]]
    >>> f = follow(p, -np.array(p), [0, 0, 1], [Segment(np.pi, twist=[1, 0, 0, 0, 0, 0])], [0, np.pi])
    >>> np.sign(f.off_tangent.sigma_psi[:, 0]).tolist()
    [-1.0, 1.0]
    """
    if method not in ("both",) + METHODS:
        raise ValueError(f"method must be 'both', 'off-tangent' or 'tangent', got {method!r}")
    points = se3._shaped(points, (3, 3), "points")
    normals = se3._shaped(normals, (3, 3), "normals")
    shapes = [points.shape[:-2], normals.shape[:-2]]
    if wrist is not None:
        wrist = se3._shaped(wrist, (3,), "wrist")
        shapes.append(wrist.shape[:-1])
    grasps = np.broadcast_shapes(*shapes)
    plan = _plan(segments)
    poses = _poses(plan, _times(times, plan.end))
    lead = poses.time.shape
    ones = (1,) * len(grasps)
    twist = poses.twist.reshape(lead + ones + (6,))
    # What moves with the object is resolved once per segment on the grasp at rest, with the
    # segment's body twist, and carried to each sample by its pose (module docstring: the
    # tangent method and the contact velocities see no wrist, so a rigid motion changes nothing).
    body = plan.body.reshape((-1,) + ones + (6,))
    at_rest = np.broadcast_to(contact_velocities(points, body), (len(body),) + grasps + (3, 3))
    points, normals = np.broadcast_to(points, grasps + (3, 3)), np.broadcast_to(normals, grasps + (3, 3))
    moved, turned, velocities = (np.empty(lead + grasps + (3, 3)) for _ in range(3))
    flat = [a.reshape((-1,) + a.shape[len(lead) :]) for a in (moved, turned, velocities)]
    rotation, position, segment = poses.rotation.reshape(-1, 3, 3), poses.position.reshape(-1, 3), poses.segment.ravel()
    step = max(1, _ROWS // max(1, math.prod(grasps)))
    for i in range(0, len(segment), step):
        rows = slice(i, i + step)
        _carry(rotation[rows], points, flat[0][rows], position[rows])
        _carry(rotation[rows], normals, flat[1][rows])
        for k in np.unique(segment[rows]):
            these = i + np.flatnonzero(segment[rows] == k)
            flat[2][these] = _carry(rotation[these], at_rest[k], np.empty((len(these),) + grasps + (3, 3)))
    overflowed = overflowing(
        poses, np.concatenate((points, normals), axis=-2), np.concatenate((moved, turned), axis=-2)
    )
    off = tan = None
    if method != "tangent" and wrist is not None:
        off = pose_overflowed(decompose_off_tangent(moved, wrist, twist, bases=bases), overflowed)
    if method != "off-tangent":
        tan = _carried(decompose_tangent(points, normals, body, bases=bases).row(poses.segment), poses, moved, twist)
        tan = pose_overflowed(tan, overflowed)
    return FollowResult(poses, moved, turned, wrist, velocities, off, tan, overflowed)


def overflowing(poses, rest, moved):
    """Where a pose overflows: its rotation, position or twist is not finite, or a point
    finite at rest is not once moved.  ``poses (T...)``, ``rest (G..., n, 3)``,
    ``moved (T..., G..., n, 3) -> (T..., G...)`` bool."""
    lead = poses.time.shape
    pose = np.isfinite(poses.rotation).all(axis=(-2, -1)) & np.isfinite(poses.position).all(axis=-1)
    pose &= np.isfinite(poses.twist).all(axis=-1)
    lost = ~np.isfinite(moved).all(axis=(-2, -1)) & np.isfinite(rest).all(axis=(-2, -1))
    return ~pose.reshape(lead + (1,) * (lost.ndim - len(lead))) | lost


def pose_overflowed(result, overflowed):
    """``result`` (a dataclass of per-row arrays with ``status`` and ``culprit``) with the rows
    where ``overflowed`` marked ``nonfinite-pose``: no culprit, NaN numbers.

    A pose that overflows double precision (a turn through more than about
    ``1e154`` radians, a distance beyond ``1e308``) moves the grasp to NaN,
    and whatever the engine would make of that, or of the grasp at rest
    carried there, is not a result of the path.

    Parameters
    ----------
    result : OffTangentResult, TangentResult or HandRates
        Rows ``(...)``.
    overflowed : (...) bool array

    >>> p = [[1, 0, 0], [-0.5, 0.866, 0], [-0.5, -0.866, 0]]
    >>> r = pose_overflowed(decompose_tangent(p, [[0, 0, 1]] * 3, [[0, 0, 1, 0, 0, 0]] * 2), np.array([False, True]))
    >>> [Status(s).code for s in r.status], np.isnan(r.alpha).all(axis=-1).tolist()
    (['ok', 'nonfinite-pose'], [False, True])
    """
    if not overflowed.any():
        return result
    changed = {
        "status": np.where(overflowed, np.int8(Status.NONFINITE_POSE), result.status),
        "culprit": np.where(overflowed, np.int8(-1), result.culprit),
    }
    for f in fields(result):
        value = getattr(result, f.name)
        if f.name not in changed and isinstance(value, np.ndarray) and value.dtype.kind == "f":
            where = overflowed.reshape(overflowed.shape + (1,) * (value.ndim - overflowed.ndim))
            changed[f.name] = np.where(where, np.nan, value)
    return replace(result, **changed)


def _carry(rotation, vectors, out, translation=None):
    """``R v (+ x)`` for every pose of a flat batch and every vector, written to ``out``.

    ``(n, 3, 3), (G..., 3), out (n, G..., 3), (n, 3) -> out``: one matrix
    product for all (a third of the memory traffic of three broadcast
    products and sums, which is what moving the grasps costs).
    """
    carried = np.moveaxis(np.tensordot(rotation, vectors, axes=([-1], [-1])), 1, -1)
    if translation is None:
        out[...] = carried
    else:
        np.add(carried, translation.reshape((len(translation),) + (1,) * (vectors.ndim - 1) + (3,)), out=out)
    return out


def _carried(result, poses, moved, twist):
    """A result for the grasp at rest and a segment's body twist, as it is in the moved grasp:
    the same amplitudes and verdicts, the basis lines carried by the pose (``Ad_H``)."""
    lead = poses.time.shape
    shape = moved.shape[:-2]
    ones = (1,) * (len(shape) - len(lead))
    r = poses.rotation.reshape(lead + ones + (1, 3, 3))
    x = poses.position.reshape(lead + ones + (1, 3))
    lines = {k: rigid_motion(getattr(result, k), r, x) for k in ("theta", "sigma") if getattr(result, k) is not None}
    return replace(result, points=moved, twist=np.broadcast_to(twist, shape + (6,)), **lines)


# --- degeneracies ------------------------------------------------------------------


def degeneracies(points, normals, wrist, segments, times=None, *, tol=DEGENERACY_TOL) -> PathDegeneracies:
    """Every stretch of a path where a method is degenerate, located between samples.

    The tangent method and the contact triangle cannot change along a path
    (see the module docstring): a failure at ``t = 0`` holds for the whole
    path.  ``wrist-coplanar``, the zero of ``D(t) = m(t) . (p_1(t) - c)``,
    is located to ``1e-9`` of its segment's duration, transversal crossings
    and tangential zeros alike, whatever the sampling.

    Parameters
    ----------
    points, normals : (3, 3) arrays
        One grasp at ``t = 0``.
    wrist : (3,) array or None
    segments : sequence of Segment
    times : array-like or None
        Sample times shown to the user: evaluated too, so that the minimum
        conditioning reported is never above a sample's.
    tol : float
        The engine's degeneracy tolerance.

    Returns
    -------
    PathDegeneracies

    Examples
    --------
    The paper's Example 1 turning about the x axis at unit rate: the
    contacts' plane turns through the x axis and reaches the wrist
    ``(0, 0, 1)`` after a quarter turn.

    >>> p = [[1, 0, 0], [-0.5, 0.866, 0], [-0.5, -0.866, 0]]
    >>> d = degeneracies(p, -np.array(p), [0, 0, 1], [Segment(np.pi, twist=[1, 0, 0, 0, 0, 0])])
    >>> [(c.method, c.code, round(c.t_start, 9), round(c.t_end, 9)) for c in d.crossings]
    [('tangent', 'normals-rank-deficient', 0.0, 3.141592654), ('off-tangent', 'wrist-coplanar', 1.570796327, 1.570796327)]
    """
    points = _finite_or_any(points, (3, 3), "points")
    normals = _finite_or_any(normals, (3, 3), "normals")
    whole = _plan(segments)
    extra = np.empty(0) if times is None else _times(times, whole.end).ravel()
    # the analysis below is of the stretch where the pose is finite; the rest is nonfinite-pose
    plan, overflow = _finite_part(whole, points, normals, extra)
    extra = extra[extra <= plan.end]
    zero = np.zeros(6)
    found = _Found(plan.end)
    found.constant("tangent", decompose_tangent(points, normals, zero, tol=tol, bases=False))
    methods = ["tangent"]
    if wrist is not None:
        methods.append("off-tangent")
        wrist = _finite_or_any(wrist, (3,), "wrist")
        start = decompose_off_tangent(points, wrist, zero, tol=tol, bases=False)
        if start.status in (Status.OK, Status.WRIST_COPLANAR) and plan.end > 0:
            _wrist_crossings(plan, points, wrist, extra, tol, found)
        else:  # a failure of the contacts alone, the same all along (or no finite stretch to follow)
            found.constant("off-tangent", start)
    if overflow is not None:
        found.crossings += [Crossing(m, Status.NONFINITE_POSE.code, overflow, whole.end, -1) for m in methods]
    crossings = tuple(sorted(found.crossings, key=lambda c: (c.t_start, c.t_end, c.method)))
    return PathDegeneracies(whole.end, crossings, found.minimum, found.warning)


def _finite_part(plan, points, normals, extra):
    """``(the plan up to the last time its pose is finite, the first time it is not or None)``,
    the change located between the segments' ends and the times ``extra`` by bisection
    (a pose overflows once the turn or the distance has grown too large, and stays so)."""
    rest = np.concatenate((points, normals))

    def overflowed(t):
        pose = _poses(plan, np.asarray(t, dtype=float))
        r = pose.rotation[..., None, :, :]
        moved = np.concatenate((se3.transform(r, pose.position[..., None, :], points), se3.rotate(r, normals)), -2)
        return overflowing(pose, rest, moved)

    nodes = np.unique(np.concatenate((plan.start, [plan.end], extra)))
    bad = overflowed(nodes)
    if not bad.any():
        return plan, None
    first = int(np.argmax(bad))
    if first == 0:  # already at the start (a pose target's twist overflows)
        return _until(plan, 0.0), 0.0
    lo, hi = _bisect(plan, overflowed, nodes[first - 1], nodes[first])
    return _until(plan, float(lo)), float(hi)


def _until(plan, end):
    """``plan`` cut at time ``end``: the segments that start before it (the first one at
    least), the last of them shortened to end there."""
    k = max(1, int(np.searchsorted(plan.start, end, side="left")))
    duration = plan.duration[:k].copy()
    duration[-1] = end - plan.start[k - 1]
    cut = (plan.start, plan.rotation, plan.position, plan.body, plan.space)
    start, rotation, position, body, space = (a[:k] for a in cut)
    return _Plan(start, duration, end, rotation, position, body, space)


def _finite_or_any(a, shape, name):
    """A float array of exactly ``shape`` (non-finite values are the engine's to report)."""
    a = np.asarray(a, dtype=float)
    if a.shape != shape:
        raise ValueError(f"{name} must have shape {shape}, got {a.shape}")
    return a


class _Found:
    """The findings of :func:`degeneracies` as they are made."""

    def __init__(self, end):
        self.end = end
        self.crossings = []
        self.minimum = {}
        self.warning = {}

    def constant(self, method, result):
        """A method whose verdict holds for the whole path: the one at ``t = 0``."""
        c = float(result.conditioning)
        if result.status != Status.OK:
            self.crossings.append(Crossing(method, Status(int(result.status)).code, 0.0, self.end, int(result.culprit)))
        self.minimum[method] = (c, 0.0)
        # a failed method may have no conditioning figure (NaN), but it is past any warning
        self.warning[method] = 0.0 if result.status != Status.OK or c < CONDITION_WARNING else None


def _turning_points(plan, points, wrist):
    """Times inside the segments where ``dD/dt = 0`` (closed form; module docstring).

    With ``w`` the body twist's unit axis, ``theta`` its rate and ``u_0`` the
    wrist's velocity seen from the object at the segment's start,
    ``-dD/dt = a + b cos(theta tau) + c sin(theta tau)`` with
    ``a = (m_0 . w)(w . u_0)``, ``b = m_0 . u_0 - a``, ``c = -m_0 . (w x u_0)``.
    """
    m0 = cross(points[1] - points[0], points[2] - points[0])
    found = []
    for k in range(len(plan.start)):
        omega, v = plan.body[k, :3], plan.body[k, 3:]
        theta = float(norm(omega))
        if theta == 0:  # a translation: dD/dt is constant
            continue
        c0 = se3.transform(*se3.inverse(plan.rotation[k], plan.position[k]), wrist)
        u0 = -(v + cross(omega, c0))
        w = omega / theta
        a = float(dot(m0, w) * dot(w, u0))
        b = float(dot(m0, u0)) - a
        c = -float(dot(m0, cross(w, u0)))
        amplitude = math.hypot(b, c)
        if not amplitude >= abs(a) or amplitude == 0:
            continue
        phase, spread = math.atan2(c, b), math.acos(-a / amplitude)
        span = theta * plan.duration[k]
        for angle in (phase + spread, phase - spread):
            turns = np.arange(math.ceil(-angle / (2 * math.pi)), math.floor((span - angle) / (2 * math.pi)) + 1)
            tau = (angle + 2 * math.pi * turns) / theta
            found.append(plan.start[k] + tau[(tau > 0) & (tau < plan.duration[k])])
    return np.concatenate(found) if found else np.empty(0)


class _Signed:
    """The engine's off-tangent conditioning along a path, signed like ``[Sigma_1|Psi_1]`` (so
    continuous through a zero of ``D``), and bisection on it."""

    def __init__(self, plan, points, wrist, tol):
        self.plan, self.points, self.wrist, self.tol = plan, points, wrist, tol

    def __call__(self, t):
        pose = _poses(self.plan, np.asarray(t, dtype=float))
        moved = se3.transform(pose.rotation[..., None, :, :], pose.position[..., None, :], self.points)
        r = decompose_off_tangent(moved, self.wrist, np.zeros(6), tol=self.tol, bases=False)
        return np.copysign(r.conditioning, r.sigma_psi[..., 0])

    def below(self, t):
        """At or below the tolerance: the engine's own test (NaN counts as degenerate)."""
        return ~(np.abs(self(t)) > self.tol)

    def bisect(self, test, lo, hi):
        """:func:`_bisect` on this path."""
        return _bisect(self.plan, test, lo, hi)

    def root(self, lo, hi, sign_hi):
        """The sign change in each ``[lo, hi]`` (``sign_hi`` the sign at ``hi``), to ``_PRECISION``."""
        a, b = self.bisect(lambda t: np.sign(self(t)) == sign_hi, lo, hi)
        return 0.5 * (a + b)


def _bisect(plan, test, lo, hi):
    """Shrink brackets ``[lo, hi]``, ``test`` False at ``lo`` and True at ``hi``, to ``_PRECISION``
    of the shorter of their ends' segments; all brackets at once, one engine call per step."""
    lo, hi = np.array(lo, dtype=float), np.array(hi, dtype=float)
    eps = _PRECISION * np.minimum(plan.duration[plan.index(lo)], plan.duration[plan.index(hi)])
    for _ in range(int(np.max(np.ceil(np.log2(np.maximum((hi - lo) / eps, 1))), initial=0))):
        mid = 0.5 * (lo + hi)
        up = test(mid)
        lo, hi = np.where(up, lo, mid), np.where(up, mid, hi)
    return lo, hi


def _wrist_crossings(plan, points, wrist, extra, tol, found):
    """``wrist-coplanar`` along the path, the smallest off-tangent conditioning and its first warning."""
    f = _Signed(plan, points, wrist, tol)
    nodes = np.unique(np.concatenate((plan.start, [plan.end], _turning_points(plan, points, wrist), extra)))
    values = f(nodes)
    zones = _zones(f, nodes, values)
    found.crossings += [Crossing("off-tangent", Status.WRIST_COPLANAR.code, a, b, -1) for a, b in zones]
    starts = [a for a, _ in zones]
    found.minimum["off-tangent"] = _smallest(f, nodes, values, starts)
    found.warning["off-tangent"] = _warning_start(f, nodes, values, starts)


def _zones(f, nodes, values):
    """``(t_start, t_end)`` of every stretch at or below the tolerance (module docstring)."""
    low = ~(np.abs(values) > f.tol)
    last = len(nodes) - 1
    found = []
    # Zones as (i, k, t): outer nodes i < k (-1 and last + 1 stand for the path's ends) and a time t
    # inside (None: the zone holds the nodes i + 1 .. k - 1).
    runs = np.split(np.flatnonzero(low), np.flatnonzero(np.diff(np.flatnonzero(low)) > 1) + 1)
    zones = [(r[0] - 1, r[-1] + 1, None) for r in runs if r.size]
    flips = np.flatnonzero(~low[:-1] & ~low[1:] & (values[:-1] * values[1:] < 0))
    roots = f.root(nodes[flips], nodes[flips + 1], np.sign(values[flips + 1]))
    for j, t, hit in zip(flips, roots, f.below(roots)):
        if hit:
            zones.append((j, j + 1, t))
        else:  # the zone is narrower than the root's bracket: the root is all of it
            found.append((float(t), float(t)))
    # The zones' ends, all bisected together: `below` turns True at a left end and False at a right end.
    left = [(nodes[i], nodes[i + 1] if t is None else t) for i, _, t in zones if i >= 0]
    right = [(nodes[k - 1] if t is None else t, nodes[k]) for _, k, t in zones if k <= last]
    brackets = np.array(left + right, dtype=float).reshape(-1, 2)
    flip = np.arange(len(brackets)) >= len(left)
    lo, hi = f.bisect(lambda t: f.below(t) != flip, brackets[:, 0], brackets[:, 1])
    starts, stops = iter(hi[: len(left)]), iter(lo[len(left) :])
    for i, k, t in zones:
        start = float(next(starts)) if i >= 0 else 0.0
        stop = float(next(stops)) if k <= last else f.plan.end
        sign_change = i >= 0 and k <= last and values[i] * values[k] < 0
        if sign_change and stop - start <= math.sqrt(f.tol) * f.plan.duration[f.plan.index(start)]:
            start = stop = float(t if t is not None else f.root(nodes[i], nodes[k], np.sign(values[k])))
        found.append((start, stop))
    return sorted(found)


def _smallest(f, nodes, values, starts):
    """``(value, t)`` of the smallest conditioning: at a zone, or near the best node, refined there
    by a golden-section search (between nodes ``|D|`` has no interior minimum, but the conditioning
    divides it by a length that varies too)."""
    times = np.concatenate((nodes, starts))
    size = np.abs(np.concatenate((values, f(starts))))
    best = int(np.nanargmin(size)) if np.isfinite(size).any() else 0
    value, at = float(size[best]), float(times[best])
    if best < len(nodes):
        lo, hi = nodes[max(best - 1, 0)], nodes[min(best + 1, len(nodes) - 1)]
        t, v = _golden(lambda t: abs(float(f(t))), lo, hi, _PRECISION * f.plan.duration[f.plan.index(nodes[best])])
        if v < value:
            value, at = v, t
    return value, at


def _warning_start(f, nodes, values, starts):
    """The first time the conditioning is below ``CONDITION_WARNING``: the first such node or the
    first zone, whichever is earlier, moved back to the onset between it and the node before."""
    warned = np.flatnonzero(np.abs(values) < CONDITION_WARNING)
    first = min(starts + ([float(nodes[warned[0]])] if warned.size else []), default=None)
    if first is not None and first > 0:
        before = nodes[np.searchsorted(nodes, first, side="left") - 1]
        first = float(f.bisect(lambda t: np.abs(f(t)) < CONDITION_WARNING, before, first)[1])
    return first


def _golden(f, lo, hi, eps):
    """Golden-section search for a minimum of ``f`` on ``[lo, hi]`` down to ``eps``: ``(t, f(t))``."""
    a, b = float(lo), float(hi)
    c, d = b - _GOLDEN * (b - a), a + _GOLDEN * (b - a)
    fc, fd = f(c), f(d)
    while b - a > eps:
        if fc < fd:
            b, d, fd = d, c, fc
            c = b - _GOLDEN * (b - a)
            fc = f(c)
        else:
            a, c, fc = c, d, fd
            d = a + _GOLDEN * (b - a)
            fd = f(d)
    return (c, fc) if fc < fd else (d, fd)
