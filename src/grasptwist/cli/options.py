"""The options several commands share, declared once (typer's ``Annotated`` style),
and how option values become the loader's objects (twists, path segments, a hand).

A command names an option by its alias and gives the default, e.g.
``digits: Digits = 4``; an option only one command has is declared there.
"""

from __future__ import annotations

import re
import sys
from enum import Enum
from typing import Annotated

import typer

from ..output.formats import FORMATS
from ..results import ALL_METHODS, KINDS, METHOD_CHOICES
from ..run.families import COMMANDS
from ..run.options import POINT_CONTACTS
from .diagnostics import WARNINGS_SHOWN, Warnings

__all__ = [
    "MethodChoice",
    "ResolveFormat",
    "RecordFormat",
    "FollowFormat",
    "ForcesFormat",
    "PlotMethod",
    "ALL",
    "ExtraPoint",
    "Order",
    "Frame",
    "Paths",
    "Method",
    "Output",
    "Digits",
    "OrderOption",
    "MaxBytes",
    "SurfaceTol",
    "Table",
    "Clearance",
    "AllowOutside",
    "reading_option",
    "Quiet",
    "WarningsOption",
    "Debug",
    "Json",
    "Workers",
    "RecordFormatOption",
    "Select",
    "parse_floats",
    "twists_option",
    "wrenches_option",
    "segments_option",
    "hand_option",
    "not_binary_to_a_terminal",
]


def _choices(name: str, values) -> type[Enum]:
    """A typer choice type of ``values`` (members named as Python allows: ``off-tangent`` is ``off_tangent``)."""
    return Enum(name, {v.replace("-", "_"): v for v in values}, type=str)


#: ``--method``: the registry's methods, or ``both``.
MethodChoice = _choices("Method", METHOD_CHOICES)
#: ``-f`` of each command: from the format registry.
ResolveFormat = _choices("Format", COMMANDS["resolve"].formats)
RecordFormat = _choices("RecordFormat", COMMANDS["basis"].formats)
FollowFormat = _choices("FollowFormat", COMMANDS["follow"].formats)
ForcesFormat = _choices("ForcesFormat", COMMANDS["forces"].formats)
SynthesizeFormat = _choices("SynthesizeFormat", COMMANDS["synthesize"].formats)
SimulateFormat = _choices("SimulateFormat", COMMANDS["simulate"].formats)
#: ``plot --method``: the bases that can be drawn.
PlotMethod = _choices("PlotMethod", [k.label for k in KINDS if k.method])
#: The default of ``--method``: every method.
ALL = MethodChoice(ALL_METHODS)


class ExtraPoint(str, Enum):
    wrist = "wrist"
    at = "at"


class Order(str, Enum):
    omega_v = "omega-v"
    v_omega = "v-omega"


class Frame(str, Enum):
    space = "space"
    body = "body"


PATHS_HELP = (
    "Grasp files (.yaml, .yml, .json; any case), JSON Lines of grasps (.jsonl), data sets (.npz, .npy, .parquet), "
    "folders of grasp files or - (stdin: YAML, or JSON Lines if it starts with '{')."
)
Paths = Annotated[list[str], typer.Argument(metavar="PATH...", help=PATHS_HELP)]
Method = Annotated[MethodChoice, typer.Option("--method", help="Decomposition(s) to run.")]
Output = Annotated[
    str | None, typer.Option("-o", "--output", metavar="FILE", help="Write to FILE (atomically) instead of stdout.")
]
Digits = Annotated[
    int, typer.Option("--digits", min=0, max=17, help="Decimals in tables (JSON and CSV keep full precision).")
]
OrderOption = Annotated[
    Order, typer.Option("--order", help="Order of every printed 6-vector: (omega; v) or (v; omega).")
]


def byte_count(text: str) -> int:
    """A whole number of bytes, written as an integer or in exponent form (``1e8``), at least 1.

    >>> byte_count("1e8"), byte_count("4096")
    (100000000, 4096)
    """
    try:
        value = float(text)
    except ValueError:
        raise typer.BadParameter(f"expected a whole number of bytes (e.g. 1048576 or 1e6), got {text!r}") from None
    if not (value >= 1 and value == int(value) and value < 2**63):
        raise typer.BadParameter(f"expected a whole number of bytes, at least 1, got {text!r}")
    return int(value)


