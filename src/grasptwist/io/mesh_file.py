"""An object's triangle mesh (STL, OBJ or PLY), read as untrusted input.

A grasp file's ``object: {mesh: path}`` names it; trimesh (the optional
extra ``grasptwist[mesh]``) parses it.  Around it, as for a URDF
(:mod:`grasptwist.io.urdf`, whose path rule this shares):

* the reference: a path relative to the grasp file's folder, refused when it
  resolves (symbolic links followed) outside that folder (``path-outside``)
  unless the caller allows it (``--allow-outside``); ``package://PKG/path``
  inside an installed Python package;
* the bytes: at most ``max_bytes`` (the loader's ``--max-bytes``) of a regular
  file are read before anything is parsed, and a PLY header declaring more
  than ``max_triangles`` faces is refused unparsed, so memory stays bounded
  by the cap;
* the geometry: at most ``max_triangles`` triangles (:data:`~grasptwist.io.limits.MAX_TRIANGLES`),
  finite vertices, every face index a vertex, and a closed surface: each
  edge shared by exactly two triangles, wound the same way (a volume, a
  centre of mass and an inside need one).  A mesh wound inwards is turned
  outwards.

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
``not-watertight``       an open, non-manifold or inconsistently wound surface
``mesh-unavailable``     trimesh is not installed
=======================  ==========================================================
"""

from __future__ import annotations

import os
import re
from pathlib import Path

import numpy as np

from ..model import InputError
from .limits import DEFAULT_MAX_BYTES, MAX_TRIANGLES
from .urdf import _read, resolve_urdf

__all__ = ["MESH_SUFFIXES", "read_mesh", "check_mesh"]

#: The formats read, by file suffix (in any letter case).
MESH_SUFFIXES = (".stl", ".obj", ".ply")

_PLY_FACES = re.compile(rb"^element\s+face\s+(\d+)\s*$", re.MULTILINE)


def read_mesh(
    reference,
    folder=None,
    *,
    max_bytes=DEFAULT_MAX_BYTES,
    max_triangles=MAX_TRIANGLES,
    allow_outside=False,
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
    data = _read(resolve_urdf(text, folder, allow_outside=allow_outside), max_bytes, text)
    if suffix == ".ply":
        _check_ply_header(data, max_triangles, text)
    trimesh = _library(text)  # after the checks that need no parser: a refused file costs no import (1 s)
    try:
        mesh = trimesh.load(
            trimesh.util.wrap_as_stream(data), file_type=suffix[1:], force="mesh", process=False, skip_materials=True
        )
        vertices = np.asarray(mesh.vertices, dtype=float)
        faces = np.asarray(mesh.faces, dtype=np.int64).reshape(-1, 3)
    except Exception:  # a parser's failure on hostile bytes has no one type; what it says varies by version
        raise InputError("invalid-mesh", f"not a readable {suffix[1:].upper()} file", text) from None
    return check_mesh(trimesh, vertices, faces, max_triangles, text)


def check_mesh(trimesh, vertices, faces, max_triangles, file):
    """``(vertices, faces)`` of a parsed mesh once it is a closed surface within the limits,
    its duplicate vertices merged and wound outwards (see :func:`read_mesh`)."""
    if not len(faces):
        raise InputError("empty-mesh", "no triangles in the mesh", file)
    if len(faces) > max_triangles:
        raise InputError("too-many-triangles", f"{len(faces)} triangles, more than the limit of {max_triangles}", file)
    if faces.min() < 0 or faces.max() >= len(vertices):
        raise InputError("invalid-mesh", "a face names a vertex the file does not have", file)
    if not np.isfinite(vertices).all():
        raise InputError("non-finite", "a vertex coordinate is NaN or infinite", file)
    mesh = trimesh.Trimesh(vertices, faces, process=False)
    mesh.merge_vertices()  # an STL repeats each vertex per triangle: edges are shared only once merged
    mesh.remove_unreferenced_vertices()
    if not (mesh.is_watertight and mesh.is_winding_consistent):
        raise InputError(
            "not-watertight",
            "not a closed surface (every edge shared by exactly two triangles, wound the same way)",
            file,
        )
    if mesh.volume < 0:
        mesh.invert()
    vertices, faces = np.array(mesh.vertices, dtype=float), np.array(mesh.faces, dtype=np.int64)
    for a in (vertices, faces):
        a.setflags(write=False)
    return vertices, faces


def _check_ply_header(data, max_triangles, file):
    """Refuse a PLY whose header declares more faces than ``max_triangles`` before trimesh
    allocates arrays of that length."""
    end = data.find(b"end_header")
    header = data[: end if end >= 0 else 4096]
    declared = _PLY_FACES.search(header)
    if declared and int(declared.group(1)) > max_triangles:
        raise InputError(
            "too-many-triangles",
            f"the header declares {int(declared.group(1))} faces, more than the limit of {max_triangles}",
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
