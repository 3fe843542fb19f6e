"""``grasptwist follow``: move the object along paths, resolve every sample, find the degeneracies."""

from typing import Annotated

import typer

from ..io.limits import MAX_SAMPLES
from .diagnostics import Warnings
from .exits import run_command
from .options import (
    ALL,
    AllowOutside,
    Clearance,
    Debug,
    Digits,
    FollowFormat,
    Frame,
    Json,
    MaxBytes,
    Method,
    Order,
    OrderOption,
    Output,
    Quiet,
    SurfaceTol,
    Table,
    hand_option,
    not_binary_to_a_terminal,
    reading_option,
    segments_option,
)
from .records import OutputSettings, write_records

__all__ = ["follow"]


def follow(
    paths: Annotated[
        list[str],
        typer.Argument(
            metavar="PATH...", help="Grasp files (.yaml, .yml, .json; any case), folders of them or - (stdin)."
        ),
    ],
    path: Annotated[
        str | None, typer.Option("--path", metavar="NAME", help="Follow only the files' paths of this name.")
    ] = None,
    twist: Annotated[
        list[str] | None,
        typer.Option(
            "--twist",
            metavar="W1,W2,W3,V1,V2,V3",
            help="A segment's constant twist (omega; v), each with a --duration, in order: a path replacing the files'.",
        ),
    ] = None,
    duration: Annotated[
        list[float] | None,
        typer.Option("--duration", metavar="T", help="How long the --twist of the same rank is held (> 0)."),
    ] = None,
    frame: Annotated[Frame, typer.Option("--frame", help="Frame of the --twist segments.")] = Frame.space,
    samples: Annotated[
        int | None,
        typer.Option(
            "--samples", min=2, max=MAX_SAMPLES, help="Samples per path, evenly spaced, ends included (default 21)."
        ),
    ] = None,
    dt: Annotated[
        float | None, typer.Option("--dt", metavar="DT", help="Time step between samples instead of --samples.")
    ] = None,
    method: Method = ALL,
    fmt: Annotated[
        FollowFormat,
        typer.Option("-f", "--format", help="table for people; json, jsonl, csv or npz (with -o) for programs."),
    ] = FollowFormat.table,
    json_: Json = False,
    output: Output = None,
    digits: Digits = 4,
    order: OrderOption = Order.omega_v,
    max_bytes: MaxBytes = None,
    surface_tol: SurfaceTol = None,
    table: Table = None,
    clearance: Clearance = None,
    allow_outside: AllowOutside = False,
    quiet: Quiet = False,
    debug: Debug = False,
) -> None:
    """Move the object along each path, the contacts with it, resolve every sample and find the degeneracies between samples.

    One record per sample, then a summary per path; exit 1 if a method is
    degenerate somewhere on a path. Examples: the paper's cylinder turning
    half a turn about x (its wrist crosses the contacts' plane at t = pi/2);
    a path from the command line, a quarter turn about z then a lift:

    \b
        grasptwist follow grasps/cylinder.yaml --method off-tangent --samples 5
        grasptwist follow grasps/polyhedron.yaml --twist 0,0,1,0,0,0 --duration 1.5708 --twist 0,0,0,0,0,1 --duration 1 -f jsonl
    """
    from ..run.families import COMMANDS
    from ..run.options import FollowOptions
    from ..run.pipeline import Job

    segments = segments_option(twist, duration, frame.value)
    if segments and path is not None:
        raise typer.BadParameter(
            "--path picks one of the files' paths; --twist replaces them: give one", param_hint="--path"
        )
    if samples is not None and dt is not None:
        raise typer.BadParameter("give --samples or --dt, not both", param_hint="--dt")
    if dt is not None and not (dt > 0 and dt != float("inf")):
        raise typer.BadParameter(f"must be a finite number > 0, got {dt}", param_hint="--dt")
    fmt = FollowFormat.json if json_ else fmt
    not_binary_to_a_terminal(fmt.value, output)
    job = Job(
        command=COMMANDS["follow"],
        fmt=fmt.value,
        max_bytes=max_bytes,
        reading=reading_option(surface_tol, allow_outside, table, clearance),
        order=order.value,
        hand=hand_option(None, paths, fmt.value),
        options=FollowOptions(method=method.value, path=path, segments=segments, samples=samples, dt=dt),
    )
    settings = OutputSettings(output, quiet, Warnings.summary, 1, {"digits": digits, "order": order.value})
    run_command(debug, lambda: write_records(job, paths, settings))
