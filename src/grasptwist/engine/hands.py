"""A hand's joint positions, finger states and joint-rate tracks along a path.

A hand is three fingers, each a serial chain of joint screws in the grasp's
frame (:class:`~grasptwist.model.Hand`); the per-finger math is in
:mod:`.kinematics` and :mod:`.tracking`.  The public entry point is
:mod:`grasptwist.hand`, which re-exports these.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .fingertips import tip_centers, tip_radii
from .kinematics import ChainState, forward_kinematics
from .segments import check_segments
from .tracking import FingerTrack, track_fingers

__all__ = [
    "joint_positions",
    "finger_states",
    "tip_poses",
    "velocity_limits",
    "padded",
    "padded_positions",
    "HandTrack",
    "track",
    "SEGMENT_INTERVALS",
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

    Examples
    --------
    >>> from grasptwist.hand import Hand
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


def tip_poses(hand, positions, tips):
    """Each finger's tip link pose at joint positions, ``(..., 3, 4, 4)``.

    .. math:: \\mathrm{tip}_f(q) = g_f(q)\\, M_f

    (:func:`~grasptwist.hand.forward_kinematics`), ``M_f`` row ``f``
    of ``tips``: the tip link's pose at home, or for a finger given inline the
    frame its tip point is carried by (:func:`~grasptwist.hand.home_tips`).

    Parameters
    ----------
    hand : Hand
    positions : (..., n_joints) array
    tips : (3, 4, 4) array

    Returns
    -------
    (..., 3, 4, 4) array

    Examples
    --------
    >>> from grasptwist.hand import Finger, Hand, Joint
    >>> f = Finger("1", None, (Joint("x", "prismatic", None, None, None, None),), np.array([[0, 0, 0, 1.0, 0, 0]]), np.zeros((1, 3)), None, 1.0, (0,))
    >>> tip_poses(Hand((f, f, f), ("x",), None, None), [[2.0]], np.eye(4)[None].repeat(3, 0))[0, :, 0, 3].tolist()
    [2.0, 2.0, 2.0]
    """
    positions = np.asarray(positions, dtype=float)
    tips = np.asarray(tips, dtype=float)
    poses = [
        forward_kinematics(f.screws, f.points, tips[i], positions[..., list(f.joint_index)]).tip
        for i, f in enumerate(hand.fingers)
    ]
    return np.stack(poses, axis=-3)


def velocity_limits(finger):
    """A finger's joint velocity limits, NaN for a joint without one: ``(n,)``.

    >>> from grasptwist.hand import Finger, Joint
    >>> j = [Joint("a", "revolute", 2.0, None, None, None), Joint("b", "revolute", None, None, None, None)]
    >>> velocity_limits(Finger("1", None, tuple(j), None, None, None, 1.0, (0, 1))).tolist()
    [2.0, nan]
    """
    return np.array([np.nan if j.velocity_limit is None else j.velocity_limit for j in finger.joints], dtype=float)


def padded(hand, screws, width=None):
    """A hand's joint screws and velocity limits as arrays of one shape, padded to ``width`` joints.

    A finger with fewer joints gets zero screws (no motion: they change no
    rank, rate or residual) with no limit.

    Parameters
    ----------
    hand : Hand
    screws : sequence of 3 (..., n_f, 6) arrays
        Each finger's joint screws at its configurations (e.g. the
        ``screws`` of :func:`finger_states`).
    width : int, optional
        Joints per finger after padding; default the longest finger's.

    Returns
    -------
    joint_screws : (..., 3, width, 6) array
    limits : (3, width) array
        NaN where a joint has no limit, and in the padding.

    >>> from grasptwist.model import Finger, Hand, Joint
    >>> h = Hand((Finger("1", None, (Joint("a", "revolute", 2.0, None, None, None),), None, None, None, 1.0, (0,)),) * 3, ("a",), None, None)
    >>> s, limits = padded(h, [np.ones((5, 1, 6))] * 3, width=2)
    >>> s.shape, limits[0].tolist()
    ((5, 3, 2, 6), [2.0, nan])
    """
    width = max(len(f.joints) for f in hand.fingers) if width is None else width
    lead = np.broadcast_shapes(*(np.shape(s)[:-2] for s in screws))
    out = np.zeros(lead + (3, width, 6))
    limits = np.full((3, width), np.nan)
    for f, (finger, s) in enumerate(zip(hand.fingers, screws, strict=True)):
        n = len(finger.joints)
        out[..., f, :n, :] = s
        limits[f, :n] = velocity_limits(finger)
    return out, limits


class HandTrack(NamedTuple):
    """A hand following its grasp's contacts along a path (see :func:`track`).

    Attributes
    ----------
    positions : (T, n_joints)
        Joint positions at the sample times, in ``hand.joint_names`` order.
    fingers : tuple of FingerTrack
        Each finger's track (its own joints), in contact order.
    """

    positions: np.ndarray
    fingers: tuple[FingerTrack, ...]


def padded_positions(hand, positions, width=None):
    """A hand's joint positions per finger, ``(..., 3, width)``, NaN in the padding (as :func:`padded`).

    Parameters
    ----------
    hand : Hand
    positions : (..., n_joints) array
        In ``hand.joint_names`` order.
    width : int, optional
        Joints per finger; default the longest finger's.

    >>> from grasptwist.model import Finger, Hand, Joint
    >>> j = Joint("a", "revolute", None, None, None, None)
    >>> h = Hand(tuple(Finger(str(f), None, (j,) * (f + 1), None, None, None, 1.0, tuple(range(f * (f + 1) // 2, (f + 1) * (f + 2) // 2))) for f in range(3)), tuple("abcdef"), None, None)
    >>> padded_positions(h, np.arange(6.0))[1].tolist()
    [1.0, 2.0, nan]
    """
    positions = np.asarray(positions, dtype=float)
    width = max(len(f.joints) for f in hand.fingers) if width is None else width
    out = np.full(positions.shape[:-1] + (3, width), np.nan)
    for f, finger in enumerate(hand.fingers):
        out[..., f, : len(finger.joints)] = positions[..., list(finger.joint_index)]
    return out


def _limits(finger, which):
    """A finger's lower or upper joint position limits, NaN where none: ``(n,)``."""
    return np.array([np.nan if getattr(j, which) is None else getattr(j, which) for j in finger.joints], dtype=float)


#: :func:`track` integrates each segment over at least this many intervals, by
#: Runge-Kutta steps no longer than ``1 / steps`` of an interval (at least one
#: between samples), however few or many the samples: the tip's error and the
#: events' times do not depend on the sampling, and dense samples cost one step each.
SEGMENT_INTERVALS = 4


def track(hand, positions, points, segments, times, *, normals=None, steps=16) -> HandTrack:
    """Every finger keeping its tip on its contact while the object follows a path.

    Finger ``f`` follows contact ``f`` by :func:`grasptwist.path.track_finger`
    (resolved rates with forward-kinematics feedback), from ``positions``
    and within its joints' position limits.  A fingertip with a radius
    ``r`` rolls: the contact stays fixed on the object, so the sphere's
    centre (the tip link's origin) tracks ``p(t) - r n(t)``, a point the
    object carries, and the contact moves over the fingertip
    (:func:`~grasptwist.hand.tip_contacts`).  A finger given inline has no
    tip link: the point it tracks is the one it touches at ``t = 0``.  The
    integration's grid holds the sample times and
    :data:`SEGMENT_INTERVALS` equal intervals of each segment.

    Parameters
    ----------
    hand : Hand
    positions : (n_joints,) array or None
        Joint positions at ``t = 0`` (None: every joint at 0).
    points : (3, 3) array
        The contacts at ``t = 0``, row ``f`` touched by finger ``f``.
    segments : sequence of Segment
    times : (T,) array
        Increasing sample times.
    normals : (3, 3) array, optional
        The contacts' normals at ``t = 0``, into the object: needed for fingertips with a radius.
    steps : int
        Runge-Kutta steps per interval of :data:`SEGMENT_INTERVALS`: steps are
        no longer than ``1 / (SEGMENT_INTERVALS * steps)`` of their segment.

    Returns
    -------
    HandTrack

    Examples
    --------
    >>> from grasptwist.hand import Finger, Hand, Joint
    >>> from grasptwist.path import Segment
    >>> slides = np.hstack((np.zeros((3, 3)), np.eye(3)))  # a Cartesian finger follows anything
    >>> f = Finger("1", None, tuple(Joint(n, "prismatic", None, None, None, None) for n in "xyz"), slides, np.zeros((3, 3)), None, 1.0, (0, 1, 2))
    >>> h = Hand((f, f, f), ("x", "y", "z"), None, None)
    >>> t = track(h, None, np.eye(3), [Segment(1.0, twist=[0, 0, 0, 0.5, 0, 0])], [0.0, 1.0], steps=1)
    >>> (t.positions[-1].round(12) + 0.0).tolist()
    [0.5, 0.0, 0.0]
    """
    q0 = np.zeros(len(hand.joint_names)) if positions is None else np.asarray(positions, dtype=float)
    radii = tip_radii(hand)
    if normals is None and radii.any():
        raise ValueError("normals: needed for fingertips with a radius (their centres sit at p - r n)")
    points = tip_centers(points, normals, radii)  # the points the fingers keep on the object
    times = np.asarray(times, dtype=float)
    ends = np.cumsum([0.0] + [s.duration for s in check_segments(segments)])
    extra = np.concatenate([np.linspace(a, b, SEGMENT_INTERVALS + 1)[1:-1] for a, b in zip(ends[:-1], ends[1:])])
    if times.size:  # none within round-off of a sample time or a boundary (no step of length ~0)
        near = np.concatenate((times, ends))
        gap = np.abs(extra[:, None] - near[None, :]).min(axis=1)
        extra = extra[(gap > 1e-9 * ends[-1]) & (extra < times[-1])]
    grid = np.union1d(times, extra)
    rows = np.searchsorted(grid, times)
    out = np.tile(q0, (len(times), 1))
    fingers = [None] * len(hand.fingers)
    sizes = [len(finger.joint_index) for finger in hand.fingers]
    for n in sorted(set(sizes)):  # the fingers of n joints step together, in one batch
        group = [f for f, size in enumerate(sizes) if size == n]
        chains = [_chain(hand.fingers[f], points[f]) for f in group]
        index = [list(hand.fingers[f].joint_index) for f in group]
        tracks = track_fingers(
            *(np.array(a, dtype=float) for a in zip(*chains)),
            np.array([q0[i] for i in index]).reshape(len(group), n),
            points[group],
            segments,
            grid,
            lower=np.array([_limits(hand.fingers[f], "lower") for f in group]).reshape(len(group), n),
            upper=np.array([_limits(hand.fingers[f], "upper") for f in group]).reshape(len(group), n),
            segment_steps=SEGMENT_INTERVALS * steps,
        )
        for f, i, got in zip(group, index, tracks):
            fingers[f] = got._replace(**{k: getattr(got, k)[rows] for k in _PER_SAMPLE})
            out[:, i] = fingers[f].positions
    return HandTrack(out, tuple(fingers))


def _chain(finger, point):
    """A finger's home screws, points and tip pose; a finger given inline has no tip link: its tip
    is its contact's point at ``t = 0``, unturned."""
    tip = finger.tip_pose
    if tip is None:
        tip = np.eye(4)
        tip[:3, 3] = point
    return finger.screws, finger.points, tip


#: The fields of a FingerTrack that hold one row per grid time.
_PER_SAMPLE = ("time", "positions", "rates", "rank", "conditioning", "error")
