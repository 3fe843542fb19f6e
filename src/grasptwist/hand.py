"""Hands, joint rates and inverse kinematics: the public entry points.

A hand is three fingers, each a serial chain of joint screws in the grasp's
frame (:class:`Hand`).  The math lives in ``grasptwist.engine.kinematics``,
``grasptwist.engine.hands``, ``grasptwist.engine.ik`` and ``grasptwist.engine.placement``
(:func:`place`: a hand put on its contacts, the one placement every command uses), URDF
reading in ``grasptwist.io.urdf``; this module gathers them, and imports nothing that runs the
command line: a grasp file's hand placed and its fingers checked as every command does is the
core's (:func:`grasptwist.place_grasp`, :func:`grasptwist.finger_collisions`).

>>> import numpy as np
>>> from grasptwist import hand
>>> h = hand.load_urdf_hand("package://robot_properties_fingers/urdf/pro/trifingerpro.urdf",
...                         ["finger_tip_link_0", "finger_tip_link_120", "finger_tip_link_240"])
>>> states = hand.finger_states(h, np.zeros((5, 9)))  # 5 configurations of the 9 joints
>>> states[0].screws.shape, states[0].tip.shape
((5, 3, 6), (5, 4, 4))
"""

from __future__ import annotations

from ._moved import topic_getattr
from .engine.fingertips import TipContacts, tip_centers, tip_contacts, tip_radii
from .engine.hands import SEGMENT_INTERVALS, HandTrack, finger_states, joint_positions, track, velocity_limits
from .engine.ik import IK_TOL, HandIK, hand_ik, home_tips
from .engine.kinematics import (
    FOLLOW_TOL,
    OFF_TANGENT_FIXED,
    TANGENT_FIXED,
    ChainState,
    JointRates,
    component_joint_rates,
    finger_jacobian,
    forward_kinematics,
    joint_rates,
    joint_screw,
    velocity_limit_ratio,
)
from .engine.placement import Placement, place
from .io.urdf import load_urdf_hand
from .model import Finger, Hand, Joint

__all__ = [
    "Hand",
    "Finger",
    "Joint",
    "load_urdf_hand",
    "joint_positions",
    "finger_states",
    "velocity_limits",
    "HandTrack",
    "track",
    "SEGMENT_INTERVALS",
    "tip_radii",
    "tip_centers",
    "tip_contacts",
    "TipContacts",
    "joint_screw",
    "finger_jacobian",
    "joint_rates",
    "component_joint_rates",
    "velocity_limit_ratio",
    "forward_kinematics",
    "JointRates",
    "ChainState",
    "FOLLOW_TOL",
    "OFF_TANGENT_FIXED",
    "TANGENT_FIXED",
    "hand_ik",
    "HandIK",
    "IK_TOL",
    "home_tips",
    "place",
    "Placement",
]

#: The names that moved out (a grasp file's hand placed and checked: ``grasptwist.place_grasp``, ...)
#: or went (tolerances, internal now), deprecated aliases for a release (``grasptwist/_moved.py``).
__getattr__ = topic_getattr(__name__)
