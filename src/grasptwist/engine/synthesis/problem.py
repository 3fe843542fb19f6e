r"""One synthesis problem: everything a search needs, built and checked in one place.

Every way into the search, the library's :func:`grasptwist.synthesize`, the command line's
``grasptwist synthesize`` and :func:`grasptwist.dask.synthesize_bag`, builds its
:class:`Problem` here: the object's surface (:func:`surface_of`; each grasp on one body unless
``span_bodies``), the wrenches to exert (the object's weight first, :func:`held_wrenches`),
the friction, the hand and where it is placed (:func:`hand_reach`; ``tip_radius`` replaces every
fingertip's radius once, :func:`with_tip_radius`), the environment and its clearance (contacts
that cannot keep it are never sampled, :func:`~.clearance.environment_search`), the objective and
the constraints, the budget (:class:`~.budget.Budget`) and the seed.  The search
(:func:`~.search.solve`) only runs it: two front doors that build the same problem get the same
grasps bit for bit.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from functools import partial
from typing import NamedTuple

import numpy as np

from ..collision import collision_tolerance
from ..degeneracy import DEGENERACY_TOL
from ..environment import clearance_of
from ..fingertips import tip_radii
from ..forces.grasp_map import check_safety
from ..forces.hold import Weight, object_weight
from ..hold_test import check_loads, direction_loads
from ..ik import home_tips
from ..objects import object_size, project_to_surface, sample_surface
from ..objects.creases import edge_distance
from ..objects.geometry import body_areas, body_of
from .budget import Budget
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
from .reach import HandReach, check_hand_reach
from .robustness import (
    FRICTION_ERROR,
    PERTURBATIONS,
    check_friction_error,
    check_perturbations,
    check_position_error,
    default_position_error,
)
from .scores import METHODS, MIN_CONDITIONING, check_min_conditioning, check_objective

__all__ = [
    "GRAVITY",
    "MIN_SPACING",
    "Surface",
    "Problem",
    "ProblemError",
    "NOTHING_TO_HOLD",
    "NO_WEIGHT",
    "WEIGHT_OVERFLOWS",
    "surface_problem",
    "synthesis_problem",
    "held_wrenches",
    "surface_of",
    "hand_reach",
    "with_tip_radius",
]

#: Gravity when none is given: 9.81 down the z axis (as grasp files').
GRAVITY = (0.0, 0.0, -9.81)

#: The default ``min_spacing``, relative to the object's size.
MIN_SPACING = 0.05

#: Why a problem cannot be built (:class:`ProblemError`'s ``code``): no wrench at all, ``hold``
#: without a mass, a weight (or its moment) beyond a double.
NOTHING_TO_HOLD, NO_WEIGHT, WEIGHT_OVERFLOWS = "nothing-to-hold", "no-weight", "non-finite"


class ProblemError(ValueError):
    """A problem no search can start from, with its ``code`` (:data:`NOTHING_TO_HOLD`,
    :data:`NO_WEIGHT`, :data:`WEIGHT_OVERFLOWS`); the command line words it as its own.

    >>> ProblemError(NOTHING_TO_HOLD, "nothing to hold").code
    'nothing-to-hold'
    """

    def __init__(self, code: str, message: str):
        super().__init__(message)
        self.code = code


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
    hand = with_tip_radius(hand, tip_radius)
    radii = tip_radii(hand)
    tips = home_tips(hand) if tips is None else np.asarray(tips, float)
    room = 0.0 if environment is None else (clearance_of(environment) if clearance is None else float(clearance))
    project = partial(project_to_surface, obj)
    reach = HandReach(hand, tips, radii, project, collision_tolerance(obj), collide, hulls, environment, room)
    return check_hand_reach(reach)


@dataclass(frozen=True, eq=False)
class Problem:
    """A synthesis problem, checked: what the search (:func:`~.search.solve`) runs, and nothing else.

    Attributes
    ----------
    surface : Surface
        The object's surface, without the contacts the environment leaves no room for.
    wrenches : (W, 6) array
        Wrenches every grasp must exert, ``(force; moment about the origin)``; the weight first when held.
    friction : float
        ``mu`` at every contact.
    budget : Budget
        Candidates, seconds and the clock they are read on.
    count, safety, objective, wrist, methods, min_conditioning, quality, seed, tol
        The search's options, checked (:func:`~.search.search`).
    spacing : float
        How far apart the grasps returned are at least (``min_spacing``, else :data:`MIN_SPACING`
        times the object's size).
    constraints : tuple of callables
        The caller's and the environment's (:class:`~.clearance.ClearTriples`).
    hand : HandReach or None
        The hand that must reach every grasp, placed on it by the search.
    perturbation : dict
        The robustness' ``position_error``, ``friction_error``, ``perturbations`` and ``seed``.
    object : GraspObject or None
        The object searched (None: a surface given as functions).
    weight : Weight or None
        The weight held (``wrenches[0]``).
    environment : Environment or None
    torsion : float or None
        Soft contacts' torsional radius at every contact (None: point contacts).
    """

    surface: Surface
    wrenches: np.ndarray
    friction: float
    budget: Budget
    count: int
    safety: float
    objective: str
    wrist: np.ndarray | None
    methods: tuple
    min_conditioning: float
    quality: bool
    seed: int
    tol: float
    spacing: float
    constraints: tuple
    hand: HandReach | None
    perturbation: dict
    object: object = None
    weight: Weight | None = None
    environment: object = None
    torsion: float | None = None


def surface_problem(
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
) -> Problem:
    """The :class:`Problem` of a surface given as functions, every option checked (their meaning:
    :func:`~.search.search`).

    >>> from grasptwist.engine.synthesis.search import _ball_project, _ball_sample
    >>> p = surface_problem(Surface(_ball_sample, _ball_project, 2.0), [[0, 0, 1.0, 0, 0, 0]], 0.5, candidates=500)
    >>> p.budget.candidates, p.spacing, p.objective
    (500, 0.1, 'robust')
    """
    seed = check_seed(seed)
    friction = check_search_friction(friction)
    min_spacing = check_min_spacing(min_spacing)
    hand = None if hand is None else check_hand_reach(hand)
    position_error = check_position_error(position_error)
    if position_error is None:
        position_error = default_position_error(surface.size, None if hand is None else hand.radii)
    return Problem(
        surface=surface,
        wrenches=check_wrenches(wrenches),
        friction=friction,
        budget=Budget(candidates, seconds, clock),
        count=check_count(count),
        safety=check_safety(safety),
        objective=check_objective(objective),
        wrist=wrist,
        methods=methods,
        min_conditioning=check_min_conditioning(min_conditioning),
        quality=quality,
        seed=seed,
        tol=tol,
        spacing=MIN_SPACING * surface.size if min_spacing is None else min_spacing,
        constraints=tuple(constraints),
        hand=hand,
        perturbation={
            "position_error": position_error,
            "friction_error": check_friction_error(friction_error),
            "perturbations": check_perturbations(perturbations),
            "seed": seed,
        },
        torsion=check_search_torsion(torsion, friction),
    )


def held_wrenches(
    obj, wrenches=(), *, hold=True, gravity=GRAVITY, weight=None, loads="weight"
) -> tuple[np.ndarray, Weight | None]:
    r"""The wrenches a grasp of ``obj`` must exert, ``(W, 6)``, its weight first when ``hold``, and that weight.

    The weight is ``obj``'s (:func:`~grasptwist.engine.forces.hold.object_weight`: ``(-m g; -c x m g)``),
    else ``weight`` (a grasp file's ``mass`` and ``center_of_mass`` apart from its object).  With
    ``loads="six"`` the hold test's loads follow ``wrenches`` when a weight is held: the weight's size
    along ``+-x, +-y, +-z`` at its centre (:func:`~grasptwist.engine.hold_test.direction_loads`).

    Raises
    ------
    ProblemError
        ``no-weight`` (``hold`` without a mass), ``non-finite`` (the weight overflows), ``nothing-to-hold``.

    >>> from grasptwist.objects import GraspObject, Shape
    >>> ball = GraspObject(Shape("sphere", np.array([0.05])), np.eye(4), mass=1.0)
    >>> w, weight = held_wrenches(ball, [[1.0, 0, 0, 0, 0, 0]])
    >>> w.tolist(), weight.mass
    ([[0.0, 0.0, 9.81, 0.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0, 0.0, 0.0]], 1.0)
    >>> held_wrenches(ball, loads="six")[0][:, :3].tolist()  # the weight, then the others of its size
    [[0.0, 0.0, 9.81], [-9.81, 0.0, 0.0], [9.81, 0.0, 0.0], [0.0, -9.81, 0.0], [0.0, 9.81, 0.0], [0.0, 0.0, -9.81]]
    """
    loads = check_loads(loads)
    listed = list(check_wrenches(wrenches)) if len(wrenches) else []
    held = None
    if hold:
        with np.errstate(over="ignore", invalid="ignore"):  # an overflow is said below
            held = object_weight(obj, np.asarray(gravity, float))
        held = weight if held is None else held
        if held is None:
            raise ProblemError(
                NO_WEIGHT, "hold=True needs the object's mass (or density): its weight is the wrench to hold"
            )
        if not np.isfinite(held.wrench).all():
            raise ProblemError(
                WEIGHT_OVERFLOWS, "the object's weight or its moment about the origin overflows (mass x gravity)"
            )
        listed.insert(0, held.wrench)
        if loads == "six":
            listed.extend(direction_loads(held)[1])
    if not listed:
        raise ProblemError(NOTHING_TO_HOLD, "nothing to hold: give the object a mass (hold=True) or wrenches")
    return np.array(listed), held


def with_tip_radius(hand, tip_radius):
    """``hand`` with every fingertip's radius ``tip_radius`` (None: as it is): the one place a search's
    ``tip_radius`` replaces the hand's.

    >>> from grasptwist.hand import Finger, Hand
    >>> f = Finger("a", None, (), None, None, None, 1.0, (), tip_radius=0.01)
    >>> [g.tip_radius for g in with_tip_radius(Hand((f, f, f), (), None, None), 0.02).fingers]
    [0.02, 0.02, 0.02]
    """
    tip_radius = check_tip_radius(tip_radius)
    if hand is None or tip_radius is None:
        return hand
    return replace(hand, fingers=tuple(replace(f, tip_radius=tip_radius) for f in hand.fingers))


def synthesis_problem(
    obj,
    friction,
    *,
    wrenches=(),
    hold=True,
    gravity=GRAVITY,
    weight=None,
    loads="weight",
    hand=None,
    tips=None,
    tip_radius=None,
    collide=None,
    hulls=None,
    environment=None,
    clearance=None,
    span_bodies=False,
    constraints=(),
    **options,
) -> Problem:
    """The :class:`Problem` of grasping ``obj``: the one builder of every front door (module docstring).

    Parameters
    ----------
    obj, friction, wrenches, hold, gravity, hand, tips, tip_radius, collide, hulls, environment, clearance, span_bodies
        As :func:`~.search.synthesize`; ``hand`` may be a :class:`~.reach.HandReach` already (its
        collision tests built by the caller: the command line's, from a URDF's meshes).
    weight : Weight, optional
        The weight held when ``obj`` has no mass (:func:`held_wrenches`).
    loads : {"weight", "six"}
        ``six``: a grip for the hold test's loads too (:func:`held_wrenches`; the front doors' default).
    constraints : sequence of callables
        Further constraints (:func:`~.search.search`), before the environment's.
    **options
        The search's (:func:`surface_problem`).

    Returns
    -------
    Problem

    Raises
    ------
    ProblemError
        No wrench to exert, or a weight that cannot be (:func:`held_wrenches`).
    ValueError
        An option out of its range, a hand that is not three fingers sharing no joint.
    """
    tip_radius = check_tip_radius(tip_radius)  # checked with or without a hand, as --tip-radius is
    listed, held = held_wrenches(obj, wrenches, hold=hold, gravity=gravity, weight=weight, loads=loads)
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
    problem = surface_problem(surface, listed, friction, hand=hand, constraints=(*constraints, *clear), **options)
    return replace(problem, object=obj, weight=held, environment=environment)
