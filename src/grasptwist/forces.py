"""The force side: how hard each finger must press, and whether a grasp is force closure.

Contacts and normals are ``(..., 3, 3)``, wrenches ``(force; moment about the
origin)`` ``(..., 6)``, friction ``mu_i`` a scalar or ``(..., 3)``; leading shapes
broadcast.  As on the twist side, a row that cannot be solved never raises: it
gets a :class:`Status`, a culprit and NaN, which :func:`status_message` puts
into words.

>>> from grasptwist import forces
>>> p = [[1, 0, 0], [-0.5, 0.75**0.5, 0], [-0.5, -(0.75**0.5), 0]]
>>> g = forces.grip(p, [[-1, 0, 0], [0.5, -(0.75**0.5), 0], [0.5, 0.75**0.5, 0]], [0, 0, 9.81, 0, 0, 0], 0.5)
>>> round(float(g.total_normal_force), 6), forces.Status(int(g.status)).code
(19.62, 'ok')

The math is in ``grasptwist.engine.forces``.
"""

from .engine.forces.closure import MAX_CONE_EDGES, Closure, force_closure
from .engine.forces.grasp_map import (
    ManipulatingForces,
    Status,
    check_friction,
    check_safety,
    check_wrench,
    grasp_map,
    manipulating_forces,
    squeeze_forces,
)
from .engine.forces.grasp_map import force_status_message as status_message
from .engine.forces.grip import Grip, PreparedGrip, grip, prepare_grip
from .engine.forces.hold import HoldStretch, cannot_hold, grip_along, hold_wrench

__all__ = [
    "grip",
    "Grip",
    "prepare_grip",
    "PreparedGrip",
    "force_closure",
    "Closure",
    "MAX_CONE_EDGES",
    "manipulating_forces",
    "ManipulatingForces",
    "squeeze_forces",
    "grasp_map",
    "Status",
    "status_message",
    "check_wrench",
    "check_friction",
    "check_safety",
    "hold_wrench",
    "grip_along",
    "cannot_hold",
    "HoldStretch",
]
