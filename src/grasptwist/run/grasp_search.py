"""``grasptwist.synthesize``, and the one synthesis problem every front door builds.

The engine's :func:`~grasptwist.engine.synthesis.problem.synthesis_problem` builds a search's
problem from an object, a hand and options; this module adds what the command line reads
around it, once, for the library (:func:`synthesize`), the command line
(``run/synthesize.py``) and Dask (:func:`grasptwist.dask.synthesize_bag`, through the command
line's records): a grasp document's object, friction, weight and wrenches (:func:`grasp_problem`),
and the hand's collision tests built the command line's way
(:func:`~grasptwist.run.collisions.hand_constraints`: a URDF's collision meshes against the
object, the fingers against each other, every part against the environment), its fingertips
placed on the file's contacts when it is given inline (:func:`~grasptwist.engine.placement.home_at`).
No math here.
"""

from __future__ import annotations

from dataclasses import replace
from typing import NamedTuple

import numpy as np

from ..engine.forces.hold import Weight, hold_wrench
from ..engine.hold_test import direction_loads
from ..engine.placement import home_at
from ..engine.synthesis.problem import (
    GRAVITY,
    NO_WEIGHT,
    NOTHING_TO_HOLD,
    WEIGHT_OVERFLOWS,
    Problem,
    ProblemError,
    synthesis_problem,
    with_tip_radius,
)
from ..engine.synthesis.reach import HandReach
from ..engine.synthesis.scores import METHODS, MIN_CONDITIONING
from ..engine.synthesis.search import Synthesis, solve
from ..io.grasp.forces import HOLD
from ..io.limits import MAX_URDF_BYTES
from ..model import Grasp, InputError, Wrench

__all__ = [
    "synthesize",
    "grasp_problem",
    "search_options",
    "Task",
    "NO_OBJECT",
    "NO_FRICTION",
    "NO_TIP_POINTS",
    "UNSEARCHABLE_HAND",
]

#: Error codes of a grasp document the search cannot start from.
NO_OBJECT, NO_FRICTION = "no-object", "no-friction"

#: An inline hand without the contacts its tips touch (``--hand`` with a mesh); a hand whose
#: fingers share joints (the search solves each finger on its own).
NO_TIP_POINTS, UNSEARCHABLE_HAND = "no-tip-points", "unsearchable-hand"


class Task(NamedTuple):
    """One grasp document's synthesis problem, with what its records name.

    Attributes
    ----------
    problem : Problem
    names : tuple of str
        Each wrench's name (``hold`` the weight's, first).
    hand : Hand or None
        The hand searched, with its fingertips' radius (``tip_radius``) applied.
    friction : float
    """

    problem: Problem
    names: tuple[str, ...]
    hand: object
    friction: float


def search_options(options) -> dict:
    """The search's keywords of the command line's options (a ``SynthesisOptions``): ``--method``
    as ``methods``, the engine's ``min_conditioning`` where none is given.

    >>> from grasptwist.run.options import SynthesisOptions
    >>> search_options(SynthesisOptions(method="tangent"))["methods"]
    ('tangent',)
    """
    o = options
    return {
        "count": o.count,
        "safety": o.safety,
        "objective": o.objective,
        "methods": METHODS if o.method == "both" else (o.method.replace("-", "_"),),
        "min_conditioning": MIN_CONDITIONING if o.min_conditioning is None else o.min_conditioning,
        "min_spacing": o.min_spacing,
        "quality": o.quality,
        "seed": o.seed,
        "candidates": o.candidates,
        "seconds": o.seconds,
        "position_error": o.position_error,
        "friction_error": o.friction_error,
        "perturbations": o.perturbations,
        "span_bodies": o.span_bodies,
        "torsion": o.torsion,
        "loads": o.loads,
    }


def _problem(grasp, code, message) -> InputError:
    return InputError(code, message, grasp.file, grasp.line, None)


def _friction(grasp, friction):
    """The friction given, else the file's least (the contacts found are none of the file's)."""
    if friction is not None:
        return friction
    if grasp.friction is not None:
        return float(np.min(grasp.friction))
    return _problem(grasp, NO_FRICTION, f"grasp '{grasp.name}' has no friction: give friction= (--friction)")


def _torsion(grasp, friction, torsion):
    """The soft contacts' radius of a search: ``torsion`` given (0: point contacts), else the least of the document's contacts'
    when every one is ``model: soft`` (as its friction, the least), else None (point contacts); None with a
    friction of 0 (``--friction 0`` over a file's soft contacts: frictionless, as the engine's models)."""
    if torsion is not None:  # given (--contact): every contact soft, or every one a point (0)
        return torsion or None
    soft = grasp.torsion
    every = soft is not None and (np.asarray(soft) > 0).all() and friction > 0
    return float(np.min(soft)) if every else None


