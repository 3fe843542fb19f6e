r"""The search: candidate triples scored in chunks, the best refined on the surface, each returned grasp verified.

1. **Sampling.**  Chunks of candidates (:func:`~.candidates.candidate_triples` over fresh
   area-weighted samples of the surface) are scored by :func:`~.scores.score_triples`;
   an archive keeps the best feasible ones.
2. **Refinement.**  The archive's best grasps are perturbed in their tangent planes,
   put back on the surface and re-scored (a contact put on an edge or corner, where
   the normal is not defined, is not); an improvement replaces its parent, a round
   without one halves that grasp's step.
   Without a feasible grasp to refine, the budget goes on sampling.
3. **Selection.**  The best grasps in order, each at least ``min_spacing`` from those
   before it (:func:`~.candidates.triple_distance`).  With the objective ``robust`` (the
   default) the finalists (the archive) are first ranked by their robustness, most robust first,
   then by their least total normal force (:mod:`~.robustness`, batched over the finalists).
4. **Verification.**  Each is solved again, one row at a time, by the exact grip
   (:func:`~grasptwist.engine.forces.grip.grip`), whose certificate (``dual`` with a zero
   ``gap``, ``n_i - G_i^T dual`` in every dual cone) proves the total optimal; one that
   fails is not returned.  The grasps returned get their margins (:func:`~.robustness.margins`).

The budget (:mod:`~.budget`) holds: the search stops after ``candidates`` scored rows or
``(1 - VERIFY_SHARE) seconds``, whichever comes first, checked after every chunk; the rest of
``seconds`` is selection's and verification's, which stops at the deadline (checked before each
grasp): the grasps verified by then are returned, the others counted as ``unverified``.  The
clock starts after the one-time warm-up (numba's compiling of the grip on a fresh install), and
the result says which limit ended it (``stopped_by``).  With the same ``seed`` and a search that
the candidates ended (``stopped_by == "candidates"``) two runs return the same grasps bit for bit.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from functools import partial
from typing import NamedTuple

import numpy as np

from ..collision import collision_tolerance
from ..degeneracy import DEGENERACY_TOL
from ..environment import clearance_of
from ..fingertips import tip_centers, tip_radii
from ..forces import compiled
from ..forces.closure import force_closure
from ..forces.grasp_map import check_safety
from ..forces.grip import Grip, grip
from ..forces.hold import object_weight
from ..ik import home_tips, joint_limits
from ..objects import object_size, project_to_surface, sample_surface
from ..objects.creases import edge_distance
from ..objects.geometry import body_areas, body_of
from .archive import Archive
from .budget import Budget, Spending, check_budget
from .candidates import candidate_triples, tangent_steps
from .checks import (
    check_count,
    check_min_spacing,
    check_search_friction,
    check_search_torsion,
    check_seed,
    check_tip_radius,
    check_wrenches,
)
from .clearance import environment_search
from .reach import HandReach, check_hand_reach, reach_tolerance, tip_errors, violations
from .robustness import (
    FRICTION_ERROR,
    PERTURBATIONS,
    check_friction_error,
    check_perturbations,
    check_position_error,
    default_position_error,
    margins,
    robustness,
)
from .scores import (
    CONSTRAINTS,
    METHODS,
    MIN_CONDITIONING,
    check_min_conditioning,
    check_objective,
    conditionings,
    score_triples,
)

__all__ = [
    "Surface",
    "Failure",
    "Synthesis",
    "Budget",
    "search",
    "search_steps",
    "synthesize",
    "surface_of",
    "hand_reach",
    "GRAVITY",
    "verified",
    "warm_up",
    "check_budget",
    "CHUNK",
    "MIN_SPACING",
    "REFINE_SHARE",
    "GAP_TOL",
    "FEW_CANDIDATES",
    "VERIFY_SHARE",
]

#: Gravity when none is given: 9.81 down the z axis (as grasp files').
GRAVITY = (0.0, 0.0, -9.81)

#: Candidates scored together (the grip's batches stay in cache; the budget is checked after each).
CHUNK = 2048

#: The default ``min_spacing``, relative to the object's size.
MIN_SPACING = 0.05

#: The share of the candidate budget spent refining the best grasps found by sampling.
REFINE_SHARE = 0.3

#: Grasps refined at once, and perturbations of each per round.
ELITES, CHILDREN = 16, 16

#: The share of ``seconds`` kept for selecting and verifying the grasps found (the search stops before it).
VERIFY_SHARE = 0.2

#: A verified grip's duality gap must be within this of its total (relative).
GAP_TOL = 1e-6

#: Fewer candidates than this, every one degenerate, say nothing of the object: the budget is the reason
#: (a chunk of ``k`` candidates draws its contacts from ``k`` surface points, all alike when ``k < 3``).
FEW_CANDIDATES = 100


class Surface(NamedTuple):
    """An object's surface as the search needs it (in the grasp frame).

    Attributes
    ----------
    sample : callable
        ``sample(n, rng) -> (points (n, 3), normals (n, 3))``: area-weighted points and unit
        inward normals, reproducible for a ``numpy.random.Generator``.
    project : callable
        ``project(points (..., 3)) -> (points, normals, distance, on_edge)``: the nearest surface
        points, their unit inward normals, the signed distance and whether each is on an edge or
        corner (where the surface has no one normal).
    size : float
        The object's size (the diagonal of its bounding box): the scale of steps and spacing.
    body : callable, optional
        ``body(points (..., 3)) -> (...)`` int: the body of the object each surface point is on,
        when a grasp keeps to one (``sample`` then draws each call's points from one body); None:
        contacts anywhere.
    edges : callable or None
        ``edges(points (..., 3)) -> (...)``: each point's distance to the nearest crease
        (:func:`~grasptwist.engine.objects.creases.edge_distance`); None: a smooth surface.
    """

    sample: Callable
    project: Callable
    size: float
    body: Callable | None = None
    edges: Callable | None = None


class Failure(NamedTuple):
    """Why a search found no feasible grasp.

    Attributes
    ----------
    constraint : str
        The tightest constraint (:data:`~.scores.CONSTRAINTS`): the furthest any candidate got;
        ``budget`` when fewer than :data:`FEW_CANDIDATES` were scored, all degenerate (``best``:
        how many); ``verification`` when candidates passed every test but none was verified.
    message : str
        In words, with how close the best candidate came.
    best, needed : float
        That constraint's best value among the candidates and the value it needed
        (NaN where it has no number: the grip).
    """

    constraint: str
    message: str
    best: float
    needed: float


@dataclass(frozen=True, eq=False)
class Synthesis:
    """The grasps a search returns, best first, and what the search did.

    Attributes
    ----------
    points, normals : (K, 3, 3)
        Each grasp's contacts and unit inward normals.
    surface_distance : (K, 3)
        Each contact's distance from the surface (round-off: they are put on it).
    total_normal_force : (K, W)
        Each wrench's least total normal force, from the verified grip.
    closure_friction : (K,)
    epsilon : (K,) or None
        Ferrari-Canny's epsilon at ``mu / safety`` (asked for, or the objective).
    conditioning : (K, 2)
        Of the off-tangent and the tangent decomposition (NaN where not asked, or without a wrist).
    grips : tuple of tuple of Grip
        The verified grip of each grasp and wrench (one row each).
    joint_positions : (K, n_joints) or None
        With a hand: where it holds each grasp, finger ``f`` on contact ``f``.
    reach_error : (K, 3) or None
        With a hand: each finger's distance from its tip point, by forward kinematics at
        ``joint_positions``, to its fingertip's centre ``p - r n`` (within the inverse
        kinematics' tolerance).
    tip_center : (K, 3, 3) or None
        With a hand: each fingertip sphere's centre ``p - r n`` (finger ``f`` on contact ``f``).
    hold_friction, edge_distance, robustness : (K,), (K, 3), (K,)
        Each grasp's margins (``grasptwist.engine.synthesis.robustness``): the least friction
        at which every wrench is still held, each contact's distance to the nearest crease, and
        the share of the perturbations under which it is still held.
    unverified : int
        Grasps selected but not verified, so not returned: ``seconds`` ran out before their turn.
    stopped_by : str
        What ended the search (``budget.STOPPED_BY``): ``candidates``, every candidate
        scored and every grasp selected verified (reproducible bit for bit from ``seed``), or
        ``seconds``, the time ran out first (the search's share, or verification's).
    candidates : int
        Candidates scored.
    seconds : float
    seed : int
    failure : Failure or None
        Why nothing was found (``K = 0``): ``constraint`` (the tightest: ``degenerate``,
        ``conditioning``, ``force_closure``, ``clearance`` (the environment's), ``constraints``, ``grip``, with a hand ``fingertips``,
        ``reach`` or ``collision``; or ``budget``, ``verification``: ``Failure``), ``message``,
        ``best`` and ``needed``.
    """

    points: np.ndarray
    normals: np.ndarray
    surface_distance: np.ndarray
    total_normal_force: np.ndarray
    closure_friction: np.ndarray
    epsilon: np.ndarray | None
    conditioning: np.ndarray
    grips: tuple
    candidates: int
    seconds: float
    seed: int
    failure: Failure | None
    joint_positions: np.ndarray | None = None
    reach_error: np.ndarray | None = None
    tip_center: np.ndarray | None = None
    unverified: int = 0
    hold_friction: np.ndarray | None = None
    edge_distance: np.ndarray | None = None
    robustness: np.ndarray | None = None
    stopped_by: str = "candidates"


def search(surface: Surface, wrenches, friction, **options) -> Synthesis:
    r"""Search ``surface`` for ``count`` three-finger grasps that exert ``wrenches`` with the least grip.

    Parameters
    ----------
    surface : Surface
    wrenches : (W, 6) array
        Wrenches the fingers must exert, ``(force; moment about the origin)`` (to hold a weight:
        :func:`~grasptwist.engine.forces.hold.hold_wrench`).
    friction : float
        ``mu`` at every contact; the forces keep within ``mu / safety``, and closure is
        required at ``mu / safety``.
    **options
        Keyword-only:
    count : int, default 1
        The grasps wanted (fewer when fewer distinct feasible ones are found).
    safety : float, default 1
        ``>= 1``.
    objective : str, default ``robust``
        ``robust`` (the finalists most robust first, then by ``total_normal_force``: module
        docstring), ``total_normal_force`` (the largest over the wrenches of the least total
        normal force), ``closure_friction`` (the least common friction of closure), or
        ``epsilon`` (Ferrari-Canny's, maximised); less is better for the middle two.
    wrist : (3,) array or None, default None
        With a wrist the off-tangent decomposition's conditioning counts too.
    methods : tuple of str, default both
        Decompositions that must stay non-degenerate (:data:`~.scores.METHODS`).
    min_conditioning : float, default :data:`~.scores.MIN_CONDITIONING` (0.05)
        Their conditioning must be at least this (0 to 1).
    min_spacing : float or None, default None
        Returned grasps are at least this far apart (:func:`~.candidates.triple_distance`);
        None: :data:`MIN_SPACING` times the object's size.
    constraints : sequence of callables, default none
        Further constraints (a table, a region), each ``(points (n, 3, 3), normals (n, 3, 3))
        -> (n,) bool``, tested after closure and before the grip.
    hand : HandReach or None, default None
        A hand that must reach each grasp (:mod:`~.reach`: fingertips on the surface, every
        contact within the joint limits, no finger link in the object), tested after the grip;
        the grasps returned then list contact ``f`` for finger ``f``, with the joint positions.
    quality : bool, default False
        Compute ``epsilon`` for the returned grasps (scipy) even when it is not the objective.
    seed : int, default 0
        Seeds the random numbers.
    candidates : int, default 20000
        Candidates scored at most (sampling and refinement together).
    seconds : float or None, default None
        Time allowed: the search stops after the chunk of :data:`CHUNK` candidates that passes
        ``(1 - VERIFY_SHARE) seconds``, verification before the first grasp after ``seconds``.
        The clock starts after :func:`~.budget.warm_up` (a fresh install's compiling).
    clock : callable, default ``time.perf_counter``
        What ``seconds`` are read on (:class:`~.budget.Budget`; a test gives a fake one).
    tol : float, default ``DEGENERACY_TOL``
        The degeneracy tolerance of the contacts (``DEGENERACY_TOL``).
    position_error : float or None, default None
        How far each perturbation of the robustness moves a contact at most
        (:mod:`~.robustness`); None: half the smallest fingertip radius with a hand whose tips
        have one, else 2% of the object's size.
    friction_error : float, default 0.2
        The largest share of ``friction`` a perturbation takes away.
    perturbations : int, default 64
        Perturbations per grasp (seeded by ``seed``).
    torsion : float or None, default None
        Soft-finger contacts' torsional radius ``e > 0`` at every contact (a length, in the surface's
        units; ``friction > 0``): closure, the grips, the hold friction, the robustness, the closure
        friction and epsilon over the soft cones (:mod:`~grasptwist.engine.forces.cones`); None: point contacts.

    Returns
    -------
    Synthesis

    See Also
    --------
    search_steps : the same search, telling its progress.

    Examples
    --------
    A unit ball (inward normals ``-p``) held against 1 N of weight with ``mu = 0.5``: no grasp
    needs less than ``1 / sqrt(1 + mu^2) = 0.894`` (a contact lifts at most ``sqrt(1 + mu^2)``
    per newton of normal force), far below the equator's ``1 / mu = 2``:

    >>> def sample(n, rng):
    ...     p = rng.normal(size=(n, 3))
    ...     p /= np.linalg.norm(p, axis=1, keepdims=True)
    ...     return p, -p
    >>> def project(q):
    ...     r = np.linalg.norm(q, axis=-1, keepdims=True)
    ...     return q / r, -q / r, r[..., 0] - 1, np.zeros(q.shape[:-1], dtype=bool)
    >>> s = search(Surface(sample, project, 2 * 3**0.5), [[0, 0, 1.0, 0, 0, 0]], 0.5, candidates=1000)
    >>> bool(0.894 < s.total_normal_force[0, 0] < 1.0), s.failure
    (True, None)
    """
    *_, found = search_steps(surface, wrenches, friction, **options)
    return found


def search_steps(
    surface: Surface,
    wrenches,
    friction,
    *,
    count=1,
    safety=1.0,
    objective="robust",
    wrist=None,
    methods=METHODS,
    min_conditioning=MIN_CONDITIONING,
    min_spacing=None,
    constraints=(),
    hand=None,
    quality=False,
    seed=0,
    candidates=20000,
    seconds=None,
    clock=time.perf_counter,
    tol=DEGENERACY_TOL,
    position_error=None,
    friction_error=FRICTION_ERROR,
    perturbations=PERTURBATIONS,
    torsion=None,
) -> Iterator:
    """:func:`search`, one step at a time: yields the candidates of each chunk scored (ints), then the
    :class:`Synthesis` (a progress bar's way through a long search)."""
    w = check_wrenches(wrenches)
    mu = check_search_friction(friction)
    torsion = check_search_torsion(torsion, mu)
    count = check_count(count)
    safety = check_safety(safety)
    objective = check_objective(objective)
    min_conditioning = check_min_conditioning(min_conditioning)
    seed = check_seed(seed)
    setting = Budget(candidates, seconds, clock)
    min_spacing = check_min_spacing(min_spacing)
    spacing = MIN_SPACING * surface.size if min_spacing is None else min_spacing
    hand = None if hand is None else check_hand_reach(hand)
    position_error = check_position_error(position_error)
    if position_error is None:
        position_error = default_position_error(surface.size, None if hand is None else hand.radii)
    perturbation = {
        "position_error": position_error,
        "friction_error": check_friction_error(friction_error),
        "perturbations": check_perturbations(perturbations),
        "seed": seed,
    }
    warm_up()  # before the clock starts: a first run's compiling is no part of its budget
    budget = Spending(setting, 1 - VERIFY_SHARE)
    budget_size = setting.candidates
    rng = np.random.default_rng(seed)
    joints = None if hand is None else len(hand.hand.joint_names)
    archive = Archive(max(ELITES, 4 * count), spacing, joints, tol, torsion)
    # closure friction, epsilon: slower rows; a hand: the archive fills (and spares rows the hand's test) sooner
    chunk = CHUNK if objective in ("robust", "total_normal_force") and hand is None else CHUNK // 8

    def score(p, n, bound=None):
        return score_triples(
            p,
            n,
            w,
            mu,
            safety=safety,
            objective=objective,
            wrist=wrist,
            methods=methods,
            min_conditioning=min_conditioning,
            constraints=constraints,
            hand=hand,
            bound=archive.bound if bound is None else bound,
            torsion=torsion,
            tol=tol,
        )

    # sampling, then refining; with nothing to refine, sampling all the way
    for until in (budget_size - int(REFINE_SHARE * budget_size), budget_size):
        while (k := budget.take(min(chunk, until - budget.used))) > 0:
            pool_p, pool_n = surface.sample(k, rng)
            t = candidate_triples(pool_p, pool_n, k, rng)
            p, n = pool_p[t], pool_n[t]
            archive.add(p, n, score(p, n))
            budget.spent(k)
            yield k
        yield from _refine(surface, archive, score, budget, rng)
    rank = np.arange(len(archive.objective))
    if objective == "robust" and rank.size:  # the finalists, most robust first, then the least total
        robust = robustness(
            surface, archive.points, archive.normals, w, mu, safety=safety, torsion=torsion, tol=tol, **perturbation
        )
        rank = np.lexsort((archive.objective, -robust))
    # the archive's grasps are spacing apart already: the first count in rank are the selection
    picked = rank[:count]
    points, normals = archive.points[picked], archive.normals[picked]
    positions = None if hand is None else archive.positions[picked]
    quality = quality or objective == "epsilon"
    out = _results(
        surface, points, normals, w, mu, safety, wrist, methods, quality, tol, hand, positions, budget, torsion
    )
    held = margins(
        surface, out["points"], out["normals"], w, mu, safety=safety, torsion=torsion, tol=tol, **perturbation
    )
    out.update(held._asdict())
    failure = None
    if not len(out["points"]) and out["unverified"]:
        failure = Failure(
            "verification",
            f"the time ran out before a grasp found was verified ({out['unverified']} not verified: allow more seconds)",
            np.nan,
            np.nan,
        )
    elif not len(out["points"]):
        failure = _failure(archive, budget.used, mu / safety, min_conditioning, tol, constraints)
    yield Synthesis(
        **out,
        candidates=budget.used,
        seconds=budget.seconds(),
        seed=seed,
        failure=failure,
        stopped_by=budget.stopped_by,
    )


def _refine(surface, archive, score, budget, rng):
    """Hill-climb the archive's best on the surface (module docstring, 2.) while the budget lasts;
    yields the candidates of each round."""
    elites = min(ELITES, len(archive.objective))
    if not elites:
        return
    p, n, best = archive.points[:elites].copy(), archive.normals[:elites].copy(), archive.objective[:elites].copy()
    step = np.full(elites, 0.05 * surface.size)
    while (children := budget.take(elites * CHILDREN) // elites) > 0:  # the last round may be smaller
        k = elites * children
        parent = np.repeat(np.arange(elites), children)
        moved = rng.random((k, 3)) < 2 / 3
        moved[np.arange(k), rng.integers(0, 3, k)] = True  # at least one contact moves
        q = p[parent] + tangent_steps(n[parent], step[parent, None] * moved, rng)
        q, m, _, on_edge = surface.project(q)
        # a point put on an edge or corner has no one normal (a mesh's there is an average: kept, it games the grip)
        defined = ~on_edge.any(axis=1)
        if surface.body is not None:  # a child whose contacts moved onto different bodies is dropped
            b = surface.body(q)
            defined &= (b == b[:, :1]).all(axis=1)
        value = np.full(k, np.inf)
        if defined.any():
            # a child better than its parent is never spared the hand's test, kept or not
            s = score(q[defined], m[defined], max(archive.bound, float(best.max())))
            archive.add(q[defined], m[defined], s)
            value[defined] = s.objective
        budget.spent(k)
        yield k
        value = value.reshape(elites, children)
        child = np.argmin(value, axis=1)
        better = value[np.arange(elites), child] < best
        rows = np.arange(elites)[better] * children + child[better]
        p[better], n[better], best[better] = q[rows], m[rows], value[better, child[better]]
        step = np.where(better, step, step / 2)


def verified(points, normals, wrench, friction, safety, tol=DEGENERACY_TOL, torsion=None) -> Grip | None:
    r"""The exact grip of one grasp and wrench when its certificate proves it optimal, else None.

    One row through :func:`~grasptwist.engine.forces.grip.grip`; its ``dual`` must close the gap
    (``|total - w . dual| <= GAP_TOL max(total, 1)``) and be dual feasible:
    ``n_i - G_i^T dual`` (``G_i^T dual = dual_F + dual_M x p_i``) in each dual cone
    ``(mu / s) |z_t| <= z_n``, to :data:`GAP_TOL`; with ``mu = inf`` (the half-space
    ``f . n >= 0``, no limit) the dual cone is the ray along ``n``: ``|z_t| = 0 <= z_n``.  With ``torsion``
    (soft contacts' radius ``e``) the grip is over the soft cones and ``|z_t|`` is ``|(z_t, e z_tau)|``,
    ``z_tau = -n_i . dual_M``.

    >>> p = np.array([[1.0, 0, 0], [-0.5, 0.75**0.5, -0.2], [-0.5, -(0.75**0.5), -0.2]])
    >>> g = verified(p, -p / np.linalg.norm(p, axis=1, keepdims=True), [0, 0, 1.0, 0, 0, 0], 0.5, 1.0)
    >>> g is not None and bool(g.ok)
    True
    >>> g = verified(p, -p / np.linalg.norm(p, axis=1, keepdims=True), [0, 0, 1.0, 0, 0, 0], np.inf, 1.0)
    >>> g is not None and bool(g.total_normal_force < 1e-6)  # tangential forces alone hold it
    True
    """
    g = grip(points, normals, wrench, friction, safety=safety, torsion=torsion, tol=tol)
    if not g.ok:
        return None
    total = float(g.total_normal_force)
    if not abs(float(g.gap)) <= GAP_TOL * max(total, 1.0):
        return None
    n = np.asarray(normals, float)
    n = n / np.linalg.norm(n, axis=-1, keepdims=True)
    z = n - (g.dual[:3] + np.cross(g.dual[3:], np.asarray(points, float)))
    zn = np.sum(z * n, axis=-1)
    zt = np.linalg.norm(z - zn[:, None] * n, axis=-1)
    if torsion is not None:  # the soft cones' dual: the torsion's multiplier beside the tangential ones
        zt = np.hypot(zt, torsion * np.sum(n * g.dual[3:], axis=-1))
    limit = friction / safety
    # no limit: (mu / s) |z_t| is inf * 0 on the ray, so ask for the ray itself
    inside = (zt <= GAP_TOL) & (zn >= -GAP_TOL) if np.isinf(limit) else limit * zt - zn <= GAP_TOL
    return g if inside.all() else None


def _results(
    surface,
    points,
    normals,
    w,
    mu,
    safety,
    wrist,
    methods,
    quality,
    tol,
    hand=None,
    positions=None,
    budget=None,
    torsion=None,
):
    """The returned grasps' fields of :class:`Synthesis`, each grasp verified (the others dropped): the
    exact grip, and with a hand its tips by forward kinematics, its limits and its links clear; those
    whose turn comes after the ``budget``'s deadline (:meth:`~.budget.Spending.late`) are not verified,
    only counted.  Epsilon (``quality``: a convex hull a grasp, milliseconds each) is computed at each
    grasp's turn, within the deadline."""
    grips, keep, epsilon, unverified = [], [], [], 0
    for i in range(len(points)):
        if budget is not None and budget.late():
            unverified = len(points) - i
            break
        found = tuple(verified(points[i], normals[i], wrench, mu, safety, tol, torsion) for wrench in w)
        if all(g is not None for g in found):
            grips.append(found)
            keep.append(i)
            if quality:
                c = force_closure(points[i], normals[i], mu / safety, torsion=torsion, quality=True, tol=tol)
                epsilon.append(float(c.epsilon))
    hand_fields = {}
    if hand is not None:
        error = tip_errors(hand, points[keep], normals[keep], positions[keep])
        good = _held(hand, error, positions[keep])
        grips, keep = [g for g, k in zip(grips, good) if k], [i for i, k in zip(keep, good) if k]
        epsilon = [e for e, k in zip(epsilon, good) if k]
        hand_fields = {
            "joint_positions": positions[keep],
            "reach_error": error[good],
            "tip_center": tip_centers(points[keep], normals[keep], hand.radii),
        }
    p, n = points[keep], normals[keep]
    closure = force_closure(p, n, mu / safety, torsion=torsion, tol=tol) if len(p) else None
    return {
        "points": p,
        "normals": n,
        "surface_distance": surface.project(p)[2] if len(p) else np.empty((0, 3)),
        "total_normal_force": np.array([[float(g.total_normal_force) for g in row] for row in grips]).reshape(
            len(p), len(w)
        ),
        "closure_friction": closure.closure_friction if closure else np.empty(0),
        "epsilon": np.array(epsilon) if quality else None,
        "conditioning": conditionings(p, n, wrist, methods, tol) if len(p) else np.empty((0, 2)),
        "grips": tuple(grips),
        "unverified": unverified,
        **hand_fields,
    }


def _held(hand, error, positions):
    """Which placed hands are verified: every tip on its target (:func:`~.reach.reach_tolerance`), every
    joint within its limits, no collision (:func:`~.reach.violations`: ``(K, 3)``, ``(K, n_joints)`` -> ``(K,)``)."""
    good = (error <= reach_tolerance(hand)).all(axis=1)
    for finger in hand.hand.fingers:
        lower, upper = joint_limits(finger)
        q = positions[:, list(finger.joint_index)]
        good &= ((q >= lower) & (q <= upper)).all(axis=1)
    return good & (violations(hand, positions) <= 0)


def _failure(archive, scored, mu, min_conditioning, tol, constraints=()) -> Failure:
    """Why no candidate was feasible: the furthest constraint any reached, and how close the best came
    (a hand's constraints are reached only with a hand: after the grip a row without one is feasible)."""
    if archive.furthest == 0 and scored < FEW_CANDIDATES:
        return Failure(
            "budget",
            f"{scored} scored {'is' if scored == 1 else 'are'} too few to judge the object, none with three "
            f"distinct contacts off one line (allow {FEW_CANDIDATES} candidates or more)",
            float(scored),
            float(FEW_CANDIDATES),
        )
    if archive.furthest >= len(CONSTRAINTS):  # feasible, or spared as no better than the grasps kept
        return Failure(
            "verification",
            "candidates passed every test, but the exact grip's certificate (or the hand's forward "
            "kinematics) verified none",
            np.nan,
            np.nan,
        )
    name = CONSTRAINTS[archive.furthest]
    if name == "degenerate":
        return Failure(name, "every candidate's contacts were degenerate (coincident or collinear)", 0.0, tol)
    if name == "conditioning":
        best = archive.best_conditioning
        return Failure(
            name,
            f"no candidate's conditioning reached {min_conditioning:g} (the best: {best:.3g})",
            best,
            min_conditioning,
        )
    if name == "force_closure":
        best = archive.closest  # inf: no candidate is closure at any finite friction (a flat object's)
        words = f"the best needs friction {best:.3g}" if np.isfinite(best) else "none is at any finite friction"
        return Failure(name, f"no candidate is force closure at friction {mu:g} (friction / safety); {words}", best, mu)
    if name == "constraints":
        # a named constraint (the environment's clearance) that no candidate it saw passed is the one
        for c in constraints:
            if np.isfinite(getattr(c, "best", np.nan)) and c.best < c.needed:
                return Failure(
                    c.name,
                    f"no force-closure candidate keeps every fingertip (a contact, without a hand) {c.needed:g} "
                    f"from the environment (the best: {c.best:.3g})",
                    c.best,
                    c.needed,
                )
        return Failure(name, "no force-closure candidate passed the further constraints", np.nan, np.nan)
    if name == "fingertips":
        return Failure(
            name,
            "on every candidate some fingertip sphere would go into the object (concave there) or within the "
            "clearance of the environment",
            np.nan,
            np.nan,
        )
    if name == "reach":
        best = archive.best_miss.get(name, np.inf)
        return Failure(
            name,
            "the hand reaches no candidate's contacts within its joint limits"
            + (
                f": the best candidate leaves a fingertip {best:.3g} from where it must be" if np.isfinite(best) else ""
            ),
            best,
            0.0,
        )
    if name == "collision":
        best = archive.best_miss.get(name, np.inf)
        return Failure(
            name,
            "every grasp the hand reaches puts a finger link into the object or another finger, or within the "
            "clearance of the environment" + (f" (the least by {best:.3g})" if np.isfinite(best) else ""),
            best,
            np.nan,
        )
    return Failure(name, "no candidate's grip holds every wrench within the friction cones", np.nan, np.nan)


def surface_of(obj, span_bodies=False) -> Surface:
    """The :class:`Surface` of a :class:`~grasptwist.model.GraspObject` (``grasptwist.engine.objects``).

    An object of several bodies (a mesh's pieces apart) keeps each grasp on one body unless
    ``span_bodies``: each call of ``sample`` draws from one body, chosen by its area.
    """
    areas = body_areas(obj)
    edges = partial(edge_distance, obj)
    if span_bodies or len(areas) < 2:
        return Surface(partial(sample_surface, obj), partial(project_to_surface, obj), object_size(obj), edges=edges)

    def sample(n, rng):
        return sample_surface(obj, n, rng, body=int(rng.choice(len(areas), p=areas / areas.sum())))

    return Surface(sample, partial(project_to_surface, obj), object_size(obj), partial(body_of, obj), edges)


def hand_reach(
    obj, hand, *, tips=None, tip_radius=None, collide=None, hulls=None, environment=None, clearance=None
) -> HandReach:
    """A hand as the search takes it (:class:`~.reach.HandReach`) against ``obj``.

    Parameters
    ----------
    obj : GraspObject
    hand : Hand
        Three fingers that share no joint, in the grasp frame.
    tips : (3, 4, 4) array, optional
        Each finger's tip link pose at home; default its tip link's (a finger given inline has
        none: give where its tip point is at home, :func:`~grasptwist.engine.ik.home_tips`).
    tip_radius : float, optional
        Every fingertip's radius; default each finger's ``tip_radius``.
    collide : callable, optional
        ``collide(positions (N, n_joints)) -> (N,)`` the deepest any finger link goes into the
        object (the command line's, from a URDF's meshes); None: links not checked.
    hulls : LinkHulls, optional
        The finger links' convex hulls (``grasptwist.engine.collision.link_hulls``), kept out of each
        other and clear of the environment; None: the fingertip spheres alone.
    environment : Environment, optional
        The table and boxes every part of the hand keeps ``clearance`` from.
    clearance : float, optional
        Default the environment's (``grasptwist.engine.environment.clearance_of``).
    """
    tip_radius = check_tip_radius(tip_radius)
    radii = tip_radii(hand) if tip_radius is None else np.full(3, tip_radius)
    tips = home_tips(hand) if tips is None else np.asarray(tips, float)
    room = 0.0 if environment is None else (clearance_of(environment) if clearance is None else float(clearance))
    project = partial(project_to_surface, obj)
    reach = HandReach(hand, tips, radii, project, collision_tolerance(obj), collide, hulls, environment, room)
    return check_hand_reach(reach)


def synthesize(
    obj,
    friction,
    *,
    wrenches=(),
    hold=True,
    gravity=GRAVITY,
    hand=None,
    tips=None,
    tip_radius=None,
    collide=None,
    span_bodies=False,
    hulls=None,
    environment=None,
    clearance=None,
    **options,
) -> Synthesis:
    r"""Grasps of an object: its surface searched for grasps that hold its weight and ``wrenches``.

    The search (``grasptwist.engine.synthesis.search.search``; the guide's synthesis page) scores
    candidate triples in batches against the constraints (degeneracy and conditioning of the
    decompositions, force closure at ``friction / safety``, a grip for every wrench), refines the
    best on the surface and verifies each grasp it returns by the exact grip and its certificate.

    Parameters
    ----------
    obj : GraspObject
        With a ``mass`` or ``density`` when ``hold`` (the weight ``m g`` at its centre of mass).
    friction : float
        ``mu`` at every contact.
    wrenches : sequence of (6,) arrays
        More wrenches every grasp must exert, ``(force; moment about the origin)``.
    hold : bool
        Hold the object's weight: the wrench ``(-m g; -c x m g)`` comes first.
    gravity : (3,) array
    hand : Hand, optional
        A hand that must reach every grasp: fingertips on the surface, every contact within
        the joint limits, no finger link in the object; the grasps then list contact ``f`` for
        finger ``f`` (the fingers are assigned to the contacts in every order), and
        ``joint_positions`` and ``reach_error`` say where the hand holds each.
    tips, tip_radius, collide, hulls
        As ``grasptwist.engine.synthesis.search.hand_reach``: each finger's tip link pose at home (needed for a finger
        given inline), every fingertip's radius (default each finger's ``tip_radius``),
        the depth of the deepest link at joint positions and the links' convex hulls (default:
        links not checked, only the fingertip spheres; ``grasptwist.synthesize`` and the command
        line check a URDF's meshes).
    environment : Environment, optional
        A table and boxes (``grasptwist.model.Environment``): every contact's fingertip sphere
        (a point without a hand) and every part of the hand keep ``clearance`` from them; contacts
        that cannot are never sampled (``grasptwist.engine.synthesis.clearance``).
    clearance : float, optional
        Default the environment's, else ``grasptwist.engine.environment.CLEARANCE``.
    span_bodies : bool
        Let a grasp's contacts lie on different bodies of the object (a mesh's pieces apart);
        by default each grasp keeps to one (``grasptwist.engine.synthesis.search.surface_of``).
    **options
        The search's keyword options: ``count`` (grasps wanted, 1), ``safety`` (1), ``objective``
        (``robust``, ``total_normal_force``, ``closure_friction`` or ``epsilon``), ``wrist`` (None),
        ``methods``, ``min_conditioning`` (0.05), ``min_spacing`` (None: 5% of the object's size),
        ``quality`` (False), ``seed`` (0), ``candidates`` (20000), ``seconds`` (None),
        ``position_error`` (None: half a tip radius, or 2% of the object's size),
        ``friction_error`` (0.2), ``perturbations`` (64).

    Returns
    -------
    Synthesis

    Examples
    --------
    A 65 mm cube of 100 g, ``mu = 0.8``:

    >>> from grasptwist.objects import GraspObject, Shape
    >>> cube = GraspObject(Shape("box", np.full(3, 0.065)), np.eye(4), mass=0.1)
    >>> s = synthesize(cube, 0.8, count=2, candidates=1000)
    >>> s.points.shape, bool((s.closure_friction < 0.8).all())
    ((2, 3, 3), True)
    """
    tip_radius = check_tip_radius(tip_radius)  # checked with or without a hand, as --tip-radius is
    listed = list(check_wrenches(wrenches)) if len(wrenches) else []
    if hold:
        with np.errstate(over="ignore", invalid="ignore"):
            weight = object_weight(obj, gravity)
        if weight is None:
            raise ValueError("hold=True needs the object's mass (or density): its weight is the wrench to hold")
        if not np.isfinite(weight.wrench).all():
            raise ValueError("the object's weight or its moment about the origin overflows (mass x gravity)")
        listed.insert(0, weight.wrench)
    if not listed:
        raise ValueError("nothing to hold: give the object a mass (hold=True) or wrenches")
    if hand is not None and not isinstance(hand, HandReach):
        hand = hand_reach(
            obj,
            hand,
            tips=tips,
            tip_radius=tip_radius,
            collide=collide,
            hulls=hulls,
            environment=environment,
            clearance=clearance,
        )
    surface, clear = environment_search(surface_of(obj, span_bodies), environment, clearance, hand)
    options["constraints"] = (*options.get("constraints", ()), *clear)
    return search(surface, np.array(listed), friction, hand=hand, **options)


#: Whether this process has warmed up (:func:`warm_up` runs once).
_WARM = []


def _ball_sample(n, rng):
    """A unit ball's surface, area-weighted, with inward normals: :func:`warm_up`'s object."""
    p = rng.normal(size=(n, 3))
    p /= np.linalg.norm(p, axis=1, keepdims=True)
    return p, -p


def _ball_project(q):
    r = np.linalg.norm(q, axis=-1, keepdims=True)
    return q / r, -q / r, r[..., 0] - 1, np.zeros(q.shape[:-1], dtype=bool)


def warm_up():
    """The one-time work of a process's first search, done before any budget's clock starts: a small
    search of a ball, which compiles the grip's numba kernels for the very arrays a search gives them
    (its batches and its verification's single rows), or loads them from numba's cache; once a process,
    and nothing on the numpy path.

    >>> warm_up()
    """
    if _WARM or compiled.kernel() is None:  # done, or the numpy path: nothing to compile
        return
    _WARM.append(True)  # first: the search below warms up too
    search(Surface(_ball_sample, _ball_project, 2 * 3**0.5), [[0, 0, 1.0, 0, 0, 0]], 0.5, candidates=200)
