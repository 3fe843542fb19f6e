r"""Holding a weight along an object path: the grip at each pose, and where none exists.

The object moves, gravity does not.  At the pose ``(R, x)`` the centre of mass is at
``c(t) = R c_0 + x`` and the fingers, moved with the object, must exert

.. math:: w(t) = \left(-m g;\; -c(t) \times m g\right)

(``g`` fixed in space), so the wrench seen from the object turns as the object turns
and the grip changes along the path.  :func:`grip_along` solves it at given times;
:func:`cannot_hold` finds the stretches of the path where no grip exists, between the
samples, to ``1e-10`` of the shortest segment's duration, as
:func:`grasptwist.engine.path.degeneracies` finds degenerate stretches; :func:`hold_verdicts`
adds the stretches where the grip fails for another reason (an overflowing pose, degenerate
contacts), where whether the weight is held cannot be judged.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .. import se3
from ..degeneracy import DEGENERACY_TOL
from ..objects import mass_properties
from ..path import Poses, integrate, overflowing, pose_overflowed
from ..screws import cross
from ..segments import check_segments
from .grasp_map import ForceStatus
from .grip import Grip, grip

__all__ = [
    "HoldStretch",
    "Unjudged",
    "Weight",
    "hold_wrench",
    "object_weight",
    "grip_along",
    "cannot_hold",
    "hold_verdicts",
    "PRECISION",
]

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


class Unjudged(NamedTuple):
    """A stretch of a path where the grip fails for a reason of its own, so that
    whether the weight is held cannot be judged there.

    Attributes
    ----------
    t_start, t_end : float
        Where the failure starts and ends, located as :class:`HoldStretch`'s ends are.
    status : int
        The grip's :class:`~grasptwist.engine.forces.grasp_map.ForceStatus` just after
        ``t_start`` (``nonfinite-pose`` where the pose overflows).
    """

    t_start: float
    t_end: float
    status: int


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


class Weight(NamedTuple):
    """An object's weight as the fingers hold it (:func:`object_weight`).

    Attributes
    ----------
    mass : float
    center_of_mass, gravity : (3,) arrays
        In the grasp frame.
    wrench : (6,) array
        :func:`hold_wrench` of the three.
    """

    mass: float
    center_of_mass: np.ndarray
    gravity: np.ndarray
    wrench: np.ndarray


def object_weight(obj, gravity) -> Weight | None:
    r"""The weight of an object (its ``mass``, or ``density`` times its volume, at its centre of mass) and
    the wrench that holds it, :func:`hold_wrench`; None when the object has neither mass nor density.

    .. math:: w = \left(-m g;\; -c \times m g\right)

    Parameters
    ----------
    obj : GraspObject
    gravity : (3,) array

    Returns
    -------
    Weight or None

    Examples
    --------
    >>> from grasptwist.objects import GraspObject, Shape
    >>> pose = np.eye(4)
    >>> pose[:3, 3] = [1.0, 0, 0]
    >>> ball = GraspObject(Shape("sphere", np.array([0.05])), pose, mass=1.0)
    >>> object_weight(ball, [0, 0, -9.81]).wrench.tolist()
    [0.0, 0.0, 9.81, 0.0, -9.81, 0.0]
    >>> object_weight(GraspObject(Shape("sphere", np.array([0.05])), pose), [0, 0, -9.81]) is None
    True
    """
    props = mass_properties(obj)
    if props.mass is None:
        return None
    g = np.asarray(gravity, dtype=float)
    return Weight(float(props.mass), props.center_of_mass, g, hold_wrench(props.mass, props.center_of_mass, g))


def grip_along(
    points,
    normals,
    friction,
    mass,
    center_of_mass,
    gravity,
    segments,
    times,
    *,
    safety=1.0,
    torsion=None,
    tol=DEGENERACY_TOL,
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
    torsion : None, scalar or (3,) array
        Soft contacts' torsional radii, as for :func:`grip` (None: point contacts).
    tol : float
        Degeneracy tolerance of the contacts.

    Returns
    -------
    (Poses, Grip)
        The poses at ``times`` and the grip of the moved grasp there, ``(T, ...)``
        (``nonfinite-pose`` where the pose overflows double precision).

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
    held = grip(moved, turned, wrench, friction, safety=safety, torsion=torsion, tol=tol)
    lost = overflowing(poses, np.concatenate((p, n)), np.concatenate((moved, turned), axis=-2))
    return poses, pose_overflowed(held, lost)


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
    torsion=None,
    tol=DEGENERACY_TOL,
) -> tuple[HoldStretch, ...]:
    """Every stretch of a path where no grip holds the weight, its ends located between samples.

    The grip's status is evaluated at the samples ``times`` and the segments' ends; each
    run of ``cannot-hold`` is widened to where it starts and ends by bisection between
    its first (last) node and the held node before (after) it, every end at once, to
    ``1e-10`` (``PRECISION``) of the shortest segment's duration.  A stretch shorter than the
    sampling, between two held nodes, is not seen.  A grasp the grip cannot solve at
    all (degenerate contacts, ``status`` other than ``cannot-hold``) has no stretches: a
    path's summary lists those as ``hold_unjudged``, and its degeneracies say why.

    Parameters
    ----------
    points, normals, friction, mass, center_of_mass, gravity, segments, safety, torsion, tol
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
    weight = (points, normals, friction, mass, center_of_mass, gravity, segments)
    return _Verdicts(weight, times, safety, tol, torsion).cannot_hold()


