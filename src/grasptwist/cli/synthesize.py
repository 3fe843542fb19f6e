"""``grasptwist synthesize``: search an object's surface for three-fingered grasps (issue 31)."""

from enum import Enum
from typing import Annotated

import typer

from .diagnostics import Warnings
from .exits import checked_output, run_command
from .options import (
    ALL,
    AllowOutside,
    At,
    Debug,
    Digits,
    Friction,
    Json,
    MaxBytes,
    Method,
    Output,
    Quiet,
    Safety,
    SurfaceTol,
    SynthesizeFormat,
    Workers,
    WrenchName,
    WrenchOption,
    hand_option,
    not_binary_to_a_terminal,
    reading_option,
    wrenches_option,
)
from .records import OutputSettings, write_records

__all__ = ["synthesize"]

#: ``-o`` names a grasp file (the grasps found) when it ends so; else it takes the records.
GRASP_FILE_SUFFIXES = (".yaml", ".yml")


class Objective(str, Enum):
    total_normal_force = "total_normal_force"
    closure_friction = "closure_friction"
    epsilon = "epsilon"


def _checked(check):
    """A typer callback that turns an engine check's ValueError into a usage error."""

    def callback(value):
        try:
            return value if value is None else check(value)
        except ValueError as err:
            raise typer.BadParameter(str(err)) from None

    return callback


def _min_conditioning(value):
    from ..engine.synthesis.scores import check_min_conditioning

    return check_min_conditioning(value)


def _positive(value):
    """--mass, --seconds: the engine's checks (check_budget's seconds), in the command line's words."""
    if not 0 < value < float("inf"):
        raise ValueError(f"must be a finite number > 0, got {value:g}")
    return value


