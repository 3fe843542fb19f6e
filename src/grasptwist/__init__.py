"""grasptwist: resolve an object twist into finger-tip twists of a three-fingered grasp.

The engine (pure numpy, batched over leading axes):

>>> import grasptwist as gt
>>> r = gt.decompose_off_tangent([[1, 0, 0], [-0.5, 0.866, 0], [-0.5, -0.866, 0]], [0, 0, 1], [0, 0, 0, 0, 0, 1])
>>> r.x.round(4).tolist()
[0.6667, 0.6667, 0.6667]
"""

from importlib import import_module

from ._version import __version__ as __version__

#: Public name -> the module defining it; imported on first use, so that the
#: command line can handle signals before numpy is imported.
_EXPORTS = {
    "screws": ".engine.screws",
    "decompose_off_tangent": ".engine.decompose",
    "decompose_tangent": ".engine.decompose",
    "contact_velocities": ".engine.decompose",
    "OffTangentResult": ".engine.decompose",
    "TangentResult": ".engine.decompose",
    "Status": ".engine.degeneracy",
    "status_message": ".engine.degeneracy",
    "DEGENERACY_TOL": ".engine.degeneracy",
    "CONDITION_WARNING": ".engine.degeneracy",
    "resolve": ".engine.decompose",
    "Resolution": ".engine.decompose",
    "prepare": ".engine.prepared",
    "PreparedGrasp": ".engine.prepared",
    "check_points": ".engine.checks",
    "check_normals": ".engine.checks",
    "check_wrist": ".engine.checks",
    "check_twist": ".engine.checks",
    "finger_jacobian": ".engine.kinematics",
    "joint_rates": ".engine.kinematics",
    "JointRates": ".engine.kinematics",
    "manipulating_forces": ".engine.forces.grasp_map",
    "ManipulatingForces": ".engine.forces.grasp_map",
    "squeeze_forces": ".engine.forces.grasp_map",
    "grasp_map": ".engine.forces.grasp_map",
    "ForceStatus": ".engine.forces.grasp_map",
    "force_status_message": ".engine.forces.grasp_map",
    "check_wrench": ".engine.forces.grasp_map",
    "check_friction": ".engine.forces.grasp_map",
    "check_safety": ".engine.forces.grasp_map",
    "grip": ".engine.forces.grip",
    "Grip": ".engine.forces.grip",
    "prepare_grip": ".engine.forces.grip",
    "PreparedGrip": ".engine.forces.grip",
    "force_closure": ".engine.forces.closure",
    "Closure": ".engine.forces.closure",
    "hand": ".hand",
    "path": ".path",
}

#: Names above that are modules themselves.
_MODULES = {"screws", "hand", "path"}

__all__ = list(_EXPORTS)


def __getattr__(name: str):
    if name not in _EXPORTS:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    module = import_module(_EXPORTS[name], __name__)
    value = module if name in _MODULES else getattr(module, name)
    globals()[name] = value
    return value


def __dir__():
    return sorted({*globals(), *_EXPORTS})
