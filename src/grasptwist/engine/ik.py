"""Inverse kinematics of a grasp: joint positions that put each finger's tip on its contact.

Finger ``f`` is a serial chain (:mod:`.kinematics`) whose *tip point* is the
origin of its tip link (for a finger given inline, the point its last link
touches at home).  Its position inverse kinematics asks for joint positions
``q`` with

.. math::

    f(q) = p_f, \\qquad \\text{lower} \\le q \\le \\text{upper},

``f(q)`` the tip point by forward kinematics, and, among the solutions, the
one the iteration reaches from a seed (by default the home configuration,
every joint at 0).  It is solved, batched over any leading axes, by damped
least squares (Levenberg-Marquardt) with the damping of Sugihara (2011):

.. math::

    \\Delta q = J^\\top \\bigl(J J^\\top + \\mu\\,(|e|^2 + \\lambda_0 L^2)\\,I\\bigr)^{-1} e,
    \\qquad e = p_f - f(q),

``J`` the finger's Jacobian at its tip point (:func:`.kinematics.finger_jacobian`)
and ``L`` its length.  ``mu`` starts at 1.  Each step is projected onto the
joint limits and accepted only where it shrinks ``|e|`` (``mu`` then shrinks
tenfold, down to 0.1; else it grows tenfold for that row); rows stop when
converged, a fixed number of iterations at most.  Rows that do not reach
their contact from the seed start again from fixed spread-out seeds within
the joints' ranges (:func:`spread_seeds`), nearest to the seed first, until one reaches it; rows that reach it from none of
them are solved once more without limits, to tell ``outside-limits``
(reached, but only with a joint outside its limits) from ``unreachable``
(the tip error is then the smallest distance found).

Revolute joints without limits are brought within ``pi`` of the seed.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from .degeneracy import Status
from .kinematics import finger_jacobian, forward_kinematics, rodrigues_terms
from .screws import cross, norm

__all__ = [
    "IK_TOL",
    "IK_ITERATIONS",
    "IK_SEEDS",
    "spread_seeds",
    "ChainIK",
    "chain_ik",
    "HandIK",
    "hand_ik",
    "finger_ik",
    "fingers_ik",
    "joint_limits",
    "home_tips",
    "contact_off_finger",
    "TIP_OFF_TOL",
    "tip_tolerance",
    "tip_off_contact",
    "place_hand",
]

#: A finger reaches its contact when its tip point is within ``IK_TOL`` times
#: the finger's length of it.
IK_TOL = 1e-9

#: Most damped least-squares iterations per seed.
IK_ITERATIONS = 60

#: Seeds tried, besides the given one, for rows that do not reach their contact from it.
IK_SEEDS = 8

#: The damping's floor ``lambda_0`` (times ``L**2``): keeps the steps bounded at
#: singular configurations, and slows convergence only where ``sigma_min**2 < 1e-8 L**2``.
_FLOOR = 1e-8

#: ``mu`` starts at 1 (Sugihara's damping); an accepted step divides it by 10, down to this: a tenth of
#: that damping once a row is on its way (a third fewer steps from home on the TriFinger, to the same solutions).
_MU_FLOOR = 0.1

#: Rows stop iterating when their tip is this close (times ``L``), well inside ``IK_TOL``.
_DONE = 1e-13

#: A row stops after this many iterations in a row that shrink its error by less than 1 %.
_STALL = 5

#: Largest joint motion per step (rad; lengths over ``L`` for prismatic joints).
_MAX_STEP = 0.5


@dataclass(frozen=True, eq=False)
class ChainIK:
    """A chain's inverse kinematics over a batch.

    Attributes
    ----------
    positions : (..., n)
    error : (...)
        Distance from the tip point at ``positions`` to the target.
    """

    positions: np.ndarray
    error: np.ndarray


class _Revolute(NamedTuple):
    """A chain of revolute joints prepared for the iteration's forward kinematics: each joint's
    Rodrigues terms (:func:`~.kinematics.joint_motion`) formed once, not at every step.  Per joint
    ``(..., n, ...)``: ``[omega]``, ``[omega]^2``, ``v``, ``omega x v``, ``omega``, and the home tip point."""

    k: np.ndarray
    kk: np.ndarray
    v: np.ndarray
    wv: np.ndarray
    w: np.ndarray
    tip: np.ndarray


def _prepared(chain):
    """``chain`` as :func:`_tip_and_jacobian` takes it: a :class:`_Revolute` where every joint is a unit
    line (a revolute joint), else the chain itself (:func:`~.kinematics.forward_kinematics` each step)."""
    screws, _, tip = chain
    terms = rodrigues_terms(screws)
    return chain if terms is None else _Revolute(*terms, screws[..., :3], tip[..., :3, 3])


def _tip_and_jacobian(chain, q):
    r"""The tip point ``(B, 3)`` and its Jacobian ``(B, 3, n)`` (:func:`~.kinematics.finger_jacobian`) of a
    :func:`_prepared` chain at ``q (B, n)``.

    For revolute joints, every joint's motion at once (Rodrigues: ``R_j = I + sin q_j [omega_j] +
    (1 - cos q_j) [omega_j]^2``, ``x_j = sin q_j v_j + (1 - cos q_j) omega_j x v_j``), then their product
    ``g_j = g_{j-1} (R_j, x_j)``; joint ``j``'s column is ``R_{<j} v_j + t_{<j} x omega'_j + omega'_j x p``
    with ``omega'_j = R_{<j} omega_j`` (the product before it, ``(R_{<j}, t_{<j})``): the same numbers as
    :func:`~.kinematics.forward_kinematics` in a quarter of its numpy calls (tests/engine/test_ik.py).
    """
    if not isinstance(chain, _Revolute):
        state = forward_kinematics(*chain, q)
        tip = state.tip[..., :3, 3]
        return tip, finger_jacobian(state.screws, tip)
    s, c = np.sin(q)[..., None], 1 - np.cos(q)[..., None]
    rotation = np.eye(3) + s[..., None] * chain.k + c[..., None] * chain.kk
    shift = s * chain.v + c * chain.wv
    n = q.shape[-1]
    before = np.empty(q.shape + (3, 3))  # R_{<j}
    moved = np.empty(q.shape + (3,))  # t_{<j}
    before[..., 0, :, :], moved[..., 0, :] = np.eye(3), 0.0
    for j in range(1, n):
        before[..., j, :, :] = before[..., j - 1, :, :] @ rotation[..., j - 1, :, :]
        moved[..., j, :] = (before[..., j - 1, :, :] @ shift[..., j - 1, :, None])[..., 0] + moved[..., j - 1, :]
    last = before[..., -1, :, :] @ rotation[..., -1, :, :]
    tip = (last @ chain.tip[..., None])[..., 0] + (before[..., -1, :, :] @ shift[..., -1, :, None])[..., 0]
    tip += moved[..., -1, :]
    w = (before @ np.broadcast_to(chain.w, q.shape + (3,))[..., None])[..., 0]
    v = (before @ np.broadcast_to(chain.v, q.shape + (3,))[..., None])[..., 0]
    columns = v + cross(moved - tip[..., None, :], w)
    return tip, np.swapaxes(columns, -1, -2)


def chain_ik(home_screws, home_points, home_tip, targets, seeds, lower=None, upper=None, *, iterations=IK_ITERATIONS):
    """Joint positions that put a chain's tip point on targets, from seeds (module docstring).

    Parameters
    ----------
    home_screws : (n, 6) or (B, n, 6) array
        One chain for every row, or one chain a row (several fingers of ``n`` joints of the
        same kinds solved in one batch).
    home_points : (n, 3) or (B, n, 3) array
    home_tip : (4, 4) or (B, 4, 4) array
        The tip link's pose at home; its origin is the tip point.
    targets : (B, 3) array
    seeds : (B, n) array
        Where each row's iteration starts, within the limits.
    lower, upper : (n,) or (B, n) arrays, optional
        Joint position limits, ``-inf``/``inf`` (or NaN) where none.
    iterations : int

    Returns
    -------
    ChainIK
        The best configuration reached by each row (within the limits) and its error.

    A planar two-link arm (links 1 and 1) reaching ``(1, 1, 0)``: the elbow
    bends a right angle.

    >>> s = [[0, 0, 1.0, 0, 0, 0], [0, 0, 1.0, 0, -1.0, 0]]
    >>> tip = np.eye(4); tip[0, 3] = 2.0
    >>> r = chain_ik(s, [[0, 0, 0], [1.0, 0, 0]], tip, [[1.0, 1.0, 0]], [[0.1, 0.1]])
    >>> (r.positions.round(9) + 0.0).tolist(), bool(r.error[0] < 1e-12)
    ([[0.0, 1.570796327]], True)
    """
    chain = tuple(np.asarray(a, dtype=float) for a in (home_screws, home_points, home_tip))
    n = chain[0].shape[-2]
    targets = np.asarray(targets, dtype=float)
    q = np.array(np.broadcast_to(seeds, targets.shape[:-1] + (n,)), dtype=float)
    lower, upper = _bounds(lower, n, -np.inf), _bounds(upper, n, np.inf)
    stacked = chain[0].ndim == 3
    if stacked:  # every per-chain array a row's, taken for the rows still iterating
        lower, upper = np.broadcast_to(lower, q.shape), np.broadcast_to(upper, q.shape)
    length = _length(chain)
    # per unit of step: rad, or L
    scale = np.where(chain[0][..., :3].any(axis=-1), 1.0, 1.0 / np.asarray(length)[..., None])
    prepared = _prepared(chain)
    tip, jacobian = _tip_and_jacobian(prepared, q)
    error = norm(targets - tip)
    mu = np.ones(len(q))
    slow = np.zeros(len(q), int)  # iterations in a row that shrank the error by less than 1 %
    active = np.flatnonzero(error > _DONE * length)
    for _ in range(iterations):
        if not active.size:
            break
        size = _rows(length, active, stacked)
        e = targets[active] - tip[active]
        jac = jacobian[active]
        damping = mu[active] * (np.einsum("...i,...i", e, e) + _FLOOR * size**2)
        normal = jac @ np.swapaxes(jac, -1, -2) + damping[:, None, None] * np.eye(3)
        step = (np.swapaxes(jac, -1, -2) @ np.linalg.solve(normal, e[..., None]))[..., 0]
        big = np.abs(step * _rows(scale, active, stacked)).max(axis=-1) / _MAX_STEP
        step /= np.maximum(big, 1.0)[:, None]
        trial = np.clip(q[active] + step, _rows(lower, active, stacked), _rows(upper, active, stacked))
        trial_tip, trial_jacobian = _tip_and_jacobian(_rows(prepared, active, stacked), trial)
        trial_error = norm(targets[active] - trial_tip)
        better = trial_error < error[active]
        slow[active] = np.where(trial_error < 0.99 * error[active], 0, slow[active] + 1)
        took = active[better]
        q[took], jacobian[took], tip[took], error[took] = (
            trial[better],
            trial_jacobian[better],
            trial_tip[better],
            trial_error[better],
        )
        mu[active] = np.where(better, np.maximum(mu[active] / 10, _MU_FLOOR), mu[active] * 10)
        # done: converged, or stuck (no step shrinks the error however damped, or barely any
        # for _STALL iterations: against a limit, or at a local minimum of the distance)
        active = active[(error[active] > _DONE * size) & (mu[active] < 1e12) & (slow[active] < _STALL)]
    return ChainIK(q, error)


def _rows(a, rows, stacked):
    """Rows ``rows`` of a per-chain array (or of each of a tuple of them) when there is one chain a row."""
    if not stacked:
        return a
    if isinstance(a, tuple):
        return type(a)(*(x[rows] for x in a)) if isinstance(a, _Revolute) else tuple(x[rows] for x in a)
    return a[rows]


def _bounds(b, n, none):
    """Limits as an ``(n,)`` array, ``none`` (an infinity) where there is none."""
    b = np.full(n, none) if b is None else np.asarray(b, dtype=float)
    return np.where(np.isnan(b), none, b)


def _length(chain):
    """The chain's length (at least its reach from the first joint, never 0); ``(B,)`` for one chain a row."""
    screws, points, tip = chain
    path = np.concatenate((points, tip[..., None, :3, 3]), axis=-2)
    reach = norm(np.diff(path, axis=-2)).sum(axis=-1)
    out = np.maximum(np.maximum(reach, np.abs(path).max(axis=(-2, -1)) * 1e-6), 1e-300)
    return out if out.ndim else float(out)


