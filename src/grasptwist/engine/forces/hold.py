r"""Holding a weight along an object path: the grip at each pose, and where none exists.

The object moves, gravity does not.  At the pose ``(R, x)`` the centre of mass is at
``c(t) = R c_0 + x`` and the fingers, moved with the object, must exert

.. math:: w(t) = \left(-m g;\; -c(t) \times m g\right)

(``g`` fixed in space), so the wrench seen from the object turns as the object turns
and the grip changes along the path.  :func:`grip_along` solves it at given times;
:func:`cannot_hold` finds the stretches of the path where no grip exists, between the
samples, to ``1e-10`` of the shortest segment's duration, as
:func:`grasptwist.engine.path.degeneracies` finds degenerate stretches.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .. import se3
from ..degeneracy import DEGENERACY_TOL
from ..path import Poses, check_segments, integrate
from ..screws import cross
from .grasp_map import ForceStatus
from .grip import Grip, grip

__all__ = ["HoldStretch", "hold_wrench", "grip_along", "cannot_hold", "PRECISION"]

#: Stretch ends are located to this fraction of the shortest segment's duration.
PRECISION = 1e-10


class HoldStretch(NamedTuple):
    """A stretch of a path where no grip holds the weight.

    Attributes
    ----------
    t_start, t_end : float
        Where ``cannot-hold`` starts and ends (the path's ends when it holds there).
    culprit : int
        Just after ``t_start`` (a millionth of the stretch in): the contact whose friction
        cone is too narrow, or -1 when the weight needs a finger to pull.
    """

    t_start: float
    t_end: float
    culprit: int


def hold_wrench(mass, center_of_mass, gravity, rotation=None, position=None) -> np.ndarray:
    r"""The wrench that balances a weight: ``(-m g; -c x m g)``, ``c`` the centre of mass at the pose.

    .. math:: c = R c_0 + x, \qquad w = \left(-m g;\; -c \times m g\right)

    Parameters
    ----------
    mass : float
    center_of_mass, gravity : (3,) arrays
        The centre of mass at ``t = 0`` and gravity, fixed in space.
    rotation, position : (..., 3, 3), (..., 3) arrays or None
        The object's poses (None: at rest).

    Returns
    -------
    (..., 6) array

    Examples
    --------
    A 1 kg weight a metre along x: the fingers lift it and make up its moment;
    turned a half turn about z, the moment changes sign, the force does not.

    >>> hold_wrench(1.0, [1, 0, 0], [0, 0, -9.81]).tolist()
    [0.0, 0.0, 9.81, 0.0, -9.81, 0.0]
    >>> hold_wrench(1.0, [1, 0, 0], [0, 0, -9.81], np.diag([-1.0, -1, 1]), [0, 0, 0]).round(12).tolist()
    [0.0, 0.0, 9.81, 0.0, 9.81, 0.0]
    """
    c = np.asarray(center_of_mass, dtype=float)
    if rotation is not None:
        c = se3.transform(rotation, position, c)
    weight = float(mass) * np.asarray(gravity, dtype=float)
    moment = cross(c, weight)
    return 0.0 - np.concatenate((np.broadcast_to(weight, moment.shape), moment), axis=-1)  # 0.0 -: no -0.0


def grip_along(
    points, normals, friction, mass, center_of_mass, gravity, segments, times, *, safety=1.0, tol=DEGENERACY_TOL
) -> tuple[Poses, Grip]:
    """The grip that holds the weight at each time of a path.

    Parameters
    ----------
    points, normals : (3, 3) arrays
        The grasp at ``t = 0``.
    friction : scalar or (3,) array
    mass, center_of_mass, gravity
        As :func:`hold_wrench`.
    segments : sequence of Segment
    times : (T,) array-like
    safety : float
        As for :func:`grip`.
    tol : float
        Degeneracy tolerance of the contacts.

    Returns
    -------
    (Poses, Grip)
        The poses at ``times`` and the grip of the moved grasp there, ``(T, ...)``.

    Examples
    --------
    A tray (contacts on its underside, normals up) carrying 1 kg at its centroid, with
    ``mu = 0.5``: level, each contact takes a third; tilted by ``atan(0.5)`` about x, every
    contact uses all of its friction; past it, the weight slides off.

    >>> from grasptwist.path import Segment
    >>> p = [[1, 0, 0], [-0.5, 0.75**0.5, 0], [-0.5, -(0.75**0.5), 0]]
    >>> turn = [Segment(1.0, twist=[1, 0, 0, 0, 0, 0])]
    >>> poses, g = grip_along(p, [[0, 0, 1]] * 3, 0.5, 1.0, [0, 0, 0], [0, 0, -9.81], turn, [0, np.arctan(0.5) - 1e-9, 0.5])
    >>> g.normal_force[0].round(4).tolist(), g.friction_used[1].round(6).tolist(), g.status.tolist()
    ([3.27, 3.27, 3.27], [0.5, 0.5, 0.5], [0, 0, 20])
    """
    poses = integrate(segments, times)
    p, n = np.asarray(points, dtype=float), np.asarray(normals, dtype=float)
    moved = se3.transform(poses.rotation[..., None, :, :], poses.position[..., None, :], p)
    turned = np.einsum("...ij,kj->...ki", poses.rotation, n)
    wrench = hold_wrench(mass, center_of_mass, gravity, poses.rotation, poses.position)
    return poses, grip(moved, turned, wrench, friction, safety=safety, tol=tol)


def cannot_hold(
    points,
    normals,
    friction,
    mass,
    center_of_mass,
    gravity,
    segments,
    times=None,
    *,
    safety=1.0,
    tol=DEGENERACY_TOL,
) -> tuple[HoldStretch, ...]:
    """Every stretch of a path where no grip holds the weight, its ends located between samples.

    The grip's status is evaluated at the samples ``times`` and the segments' ends; each
    run of ``cannot-hold`` is widened to where it starts and ends by bisection between
    its first (last) node and the held node before (after) it, every end at once, to
    ``1e-10`` (``PRECISION``) of the shortest segment's duration.  A stretch shorter than the
    sampling, between two held nodes, is not seen.  A grasp the grip cannot solve at
    all (degenerate contacts, ``status`` other than ``cannot-hold``) has no stretches:
    the path's degeneracies report it.

    Parameters
    ----------
    points, normals, friction, mass, center_of_mass, gravity, segments, safety, tol
        As for :func:`grip_along`.
    times : (T,) array-like or None
        The samples; None: the segments' ends only.

    Returns
    -------
    tuple of HoldStretch
        Ordered by ``t_start``.

    Examples
    --------
    The tray of :func:`grip_along` turned a full turn about x: it holds until it is
    tilted by ``atan(mu)``, and again from ``2 pi - atan(mu)``.

    >>> from grasptwist.path import Segment
    >>> p = [[1, 0, 0], [-0.5, 0.75**0.5, 0], [-0.5, -(0.75**0.5), 0]]
    >>> turn = [Segment(2 * np.pi, twist=[1, 0, 0, 0, 0, 0])]
    >>> (s,) = cannot_hold(p, [[0, 0, 1]] * 3, 0.5, 1.0, [0, 0, 0], [0, 0, -9.81], turn, np.linspace(0, 2 * np.pi, 9))
    >>> round(s.t_start, 9), round(2 * np.pi - s.t_end, 9), round(float(np.arctan(0.5)), 9)
    (0.463647609, 0.463647609, 0.463647609)
    """
    durations = np.array([s.duration for s in check_segments(segments)])
    ends = np.concatenate(([0.0], np.cumsum(durations)))
    extra = np.empty(0) if times is None else np.asarray(times, dtype=float).ravel()
    nodes = np.unique(np.concatenate((ends, extra)))

    def status(t):
        return grip_along(
            points, normals, friction, mass, center_of_mass, gravity, segments, t, safety=safety, tol=tol
        )[1]

    at = status(nodes)
    fails = at.status == ForceStatus.CANNOT_HOLD
    if not fails.any():
        return ()
    where = np.flatnonzero(fails)
    runs = np.split(where, np.flatnonzero(np.diff(where) > 1) + 1)
    first, last = np.array([r[0] for r in runs]), np.array([r[-1] for r in runs])
    # Bracket each inner end between a held node and a failing one; `fails` is False at lo, True at hi
    # for a start, the reverse for an end (flip).
    opens, closes = first[first > 0], last[last < len(nodes) - 1]
    lo = np.concatenate((nodes[opens - 1], nodes[closes]))
    hi = np.concatenate((nodes[opens], nodes[closes + 1]))
    flip = np.arange(lo.size) >= opens.size
    eps = PRECISION * durations.min()
    for _ in range(int(np.max(np.ceil(np.log2(np.maximum((hi - lo) / eps, 1))), initial=0))):
        mid = 0.5 * (lo + hi)
        up = (status(mid).status == ForceStatus.CANNOT_HOLD) != flip
        lo, hi = np.where(up, lo, mid), np.where(up, mid, hi)
    starts = dict(zip(opens.tolist(), hi[: opens.size].tolist()))
    stops = dict(zip(closes.tolist(), lo[opens.size :].tolist()))
    t_start = np.array([starts.get(i, 0.0) for i in first.tolist()])
    t_end = np.array([stops.get(k, float(ends[-1])) for k in last.tolist()])
    # the reason a little inside (at the located start the grip is within round-off of existing)
    culprit = status(t_start + 1e-6 * (t_end - t_start)).culprit
    return tuple(HoldStretch(float(a), float(b), int(c)) for a, b, c in zip(t_start, t_end, culprit))
