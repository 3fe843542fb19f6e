r"""Scoring candidate contact triples in batches: the constraints as cheap filters, then the grip.

A candidate ``(p, n)`` (``(N, 3, 3)`` contacts and inward normals) is *feasible* when,
in this order (cheapest first, each test run only on the rows that passed the ones
before it):

1. its contacts are not degenerate (distinct, not collinear) and every asked
   decomposition has ``conditioning >= min_conditioning`` (the tangent method always,
   the off-tangent one when a wrist is given);
2. it is force closure at the friction the grip may use, ``mu / safety`` (the planar
   reduction's one test, :func:`~grasptwist.engine.forces.closure.internal_inside`);
3. it passes every further constraint given (``constraints``: functions of the contacts and
   normals, a hand's reach or a table, each ``(n, 3, 3), (n, 3, 3) -> (n,) bool``);
4. a grip exists for every wrench (the batched least grip,
   :func:`~grasptwist.engine.forces.grip.grip`);
5. with a hand (``hand``), some assignment of its fingers to the contacts has the fingertips
   on the surface, reaches every contact within the joint limits and keeps every finger link
   out of the object (:mod:`~grasptwist.engine.synthesis.reach`: the most expensive test, last).

For each wrench the least total normal force

.. math:: \min \sum_i f_i \cdot n_i \quad \text{s.t.} \quad G f = w, \;
          |f_i - (f_i \cdot n_i) n_i| \le \frac{\mu}{s} f_i \cdot n_i

is the row's score for that wrench.  The objectives ``total_normal_force`` and ``robust`` are the
largest of them (a grip must hold each wrench); ``closure_friction`` (the least common
friction of closure) and ``epsilon`` (Ferrari-Canny's, negated so that less is better)
are computed only on feasible rows.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..decompose import decompose_off_tangent, decompose_tangent
from ..degeneracy import DEGENERACY_TOL
from ..forces.closure import force_closure, internal_inside, soft_closure_verdict
from ..forces.grasp_map import geometry
from ..forces.grip import wrench_grips
from .reach import HAND_CONSTRAINTS, reach

__all__ = [
    "OBJECTIVES",
    "CONSTRAINTS",
    "METHODS",
    "MIN_CONDITIONING",
    "TIE_TOL",
    "Scores",
    "tie_broken",
    "check_objective",
    "check_min_conditioning",
    "score_triples",
]

#: The objectives a search may minimise (``epsilon`` is maximised: its score is ``-epsilon``).  ``robust``
#: scores candidates as ``total_normal_force`` does and ranks the finalists by their robustness
#: first (:mod:`~grasptwist.engine.synthesis.robustness`, in the search).
OBJECTIVES = ("robust", "total_normal_force", "closure_friction", "epsilon")

#: The constraints in the order they are tested; a row's ``failed`` indexes this (-1: feasible).
CONSTRAINTS = ("degenerate", "conditioning", "force_closure", "constraints", "grip", *HAND_CONSTRAINTS)

#: The decompositions whose conditioning a grasp must keep above ``min_conditioning``.
METHODS = ("off_tangent", "tangent")

#: The default ``min_conditioning`` of the command line and of Python.  Least total force pulls a
#: search to its conditioning floor (on the TriFinger cube on its table the least total, ``m g / mu``,
#: is reached only as the tangent conditioning goes to 0, the total above it growing as its square):
#: at 0.001 (the degeneracy warnings' threshold) the grasps found turn the cube at 0.5 rad/s with
#: tangent amplitudes up to 166; at 0.05 up to 1.17 (the bundled grasp's: 1.24) for 0.6-0.8% more force.
MIN_CONDITIONING = 0.05

#: Objectives within this share of each other are ties, broken by the larger conditioning (:func:`tie_broken`).
TIE_TOL = 1e-6


class Scores(NamedTuple):
    """The scores of ``N`` candidates (NaN where a row did not reach that test).

    Attributes
    ----------
    objective : (N,)
        What the search minimises; ``inf`` where the row is not feasible.
    total_normal_force : (N, W)
        The least total normal force for each wrench.
    conditioning : (N, 2)
        Of the off-tangent (NaN without a wrist) and the tangent decomposition (:data:`METHODS`).
    failed : (N,) int8
        The first constraint (:data:`CONSTRAINTS`) the row fails, -1 where it passes them all,
        ``len(CONSTRAINTS)`` where it was not tested further (``bound``).
    order : (N, 3) int or None
        With a hand: finger ``f`` touches contact ``order[:, f]``.
    joint_positions : (N, n_joints) or None
        With a hand: where it reaches the feasible rows (NaN elsewhere).
    miss : (N,) or None
        With a hand: how close a row that fails one of its constraints came
        (:class:`~grasptwist.engine.synthesis.reach.Reached`).
    """

    objective: np.ndarray
    total_normal_force: np.ndarray
    conditioning: np.ndarray
    failed: np.ndarray
    order: np.ndarray | None = None
    joint_positions: np.ndarray | None = None
    miss: np.ndarray | None = None


def check_objective(objective) -> str:
    """One of :data:`OBJECTIVES`.

    >>> check_objective("epsilon")
    'epsilon'
    >>> check_objective("speed")
    Traceback (most recent call last):
    ValueError: objective must be one of robust, total_normal_force, closure_friction, epsilon, got 'speed'
    """
    if objective not in OBJECTIVES:
        raise ValueError(f"objective must be one of {', '.join(OBJECTIVES)}, got {objective!r}")
    return objective


def check_min_conditioning(value) -> float:
    """A conditioning floor: a number from 0 to 1 (conditionings are at most 1).

    >>> check_min_conditioning(0.05)
    0.05
    >>> check_min_conditioning(2)
    Traceback (most recent call last):
    ValueError: min_conditioning must be a number from 0 to 1, got 2
    """
    number = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool)
    if not (number and 0 <= value <= 1):
        raise ValueError(f"min_conditioning must be a number from 0 to 1, got {value!r}")
    return float(value)


def conditionings(points, normals, wrist, methods, tol=DEGENERACY_TOL):
    """``(N, 2)`` conditioning of each decomposition in ``methods`` (NaN for the others), 0 where degenerate.

    >>> p = np.array([[[1.0, 0, 0], [-0.5, 0.75**0.5, 0], [-0.5, -(0.75**0.5), 0]]])
    >>> conditionings(p, -p, None, METHODS).round(4).tolist()
    [[nan, 0.0]]
    """
    out = np.full((len(points), 2), np.nan)
    zero = np.zeros(6)
    if "off_tangent" in methods and wrist is not None:
        r = decompose_off_tangent(points, wrist, zero, tol=tol, bases=False)
        out[:, 0] = np.where(r.status == 0, r.conditioning, 0.0)
    if "tangent" in methods:
        r = decompose_tangent(points, normals, zero, tol=tol, bases=False)
        out[:, 1] = np.where(r.status == 0, r.conditioning, 0.0)
    return out


def score_triples(
    points,
    normals,
    wrenches,
    friction,
    *,
    safety=1.0,
    objective="total_normal_force",
    wrist=None,
    methods=METHODS,
    min_conditioning=MIN_CONDITIONING,
    constraints=(),
    hand=None,
    bound=np.inf,
    torsion=None,
    tol=DEGENERACY_TOL,
) -> Scores:
    """Score ``N`` candidate triples against every constraint and the objective (module docstring).

    Parameters
    ----------
    points, normals : (N, 3, 3) arrays
        Contacts and unit inward normals.
    wrenches : (W, 6) array
        The wrenches every grasp must exert (``W >= 1``).
    friction : float
        ``mu``, the same at every contact.
    safety, objective, wrist, methods, min_conditioning, constraints, hand, tol
        As :func:`~grasptwist.engine.synthesis.search.search`.
    torsion : None or float
        Soft-finger contacts' torsional radius ``e > 0`` at every contact (None: point contacts): closure,
        the grip and the objective over the soft cones (:func:`~grasptwist.engine.forces.closure.force_closure`).
    bound : float
        With a hand: rows whose objective is at least this are not put to the hand's test
        (a search's archive would not keep them); their ``failed`` is ``len(CONSTRAINTS)``,
        their objective ``inf``.

    Returns
    -------
    Scores

    Examples
    --------
    Three fingers at the equator of a unit ball hold 1 N with ``1 / mu`` of grip, but
    their normals lie in the contacts' plane: the tangent method is degenerate there.

    >>> p = np.array([[[1.0, 0, 0], [-0.5, 0.75**0.5, 0], [-0.5, -(0.75**0.5), 0]]])
    >>> s = score_triples(p, -p, [[0, 0, 1.0, 0, 0, 0]], 0.5, methods=("off_tangent",))
    >>> s.objective.round(6).tolist(), s.failed.tolist()
    ([2.0], [-1])
    >>> CONSTRAINTS[score_triples(p, -p, [[0, 0, 1.0, 0, 0, 0]], 0.5).failed[0]]
    'degenerate'
    """
    p, n = np.asarray(points, float), np.asarray(normals, float)
    w = np.asarray(wrenches, float).reshape(-1, 6)
    rows = len(p)
    total = np.full((rows, len(w)), np.nan)
    objective_value = np.full(rows, np.inf)
    failed = np.full(rows, CONSTRAINTS.index("degenerate"), np.int8)
    geo = geometry(p, tol)
    live = np.flatnonzero(geo.status == 0)
    cond = np.full((rows, 2), np.nan)
    cond[live] = conditionings(p[live], n[live], wrist, methods, tol)
    asked = ~np.isnan(cond[live]).all(axis=0)
    good = (cond[live][:, asked] > tol).all(axis=1)
    failed[live[good]] = CONSTRAINTS.index("conditioning")
    live = live[good & (cond[live][:, asked] >= min_conditioning).all(axis=1)]
    failed[live] = CONSTRAINTS.index("force_closure")
    mu = np.full((live.size, 3), friction / safety)
    if torsion is None:
        live = live[~np.isnan(internal_inside(p[live], n[live], type(geo)(*(a[live] for a in geo)), mu)).any(axis=1)]
    else:
        live = live[soft_closure_verdict(p[live], n[live], mu, np.full((live.size, 3), float(torsion)), tol)]
    failed[live] = CONSTRAINTS.index("constraints")
    for constraint in constraints:  # a hand's reach, a table, ...: after the cheap tests, before the grip
        if live.size:
            live = live[np.asarray(constraint(p[live], n[live]), bool)]
    failed[live] = CONSTRAINTS.index("grip")
    total[live], ok = wrench_grips(p[live], n[live], w, friction, safety=safety, torsion=torsion, tol=tol)
    live = live[ok.all(axis=1)]
    failed[live] = -1
    value = objective_values(p[live], n[live], total[live], friction / safety, objective, tol, torsion)
    objective_value[live] = tie_broken(value, cond[live])
    if hand is None:
        return Scores(objective_value, total, cond, failed)
    # rows no better than ``bound`` are never kept: the hand, the costliest test, is spared them
    spared = live[objective_value[live] >= bound]
    failed[spared], objective_value[spared] = len(CONSTRAINTS), np.inf
    live = live[objective_value[live] < bound]
    order = np.tile(np.arange(3), (rows, 1))
    positions = np.full((rows, len(hand.hand.joint_names)), np.nan)
    miss = np.full(rows, np.nan)
    if live.size:
        r = reach(hand, p[live], n[live])
        failed[live] = np.where(r.failed == -1, -1, CONSTRAINTS.index("grip") + 1 + r.failed)
        order[live], positions[live], miss[live] = r.order, r.positions, r.miss
        objective_value[live[r.failed != -1]] = np.inf
    return Scores(objective_value, total, cond, failed, order, positions, miss)


def tie_broken(value, conditioning):
    r"""The objective a search ranks by: ``value`` with its ties broken by the larger conditioning.

    .. math:: v + \tau\, |v|\, (1 - c), \qquad \tau = 10^{-6}\ (:data:`TIE_TOL`)

    with ``c`` the worse conditioning of the decompositions asked (NaN where not asked).  Grasps
    whose objectives differ by more than ``tau |v|`` keep their order; among those within it (a
    plateau: on a box held by side faces every grasp with a balanced grip needs ``m g / mu``) the
    better conditioned one comes first, so that a search no longer ends on its conditioning floor.

    Parameters
    ----------
    value : (N,) array
        The objective (less is better).
    conditioning : (N, 2) array
        As :attr:`Scores.conditioning`.

    Returns
    -------
    (N,) array

    Examples
    --------
    >>> tie_broken(np.array([2.0, 2.0, 2.0000001]), np.array([[np.nan, 0.001], [0.6, 0.5], [np.nan, 0.9]])).round(8).tolist()
    [2.000002, 2.000001, 2.0000003]
    """
    c = np.nanmin(np.asarray(conditioning, float), axis=1, initial=np.inf)
    c = np.where(np.isfinite(c), c, 1.0)  # no decomposition asked: no tie to break
    return value + TIE_TOL * np.abs(value) * (1.0 - c)


def objective_values(points, normals, total, mu, objective, tol=DEGENERACY_TOL, torsion=None):
    """The objective of feasible rows (less is better): ``(N, 3, 3), (N, 3, 3), (N, W)`` -> ``(N,)``."""
    if objective in ("robust", "total_normal_force"):
        return total.max(axis=1, initial=-np.inf)
    c = force_closure(points, normals, mu, torsion=torsion, quality=objective == "epsilon", tol=tol)
    return -c.epsilon if objective == "epsilon" else c.closure_friction
