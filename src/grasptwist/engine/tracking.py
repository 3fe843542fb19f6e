"""A finger following its contact along an object path: joint positions, rates and where it fails.

Along a path (:mod:`.path`) contact ``i`` moves with the object, to
``p(t) = R(t) p + x(t)`` with velocity ``T_s(t)(p(t))``.  A finger whose tip
touches it at the start (joint positions ``q_0``) keeps the tip's point,
fixed on the tip link, on it by resolved-rate control with
forward-kinematics feedback (for a fingertip with a radius the point is the
sphere's centre and ``p`` the centre's place on the object, ``p - r n``:
:mod:`.fingertips`):

.. math::

    \\dot q = J(q)^+ \\bigl(T_s(p(t)) + k\\,(p(t) - f(q))\\bigr),

``f(q)`` the tip's contact point by forward kinematics and ``J(q)^+`` the
minimum-norm least-squares inverse (:func:`.kinematics.joint_rates`).  The
feedback pulls the drift of the integration back, so the tip stays on the
contact to the integration's accuracy rather than drifting with it.  The
joint positions are integrated by the classical fourth-order Runge-Kutta
method on a grid that holds every sample time and segment boundary (where the
twist jumps), each interval cut into ``steps`` equal steps; the gain is
``k = 1 / (2 h)`` for a step ``h`` (well inside the method's stability).
At each sample the integrated positions (some 1e-8 of the finger's reach
off) are brought onto the target by at most three Gauss-Newton steps
``q += J^+ (p(t) - f(q))``, so a finger that follows is on it to round-off.

Events located between the grid's times by bisection, each trial time
reached by one Runge-Kutta step from the grid time before it: the first time
a joint leaves its position limits, and the first time the finger's Jacobian
loses rank (rank < 3) or its conditioning falls below
:data:`~.degeneracy.CONDITION_WARNING`.  An event is seen at the first grid
time where it holds, then located back to its start.  A conditioning that
dips below a level and comes back within one step (a Jacobian passing
through a singular configuration: the conditioning is ``|sin|`` of an angle
or a length going through zero, a tangential zero of ``sigma_3 / sigma_1``) is
found at the local minima of the conditioning over the steps' ends: a
golden-section search between the neighbouring steps finds its smallest
value, and, below the level, bisection its start.  A joint that leaves its
limits and comes back within one step is missed, so ``steps`` sets that grain.
"""

from __future__ import annotations

from functools import lru_cache
from typing import NamedTuple

import numpy as np

from . import se3
from .degeneracy import CONDITION_WARNING
from .kinematics import RANK_TOL, forward_kinematics, joint_rates
from .path import _golden, _plan, _poses, _times
from .screws import field_at, norm

__all__ = ["FingerTrack", "track_finger", "track_fingers"]

#: Bisection of an event stops at this fraction of the grid step it is in.
_PRECISION = 1e-10

#: Most Gauss-Newton steps that bring a sample's tip onto its target (:func:`_polish`).
_POLISH = 3


class FingerTrack(NamedTuple):
    """What a finger does along a path: arrays over the sample times, then the first events.

    Attributes
    ----------
    time : (T,)
    positions, rates : (T, n)
        Joint positions, and the joint rates that move the tip's point with
        the target's velocity there.
    rank : (T,) int
    conditioning : (T,)
        Of the finger's Jacobian (see :class:`.kinematics.JointRates`).
    error : (T,)
        Distance from the tip's point to the target.
    limit_exit : (float, int) or None
        ``(t, joint)`` of the first time a joint leaves its position limits.
    rank_loss, warning : float or None
        The first time the Jacobian's rank falls below 3, and its conditioning
        below ``CONDITION_WARNING``.
    """

    time: np.ndarray
    positions: np.ndarray
    rates: np.ndarray
    rank: np.ndarray
    conditioning: np.ndarray
    error: np.ndarray
    limit_exit: tuple | None
    rank_loss: float | None
    warning: float | None


