"""``grasptwist synthesize``: search an object's surface for three-fingered grasps (issue 31)."""

from enum import Enum
from typing import Annotated

import typer

from ..engine.synthesis.scores import MIN_CONDITIONING
from .diagnostics import Warnings, compile_notices
from .exits import checked_output, run_command
from .options import (
    ALL,
    AllowOutside,
    At,
    Clearance,
    ContactOption,
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
    Table,
    Torsion,
    Workers,
    WrenchName,
    WrenchOption,
    contact_torsion,
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
    robust = "robust"
    total_normal_force = "total_normal_force"
    closure_friction = "closure_friction"
    epsilon = "epsilon"


class Loads(str, Enum):
    six = "six"
    weight = "weight"


def _checked(name, module="checks"):
    """A typer callback running the engine's check ``name`` (of ``engine.synthesis.<module>``, imported
    when the option is given; or the function ``name``): the library's words, as a usage error
    naming the option."""

    def callback(value):
        if value is None:
            return value
        from importlib import import_module

        check = name if callable(name) else getattr(import_module(f"grasptwist.engine.synthesis.{module}"), name)
        try:
            return check(value)
        except ValueError as err:
            raise typer.BadParameter(str(err)) from None

    return callback


def _units(value):
    """--units: a length unit the engine knows (its length is what the mesh's size is judged by)."""
    from ..engine.units import LENGTH_UNITS

    if value not in LENGTH_UNITS:
        raise ValueError(f"must be a length unit, one of {', '.join(LENGTH_UNITS)}; got {value!r}")
    return value


def _reading(reading, grasp_file):
    """How grasp files are read: never a mesh or URDF that ``-o FILE.yaml`` would replace."""
    from dataclasses import replace

    from ..run.target import replaced_file

    return replace(reading, output=replaced_file(grasp_file))


def _warmed_up(quiet: bool) -> None:
    """The grip's kernels compiled, or loaded from numba's cache, before any search's clock starts
    (:func:`~grasptwist.engine.synthesis.search.warm_up`; the workers forked later inherit them),
    under the command line's notice of a long compile (:func:`~.diagnostics.compile_notices`)."""
    from ..engine.hooks import watching_first_load
    from ..engine.synthesis.search import warm_up

    with watching_first_load(compile_notices(quiet, "; --seconds counts from when it is done")):
        warm_up()


def synthesize(
    paths: Annotated[
        list[str],
        typer.Argument(
            metavar="PATH...",
            help="Grasp files with an object (.yaml, .yml, .json), mesh files (.stl, .obj, .ply) or folders.",
        ),
    ],
    count: Annotated[
        int,
        typer.Option(
            "-n", "--count", callback=_checked("check_count"), help="Grasps wanted per object (at most 10000)."
        ),
    ] = 5,
    friction: Friction = None,
    mass: Annotated[
        float | None,
        typer.Option(
            "--mass",
            metavar="KG",
            callback=_checked("check_mass"),
            help="The object's mass: its weight is the wrench 'hold'.",
        ),
    ] = None,
    wrench: WrenchOption = None,
    wrench_name: WrenchName = None,
    at: At = None,
    safety: Safety = 1.0,
    contact: ContactOption = None,
    torsion: Torsion = None,
    objective: Annotated[
        Objective,
        typer.Option(
            "--objective",
            help="What ranks the grasps: robust (the most robust first, then the least total normal force), "
            "or what the search minimises (epsilon: maximises).",
        ),
    ] = Objective.robust,
    position_error: Annotated[
        float | None,
        typer.Option(
            "--position-error",
            metavar="E",
            callback=_checked("check_position_error", "robustness"),
            help="How far a perturbation moves each contact at most (robustness; default: half the smallest "
            "fingertip radius, or 2% of the object's size).",
        ),
    ] = None,
    friction_error: Annotated[
        float,
        typer.Option(
            "--friction-error",
            metavar="SHARE",
            callback=_checked("check_friction_error", "robustness"),
            help="The largest share of the friction a perturbation takes away (0 to < 1).",
        ),
    ] = 0.2,
    perturbations: Annotated[
        int,
        typer.Option("--perturbations", min=1, max=10_000, help="Perturbations per grasp (robustness)."),
    ] = 64,
    method: Method = ALL,
    min_conditioning: Annotated[
        float,
        typer.Option(
            "--min-conditioning",
            metavar="C",
            callback=_checked("check_min_conditioning", "scores"),
            help="Each decomposition's conditioning must be at least this (0 to 1).",
        ),
    ] = MIN_CONDITIONING,
    min_spacing: Annotated[
        float | None,
        typer.Option(
            "--min-spacing",
            metavar="D",
            callback=_checked("check_min_spacing"),
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
            callback=_checked("check_tip_radius"),
            help="Every fingertip's radius (default: the hand's tip_radius, or its URDF's tip spheres); "
            "an object without a hand warns that it is ignored.",
        ),
    ] = None,
    units: Annotated[
        str | None,
        typer.Option(
            "--units",
            metavar="UNIT",
            callback=_checked(_units),
            help="The length unit of mesh files given directly (m, mm, cm, in, ...; default m): the records "
            "and -o FILE.yaml say it. A grasp file gives its own 'units'.",
        ),
    ] = None,
    quality: Annotated[bool, typer.Option("--quality", help="Also Ferrari-Canny's epsilon (needs scipy).")] = False,
    span_bodies: Annotated[
        bool,
        typer.Option(
            "--span-bodies", help="Let a grasp's contacts lie on different bodies of a mesh (default: one body)."
        ),
    ] = False,
    loads: Annotated[
        Loads,
        typer.Option(
            "--loads",
            help="What every grasp holds when a weight is held: six (a grip for the weight's size along "
            "+x, -x, +y, -y, +z, -z too, the hold test's loads 'load +x' ... beside the weight), or the weight alone.",
        ),
    ] = Loads.six,
    simulate: Annotated[
        bool,
        typer.Option(
            "--simulate",
            help="Keep only the grasps that hold in all six directions in MuJoCo (grasptwist simulate's "
            "defaults); stderr counts the others. Needs MuJoCo: pip install 'grasptwist[sim]'.",
        ),
    ] = False,
    seed: Annotated[
        int,
        typer.Option(
            "--seed",
            callback=_checked("check_seed"),
            help="Seed of the random numbers, 0 to 2**63-1 (reproducible runs).",
        ),
    ] = 0,
    candidates: Annotated[
        int,
        typer.Option(
            "--candidates", callback=_checked("check_candidates"), help="Candidate triples scored at most, per object."
        ),
    ] = 20000,
    seconds: Annotated[
        float,
        typer.Option(
            "--seconds",
            metavar="S",
            callback=_checked("check_seconds"),
            help="Time allowed per object, counted after a fresh install's one-time compiling: the search stops "
            "at 80% of it, verification at the end (grasps left unverified are not reported).",
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
    table: Table = None,
    clearance: Clearance = None,
    allow_outside: AllowOutside = False,
    workers: Workers = 1,
    quiet: Quiet = False,
    debug: Debug = False,
) -> None:
    """Search each object's surface for three-fingered grasps that hold it: one record per grasp, best first.

    Candidates are scored in batches (force closure at mu / S, both decompositions
    well conditioned, the least total normal force for every wrench), the best
    refined on the surface, ranked by robustness (the share of perturbations of the
    contacts and the friction under which a grip still exists; --objective), and each
    grasp returned is verified by the exact grip.
    With a hand (the file's, or --hand) every grasp is reached within the joint limits,
    fingertips on the surface and no finger link in the object; the records give the
    joint positions. The object's weight ('hold', from its mass or --mass) is always
    held; --wrench adds wrenches beside it. With -o FILE.yaml the grasps are written as a grasp file every
    command reads (the records go to stdout). Exit 1 when an object has no feasible grasp.
    Examples:

    \b
        grasptwist synthesize grasps/sphere.yaml -n 3 --friction 0.5 --mass 0.1
        grasptwist synthesize grasps/trifinger-cube.yaml --friction 0.8 --mass 0.1 -o found.yaml
        grasptwist synthesize objects/ -j 2 -f jsonl      # a folder: one object a process
    """
    from ..extras import require
    from ..run.families import COMMANDS
    from ..run.options import SimulateOptions, SynthesisOptions
    from ..run.pipeline import Job

    wrenches = wrenches_option(wrench, at, wrench_name)
    torsion = contact_torsion(contact, torsion, friction)
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
        reading=_reading(reading_option(surface_tol, allow_outside, table, clearance), grasp_file),
        options=SynthesisOptions(
            count=count,
            friction=friction,
            mass=mass,
            wrenches=None if wrenches is None else tuple(wrenches),
            safety=safety,
            torsion=torsion,
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
            units=units,
            span_bodies=span_bodies,
            position_error=position_error,
            friction_error=friction_error,
            perturbations=perturbations,
            loads=loads.value,
            simulate=SimulateOptions() if simulate else None,
        ),
    )
    settings = OutputSettings(records_to, quiet, Warnings.summary, workers, {"digits": digits}, reads=(hand,))

    def search_all() -> int:
        # a missing extra: one line (run_command's) before any input is read
        if quality or objective == Objective.epsilon:
            require("scipy", "--quality" if quality else "--objective epsilon")
        if simulate:
            require("mujoco", "--simulate")
        _warmed_up(quiet)
        return write_records(job, paths, settings)

    run_command(debug, search_all)