MaxBytes = Annotated[
    int | None,
    typer.Option(
        "--max-bytes",
        parser=byte_count,
        metavar="BYTES",
        help="Refuse grasp files larger than this many bytes (default 1 MiB; 1e8 is 100 MB).",
    ),
]


def _nonnegative(text: str, what: str) -> float:
    """A finite number >= 0 (``what`` says which, in the usage error)."""
    try:
        value = float(text)
    except ValueError:
        value = -1.0
    if not 0 <= value < float("inf"):
        raise typer.BadParameter(f"expected {what}, got {text!r}")
    return value


def surface_tol(text: str) -> float:
    """A surface tolerance: a finite number >= 0, relative to the object's size.

    >>> surface_tol("1e-3")
    0.001
    """
    return _nonnegative(text, "a finite number >= 0 (a fraction of the object's size)")


SurfaceTol = Annotated[
    float | None,
    typer.Option(
        "--surface-tol",
        parser=surface_tol,
        metavar="FRACTION",
        help="How far a contact may lie from its object's surface, as a fraction of the object's size "
        "(its bounding box's diagonal; default 0.01).",
    ),
]
AllowOutside = Annotated[
    bool,
    typer.Option(
        "--allow-outside",
        help="Read meshes and URDFs that a grasp file names outside its own folder (default: refused, path-outside).",
    ),
]


def reading_option(surface_tol: float | None, allow_outside: bool, table=None, clearance=None):
    """How grasp files are read under ``--surface-tol``, ``--allow-outside``, ``--table`` and
    ``--clearance``: the loader's :class:`~grasptwist.io.grasp.Reading`."""
    from dataclasses import replace

    from ..io.grasp import READING

    return replace(READING, surface_tol=surface_tol, allow_outside=allow_outside, table=table, clearance=clearance)


def finite(text: str) -> float:
    """A finite number (a table's height).

    >>> finite("-0.5")
    -0.5
    """
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not abs(value) < float("inf"):
        raise typer.BadParameter(f"expected a finite number, got {text!r}")
    return value


def clearance(text: str) -> float:
    """A clearance: a finite length >= 0.

    >>> clearance("0.002")
    0.002
    """
    return _nonnegative(text, "a finite length >= 0")


Table = Annotated[
    float | None,
    typer.Option(
        "--table",
        parser=finite,
        metavar="Z",
        help="A table at height Z under every object (the plane z = Z of the grasp frame, replacing a file's "
        "environment table): fingers keep --clearance above it.",
    ),
]
Clearance = Annotated[
    float | None,
    typer.Option(
        "--clearance",
        parser=clearance,
        metavar="LENGTH",
        help="The least distance every finger part keeps from the table and boxes, in the files' units "
        "(default: a file's environment clearance, else 0.001: 1 mm in metres).",
    ),
]


Quiet = Annotated[bool, typer.Option("-q", "--quiet", help="No warnings or summary on stderr (errors still).")]
WarningsOption = Annotated[
    Warnings,
    typer.Option(
        "--warnings",
        help="Warnings, and the errors of a data set's or stream's rows, on stderr: all, none, "
        f"or the first {WARNINGS_SHOWN} of each and a count of the rest by kind.",
    ),
]
Debug = Annotated[bool, typer.Option("--debug", help="Show the Python traceback of an internal error.")]
Json = Annotated[bool, typer.Option("--json", help="Same as --format json.")]


def _friction(value: float | None) -> float | None:
    """NaN is no coefficient: refused as a negative one is (``inf``, no limit, is one)."""
    if value is not None and value != value:
        raise typer.BadParameter("must be a number >= 0 (inf: no limit), got nan")
    return value


def _safety(value: float) -> float:
    from ..engine.forces.grasp_map import check_safety  # the force engine loads only when a force command runs

    try:
        return check_safety(value)
    except ValueError as err:
        raise typer.BadParameter(str(err)) from None


# the force commands' options (forces, synthesize)
WrenchOption = Annotated[
    list[str] | None,
    typer.Option(
        "--wrench",
        metavar="F,F,F,M,M,M",
        help="Wrench the fingers exert on the object (force; moment about --at); repeatable; "
        "replaces the files' wrenches.",
    ),
]
WrenchName = Annotated[
    list[str] | None,
    typer.Option(
        "--wrench-name",
        metavar="NAME",
        help="Name of each --wrench in the records, paired in order (default: the wrench as written).",
    ),
]
At = Annotated[
    str | None,
    typer.Option("--at", metavar="X,Y,Z", help="Point the --wrench moments are about (default: the origin)."),
]
Friction = Annotated[
    float | None,
    typer.Option(
        "--friction",
        metavar="MU",
        min=0,
        callback=_friction,
        help="Friction coefficient of every contact (replaces the files'; inf: no limit).",
    ),
]