def synthesize(
    paths: Annotated[
        list[str],
        typer.Argument(
            metavar="PATH...",
            help="Grasp files with an object (.yaml, .yml, .json), mesh files (.stl, .obj, .ply) or folders.",
        ),
    ],
    count: Annotated[int, typer.Option("-n", "--count", min=1, max=10_000, help="Grasps wanted per object.")] = 5,
    friction: Friction = None,
    mass: Annotated[
        float | None,
        typer.Option(
            "--mass",
            metavar="KG",
            callback=_checked(_positive),
            help="The object's mass: its weight is the wrench 'hold'.",
        ),
    ] = None,
    wrench: WrenchOption = None,
    wrench_name: WrenchName = None,
    at: At = None,
    safety: Safety = 1.0,
    objective: Annotated[
        Objective, typer.Option("--objective", help="What the search minimises (epsilon: maximises).")
    ] = Objective.total_normal_force,
    method: Method = ALL,
    min_conditioning: Annotated[
        float,
        typer.Option(
            "--min-conditioning",
            metavar="C",
            callback=_checked(_min_conditioning),
            help="Each decomposition's conditioning must be at least this (0 to 1).",
        ),
    ] = 1e-3,
    min_spacing: Annotated[
        float | None,
        typer.Option(
            "--min-spacing",
            metavar="D",
            min=0,
            help="Grasps returned are at least this far apart (default: 5% of the object's size).",
        ),
    ] = None,
    hand: Annotated[
        str | None,
        typer.Option(
            "--hand",
            metavar="FILE",
            help="A hand that must reach every grasp (a YAML file holding just hand:, a URDF one); "
            "default: the grasp file's hand.",
        ),
    ] = None,
    tip_radius: Annotated[
        float | None,
        typer.Option(
            "--tip-radius",
            metavar="R",
            min=0,
            help="Every fingertip's radius (default: the hand's tip_radius, or its URDF's tip spheres); "
            "an object without a hand warns that it is ignored.",
        ),
    ] = None,
    quality: Annotated[bool, typer.Option("--quality", help="Also Ferrari-Canny's epsilon (needs scipy).")] = False,
    simulate: Annotated[
        bool,
        typer.Option(
            "--simulate",
            help="Keep only the grasps that hold in all six directions in MuJoCo (grasptwist simulate's "
            "defaults); stderr counts the others. Needs MuJoCo: pip install 'grasptwist[sim]'.",
        ),
    ] = False,
    seed: Annotated[int, typer.Option("--seed", min=0, help="Seed of the random numbers (reproducible runs).")] = 0,
    candidates: Annotated[
        int, typer.Option("--candidates", min=1, max=10**9, help="Candidate triples scored at most, per object.")
    ] = 20000,
    seconds: Annotated[
        float,
        typer.Option(
            "--seconds",
            metavar="S",
            callback=_checked(_positive),
            help="Time allowed per object: the search stops at 80% of it, verification at the end (grasps left unverified are not reported).",
        ),
    ] = 60.0,
    fmt: Annotated[
        SynthesizeFormat,
        typer.Option("-f", "--format", help="table for people; json, jsonl, csv or parquet (with -o) for programs."),
    ] = SynthesizeFormat.table,
    json_: Json = False,
    output: Output = None,
    digits: Digits = 4,
    max_bytes: MaxBytes = None,
    surface_tol: SurfaceTol = None,
    allow_outside: AllowOutside = False,
    workers: Workers = 1,
    quiet: Quiet = False,
    debug: Debug = False,
) -> None:
    """Search each object's surface for three-fingered grasps that hold it: one record per grasp, best first.

    Candidates are scored in batches (force closure at mu / S, both decompositions
    well conditioned, the least total normal force for every wrench), the best
    refined on the surface, and each grasp returned is verified by the exact grip.
    With a hand (the file's, or --hand) every grasp is reached within the joint limits,
    fingertips on the surface and no finger link in the object; the records give the
    joint positions. The object's weight ('hold', from its mass or --mass) is always
    held; --wrench adds wrenches beside it. With -o FILE.yaml the grasps are written as a grasp file every
    command reads (the records go to stdout). Exit 1 when an object has no feasible grasp.
    Examples:

    \b
        grasptwist synthesize grasps/sphere.yaml -n 3
        grasptwist synthesize grasps/trifinger-cube.yaml --friction 0.8 --mass 0.1 -o found.yaml
        grasptwist synthesize objects/ -j 2 -f jsonl      # a folder: one object a process
    """
    from ..extras import require
    from ..run.families import COMMANDS
    from ..run.options import SimulateOptions, SynthesisOptions
    from ..run.pipeline import Job

    if quality or objective == Objective.epsilon:
        require("scipy", "--quality")
    if simulate:
        require("mujoco", "--simulate")
    wrenches = wrenches_option(wrench, at, wrench_name)
    grasp_file = output if output is not None and output.lower().endswith(GRASP_FILE_SUFFIXES) else None
    records_to = None if grasp_file is not None else output
    if grasp_file is not None:  # written at the end of the run: refused before any work, as a records file is
        from ..io.inputs import OBJECT_SUFFIXES, expand

        checked_output(grasp_file, [p for p in expand(paths, OBJECT_SUFFIXES) if isinstance(p, str)])
    fmt = SynthesizeFormat.json if json_ else fmt
    not_binary_to_a_terminal(fmt.value, records_to)
    job = Job(
        command=COMMANDS["synthesize"],
        fmt=fmt.value,
        # --hand's, else one grasp file's first hand: it names the joint columns of CSV and Parquet
        hand=hand_option(hand, paths, fmt.value),
        max_bytes=max_bytes,
        reading=reading_option(surface_tol, allow_outside),
        options=SynthesisOptions(
            count=count,
            friction=friction,
            mass=mass,
            wrenches=None if wrenches is None else tuple(wrenches),
            safety=safety,
            objective=objective.value,
            method=method.value,
            min_conditioning=min_conditioning,
            min_spacing=min_spacing,
            quality=quality,
            seed=seed,
            candidates=candidates,
            seconds=seconds,
            grasp_file=grasp_file,
            tip_radius=tip_radius,
            hand_file=hand,
            simulate=SimulateOptions() if simulate else None,
        ),
    )
    settings = OutputSettings(records_to, quiet, Warnings.summary, workers, {"digits": digits}, reads=(hand,))
    run_command(debug, lambda: write_records(job, paths, settings))
