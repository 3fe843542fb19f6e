"""Hands and joint rates: the public entry points.

A hand is three fingers, each a serial chain of joint screws in the grasp's
frame (:class:`~grasptwist.model.Hand`).  The math lives in
:mod:`grasptwist.engine.kinematics`, URDF reading in :mod:`grasptwist.io.urdf`;
this module gathers them.

>>> import numpy as np
>>> from grasptwist import hand
>>> h = hand.load_urdf_hand("package://robot_properties_fingers/urdf/pro/trifingerpro.urdf",
...                         ["finger_tip_link_0", "finger_tip_link_120", "finger_tip_link_240"])
>>> states = hand.finger_states(h, np.zeros((5, 9)))  # 5 configurations of the 9 joints
>>> states[0].screws.shape, states[0].tip.shape
((5, 3, 6), (5, 4, 4))
"""

from __future__ import annotations

import numpy as np

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
from .model import Finger, Hand, Joint

__all__ = [
    "Hand",
    "Finger",
    "Joint",
    "load_urdf_hand",
    "joint_positions",
    "finger_states",
    "velocity_limits",
    "padded",
    "joint_screw",
    "finger_jacobian",
    "joint_rates",
    "component_joint_rates",
    "velocity_limit_ratio",
    "forward_kinematics",
    "JointRates",
    "ChainState",
    "RANK_TOL",
    "FOLLOW_TOL",
    "OFF_TANGENT_FIXED",
    "TANGENT_FIXED",
]


def joint_positions(hand, values):
    """A hand's joint-position vector from a mapping ``{joint name: position}``.

    Joints not named are at 0.

    Parameters
    ----------
    hand : Hand
    values : mapping of str to float

    Returns
    -------
    (n_joints,) array, in ``hand.joint_names`` order.

    Raises
    ------
    ValueError
        A name that is none of the hand's joints.

    >>> from grasptwist.model import Hand
    >>> joint_positions(Hand((), ("a", "b"), None, None), {"b": 0.5}).tolist()
    [0.0, 0.5]
    """
    index = {name: i for i, name in enumerate(hand.joint_names)}
    out = np.zeros(len(index))
    for name, value in values.items():
        if name not in index:
            raise ValueError(f"values: {name!r} is not a joint of the hand's fingers ({', '.join(hand.joint_names)})")
        out[index[name]] = value
    return out


def finger_states(hand, positions=None):
    """Each finger's joint screws, joint points and tip pose at joint positions.

    Parameters
    ----------
    hand : Hand
    positions : (..., n_joints) array, optional
        In ``hand.joint_names`` order; None: the home configuration.

    Returns
    -------
    tuple of ChainState
        One per finger, batch shape ``(...)``.
    """
    if positions is None:
        return tuple(ChainState(f.screws, f.points, f.tip_pose) for f in hand.fingers)
    positions = np.asarray(positions, dtype=float)
    if positions.shape[-1:] != (len(hand.joint_names),):
        raise ValueError(f"positions must have shape (..., {len(hand.joint_names)}), got {positions.shape}")
    return tuple(
        forward_kinematics(f.screws, f.points, f.tip_pose, positions[..., list(f.joint_index)]) for f in hand.fingers
    )


def velocity_limits(finger):
    """A finger's joint velocity limits, NaN for a joint without one: ``(n,)``.

    >>> from grasptwist.model import Finger, Joint
    >>> j = [Joint("a", "revolute", 2.0, None, None, None), Joint("b", "revolute", None, None, None, None)]
    >>> velocity_limits(Finger("1", None, tuple(j), None, None, None, 1.0, (0, 1))).tolist()
    [2.0, nan]
    """
    return np.array([np.nan if j.velocity_limit is None else j.velocity_limit for j in finger.joints], dtype=float)


def padded(hands, screws):
    """Rows of hands as arrays of one shape: joint screws and velocity limits, padded to ``J``.

    ``J`` is the longest finger's joint count; a shorter finger's extra joints
    are zero screws (no motion: they change no rank, rate or residual) with no
    limit.  Rows without a hand are all padding.

    Parameters
    ----------
    hands : sequence of Hand or None
        One per row.
    screws : sequence of (tuple of 3 (n_f, 6) arrays) or None
        Each row's fingers' joint screws at its configuration (e.g.
        :func:`finger_states`), None where the row has no hand.

    Returns
    -------
    joint_screws : (N, 3, J, 6) array
    limits : (N, 3, J) array
        NaN where a joint has no limit, and in the padding.

    >>> h = Hand((Finger("1", None, (Joint("a", "revolute", 2.0, None, None, None),), None, None, None, 1.0, (0,)),) * 3, ("a",), None, None)
    >>> s, lim = padded([h, None], [(np.ones((1, 6)),) * 3, None])
    >>> s.shape, lim[:, 0].tolist()
    ((2, 3, 1, 6), [[2.0], [nan]])
    """
    width = max((len(f.joints) for h in hands if h is not None for f in h.fingers), default=0)
    out = np.zeros((len(hands), 3, width, 6))
    limits = np.full((len(hands), 3, width), np.nan)
    for i, (hand, fingers) in enumerate(zip(hands, screws, strict=True)):
        if hand is None:
            continue
        for f, (finger, s) in enumerate(zip(hand.fingers, fingers, strict=True)):
            out[i, f, : len(s)] = s
            limits[i, f, : len(s)] = velocity_limits(finger)
    return out, limits
