"""The ``plot`` command's run: grasps read, paths followed, meshes loaded and grips found, then drawn.

The pictures (:mod:`grasptwist.plot`) draw from the engine's geometry
alone; this module gives them what they draw beside a grasp: its hand's
link meshes, its paths followed as ``follow`` follows them and the grip
that holds its wrench, drawn in its friction cones.  Every input's errors
come back as :class:`~grasptwist.plot.Note` lines, in order.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import replace

from .. import plot as pictures
from ..engine.forces.grip import grip
from ..io.grasp import READING, Reading
from ..io.urdf_meshes import grasp_folder, hand_meshes
from ..model import Grasp, InputError
from ..output.records import diagnostics, error_record
from ..plot.animation import DEFAULT_SAMPLES
from .follow import Samples, Summary, follow_grasp
from .options import FollowOptions
from .placement import read

__all__ = ["draw", "read_grasps", "page_extras", "grip_forces"]


def read_grasps(inputs, twists, max_bytes: int | None, reading: Reading = READING) -> Iterator[Grasp | pictures.Note]:
    """The grasps of ``inputs`` (files, and the errors of listing a folder), read as every command
    reads them, with ``twists`` (the command line's) in place of their own; an input's errors as notes."""
    for item in inputs:
        for entry in read(item, max_bytes, reading) if isinstance(item, str) else [item]:
            if isinstance(entry, InputError):
                yield from (pictures.Note(line) for line in diagnostics(error_record(entry))[0])
            else:
                yield replace(entry, twists=tuple(twists)) if twists else entry


def page_extras(path_name):
    """What an HTML page shows beside the grasp (see :func:`grasptwist.plot.html_loaded`): its
    hand's link meshes and its paths (``path_name``: that one) followed as ``follow`` follows them."""

    def extras(grasp):
        meshes, followed, notes, chunks = [], [], [], []
        if grasp.hand is not None and grasp.hand.source is not None:
            try:
                meshes = hand_meshes(grasp.hand, grasp.joint_positions, folder=grasp_folder(grasp))
            except InputError as exc:  # the chains are drawn all the same
                notes.append(pictures.Note(f"{exc.file}: warning: no link meshes: {exc.message}", error=False))
        if grasp.paths or path_name is not None:
            options = FollowOptions(method="both", path=path_name, samples=DEFAULT_SAMPLES, bases=False)
            for item in follow_grasp(options, grasp):
                if isinstance(item, InputError):
                    notes.append(pictures.Note(f"{item.file}: error: {item.message}"))
                elif isinstance(item, Samples):
                    chunks.append(item)
                elif isinstance(item, Summary):
                    followed.append((chunks, item))
                    chunks = []
        return meshes, followed, notes

    return extras


def grip_forces(grasp):
    """The grip forces drawn with a grasp's friction cones: the engine's least grip for the
    wrench it holds (``hold``, from its ``mass``, else its first wrench); None without a
    friction, a wrench or a grip."""
    if grasp.friction is None or not grasp.wrenches:
        return None
    chosen = {w.name: w for w in grasp.wrenches}.get("hold", grasp.wrenches[0])
    g = grip(grasp.points, grasp.normals, chosen.wrench, grasp.friction)
    return g.force if bool(g.ok) else None


def draw(path, output, grasps, twist_name, method, html: bool, views, opener) -> Iterator[pictures.Note | str]:
    """Draw ``grasps`` (of ``path``) into ``output`` (``html``: interactive pages, with ``views``'
    ``js_beside`` and ``path_name``), each file written by ``opener``: the notes of what could not
    be drawn, and the name of each picture written, in order, as they are drawn.

    Raises
    ------
    TwistNotFound, ValueError
        ``twist_name`` is not a twist of the file; an unknown method or suffix.
    """
    if html:
        yield from pictures.html_loaded(
            path,
            output,
            grasps,
            twist_name=twist_name,
            method=method,
            js_beside=views["js_beside"],
            extras=page_extras(views["path_name"]),
            grips=grip_forces,
            opener=opener,
        )
    else:
        yield from pictures.render_loaded(
            path, output, grasps, twist_name=twist_name, method=method, grips=grip_forces, opener=opener
        )
