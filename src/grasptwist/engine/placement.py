r"""A hand put on its contacts: the one place a placement is assembled.

Finger ``f`` touches contact ``f`` with its fingertip sphere of radius ``r_f``, whose centre,
the origin of its tip link, sits behind the contact:

.. math:: c_f = p_f - r_f\,\hat n_f

(:func:`~.fingertips.tip_centers`).  A placement is the joint positions that put every tip there,
given and checked or solved by inverse kinematics (:func:`~.ik.place_hand`), each finger's tip
pose at home (a URDF finger's tip link; a finger given inline carries its tip point where the
file's contact puts it, :func:`home_at`), and where each fingertip then touches its contact
(:func:`~.fingertips.tip_contacts`).  The grasp reader's placement (``run/placement.py``), the
rows of ``resolve`` and ``follow`` (``run/batch.py``, ``run/follow.py``), the search's hand
(``run/grasp_search.py``) and the collision checks (``run/collisions.py``) all take it from here.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from .fingertips import TipContacts, tip_centers, tip_contacts, tip_radii
from .hands import padded_positions, tip_poses
from .ik import HandIK, home_tips, place_hand
from .kinematics import forward_kinematics

__all__ = ["Placement", "place", "home_at", "joints_at"]


def home_at(hand, points, normals):
    """Each finger's tip link pose at home, ``(3, 4, 4)``, a finger given inline with its tip point on
    the centre of its fingertip sphere touching contact ``f`` (``p_f - r_f n_f``): where a grasp file
    gives its joints.

    >>> from grasptwist.hand import Finger, Hand
    >>> f = Finger("a", None, (), np.zeros((0, 6)), np.zeros((0, 3)), None, 1.0, (), tip_radius=0.01)
    >>> home_at(Hand((f, f, f), (), None, None), np.eye(3), -np.eye(3))[:, :3, 3].round(3).tolist()
    [[1.01, 0.0, 0.0], [0.0, 1.01, 0.0], [0.0, 0.0, 1.01]]
    """
    return home_tips(hand, tip_centers(points, normals, tip_radii(hand)))


def joints_at(hand, positions) -> tuple:
    """Each finger's joints moved to ``positions`` ``(n_joints,)``, per finger ``(screws (n, 6), points (n, 3))``:
    the hand as a grasp file gives it inline at that configuration (its joints at 0 there).

    >>> from grasptwist.hand import Finger, Hand, Joint
    >>> slides = (Joint("x", "prismatic", None, None, None, None), Joint("y", "prismatic", None, None, None, None))
    >>> f = Finger("a", None, slides, np.array([[0, 0, 0, 1.0, 0, 0], [0, 0, 0, 0, 1.0, 0]]), np.zeros((2, 3)), None, 1.0, (0, 1))
    >>> joints_at(Hand((f, f, f), ("x", "y"), None, None), [0.5, 0])[0][1].tolist()  # the second rides the first
    [[0.0, 0.0, 0.0], [0.5, 0.0, 0.0]]
    """
    q = np.asarray(positions, dtype=float)
    return tuple(forward_kinematics(f.screws, f.points, None, q[list(f.joint_index)])[:2] for f in hand.fingers)


@dataclass(frozen=True, eq=False)
class Placement:
    """A hand on its contacts (:func:`place`).

    Attributes
    ----------
    hand : Hand
    ik : HandIK
        Joint positions ``(..., n_joints)``, each finger's tip error, whether within its limits,
        its status (``ok``, ``contact-off-finger``, ``unreachable``, ``outside-limits``).
    centers : (..., 3, 3)
        Each fingertip sphere's centre ``p - r n``, where its tip point must be.
    home : (3, 4, 4)
        Each finger's tip pose at home.
    points, normals, radii
        The contacts and each fingertip's radius.
    """

    hand: object
    ik: HandIK
    centers: np.ndarray
    home: np.ndarray
    points: np.ndarray
    normals: np.ndarray
    radii: np.ndarray

    @cached_property
    def touch(self) -> TipContacts:
        """Where each fingertip touches its contact at the placed positions (the gap, the point)."""
        return tip_contacts(tip_poses(self.hand, self.ik.positions, self.home), self.points, self.normals, self.radii)

    def fields(self, width=None) -> dict:
        """The placement as a block of rows carries it: ``joint_positions (..., 3, width)``,
        ``tip_error (..., 3)``, ``within_limits (..., 3)``, ``tip_center (..., 3, 3)``,
        ``tip_gap (..., 3)`` and ``tip_contact (..., 3, 3)``."""
        return {
            "joint_positions": padded_positions(self.hand, self.ik.positions, width),
            "tip_error": self.ik.tip_error,
            "within_limits": self.ik.within_limits,
            "tip_center": self.centers,
            "tip_gap": self.touch.gap,
            "tip_contact": self.touch.contact,
        }


def place(hand, points, normals, positions=None, *, seed=None, home=None) -> Placement:
    """A batch of hands put on their contacts, fingertip ``f`` touching contact ``f`` (module docstring).

    Parameters
    ----------
    hand : Hand
    points, normals : (..., 3, 3) arrays
        The contacts and their normals.
    positions : (..., n_joints) array, optional
        Joint positions to check (forward kinematics); without them they are solved from ``seed``
        (inverse kinematics, ``grasptwist.engine.ik.place_hand``).
    home : (3, 4, 4) array, optional
        Each finger's tip pose at home (``home_at``: an inline finger's on a grasp file's contact); None: a finger given inline is
        unchecked (tip error NaN), its tip point taken where its sphere's centre is now.

    Returns
    -------
    Placement

    Examples
    --------
    >>> from grasptwist.hand import Finger, Hand, Joint
    >>> slide = (Joint("x", "prismatic", None, None, None, None),)
    >>> f = Finger("a", "tip", slide, np.array([[0, 0, 0, 1.0, 0, 0]]), np.zeros((1, 3)), np.eye(4), 2.0, (0,))
    >>> p = place(Hand((f, f, f), ("x",), None, None), np.eye(3) * 0.5, -np.eye(3), [0.5])
    >>> p.ik.tip_error.round(4).tolist(), p.centers[1].tolist()  # every tip at x = 0.5: on contact 0 only
    ([0.0, 0.7071, 0.7071], [0.0, 0.5, 0.0])
    """
    radii = tip_radii(hand)
    points, normals = np.asarray(points, dtype=float), np.asarray(normals, dtype=float)
    centers = tip_centers(points, normals, radii)
    ik = place_hand(hand, centers, positions, seed=seed, tips=home)
    at_home = home_tips(hand, centers) if home is None else np.asarray(home, dtype=float)
    return Placement(hand, ik, centers, at_home, points, normals, radii)
