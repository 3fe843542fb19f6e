"""The tolerances of an object's surface, in one place.

Lengths are relative to the object's size
(:func:`~grasptwist.engine.objects.geometry.object_size`, the diagonal of its
bounding box), so that an object scaled by 1e-3 or 1e3 gets the same verdicts.
"""

from __future__ import annotations

__all__ = ["SURFACE_TOL", "NORMAL_DISAGREE_DEG", "EDGE_TOL", "MESH_EDGE_TOL"]

#: A given contact point farther than ``SURFACE_TOL * object_size`` from the
#: surface is off it (``contact-off-surface``); nearer, it is put on it.  1 % of
#: the diagonal is 1.1 mm on a 65 mm cube: it forgives points typed to the
#: millimetre (at most 0.5 mm off) and catches the usual mix-ups, a fingertip's
#: centre given for its contact (10 mm on the TriFinger, 9 %) or a point in the
#: wrong unit.
SURFACE_TOL = 1e-2

#: A given normal more than this many degrees from the surface's is worth a
#: warning (``normal-disagrees``).  Normals typed by hand to two decimals are
#: within about 1 degree of what they mean, and a point put on a curved surface
#: from 1 % of its size away turns its normal by a few degrees at most; a normal
#: of the wrong face (90 degrees) or with a wrong component is far beyond 10.
NORMAL_DISAGREE_DEG = 10.0

#: A point within ``EDGE_TOL * object_size`` of a primitive's edge, corner or
#: rim counts as on it, and its normal is the bisector of the faces that meet
#: there.  Round-off leaves a point typed on an edge and carried by a pose about
#: 1e-16 of the size off it per operation; 1e-9 is far above that and far below
#: any distance a user means.
EDGE_TOL = 1e-9

#: A point of a mesh within ``MESH_EDGE_TOL * object_size`` of an edge or a
#: vertex takes the area-weighted normal of the faces that meet there instead
#: of one face's.  Every point outside a convex edge or corner projects exactly
#: onto it, where a face normal would depend on round-off; the closest point's
#: own round-off is about 1e-16 of the size, and 1e-6 is far below the edge of
#: any triangle of a mesh one would hold (a million triangles on a sphere have
#: edges of some 3e-3 of its diagonal).
MESH_EDGE_TOL = 1e-6
