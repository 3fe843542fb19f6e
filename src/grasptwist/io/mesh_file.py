"""An object's triangle mesh (STL, OBJ or PLY), read as untrusted input.

A grasp file's ``object: {mesh: path}`` names it; trimesh (the optional
extra ``grasptwist[mesh]``) parses STL and PLY, an OBJ's ``v`` and ``f``
lines are read here (the format this project writes, without trimesh's
second of import), and the checks are numpy's.  Around it, as for a URDF
(:mod:`grasptwist.io.urdf`, whose path rule this shares):

* the reference: a path relative to the grasp file's folder, refused when it
  resolves (symbolic links followed) outside that folder (``path-outside``)
  unless the caller allows it (``--allow-outside``); ``package://PKG/path``
  inside an installed Python package;
* the bytes: at most ``max_bytes`` (the loader's ``--max-bytes``) of a regular
  file are read before anything is parsed, and a file whose format says it
  holds more than ``max_triangles`` triangles is refused unparsed (a binary
  STL's count, an ASCII STL's ``endfacet`` words, a PLY header's faces, an
  OBJ's ``f`` lines), so memory stays bounded by the cap; bytes that are no
  STL (neither a binary STL of its count's length nor text starting with
  ``solid``) are ``invalid-mesh`` unparsed;
* the geometry: at most ``max_triangles`` triangles (:data:`~grasptwist.io.limits.MAX_TRIANGLES`),
  finite vertices, every face index a vertex, and a size within ``SIZE_RANGE``
  (:mod:`grasptwist.engine.objects.checks`).  It is repaired without changing its geometry
  (equal vertices merged, zero-area triangles dropped: ``mesh-repaired``) and may be open or
  made of pieces: the solid it bounds is the engine's (:mod:`grasptwist.engine.objects.solid`).
  A mesh wound inwards is turned outwards.

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
``too-many-triangles``   more than ``max_triangles``
``non-finite``           a vertex coordinate that is NaN or infinite
``mesh-not-solid``       every triangle of zero area (the engine's check: no inside anywhere)
``invalid-size``         a size (bounding box diagonal) outside ``SIZE_RANGE``, 1e-75 to 1e75
``mesh-unavailable``     trimesh is not installed (an STL or PLY)
=======================  ==========================================================
"""

from __future__ import annotations

import os
import re
from pathlib import Path

import numpy as np

from ..model import InputError
from .limits import DEFAULT_MAX_BYTES, MAX_TRIANGLES, MESH_SUFFIXES

__all__ = ["read_mesh", "check_mesh"]

_PLY_FACES = re.compile(rb"^element\s+face\s+(\d+)\s*$", re.MULTILINE)
_ASCII_STL = re.compile(rb"\s*solid", re.IGNORECASE)
#: A binary STL: an 80-byte header, a little-endian uint32 count, then 50 bytes per triangle.
_STL_HEADER, _STL_TRIANGLE = 84, 50


def read_mesh(
    reference,
    folder=None,
    *,
    max_bytes=DEFAULT_MAX_BYTES,
    max_triangles=MAX_TRIANGLES,
    allow_outside=False,
    warnings=None,
):
    """The vertices and outward-wound triangles of a mesh file (repaired: :func:`check_mesh`).

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
    grasptwist.model.GraspFileError: box.step: expected a mesh file ending in .stl, .obj or .ply
    """
    text = os.fspath(reference)
    suffix = Path(text).suffix.lower()
    if suffix not in MESH_SUFFIXES:
        raise InputError(
            "unsupported-mesh", f"expected a mesh file ending in {', '.join(MESH_SUFFIXES[:-1])} or .ply", text
        )
    from .urdf import _read, resolve_urdf  # here: listing a folder (MESH_SUFFIXES) imports no URDF reader

    data = _read(resolve_urdf(text, folder, allow_outside=allow_outside), max_bytes, text)
    _too_many(_declared_triangles(data, suffix, text), max_triangles, text)
    try:
        vertices, faces = _obj(data) if suffix == ".obj" else _parsed(data, suffix, text)
    except (ValueError, IndexError):
        raise InputError("invalid-mesh", f"not a readable {suffix[1:].upper()} file", text) from None
    return check_mesh(vertices, faces, max_triangles, text, warnings)


def _obj(data):
    """``(vertices, faces)`` of a Wavefront OBJ's ``v`` and ``f`` lines (polygons as fans of
    triangles; ``a/b/c`` takes ``a``; negative indices count back from the vertices so far),
    read here: it is the format this project writes (``grasps/meshes/make_bottle.py``), and trimesh
    costs a second to import.  Other lines (normals, texture coordinates, groups, materials)
    are passed over.  Raises ValueError on what does not read."""
    vertices, faces = [], []
    for line in data.decode("utf-8", "strict").splitlines():
        words = line.split()
        if not words or words[0] not in ("v", "f"):
            continue
        if words[0] == "v":
            vertices.append([float(w) for w in words[1:4]])
            continue
        corners = [int(w.partition("/")[0]) for w in words[1:]]
        if len(corners) < 3 or 0 in corners:
            raise ValueError("a face needs three vertices, numbered from 1")
        corners = [c - 1 if c > 0 else len(vertices) + c for c in corners]
        faces += [(corners[0], corners[k], corners[k + 1]) for k in range(1, len(corners) - 1)]
    return np.array(vertices, dtype=float).reshape(-1, 3), np.array(faces, dtype=np.int64).reshape(-1, 3)


