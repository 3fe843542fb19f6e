"""An object's triangle mesh (STL, OBJ or PLY), read as untrusted input.

A grasp file's ``object: {mesh: path}`` names it, or ``synthesize``'s command line (a
path, a folder's file); :mod:`grasptwist.io.mesh_formats` turns its bytes into vertices and
faces (STL, OBJ and ASCII PLY there, without trimesh's second of import; a binary PLY by
trimesh, the optional extra ``grasptwist[mesh]``), and the checks are numpy's.  Around it, as
for a URDF (:mod:`grasptwist.io.urdf`, whose path rule this shares):

* the reference: a path relative to the grasp file's folder, refused when it
  resolves (symbolic links followed) outside that folder (``path-outside``)
  unless the caller allows it (``--allow-outside``); ``package://PKG/path``
  inside an installed Python package;
* the bytes: at most ``max_bytes`` (:data:`~grasptwist.io.limits.MAX_MESH_BYTES`,
  ``Reading.max_mesh_bytes``: one cap however the mesh is named) of a regular
  file are read before anything is parsed, and a file whose format says it
  holds more than :data:`~grasptwist.io.limits.MAX_VERTICES` vertices or
  ``max_triangles`` triangles is refused unparsed (a binary STL's count, an
  ASCII STL's ``endfacet`` words, a PLY header's elements, an OBJ's ``v`` and
  ``f`` lines; :func:`~grasptwist.io.mesh_formats.check_counts`), as is a PLY whose header declares more
  than its body holds; the readers stop at the caps whatever the file
  says, so memory stays within a few times ``max_bytes``; bytes
  that are no STL (neither a binary STL of its count's length nor text
  starting with ``solid``) are ``invalid-mesh`` unparsed;
* the geometry: at most ``max_triangles`` triangles (:data:`~grasptwist.io.limits.MAX_TRIANGLES`),
  finite vertices, every face index a vertex, and a size within ``SIZE_RANGE``
  (:mod:`grasptwist.engine.objects.checks`).  It is repaired without changing its geometry
  (equal vertices merged, zero-area triangles dropped: ``mesh-repaired``) and may be open or
  made of pieces: the solid it bounds is the engine's (:mod:`grasptwist.engine.objects.solid`).
  A mesh wound inwards is turned outwards (``mesh-repaired``: "faces re-wound outwards").

Every refusal is a :class:`~grasptwist.model.InputError` with a code:

=======================  ==========================================================
``read-error``           missing or unreadable file, not a regular file
``too-large``            more than ``max_bytes``
``path-outside``         the path resolves outside the grasp file's folder
``unsupported-url``      a URL scheme other than ``package://``
``package-not-found``    ``package://PKG``: no installed Python package ``PKG``
``unsupported-mesh``     a file name not ending in ``.stl``, ``.obj`` or ``.ply``
``invalid-mesh``         not readable as its format (bad face indices, truncated)
``empty-mesh``           no triangles
``too-many-triangles``   more than ``max_triangles`` (an OBJ polygon counts as its fan's)
``too-many-vertices``    more than :data:`~grasptwist.io.limits.MAX_VERTICES`
``non-finite``           a vertex coordinate that is NaN or infinite
``mesh-not-solid``       every triangle of zero area (the engine's check: no inside anywhere)
``invalid-size``         a size (bounding box diagonal) outside ``SIZE_RANGE``, 1e-75 to 1e75
``mesh-unavailable``     trimesh is not installed (a binary PLY)
=======================  ==========================================================
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..model import InputError
from .limits import MAX_MESH_BYTES, MAX_TRIANGLES, MESH_SUFFIXES
from .mesh_formats import parse_mesh

__all__ = ["read_mesh", "check_mesh"]


def read_mesh(
    reference,
    folder=None,
    *,
    max_bytes=MAX_MESH_BYTES,
    max_triangles=MAX_TRIANGLES,
    allow_outside=False,
    output=None,
    warnings=None,
):
    """The vertices and outward-wound triangles of a mesh file.

    Parameters
    ----------
    reference : str
        The file as the grasp file names it: a path relative to ``folder``,
        or ``package://PKG/path``.
    folder : str or os.PathLike, optional
        The grasp file's folder, which the path must stay inside.  None: the
        path is used as given.
    max_bytes : int
        Size cap, checked before parsing.
    max_triangles : int
        Most triangles.
    allow_outside : bool
        Take a relative path wherever it leads.
    output : (int, int), optional
        The ``(device, inode)`` of the file ``-o`` replaces: a mesh that is it is ``output-is-input``.
    warnings : list, optional
        Where the ``mesh-repaired`` warning goes, when the mesh was repaired.

    Returns
    -------
    vertices : numpy.ndarray
        ``(V, 3)`` float, every one used by a face.
    faces : numpy.ndarray
        ``(F, 3)`` int vertex indices, counter-clockwise seen from outside.

    Raises
    ------
    InputError
        One of the codes in the module's table, its message one line.

    Examples
    --------
    >>> read_mesh("box.step", ".")
    Traceback (most recent call last):
    grasptwist.model.InputError: box.step: expected a mesh file ending in .stl, .obj or .ply
    """
    text = os.fspath(reference)
    suffix = Path(text).suffix.lower()
    if suffix not in MESH_SUFFIXES:
        raise InputError(
            "unsupported-mesh", f"expected a mesh file ending in {', '.join(MESH_SUFFIXES[:-1])} or .ply", text
        )
    from .urdf import _read, resolve_urdf  # here: listing a folder (MESH_SUFFIXES) imports no URDF reader

    data = _read(resolve_urdf(text, folder, allow_outside=allow_outside, output=output), max_bytes, text, output)
    return check_mesh(*parse_mesh(data, suffix, text, max_triangles), max_triangles, text, warnings)


def check_mesh(vertices, faces, max_triangles, file, warnings=None):
    """``(vertices, faces)`` of a parsed mesh within the limits, repaired without changing its geometry
    (:func:`~grasptwist.engine.objects.checks.repair_mesh`: equal vertices merged, zero-area faces
    dropped, unused vertices left out) and wound outwards.  Whether it bounds a solid (it may be open
    or made of pieces) is the engine's to tell (``grasptwist.engine.objects.solid``).

    A repair adds its ``mesh-repaired`` warning to ``warnings``; an STL repeats each vertex in
    every triangle, so its merged vertices are not counted.  Outwards: the signed volume

    .. math::

        V = \\frac{1}{6} \\sum_f \\mathbf v_{f,0} \\cdot (\\mathbf v_{f,1} \\times \\mathbf v_{f,2}) > 0.

    Parameters
    ----------
    vertices : (V, 3) float array
    faces : (F, 3) int array
    max_triangles : int
    file : str
        The mesh file, as the grasp file names it (for the errors).
    warnings : list, optional

    Returns
    -------
    vertices : (V', 3) float array, read-only
    faces : (F, 3) int array, read-only

    Raises
    ------
    InputError
        ``empty-mesh``, ``too-many-triangles``, ``invalid-mesh``, ``non-finite``, ``invalid-size`` or
        ``mesh-not-solid`` (every triangle of zero area).

    >>> tetra = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]])
    >>> faces = np.array([[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]])  # wound inwards
    >>> vertices, outwards = check_mesh(tetra, faces, 10, "t.obj")
    >>> a, b, c = vertices[outwards].transpose(1, 0, 2)
    >>> float(np.einsum("ij,ij->", a, np.cross(b, c)) / 6)  # the tetrahedron's volume, now positive
    0.16666666666666666
    >>> said = []
    >>> _ = check_mesh(tetra, faces, 10, "t.obj", said)
    >>> said
    ['mesh-repaired: faces re-wound outwards (the geometry is unchanged)']
    >>> said = []
    >>> _ = check_mesh(np.concatenate([tetra, tetra[:1]]), np.concatenate([faces, [[4, 1, 2]]]), 10, "t.obj", said)
    >>> said
    ['mesh-repaired: 1 duplicate vertex merged, faces re-wound outwards (the geometry is unchanged)']
    """
    if not len(faces):
        raise InputError("empty-mesh", "no triangles in the mesh", file)
    if len(faces) > max_triangles:
        raise InputError("too-many-triangles", f"{len(faces)} triangles, more than the limit of {max_triangles}", file)
    if faces.min() < 0 or faces.max() >= len(vertices):
        raise InputError("invalid-mesh", "a face names a vertex the file does not have", file)
    if not np.isfinite(vertices).all():
        raise InputError("non-finite", "a vertex coordinate is NaN or infinite", file)
    from ..engine.objects.checks import NOT_SOLID_HINT, repair_mesh

    _check_geometry(vertices, faces, file)
    repaired = repair_mesh(vertices, faces)  # equal vertices merged, zero-area faces dropped
    if str(file).lower().endswith(".stl"):  # the format repeats each vertex: merging them repairs nothing
        repaired = repaired._replace(merged=0)
    vertices, faces = repaired.vertices, repaired.faces
    if not len(faces):
        raise InputError(
            "mesh-not-solid", f"every triangle has zero area: the mesh bounds no solid: {NOT_SOLID_HINT}", file
        )
    a, b, c = vertices[faces].transpose(1, 0, 2)
    if np.einsum("ij,ij->", a, np.cross(b, c)) < 0:
        faces = np.ascontiguousarray(faces[:, ::-1])
        faces.setflags(write=False)
        repaired = repaired._replace(faces=faces, turned=True)
    if warnings is not None and repaired.warning():
        warnings.append(repaired.warning())
    return vertices, faces


def _check_geometry(vertices, faces, file):
    """Refuse a mesh whose own size is outside :data:`~grasptwist.engine.objects.checks.SIZE_RANGE`
    (checked here, before any ``scale``), as the engine's ``check_shape`` does."""
    from ..engine.objects.checks import check_extent

    try:
        check_extent(np.linalg.norm(vertices.max(axis=0) - vertices.min(axis=0)), "the mesh's")
    except ValueError as err:
        raise InputError("invalid-size", str(err), file) from None
