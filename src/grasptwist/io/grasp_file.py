"""The grasp loader's import path in grasptwist 0.1 and 0.2 (``from grasptwist.io.grasp_file import read_grasps``).

Deprecated since 0.4: importing it warns.  The loader's public names are in the
core, ``import grasptwist as gt``: ``gt.read_grasps``, ``gt.load_grasps``,
``gt.read_line``, ``gt.read_twist_line``, ``gt.grasp_schema``, ``gt.Grasp``,
``gt.Twist``, ``gt.InputError`` (this module's ``GraspFileError``).  Nothing inside grasptwist imports this module.
"""

import warnings

from .grasp import (
    DEFAULT_MAX_BYTES,
    MAX_DEPTH,
    MAX_DOCUMENTS,
    MAX_ERRORS,
    READING,
    Grasp,
    InputError,
    Reading,
    Twist,
    grasp_schema,
    load_grasps,
    read_grasps,
    read_line,
    read_twist_line,
)

#: 0.5's name of :class:`~grasptwist.model.InputError`.
GraspFileError = InputError

__all__ = [
    "read_line",
    "read_twist_line",
    "Twist",
    "Grasp",
    "GraspFileError",
    "DEFAULT_MAX_BYTES",
    "MAX_DEPTH",
    "MAX_DOCUMENTS",
    "MAX_ERRORS",
    "Reading",
    "READING",
    "read_grasps",
    "load_grasps",
    "grasp_schema",
]

warnings.warn(
    "grasptwist.io.grasp_file is deprecated since 0.4: use grasptwist's own names, "
    "e.g. `import grasptwist as gt; gt.load_grasps(...)` (gt.read_grasps, gt.InputError, ...)",
    DeprecationWarning,
    stacklevel=2,
)