def _wrenches(grasp, wrenches):
    """The named wrenches besides the weight: ``wrenches`` (``Wrench`` or ``(6,)`` arrays, named by
    position) replace the file's."""
    if wrenches is None:
        return [(w.name, w.wrench) for w in grasp.wrenches if w.name != HOLD]
    return [(w.name, w.wrench) if isinstance(w, Wrench) else (str(i), w) for i, w in enumerate(wrenches, 1)]


def grasp_problem(
    grasp: Grasp,
    *,
    friction=None,
    mass=None,
    wrenches=None,
    hand=None,
    hand_file=None,
    tips=None,
    tip_radius=None,
    environment=None,
    folder=None,
    max_bytes=MAX_URDF_BYTES,
    loads="six",
    **options,
) -> Task | InputError:
    """The synthesis problem a grasp document poses, or its error: the command line's, the
    library's and Dask's one builder.

    The document's object (``mass`` replaces its mass), its friction (``friction``, else the
    least of the file's), its weight held whenever there is a mass (the object's, else the
    file's ``mass`` at its ``center_of_mass``), its other wrenches (``wrenches`` replace them),
    its hand (``hand`` replaces it; ``tip_radius`` every fingertip's radius; a hand given inline
    has its tips on the file's contacts), its environment (``environment`` replaces it) and wrist.

    Parameters
    ----------
    grasp : Grasp
        Read unplaced (its hand is placed on the contacts found, not the file's).
    hand_file : str, optional
        The file ``hand`` was read from (``--hand``): a URDF's meshes are found from it.
    tips : (3, 4, 4) array, optional
        An inline ``hand``'s tip poses at home (without them it needs the file's contacts).
    folder, max_bytes
        Where a URDF hand's files are found (default: its file's folder), its size cap.
    loads : {"six", "weight"}
        ``six`` (the default, ``--loads six``): whenever a weight is held, a grip for the hold test's
        loads too, named ``load +x`` ... after the other wrenches: the weight's size along ``+-x``,
        ``+-y``, ``+-z`` at its centre (:func:`~grasptwist.engine.hold_test.direction_loads`), BODex's
        protocol; ``weight``: the weight alone.
    **options
        The search's (:func:`~grasptwist.engine.synthesis.problem.surface_problem`), and
        ``clearance``, ``span_bodies``, ``gravity`` (default the file's), ``hold`` (default:
        whenever there is a mass), ``torsion`` (soft contacts' radius; default the least of the
        document's when every contact is ``model: soft``).

    Returns
    -------
    Task or InputError
        ``no-object``, ``no-friction``, ``nothing-to-hold``, ``non-finite``, ``no-tip-points``,
        ``unsearchable-hand``, located at the document, or a URDF's meshes' error, at the ``urdf``
        key of the file that names it (:func:`~grasptwist.run.collisions.hand_error`).
    """
    if grasp.object is None:
        return _problem(grasp, NO_OBJECT, f"grasp '{grasp.name}' has no object to search")
    obj = weighed(grasp.object, mass)
    friction = _friction(grasp, friction)
    if isinstance(friction, InputError):
        return friction
    options["torsion"] = _torsion(grasp, friction, options.get("torsion"))
    named = _wrenches(grasp, wrenches)
    gravity = np.asarray(options.pop("gravity", None) or (GRAVITY if grasp.gravity is None else grasp.gravity), float)
    held = options.pop("hold", None)  # None: whenever there is a mass
    if held is None:  # the object's mass or density, the file's top-level mass, or mass=
        own = grasp.object.mass is not None or grasp.object.density is not None
        held = mass is not None or grasp.mass is not None or own
    fallback = None  # a weight apart from the object: the file's top-level mass and center_of_mass
    if held and grasp.mass is not None:
        with np.errstate(over="ignore", invalid="ignore"):  # an overflow is the problem's error
            wrench = hold_wrench(grasp.mass, grasp.center_of_mass, gravity)
        fallback = Weight(grasp.mass, grasp.center_of_mass, gravity, wrench)
    environment = grasp.environment if environment is None else environment
    options.setdefault("wrist", grasp.wrist)
    given = hand is not None
    hand = with_tip_radius(hand if given else grasp.hand, tip_radius)
    reach = None
    if hand is not None:
        if tips is None and any(f.tip_pose is None for f in hand.fingers):
            if given or np.isnan(grasp.points).any():  # --hand, a mesh, a document without contacts
                return _problem(
                    grasp,
                    NO_TIP_POINTS,
                    "an inline hand has no tip points without the contacts its fingers touch: put it in a grasp file",
                )
            tips = home_at(hand, grasp.points, grasp.normals)  # where the file gives its joints
        from ..io.urdf_meshes import grasp_folder  # the finger links' meshes: with the first URDF hand

        if folder is None:  # a URDF's meshes are found from the file that names it: the grasp file, or --hand's
            folder = grasp_folder(replace(grasp, file=hand_file if given and hand_file else grasp.file))
        try:
            reach = hand_reach(obj, hand, environment, options.get("clearance"), tips, folder, max_bytes)
        except InputError as exc:
            from .collisions import hand_error  # with the first URDF hand, as hand_reach's

            return hand_error(exc, grasp, hand)
        except ValueError as exc:
            return _problem(grasp, UNSEARCHABLE_HAND, str(exc))
    try:
        problem = synthesis_problem(
            obj,
            friction,
            wrenches=[w for _, w in named],
            hold=held,
            gravity=gravity,
            weight=fallback,
            loads=loads,
            hand=reach,
            environment=environment,
            **options,
        )
    except ProblemError as exc:
        return _problem(grasp, *_words(grasp, exc))
    names = ((HOLD,) if held else ()) + tuple(n for n, _ in named)
    if held and loads == "six":
        names += direction_loads(problem.weight)[0]
    return Task(problem, names, hand, friction)


