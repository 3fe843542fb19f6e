"""``grasptwist plot``: draw a grasp, its basis screw axes and the finger-tip velocities."""

import os
from dataclasses import replace
from typing import Annotated

import typer

from .diagnostics import Diagnostics, to_stderr
from .exits import EXIT_FAILED, EXIT_OK, checked_output, run_command
from .options import Debug, MaxBytes, PlotMethod, Select, twists_option

__all__ = ["plot", "draw_pictures"]


def plot(
    path: Annotated[
        str, typer.Argument(metavar="PATH", help="A grasp file, or a folder for one image per grasp and twist.")
    ],
    output: Annotated[
        str,
        typer.Option(
            "-o",
            "--output",
            metavar="FILE|FOLDER",
            help="The image (.png, .svg or .pdf) or interactive view (.html), or the folder for a folder's images.",
        ),
    ],
    twist: Annotated[
        str | None,
        typer.Option("--twist", metavar="W1,W2,W3,V1,V2,V3", help="Draw this twist (omega; v) instead of the file's."),
    ] = None,
    twist_name: Annotated[
        str | None,
        typer.Option("--twist-name", metavar="NAME", help="The name of --twist in the picture."),
    ] = None,
    select: Select = None,
    at: Annotated[
        str | None,
        typer.Option("--at", metavar="X,Y,Z", help="Point whose velocity the --twist linear part gives."),
    ] = None,
    method: Annotated[
        PlotMethod | None,
        typer.Option("--method", help="Basis to draw (default: off-tangent with a wrist, else tangent)."),
    ] = None,
    js_beside: Annotated[
        bool,
        typer.Option(
            "--js-beside", help="HTML views: write plotly.js once beside them (plotly.min.js), not inside each."
        ),
    ] = False,
    path_name: Annotated[
        str | None,
        typer.Option(
            "--path", metavar="NAME", help="HTML views: animate this path of the grasp (default: every path)."
        ),
    ] = None,
    max_bytes: MaxBytes = None,
    debug: Debug = False,
) -> None:
    """Draw a grasp, its basis screw axes and the finger-tip velocities (needs matplotlib: from a clone,
    pip install -e '.[plot]'; an interactive .html view needs plotly: pip install -e '.[html]').
    A folder gets HTML views with --js-beside or --path.

    Examples: the paper's cylinder spinning about z, every bundled grasp, and a view to turn in a browser:

    \b
        grasptwist plot grasps/cylinder.yaml --select spin-z -o cylinder.png
        grasptwist plot grasps/ -o pictures/
        grasptwist plot grasps/trifinger-cube.yaml -o trifinger.html
    """
    twists = twists_option([twist] if twist else None, at)
    if twists and select:
        raise typer.BadParameter(
            "--select picks one of the file's twists; --twist replaces them: give one", param_hint="--select"
        )
    if twists and twist_name:
        twists = [replace(twists[0], name=twist_name)]
    elif twist_name:  # before --select, --twist-name also picked the file's twist
        if select:
            raise typer.BadParameter("names --twist only: give the file's twist by --select", param_hint="--twist-name")
        to_stderr(f"grasptwist: warning: plot --twist-name without --twist is deprecated: use --select {twist_name}")
        select = [twist_name]
    if select and os.path.isdir(path):
        raise typer.BadParameter("picks a twist of one grasp file; a folder gets every twist", param_hint="--select")
    if select and len(select) > 1:
        raise typer.BadParameter(f"a picture draws one twist: give one (got {len(select)})", param_hint="--select")
    chosen = select[0] if select else None
    views = {"js_beside": js_beside, "path_name": path_name}
    run_command(
        debug,
        lambda: draw_pictures(path, output, twists, chosen, method.value if method else None, max_bytes, views),
    )


