r"""The six-direction hold test's math: the loads, the grips that resist them, the joint torques.

The protocol (BODex's, made exact): the object's weight ``m |g|`` is applied at its centre of
mass along each of ``+x, -x, +y, -y, +z, -z`` in turn; for each, the fingers exert the grip that
balances it (:func:`~grasptwist.engine.forces.grip.grip` of :func:`direction_wrenches`), squeezed so
that every finger presses (:func:`squeezed`), through
joint torques ``tau = J^T f`` (:func:`joint_torques`); the grasp holds in a direction when the
object moves less than the tolerances (:func:`held`).  The simulation itself is
:mod:`grasptwist.sim`'s.
"""

from __future__ import annotations

import numpy as np

from .forces.closure import internal_inside
from .forces.grasp_map import geometry, squeeze_forces
from .forces.hold import hold_wrench
from .hands import finger_states
from .kinematics import finger_jacobian

__all__ = [
    "DIRECTIONS",
    "UNITS",
    "LOADS",
    "MIN_DURATION",
    "MAX_DURATION",
    "MAX_ANGLE_TOL",
    "direction_wrenches",
    "direction_loads",
    "check_loads",
    "squeezed",
    "joint_torques",
    "held",
    "check_duration",
    "check_tolerance",
    "check_distance_tol",
]

#: The six directions, in the order they are tested, and their unit vectors ``(6, 3)``.
DIRECTIONS = ("+x", "-x", "+y", "-y", "+z", "-z")
UNITS = np.array([[1.0, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]])

#: What the grasps a search returns must hold (``loads=``, ``--loads``): ``six``, the weight and
#: the hold test's loads beside it (:func:`direction_loads`), BODex's protocol; ``weight``, the
#: weight alone.
LOADS = ("six", "weight")

#: The shortest time a direction's load is applied (seconds): 50 of the simulation's 1 ms steps,
#: long enough for an object that slips to leave the tolerance (it falls 12 mm in 0.05 s under its
#: weight); shorter, every grasp would "hold".
MIN_DURATION = 0.05

#: The longest (seconds of simulated time): a hold test's CPU is about 0.03 s per simulated second
#: and direction, so this bounds one grasp's test to a few minutes.
MAX_DURATION = 600.0

#: The largest angle tolerance (degrees): an object turned further has not been held.
MAX_ANGLE_TOL = 45.0


def check_duration(duration) -> float:
    """``duration`` (seconds per direction), or ``ValueError``: at least :data:`MIN_DURATION`, at most
    :data:`MAX_DURATION`.

    >>> check_duration(0.05)
    0.05
    """
    d = float(duration)
    if not MIN_DURATION <= d <= MAX_DURATION:
        raise ValueError(
            f"must be at least {MIN_DURATION:g} s (50 time steps) and at most {MAX_DURATION:g} s, got {d:g}"
        )
    return d


def check_loads(loads) -> str:
    """``loads``, one of :data:`LOADS`, or ``ValueError``.

    >>> check_loads("six")
    'six'
    """
    if loads not in LOADS:
        raise ValueError(f"loads must be one of {', '.join(LOADS)}, got {loads!r}")
    return loads


def check_tolerance(distance, angle) -> tuple[float, float]:
    """``(distance, angle)``, the hold's tolerances (angle in degrees), or ``ValueError``: a finite
    distance > 0 and an angle in ``(0, MAX_ANGLE_TOL]``.

    >>> check_tolerance(0.002, 2)
    (0.002, 2.0)
    """
    distance, angle = float(distance), float(angle)
    if not 0 < distance < np.inf:
        raise ValueError(f"the distance must be a finite number > 0, got {distance:g}")
    if not 0 < angle <= MAX_ANGLE_TOL:
        raise ValueError(f"the angle must be in degrees, > 0 and at most {MAX_ANGLE_TOL:g}, got {angle:g}")
    return distance, angle


