r"""How far points are from the creases of an object's surface: where a fingertip would roll off a face.

A *crease* is a curve where the surface's normal jumps: a box's twelve edges, a cylinder's two
rims, and a mesh's edges whose faces meet at a dihedral angle above :data:`CREASE_ANGLE_DEG`
(a sphere and a capsule have none: their distance is ``inf``).  For the primitives the
distance is exact, in the object's frame (box of half edges ``h``, cylinder of radius ``R``
and half height ``H``, :math:`\rho = \sqrt{x^2 + y^2}`):

.. math::

    d_\text{box}(q) = \min_k \sqrt{(h_i - |q_i|)^2 + (h_j - |q_j|)^2 + \max(|q_k| - h_k, 0)^2},
    \qquad \{i, j, k\} = \{0, 1, 2\}

(the nearest of the four edges along axis ``k``), and the nearest rim,

.. math:: d_\text{cylinder}(q) = \sqrt{(\rho - R)^2 + (|q_z| - H)^2}.

For a mesh it is the exact distance to the nearest crease edge (a segment), brute force over
the creases in chunks: meant for the few contacts of the grasps a search returns.
"""

from __future__ import annotations

import weakref

import numpy as np

from ...model import GraspObject
from ..se3 import rotate
from .checks import check_size
from .mesh import _derived

__all__ = ["CREASE_ANGLE_DEG", "edge_distance", "mesh_creases"]

#: A mesh edge is a crease when its two faces' normals differ by more than this many degrees.
#: A cylinder tessellated with 32 segments turns 11.25 degrees from face to face, a scanned
#: fruit a few: neither is creased; a box's edge turns 90, a 20-sided die's 41.8.
CREASE_ANGLE_DEG = 30.0

#: Points times creases handled at once (the temporaries of a chunk stay small).
_PAIRS = 1 << 20

_CACHE: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def mesh_creases(shape, angle_deg=CREASE_ANGLE_DEG):
    """The creases of a mesh's outer surface (the one its nearest points lie on, :func:`~.solid.solid`'s:
    internal faces and cavities left out, faces another piece crosses split): ``(E, 2, 3)`` segments
    whose two faces turn more than ``angle_deg`` (an edge of one face only, such as where a split
    face meets the piece that crosses it, is none).

    >>> from grasptwist.model import Shape
    >>> from grasptwist.engine.objects.primitives import triangles
    >>> v, f = triangles("box", [2.0, 2.0, 2.0], 0)
    >>> len(mesh_creases(Shape("mesh", np.zeros(0), v, f)))  # the cube's 12 edges, not its 6 diagonals
    12
    """
    known = _CACHE.setdefault(shape, {})
    if angle_deg in known:
        return known[angle_deg]
    d = _derived(shape)
    faces = d.faces
    normals = d.face_normals
    # side i of face f (opposite vertex i) joins vertices (i + 1, i + 2); each edge once (f < its partner)
    mine = np.repeat(np.arange(len(faces)), 3).reshape(-1, 3)
    turned = np.einsum("fsi,fsi->fs", normals[mine], normals[d.partner]) < np.cos(np.radians(angle_deg))
    face, side = np.nonzero(turned & (mine < d.partner))
    ends = np.stack([faces[face, (side + 1) % 3], faces[face, (side + 2) % 3]], axis=1)
    segments = d.vertices[ends]
    known[angle_deg] = segments
    return segments


def _segments_distance(q, segments):
    """``(N,)`` distance of each point ``q (N, 3)`` to the nearest of ``segments (E, 2, 3)`` (``inf`` for none)."""
    out = np.full(len(q), np.inf)
    if not len(segments):
        return out
    a, ab = segments[:, 0], segments[:, 1] - segments[:, 0]
    length2 = np.einsum("ei,ei->e", ab, ab)
    step = max(1, _PAIRS // len(segments))
    for start in range(0, len(q), step):
        aq = q[start : start + step, None, :] - a  # (n, E, 3)
        with np.errstate(invalid="ignore", divide="ignore"):
            t = np.clip(np.einsum("nei,ei->ne", aq, ab) / length2, 0.0, 1.0)
        t = np.nan_to_num(t)  # a segment of length 0: its end
        gap = aq - t[..., None] * ab
        out[start : start + step] = np.sqrt(np.einsum("nei,nei->ne", gap, gap).min(axis=1))
    return out


def edge_distance(obj: GraspObject, points) -> np.ndarray:
    """Each point's distance to the nearest crease of ``obj``'s surface (module docstring): ``(..., 3)`` -> ``(...)``.

    Points in the grasp frame; ``inf`` on a smooth object (sphere, capsule, a mesh without creases).

    >>> from grasptwist.objects import Shape
    >>> cube = GraspObject(Shape("box", np.full(3, 2.0)), np.eye(4))
    >>> edge_distance(cube, [[0.0, 0.0, 1.0], [0.5, 0.8, 1.0], [1.0, 1.0, 1.0]]).round(6).tolist()
    [1.0, 0.2, 0.0]
    >>> can = GraspObject(Shape("cylinder", np.array([1.0, 2.0])), np.eye(4))
    >>> edge_distance(can, [[0.0, 0.0, 1.0], [0.6, 0.0, 1.0], [1.0, 0.0, 0.5]]).round(6).tolist()
    [1.0, 0.4, 0.5]
    """
    p = np.asarray(points, float)
    rotation, translation = obj.pose[:3, :3], obj.pose[:3, 3]
    q = rotate(rotation.T, p - translation).reshape(-1, 3)
    shape = obj.shape
    if shape.kind == "mesh":
        d = _segments_distance(q, mesh_creases(shape))
    elif shape.kind == "box":
        gap = 0.5 * check_size("box", shape.size) - np.abs(q)  # (N, 3): >= 0 inside along each axis
        d = np.min(
            [np.sqrt(gap[:, i] ** 2 + gap[:, j] ** 2 + np.maximum(-gap[:, k], 0.0) ** 2) for i, j, k in _AXES],
            axis=0,
        )
    elif shape.kind == "cylinder":
        radius, height = check_size("cylinder", shape.size)
        d = np.hypot(np.hypot(q[:, 0], q[:, 1]) - radius, np.abs(q[:, 2]) - 0.5 * height)
    else:  # sphere, capsule: smooth
        d = np.full(len(q), np.inf)
    return d.reshape(p.shape[:-1])


#: For each axis k along which four box edges run, the other two axes.
_AXES = ((1, 2, 0), (0, 2, 1), (0, 1, 2))