@dataclass(frozen=True, eq=False)
class HandIK:
    """Joint positions of a batch of hands that put their fingers' tips on the contacts.

    Attributes
    ----------
    positions : (..., n_joints)
        In ``hand.joint_names`` order.
    tip_error : (..., 3)
        Per finger, the distance from its tip point to its target at
        ``positions``: the point given for it (a contact, or with a fingertip radius the
        sphere's centre ``p - r n``); for an ``unreachable`` finger, the smallest distance found.
    within_limits : (..., 3) bool
        Per finger, whether its joints at ``positions`` are within their limits.
    status : (..., 3) int8
        Per finger, a :class:`~.degeneracy.Status`: ``ok`` (tip error at most
        :data:`IK_TOL` times the finger's length, within limits),
        ``outside-limits`` (reached only with a joint outside its limits) or
        ``unreachable``; ``nonfinite-input`` where the contact is not finite.
    """

    positions: np.ndarray
    tip_error: np.ndarray
    within_limits: np.ndarray
    status: np.ndarray

    @property
    def ok(self) -> np.ndarray:
        """Per hand: does every finger reach its contact within its limits?"""
        return (self.status == Status.OK).all(axis=-1)

    @property
    def culprit(self) -> np.ndarray:
        """Per hand: the failing finger with the largest tip error, -1 where none fails."""
        failing = np.where(self.status != Status.OK, np.nan_to_num(self.tip_error, nan=np.inf), -1.0)
        return np.where(self.ok, -1, np.argmax(failing, axis=-1)).astype(np.int8)


