"""Screw algebra and rigid motions: the public entry points.

A screw (a twist or a wrench) is six numbers ``(omega; v)``: ``omega`` its
angular part and ``v`` the value of its field at the frame origin, so that the
field at a point ``p`` is ``V(p) = v + omega x p``.  Screws are ``(..., 6)``,
points and vectors ``(..., 3)``, rotations ``(..., 3, 3)``; leading shapes
broadcast.  A pose is a pair ``(R, x)`` acting on points as ``p -> R p + x``.

>>> from grasptwist import screws
>>> spin = screws.twist_at([0, 0, 1], [0, 0, 0], [1, 0, 0])  # about the vertical through (1, 0, 0)
>>> spin.tolist(), float(screws.pitch(spin))  # the origin moves along -y
([0.0, 0.0, 1.0, 0.0, -1.0, 0.0], 0.0)
>>> rotation, translation = screws.exp(spin, 3.141592653589793)  # half a turn: the origin goes to (2, 0, 0)
>>> translation.round(12).tolist()
[2.0, 0.0, 0.0]

The math is in ``grasptwist.engine.screws`` and ``grasptwist.engine.se3``.
"""

from .engine.screws import (
    axis_point,
    constant_field,
    direction,
    field_at,
    klein,
    klein_table,
    line_between,
    line_through,
    pitch,
    rigid_motion,
    screw,
    twist_at,
    unit,
)
from .engine.se3 import adjoint, exp, log

__all__ = [
    "screw",
    "klein",
    "klein_table",
    "field_at",
    "constant_field",
    "line_through",
    "line_between",
    "twist_at",
    "pitch",
    "axis_point",
    "rigid_motion",
    "unit",
    "direction",
    "exp",
    "log",
    "adjoint",
]
