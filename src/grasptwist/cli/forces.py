"""``grasptwist forces``: how hard each finger must press (issue 19)."""

from typing import Annotated

import typer

from .diagnostics import Warnings
from .exits import run_command
from .options import (
    AllowOutside,
    At,
    Clearance,
    ContactOption,
    Debug,
    Digits,
    ForcesFormat,
    Friction,
    Json,
    MaxBytes,
    Output,
    Paths,
    Quiet,
    Safety,
    SurfaceTol,
    Table,
    Torsion,
    WarningsOption,
    Workers,
    WrenchName,
    WrenchOption,
    contact_torsion,
    not_binary_to_a_terminal,
    reading_option,
    wrenches_option,
)
from .records import OutputSettings, write_records

__all__ = ["forces"]


def _cone_edges(value: int) -> int:
    from ..engine.forces.closure import check_cone_edges

    try:
        return check_cone_edges(value)
    except ValueError as err:
        raise typer.BadParameter(str(err)) from None


def forces(
    paths: Paths,
    wrench: WrenchOption = None,
    wrench_name: WrenchName = None,
    at: At = None,
    friction: Friction = None,
    safety: Safety = 1.0,
    contact: ContactOption = None,
    torsion: Torsion = None,
    quality: Annotated[
        bool, typer.Option("--quality", help="Also Ferrari-Canny's epsilon (needs scipy: grasptwist[quality]).")
    ] = False,
    cone_edges: Annotated[
        int,
        typer.Option(
            "--cone-edges",
            metavar="M",
            callback=_cone_edges,
            help="Sides of each friction pyramid for --quality (3 to 64).",
        ),
    ] = 8,
    fmt: Annotated[
        ForcesFormat,
        typer.Option(
            "-f", "--format", help="table for people; json, jsonl, csv, npz or parquet (with -o) for programs."
        ),
    ] = ForcesFormat.table,
    json_: Json = False,
    output: Output = None,
    digits: Digits = 4,
    max_bytes: MaxBytes = None,
    surface_tol: SurfaceTol = None,
    table: Table = None,
    clearance: Clearance = None,
    allow_outside: AllowOutside = False,
    workers: Workers = 0,
    quiet: Quiet = False,
    warnings: WarningsOption = Warnings.summary,
    debug: Debug = False,
) -> None:
    """Finger forces that exert each wrench: one record per (grasp, wrench).

    Per contact the manipulating forces (minimum norm), the grip (least total
    normal force inside the friction cones) and how close each finger is to
    slipping; per grasp its force closure.  Examples: hold the bundled 1 kg
    ball; a wrench from the command line with mu 0.8:

    \b
        grasptwist forces grasps/sphere.yaml
        grasptwist forces grasps/polyhedron.yaml --wrench 0,0,1,0,0,0 --friction 0.8 --json
    """
    from ..run.families import COMMANDS
    from ..run.options import ForceOptions
    from ..run.pipeline import Job

    wrenches = wrenches_option(wrench, at, wrench_name)
    torsion = contact_torsion(contact, torsion, friction)
    fmt = ForcesFormat.json if json_ else fmt
    not_binary_to_a_terminal(fmt.value, output)
    job = Job(
        command=COMMANDS["forces"],
        fmt=fmt.value,
        max_bytes=max_bytes,
        reading=reading_option(surface_tol, allow_outside, table, clearance),
        options=ForceOptions(
            wrenches=None if wrenches is None else tuple(wrenches),
            friction=friction,
            safety=safety,
            quality=quality,
            cone_edges=cone_edges,
            torsion=torsion,
        ),
    )
    settings = OutputSettings(output, quiet, warnings, workers, {"digits": digits})

    def body() -> int:
        if quality:  # a missing extra: one line (run_command's) before any input is read
            from ..extras import require

            require("scipy", "--quality")
        return write_records(job, paths, settings)

    run_command(debug, body)