def hold_verdicts(
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
    torsion=None,
    tol=DEGENERACY_TOL,
) -> tuple[tuple[HoldStretch, ...], tuple[Unjudged, ...]]:
    """Where the weight is not held along a path, and where that cannot be judged.

    The stretches of :func:`cannot_hold`, and beside them, located the same way, the
    stretches where the grip fails for another reason (a status other than ``ok`` and
    ``cannot-hold``: the pose overflows, the moved contacts are degenerate), each with the
    status it has just inside.  A path is held all along only where both are empty.

    Parameters
    ----------
    points, normals, friction, mass, center_of_mass, gravity, segments, times, safety, torsion, tol
        As for :func:`cannot_hold`.

    Returns
    -------
    (tuple of HoldStretch, tuple of Unjudged)
        Each ordered by ``t_start``.

    Examples
    --------
    A tray spun at ``1e300`` rad/s turns through more than the float range at once (its
    pose overflows, from ``1e-10`` of the path's duration on): it is nowhere known to fall,
    and nowhere known to be held.

    >>> from grasptwist.path import Segment
    >>> p = [[1, 0, 0], [-0.5, 0.75**0.5, 0], [-0.5, -(0.75**0.5), 0]]
    >>> spin = [Segment(1.0, twist=[0, 0, 1e300, 0, 0, 0])]
    >>> with np.errstate(over="ignore", invalid="ignore"):  # the overflow is the point
    ...     falls, (u,) = hold_verdicts(p, [[0, 0, 1]] * 3, 0.5, 1.0, [0, 0, 0], [0, 0, -9.81], spin, [0, 0.5, 1])
    >>> falls, ForceStatus(u.status).code, round(u.t_start, 9), u.t_end
    ((), 'nonfinite-pose', 0.0, 1.0)
    """
    weight = (points, normals, friction, mass, center_of_mass, gravity, segments)
    verdicts = _Verdicts(weight, times, safety, tol, torsion)
    return verdicts.cannot_hold(), verdicts.unjudged()


class _Verdicts:
    """The grip's status along one path: at its nodes (the samples and the segments'
    ends) once, and the runs of a kind of status located between them."""

    def __init__(self, weight, times, safety, tol, torsion=None):
        self.weight, self.safety, self.tol, self.torsion = weight, safety, tol, torsion
        durations = np.array([s.duration for s in check_segments(weight[-1])])
        self.ends = np.concatenate(([0.0], np.cumsum(durations)))
        self.eps = PRECISION * durations.min()
        extra = np.empty(0) if times is None else np.asarray(times, dtype=float).ravel()
        self.nodes = np.unique(np.concatenate((self.ends, extra)))
        self.at = self.status(self.nodes).status

    def status(self, t) -> Grip:
        return grip_along(*self.weight, t, safety=self.safety, torsion=self.torsion, tol=self.tol)[1]

    def cannot_hold(self) -> tuple[HoldStretch, ...]:
        t_start, t_end = self._runs(lambda s: s == ForceStatus.CANNOT_HOLD)
        # the reason a little inside (at the located start the grip is within round-off of existing)
        culprit = self.status(t_start + 1e-6 * (t_end - t_start)).culprit if t_start.size else ()
        return tuple(HoldStretch(float(a), float(b), int(c)) for a, b, c in zip(t_start, t_end, culprit))

    def unjudged(self) -> tuple[Unjudged, ...]:
        t_start, t_end = self._runs(lambda s: (s != ForceStatus.OK) & (s != ForceStatus.CANNOT_HOLD))
        status = self.status(t_start + 1e-6 * (t_end - t_start)).status if t_start.size else ()
        return tuple(Unjudged(float(a), float(b), int(s)) for a, b, s in zip(t_start, t_end, status))

    def _runs(self, failing) -> tuple[np.ndarray, np.ndarray]:
        """``(t_start, t_end)`` of every run of nodes whose status is ``failing``, each inner
        end bisected between a node that is and one that is not, every end at once."""
        nodes, fails = self.nodes, failing(self.at)
        if not fails.any():
            return np.empty(0), np.empty(0)
        where = np.flatnonzero(fails)
        runs = np.split(where, np.flatnonzero(np.diff(where) > 1) + 1)
        first, last = np.array([r[0] for r in runs]), np.array([r[-1] for r in runs])
        # `fails` is False at lo, True at hi for a start, the reverse for an end (flip).
        opens, closes = first[first > 0], last[last < len(nodes) - 1]
        lo = np.concatenate((nodes[opens - 1], nodes[closes]))
        hi = np.concatenate((nodes[opens], nodes[closes + 1]))
        flip = np.arange(lo.size) >= opens.size
        for _ in range(int(np.max(np.ceil(np.log2(np.maximum((hi - lo) / self.eps, 1))), initial=0))):
            mid = 0.5 * (lo + hi)
            up = failing(self.status(mid).status) != flip
            lo, hi = np.where(up, lo, mid), np.where(up, mid, hi)
        starts = dict(zip(opens.tolist(), hi[: opens.size].tolist()))
        stops = dict(zip(closes.tolist(), lo[opens.size :].tolist()))
        t_start = np.array([starts.get(i, 0.0) for i in first.tolist()])
        t_end = np.array([stops.get(k, float(self.ends[-1])) for k in last.tolist()])
        return t_start, t_end
