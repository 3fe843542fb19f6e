"""An object's geometry (issue 30): its surface, mass properties, samples and triangles, in the grasp frame.

- ``geometry``: the functions on a :class:`~grasptwist.model.GraspObject` that the other layers call
  (``project_to_surface``, ``mass_properties``, ``sample_surface``, ``tessellate``, ``object_size``,
  ``moved``), re-exported here;
- ``primitives``: box, sphere, cylinder and capsule in their own frame, exactly (numpy only);
- ``mesh``: a closed triangle mesh in its own frame (nearest points through libigl, the ``mesh`` extra);
- ``checks``: the validators ``check_shape``, ``check_size``, ``check_pose``, ``check_object``;
- ``tolerances``: ``SURFACE_TOL``, ``NORMAL_DISAGREE_DEG``, ``EDGE_TOL``, ``MESH_EDGE_TOL``.

Conventions: normals point into the object, distances are > 0 outside (docs/guide/objects.md).
"""

from .checks import KINDS, check_object, check_pose, check_shape, check_size
from .geometry import (
    MassProperties,
    SurfacePoints,
    mass_properties,
    moved,
    object_size,
    project_to_surface,
    sample_surface,
    tessellate,
)
from .tolerances import EDGE_TOL, MESH_EDGE_TOL, NORMAL_DISAGREE_DEG, SURFACE_TOL

__all__ = [
    "KINDS",
    "SurfacePoints",
    "MassProperties",
    "project_to_surface",
    "mass_properties",
    "sample_surface",
    "tessellate",
    "object_size",
    "moved",
    "check_shape",
    "check_size",
    "check_pose",
    "check_object",
    "SURFACE_TOL",
    "NORMAL_DISAGREE_DEG",
    "EDGE_TOL",
    "MESH_EDGE_TOL",
]