def _torsion(value: float | None) -> float | None:
    """A torsional radius: a finite length > 0."""
    if value is not None and not (0 < value < float("inf")):
        raise typer.BadParameter(f"must be a finite length > 0 (the soft fingers' torsional radius), got {value!r}")
    return value


class Contact(str, Enum):
    """The contact model of ``--contact``."""

    point = "point"
    soft = "soft"


ContactOption = Annotated[
    Contact | None,
    typer.Option(
        "--contact",
        show_default=False,
        help="Contact model of every contact, replacing the files': point (Coulomb cones; a file's soft "
        "contacts too) or soft (finger pads that also resist turning about the normal, "
        "|(f_t, tau / E)| <= mu f_n; needs --torsion). [default: the files' (model: soft, else point)]",
    ),
]
Torsion = Annotated[
    float | None,
    typer.Option(
        "--torsion",
        metavar="E",
        callback=_torsion,
        help="Torsional radius of every soft contact (a length, in the grasps' units; with --contact soft).",
    ),
]


def contact_torsion(contact: Contact | None, torsion: float | None, friction: float | None = None) -> float | None:
    """``--contact`` and ``--torsion`` as every contact's torsional radius: None without ``--contact`` (the
    files' contacts as they are), :data:`~grasptwist.run.options.POINT_CONTACTS` (0) with ``--contact point``
    (every contact a point, a file's soft ones too), ``E`` with ``--contact soft --torsion E``; a usage error
    when ``--torsion`` comes without ``--contact soft`` or the reverse, or soft contacts with ``--friction 0``
    (torsional friction is friction).

    >>> contact_torsion(None, None), contact_torsion(Contact.point, None), contact_torsion(Contact.soft, 0.01)
    (None, 0.0, 0.01)
    """
    if contact is Contact.soft and torsion is None:
        raise typer.BadParameter(
            "--contact soft needs --torsion E (the torsional radius, a length > 0)", param_hint="'--contact'"
        )
    if contact is not Contact.soft and torsion is not None:
        raise typer.BadParameter(
            "--torsion is the soft contacts' radius: give --contact soft too", param_hint="'--torsion'"
        )
    if contact is Contact.soft and friction == 0:
        raise typer.BadParameter(
            "soft contacts need friction (their torsion is friction): --friction 0 makes every contact frictionless",
            param_hint="'--contact'",
        )
    return POINT_CONTACTS if contact is Contact.point else torsion


Safety = Annotated[
    float,
    typer.Option(
        "--safety",
        metavar="S",
        callback=_safety,
        help="Safety factor >= 1: forces keep within mu / S, closure is judged with it.",
    ),
]
Workers = Annotated[
    int,
    typer.Option(
        "-j",
        "--workers",
        min=0,
        help="Processes for big batches (0: every core, used for 256+ files or 4096+ data-set grasps); "
        "never more than the tasks, 4 per core or 64.",
    ),
]
Select = Annotated[
    list[str] | None,
    typer.Option(
        "--select",
        metavar="NAME",
        help="Only the file's twist of this name (repeatable); a name the file has no twist of is an error "
        "that lists the twists it has.",
    ),
]
RecordFormatOption = Annotated[
    RecordFormat, typer.Option("-f", "--format", help="table for people, json or jsonl for programs.")
]


def parse_floats(text: str, n: int, what: str) -> list[float]:
    """``n`` finite comma-separated numbers of option ``what``, or a usage error."""
    try:
        values = [float(x) for x in text.replace(" ", "").split(",")]
    except ValueError:
        values = []
    if len(values) != n or not all(v == v and abs(v) != float("inf") for v in values):
        raise typer.BadParameter(f"needs {n} finite comma-separated numbers, got {text!r}", param_hint=what)
    return values


def _names(names, texts, what):
    """``--twist-name`` / ``--wrench-name`` values: one per vector, each a printable line."""
    if names and len(names) != len(texts or ()):
        raise typer.BadParameter(
            f"give one --{what}-name per --{what} (got {len(names)} names for {len(texts or ())} {what}es)".replace(
                "twistes", "twists"
            ),
            param_hint=f"--{what}-name",
        )
    for name in names or ():
        if not name.strip() or not name.isprintable():
            raise typer.BadParameter(
                f"{name!r}: a name is a non-empty line of printable text", param_hint=f"--{what}-name"
            )