def joint_limits(finger):
    """A finger's position limits, ``(lower, upper)``, each ``(n,)`` with ``-inf``/``inf`` where none.

    >>> from grasptwist.model import Finger, Joint
    >>> j = (Joint("a", "revolute", None, -1.0, 2.0, None), Joint("b", "revolute", None, None, None, None))
    >>> [b.tolist() for b in joint_limits(Finger("1", None, j, None, None, None, 1.0, (0, 1)))]
    [[-1.0, -inf], [2.0, inf]]
    """
    lower = np.array([-np.inf if j.lower is None else j.lower for j in finger.joints], dtype=float)
    upper = np.array([np.inf if j.upper is None else j.upper for j in finger.joints], dtype=float)
    return lower, upper


def home_tips(hand, points=None):
    """Each finger's tip link pose at home, ``(3, 4, 4)``: a finger given inline has none, and
    its tip point is the contact it touches at home, row ``f`` of ``points`` ``(3, 3)``.

    Raises
    ------
    ValueError
        A finger given inline and no ``points``.
    """
    out = np.tile(np.eye(4), (len(hand.fingers), 1, 1))
    for f, finger in enumerate(hand.fingers):
        if finger.tip_pose is not None:
            out[f] = finger.tip_pose
        elif points is None:
            raise ValueError(f"finger {finger.name!r} has no tip link: give the points its tip touches at home")
        else:
            out[f, :3, 3] = np.asarray(points, dtype=float)[f]
    return out