def _words(grasp, exc: ProblemError) -> tuple[str, str]:
    """A problem's error in a document's words: its code and what would mend it, in its callers' words (the
    library's keyword, the command line's option)."""
    if exc.code in (NOTHING_TO_HOLD, NO_WEIGHT):
        return NOTHING_TO_HOLD, (
            f"grasp '{grasp.name}' has nothing to hold: give the object a mass (mass=, --mass) "
            "or a wrench (wrenches=, --wrench)"
        )
    return WEIGHT_OVERFLOWS, (
        f"grasp '{grasp.name}': the weight or its moment about the origin overflows "
        "(mass x gravity, center_of_mass x weight)"
    )


def weighed(obj, mass):
    """``obj`` with ``mass`` (``mass=``, ``--mass``) in place of its mass or density; as it is when None.

    >>> from grasptwist.objects import GraspObject, Shape
    >>> ball = GraspObject(Shape("sphere", np.array([0.05])), np.eye(4), density=1000.0)
    >>> w = weighed(ball, 0.1)
    >>> w.mass, w.density, weighed(ball, None) is ball
    (0.1, None, True)
    """
    return obj if mass is None else replace(obj, mass=mass, density=None)


def hand_reach(obj, hand, environment, clearance, tips, folder, max_bytes) -> HandReach:
    """A hand as the search takes it, with every check the command line makes
    (:func:`~grasptwist.run.collisions.hand_constraints`)."""
    from .collisions import hand_constraints  # the finger links' meshes: with the first hand

    return hand_constraints(
        obj, hand, environment=environment, clearance=clearance, tips=tips, folder=folder, max_bytes=max_bytes
    )


