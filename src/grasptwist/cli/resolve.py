"""``grasptwist resolve``: object twists into finger-tip twists and amplitudes."""

from typing import Annotated

import typer

from .diagnostics import Warnings
from .exits import run_command
from .options import (
    ALL,
    AllowOutside,
    Clearance,
    Debug,
    Digits,
    ExtraPoint,
    Json,
    MaxBytes,
    Method,
    Order,
    OrderOption,
    Output,
    Paths,
    Quiet,
    ResolveFormat,
    Select,
    SurfaceTol,
    Table,
    WarningsOption,
    Workers,
    hand_option,
    not_binary_to_a_terminal,
    reading_option,
    twists_option,
)
from .records import OutputSettings, write_records

__all__ = ["resolve"]


def resolve(
    paths: Paths,
    twist: Annotated[
        list[str] | None,
        typer.Option(
            "--twist",
            metavar="W1,W2,W3,V1,V2,V3",
            help="Object twist (omega; v); repeatable; replaces the files' twists.",
        ),
    ] = None,
    twist_name: Annotated[
        list[str] | None,
        typer.Option(
            "--twist-name",
            metavar="NAME",
            help="Name of each --twist in the records, paired in order (default: the twist as written).",
        ),
    ] = None,
    select: Select = None,
    at: Annotated[
        str | None,
        typer.Option(
            "--at", metavar="X,Y,Z", help="Point whose velocity the --twist linear part gives (default: the origin)."
        ),
    ] = None,
    twists_from: Annotated[
        str | None,
        typer.Option(
            "--twists-from",
            metavar="FILE|-",
            help="Twists one per line (JSON: [w1,w2,w3,v1,v2,v3] or a twist mapping), each resolved as it arrives.",
        ),
    ] = None,
    method: Method = ALL,
    fmt: Annotated[
        ResolveFormat,
        typer.Option(
            "-f", "--format", help="table for people; json, jsonl, csv, npz or parquet (with -o) for programs."
        ),
    ] = ResolveFormat.table,
    json_: Json = False,
    output: Output = None,
    digits: Digits = 4,
    order: OrderOption = Order.omega_v,
    extra_point: Annotated[
        ExtraPoint,
        typer.Option(
            "--extra-point",
            help="Role of a .npy's 19th-21st columns: the wrist, or the point the twists' linear velocity is given at.",
        ),
    ] = ExtraPoint.wrist,
    hand: Annotated[
        str | None,
        typer.Option(
            "--hand",
            metavar="FILE.yaml",
            help="The hand of a data set's rows (a YAML file holding just hand:), at its joint_positions; "
            "its joints name the CSV and npz joint-rate columns.",
        ),
    ] = None,
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
    """Resolve object twists into finger-tip twists and amplitudes: one record per (grasp, twist).

    Examples: spin the paper's cylinder about z and read the Psi amplitudes
    (--method off-tangent: the cylinder is degenerate for the tangent method);
    a data set of grasps as arrays, results as arrays:

    \b
        grasptwist resolve grasps/cylinder.yaml --method off-tangent --twist 0,0,1,0,0,0 --json | jq '.[0].off_tangent.y'
        grasptwist resolve grasps/cylinder.yaml --select spin-z --method off-tangent
        grasptwist resolve grasps.npz --twist 0,0,1,0,0,0 -f npz -o results.npz
    """
    from ..io.datasets import DATASET_SUFFIXES
    from ..run.families import COMMANDS
    from ..run.options import TwistOptions
    from ..run.pipeline import Job

    twists = twists_option(twist, at, twist_name)
    if twists_from is not None and twists is not None:
        raise typer.BadParameter("give twists by --twist or by --twists-from, not both", param_hint="--twists-from")
    if select and (twists is not None or twists_from is not None):
        raise typer.BadParameter(
            "--select picks the files' own twists; --twist and --twists-from replace them: give one",
            param_hint="--select",
        )
    if select and any(p.endswith(DATASET_SUFFIXES) for p in paths):
        raise typer.BadParameter("picks a grasp file's named twists; a data set's are not named", param_hint="--select")
    if twists_from == "-" and "-" in paths:
        raise typer.BadParameter("standard input can be read only once", param_hint="--twists-from")
    if extra_point == ExtraPoint.at and at is not None:
        raise typer.BadParameter("--extra-point at gives each row its own point; drop --at", param_hint="--at")
    if extra_point == ExtraPoint.at and not any(p.endswith(".npy") for p in paths):
        raise typer.BadParameter("applies to .npy data sets (their 19th-21st columns)", param_hint="--extra-point")
    fmt = ResolveFormat.json if json_ else fmt
    not_binary_to_a_terminal(fmt.value, output)
    job = Job(
        command=COMMANDS["resolve"],
        fmt=fmt.value,
        max_bytes=max_bytes,
        reading=reading_option(surface_tol, allow_outside, table, clearance),
        order=order.value,
        extra_point=extra_point.value,
        hand=hand_option(hand, paths, fmt.value),
        options=TwistOptions(
            twists=None if twists is None else tuple(twists),
            method=method.value,
            twists_from=twists_from,
            select=tuple(select) if select else None,
        ),
    )
    table_options = {"digits": digits, "order": order.value}
    settings = OutputSettings(output, quiet, warnings, workers, table_options, reads=(twists_from, hand))
    run_command(debug, lambda: write_records(job, paths, settings))
