"""``grasptwist simulate``: run each grasp in MuJoCo, the six-direction hold test (issue 38)."""

import math
import os
from typing import Annotated

import typer

from .diagnostics import Warnings
from .exits import run_command
from .options import (
    AllowOutside,
    Debug,
    Digits,
    Friction,
    Json,
    MaxBytes,
    Output,
    Quiet,
    Safety,
    SimulateFormat,
    SurfaceTol,
    Workers,
    not_binary_to_a_terminal,
    reading_option,
)
from .records import OutputSettings, write_records

__all__ = ["simulate"]


def _finite_positive(value, name):
    if not 0 < value < math.inf:
        raise typer.BadParameter(f"must be a finite number > 0, got {value:g}", param_hint=name)
    return value


def _checked(check, name, *values):
    """``check(*values)`` (:mod:`grasptwist.engine.hold_test`'s), its ``ValueError`` a usage error naming ``name``."""
    try:
        return check(*values)
    except ValueError as exc:
        raise typer.BadParameter(str(exc), param_hint=name) from None


def _duration(value):
    from ..engine.hold_test import check_duration

    return value if value is None else _checked(check_duration, "--duration", value)


def _mass(value):
    return value if value is None else _finite_positive(value, "--mass")


def _table(value):
    if value is not None and not math.isfinite(value):
        raise typer.BadParameter(f"must be a finite height, got {value:g}", param_hint="--table")
    return value


def _tolerance(value):
    """``D,DEG``: a distance > 0 and an angle in degrees (:func:`~grasptwist.engine.hold_test.check_tolerance`)."""
    from ..engine.hold_test import check_tolerance

    if value is None:
        return None
    try:
        distance, angle = (float(v) for v in value.split(","))
    except ValueError:
        raise typer.BadParameter(f"must be D,DEG (a distance and an angle in degrees), got {value!r}") from None
    return _checked(check_tolerance, "--tolerance", distance, angle)


def simulate(
    paths: Annotated[
        list[str],
        typer.Argument(
            metavar="PATH...", help="Grasp files with an object (.yaml, .yml, .json), folders of them or -."
        ),
    ],
    friction: Friction = None,
    mass: Annotated[
        float | None,
        typer.Option("--mass", metavar="KG", callback=_mass, help="The object's mass (replaces the file's)."),
    ] = None,
    table: Annotated[
        float | None,
        typer.Option("--table", metavar="Z", callback=_table, help="A table: the plane z = Z under the object."),
    ] = None,
    duration: Annotated[
        float,
        typer.Option(
            "--duration",
            metavar="T",
            callback=_duration,
            help="Seconds of simulated time each direction's load is applied (0.05 to 600).",
        ),
    ] = 1.0,
    tolerance: Annotated[
        str | None,
        typer.Option(
            "--tolerance",
            metavar="D,DEG",
            callback=_tolerance,
            help="Held when the object moves less than D (length units) and turns less than DEG degrees "
            "(default 0.002,2: 2 mm in metres, 2 degrees; D below the object's size, DEG at most 45).",
        ),
    ] = None,
    safety: Safety = 1.25,
    path: Annotated[
        str | None,
        typer.Option(
            "--path",
            metavar="NAME",
            help="Execute the grasp's path (or twist, for one unit of time) NAME instead: the fingers driven "
            "by follow's joint rates, the object's pose compared with the plan at 21 samples.",
        ),
    ] = None,
    mjcf: Annotated[
        str | None,
        typer.Option(
            "--mjcf",
            metavar="OUT.xml",
            help="Write the scene (MJCF, its meshes beside it) for MuJoCo's viewer; OUT-2.xml, ... for the next "
            "scenes written (each record's scene names its file).",
        ),
    ] = None,
    fmt: Annotated[
        SimulateFormat,
        typer.Option("-f", "--format", help="table for people; json, jsonl or csv for programs."),
    ] = SimulateFormat.table,
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
    """Run each grasp in MuJoCo: the hand at its joint positions exerting grasptwist's grip, the object's
    weight applied along +x, -x, +y, -y, +z, -z in turn; held when it stays within the tolerance.

    One record per grasp: held or not, and per direction how far the object moved and turned and each
    finger's contact force beside the planned one. The grasp needs an object, a mass and a friction
    (the file's, or --mass, --friction). Exit 1 when a grasp does not hold. Needs MuJoCo:
    pip install 'grasptwist[sim]' (from a clone: .venv/bin/pip install -e '.[sim]'). Examples:

    \b
        grasptwist simulate grasps/trifinger-cube.yaml --mass 0.094 --friction 1 --table 0
        grasptwist simulate grasps/ -j 2 -f jsonl --mjcf scene.xml
    """
    from ..extras import require
    from ..run.families import COMMANDS
    from ..run.options import SimulateOptions
    from ..run.pipeline import Job

    if mjcf is not None and not os.path.isdir(os.path.dirname(os.path.abspath(mjcf))):
        raise typer.BadParameter(f"no folder {os.path.dirname(mjcf)!r} to write the scene in", param_hint="--mjcf")
    fmt = SimulateFormat.json if json_ else fmt
    if path is not None and fmt == SimulateFormat.csv:
        raise typer.BadParameter("a path's samples are records: give -f json or jsonl", param_hint="--path")
    not_binary_to_a_terminal(fmt.value, output)
    distance, angle = tolerance if tolerance is not None else (SimulateOptions.distance_tol, SimulateOptions.angle_tol)
    job = Job(
        command=COMMANDS["simulate"],
        fmt=fmt.value,
        max_bytes=max_bytes,
        reading=reading_option(surface_tol, allow_outside),
        options=SimulateOptions(
            mass=mass,
            friction=friction,
            table=table,
            duration=duration,
            distance_tol=distance,
            angle_tol=angle,
            safety=safety,
            mjcf=mjcf,
            path=path,
        ),
    )
    settings = OutputSettings(
        output, quiet, Warnings.summary, workers, {"digits": digits}, reads=(mjcf,) if mjcf else ()
    )

    def body() -> int:
        require("mujoco", "grasptwist simulate")  # one line before any input is read
        return write_records(job, paths, settings)

    run_command(debug, body)