def _parsed(data, suffix, file):
    """``(vertices, faces)`` of an STL or PLY file, parsed by trimesh."""
    trimesh = _library(file)
    try:
        mesh = trimesh.load(
            trimesh.util.wrap_as_stream(data), file_type=suffix[1:], force="mesh", process=False, skip_materials=True
        )
        return np.asarray(mesh.vertices, dtype=float), np.asarray(mesh.faces, dtype=np.int64).reshape(-1, 3)
    except Exception:  # a parser's failure on hostile bytes has no one type; what it says varies by version
        raise ValueError(f"not a readable {suffix[1:].upper()} file") from None


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
    >>> _ = check_mesh(np.concatenate([tetra, tetra[:1]]), np.concatenate([faces, [[4, 1, 2]]]), 10, "t.obj", said)
    >>> said
    ['mesh-repaired: 1 duplicate vertex merged (the geometry is unchanged)']
    """
    if not len(faces):
        raise InputError("empty-mesh", "no triangles in the mesh", file)
    if len(faces) > max_triangles:
        raise InputError("too-many-triangles", f"{len(faces)} triangles, more than the limit of {max_triangles}", file)
    if faces.min() < 0 or faces.max() >= len(vertices):
        raise InputError("invalid-mesh", "a face names a vertex the file does not have", file)
    if not np.isfinite(vertices).all():
        raise InputError("non-finite", "a vertex coordinate is NaN or infinite", file)
    from ..engine.objects.checks import repair_mesh

    _check_geometry(vertices, faces, file)
    repaired = repair_mesh(vertices, faces)  # equal vertices merged, zero-area faces dropped
    if str(file).lower().endswith(".stl"):  # the format repeats each vertex: merging them repairs nothing
        repaired = repaired._replace(merged=0)
    if warnings is not None and repaired.warning():
        warnings.append(repaired.warning())
    vertices, faces = repaired.vertices, repaired.faces
    if not len(faces):
        raise InputError("mesh-not-solid", "every triangle has zero area: the mesh bounds no solid", file)
    a, b, c = vertices[faces].transpose(1, 0, 2)
    if np.einsum("ij,ij->", a, np.cross(b, c)) < 0:
        faces = np.ascontiguousarray(faces[:, ::-1])
        faces.setflags(write=False)
    return vertices, faces


def _check_geometry(vertices, faces, file):
    """Refuse a mesh whose own size is outside :data:`~grasptwist.engine.objects.checks.SIZE_RANGE`
    (checked here, before any ``scale``), as the engine's ``check_shape`` does."""
    from ..engine.objects.checks import check_extent

    try:
        check_extent(np.linalg.norm(vertices.max(axis=0) - vertices.min(axis=0)), "the mesh's")
    except ValueError as err:
        raise InputError("invalid-size", str(err), file) from None


def _declared_triangles(data, suffix, file):
    r"""How many triangles (or faces: a polygon is a fan of them) the file says it holds, found
    without parsing it; None where the format does not say.

    A binary STL gives its count in its header, and is exactly that long; an ASCII STL starts with
    ``solid`` and closes each triangle with ``endfacet``; a PLY's header declares its faces; an
    OBJ has an ``f`` line per face.  Bytes that are neither kind of STL are ``invalid-mesh``.

    >>> import struct
    >>> _declared_triangles(bytes(80) + struct.pack("<I", 2) + bytes(100), ".stl", "a.stl")
    2
    >>> _declared_triangles(b"v 0 0 0\nf 1 2 3\r\nf 1 3 4\n", ".obj", "a.obj")
    2
    >>> _declared_triangles(b"not a mesh", ".stl", "junk.stl")
    Traceback (most recent call last):
    grasptwist.model.GraspFileError: junk.stl: not a readable STL file (neither a binary STL of the length its count gives nor text starting with 'solid')
    """
    if suffix == ".stl":
        if len(data) >= _STL_HEADER:
            count = int.from_bytes(data[80:84], "little")
            if len(data) == _STL_HEADER + _STL_TRIANGLE * count:
                return count
        if _ASCII_STL.match(data[:1024]):
            return data.count(b"endfacet")
        raise InputError(
            "invalid-mesh",
            "not a readable STL file (neither a binary STL of the length its count gives nor text starting with 'solid')",
            file,
        )
    if suffix == ".ply":
        end = data.find(b"end_header")
        declared = _PLY_FACES.search(data[: end if end >= 0 else 4096])
        return int(declared.group(1)) if declared else None
    return sum(data.count(line) for line in (b"\nf ", b"\nf\t")) + data.startswith((b"f ", b"f\t"))


def _too_many(declared, max_triangles, file):
    """Refuse a file that says it holds more than ``max_triangles`` triangles, before a parser
    allocates arrays of that length."""
    if declared is not None and declared > max_triangles:
        raise InputError(
            "too-many-triangles",
            f"the file declares {declared} faces, more than the limit of {max_triangles} triangles",
            file,
        )


def _library(file):
    """trimesh, or the error that says which extra to install."""
    try:
        import trimesh
    except ImportError:
        raise InputError(
            "mesh-unavailable",
            "reading a mesh needs trimesh: pip install trimesh (from a clone of grasptwist: pip install -e '.[mesh]')",
            file,
        ) from None
    return trimesh