def _wrap(q, seed, unlimited):
    """Revolute joints without limits within ``pi`` of the seed (the same configuration)."""
    turns = np.round((q - seed) / (2 * np.pi))
    return np.where(unlimited, q - 2 * np.pi * turns, q)


def hand_ik(hand, points, *, seed=None, tips=None, iterations=IK_ITERATIONS) -> HandIK:
    """Joint positions that put every finger's tip point on its contact (module docstring).

    Parameters
    ----------
    hand : Hand
    points : (..., 3, 3) array
        The contacts, row ``f`` for finger ``f`` (its tip point goes there).
    seed : (..., n_joints) array, optional
        Where to start, in ``hand.joint_names`` order; default the home
        configuration (every joint at 0), brought within the limits.
    tips : (3, 4, 4) array, optional
        Each finger's tip link pose at home (:func:`home_tips`); default
        their tip links' (a finger given inline needs it).
    iterations : int
        Most iterations per seed.

    Returns
    -------
    HandIK

    Examples
    --------
    A hand of three 2-link planar fingers (links 1 and 1), each reaching a
    point at distance ``sqrt 2`` (reached) or 3 (beyond its length 2, by 1):

    >>> from grasptwist.hand import Finger, Hand, Joint
    >>> s = np.array([[0, 0, 1.0, 0, 0, 0], [0, 0, 1.0, 0, -1.0, 0]])
    >>> joints = (Joint("a", "revolute", None, None, None, None), Joint("b", "revolute", None, None, None, None))
    >>> tip = np.eye(4); tip[0, 3] = 2.0
    >>> f = [Finger(str(i), "tip", joints, s, np.array([[0, 0, 0], [1.0, 0, 0]]), tip, 2.0, (2 * i, 2 * i + 1)) for i in range(3)]
    >>> h = Hand(tuple(f), ("a0", "b0", "a1", "b1", "a2", "b2"), None, None)
    >>> r = hand_ik(h, [[1.0, 1, 0], [1.0, -1, 0], [3.0, 0, 0]])
    >>> [Status(int(s)).code for s in r.status], r.tip_error[2].round(9).tolist()
    (['ok', 'ok', 'unreachable'], 1.0)
    """
    points = np.asarray(points, dtype=float)
    lead = points.shape[:-2]
    tips = home_tips(hand) if tips is None else np.asarray(tips, dtype=float)
    n = len(hand.joint_names)
    seed = np.zeros(lead + (n,)) if seed is None else np.broadcast_to(np.asarray(seed, dtype=float), lead + (n,))
    positions = np.array(seed, dtype=float)
    shape3 = lead + (len(hand.fingers),)
    tip_error, within, status = np.zeros(shape3), np.ones(shape3, bool), np.zeros(shape3, np.int8)
    for f, finger in enumerate(hand.fingers):
        index = list(finger.joint_index)
        chain = (finger.screws, finger.points, tips[f])
        lower, upper = joint_limits(finger)
        target = points[..., f, :].reshape(-1, 3)
        start = np.clip(seed[..., index].reshape(-1, len(index)), lower, upper)
        spread = spread_seeds(finger)
        q, err, inside, code = _finger(chain, target, start, lower, upper, _unlimited(finger), spread, iterations)
        positions[..., index] = q.reshape(lead + (len(index),))
        tip_error[..., f], within[..., f], status[..., f] = (a.reshape(lead) for a in (err, inside, code))
    return HandIK(positions, tip_error, within, status)