def synthesize(
    obj,
    friction=None,
    *,
    hand=None,
    environment=None,
    clearance=None,
    folder=None,
    max_bytes=MAX_URDF_BYTES,
    tips=None,
    tip_radius=None,
    loads="six",
    **options,
) -> Synthesis:
    r"""Grasps of an object: its surface searched for grasps that hold its weight and ``wrenches``, and
    by default (``loads="six"``) the weight's size along each of the six axis directions.

    The search scores candidate triples in batches against the constraints (degeneracy and
    conditioning of the decompositions, force closure at ``friction / safety``, a grip for every
    wrench), refines the best on the surface and verifies each grasp it returns by the exact grip
    and its certificate (the guide's synthesis page).  With a hand, every grasp is one the hand
    can take as the command line checks it: fingertips on the surface, joints within their
    limits, no finger link (a URDF's collision meshes) in the object, no two fingers into each
    other (their links' convex hulls and fingertip spheres), every part ``clearance`` from the
    ``environment`` (``grasptwist.run.collisions.hand_constraints``).  The problem is built as the
    command line and :func:`grasptwist.dask.synthesize_bag` build it (``grasp_problem``): the
    same options give the same grasps through all three.

    Parameters
    ----------
    obj : GraspObject or Grasp
        With a ``mass`` or ``density`` (or ``mass=``) when ``hold`` (the weight ``m g`` at its centre of mass).  A
        ``Grasp`` (``grasptwist.read_grasps``) stands for its file, as ``grasptwist synthesize FILE``
        takes it: its ``object`` is searched, with its friction (the least of its contacts') unless
        ``friction`` is given, its weight (``mass`` replaces the object's), its other wrenches
        (``wrenches`` replace them), its ``hand``, ``environment`` and ``wrist`` unless given here,
        and its file's folder as ``folder``.
    friction : float
        ``mu`` at every contact (a ``Grasp``'s own when None).
    hand : Hand or HandReach, optional
        A hand that must reach every grasp; the grasps then list contact ``f`` for finger ``f``
        (the fingers are assigned to the contacts in every order), and ``joint_positions``,
        ``reach_error`` and ``tip_center`` say where the hand holds each.  A ``HandReach``
        (``grasptwist.run.collisions.hand_constraints``) is taken as it is.
    environment : Environment, optional
        A table and boxes (``grasptwist.objects.Environment``; a grasp file's ``environment``):
        every contact's fingertip sphere (a point without a hand) and every part of the hand
        keep ``clearance`` from them; contacts that cannot are never sampled.
    clearance : float, optional
        Default the environment's, else ``grasptwist.objects.CLEARANCE`` (1 mm in metres).
    folder : str or os.PathLike, optional
        The folder a URDF hand's relative paths are found from (its grasp file's).
    max_bytes : int
        Size cap of the URDF.
    tips, tip_radius
        Each finger's tip link pose at home (needed for a finger given inline), every
        fingertip's radius (default each finger's ``tip_radius``).
    loads : {"six", "weight"}
        What every grasp holds besides ``wrenches`` when a weight is held: ``six`` (the default), a
        grip for the weight's size along each of ``+-x, +-y, +-z`` at the centre of mass too (the hold
        test's loads, BODex's protocol: ``grasptwist.engine.hold_test.direction_loads``), after the
        other wrenches; ``weight``, the weight alone.
    **options
        ``wrenches`` (more wrenches every grasp must exert, ``(force; moment about the
        origin)``), ``hold`` (True: the weight comes first), ``gravity``, ``span_bodies``
        (False: each grasp on one body of the object), ``mass`` (in place of the object's mass or
        density, a ``Grasp``'s object's as a ``GraspObject``'s: ``--mass``), and the
        search's: ``count`` (grasps wanted, 1), ``safety`` (1), ``objective`` (``robust``,
        ``total_normal_force``, ``closure_friction`` or ``epsilon``), ``wrist`` (None),
        ``methods``, ``min_conditioning`` (0.05), ``min_spacing`` (None: 5% of the object's
        size), ``quality`` (False), ``seed`` (0), ``candidates`` (20000), ``seconds`` (None; the
        command line's 60 s give the same grasps unless they run out: ``budget.Spending.take``),
        ``position_error``, ``friction_error`` (0.2), ``perturbations`` (64), ``torsion`` (None:
        point contacts; soft contacts' radius, a ``Grasp``'s when all its contacts are soft; 0: a
        ``Grasp``'s soft contacts searched as points, ``--contact point``); and
        ``collide``, ``hulls``: the hand's tests given as functions instead
        (``grasptwist.engine.synthesis.search.synthesize``).

    Returns
    -------
    Synthesis

    Raises
    ------
    InputError
        A ``Grasp`` the search cannot start from (its code: ``no-object``, ``no-friction``,
        ``nothing-to-hold``, ...), a URDF hand's meshes that cannot be read.
    ValueError
        No weight to hold and no wrench, or a hand that is not three fingers sharing no joint.

    Examples
    --------
    A 65 mm cube of 100 g on a table, ``mu = 0.8``, held against its weight: no contact within 1 mm of
    the table (the face it rests on is never touched):

    >>> import numpy as np
    >>> from grasptwist.objects import Environment, GraspObject, Shape
    >>> cube = GraspObject(Shape("box", np.full(3, 0.065)), np.eye(4), mass=0.1)
    >>> table = Environment(table_height=-0.0325)
    >>> s = synthesize(cube, 0.8, count=2, candidates=500, environment=table, loads="weight")
    >>> s.points.shape, bool((s.closure_friction < 0.8).all()), bool((s.points[..., 2] >= -0.0315).all())
    ((2, 3, 3), True, True)
    """
    if isinstance(obj, Grasp):
        task = grasp_problem(
            obj,
            friction=friction,
            hand=hand,
            tips=tips,
            tip_radius=tip_radius,
            environment=environment,
            clearance=clearance,
            folder=folder,
            max_bytes=max_bytes,
            loads=loads,
            **options,
        )
        if isinstance(task, InputError):
            raise task
        return solve(task.problem)
    if friction is None:
        raise ValueError("friction: give mu at every contact (only a Grasp brings its own)")
    obj = weighed(obj, options.pop("mass", None))  # as a Grasp's: the object with that mass
    if hand is not None and not isinstance(hand, HandReach) and "collide" not in options and "hulls" not in options:
        hand = with_tip_radius(hand, tip_radius)
        hand = hand_reach(obj, hand, environment, clearance, tips, folder, max_bytes)
    return solve(
        synthesis_problem(
            obj,
            friction,
            hand=hand,
            tips=tips,
            tip_radius=tip_radius,
            environment=environment,
            clearance=clearance,
            loads=loads,
            **options,
        )
    )
