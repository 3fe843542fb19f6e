"""The visual meshes of a hand's URDF, posed at joint positions, for pictures.

:mod:`grasptwist.io.urdf` reads a URDF for its joints and never opens a
mesh; a picture of the hand wants the links' shapes.  This reads the same
URDF again with the same checks (size cap, no DTD), then lets yourdfpy load
its visual meshes (through trimesh, which yourdfpy brings) and pose them by
its own forward kinematics of the same joints.  Each mesh file is resolved
as the URDF itself is (:func:`~grasptwist.io.urdf.resolve_urdf`: inside its
``package://`` package, or inside the URDF's folder) and must be a regular
file that decodes to at most :data:`MAX_MESH_BYTES` (:func:`decoded_size`:
an archive or compressed stream is measured before the mesh library inflates
it).  A mesh the library cannot read, whatever it raises, is an
:class:`~grasptwist.model.InputError` naming it.
"""

from __future__ import annotations

import bz2
import gzip
import io
import lzma
import os
import stat
import zipfile
import zlib
from pathlib import Path

import numpy as np

from ..model import InputError
from .limits import DEFAULT_MAX_BYTES
from .urdf import _library, _parse, _read, resolve_urdf

__all__ = ["MAX_MESH_BYTES", "decoded_size", "grasp_folder", "hand_meshes"]

#: Most bytes a mesh file may hold, or decode to when it is an archive or compressed.
MAX_MESH_BYTES = 64 << 20

#: Compressed streams by their first bytes, and how to open one.
_STREAMS = {b"\x1f\x8b": gzip.open, b"BZh": bz2.open, b"\xfd7zXZ\x00": lzma.open}
_CHUNK = 1 << 20


def decoded_size(path, cap: int) -> int:
    """The bytes the file at ``path`` decodes to, counted no further than just past ``cap``.

    A zip archive (``.zip``, ``.3mf``: whatever its name, as a mesh library may
    open it by its content) decodes to the sizes its directory declares, which
    reading never exceeds; a gzip, bzip2 or xz stream (``.gz``, ``.tar.bz2``,
    ...) is inflated and counted, a megabyte at a time, up to ``cap``; any
    other file is its size.

    Raises
    ------
    OSError, EOFError, zipfile.BadZipFile, zlib.error, lzma.LZMAError
        A damaged archive or stream.

    >>> import tempfile
    >>> with tempfile.NamedTemporaryFile(suffix=".gz") as f:
    ...     f.write(gzip.compress(bytes(5_000_000))) and None
    ...     f.flush()
    ...     os.path.getsize(f.name) < 10_000, decoded_size(f.name, 1 << 20) > 1 << 20
    (True, True)
    """
    with open(path, "rb") as f:
        if zipfile.is_zipfile(f):
            with zipfile.ZipFile(f) as archive:
                return sum(info.file_size for info in archive.infolist())
        f.seek(0)
        head = f.read(6)
        opener = next((o for magic, o in _STREAMS.items() if head.startswith(magic)), None)
        if opener is None:
            return os.fstat(f.fileno()).st_size
        f.seek(0)
        size = 0
        with opener(f) as stream:
            while size <= cap and (chunk := stream.read(_CHUNK)):
                size += len(chunk)
        return size


def hand_meshes(hand, positions=None, *, folder=None, max_bytes=DEFAULT_MAX_BYTES) -> list[tuple]:
    """Every visual mesh of ``hand``'s URDF at joint ``positions``, in the hand's root frame.

    Parameters
    ----------
    hand : Hand
        Read from a URDF (``hand.source``); inline joints have no meshes.
    positions : (n_joints,) array, optional
        In ``hand.joint_names`` order (the URDF's other joints at 0); None: home.
    folder : str or os.PathLike, optional
        The referring grasp file's folder, for a URDF given by path.
    max_bytes : int
        Size cap of the URDF.

    Returns
    -------
    list of (vertices (n, 3) array, faces (m, 3) int array)
        Empty for a hand without a URDF.

    Raises
    ------
    InputError
        The URDF's errors (:mod:`grasptwist.io.urdf`), and for a mesh file
        ``path-outside``, ``read-error`` or ``too-large``.
    """
    if hand.source is None:
        return []
    urdf = resolve_urdf(hand.source, folder)
    data = _read(urdf, max_bytes, hand.source)
    _parse(data, hand.source)  # refuses a DTD, as the joints' reading did
    yourdfpy = _library(hand.source)

    def mesh_file(fname):  # yourdfpy passes it by this name
        name = fname
        try:
            path = resolve_urdf(name, urdf.parent)
        except InputError as exc:  # the error is the URDF's, about one of its meshes
            raise InputError(exc.code, f"mesh {exc.message}", hand.source) from None
        try:
            info = os.stat(path)
        except OSError as exc:
            raise InputError("read-error", f"mesh {name!r}: cannot read: {exc.strerror}", hand.source) from None
        if not stat.S_ISREG(info.st_mode):
            raise InputError("read-error", f"mesh {name!r}: not a regular file", hand.source)
        if info.st_size > MAX_MESH_BYTES:
            raise InputError("too-large", f"mesh {name!r}: larger than {MAX_MESH_BYTES} bytes", hand.source)
        try:
            size = decoded_size(path, MAX_MESH_BYTES)
        except (OSError, EOFError, zipfile.BadZipFile, zlib.error, lzma.LZMAError) as exc:
            raise InputError("read-error", f"mesh {name!r}: cannot read: {exc}", hand.source) from None
        if size > MAX_MESH_BYTES:
            raise InputError(
                "too-large",
                f"mesh {name!r}: decodes to more than {MAX_MESH_BYTES} bytes ({info.st_size:,} compressed)",
                hand.source,
            )
        asked.append(name)
        return str(path)

    asked = []  # the mesh files handed to the library, the one it is reading last
    try:
        model = yourdfpy.URDF.load(
            io.BytesIO(data),
            build_scene_graph=True,
            load_meshes=True,
            build_collision_scene_graph=False,
            load_collision_meshes=False,
            filename_handler=mesh_file,
        )
    except InputError:
        raise
    except Exception as exc:  # noqa: BLE001 - a malformed mesh: each format's parser raises its own kinds
        what = f"mesh {asked[-1]!r}" if asked else "its meshes"
        raise InputError("read-error", f"{what}: cannot read: {type(exc).__name__}: {exc}", hand.source) from None
    if positions is not None:
        moved = dict(zip(hand.joint_names, map(float, positions)))
        model.update_cfg({j: moved.get(j, 0.0) for j in model.actuated_joint_names})
    return [(np.asarray(m.vertices, dtype=float), np.asarray(m.faces)) for m in model.scene.dump(concatenate=False)]


def grasp_folder(grasp) -> Path | None:
    """The folder of the file a grasp was read from (None for standard input or a string)."""
    return None if grasp.file.startswith("<") else Path(grasp.file).parent