def finger_ik(finger, tip, targets, *, seeds=IK_SEEDS, classify=True, iterations=IK_ITERATIONS):
    """One finger's inverse kinematics over rows of targets, from home (:func:`hand_ik`'s for one finger).

    Parameters
    ----------
    finger : Finger
    tip : (4, 4) array
        Its tip link's pose at home (:func:`home_tips`).
    targets : (B, 3) array
    seeds : int
        Spread seeds (:func:`spread_seeds`) tried by rows that miss from home; fewer is faster.
    classify : bool
        Tell ``outside-limits`` from ``unreachable`` (a second solve without limits); a search
        that only needs to know whether the finger reaches leaves it out.
    iterations : int

    Returns
    -------
    (positions (B, n), tip error (B,), within limits (B,), status (B,) int8)

    >>> from grasptwist.hand import Finger, Joint
    >>> s = np.array([[0, 0, 1.0, 0, 0, 0], [0, 0, 1.0, 0, -1.0, 0]])
    >>> j = (Joint("a", "revolute", None, None, None, None), Joint("b", "revolute", None, None, None, None))
    >>> tip = np.eye(4); tip[0, 3] = 2.0
    >>> f = Finger("1", "tip", j, s, np.array([[0, 0, 0], [1.0, 0, 0]]), tip, 2.0, (0, 1))
    >>> [Status(int(c)).code for c in finger_ik(f, tip, [[1.0, 1, 0], [3.0, 0, 0]], classify=False)[3]]
    ['ok', 'unreachable']
    """
    targets = np.asarray(targets, dtype=float).reshape(-1, 3)
    lower, upper = joint_limits(finger)
    start = np.clip(np.zeros((len(targets), len(finger.joints))), lower, upper)
    chain = (finger.screws, finger.points, np.asarray(tip, dtype=float))
    return _finger(
        chain, targets, start, lower, upper, _unlimited(finger), spread_seeds(finger)[:seeds], iterations, classify
    )


