"""Hands, joint rates and inverse kinematics: the public entry points.

A hand is three fingers, each a serial chain of joint screws in the grasp's
frame (:class:`Hand`).  The math lives in ``grasptwist.engine.kinematics``,
``grasptwist.engine.hands`` and ``grasptwist.engine.ik``, URDF reading in
``grasptwist.io.urdf``; this module gathers them.

>>> import numpy as np
>>> from grasptwist import hand
>>> h = hand.load_urdf_hand("package://robot_properties_fingers/urdf/pro/trifingerpro.urdf",
...                         ["finger_tip_link_0", "finger_tip_link_120", "finger_tip_link_240"])
>>> states = hand.finger_states(h, np.zeros((5, 9)))  # 5 configurations of the 9 joints
>>> states[0].screws.shape, states[0].tip.shape
((5, 3, 6), (5, 4, 4))
"""

from __future__ import annotations

from .engine.collision import COLLISION_TOL
from .engine.fingertips import TipContacts, sphere_radius, tip_centers, tip_contacts, tip_radii
from .engine.hands import (
    SEGMENT_INTERVALS,
    HandTrack,
    finger_states,
    joint_positions,
    tip_poses,
    track,
    velocity_limits,
)
from .engine.ik import IK_TOL, HandIK, hand_ik, home_tips, place_hand
from .engine.kinematics import (
    FOLLOW_TOL,
    OFF_TANGENT_FIXED,
    RANK_TOL,
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
from .io.urdf import load_urdf_hand
from .model import Finger, Hand, HandPlacement, Joint
from .run.collisions import (
    Collision,
    EnvironmentHit,
    Overlap,
    finger_collisions,
    hand_checks_along,
    hand_constraints,
    with_collisions,
)
from .run.placement import place_grasp

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
    "tip_radii",
    "tip_centers",
    "tip_contacts",
    "TipContacts",
    "tip_poses",
    "sphere_radius",
    "SEGMENT_INTERVALS",
    "joint_screw",
    "finger_jacobian",
    "joint_rates",
    "component_joint_rates",
    "velocity_limit_ratio",
    "forward_kinematics",
    "JointRates",
    "ChainState",
    "hand_ik",
    "place_hand",
    "place_grasp",
    "HandPlacement",
    "home_tips",
    "HandIK",
    "IK_TOL",
    "RANK_TOL",
    "FOLLOW_TOL",
    "OFF_TANGENT_FIXED",
    "TANGENT_FIXED",
    "finger_collisions",
    "Collision",
    "hand_checks_along",
    "Overlap",
    "EnvironmentHit",
    "with_collisions",
    "hand_constraints",
    "COLLISION_TOL",
]