def check_distance_tol(distance, size) -> str | None:
    """Why the distance tolerance does not fit an object of ``size`` (its bounding box's diagonal), or
    None: the object may not move as far as its own size and still count as held.

    >>> check_distance_tol(1e6, 0.11)
    "the distance tolerance 1e+06 is not less than the object's size 0.11 (its bounding box's diagonal)"
    """
    if distance < size:
        return None
    return f"the distance tolerance {distance:g} is not less than the object's size {size:.3g} (its bounding box's diagonal)"


def direction_wrenches(mass, center_of_mass, load) -> np.ndarray:
    r"""The wrenches the fingers must exert to balance a load of size ``load`` at the centre of mass
    along each of the six directions, ``(6, 6)``: :func:`hold_wrench` with gravity ``load / m * u``.

    .. math:: w_d = \left(-L u_d;\; -c \times L u_d\right)

    >>> direction_wrenches(2.0, [1.0, 0, 0], 19.62)[4].tolist()
    [0.0, 0.0, -19.62, 0.0, 19.62, 0.0]
    """
    return hold_wrench(mass, center_of_mass, UNITS * (float(load) / float(mass)))


def direction_loads(weight) -> tuple[tuple[str, ...], np.ndarray]:
    """The hold test's loads besides the weight itself (:func:`direction_wrenches` of the weight's size),
    named ``load +x`` ...: ``(k,)`` names and ``(k, 6)`` wrenches, ``k`` 5 where the weight is one of them.

    >>> from grasptwist.engine.forces.hold import Weight, hold_wrench
    >>> g = np.array([0, 0, -9.81])
    >>> names, loads = direction_loads(Weight(1.0, np.zeros(3), g, hold_wrench(1.0, np.zeros(3), g)))
    >>> names, loads[0].tolist()
    (('load +x', 'load -x', 'load +y', 'load -y', 'load +z'), [-9.81, 0.0, 0.0, 0.0, 0.0, 0.0])
    """
    load = weight.mass * float(np.linalg.norm(weight.gravity))
    loads = direction_wrenches(weight.mass, weight.center_of_mass, load)
    other = ~np.isclose(loads, weight.wrench).all(axis=-1)
    return tuple(f"load {d}" for d, o in zip(DIRECTIONS, other, strict=True) if o), loads[other]