def fingers_ik(fingers, tips, which, targets, *, seeds=IK_SEEDS, iterations=IK_ITERATIONS):
    """Several fingers' inverse kinematics in one batch, from home: row ``k`` puts finger ``which[k]``'s
    tip point on ``targets[k]`` (:func:`finger_ik` without ``classify``, each row as it would solve it).

    Fingers whose joints are of the same kinds, in the same order (the TriFinger's three), are
    stepped together, one chain a row, so that a batch pays the iterations' overhead once.

    Parameters
    ----------
    fingers : sequence of Finger
    tips : (F, 4, 4) array
        Their tip links' poses at home.
    which : (B,) int array
    targets : (B, 3) array
    seeds, iterations
        As :func:`finger_ik`.

    Returns
    -------
    (positions (B, n_max) (NaN past a finger's joints), tip error (B,), status (B,) int8)

    >>> from grasptwist.hand import Finger, Joint
    >>> s = np.array([[0, 0, 1.0, 0, 0, 0], [0, 0, 1.0, 0, -1.0, 0]])
    >>> j = (Joint("a", "revolute", None, None, None, None), Joint("b", "revolute", None, None, None, None))
    >>> tip = np.eye(4); tip[0, 3] = 2.0
    >>> f = Finger("1", "tip", j, s, np.array([[0, 0, 0], [1.0, 0, 0]]), tip, 2.0, (0, 1))
    >>> q, error, status = fingers_ik([f, f], np.array([tip, tip]), [0, 1], [[1.0, 1, 0], [3.0, 0, 0]])
    >>> [Status(int(c)).code for c in status], (q[0].round(9) + 0.0).tolist(), error.round(9).tolist()
    (['ok', 'unreachable'], [0.0, 1.570796327], [0.0, 1.0])
    """
    which = np.asarray(which, dtype=int)
    targets = np.asarray(targets, dtype=float).reshape(-1, 3)
    tips = np.asarray(tips, dtype=float)
    q = np.full((len(targets), max((len(f.joints) for f in fingers), default=0)), np.nan)
    error, status = np.full(len(targets), np.nan), np.zeros(len(targets), np.int8)
    kinds = {}
    for f, finger in enumerate(fingers):
        kinds.setdefault(tuple(j.type for j in finger.joints), []).append(f)
    for members in kinds.values():
        rows = np.flatnonzero(np.isin(which, members))
        if not rows.size:
            continue
        local = np.searchsorted(members, which[rows])  # each row's finger among ``members``

        def per_row(values, local=local):
            return np.array(values)[local]

        mine = [fingers[k] for k in members]
        lower, upper = (per_row(b) for b in zip(*map(joint_limits, mine)))
        chain = per_row([f.screws for f in mine]), per_row([f.points for f in mine]), tips[members][local]
        spread = per_row([spread_seeds(f)[:seeds] for f in mine])
        start = np.clip(np.zeros(lower.shape), lower, upper)
        got, err, _, code = _finger(
            chain, targets[rows], start, lower, upper, per_row([_unlimited(f) for f in mine]), spread, iterations, False
        )
        q[rows, : lower.shape[1]], error[rows], status[rows] = got, err, code
    return q, error, status


def _unlimited(finger):
    """Which of a finger's joints are revolute without limits (brought within ``pi`` of the seed)."""
    lower, upper = joint_limits(finger)
    return np.array([j.type != "prismatic" for j in finger.joints]) & ~np.isfinite(lower) & ~np.isfinite(upper)


