"""Finger kinematics: joint screws, the finger Jacobian at a contact, joint rates.

A finger is a serial chain.  At a configuration, each of its joints is a screw
in the grasp's frame, ``(omega; v)`` as in ``grasptwist.engine.screws``:

* a revolute joint through the point ``a`` along the unit vector ``d`` is the
  unit line ``(d; a x d)``; per unit rate it moves a point ``p`` of the links
  after it with ``d x (p - a)``;
* a prismatic joint along the unit vector ``d`` is the translation ``(0; d)``;
  per unit rate it moves every such point with ``d``.

The tip's contact point ``p`` therefore moves with ``J qdot``, where column
``j`` of the ``3 x n`` Jacobian ``J`` is joint ``j``'s field at ``p`` (paper,
eq. 2).  A point contact with friction that does not slip must move with the
object's velocity there, ``T(p) = v + omega x p``, so the joint rates solve

.. math::

    J \\dot q = T(p),

in the minimum-norm least-squares sense (:func:`joint_rates`).  Each
component ``C`` of the paper's decompositions asks ``C(p)`` of the finger
instead (:func:`component_joint_rates`).

Forward kinematics (:func:`forward_kinematics`) moves a chain's joint screws
from its home configuration (all joints at 0) to any batch of joint positions
by the product of exponentials; :func:`chain_from_origins` builds the home
screws from URDF-style joint origins.

Shapes: joint screws are ``(..., n, 6)``, points and velocities ``(..., 3)``,
joint positions ``(..., n)``; leading shapes broadcast.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import NamedTuple

import numpy as np

from . import se3
from .degeneracy import Status
from .screws import cross, dot, field_at, norm, unit

__all__ = [
    "RANK_TOL",
    "FOLLOW_TOL",
    "OFF_TANGENT_FIXED",
    "TANGENT_FIXED",
    "JointRates",
    "ChainState",
    "joint_screw",
    "finger_jacobian",
    "joint_rates",
    "component_joint_rates",
    "velocity_limit_ratio",
    "HandRates",
    "hand_joint_rates",
    "forward_kinematics",
    "rodrigues_terms",
    "chain_from_origins",
    "chain_length",
]

#: Singular values of a finger's Jacobian at or below ``RANK_TOL`` times its
#: largest count as zero: they set the rank, and their directions get no joint
#: rate (a direction that needs ``1e9`` times the velocity's size in joint rates
#: is one the finger cannot follow in practice).
RANK_TOL = 1e-9

#: A finger whose relative residual ``|J qdot - V| / |V|`` exceeds this cannot
#: follow its contact (code ``finger-cannot-follow``).
FOLLOW_TOL = 1e-6

_I = np.eye(3, dtype=bool)

#: ``OFF_TANGENT_FIXED[c, f]``: component ``c`` of the off-tangent decomposition,
#: in basis order ``Sigma_1..3, Psi_1..3``, leaves contact ``f`` still.  ``Sigma_i``
#: is the line through the two other contacts, so it moves contact ``i`` alone;
#: ``Psi_i`` is a line through ``p_i`` (Proposition 1).
OFF_TANGENT_FIXED = np.concatenate((~_I, _I))
OFF_TANGENT_FIXED.flags.writeable = False

#: ``TANGENT_FIXED[c, f]`` for the tangent decomposition's components
#: ``Theta_1..3, Sigma_1..3``: ``Theta_i`` is a line through ``p_i`` (eq. 22).
TANGENT_FIXED = np.concatenate((_I, ~_I))
TANGENT_FIXED.flags.writeable = False


def _checked(a, trailing, name):
    """``a`` as a float array whose shape ends in ``trailing`` (None: any size)."""
    a = np.asarray(a, dtype=float)
    if a.ndim < len(trailing) or any(
        want is not None and got != want for got, want in zip(a.shape[a.ndim - len(trailing) :], trailing)
    ):
        want = "(..., " + ", ".join("n" if t is None else str(t) for t in trailing) + ")"
        raise ValueError(f"{name} must have shape {want}, got {a.shape}")
    return a


def joint_screw(axis, point, prismatic=False):
    """The screw of a revolute joint (unit line) or a prismatic one (translation).

    .. math::

        S = (d;\\ a \\times d) \\text{ (revolute)}, \\qquad S = (0;\\ d) \\text{ (prismatic)},

    with ``d = axis / |axis|`` and ``a = point`` (ignored for a prismatic joint).

    Parameters
    ----------
    axis : (..., 3) array
        Joint direction, any non-zero length.
    point : (..., 3) array
        A point on a revolute joint's axis.
    prismatic : (...) bool array

    Returns
    -------
    (..., 6) array, ``(omega; v)``.

    Examples
    --------
    >>> joint_screw([0, 0, 2.0], [1.0, 0, 0]).tolist()
    [0.0, 0.0, 1.0, 0.0, -1.0, 0.0]
    >>> joint_screw([0, 0, 2.0], [1.0, 0, 0], prismatic=True).tolist()
    [0.0, 0.0, 0.0, 0.0, 0.0, 1.0]
    """
    d = unit(_checked(axis, (3,), "axis"))
    a = _checked(point, (3,), "point")
    prismatic = np.asarray(prismatic, dtype=bool)[..., None]
    omega = np.where(prismatic, 0.0, d)
    return np.concatenate(np.broadcast_arrays(omega, np.where(prismatic, d, cross(a, d))), axis=-1)


def finger_jacobian(joint_screws, points):
    """The ``3 x n`` Jacobian of a finger at a point of its tip link.

    Column ``j`` is joint ``j``'s field at ``p``, the velocity it gives ``p``
    per unit rate:

    .. math::

        J_{:, j} = v_j + \\omega_j \\times p = d_j \\times (p - a_j) \\text{ (revolute)}
        \\text{ or } d_j \\text{ (prismatic)}.

    Parameters
    ----------
    joint_screws : (..., n, 6) array
        The finger's joints, base to tip, as ``(omega; v)`` at the configuration.
    points : (..., 3) array
        The contact point on the tip link.

    Returns
    -------
    (..., 3, n) array

    Examples
    --------
    >>> finger_jacobian([[0, 0, 1.0, 0, 0, 0], [0, 0, 0, 1.0, 0, 0]], [1.0, 0, 0]).tolist()
    [[0.0, 1.0], [1.0, 0.0], [0.0, 0.0]]
    """
    screws = _checked(joint_screws, (None, 6), "joint_screws")
    p = _checked(points, (3,), "points")
    return np.swapaxes(field_at(screws, p[..., None, :]), -1, -2)


@dataclass(frozen=True, eq=False)
class JointRates:
    """Joint rates of a batch of fingers, with how well they follow.

    Attributes
    ----------
    rates : (..., n)
        Minimum-norm least-squares joint rates ``qdot = J^+ V``; NaN where the
        Jacobian or the velocity is not finite.
    rank : (...) int
        Rank of ``J``: its singular values above ``RANK_TOL`` times the largest.
    residual : (...)
        ``|J qdot - V| / |V|`` (0 for ``V = 0``).  Above :data:`FOLLOW_TOL` the
        finger cannot follow the contact.
    conditioning : (...)
        ``sigma_3 / sigma_1`` of ``J`` (its smallest over its largest singular
        value) when the rank is 3, else 0.  Dimensionless: the rates can reach
        ``|V| / (conditioning sigma_1)``, ``sigma_1`` being about the finger's
        length; below :data:`~grasptwist.CONDITION_WARNING`
        that is worth a warning.

    The arrays are read-only (broadcast views).
    """

    rates: np.ndarray
    rank: np.ndarray
    residual: np.ndarray
    conditioning: np.ndarray


def joint_rates(joint_screws, points, velocities):
    """Joint rates that move a finger's contact point with a given velocity.

    The minimum-norm least-squares solution of ``J qdot = V``, through the
    singular value decomposition ``J = U S W^T``:

    .. math::

        \\dot q = \\sum_{\\sigma_k > \\epsilon \\sigma_1} \\frac{u_k \\cdot V}{\\sigma_k} w_k,
        \\qquad \\epsilon = \\mathtt{RANK\\_TOL} = 10^{-9}.

    Among the rates that bring ``J qdot`` nearest to ``V`` it is the shortest,
    so a redundant finger (``n > 3``) gets no motion in its null space.  The
    Jacobian's decomposition is computed once for its own batch shape, so
    ``velocities`` may add leading axes (several velocities for one finger).

    Parameters
    ----------
    joint_screws : (..., n, 6) array
        The finger's joint screws at the configuration, ``(omega; v)``.
    points : (..., 3) array
        Contact point on the tip link.
    velocities : (..., 3) array
        Velocity the contact point must have, e.g. ``T(p)``.

    Returns
    -------
    JointRates
        Its arrays have the broadcast batch shape.

    Examples
    --------
    >>> r = joint_rates([[0, 0, 1.0, 0, 0, 0], [0, 0, 1.0, 0, -1.0, 0]], [2.0, 0, 0], [0, 1.0, 0])
    >>> r.rates.round(12).tolist(), int(r.rank), float(r.residual) < 1e-12, float(r.conditioning)
    ([0.4, 0.2], 1, True, 0.0)
    """
    jac = finger_jacobian(joint_screws, points)
    vel = _checked(velocities, (3,), "velocities")
    shape = np.broadcast_shapes(jac.shape[:-2], vel.shape[:-1])
    n = jac.shape[-1]
    finite = np.isfinite(jac).all(axis=(-2, -1))
    if n == 0:  # a finger with no joint reaches nothing
        rates = np.zeros(shape + (0,))
        rank = np.zeros(jac.shape[:-2], dtype=int)
        s = np.zeros(jac.shape[:-2] + (0,))
    else:
        # LAPACK fails on NaN: decompose zeros in those rows and mark them afterwards.
        u, s, wt = np.linalg.svd(np.where(finite[..., None, None], jac, 0.0), full_matrices=False)
        keep = s > RANK_TOL * s[..., :1]
        rank = keep.sum(axis=-1)
        inverse = np.where(keep, 1.0 / np.where(keep, s, 1.0), 0.0)
        coords = (np.swapaxes(u, -1, -2) @ vel[..., None])[..., 0] * inverse
        rates = (np.swapaxes(wt, -1, -2) @ coords[..., None])[..., 0]
        rates = np.where(finite[..., None], rates, np.nan)
    error = (jac @ rates[..., None])[..., 0] - vel
    size = norm(vel)
    with np.errstate(invalid="ignore", divide="ignore"):
        residual = np.where(size > 0, norm(error) / np.where(size > 0, size, 1.0), norm(error))
        conditioning = s[..., 2] / s[..., 0] if s.shape[-1] == 3 else np.zeros(rank.shape)
    conditioning = np.where(rank == 3, conditioning, np.where(finite, 0.0, np.nan))
    return JointRates(
        rates=np.broadcast_to(rates, shape + (n,)),
        rank=np.broadcast_to(np.where(finite, rank, 0), shape),
        residual=np.broadcast_to(residual, shape),
        conditioning=np.broadcast_to(conditioning, shape),
    )


def component_joint_rates(joint_screws, point, twist, components, fixed):
    """A finger's joint rates for a twist and for each of its components.

    Component ``c`` (a twist, amplitude times basis screw) asks the contact
    point to move with ``C_c(p)``; since the joint rates are linear in the
    velocity, the components' rates add up to the twist's.  Where ``fixed``
    says the component leaves this contact still (``Sigma_i`` moves contact
    ``i`` alone; ``Psi_i`` and ``Theta_i`` keep contact ``i`` fixed), its rates
    are exactly zero rather than rounding noise.

    Parameters
    ----------
    joint_screws : (..., n, 6) array
    point : (..., 3) array
        This finger's contact point.
    twist : (..., 6) array
        The object twist, ``(omega; v)``.
    components : (..., m, 6) array
        Its components, e.g. ``(x_i Sigma_i, y_i Psi_i)`` concatenated.
    fixed : (..., m) bool array
        Whether each component leaves this contact still: a column of
        :data:`OFF_TANGENT_FIXED` or :data:`TANGENT_FIXED`.

    Returns
    -------
    total : JointRates
        For ``T(p)``, batch shape ``(...)``.
    rates : (..., m, n) array
        Component ``c``'s joint rates in row ``c``.

    Examples
    --------
    A Cartesian finger (three prismatic joints) at ``p = (1, 0, 0)``; the
    second component turns about the z axis through ``p``, leaving it still:

    >>> screws = np.hstack((np.zeros((3, 3)), np.eye(3)))
    >>> comps = [[0, 0, 0, 1.0, 0, 0], [0, 0, 1.0, 0, -1.0, 0]]
    >>> total, rates = component_joint_rates(screws, [1.0, 0, 0], np.sum(comps, 0), comps, [False, True])
    >>> rates.tolist(), total.rates.tolist()
    ([[1.0, 0.0, 0.0], [0.0, 0.0, 0.0]], [1.0, 0.0, 0.0])
    """
    p = _checked(point, (3,), "point")
    velocities = field_at(_checked(components, (None, 6), "components"), p[..., None, :])
    still = np.asarray(fixed, dtype=bool)[..., None]
    velocities = np.where(still, 0.0, velocities)
    total_velocity = field_at(_checked(twist, (6,), "twist"), p)
    lead = np.broadcast_shapes(total_velocity.shape[:-1], velocities.shape[:-2])
    velocities = np.concatenate(
        (
            np.broadcast_to(total_velocity[..., None, :], lead + (1, 3)),
            np.broadcast_to(velocities, lead + velocities.shape[-2:]),
        ),
        axis=-2,
    )
    # One decomposition of J serves the twist and every component.
    result = joint_rates(
        _checked(joint_screws, (None, 6), "joint_screws")[..., None, :, :], p[..., None, :], velocities
    )
    total = JointRates(
        result.rates[..., 0, :], result.rank[..., 0], result.residual[..., 0], result.conditioning[..., 0]
    )
    return total, np.where(still, 0.0, result.rates[..., 1:, :])


def velocity_limit_ratio(rates, limits):
    """How far joint rates exceed their velocity limits: ``max_j |qdot_j| / limit_j``.

    .. math::

        \\rho = \\max_{j:\\ \\ell_j \\text{ given}} |\\dot q_j| / \\ell_j .

    Above 1 the motion must be slowed down by the factor ``rho``.

    Parameters
    ----------
    rates : (..., n) array
    limits : (..., n) array
        Positive limits, broadcast against ``rates``; NaN (or None) for a
        joint without one.

    Returns
    -------
    (...) array
        NaN where no joint has a limit.

    Examples
    --------
    >>> float(velocity_limit_ratio([2.0, -6.0, 100.0], [4.0, 3.0, None]))
    2.0
    """
    rates = _checked(rates, (None,), "rates")
    limits = np.asarray(limits, dtype=float)
    if limits.shape[-1:] != rates.shape[-1:] or not np.all(np.isnan(limits) | (limits > 0)):
        raise ValueError(f"limits must be positive numbers or NaN, one per joint, got {limits.tolist()}")
    given = ~np.isnan(limits)
    with np.errstate(invalid="ignore"):
        ratio = np.where(given, np.abs(rates) / np.where(given, limits, 1.0), 0.0)
    return np.where(given.any(axis=-1), ratio.max(axis=-1, initial=0.0), np.nan)


@dataclass(frozen=True, eq=False)
class HandRates:
    """Joint rates of a batch of three-fingered hands for their grasps' twists.

    Fingers are padded to a common joint count ``J`` with zero screws, which
    get zero rates and change no rank, residual or conditioning.

    Attributes
    ----------
    rates : (..., 3, J)
        Each finger's joint rates for ``T(p_f)``.
    finger_rank, finger_residual, finger_conditioning : (..., 3)
        Per finger, ``rank``, ``residual`` and ``conditioning`` of :class:`JointRates`.
    finger_limit_ratio : (..., 3)
        Per finger, :func:`velocity_limit_ratio` (NaN: no limit given).
    velocity_limit_ratio : (...)
        The largest over the fingers (NaN: no limit given).
    conditioning : (...)
        The worst finger's conditioning.
    components : dict of str to (..., m, 3, J) array
        Per decomposition given, each component's joint rates per finger.
    status, culprit : (...) int8
        ``finger-cannot-follow`` (or ``nonfinite-input``) and the finger it is
        about (the one with the largest residual), as for the decompositions.
    joint_positions : (..., 3, J) array or None
        The configuration the rates are at, each finger's joint positions
        padded with NaN (:func:`grasptwist.engine.hands.padded_positions`);
        None when not told.
    tip_error, within_limits : (..., 3) arrays or None
        Per finger at that configuration, :class:`grasptwist.engine.ik.HandIK`'s.
    tip_center : (..., 3, 3) array or None
        Each fingertip sphere's centre, ``p - r n`` (:mod:`grasptwist.engine.fingertips`).
    tip_gap : (..., 3) array or None
        Each sphere's gap to its contact's tangent plane at that configuration (< 0: a penetration).
    tip_contact : (..., 3, 3) array or None
        Where each sphere faces its contact: a unit vector in its tip link's frame.
    """

    rates: np.ndarray
    finger_rank: np.ndarray
    finger_residual: np.ndarray
    finger_conditioning: np.ndarray
    finger_limit_ratio: np.ndarray
    velocity_limit_ratio: np.ndarray
    conditioning: np.ndarray
    components: dict
    status: np.ndarray
    culprit: np.ndarray
    joint_positions: np.ndarray | None = None
    tip_error: np.ndarray | None = None
    within_limits: np.ndarray | None = None
    tip_center: np.ndarray | None = None
    tip_gap: np.ndarray | None = None
    tip_contact: np.ndarray | None = None

    @property
    def ok(self) -> np.ndarray:
        """``status == 0`` per row."""
        return self.status == 0

    def row(self, i):
        """Rows ``i`` of the leading axis, as a result of the same type."""
        values = {k: None if v is None else v[i] for k, v in vars(self).items() if k != "components"}
        return HandRates(**values, components={k: v[i] for k, v in self.components.items()})


def hand_joint_rates(joint_screws, points, twist, limits, decompositions=None):
    """Every finger's joint rates for an object twist, and for each component of its decompositions.

    Finger ``f`` is a chain whose tip touches contact ``p_f``; it must move it
    with ``T(p_f)`` (:func:`joint_rates`), each component ``C`` with ``C(p_f)``
    (:func:`component_joint_rates`).  Its relative residual above
    :data:`FOLLOW_TOL` means it cannot follow: status ``finger-cannot-follow``.

    Parameters
    ----------
    joint_screws : (..., 3, J, 6) array
        Each finger's joint screws at the configuration, zero-padded to ``J``.
    points : (..., 3, 3) array
        The contact points, row ``f`` touched by finger ``f``.
    twist : (..., 6) array
    limits : (..., 3, J) array
        Joint velocity limits, NaN where none is given (padding too).
    decompositions : dict of str to (components (..., m, 6), fixed (m, 3) bool), optional
        Component twists in basis order and which contacts each leaves
        still (:data:`OFF_TANGENT_FIXED`, :data:`TANGENT_FIXED`).

    Returns
    -------
    HandRates

    Three Cartesian fingers follow anything:

    >>> screws = np.broadcast_to(np.hstack((np.zeros((3, 3)), np.eye(3))), (3, 3, 6))
    >>> r = hand_joint_rates(screws, np.eye(3), [0, 0, 1.0, 0, 0, 0], np.full((3, 3), 2.0))
    >>> (r.rates[0] + 0.0).tolist(), r.finger_rank.tolist(), float(r.velocity_limit_ratio), int(r.status)
    ([0.0, 1.0, 0.0], [3, 3, 3], 0.5, 0)
    """
    screws = _checked(joint_screws, (3, None, 6), "joint_screws")
    p = _checked(points, (3, 3), "points")
    twist = _checked(twist, (6,), "twist")
    decompositions = decompositions or {}
    names = list(decompositions)
    sizes = [np.shape(decompositions[k][0])[-2] for k in names]
    comps = [np.asarray(decompositions[k][0], dtype=float) for k in names]
    lead = np.broadcast_shapes(screws.shape[:-3], p.shape[:-2], twist.shape[:-1], *(c.shape[:-2] for c in comps))
    if comps:
        every = np.concatenate([np.broadcast_to(c, lead + c.shape[-2:]) for c in comps], axis=-2)
        fixed = np.concatenate([np.asarray(decompositions[k][1], dtype=bool) for k in names])
    else:
        every, fixed = np.zeros(lead + (0, 6)), np.zeros((0, 3), bool)
    fingers = [component_joint_rates(screws[..., f, :, :], p[..., f, :], twist, every, fixed[:, f]) for f in range(3)]
    rates = np.stack([t.rates for t, _ in fingers], axis=-2)
    residual = np.stack([t.residual for t, _ in fingers], axis=-1)
    parts = np.stack([c for _, c in fingers], axis=-2)  # (..., m, 3, J)
    limit_ratio = velocity_limit_ratio(rates, limits)
    conditioning = np.stack([t.conditioning for t, _ in fingers], axis=-1)
    finite = np.isfinite(residual).all(axis=-1)
    follows = (residual <= FOLLOW_TOL).all(axis=-1)
    status = np.where(~finite, Status.NONFINITE_INPUT, np.where(follows, Status.OK, Status.FINGER_CANNOT_FOLLOW))
    starts = np.cumsum([0, *sizes])
    return HandRates(
        rates=rates,
        finger_rank=np.stack([t.rank for t, _ in fingers], axis=-1),
        finger_residual=residual,
        finger_conditioning=conditioning,
        finger_limit_ratio=limit_ratio,
        velocity_limit_ratio=np.fmax.reduce(limit_ratio, axis=-1),  # fmax: NaN only where every finger's is
        conditioning=conditioning.min(axis=-1),
        components={k: parts[..., a:b, :, :] for k, a, b in zip(names, starts, starts[1:])},
        status=status.astype(np.int8),
        culprit=np.where(status == Status.OK, -1, np.argmax(np.nan_to_num(residual, nan=np.inf), axis=-1)).astype(
            np.int8
        ),
    )


class ChainState(NamedTuple):
    """A serial chain at a batch of configurations (see :func:`forward_kinematics`)."""

    #: ``(..., n, 6)`` joint screws ``(omega; v)`` in the root frame.
    screws: np.ndarray
    #: ``(..., n, 3)`` each joint frame's origin (on a revolute joint's axis).
    points: np.ndarray
    #: ``(..., 4, 4)`` pose of the tip link, or None when no home pose was given.
    tip: np.ndarray | None


def _apply(r, x):
    """``R x`` over batches: ``(..., 3, 3), (..., 3) -> (..., 3)``."""
    return (r @ x[..., None])[..., 0]


#: A home screw is a pure rotation (Rodrigues in :func:`joint_motion`) when ``|omega|`` is 1 and
#: ``omega . v`` is 0 to this (a URDF's axes are normalised to round-off).
_UNIT_TOL = 1e-12


def joint_motion(screw, q):
    r"""``exp([S] q)`` of one joint's home screw ``S (..., 6)`` at positions ``q (...)``: ``(R (..., 3, 3), x (..., 3))``.

    :func:`~grasptwist.engine.se3.exp` in general; for the two kinds of joint (every screw of
    the batch of one kind: the same joint at many positions, or one joint of each of a batch of
    fingers stepped together), the closed forms with the screw's matrices formed once
    (forward kinematics' inner loop, the inverse kinematics' cost): a revolute joint, the unit
    line ``(omega; v)`` (``omega . v = 0``), turns about it by Rodrigues' formula,

    .. math:: R = I + \sin q\, [\omega] + (1 - \cos q)\, [\omega]^2, \qquad
              x = \sin q\, v + (1 - \cos q)\, \omega \times v,

    and a prismatic one ``(0; d)`` moves by ``x = q d`` (``R = I``).

    >>> r, x = joint_motion(np.array([0, 0, 1.0, 0, -1.0, 0]), np.array([np.pi / 2]))
    >>> (x.round(12) + 0.0).tolist(), (r[0] @ [1.0, 0, 0] + x[0]).round(12).tolist()
    ([[1.0, -1.0, 0.0]], [1.0, 0.0, 0.0])
    """
    screw = np.asarray(screw, dtype=float)
    kind, k, kk, v, wv = _joint_terms(screw.tobytes(), screw.shape)
    if kind == "revolute":
        s, c = np.sin(q)[..., None], 1 - np.cos(q)[..., None]
        return np.eye(3) + s[..., None] * k + c[..., None] * kk, s * v + c * wv
    if kind == "prismatic":
        shape = np.broadcast_shapes(np.shape(q), screw.shape[:-1])
        return np.broadcast_to(np.eye(3), shape + (3, 3)), np.asarray(q, float)[..., None] * v
    return se3.exp(screw, q)


def rodrigues_terms(screws):
    """``[omega]``, ``[omega]^2``, ``v`` and ``omega x v`` of home screws ``(..., 6)`` that are all unit lines
    (revolute joints: ``|omega| = 1``, ``omega . v = 0`` to round-off), the terms of :func:`joint_motion`'s
    Rodrigues formula; None where one is not.

    >>> k, kk, v, wv = rodrigues_terms(np.array([0, 0, 1.0, 0, -1.0, 0]))
    >>> k.tolist()[0], (wv + 0.0).tolist()
    ([0.0, -1.0, 0.0], [1.0, 0.0, 0.0])
    >>> rodrigues_terms(np.array([0, 0, 0, 0, 0, 1.0])) is None  # a prismatic joint
    True
    """
    w, v = screws[..., :3], screws[..., 3:]
    if not ((np.abs(dot(w, w) - 1) <= _UNIT_TOL).all() and (np.abs(dot(w, v)) <= _UNIT_TOL).all()):
        return None
    k = se3.skew(w)
    return k, k @ k, v, cross(w, v)


@lru_cache(maxsize=256)
def _joint_terms(data, shape):
    """The kind of a batch of home screws (``data`` their bytes) and, for :func:`joint_motion`'s
    closed forms, ``[omega]``, ``[omega]^2``, ``v`` and ``omega x v``: a chain's screws are the
    same at every call (a tracker's thousands of steps), so they are formed once (read-only)."""
    screw = np.frombuffer(data).reshape(shape)
    rodrigues = rodrigues_terms(screw)
    if rodrigues is not None:
        terms = ("revolute", *rodrigues)
    elif not screw[..., :3].any():
        terms = ("prismatic", None, None, screw[..., 3:], None)
    else:
        return ("other", None, None, None, None)
    for a in terms[1:]:
        if a is not None:
            a.flags.writeable = False
    return terms


def forward_kinematics(home_screws, home_points, home_tip, positions):
    """Joint screws, joint points and tip pose of a serial chain at joint positions.

    The product of exponentials in the root ("space") frame: with ``S_j`` the
    joints' screws at home (every joint at 0) and ``M`` the tip's home pose,

    .. math::

        g_j = e^{[S_1] q_1} \\cdots e^{[S_j] q_j}, \\qquad
        S_j(q) = \\mathrm{Ad}_{g_{j-1}} S_j, \\qquad
        \\mathrm{tip}(q) = g_n M,

    where ``Ad_(R, t)`` carries ``(omega; v)`` to ``(R omega; R v + t x R omega)``.

    Parameters
    ----------
    home_screws : (..., n, 6) array
        Unit lines (revolute joints) or ``(0; d)`` (prismatic ones), base to tip.
    home_points : (..., n, 3) array
        Each joint frame's origin at home.
    home_tip : (..., 4, 4) array or None
        The tip link's pose at home.
    positions : (..., n) array
        Joint positions (radians, lengths).

    Returns
    -------
    ChainState
        With the broadcast batch shape.

    Examples
    --------
    >>> s = forward_kinematics([[0, 0, 1.0, 0, 0, 0], [0, 0, 1.0, 0, -1.0, 0]], [[0, 0, 0], [1.0, 0, 0]], None, [np.pi / 2, 0])
    >>> (s.screws[1].round(12) + 0.0).tolist(), (s.points[1].round(12) + 0.0).tolist()
    ([0.0, 0.0, 1.0, 1.0, 0.0, 0.0], [0.0, 1.0, 0.0])
    """
    screws = _checked(home_screws, (None, 6), "home_screws")
    points = _checked(home_points, (screws.shape[-2], 3), "home_points")
    q = _checked(positions, (screws.shape[-2],), "positions")
    tip = None if home_tip is None else _checked(home_tip, (4, 4), "home_tip")
    lead = np.broadcast_shapes(
        screws.shape[:-2], points.shape[:-2], q.shape[:-1], () if tip is None else tip.shape[:-2]
    )
    n = screws.shape[-2]
    out_screws = np.empty(lead + (n, 6))
    out_points = np.empty(lead + (n, 3))
    rotation, translation = None, None  # g_0 = identity
    for j in range(n):
        s, a = screws[..., j, :], points[..., j, :]
        if rotation is None:
            out_screws[..., j, :], out_points[..., j, :] = s, a
        else:
            w = _apply(rotation, s[..., :3])
            out_screws[..., j, :3] = w
            out_screws[..., j, 3:] = _apply(rotation, s[..., 3:]) + cross(translation, w)
            out_points[..., j, :] = _apply(rotation, a) + translation
        r, t = joint_motion(s, q[..., j])  # the joint's motion, exp([S_j] q_j)
        if rotation is None:
            rotation, translation = r, t
        else:
            rotation, translation = rotation @ r, _apply(rotation, t) + translation
    if tip is None:
        return ChainState(out_screws, out_points, None)
    pose = np.empty(lead + (4, 4))
    pose[..., 3, :] = (0.0, 0.0, 0.0, 1.0)
    if rotation is None:
        pose[..., :3, :] = tip[..., :3, :]
    else:
        pose[..., :3, :3] = rotation @ tip[..., :3, :3]
        pose[..., :3, 3] = _apply(rotation, tip[..., :3, 3]) + translation
    return ChainState(out_screws, out_points, pose)


def chain_from_origins(origins, axes, kinds):
    """Home joint screws of a chain given URDF-style: each joint's origin in its parent.

    Joint ``j``'s frame is ``F_j = F_{j-1} O_j`` with every joint at 0
    (``F_0 = I``, the root); its axis in the root frame is ``R(F_j) d_j`` and its
    point the origin of ``F_j``.  Fixed joints only carry the frame along.

    Parameters
    ----------
    origins : (m, 4, 4) array
        ``O_j``: joint ``j``'s frame in its parent link's frame, root to tip.
    axes : (m, 3) array
        Each joint's axis in its own frame (ignored for fixed joints).
    kinds : sequence of str
        ``"revolute"``, ``"prismatic"`` or ``"fixed"`` per joint.

    Returns
    -------
    screws : (n, 6) array
        The ``n`` movable joints' home screws.
    points : (n, 3) array
        Their frames' origins.
    tip : (4, 4) array
        The last frame ``F_m`` (the tip link's pose at home).

    >>> up = np.eye(4); up[2, 3] = 1.0
    >>> s, p, tip = chain_from_origins([up, up], [[0, 1.0, 0], [1.0, 0, 0]], ["revolute", "fixed"])
    >>> s.tolist(), tip[:3, 3].tolist()
    ([[0.0, 1.0, 0.0, -1.0, 0.0, 0.0]], [0.0, 0.0, 2.0])
    """
    origins = _checked(origins, (4, 4), "origins")
    axes = _checked(axes, (3,), "axes")
    frame = np.eye(4)
    screws, points = [], []
    for origin, axis, kind in zip(origins, axes, kinds, strict=True):
        frame = frame @ origin
        if kind != "fixed":
            points.append(frame[:3, 3])
            screws.append(joint_screw(frame[:3, :3] @ axis, frame[:3, 3], kind == "prismatic"))
    return np.reshape(screws, (-1, 6)), np.reshape(points, (-1, 3)), frame


def chain_length(points, tip):
    """A chain's length: from its first joint through the others to the tip.

    .. math::

        L = \\sum_{j=1}^{n-1} |a_{j+1} - a_j| + |t - a_n| .

    Rigid links keep it the same at every configuration of revolute joints.

    Parameters
    ----------
    points : (..., n, 3) array
        Joint points, base to tip.
    tip : (..., 3) array
        The tip link's origin.

    Returns
    -------
    (...) array

    >>> float(chain_length([[0, 0, 0], [0, 0, 3.0]], [4.0, 0, 3]))
    7.0
    """
    path = np.concatenate((_checked(points, (None, 3), "points"), _checked(tip, (3,), "tip")[..., None, :]), axis=-2)
    with np.errstate(over="ignore"):  # hypot: no square overflows below 1e308 (the sum of links may)
        return np.hypot.reduce(np.diff(path, axis=-2), axis=-1).sum(axis=-1)