def wrenches_option(texts: list[str] | None, at: str | None, names: list[str] | None = None):
    """``--wrench`` values (force; moment about ``--at``) as loader wrenches, moments about the
    origin, named by ``names`` (``--wrench-name``) or as written."""
    _names(names, texts, "wrench")
    if not texts:
        if at is not None:
            raise typer.BadParameter("applies to --wrench; give at least one --wrench", param_hint="--at")
        return None
    import numpy as np

    from ..engine.screws import cross
    from ..model import Wrench

    point = np.array(parse_floats(at, 3, "--at") if at is not None else [0.0, 0.0, 0.0])
    wrenches = []
    for k, text in enumerate(texts):
        w = np.array(parse_floats(text, 6, "--wrench"))
        with np.errstate(all="ignore"):
            wrench = np.concatenate([w[:3], w[3:] + cross(point, w[:3])]) + 0.0  # moment about the origin
        if not np.isfinite(wrench).all():
            raise typer.BadParameter(f"{text!r} at {at}: the moment about the origin overflows", param_hint="--wrench")
        wrenches.append(Wrench(name=names[k] if names else text.replace(" ", ""), wrench=wrench, line=None))
    return wrenches


def twists_option(texts: list[str] | None, at: str | None, names: list[str] | None = None):
    """``--twist`` values as loader twists at the origin (``--at`` names the reference point),
    named by ``names`` (``--twist-name``, one per twist) or as written."""
    _names(names, texts, "twist")
    if not texts:
        if at is not None:
            raise typer.BadParameter("applies to --twist; give at least one --twist", param_hint="--at")
        return None
    import numpy as np

    from ..engine.screws import twist_at
    from ..model import Twist

    point = parse_floats(at, 3, "--at") if at is not None else [0.0, 0.0, 0.0]
    twists = []
    for k, text in enumerate(texts):
        w = parse_floats(text, 6, "--twist")
        with np.errstate(all="ignore"):
            screw = twist_at(w[:3], w[3:], point)
        if not np.isfinite(screw).all():
            raise typer.BadParameter(f"{text!r} at {at}: the velocity of the origin overflows", param_hint="--twist")
        twists.append(Twist(name=names[k] if names else text.replace(" ", ""), screw=screw, line=None))
    return twists


def segments_option(twists, durations, frame):
    """``--twist``/``--duration`` pairs as path segments (None without ``--twist``)."""
    if not twists and not durations:
        if frame != "space":
            raise typer.BadParameter("applies to --twist segments", param_hint="--frame")
        return None
    if len(twists or ()) != len(durations or ()):
        raise typer.BadParameter(
            f"each --twist needs a --duration: got {len(twists or ())} and {len(durations or ())}",
            param_hint="--duration",
        )
    from ..engine.segments import check_segments
    from ..model import Segment

    segments = [Segment(d, twist=parse_floats(t, 6, "--twist"), frame=frame) for t, d in zip(twists, durations)]
    try:
        return check_segments(segments)
    except ValueError as exc:
        # the engine names segments[k]; here they are the k+1-th --twist/--duration pair
        message = re.sub(r"segments\[(\d+)\]\.duration", lambda m: f"--duration number {int(m[1]) + 1}", str(exc))
        raise typer.BadParameter(message.replace("segments[", "segment ["), param_hint="--duration") from None


def hand_option(path: str | None, paths: list[str], fmt: str):
    """The run's hand (:func:`grasptwist.run.placement.run_hand`); a ``--hand`` file that cannot be
    read is a usage error."""
    from ..model import InputError
    from ..run.placement import run_hand

    try:
        return run_hand(path, paths, FORMATS[fmt].per_hand)
    except InputError as err:
        raise typer.BadParameter(f"{err.code}: {err}", param_hint="--hand") from None


def not_binary_to_a_terminal(fmt: str, output: str | None) -> None:
    """A usage error, before any work, when a binary format (npz, parquet) would go to a terminal."""
    if FORMATS[fmt].binary and output is None and sys.stdout.isatty():
        raise typer.BadParameter(f"{fmt} is binary: give -o FILE.{fmt}", param_hint="--format")