def _finger(chain, target, start, lower, upper, unlimited, spread, iterations, classify=True):
    """One finger over flat rows (or one chain a row, :func:`chain_ik`): positions, tip error, within
    limits, status (per row); ``spread`` its seeds ``(S, n)`` (``(B, S, n)``, one chain a row)."""
    stacked = chain[0].ndim == 3
    length = _length(chain)
    tol = IK_TOL * length
    finite = np.isfinite(target).all(axis=-1)
    target = np.where(finite[:, None], target, 0.0)
    best = chain_ik(*chain, target, start, lower, upper, iterations=iterations)
    q, err = best.positions, np.where(finite, best.error, 0.0)
    _restart(chain, target, start, spread, lower, upper, tol, iterations, q, err)
    status = np.where(err <= tol, Status.OK, Status.UNREACHABLE)
    missed = np.flatnonzero(err > tol)
    limited = np.isfinite(lower).any() or np.isfinite(upper).any()
    if classify and missed.size and limited:  # reachable outside the limits?
        sub, within = _rows(chain, missed, stacked), _rows(tol, missed, stacked)
        free = chain_ik(*sub, target[missed], start[missed], iterations=iterations)
        fq, fe = free.positions, free.error
        _restart(
            sub, target[missed], start[missed], _rows(spread, missed, stacked), None, None, within, iterations, fq, fe
        )
        outside = fe <= within
        q[missed[outside]], err[missed[outside]] = fq[outside], fe[outside]
        status[missed[outside]] = Status.OUTSIDE_LIMITS
    q = _wrap(q, start, unlimited)
    inside = ((q >= lower) & (q <= upper)).all(axis=-1)
    status = np.where(finite, status, Status.NONFINITE_INPUT)
    return q, np.where(finite, err, np.nan), inside, status.astype(np.int8)


def _restart(chain, target, start, spread, lower, upper, tol, iterations, q, err):
    """Rows that miss (``err > tol``) start again from the spread seeds, nearest to their own
    start first, while they miss; each row keeps its best (``q`` and ``err`` updated in place)."""
    stacked = chain[0].ndim == 3
    seeds = spread if stacked else spread[None]
    order = np.argsort(np.linalg.norm(seeds - start[:, None, :], axis=-1), axis=-1)
    for k in range(spread.shape[-2]):
        missed = np.flatnonzero(err > tol)
        if not missed.size:
            return
        seed = spread[missed, order[missed, k]] if stacked else spread[order[missed, k]]
        limits = (None, None) if lower is None else (_rows(lower, missed, stacked), _rows(upper, missed, stacked))
        got = chain_ik(*_rows(chain, missed, stacked), target[missed], seed, *limits, iterations=iterations)
        better = got.error < err[missed]
        q[missed[better]], err[missed[better]] = got.positions[better], got.error[better]


def spread_seeds(finger, count=IK_SEEDS):
    """``count`` fixed seeds spread over a finger's joint ranges: its limits, or ``[-pi, pi]`` (revolute)
    and ``[-L, L]`` (prismatic) where a joint has none; the same every run.

    Returns
    -------
    (count, n) array
    """
    lower, upper = joint_limits(finger)
    wide = np.array([finger.length if j.type == "prismatic" else np.pi for j in finger.joints])
    lo = np.where(np.isfinite(lower), lower, -wide)
    hi = np.where(np.isfinite(upper), upper, wide)
    return lo + np.random.default_rng(20231).random((count, len(lo))) * (hi - lo)


def contact_off_finger(tip_points, points, lengths):
    """Contacts farther from their finger's tip than the finger is long: a frame mix-up, not a grasp.

    .. math:: |p_f - t_f| > L_f

    Parameters
    ----------
    tip_points : (..., 3, 3) array
        Each finger's tip link origin at the configuration.
    points : (..., 3, 3) array
        The contacts.
    lengths : (3,) array
        The fingers' lengths.

    Returns
    -------
    (..., 3) bool

    >>> contact_off_finger(np.zeros((3, 3)), np.diag([0.5, 2.0, 0.0]), [1.0, 1.0, 1.0]).tolist()
    [False, True, False]
    """
    return norm(np.asarray(points, dtype=float) - np.asarray(tip_points, dtype=float)) > np.asarray(lengths, float)


#: Given joint positions whose tip point is farther from where it must be than this fraction of its
#: finger's length are warned of (``tip-off-contact``): 1%, 3.8 mm on the TriFinger's 0.38 m fingers, where
#: positions written to 4 decimals (1e-4 rad) leave the tip some 4e-5 m off.
TIP_OFF_TOL = 0.01


def tip_tolerance(lengths):
    """How far a tip point at given joint positions may be from where it must be: ``TIP_OFF_TOL L``.

    >>> tip_tolerance([0.38, 3.0]).tolist()
    [0.0038, 0.03]
    """
    return TIP_OFF_TOL * np.asarray(lengths, dtype=float)


