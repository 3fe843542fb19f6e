"""The visual meshes of a hand's URDF, posed at joint positions, for pictures.

:mod:`grasptwist.io.urdf` reads a URDF for its joints and never opens a
mesh; a picture of the hand wants the links' shapes.  This reads the same
URDF again with the same checks (size cap, no DTD), then lets yourdfpy load
its visual meshes (through trimesh, which yourdfpy brings) and pose them by
its own forward kinematics of the same joints.  Each mesh file is resolved
as the URDF itself is (:func:`~grasptwist.io.urdf.resolve_urdf`: inside its
``package://`` package, or inside the URDF's folder) and must be a regular
file of at most :data:`MAX_MESH_BYTES`.
"""

from __future__ import annotations

import io
import os
import stat
from pathlib import Path

import numpy as np

from ..model import InputError
from .limits import DEFAULT_MAX_BYTES
from .urdf import _library, _parse, _read, resolve_urdf

__all__ = ["MAX_MESH_BYTES", "grasp_folder", "hand_meshes"]

#: Largest mesh file read.
MAX_MESH_BYTES = 64 << 20


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
        return str(path)

    model = yourdfpy.URDF.load(
        io.BytesIO(data),
        build_scene_graph=True,
        load_meshes=True,
        build_collision_scene_graph=False,
        load_collision_meshes=False,
        filename_handler=mesh_file,
    )
    if positions is not None:
        moved = dict(zip(hand.joint_names, map(float, positions)))
        model.update_cfg({j: moved.get(j, 0.0) for j in model.actuated_joint_names})
    return [(np.asarray(m.vertices, dtype=float), np.asarray(m.faces)) for m in model.scene.dump(concatenate=False)]


def grasp_folder(grasp) -> Path | None:
    """The folder of the file a grasp was read from (None for standard input or a string)."""
    return None if grasp.file.startswith("<") else Path(grasp.file).parent
