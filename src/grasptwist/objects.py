"""The object a grasp holds: its shape, its surface, its mass properties (issue 30): the public API.

>>> import numpy as np
>>> from grasptwist.objects import GraspObject, Shape, project_to_surface
>>> cube = GraspObject(Shape("box", np.array([0.065, 0.065, 0.065])), np.eye(4))
>>> s = project_to_surface(cube, [0.04, 0.01, 0.0])
>>> s.points.round(4).tolist(), s.normals.tolist(), round(float(s.distance), 4)
([0.0325, 0.01, 0.0], [-1.0, 0.0, 0.0], 0.0075)

Normals point into the object, distances are > 0 outside.  The math is in
``grasptwist.engine.objects``.
"""

from .engine.environment import CLEARANCE, box_distance, environment_distance
from .engine.objects.checks import KINDS, ObjectError, check_object, check_pose, check_shape, check_size
from .engine.objects.geometry import (
    MassProperties,
    SurfacePoints,
    mass_properties,
    moved,
    object_size,
    project_to_surface,
    sample_surface,
    tessellate,
)
from .engine.objects.tolerances import EDGE_TOL, MESH_EDGE_TOL, NORMAL_DISAGREE_DEG, SURFACE_TOL
from .model import Environment, GraspObject, Obstacle, Shape

__all__ = [
    "Shape",
    "GraspObject",
    "project_to_surface",
    "mass_properties",
    "sample_surface",
    "tessellate",
    "object_size",
    "moved",
    "SurfacePoints",
    "MassProperties",
    "check_shape",
    "check_size",
    "check_pose",
    "check_object",
    "ObjectError",
    "KINDS",
    "SURFACE_TOL",
    "NORMAL_DISAGREE_DEG",
    "EDGE_TOL",
    "MESH_EDGE_TOL",
    "Environment",
    "Obstacle",
    "environment_distance",
    "box_distance",
    "CLEARANCE",
]
