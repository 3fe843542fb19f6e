"""grasptwist: resolve an object twist into finger-tip twists of a three-fingered grasp.

The engine (pure numpy, batched over leading axes):

>>> import grasptwist as gt
>>> r = gt.decompose_off_tangent([[1, 0, 0], [-0.5, 0.866, 0], [-0.5, -0.866, 0]], [0, 0, 1], [0, 0, 0, 0, 0, 1])
>>> r.x.round(4).tolist()
[0.6667, 0.6667, 0.6667]
"""

from .engine import screws
from .engine.decompose import (
    OffTangentResult,
    TangentResult,
    contact_velocities,
    decompose_off_tangent,
    decompose_tangent,
)
from .engine.degeneracy import CONDITION_WARNING, DEGENERACY_TOL, Status, status_message
from .engine.kinematics import JointRates, finger_jacobian, joint_rates

__version__ = "0.1.0"

__all__ = [
    "screws",
    "decompose_off_tangent",
    "decompose_tangent",
    "contact_velocities",
    "OffTangentResult",
    "TangentResult",
    "Status",
    "status_message",
    "DEGENERACY_TOL",
    "CONDITION_WARNING",
    "finger_jacobian",
    "joint_rates",
    "JointRates",
]
