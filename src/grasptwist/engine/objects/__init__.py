"""An object's geometry (issue 30): its surface, mass properties, samples and triangles, in the grasp frame.

- ``geometry``: the functions on a :class:`~grasptwist.model.GraspObject` that the other layers call
  (``project_to_surface``, ``mass_properties``, ``sample_surface``, ``tessellate``, ``object_size``,
  ``moved``, ``body_areas``, ``body_of``, ``on_hidden_face``), the first six re-exported here;
- ``primitives``: box, sphere, cylinder and capsule in their own frame, exactly (numpy only);
- ``mesh``: a triangle mesh in its own frame, on its solid's outer surface (nearest points through libigl,
  the ``mesh`` extra);
- ``solid``: the solid a mesh bounds (generalized winding number above 1/2, issue 35): its outer surface,
  bodies, cavities and mass moments;
- ``checks``: the validators ``check_shape``, ``check_size``, ``check_pose``, ``check_object``, and
  ``repair_mesh`` (equal vertices merged, zero-area faces dropped);
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
