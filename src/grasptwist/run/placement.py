"""Hands put on their contacts: the inverse kinematics the loader leaves to the run.

The loader only reads (:mod:`grasptwist.io.grasp.hand`): a grasp whose URDF
hand is not yet on its contacts carries a :class:`~grasptwist.model.HandPlacement`,
the joint positions the file gives (to check) or its seed (to solve from),
and where each finger's ``tip`` stood in the file.  :func:`place_grasp` runs the
engine (:func:`grasptwist.engine.placement.place`) and gives the grasp at its
placed joint positions, or its error: each finger that cannot be put on
its contact (``contact-off-finger``, ``unreachable``, ``outside-limits``)
located at its ``tip``, coded and worded as a loader's problem.  Every
reader of grasps in the run layer goes through :func:`placed`.
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from ..engine.degeneracy import Status
from ..engine.environment import needs_checks
from ..io import grasp as loader
from ..io import inputs
from ..io.grasp import READING, Reading
from ..io.grasp.problems import MAX_ERRORS, Problems, Reject
from ..io.grasp.values import readonly
from ..model import Grasp, InputError
from ..output.names import escaped

if TYPE_CHECKING:
    from ..model.hands import Hand

__all__ = ["TIP_CODE", "place_grasp", "placed", "read", "read_grasps", "run_hand", "tip_warnings"]

#: The warning of given joint positions that leave a tip off its contact (within the finger's reach).
TIP_CODE = "tip-off-contact"


def place_grasp(grasp: Grasp) -> Grasp | InputError:
    """A grasp with its URDF hand put on its contacts, as every command reads it.

    The loader only reads (:func:`grasptwist.read_grasps`): a URDF hand comes at the
    ``joint_positions`` its file gives, or at its ``seed``, with ``grasp.placement`` saying
    which.  Here the given positions are checked against the contacts (forward kinematics), or
    positions are solved from the seed (inverse kinematics): each tip link's origin, the
    centre of its fingertip's sphere, on ``point - tip_radius * normal``
    (:func:`grasptwist.hand.tip_centers`).  Every grasp's fingers are then checked
    (``grasptwist.run.collisions.with_collisions``: links in the object, fingers into each other,
    parts too near its environment: warnings).

    Parameters
    ----------
    grasp : Grasp or InputError
        As read; one without a pending placement (no hand, an inline hand, placed) is returned as it is,
        and so is a document's error that :func:`grasptwist.read_grasps` gave in its place (a list of
        what was read places whole).

    Returns
    -------
    Grasp or InputError
        The grasp at its checked or solved joint positions (``placement`` None), or the error of
        its document: ``contact-off-finger``, ``unreachable`` or ``outside-limits`` located at
        each failing finger's ``tip`` in the file, every such problem in its ``problems``.

    Examples
    --------
    >>> import grasptwist as gt
    >>> (g,) = gt.read_grasps("grasps/three-finger-hand.yaml")  # an inline hand: nothing to place
    >>> gt.place_grasp(g) is g
    True
    >>> error = gt.InputError("fixed-finger", "hand.fingers[2].tip: ...", "h.yaml", 16, 13)
    >>> gt.place_grasp(error) is error
    True
    """
    if isinstance(grasp, InputError):  # read_grasps' entry for a document it could not read
        return grasp
    p = grasp.placement
    if p is None:  # placed already, an inline hand or none: its fingers and contacts checked all the same
        if not needs_checks(grasp.hand, grasp.environment):
            return grasp
        from .collisions import with_collisions  # the fingers against each other and the environment

        return with_collisions(grasp)
    # inverse kinematics loads with the first URDF hand
    from ..engine.placement import place

    hand, q = grasp.hand, grasp.joint_positions
    # each tip link's origin, the centre of its fingertip's sphere, goes r behind the contact
    solved = (
        place(hand, grasp.points, grasp.normals, q) if p.given else place(hand, grasp.points, grasp.normals, seed=q)
    ).ik
    problems = Problems(MAX_ERRORS)
    for f, finger in enumerate(hand.fingers):
        status = Status(int(solved.status[f]))
        if status != Status.OK:
            message = _placement_message(status, grasp.contact_names[f], finger, float(solved.tip_error[f]))
            line, column = p.tips[f]
            problems.add(Reject(status.code, f"hand.fingers[{f}].tip", message, line, column))
    if problems.count:
        errors = [reject.error(grasp.file, grasp.document) for reject in problems.first()[0]]
        return InputError(*errors[0].args[:6], errors)  # one per document, as the reader gives them
    from .collisions import with_collisions  # as the inverse kinematics: with the first URDF hand

    said = tip_warnings(hand, grasp.contact_names, solved.tip_error) if p.given else ()
    placed = replace(grasp, joint_positions=readonly(solved.positions), placement=None, warnings=grasp.warnings + said)
    return with_collisions(placed)


def tip_warnings(hand, names, tip_error) -> tuple[str, ...]:
    """The ``tip-off-contact`` warnings of a hand at given joint positions: one per finger whose tip
    point is farther from where it must be than :func:`~grasptwist.engine.ik.tip_tolerance` (1% of
    the finger's length), naming the finger (its contact's name), the distance and the tolerance.

    Parameters
    ----------
    hand : Hand
    names : sequence of 3 str
        The contacts' names.
    tip_error : (3,) array
        Each finger's distance from where it must be (NaN: unchecked).

    Examples
    --------
    >>> import grasptwist as gt
    >>> (g,) = gt.read_grasps("grasps/trifinger-cube.yaml")
    >>> tip_warnings(g.hand, ("0", "1", "2"), [0.0474, 0.0, float("nan")])  # doctest: +NORMALIZE_WHITESPACE
    ("tip-off-contact: finger 0's tip link 'finger_tip_link_0' is 0.0474 from where its contact puts it,
    over the tolerance 0.00382 (1% of the finger's length): are the joint_positions this grasp's?",)
    """
    from ..engine.ik import TIP_OFF_TOL, tip_off_contact, tip_tolerance

    lengths = [f.length for f in hand.fingers]
    off, tol = tip_off_contact(tip_error, lengths), tip_tolerance(lengths)
    return tuple(
        f"{TIP_CODE}: finger {escaped(names[f])}'s tip link {escaped(hand.fingers[f].tip)!r} is {tip_error[f]:.3g} "
        f"from where its contact puts it, over the tolerance {tol[f]:.3g} ({TIP_OFF_TOL:.0%} of the finger's "
        "length): are the joint_positions this grasp's?"
        for f in np.flatnonzero(off)
    )


def placed(items: Iterable) -> list:
    """Read grasps and errors with every hand placed (:func:`place_grasp`), in order."""
    return [place_grasp(item) if isinstance(item, Grasp) else item for item in items]


def read(path, max_bytes: int | None = None, reading: Reading = READING) -> list:
    """The grasps and errors of one input (:func:`grasptwist.io.inputs.read`), hands placed."""
    return placed(inputs.read(path, max_bytes, reading))


def run_hand(path: str | None, paths: list[str], per_hand: bool) -> Hand | None:
    """The run's hand: the one of ``path`` (``--hand``, a file holding just ``hand:``), or for a
    format whose columns a hand's joints name (``per_hand``) of one grasp file, that file's first
    hand (a folder's grasps may each have another); None without.

    Raises
    ------
    InputError
        The ``--hand`` file's first problem.
    """
    if path is not None:
        return loader.load_hand_file(path)[0]
    if not per_hand or len(paths) != 1 or not paths[0].lower().endswith((".yaml", ".yml", ".json")):
        return None
    if not os.path.isfile(paths[0]):
        return None
    return next((g.hand for g in read(paths[0]) if getattr(g, "hand", None) is not None), None)


def read_grasps(source, **kw) -> list:
    """:func:`grasptwist.io.grasp.read_grasps` with every hand placed: the grasps and, one
    entry per problem, the errors of a grasp file (a path or its bytes)."""
    return [p for e in placed(loader.read_grasps(source, **kw)) for p in getattr(e, "problems", (e,))]


def _placement_message(status, name, finger, distance):
    """Why the finger of contact ``name`` (named by it, as everywhere) is not on its contact, with the
    distance from its tip link's origin."""
    if status == Status.CONTACT_OFF_FINGER:
        return (
            f"contact {name} is {distance:.6g} from the origin of its finger's tip link {finger.tip!r}{_behind(finger)}, farther "
            f"than the finger is long ({finger.length:.6g}): are the contacts in the URDF's root frame?"
        )
    if status == Status.OUTSIDE_LIMITS:
        return (
            f"finger {name} reaches its contact only with a joint outside its limits: "
            "move the contact, or give joint_positions"
        )
    # the closest the iteration came: where it stalled, within about 2e-5 of the true least distance, so 4 digits
    return (
        f"finger {name} cannot reach its contact: the origin of its tip link {finger.tip!r}{_behind(finger)} comes "
        f"no closer than {distance:.4g} (the finger is {finger.length:.6g} long): "
        "are the contacts in the URDF's root frame?"
    )


def _behind(finger):
    """How far behind the contact the tip's origin goes, for a finger with a fingertip radius."""
    return f" (to sit {finger.tip_radius:.6g} behind it, the fingertip's radius)" if finger.tip_radius else ""
