"""grasptwist: resolve an object twist into finger-tip twists of a three-fingered grasp.

The core: the twist decompositions (pure numpy, batched over leading axes),
their statuses, and grasp files.  One public module per topic holds the rest:
:mod:`grasptwist.screws` (screw algebra), :mod:`grasptwist.hand` (hands, joint
rates, inverse kinematics), :mod:`grasptwist.forces`, :mod:`grasptwist.path`,
:mod:`grasptwist.pictures`, :mod:`grasptwist.objects` (the object held) and
:mod:`grasptwist.dask`.  Every other module is
internal (``docs/api/index.rst`` says which).

>>> import grasptwist as gt
>>> r = gt.decompose_off_tangent([[1, 0, 0], [-0.5, 0.866, 0], [-0.5, -0.866, 0]], [0, 0, 1], [0, 0, 0, 0, 0, 1])
>>> r.x.round(4).tolist()
[0.6667, 0.6667, 0.6667]
"""

import importlib as _importlib
import warnings as _warnings

from ._version import __version__ as __version__

#: Public name -> the module defining it; imported on first use, so that the
#: command line can handle signals before numpy is imported.
_EXPORTS = {
    # the decompositions
    "decompose_off_tangent": ".engine.decompose",
    "decompose_tangent": ".engine.decompose",
    "resolve": ".engine.decompose",
    "contact_velocities": ".engine.decompose",
    "OffTangentResult": ".engine.decompose",
    "TangentResult": ".engine.decompose",
    "Resolution": ".engine.decompose",
    "prepare": ".engine.prepared",
    "PreparedGrasp": ".engine.prepared",
    # statuses and tolerances
    "Status": ".engine.degeneracy",
    "status_message": ".engine.degeneracy",
    "DEGENERACY_TOL": ".engine.degeneracy",
    "CONDITION_WARNING": ".engine.degeneracy",
    # the engine's argument checks
    "check_points": ".engine.checks",
    "check_normals": ".engine.checks",
    "check_wrist": ".engine.checks",
    "check_twist": ".engine.checks",
    # grasp files
    "read_grasps": ".io.grasp",
    "load_grasps": ".io.grasp",
    "read_line": ".io.grasp",
    "read_twist_line": ".io.grasp",
    "grasp_schema": ".io.grasp",
    "InputError": ".model",
    "Grasp": ".model",
    "Twist": ".model",
    "Wrench": ".model",
    "grasp_table": ".io.parquet",
    # the grip, a control loop's one call (also in grasptwist.forces, with the rest of the force side)
    "grip": ".engine.forces.grip",
    "Grip": ".engine.forces.grip",
    "prepare_grip": ".engine.forces.grip",
    "PreparedGrip": ".engine.forces.grip",
    # finding grasps on an object's surface
    "synthesize": ".run.grasp_search",
    "Synthesis": ".engine.synthesis.search",
    # a grasp run in MuJoCo (the sim extra)
    "simulate": ".run.simulate",
    # the topics
    "screws": ".screws",
    "hand": ".hand",
    "forces": ".forces",
    "path": ".path",
    "pictures": ".pictures",
    "objects": ".objects",
    "dask": ".dask",
}

#: Names above that are modules themselves.
_MODULES = {"screws", "hand", "forces", "path", "pictures", "objects", "dask"}

#: Names that moved or were renamed: old name -> (the release that deprecated it, its new name,
#: from ``grasptwist``).  They still work, with a DeprecationWarning naming their new place.
_MOVED = {
    # 0.3's names that moved to a topic module
    "finger_jacobian": ("0.4", "hand.finger_jacobian"),
    "joint_rates": ("0.4", "hand.joint_rates"),
    "JointRates": ("0.4", "hand.JointRates"),
    "force_closure": ("0.4", "forces.force_closure"),
    "Closure": ("0.4", "forces.Closure"),
    "manipulating_forces": ("0.4", "forces.manipulating_forces"),
    "ManipulatingForces": ("0.4", "forces.ManipulatingForces"),
    "squeeze_forces": ("0.4", "forces.squeeze_forces"),
    "grasp_map": ("0.4", "forces.grasp_map"),
    "ForceStatus": ("0.4", "forces.Status"),
    "force_status_message": ("0.4", "forces.status_message"),
    "check_wrench": ("0.4", "forces.check_wrench"),
    "check_friction": ("0.4", "forces.check_friction"),
    "check_safety": ("0.4", "forces.check_safety"),
    # one name for the error of every input, not only a grasp file's
    "GraspFileError": ("0.6", "InputError"),
}

__all__ = list(_EXPORTS)


def __getattr__(name: str):
    if name in _MOVED:
        since, new = _MOVED[name]
        _warnings.warn(
            f"grasptwist.{name} is deprecated since {since}: use grasptwist.{new}", DeprecationWarning, stacklevel=2
        )
        topic, _, new = new.rpartition(".")
        return getattr(__getattr__(topic), new) if topic else __getattr__(new)
    if name not in _EXPORTS:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    module = _importlib.import_module(_EXPORTS[name], __name__)
    value = module if name in _MODULES else getattr(module, name)
    globals()[name] = value
    return value


def __dir__():
    # the public names only: not the subpackages that importing them binds here (engine, io, ...)
    return sorted([*__all__, "__version__"])