def track_finger(
    home_screws,
    home_points,
    home_tip,
    positions,
    contact,
    segments,
    times,
    *,
    lower=None,
    upper=None,
    steps=16,
    segment_steps=None,
) -> FingerTrack:
    """Follow one contact along a path with one finger (module docstring).

    Parameters
    ----------
    home_screws, home_points, home_tip
        The finger at home, as :func:`~grasptwist.hand.forward_kinematics` takes
        them (``home_tip`` the tip link's ``(4, 4)`` pose).
    positions : (n,) array
        Joint positions at ``t = 0``, where the tip touches ``contact``.
    contact : (3,) array
        The contact point at ``t = 0``.
    segments : sequence of Segment
    times : (T,) array
        Increasing sample times.
    lower, upper : (n,) arrays, optional
        Joint position limits (NaN: none).
    steps : int
        Runge-Kutta steps per interval of the grid.
    segment_steps : int, optional
        Instead of ``steps``: steps no longer than ``1 / segment_steps`` of
        their segment, at least one per interval, so that dense samples do not
        multiply the work and sparse ones cost no accuracy.

    Returns
    -------
    FingerTrack

    Examples
    --------
    A two-link arm in the plane y = 0 on a turntable (a base joint about z)
    holding a point that moves along x:

    >>> from grasptwist.path import Segment
    >>> screws = [[0, 0, 1.0, 0, 0, 0], [0, 1.0, 0, 0, 0, 0], [0, 1.0, 0, 0, 0, 1.0]]
    >>> tip = np.eye(4); tip[:3, 3] = [2.0, 0, 0]
    >>> q0 = [0, -np.pi / 3, 2 * np.pi / 3]
    >>> start = forward_kinematics(screws, [[0, 0, 0], [0, 0, 0], [1.0, 0, 0]], tip, q0).tip[:3, 3]
    >>> track = track_finger(screws, [[0, 0, 0], [0, 0, 0], [1.0, 0, 0]], tip, q0, start,
    ...                      [Segment(1.0, twist=[0, 0, 0, 0.2, 0, 0])], [0.0, 1.0])
    >>> bool(track.error.max() < 1e-6), (track.positions[-1].round(6) + 0.0).tolist()  # elbow: cos q3 = (1.2^2 - 2) / 2
    (True, [0.0, -0.927295, 1.85459])
    """
    n = np.shape(positions)[-1]
    lower = np.full(n, np.nan) if lower is None else lower
    upper = np.full(n, np.nan) if upper is None else upper
    one = [np.asarray(a, float)[None] for a in (home_screws, home_points, home_tip, positions, contact, lower, upper)]
    return track_fingers(
        *one[:5], segments, times, lower=one[5], upper=one[6], steps=steps, segment_steps=segment_steps
    )[0]


