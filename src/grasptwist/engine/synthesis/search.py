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

The problem (:mod:`~.problem`: the object's surface, the wrenches, the hand, the environment, the
options and the budget) is built once, by :func:`~.problem.synthesis_problem` for every front door;
this module is the loop that runs it (:func:`solve`).  Verification is :mod:`~.verify`'s, the
reason for finding nothing :mod:`~.diagnosis`'s, the grasps kept apart :mod:`~.archive`'s.

The budget (:mod:`~.budget`) holds: the search stops after ``candidates`` scored rows or
``(1 - VERIFY_SHARE) seconds``, whichever comes first, checked after every chunk; the rest of
``seconds`` is selection's and verification's, which stops at the deadline (checked before each
grasp): the grasps verified by then are returned, the others counted as ``unverified``.  The
clock starts after the one-time warm-up (numba's compiling of the grip on a fresh install), and
the result says which limit ended it (``stopped_by``).  With the same ``seed`` and a search that
the candidates ended (``stopped_by == "candidates"``) two runs return the same grasps bit for bit.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np

from ..forces import compiled
from ..hooks import first_load
from .archive import Archive
from .budget import Spending
from .candidates import candidate_triples, tangent_steps
from .diagnosis import Failure, diagnose, unverified
from .problem import GRAVITY, Problem, Surface, surface_problem, synthesis_problem
from .robustness import margins, robustness
from .scores import score_triples
from .verify import verify

__all__ = [
    "Synthesis",
    "search",
    "search_steps",
    "solve",
    "solve_steps",
    "synthesize",
    "warm_up",
    "CHUNK",
    "REFINE_SHARE",
    "VERIFY_SHARE",
]

#: Candidates scored together (the grip's batches stay in cache; the budget is checked after each).
CHUNK = 2048

#: The share of the candidate budget spent refining the best grasps found by sampling.
REFINE_SHARE = 0.3

#: Grasps refined at once, and perturbations of each per round.
ELITES, CHILDREN = 16, 16

#: The share of ``seconds`` kept for selecting and verifying the grasps found (the search stops before it).
VERIFY_SHARE = 0.2


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
        None: :data:`~.problem.MIN_SPACING` times the object's size.
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
    solve : the search of a :class:`~.problem.Problem`.

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
    return solve(surface_problem(surface, wrenches, friction, **options))


def search_steps(surface: Surface, wrenches, friction, **options) -> Iterator:
    """:func:`search`, one step at a time: yields the candidates of each chunk scored (ints), then the
    :class:`Synthesis` (a progress bar's way through a long search)."""
    return solve_steps(surface_problem(surface, wrenches, friction, **options))


def solve(problem: Problem) -> Synthesis:
    """The grasps of a :class:`~.problem.Problem` (module docstring): the search's loop, and nothing
    else (every option was checked when the problem was built)."""
    *_, found = solve_steps(problem)
    return found


def solve_steps(problem: Problem) -> Iterator:
    """:func:`solve`, one step at a time: yields the candidates of each chunk scored (ints), then the
    :class:`Synthesis`."""
    surface, w, mu, hand, count = problem.surface, problem.wrenches, problem.friction, problem.hand, problem.count
    safety, objective, tol, torsion = problem.safety, problem.objective, problem.tol, problem.torsion
    warm_up()  # before the clock starts: a first run's compiling is no part of its budget
    budget = Spending(problem.budget, 1 - VERIFY_SHARE)
    budget_size = problem.budget.candidates
    rng = np.random.default_rng(problem.seed)
    joints = None if hand is None else len(hand.hand.joint_names)
    archive = Archive(max(ELITES, 4 * count), problem.spacing, joints, tol, torsion)
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
            wrist=problem.wrist,
            methods=problem.methods,
            min_conditioning=problem.min_conditioning,
            constraints=problem.constraints,
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
    perturbation = problem.perturbation
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
    quality = problem.quality or objective == "epsilon"
    out = verify(
        surface,
        points,
        normals,
        w,
        mu,
        safety,
        problem.wrist,
        problem.methods,
        quality,
        tol,
        hand,
        positions,
        budget,
        torsion,
    )
    held = margins(
        surface, out["points"], out["normals"], w, mu, safety=safety, torsion=torsion, tol=tol, **perturbation
    )
    out.update(held._asdict())
    failure = None
    if not len(out["points"]) and out["unverified"]:
        failure = unverified(out["unverified"])
    elif not len(out["points"]):
        failure = diagnose(archive, budget.used, mu / safety, problem.min_conditioning, tol, problem.constraints)
    yield Synthesis(
        **out,
        candidates=budget.used,
        seconds=budget.seconds(),
        seed=problem.seed,
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
    weight=None,
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
        As ``grasptwist.engine.synthesis.problem.hand_reach``: each finger's tip link pose at home (needed for a finger
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
    weight : Weight, optional
        The weight held when ``obj`` has no mass (a grasp file's ``mass`` apart from its object).
    span_bodies : bool
        Let a grasp's contacts lie on different bodies of the object (a mesh's pieces apart);
        by default each grasp keeps to one (``grasptwist.engine.synthesis.problem.surface_of``).
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
    problem = synthesis_problem(
        obj,
        friction,
        wrenches=wrenches,
        hold=hold,
        gravity=gravity,
        weight=weight,
        hand=hand,
        tips=tips,
        tip_radius=tip_radius,
        collide=collide,
        hulls=hulls,
        environment=environment,
        clearance=clearance,
        span_bodies=span_bodies,
        **options,
    )
    return solve(problem)


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
    (its batches and its verification's single rows), or loads them from numba's cache, and the compiled
    interior-point iterations of soft contacts' cones (``compiled.iteration``); once a
    process, and nothing on the numpy path.

    >>> warm_up()
    """
    if _WARM:
        return
    with first_load():  # one watch (the command line's one notice) for both
        if compiled.kernel() is None:  # the numpy path: nothing to compile
            return
        compiled.iteration()  # soft contacts' cones, and any row the grip's kernel leaves to socp
    _WARM.append(True)  # before the search below, which warms up too
    search(Surface(_ball_sample, _ball_project, 2 * 3**0.5), [[0, 0, 1.0, 0, 0, 0]], 0.5, candidates=200)
