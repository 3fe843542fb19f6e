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

from . import _moved
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
    # a grasp file's hand put on its contacts and its fingers checked, as every command does
    # (the command line's machinery, run/: the core's, never a topic's)
    "place_grasp": ".run.placement",
    "finger_collisions": ".run.collisions",
    "hand_checks_along": ".run.collisions",
    "Collision": ".run.collisions",
    "Overlap": ".run.collisions",
    "EnvironmentHit": ".run.collisions",
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

#: The names that moved or went, each a deprecated alias for a release (``_moved.py``): the
#: core's old names, and ``topic.name`` for a topic's (whose ``__getattr__`` looks there).
_MOVED = _moved.MOVED

#: Names of a topic module that the core re-exports as well: by the rule of ARCHITECTURE.md ("The
#: public API"), only a whole job's one call, with the types it takes and gives; today the grip, a
#: control loop's one call (issue 29).  Every other public name has one home.
_REEXPORTED = {"grip": "forces", "Grip": "forces", "prepare_grip": "forces", "PreparedGrip": "forces"}

__all__ = list(_EXPORTS)


def __getattr__(name: str):
    if name in _MOVED:
        return _moved.moved(name)
    if name not in _EXPORTS:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    module = _importlib.import_module(_EXPORTS[name], __name__)
    value = module if name in _MODULES else getattr(module, name)
    globals()[name] = value
    return value


def __dir__():
    # the public names only: not the subpackages that importing them binds here (engine, io, ...)
    return sorted([*__all__, "__version__"])