def track_fingers(
    home_screws,
    home_points,
    home_tips,
    positions,
    contacts,
    segments,
    times,
    *,
    lower=None,
    upper=None,
    steps=16,
    segment_steps=None,
) -> list[FingerTrack]:
    """Follow ``F`` contacts along one path with ``F`` fingers of ``n`` joints each, in one batch.

    :func:`track_finger` for each finger, the fingers stepped together: every
    Runge-Kutta step is one forward kinematics and one decomposition over the
    ``(F, ...)`` batch (they share the path, hence the grid), and the samples'
    last Gauss-Newton steps and rates are one batch over fingers and samples.
    Each finger's events are its own (located for it alone), so a finger's track
    does not depend on the others it is batched with.

    Parameters
    ----------
    home_screws : (F, n, 6)
    home_points : (F, n, 3)
    home_tips : (F, 4, 4)
    positions : (F, n)
    contacts : (F, 3)
    segments, times, steps, segment_steps
        As for :func:`track_finger`.
    lower, upper : (F, n) arrays, optional
        Joint position limits (NaN: none).

    Returns
    -------
    list of FingerTrack
        One per finger, in order.

    Examples
    --------
    Two Cartesian fingers (three slides each) carried along x:

    >>> from grasptwist.path import Segment
    >>> slides = np.broadcast_to(np.hstack((np.zeros((3, 3)), np.eye(3))), (2, 3, 6))
    >>> tips = np.broadcast_to(np.eye(4), (2, 4, 4))
    >>> out = track_fingers(slides, np.zeros((2, 3, 3)), tips, np.zeros((2, 3)), np.zeros((2, 3)),
    ...                     [Segment(1.0, twist=[0, 0, 0, 0.5, 0, 0])], [0.0, 1.0], steps=1)
    >>> [(t.positions[-1].round(12) + 0.0).tolist() for t in out]
    [[0.5, 0.0, 0.0], [0.5, 0.0, 0.0]]
    """
    plan = _plan(segments)
    times = _times(times, plan.end)
    q = np.array(positions, dtype=float)
    fingers, n = q.shape
    lower = np.full((fingers, n), -np.inf) if lower is None else np.where(np.isnan(lower), -np.inf, lower)
    upper = np.full((fingers, n), np.inf) if upper is None else np.where(np.isnan(upper), np.inf, upper)
    chain = (np.asarray(home_screws, float), np.asarray(home_points, float), np.asarray(home_tips, float))
    tip = forward_kinematics(*chain, q).tip
    local = se3.transform(*se3.inverse(tip[..., :3, :3], tip[..., :3, 3]), np.asarray(contacts, float))
    contacts = np.asarray(contacts, float)
    every = np.arange(fingers)

    @lru_cache(maxsize=4)
    def at_time(t, k):
        """The object's pose at time ``t`` in segment ``k``: a step's stages 2 and 3 share theirs,
        its stage 4 shares its end's with the check there."""
        return _poses(plan, np.asarray(t), k)

    def state(t, q, k=None, f=every):
        """The targets, the tips' points, the fingers' joint screws and the targets' velocities at
        ``(t, q)`` for fingers ``f`` (``q`` theirs; ``t`` a time, or one per row of ``q``), in
        segment ``k`` (the one being integrated, up to its end)."""
        pose = (
            _poses(plan, np.asarray(t, float), k)
            if np.ndim(t)
            else at_time(float(t), int(plan.index(t) if k is None else k))
        )
        r, x = (pose.rotation, pose.position) if np.ndim(t) == 0 else (pose.rotation[:, None], pose.position[:, None])
        target = se3.transform(r, x, contacts[f])
        st = forward_kinematics(chain[0][f], chain[1][f], chain[2][f], q)
        point = se3.transform(st.tip[..., :3, :3], st.tip[..., :3, 3], local[f])
        twist = pose.twist if np.ndim(t) == 0 else pose.twist[:, None]
        return target, point, st.screws, field_at(twist, target)

    def rates(t, q, gain, k, f, at=None):
        target, point, screws, velocity = state(t, q, k, f) if at is None else at
        return joint_rates(screws, point, velocity + gain * (target - point)).rates

    def step(t, q, h, at=None, f=every):
        """One Runge-Kutta step of fingers ``f`` from ``(t, q)``; ``at``: :func:`state` there, when known."""
        gain, k = 0.5 / h, plan.index(t)  # a step never crosses a boundary (the grid holds them)
        k1 = rates(t, q, gain, k, f, at)
        k2 = rates(t + h / 2, q + h / 2 * k1, gain, k, f)
        k3 = rates(t + h / 2, q + h / 2 * k2, gain, k, f)
        k4 = rates(t + h, q + h * k3, gain, k, f)
        return q + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)

    def assess(t, q, f=every):
        """What happened at ``(t, q)`` to fingers ``f``, ``(F, 3)``: the joint out of its limits, then
        0 for a rank loss and 0 for a conditioning below the warning level (-1 for nothing); the
        conditioning ``(F,)``; and :func:`state` there (the next step starts from it: one forward
        kinematics for both)."""
        at = state(t, q, None, f)
        r = joint_rates(at[2], at[1], at[3])
        out = (q < lower[f]) | (q > upper[f])
        joint = np.where(out.any(axis=-1), out.argmax(axis=-1), -1)
        events = np.stack((joint, (r.rank < 3) - 1, (r.conditioning < CONDITION_WARNING) - 1), axis=-1)
        return events, r.conditioning, at

    def judge(t, q, f):
        return assess(t, q, [f])[0][0]

    def conditioning(t, q, f):
        return float(assess(t, q, [f])[1][0])

    def one(at, f):
        return tuple(a[[f]] for a in at)

    grid = np.unique(np.concatenate((times, plan.start, [plan.end])))
    grid = grid[grid <= times[-1]]
    events, c, here = assess(0.0, q)
    first = [[(0.0, int(w)) if w >= 0 else None for w in row] for row in events]
    at = {0.0: q.copy()}
    ends, starts, values = [0.0], [q.copy()], [c]  # every step's end and state there, and the conditioning
    for a, b in zip(grid[:-1], grid[1:]):
        m = steps
        if segment_steps is not None:  # round-off must not add a step to an interval of exactly 1/m
            m = max(1, int(np.ceil(segment_steps * (b - a) / plan.duration[plan.index(a)] * (1 - 1e-12))))
        h = (b - a) / m
        for s in range(m):
            t0, t1 = a + s * h, (a + (s + 1) * h if s < m - 1 else b)
            q1 = step(t0, q, t1 - t0, here)
            events, c, there = assess(t1, q1)
            for f, e in zip(*np.nonzero(events >= 0)):
                if first[f][e] is None:
                    first[f][e] = _locate(
                        lambda t, e=e, f=f, t0=t0, q=q[[f]], h=one(here, f): judge(t, step(t0, q, t - t0, h, [f]), f)[
                            e
                        ],
                        t0,
                        t1,
                    )
            ends.append(t1)
            starts.append(q1)
            values.append(c)
            q, here = q1, there
        at[float(b)] = q.copy()

    def reached(t, f):
        """Finger ``f``'s conditioning at ``t``, reached by one step from the last step's end before it."""
        k = max(int(np.searchsorted(ends, t, side="right")) - 1, 0)
        q = starts[k][[f]]
        return conditioning(t, step(ends[k], q, t - ends[k], None, [f]) if t > ends[k] else q, f)

    values = np.array(values)
    for f in range(fingers):
        for e, level in ((1, RANK_TOL), (2, CONDITION_WARNING)):
            dip = _dip(lambda t, f=f: reached(t, f), np.array(ends), values[:, f], level)
            if dip is not None and (first[f][e] is None or dip < first[f][e][0]):
                first[f][e] = (dip, 0)
    # the samples: every finger at every sample time in one batch, (T, F, ...)
    track = _polish(state, times, np.array([at[float(t)] for t in times]))
    target, point, screws, velocity = state(times, track)
    solved = joint_rates(screws, point, velocity)
    error = norm(target - point)
    return [
        FingerTrack(
            time=times,
            positions=track[:, f],
            rates=np.array(solved.rates[:, f]),
            rank=np.array(solved.rank[:, f], dtype=int),
            conditioning=np.array(solved.conditioning[:, f], dtype=float),
            error=error[:, f],
            limit_exit=limit,
            rank_loss=None if rank is None else rank[0],
            warning=None if warning is None else warning[0],
        )
        for f, (limit, rank, warning) in enumerate(first)
    ]