def _page_extras(path_name):
    """What an HTML page shows beside the grasp (see :func:`grasptwist.plot.html_loaded`): its
    hand's link meshes and its paths followed as ``follow`` follows them."""
    from .. import plot as pictures
    from ..io.urdf_meshes import grasp_folder, hand_meshes
    from ..model import InputError
    from ..plot.animation import DEFAULT_SAMPLES
    from ..run.follow import FollowJob, Samples, Summary, follow_grasp

    def extras(grasp):
        meshes, followed, notes, chunks = [], [], [], []
        if grasp.hand is not None and grasp.hand.source is not None:
            try:
                meshes = hand_meshes(grasp.hand, grasp.joint_positions, folder=grasp_folder(grasp))
            except InputError as exc:  # the chains are drawn all the same
                notes.append(pictures.Note(f"{exc.file}: warning: no link meshes: {exc.message}", error=False))
        if grasp.paths or path_name is not None:
            job = FollowJob(method="both", path=path_name, samples=DEFAULT_SAMPLES, bases=False)
            for item in follow_grasp(job, grasp):
                if isinstance(item, InputError):
                    notes.append(pictures.Note(f"{item.file}: error: {item.message}"))
                elif isinstance(item, Samples):
                    chunks.append(item)
                elif isinstance(item, Summary):
                    followed.append((chunks, item))
                    chunks = []
        return meshes, followed, notes

    return extras


def _grip_forces(grasp):
    """The grip forces drawn with a grasp's friction cones: the engine's least grip for the
    wrench it holds (``hold``, from its ``mass``, else its first wrench); None without a
    friction, a wrench or a grip."""
    from ..engine.forces.grip import grip

    if grasp.friction is None or not grasp.wrenches:
        return None
    chosen = {w.name: w for w in grasp.wrenches}.get("hold", grasp.wrenches[0])
    g = grip(grasp.points, grasp.normals, chosen.wrench, grasp.friction)
    return g.force if bool(g.ok) else None


def draw_pictures(path, output, twists, twist_name, method, max_bytes, views) -> int:
    """The body of ``plot``: read ``path`` as every command does, draw by
    :func:`grasptwist.plot.render_loaded`, report on stderr; the exit status."""
    from .. import plot as pictures
    from ..io.datasets import DATASET_SUFFIXES
    from ..io.inputs import expand, read
    from ..model import InputError
    from ..output.records import diagnostics, error_record
    from ..run.target import opened

    stderr = Diagnostics()
    if path.endswith(DATASET_SUFFIXES):
        raise typer.BadParameter(
            "plot draws grasp files (.yaml, .yml) or folders of them, not data sets", param_hint="PATH"
        )
    inputs = list(expand([path]))
    if not os.path.isdir(path) or not output:  # a folder's -o is the folder its images go to
        checked_output(output, inputs)

    def opener(image):  # each image as -o writes a file: replaced atomically, never an input
        return opened(str(image), inputs)

    def note(line: str, error: bool = True) -> None:
        stderr.failed += error
        stderr.say(line, ": error: " if error else ": warning: ", "31" if error else "33")

    html = output.lower().endswith(pictures.HTML) or (os.path.isdir(path) and any(views.values()))
    if not html and any(views.values()):
        raise typer.BadParameter("applies to HTML views (-o FILE.html)", param_hint="--js-beside/--path")
    try:
        (pictures.require_plotly if html else pictures.require_matplotlib)()  # before anything is read
        grasps = []
        for item in inputs:
            for entry in read(item, max_bytes) if isinstance(item, str) else [item]:
                if isinstance(entry, InputError):
                    for line in diagnostics(error_record(entry))[0]:
                        note(line)
                else:
                    grasps.append(replace(entry, twists=tuple(twists)) if twists else entry)
        if html:
            drawn = pictures.html_loaded(
                path,
                output,
                grasps,
                twist_name=None if twists else twist_name,
                method=method,
                js_beside=views["js_beside"],
                extras=_page_extras(views["path_name"]),
                grips=_grip_forces,
                opener=opener,
            )
        else:
            drawn = pictures.render_loaded(
                path,
                output,
                grasps,
                twist_name=None if twists else twist_name,
                method=method,
                grips=_grip_forces,
                opener=opener,
            )
        with opened(None) as listing:  # a closed stdout is a write error before anything is drawn
            for item in drawn:
                if isinstance(item, pictures.Note):
                    note(item.line, item.error)
                else:
                    listing.write(os.fsencode(f"{item}\n"))
    except (pictures.MissingMatplotlib, pictures.MissingPlotly) as exc:
        to_stderr(str(exc))  # "grasptwist plot needs matplotlib: ..." (or plotly)
        return EXIT_FAILED
    except pictures.TwistNotFound as exc:
        raise typer.BadParameter(str(exc), param_hint="--select") from None
    except ValueError as exc:  # an unknown method or suffix, off-tangent without a wrist
        raise typer.BadParameter(str(exc)) from None
    return EXIT_FAILED if stderr.failed else EXIT_OK