def tip_off_contact(tip_error, lengths):
    """Fingers whose tip point, at given joint positions, is off its contact: farther from where it
    must be (the centre of its fingertip sphere touching the contact) than :func:`tip_tolerance`.

    .. math:: e_f > 0.01 L_f

    Parameters
    ----------
    tip_error : (..., 3) array
        Each finger's distance from where it must be (:func:`place_hand`); NaN (unchecked) is not off.
    lengths : (3,) array
        The fingers' lengths.

    Returns
    -------
    (..., 3) bool

    >>> tip_off_contact([[0.0474, 0.003, np.nan]], [0.38, 0.38, 0.38]).tolist()
    [[True, False, False]]
    """
    return np.asarray(tip_error, dtype=float) > tip_tolerance(lengths)


def place_hand(hand, points, positions=None, *, seed=None, tips=None) -> HandIK:
    """A batch of hands on their contacts: at given joint positions, checked, or else solved.

    With ``positions``, each finger's tip is checked against its contact
    (``contact-off-finger`` when a contact is farther from its tip than the
    finger is long; the tip error the distance from the tip to the point given); without, they are solved by
    :func:`hand_ik` from ``seed``.  A finger given inline has no tip point
    unless ``tips`` gives one: it is unchecked (tip error NaN), and a hand
    with such a finger is not solved but taken as given (every joint at 0,
    the configuration its screws describe).

    Parameters
    ----------
    hand : Hand
    points : (..., 3, 3) array
    positions : (..., n_joints) array, optional
    seed : (..., n_joints) array, optional
    tips : (3, 4, 4) array, optional
        As for :func:`hand_ik`.

    Returns
    -------
    HandIK

    Examples
    --------
    >>> from grasptwist.hand import Finger, Hand, Joint
    >>> s = np.array([[0, 0, 1.0, 0, 0, 0], [0, 0, 1.0, 0, -1.0, 0]])
    >>> joints = (Joint("a", "revolute", None, None, None, None), Joint("b", "revolute", None, None, None, None))
    >>> tip = np.eye(4); tip[0, 3] = 2.0
    >>> f = [Finger(str(i), "tip", joints, s, np.array([[0, 0, 0], [1.0, 0, 0]]), tip, 2.0, (2 * i, 2 * i + 1)) for i in range(3)]
    >>> h = Hand(tuple(f), ("a0", "b0", "a1", "b1", "a2", "b2"), None, None)
    >>> r = place_hand(h, [[2.0, 0, 0], [1.0, 0, 0], [-3.0, 0, 0]], np.zeros(6))
    >>> [Status(int(s)).code for s in r.status], r.tip_error.tolist()
    (['ok', 'ok', 'contact-off-finger'], [0.0, 1.0, 5.0])
    """
    points = np.asarray(points, dtype=float)
    lead, n = points.shape[:-2], len(hand.joint_names)
    known = [f.tip_pose is not None or tips is not None for f in hand.fingers]
    if positions is None and all(known):
        return hand_ik(hand, points, seed=seed, tips=tips)
    if positions is None:  # a finger without a tip point: every joint as given
        positions = np.zeros(lead + (n,))
    positions = np.broadcast_to(np.asarray(positions, dtype=float), lead + (n,))
    shape3 = lead + (len(hand.fingers),)
    tip_error, within, status = np.full(shape3, np.nan), np.ones(shape3, bool), np.zeros(shape3, np.int8)
    for f, finger in enumerate(hand.fingers):
        q = positions[..., list(finger.joint_index)]
        lower, upper = joint_limits(finger)
        within[..., f] = ((q >= lower) & (q <= upper)).all(axis=-1)
        if not known[f]:
            continue
        home = finger.tip_pose if tips is None else np.asarray(tips, dtype=float)[f]
        tip = forward_kinematics(finger.screws, finger.points, home, q).tip[..., :3, 3]
        tip_error[..., f] = norm(points[..., f, :] - tip)
        off = contact_off_finger(tip, points[..., f, :], finger.length)
        status[..., f] = np.where(off, Status.CONTACT_OFF_FINGER, Status.OK)
    return HandIK(np.array(positions), tip_error, within, status)
