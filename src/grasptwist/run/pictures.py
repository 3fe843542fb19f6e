"""The ``plot`` command's run: grasps read, paths followed, meshes loaded and grips found, then drawn.

The pictures (:mod:`grasptwist.plot`) draw from the engine's geometry
alone; this module gives them what they draw beside a grasp: its hand's
link meshes, its paths followed as ``follow`` follows them and the grip
that holds its wrench, drawn in its friction cones.  Every input's errors
come back as :class:`~grasptwist.plot.Note` lines, in order.
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from dataclasses import replace

import numpy as np

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

__all__ = ["draw", "drawn_together", "read_grasps", "page_extras", "grip_forces", "same_object"]


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


def same_object(a, b) -> bool:
    """Whether two objects are one: the same shape (kind, sizes, a mesh's vertices and faces)
    at the same pose, number for number (as the documents ``synthesize -o`` writes hold it)."""
    x, y = a.shape, b.shape
    pairs = ((x.size, y.size), (x.vertices, y.vertices), (x.faces, y.faces), (a.pose, b.pose))
    return x.kind == y.kind and all(
        (u is None) == (v is None) and (u is None or np.array_equal(u, v)) for u, v in pairs
    )


def drawn_together(path, grasps, asked: bool) -> bool:
    """Whether the grasps read from ``path`` make one picture (:func:`grasptwist.plot.grasps_scene`):
    a file (not a folder) of several grasps of one object (:func:`same_object`), as ``synthesize -o``
    writes them, none with a twist or a path to draw, and none asked for (``asked``: a twist, a
    method or a path on the command line).  Otherwise each grasp is a picture of its own, of a
    file its first."""
    if asked or os.path.isdir(path) or len(grasps) < 2 or grasps[0].object is None:
        return False
    first = grasps[0].object
    return all(not g.twists and not g.paths and g.object is not None and same_object(g.object, first) for g in grasps)


def draw(path, output, grasps, twist_name, method, html: bool, views, opener) -> Iterator[pictures.Note | str]:
    """Draw ``grasps`` (of ``path``) into ``output`` (``html``: interactive pages, with ``views``'
    ``js_beside`` and ``path_name``), each file written by ``opener``: the notes of what could not
    be drawn, and the name of each picture written, in order, as they are drawn.  Several grasps
    of one object (:func:`drawn_together`) make one picture of them all.

    Raises
    ------
    TwistNotFound, ValueError
        ``twist_name`` is not a twist of the file; an unknown method or suffix.
    """
    asked = twist_name is not None or method is not None or views["path_name"] is not None
    if drawn_together(path, grasps, asked):
        if html:
            figure = pictures.grasps_figure(grasps)
            heading = f"{grasps[0].name} to {grasps[-1].name}"
            yield pictures.write_page(
                output, [(heading, figure)], title=f"grasptwist: {heading}", js_beside=views["js_beside"], opener=opener
            )
        else:
            yield pictures.render(pictures.grasps_scene(grasps), output, opener=opener)
        return
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