def squeezed(points, normals, forces, friction, floor) -> np.ndarray:
    r"""The forces ``f`` with a squeeze added, so that every finger presses at least ``floor`` along its
    normal: ``f + lambda s``, ``s`` an internal force (a squeeze, in the null space of the grasp map)
    strictly inside every cone ``friction`` (:func:`~grasptwist.engine.forces.closure.internal_inside`),
    ``lambda >= 0`` the least that lifts every normal force to the floor.

    .. math:: \lambda = \max\Bigl(0,\; \max_i \frac{F - f_i \cdot n_i}{s_i \cdot n_i}\Bigr)

    The sum exerts the same wrench, and stays inside the cones that hold ``f`` and ``s`` (a cone is
    convex).  Where no squeeze is inside the cones (no force closure) ``f`` is returned unchanged, and
    NaN forces stay NaN.  ``(..., 3, 3)`` arrays; ``normals`` unit, into the object; ``friction`` a
    scalar or ``(..., 3)``.

    >>> p = [[1.0, 0, 0], [-0.5, 0.75**0.5, 0], [-0.5, -(0.75**0.5), 0]]
    >>> f = squeezed(p, -np.array(p), np.zeros((3, 3)), 0.5, 2.0)
    >>> (f * -np.array(p)).sum(axis=-1).round(12).tolist()
    [2.0, 2.0, 2.0]
    """
    p, n, f = (np.asarray(a, dtype=float) for a in (points, normals, forces))
    p, n = np.broadcast_to(p, f.shape), np.broadcast_to(n, f.shape)
    rows = p.reshape(-1, 3, 3)
    mu = np.broadcast_to(np.asarray(friction, dtype=float), f.shape[:-1]).reshape(-1, 3)
    unit = squeeze_forces(rows, internal_inside(rows, n.reshape(-1, 3, 3), geometry(rows), mu)).reshape(f.shape)
    pressed, pushes = (f * n).sum(axis=-1), (unit * n).sum(axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        scale = np.maximum(0.0, ((float(floor) - pressed) / pushes).max(axis=-1))
    scale = np.where(np.isnan(scale), 0.0, scale)[..., None, None]
    return f + np.where(np.isnan(unit), 0.0, scale * unit)


def joint_torques(hand, positions, points, forces, moments=None) -> np.ndarray:
    r"""The joint torques by which each finger exerts its force at its contact, and its moment
    (a soft contact's torsion ``tau_n n``): ``tau = J^T (f; m)``, ``J`` the finger's twist Jacobian at
    the contact.

    .. math:: \tau_{f,j} = (v_j + \omega_j \times p_f) \cdot f_f + \omega_j \cdot m_f

    Parameters
    ----------
    hand : Hand or None
        None: each finger is a point on three slides (x, y, z), whose torques are the forces.
    positions : (n_joints,) array
        The hand's joint positions.
    points : (3, 3) array
        The contacts, row ``f`` touched by finger ``f``.
    forces : (..., 3, 3) array
        Row ``f`` the force finger ``f`` exerts on the object.
    moments : (..., 3, 3) array or None
        Row ``f`` the moment finger ``f`` exerts on the object (None: none).  Without a hand the
        fingertips cannot turn (three slides each): the slides' structure bears it, no torque.

    Returns
    -------
    (..., n_joints) array, in ``hand.joint_names`` order (``(..., 9)`` without a hand).

    Examples
    --------
    A finger on one slide along x pushing with 2 N along x and 1 N along y: the slide carries 2 N.

    >>> from grasptwist.hand import Finger, Hand, Joint
    >>> f = Finger("1", None, (Joint("x", "prismatic", None, None, None, None),), np.array([[0, 0, 0, 1.0, 0, 0]]), np.zeros((1, 3)), None, 1.0, (0,))
    >>> joint_torques(Hand((f, f, f), ("x",), None, None), [0.0], np.zeros((3, 3)), [[2.0, 1, 0], [0] * 3, [0] * 3]).tolist()
    [2.0]

    A fingertip on a hinge about z through the origin, turning the object about z with 0.5 N m: the
    hinge carries it.

    >>> f = Finger("1", None, (Joint("z", "revolute", None, None, None, None),), np.array([[0, 0, 1.0, 0, 0, 0]]), np.zeros((1, 3)), None, 1.0, (0,))
    >>> joint_torques(Hand((f, f, f), ("z",), None, None), [0.0], np.zeros((3, 3)), np.zeros((3, 3)), [[0, 0, 0.5], [0] * 3, [0] * 3]).tolist()
    [0.5]
    """
    forces = np.asarray(forces, dtype=float)
    moments = None if moments is None else np.asarray(moments, dtype=float)
    if hand is None:
        return forces.reshape(forces.shape[:-2] + (9,))
    out = np.zeros(forces.shape[:-2] + (len(hand.joint_names),))
    for f, (finger, state) in enumerate(zip(hand.fingers, finger_states(hand, np.asarray(positions, float)))):
        jac = finger_jacobian(state.screws, np.asarray(points, float)[f])
        out[..., list(finger.joint_index)] += np.einsum("ij,...i->...j", jac, forces[..., f, :])
        if moments is not None:
            out[..., list(finger.joint_index)] += np.einsum("ji,...i->...j", state.screws[:, :3], moments[..., f, :])
    return out


def held(displacement, rotation, distance_tol, angle_tol) -> np.ndarray:
    """Held where the object moved less than both tolerances (``rotation`` and ``angle_tol`` in radians).

    >>> held([0.001, 0.003], [0.0, 0.0], 0.002, 0.035).tolist()
    [True, False]
    """
    return (np.asarray(displacement) < distance_tol) & (np.asarray(rotation) < angle_tol)
