"""The data types of a hand: its joints and fingers, and where a grasp file puts it.

Apart from :mod:`grasptwist.model` (which names them) so that a run without a hand
compiles none of their dataclasses' methods at start-up (bench/startup.py).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Joint", "Finger", "Hand", "HandPlacement"]


@dataclass(frozen=True)
class HandPlacement:
    """Where a grasp file puts its URDF hand, as the file says it (nothing solved yet).

    Attributes
    ----------
    given : bool
        The file gives ``joint_positions`` (checked against the contacts);
        else the grasp's joint positions are the ``seed`` that inverse
        kinematics starts from.
    tips : tuple of (int, int)
        ``(line, column)`` of each finger's ``tip`` in the file: where a finger
        that cannot be put on its contact is reported.
    """

    given: bool
    tips: tuple[tuple[int | None, int | None], ...]


@dataclass(frozen=True, eq=False)
class Joint:
    """One movable joint of a finger.

    Attributes
    ----------
    name : str
    type : str
        ``"revolute"`` (URDF ``continuous`` too) or ``"prismatic"``.
    velocity_limit : float or None
        Largest rate (rad or length per unit time), None when not given.
    lower, upper : float or None
        Position limits, None when not given.
    line : int or None
        1-based line of its definition (URDF element or grasp-file entry).
    """

    name: str
    type: str
    velocity_limit: float | None
    lower: float | None
    upper: float | None
    line: int | None


@dataclass(frozen=True, eq=False)
class Finger:
    """A finger: a serial chain of joints at its home configuration (every joint at 0).

    Arrays are read-only, in the hand's root frame (the grasp's frame).
    :func:`~grasptwist.hand.forward_kinematics` moves them to
    other joint positions.

    Attributes
    ----------
    name : str
    tip : str or None
        The link whose body touches the contact (URDF), None for inline joints.
    joints : tuple of Joint
        Base to tip.
    screws : numpy.ndarray
        ``(n, 6)`` joint screws ``(omega; v)``: unit lines for revolute joints,
        ``(0; d)`` for prismatic ones.
    points : numpy.ndarray
        ``(n, 3)`` a point of each joint (its frame's origin; on a revolute axis).
    tip_pose : numpy.ndarray or None
        ``(4, 4)`` pose of the tip link, None for inline joints.
    length : float
        From the first joint through the others to the tip link's origin: a
        contact farther than this from the tip is a frame mix-up.
    joint_index : tuple of int
        Position of each joint in ``Hand.joint_names``.
    tip_radius : float
        Radius of the fingertip's sphere, centred at the tip link's origin (0: a
        point tip). The tip's centre sits at ``point - tip_radius * normal``
        (normal into the object), so the sphere touches the object at the contact.
    """

    name: str
    tip: str | None
    joints: tuple[Joint, ...]
    screws: np.ndarray
    points: np.ndarray
    tip_pose: np.ndarray | None
    length: float
    joint_index: tuple[int, ...]
    tip_radius: float = 0.0


@dataclass(frozen=True, eq=False)
class Hand:
    """A hand: its fingers in contact order, and the joints that move them.

    Attributes
    ----------
    fingers : tuple of Finger
    joint_names : tuple of str
        Every finger's joints, each once, in finger then joint order: the
        columns of a ``joint_positions`` array.
    source : str or None
        The robot description it was read from (as referenced), None for inline joints.
    root : str or None
        The URDF's root link, whose frame is the grasp's frame.
    urdf_at : (str, int, int) or None
        ``(file, line, column)`` of the ``urdf`` key that names the URDF (in a grasp file or a
        ``--hand`` file), where the problems of its meshes, read later, are reported; None when
        not read from a file.
    """

    fingers: tuple[Finger, ...]
    joint_names: tuple[str, ...]
    source: str | None
    root: str | None
    urdf_at: tuple[str, int | None, int | None] | None = None
