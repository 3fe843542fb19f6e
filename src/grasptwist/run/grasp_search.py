"""``grasptwist.synthesize``: the engine's search, with a hand checked as the command line checks it.

The engine's :func:`~grasptwist.engine.synthesis.search.synthesize` takes the hand's collision
tests as functions; this one builds them the command line's way
(:func:`~grasptwist.run.collisions.hand_constraints`: a URDF's collision meshes against the
object, the fingers against each other, every part against the environment), so that a
Python caller gets the grasps ``grasptwist synthesize`` would give.  No math here.
"""

from __future__ import annotations

from ..engine.fingertips import tip_centers, tip_radii
from ..engine.ik import home_tips
from ..engine.synthesis.reach import HandReach
from ..engine.synthesis.search import synthesize as search_object
from ..io.limits import MAX_URDF_BYTES
from ..model import Grasp

__all__ = ["synthesize", "file_tips"]


def synthesize(
    obj,
    friction,
    *,
    hand=None,
    environment=None,
    clearance=None,
    folder=None,
    max_bytes=MAX_URDF_BYTES,
    tips=None,
    tip_radius=None,
    **options,
):
    r"""Grasps of an object: its surface searched for grasps that hold its weight and ``wrenches``.

    The search scores candidate triples in batches against the constraints (degeneracy and
    conditioning of the decompositions, force closure at ``friction / safety``, a grip for every
    wrench), refines the best on the surface and verifies each grasp it returns by the exact grip
    and its certificate (the guide's synthesis page).  With a hand, every grasp is one the hand
    can take as the command line checks it: fingertips on the surface, joints within their
    limits, no finger link (a URDF's collision meshes) in the object, no two fingers into each
    other (their links' convex hulls and fingertip spheres), every part ``clearance`` from the
    ``environment`` (:func:`grasptwist.hand.hand_constraints`).

    Parameters
    ----------
    obj : GraspObject or Grasp
        With a ``mass`` or ``density`` when ``hold`` (the weight ``m g`` at its centre of mass).  A
        ``Grasp`` (``grasptwist.read_grasps``) stands for its file: its ``object`` is searched, and
        its ``hand``, ``environment`` and ``wrist`` are taken, with its file's folder as ``folder``,
        unless given here (as ``grasptwist synthesize FILE`` takes them).
    friction : float
        ``mu`` at every contact.
    hand : Hand or HandReach, optional
        A hand that must reach every grasp; the grasps then list contact ``f`` for finger ``f``
        (the fingers are assigned to the contacts in every order), and ``joint_positions``,
        ``reach_error`` and ``tip_center`` say where the hand holds each.  A ``HandReach``
        (:func:`grasptwist.hand.hand_constraints`) is taken as it is.
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
    **options
        ``wrenches`` (more wrenches every grasp must exert, ``(force; moment about the
        origin)``), ``hold`` (True: the weight comes first), ``gravity``, ``span_bodies``
        (False: each grasp on one body of the object), and the search's: ``count`` (grasps
        wanted, 1), ``safety`` (1), ``objective`` (``robust``, ``total_normal_force``,
        ``closure_friction`` or ``epsilon``), ``wrist`` (None), ``methods``,
        ``min_conditioning`` (0.05), ``min_spacing`` (None: 5% of the object's size),
        ``quality`` (False), ``seed`` (0), ``candidates`` (20000), ``seconds`` (None),
        ``position_error``, ``friction_error`` (0.2), ``perturbations`` (64); and
        ``collide``, ``hulls``: the hand's tests given as functions instead
        (``grasptwist.engine.synthesis.search.synthesize``).

    Returns
    -------
    Synthesis

    Raises
    ------
    InputError
        A URDF hand's meshes that cannot be read.
    ValueError
        No weight to hold and no wrench, or a hand that is not three fingers sharing no joint.

    Examples
    --------
    A 65 mm cube of 100 g on a table, ``mu = 0.8``: no contact within 1 mm of the table (the
    face it rests on is never touched):

    >>> import numpy as np
    >>> from grasptwist.objects import Environment, GraspObject, Shape
    >>> cube = GraspObject(Shape("box", np.full(3, 0.065)), np.eye(4), mass=0.1)
    >>> s = synthesize(cube, 0.8, count=2, candidates=1000, environment=Environment(table_height=-0.0325))
    >>> s.points.shape, bool((s.closure_friction < 0.8).all()), bool((s.points[..., 2] >= -0.0315).all())
    ((2, 3, 3), True, True)
    """
    if isinstance(obj, Grasp):
        if hand is None and tips is None and obj.hand is not None and any(f.tip_pose is None for f in obj.hand.fingers):
            tips = file_tips(obj, obj.hand)  # an inline hand's tips: at the file's contacts, as the command line's
        obj, hand, environment, folder, options = _from_file(obj, hand, environment, folder, options)
    if hand is not None and not isinstance(hand, HandReach) and "collide" not in options and "hulls" not in options:
        from .collisions import hand_constraints  # the finger links' meshes: with the first hand

        hand = hand_constraints(
            obj,
            hand,
            environment=environment,
            clearance=clearance,
            tips=tips,
            tip_radius=tip_radius,
            folder=folder,
            max_bytes=max_bytes,
        )
    return search_object(
        obj,
        friction,
        hand=hand,
        tips=tips,
        tip_radius=tip_radius,
        environment=environment,
        clearance=clearance,
        **options,
    )


def _from_file(grasp, hand, environment, folder, options):
    """What a grasp file gives a search (:func:`synthesize`'s ``obj``): its object, and its hand,
    environment, wrist and folder where the caller gives none."""
    if grasp.object is None:
        raise ValueError(f"grasp '{grasp.name}' of {grasp.file} has no object to search")
    from ..io.urdf_meshes import grasp_folder

    options.setdefault("wrist", grasp.wrist)
    return (
        grasp.object,
        grasp.hand if hand is None else hand,
        grasp.environment if environment is None else environment,
        grasp_folder(grasp) if folder is None else folder,
        options,
    )


def file_tips(grasp, hand):
    """Each finger's tip link pose at home ``(3, 4, 4)`` for a hand given inline in ``grasp``'s file:
    where its fingertip sphere's centre is on the file's contact (its joints are given there)."""
    return home_tips(hand, tip_centers(grasp.points, grasp.normals, tip_radii(hand)))