def _polish(state, t, q):
    """``q (T, F, n)`` with the tips' points brought onto their targets at times ``t (T,)`` by
    Gauss-Newton steps ``q += J^+ (target - f(q))`` (:data:`_POLISH` at most, each kept only where it
    shrinks the error, and none after one that does not): the integration leaves ~1e-8 of the
    finger's reach, two steps leave round-off."""
    target, point, screws, _ = state(t, q)
    error = norm(target - point)
    going = np.ones(error.shape, dtype=bool)
    for _ in range(_POLISH):
        trial = q + joint_rates(screws, point, target - point).rates
        target, trial_point, trial_screws, _ = state(t, trial)
        trial_error = norm(target - trial_point)
        going &= trial_error < error
        if not going.any():
            break
        q = np.where(going[..., None], trial, q)
        point = np.where(going[..., None], trial_point, point)
        screws = np.where(going[..., None, None], trial_screws, screws)
        error = np.where(going, trial_error, error)
    return q


def _dip(f, t, values, level):
    """The first time ``f`` (the conditioning) falls to ``level`` or below between its values at ``t``,
    found at its local minima (module docstring); None if it never does there."""
    mid, before, after = values[1:-1], values[:-2], values[2:]
    # A local minimum that the steeper of its sides, continued for one more step, takes to the
    # level: a dip through zero (V-shaped or tangential) between steps always is one, round-off
    # wobbles of a steady conditioning are not.
    deep = 2 * mid - np.maximum(before, after) <= level
    inner = np.flatnonzero((mid <= before) & (mid <= after) & deep & (mid > level)) + 1
    for i in inner:
        lo, hi = t[i - 1], t[i + 1]
        at, low = _golden(f, lo, hi, _PRECISION * (hi - lo))
        if low <= level:
            return _locate(lambda s: 0 if f(s) <= level else -1, lo, at)[0]
    return None


def _locate(test, lo, hi):
    """``(t, test(t))`` at the first time in ``(lo, hi]`` where ``test(t) >= 0``, to ``_PRECISION``
    of the step, knowing it is not so at ``lo`` and is at ``hi``."""
    which = test(hi)
    eps = _PRECISION * (hi - lo)
    while hi - lo > eps:
        mid = 0.5 * (lo + hi)
        got = test(mid)
        if got >= 0:
            hi, which = mid, got
        else:
            lo = mid
    return float(hi), int(which)
