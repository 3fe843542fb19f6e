"""``grasptwist plot``: draw a grasp, its basis screw axes and the finger-tip velocities."""

import os
from dataclasses import replace
from typing import Annotated

import typer

from .diagnostics import Diagnostics, to_stderr
from .exits import EXIT_FAILED, EXIT_OK, checked_output, run_command
from .options import (
    AllowOutside,
    Clearance,
    Debug,
    MaxBytes,
    PlotMethod,
    Select,
    SurfaceTol,
    Table,
    reading_option,
    twists_option,
)

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
    surface_tol: SurfaceTol = None,
    table: Table = None,
    clearance: Clearance = None,
    allow_outside: AllowOutside = False,
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
    reading = reading_option(surface_tol, allow_outside, table, clearance)
    run_command(
        debug,
        lambda: draw_pictures(
            path, output, twists, chosen, method.value if method else None, max_bytes, views, reading
        ),
    )


def draw_pictures(path, output, twists, twist_name, method, max_bytes, views, reading) -> int:
    """The body of ``plot``: the command line's checks, then the run's reading
    (:func:`grasptwist.run.pictures.read_grasps`) and drawing (:func:`grasptwist.run.pictures.draw`);
    notes on stderr, the pictures' names on stdout; the exit status."""
    from .. import plot as pictures
    from ..io.datasets import DATASET_SUFFIXES
    from ..io.inputs import expand
    from ..run.pictures import draw, read_grasps
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
        for item in read_grasps(inputs, twists, max_bytes, reading):
            if isinstance(item, pictures.Note):
                note(item.line, item.error)
            else:
                grasps.append(item)
        drawn = draw(path, output, grasps, None if twists else twist_name, method, html, views, opener)
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
