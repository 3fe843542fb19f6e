"""The grasp loader's import path in grasptwist 0.1 and 0.2 (``from grasptwist.io.grasp_file import read_grasps``), kept so that scripts written for them go on working.

A facade: it only re-exports the public API of :mod:`grasptwist.io.grasp`,
where the loader lives; nothing inside grasptwist imports it.
"""

from .grasp import (
    DEFAULT_MAX_BYTES,
    MAX_DEPTH,
    MAX_DOCUMENTS,
    MAX_ERRORS,
    READING,
    Grasp,
    GraspFileError,
    Reading,
    Twist,
    grasp_schema,
    load_grasps,
    read_grasps,
    read_line,
    read_twist_line,
)

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
