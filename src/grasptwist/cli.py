"""The ``grasptwist`` command line (typer).

A thin layer: it parses options, asks :mod:`inputs` for files, the loader
for grasps, :mod:`batch` for resolutions and :mod:`report` for output.
stdout carries data only; every diagnostic goes to stderr as one line
``path:line:col: error: message``.  Exit codes: 0 all records ok, 1 some
record failed (the others are still written in full), 2 usage error,
3 the output could not be written, 4 a worker process died, 128 + the
signal's number when SIGINT, SIGTERM or SIGHUP stopped the run, 141 the
reader of stdout went away.
"""

from __future__ import annotations

import os
import re
import signal
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field, replace
from enum import Enum

import typer

from . import __version__
from .output.formats import FORMATS, names_for
from .results import ALL_METHODS, KINDS, METHOD_CHOICES

EXIT_OK, EXIT_FAILED, EXIT_USAGE, EXIT_WRITE, EXIT_WORKER, EXIT_BROKEN_PIPE = 0, 1, 2, 3, 4, 141

app = typer.Typer(
    name="grasptwist",
    help="Resolve a desired object twist into finger-tip twists for a three-fingered grasp (screw theory).",
    no_args_is_help=True,
    add_completion=True,
    rich_markup_mode=None,
    pretty_exceptions_enable=False,
    context_settings={"help_option_names": ["-h", "--help"]},
)


def _version(value: bool) -> None:
    if value:
        sys.stdout.write(f"grasptwist {__version__}\n")
        raise typer.Exit(EXIT_OK)


@app.callback()
def _root(
    version: bool = typer.Option(
        False, "--version", callback=_version, is_eager=True, help="Print the version and exit."
    ),
) -> None:
    """Resolve a desired object twist into finger-tip twists for a three-fingered grasp (screw theory)."""


def _choices(name: str, values) -> type[Enum]:
    """A typer choice type of ``values`` (members named as Python allows: ``off-tangent`` is ``off_tangent``)."""
    return Enum(name, {v.replace("-", "_"): v for v in values}, type=str)


#: ``--method``: the registry's methods, or ``both``.
Method = _choices("Method", METHOD_CHOICES)
#: ``-f`` of ``resolve``, and of ``basis`` and ``check``: from the format registry.
Format = _choices("Format", names_for("resolve"))
RecordFormat = _choices("RecordFormat", names_for("basis"))


class ExtraPoint(str, Enum):
    wrist = "wrist"
    at = "at"


class Order(str, Enum):
    omega_v = "omega-v"
    v_omega = "v-omega"


def _floats(text: str, n: int, what: str) -> list[float]:
    try:
        values = [float(x) for x in text.replace(" ", "").split(",")]
    except ValueError:
        values = []
    if len(values) != n or not all(v == v and abs(v) != float("inf") for v in values):
        raise typer.BadParameter(f"needs {n} finite comma-separated numbers, got {text!r}", param_hint=what)
    return values


def _cli_twists(texts: list[str] | None, at: str | None, names: list[str] | None = None):
    """``--twist`` values as loader twists at the origin (``--at`` names the reference point),
    named by ``names`` (``--twist-name``, one per twist) or as written."""
    if names and len(names) != len(texts or ()):
        raise typer.BadParameter(
            f"give one --twist-name per --twist (got {len(names)} names for {len(texts or ())} twists)",
            param_hint="--twist-name",
        )
    for name in names or ():
        if not name.strip() or not name.isprintable():
            raise typer.BadParameter(
                f"{name!r}: a name is a non-empty line of printable text", param_hint="--twist-name"
            )
    if not texts:
        if at is not None:
            raise typer.BadParameter("applies to --twist; give at least one --twist", param_hint="--at")
        return None
    import numpy as np

    from .engine.screws import twist_at
    from .model import Twist

    point = _floats(at, 3, "--at") if at is not None else [0.0, 0.0, 0.0]
    twists = []
    for k, text in enumerate(texts):
        w = _floats(text, 6, "--twist")
        with np.errstate(all="ignore"):
            screw = twist_at(w[:3], w[3:], point)
        if not np.isfinite(screw).all():
            raise typer.BadParameter(f"{text!r} at {at}: the velocity of the origin overflows", param_hint="--twist")
        twists.append(Twist(name=names[k] if names else text.replace(" ", ""), screw=screw, line=None))
    return twists


class Warnings(str, Enum):
    all = "all"
    summary = "summary"
    none = "none"


#: Warnings ``--warnings summary`` prints before it only counts them.
WARNINGS_SHOWN = 20

#: Records of a table from which stderr suggests the machine formats, once.
TABLE_HINT_AT = 50


class _Stderr:
    """Diagnostics on stderr: one line each, counted; colour only on a terminal.

    Errors are all printed; warnings as ``--warnings`` asks (``summary``: the
    first :data:`WARNINGS_SHOWN`, then one line counting the rest by kind);
    ``-q`` drops warnings, the table hint and the summary.  ``hint`` is the
    line said once when a table passes :data:`TABLE_HINT_AT` records.
    """

    def __init__(self, quiet: bool = False, warnings: Warnings = Warnings.summary, hint: str | None = None):
        self.failed = 0
        self.records = 0
        self.quiet = quiet
        self.shown = {Warnings.all: None, Warnings.summary: WARNINGS_SHOWN, Warnings.none: 0}[Warnings(warnings)]
        self.counting = warnings == Warnings.summary
        self.unshown: dict[str, int] = {}  # warnings not printed, by kind
        self.hint = None if quiet else hint
        self.color = sys.stderr.isatty() and not os.environ.get("NO_COLOR")

    def take(self, out) -> None:
        """Count a pipeline Output and print its lines."""
        self.records += out.records
        self.failed += out.failed
        for line in out.errors:
            self.say(line, ": error: ", "31")
        if not self.quiet:
            for line in out.warnings:
                self.warn(line)
        if self.hint and self.records > TABLE_HINT_AT:
            _say(self.hint)
            self.hint = None

    def warn(self, line: str) -> None:
        """Print a warning line, or count it by kind once the first ``shown`` are out."""
        if self.shown is None or self.shown > 0:
            self.say(line, ": warning: ", "33")
            self.shown = None if self.shown is None else self.shown - 1
        elif self.counting:
            kind = _warning_kind(line)
            self.unshown[kind] = self.unshown.get(kind, 0) + 1

    def say(self, line: str, label: str, colour: str) -> None:
        """Print one diagnostic line, its label coloured on a terminal."""
        if self.color:
            line = line.replace(label, f": \x1b[{colour}m{label[2:-2]}\x1b[0m: ", 1)
        _say(line)

    def summary(self) -> None:
        if self.quiet:
            return
        if self.unshown:
            total = sum(self.unshown.values())
            kinds = ", ".join(f"{n} {kind}" for kind, n in sorted(self.unshown.items(), key=lambda kv: -kv[1]))
            _say(f"grasptwist: {total} more warning{'' if total == 1 else 's'} not shown (--warnings all): {kinds}")
        _say(f"{self.records} record{'' if self.records == 1 else 's'}, {self.failed} failed")


def _warning_kind(line: str) -> str:
    """What a warning line is about, without its place and numbers: its message
    up to the first parenthesis or colon (``tangent basis is nearly degenerate``).

    >>> _warning_kind("a.yaml: grasp 'g': warning: tangent basis is nearly degenerate (conditioning 2e-05 < 0.001): ...")
    'tangent basis is nearly degenerate'
    """
    message = line.rpartition(": warning: ")[2]
    return message.split(" (", 1)[0].split(":", 1)[0].strip()


def _table_hint(command: str) -> str:
    """The line that points a reader of a long table to the machine formats."""
    others = [f for f in names_for(command) if f != "table"]
    listed = ", ".join(others[:-1]) + f" or {others[-1]}"
    return f"grasptwist: hint: more than {TABLE_HINT_AT} records: -f {listed} writes them far faster, for programs"


def _say(line: str) -> None:
    """One line on stderr; if stderr is gone (a hung-up terminal), there is nobody to tell."""
    try:
        sys.stderr.write(line + "\n")
        sys.stderr.flush()
    except (OSError, ValueError):
        pass


@contextmanager
def _output(path: str | None) -> Iterator:
    """stdout, or ``path`` by the rule of :mod:`grasptwist.run.target`: a file
    replaced atomically on success only, a pipe or device written through;
    an unusable ``path`` is a usage error before any work."""
    from .run.signals import finishing
    from .run.target import check_target, opened

    if path is not None and path != "-":
        try:
            check_target(path)
        except ValueError as exc:
            raise typer.BadParameter(str(exc), param_hint="-o") from None
    with opened(path) as out:
        yield out
        finishing()  # all written: commit it and end normally, whatever signal comes now


def _writable_folder(path: str) -> None:
    """A usage error, before any work, when ``path``'s folder cannot take a file."""
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder):
        raise typer.BadParameter(f"cannot write {path}: no folder {os.path.dirname(path) or folder}", param_hint="-o")
    if not os.access(folder, os.W_OK):
        raise typer.BadParameter(f"cannot write {path}: the folder is not writable", param_hint="-o")


@contextmanager
def _progress(inputs: list, command: str, out):
    """A rich progress bar on stderr, named after ``command``, when it is a
    terminal and there is more than one input or a data set (whose records
    are counted as they come); not when the output ``out`` goes to a
    terminal too, where it shows the progress itself (and a bar would be
    drawn between its lines)."""
    from .io.datasets import DATASET_SUFFIXES

    big = len(inputs) > 1 or any(isinstance(p, str) and p.endswith(DATASET_SUFFIXES) for p in inputs)
    if not big or not sys.stderr.isatty() or out.isatty():
        yield lambda output: None
        return
    from rich.progress import Progress

    from .output.table import console

    # the console never wraps: lines printed under the bar (stderr is redirected
    # through it) stay one line each, folded only by the terminal
    with Progress(console=console(sys.stderr), transient=True) as bar:
        task = bar.add_task(f"grasptwist {command}", total=len(inputs))

        def advance(output):
            if output.grows:
                bar.update(task, total=bar.tasks[0].total + output.grows)
            bar.advance(task, output.done)

        yield advance


_METHOD = typer.Option(Method(ALL_METHODS), "--method", help="Decomposition(s) to run.")
_OUTPUT = typer.Option(None, "-o", "--output", metavar="FILE", help="Write to FILE (atomically) instead of stdout.")
_DIGITS = typer.Option(4, "--digits", min=0, max=17, help="Decimals in tables (JSON and CSV keep full precision).")
_ORDER = typer.Option(Order.omega_v, "--order", help="Order of every printed 6-vector: (omega; v) or (v; omega).")
_MAX_BYTES = typer.Option(
    None, "--max-bytes", min=1, help="Refuse grasp files larger than this many bytes (default 1 MiB)."
)
_QUIET = typer.Option(False, "-q", "--quiet", help="No warnings or summary on stderr (errors still).")
_WARNINGS = typer.Option(
    Warnings.summary,
    "--warnings",
    help=f"Warnings on stderr: all, none, or the first {WARNINGS_SHOWN} and a count of the rest by kind.",
)
_DEBUG = typer.Option(False, "--debug", help="Show the Python traceback of an internal error.")
_JSON = typer.Option(False, "--json", help="Same as --format json.")


_WORKERS = typer.Option(
    0,
    "-j",
    "--workers",
    min=0,
    help="Processes for big batches (0: every core, used for 256+ files or 4096+ data-set grasps).",
)
_PATHS_HELP = (
    "Grasp files (.yaml, .yml, .json; any case), JSON Lines of grasps (.jsonl), data sets (.npz, .npy, .parquet), "
    "folders of grasp files or - (stdin: YAML, or JSON Lines if it starts with '{')."
)
_PATHS = typer.Argument(..., metavar="PATH...", help=_PATHS_HELP)


@app.command()
def resolve(
    paths: list[str] = _PATHS,
    twist: list[str] | None = typer.Option(
        None,
        "--twist",
        metavar="W1,W2,W3,V1,V2,V3",
        help="Object twist (omega; v); repeatable; replaces the files' twists.",
    ),
    twist_name: list[str] | None = typer.Option(
        None,
        "--twist-name",
        metavar="NAME",
        help="Name of each --twist in the records, paired in order (default: the twist as written).",
    ),
    at: str | None = typer.Option(
        None, "--at", metavar="X,Y,Z", help="Point whose velocity the --twist linear part gives (default: the origin)."
    ),
    twists_from: str | None = typer.Option(
        None,
        "--twists-from",
        metavar="FILE|-",
        help="Twists one per line (JSON: [w1,w2,w3,v1,v2,v3] or a twist mapping), each resolved as it arrives.",
    ),
    method: Method = _METHOD,
    fmt: Format = typer.Option(
        Format.table,
        "-f",
        "--format",
        help="table for people; json, jsonl, csv, npz or parquet (with -o) for programs.",
    ),
    json_: bool = _JSON,
    output: str | None = _OUTPUT,
    digits: int = _DIGITS,
    order: Order = _ORDER,
    extra_point: ExtraPoint = typer.Option(
        ExtraPoint.wrist,
        "--extra-point",
        help="Role of a .npy's 19th-21st columns: the wrist, or the point the twists' linear velocity is given at.",
    ),
    hand: str | None = typer.Option(
        None,
        "--hand",
        metavar="FILE.yaml",
        help="The hand of a data set's rows (a YAML file holding just hand:), at its joint_positions; "
        "its joints name the CSV and npz joint-rate columns.",
    ),
    max_bytes: int | None = _MAX_BYTES,
    workers: int = _WORKERS,
    quiet: bool = _QUIET,
    warnings: Warnings = _WARNINGS,
    debug: bool = _DEBUG,
) -> None:
    """Resolve object twists into finger-tip twists and amplitudes: one record per (grasp, twist).

    Examples: spin the paper's cylinder about z and read the Psi amplitudes
    (--method off-tangent: the cylinder is degenerate for the tangent method);
    a data set of grasps as arrays, results as arrays:

    \b
        grasptwist resolve grasps/cylinder.yaml --method off-tangent --twist 0,0,1,0,0,0 --json | jq '.[0].off_tangent.y'
        grasptwist resolve grasps.npz --twist 0,0,1,0,0,0 -f npz -o results.npz
    """
    from .run.pipeline import Job

    twists = _cli_twists(twist, at, twist_name)
    if twists_from is not None and twists is not None:
        raise typer.BadParameter("give twists by --twist or by --twists-from, not both", param_hint="--twists-from")
    if twists_from == "-" and "-" in paths:
        raise typer.BadParameter("standard input can be read only once", param_hint="--twists-from")
    if extra_point == ExtraPoint.at and at is not None:
        raise typer.BadParameter("--extra-point at gives each row its own point; drop --at", param_hint="--at")
    if extra_point == ExtraPoint.at and not any(p.endswith(".npy") for p in paths):
        raise typer.BadParameter("applies to .npy data sets (their 19th-21st columns)", param_hint="--extra-point")
    fmt = Format.json if json_ else fmt
    _not_binary_to_a_terminal(fmt.value, output)
    job = Job(
        kind="resolve",
        twists=None if twists is None else tuple(twists),
        method=method.value,
        order=order.value,
        fmt=fmt.value,
        max_bytes=max_bytes,
        extra_point=extra_point.value,
        hand=_hand_option(hand, paths, fmt.value),
        twists_from=twists_from,
    )
    shared = Shared(output, quiet, warnings, workers, {"digits": digits, "order": order.value})
    _run(debug, lambda: _emit(job, paths, shared))


def _hand_option(path: str | None, paths: list[str], fmt: str):
    """The run's hand: ``--hand``'s, or for CSV and npz of one grasp file, that file's first hand
    (its joints name the columns; a folder's grasps may each have another)."""
    from .model import InputError

    if path is not None:
        from .io.grasp import load_hand_file

        try:
            return load_hand_file(path)[0]
        except InputError as err:
            raise typer.BadParameter(f"{err.code}: {err}", param_hint="--hand") from None
    if not FORMATS[fmt].per_hand or len(paths) != 1 or not paths[0].lower().endswith((".yaml", ".yml", ".json")):
        return None
    if not os.path.isfile(paths[0]):
        return None
    from .io.inputs import read

    return next((g.hand for g in read(paths[0]) if getattr(g, "hand", None) is not None), None)


@app.command()
def basis(
    paths: list[str] = _PATHS,
    method: Method = _METHOD,
    fmt: RecordFormat = typer.Option(
        RecordFormat.table, "-f", "--format", help="table for people, json or jsonl for programs."
    ),
    json_: bool = _JSON,
    output: str | None = _OUTPUT,
    digits: int = _DIGITS,
    order: Order = _ORDER,
    max_bytes: int | None = _MAX_BYTES,
    workers: int = _WORKERS,
    quiet: bool = _QUIET,
    warnings: Warnings = _WARNINGS,
    debug: bool = _DEBUG,
) -> None:
    """Show each grasp's basis screws Sigma, Psi, Theta, their Klein products and conditioning.

    Example (the paper's eqs. 16-18, with unit Psi):

    \b
        grasptwist basis grasps/cylinder.yaml --method off-tangent
    """
    from .run.pipeline import Job

    job = Job(
        kind="basis", method=method.value, order=order.value, fmt="json" if json_ else fmt.value, max_bytes=max_bytes
    )
    _run(
        debug,
        lambda: _emit(job, paths, Shared(output, quiet, warnings, workers, {"digits": digits, "order": order.value})),
    )


@app.command()
def check(
    paths: list[str] = _PATHS,
    method: Method = _METHOD,
    fmt: RecordFormat = typer.Option(
        RecordFormat.table, "-f", "--format", help="table for people, json or jsonl for programs."
    ),
    json_: bool = _JSON,
    output: str | None = _OUTPUT,
    max_bytes: int | None = _MAX_BYTES,
    workers: int = _WORKERS,
    quiet: bool = _QUIET,
    warnings: Warnings = _WARNINGS,
    debug: bool = _DEBUG,
) -> None:
    """Validate grasp files and report degenerate grasps without resolving; exit 1 if any fails.

    Example, over a folder, listing only the failures:

    \b
        grasptwist check grasps/ -f jsonl | jq -c 'select(.ok | not)'
    """
    from .run.pipeline import Job

    job = Job(kind="check", method=method.value, fmt="json" if json_ else fmt.value, max_bytes=max_bytes)
    _run(debug, lambda: _emit(job, paths, Shared(output, quiet, warnings, workers)))


FollowFormat = _choices("FollowFormat", names_for("follow"))


class Frame(str, Enum):
    space = "space"
    body = "body"


@app.command()
def follow(
    paths: list[str] = typer.Argument(
        ..., metavar="PATH...", help="Grasp files (.yaml, .yml, .json; any case), folders of them or - (stdin)."
    ),
    path: str | None = typer.Option(None, "--path", metavar="NAME", help="Follow only the files' paths of this name."),
    twist: list[str] | None = typer.Option(
        None,
        "--twist",
        metavar="W1,W2,W3,V1,V2,V3",
        help="A segment's constant twist (omega; v), each with a --duration, in order: a path replacing the files'.",
    ),
    duration: list[float] | None = typer.Option(
        None, "--duration", metavar="T", help="How long the --twist of the same rank is held (> 0)."
    ),
    frame: Frame = typer.Option(Frame.space, "--frame", help="Frame of the --twist segments."),
    samples: int | None = typer.Option(
        None, "--samples", min=2, max=1_000_000, help="Samples per path, evenly spaced, ends included (default 21)."
    ),
    dt: float | None = typer.Option(None, "--dt", metavar="DT", help="Time step between samples instead of --samples."),
    method: Method = _METHOD,
    fmt: FollowFormat = typer.Option(
        FollowFormat.table, "-f", "--format", help="table for people; json, jsonl, csv or npz (with -o) for programs."
    ),
    json_: bool = _JSON,
    output: str | None = _OUTPUT,
    digits: int = _DIGITS,
    order: Order = _ORDER,
    max_bytes: int | None = _MAX_BYTES,
    quiet: bool = _QUIET,
    debug: bool = _DEBUG,
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
    from .run.follow import FollowJob

    segments = _cli_segments(twist, duration, frame.value)
    if segments and path is not None:
        raise typer.BadParameter(
            "--path picks one of the files' paths; --twist replaces them: give one", param_hint="--path"
        )
    if samples is not None and dt is not None:
        raise typer.BadParameter("give --samples or --dt, not both", param_hint="--dt")
    if dt is not None and not (dt > 0 and dt != float("inf")):
        raise typer.BadParameter(f"must be a finite number > 0, got {dt}", param_hint="--dt")
    fmt = FollowFormat.json if json_ else fmt
    _not_binary_to_a_terminal(fmt.value, output)
    job = FollowJob(
        method=method.value,
        path=path,
        segments=segments,
        samples=samples,
        dt=dt,
        max_bytes=max_bytes,
        bases=FORMATS[fmt.value].bases,
        hand=_hand_option(None, paths, fmt.value),
    )
    _run(debug, lambda: _follow(job, paths, output, quiet, fmt.value, digits=digits, order=order.value))


def _not_binary_to_a_terminal(fmt: str, output: str | None) -> None:
    """A usage error, before any work, when a binary format (npz, parquet) would go to a terminal."""
    if FORMATS[fmt].binary and output is None and sys.stdout.isatty():
        raise typer.BadParameter(f"{fmt} is binary: give -o FILE.{fmt}", param_hint="--format")


def _cli_segments(twists, durations, frame):
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
    from .path import Segment, check_segments

    segments = [Segment(d, twist=_floats(t, 6, "--twist"), frame=frame) for t, d in zip(twists, durations)]
    try:
        return check_segments(segments)
    except ValueError as exc:
        # the engine names segments[k]; here they are the k+1-th --twist/--duration pair
        message = re.sub(r"segments\[(\d+)\]\.duration", lambda m: f"--duration number {int(m[1]) + 1}", str(exc))
        raise typer.BadParameter(message.replace("segments[", "segment ["), param_hint="--duration") from None


def _follow(job, paths: list[str], output, quiet: bool, fmt: str, **table_options) -> int:
    """The body of follow: records out, counts and diagnostics on stderr."""
    from .io.inputs import expand
    from .run.follow import write_follow

    stderr = _Stderr(quiet)
    with _output(output) as out:
        w = FORMATS[fmt].open(out, "follow", **table_options, **FORMATS[fmt].hand_options(job.hand))
        for o in write_follow(job, expand(paths), w, fmt, table_options.get("order", "omega-v")):
            out.flush()
            stderr.take(o)
        w.close()
    stderr.summary()
    return EXIT_FAILED if stderr.failed else EXIT_OK


@app.command()
def schema(output: str | None = _OUTPUT, debug: bool = _DEBUG) -> None:
    """Print the JSON Schema of grasp files (for editors with a YAML language server).

    Example:

    \b
        grasptwist schema -o grasp.schema.json
    """
    from .io.grasp import grasp_schema
    from .output.records import dumps

    def job():
        with _output(output) as out:
            out.write(dumps(grasp_schema(), indent=True) + b"\n")
        return EXIT_OK

    _run(debug, job)


PlotMethod = _choices("PlotMethod", [k.label for k in KINDS if k.method])


@app.command()
def plot(
    path: str = typer.Argument(
        ..., metavar="PATH", help="A grasp file, or a folder for one image per grasp and twist."
    ),
    output: str = typer.Option(
        ...,
        "-o",
        "--output",
        metavar="FILE|FOLDER",
        help="The image (.png, .svg or .pdf), or the folder for a folder's images.",
    ),
    twist: str | None = typer.Option(
        None, "--twist", metavar="W1,W2,W3,V1,V2,V3", help="Draw this twist (omega; v) instead of the file's."
    ),
    twist_name: str | None = typer.Option(
        None, "--twist-name", metavar="NAME", help="Which of the file's twists to draw (or the name of --twist)."
    ),
    at: str | None = typer.Option(
        None, "--at", metavar="X,Y,Z", help="Point whose velocity the --twist linear part gives."
    ),
    method: PlotMethod | None = typer.Option(
        None, "--method", help="Basis to draw (default: off-tangent with a wrist, else tangent)."
    ),
    max_bytes: int | None = _MAX_BYTES,
    debug: bool = _DEBUG,
) -> None:
    """Draw a grasp, its basis screw axes and the finger-tip velocities (needs matplotlib: from a clone, pip install '.[plot]').

    Examples: the paper's cylinder spinning about z, and every bundled grasp:

    \b
        grasptwist plot grasps/cylinder.yaml --twist-name spin-z -o cylinder.png
        grasptwist plot grasps/ -o pictures/
    """
    twists = _cli_twists([twist] if twist else None, at)
    if twists and twist_name:
        twists = [replace(twists[0], name=twist_name)]
    _run(debug, lambda: _plot(path, output, twists, twist_name, method.value if method else None, max_bytes))


def _plot(path, output, twists, twist_name, method, max_bytes) -> int:
    """The body of ``plot``: the drawing and its notes come from plot.render_inputs;
    here only usage errors, stdout and stderr."""
    from . import plot as pictures
    from .io.datasets import DATASET_SUFFIXES

    stderr = _Stderr()
    if path.endswith(DATASET_SUFFIXES):
        raise typer.BadParameter(
            "plot draws grasp files (.yaml, .yml) or folders of them, not data sets", param_hint="PATH"
        )
    if not os.path.isdir(path):
        _writable_folder(output)
    try:
        for item in pictures.render_inputs(
            path, output, twists=twists, twist_name=twist_name, method=method, max_bytes=max_bytes
        ):
            if isinstance(item, pictures.Note):
                stderr.failed += item.error
                stderr.say(item.line, ": error: " if item.error else ": warning: ", "31" if item.error else "33")
            else:
                sys.stdout.write(f"{item}\n")
    except pictures.MissingMatplotlib as exc:
        sys.stderr.write(f"{exc}\n")  # the README's line: "grasptwist plot needs matplotlib: ..."
        return EXIT_FAILED
    except pictures.TwistNotFound as exc:
        raise typer.BadParameter(str(exc), param_hint="--twist-name") from None
    except ValueError as exc:  # an unknown method or suffix, off-tangent without a wrist
        raise typer.BadParameter(str(exc)) from None
    return EXIT_FAILED if stderr.failed else EXIT_OK


def _workers(requested: int) -> int:
    """Processes: as asked, or every core (the pipeline uses them only for big batches)."""
    return requested if requested > 0 else min(os.cpu_count() or 1, 8)


@dataclass(frozen=True)
class Shared:
    """The options resolve, basis and check share beyond their job, as one object: where the
    records go, how many processes make them, what stderr says, and how tables print numbers.
    (typer declares options as parameters, so each command lists them; the same typer.Option
    objects, defined once above.)"""

    output: str | None
    quiet: bool
    warnings: Warnings
    workers: int
    table_options: dict = field(default_factory=dict)


def _emit(job, paths: list[str], shared: Shared) -> int:
    """Files in, records out: the body of resolve, basis and check."""
    from .io.inputs import expand
    from .run.pipeline import run, write_blocks

    stderr = _Stderr(shared.quiet, shared.warnings, hint=_table_hint(job.kind) if job.fmt == "table" else None)
    inputs = list(expand(paths))
    fmt = FORMATS[job.fmt]
    with _output(shared.output) as out, _progress(inputs, job.kind, out) as advance:
        w = fmt.open(out, job.kind, **shared.table_options, **fmt.hand_options(job.hand))
        # block writers (npz) take results here; the others get records encoded where they were made
        outputs = write_blocks(job, inputs, w) if fmt.takes_blocks else run(job, inputs, _workers(shared.workers))
        for o in outputs:
            for encoded in o.encoded:
                w.write(encoded)
            if o.spool:
                w.write_spooled(o.spool)
            out.flush()  # a batch streams: each group is out as soon as it is ready
            stderr.take(o)
            advance(o)
        w.close()
    stderr.summary()
    return EXIT_FAILED if stderr.failed else EXIT_OK


def _drop_stdout() -> None:
    """Send what stdout still buffers to /dev/null: after a failure it must
    neither block the exit on a stalled reader nor fail a second time."""
    try:
        fd = sys.stdout.fileno()
    except (AttributeError, OSError, ValueError):  # not a real file (tests' capture)
        return
    os.dup2(os.open(os.devnull, os.O_WRONLY), fd)


def _stopped(stop) -> int:
    """Say which signal stopped the run; the exit status a shell gives for it."""
    _drop_stdout()
    _say(f"grasptwist: stopped by {stop.name}")
    return stop.exit_status


def _run(debug: bool, job) -> None:
    """Run a command body; turn every way it can end into one line and an exit status."""
    from .extras import MissingExtra
    from .run.pool import WorkerDied
    from .run.signals import Interrupted
    from .run.target import WriteError

    try:
        code = job()
    except (typer.Exit, typer.Abort, typer.BadParameter):
        raise  # typer's own ways out: exit codes, usage errors (2)
    except (Interrupted, KeyboardInterrupt) as exc:  # KeyboardInterrupt: run without main(), as by tests
        raise typer.Exit(_stopped(exc if isinstance(exc, Interrupted) else Interrupted(signal.SIGINT))) from None
    except BrokenPipeError:
        # The reader (e.g. `head`) went away: stop quietly with the status of a
        # Unix filter killed by SIGPIPE, and keep Python's final flush quiet too.
        _drop_stdout()
        raise typer.Exit(EXIT_BROKEN_PIPE) from None
    except MissingExtra as exc:  # e.g. -f parquet without pyarrow, found before any output
        _say(f"grasptwist: error: {exc}")
        raise typer.Exit(EXIT_USAGE) from None
    except (WriteError, WorkerDied) as exc:
        _drop_stdout()
        _say(f"grasptwist: error: {exc}")
        raise typer.Exit(EXIT_WRITE if isinstance(exc, WriteError) else EXIT_WORKER) from None
    except Exception as exc:  # noqa: BLE001 - the one place a traceback is turned into a line
        if debug:
            raise
        _say(f"grasptwist: internal error: {type(exc).__name__}: {exc} (rerun with --debug for the traceback)")
        raise typer.Exit(EXIT_FAILED) from None
    raise typer.Exit(code)


def main() -> None:
    """Run the command line (the ``grasptwist`` script is :func:`grasptwist.__main__.main`)."""
    from .run.signals import Interrupted, stop_on_signals

    stop_on_signals()
    try:
        code = app(standalone_mode=False)
    except Interrupted as stop:  # while typer parsed the command line
        sys.exit(_stopped(stop))
    except _CLICK_ERROR as exc:
        sys.exit(_usage_error(exc))
    sys.exit(code if isinstance(code, int) else EXIT_OK)


# The base of the usage errors of typer's click (typer 0.2x carries its own copy of click, so it is
# found from the one typer exports, whichever click that is).
_CLICK_ERROR = next(c for c in typer.BadParameter.__mro__ if c.__name__ == "ClickException")


def _usage_error(exc) -> int:
    """One line for a usage error (exit 2), as for every other diagnostic: what is wrong, and
    where help is, instead of click's four lines of usage, hint, blank and error."""
    if type(exc).__name__ == "NoArgsIsHelpError":  # `grasptwist` alone: the help is the answer
        _say(exc.format_message())
        return exc.exit_code
    ctx = getattr(exc, "ctx", None)
    message = " ".join(exc.format_message().split())  # on one line, whatever it quotes
    where = f" (see '{ctx.command_path} -h')" if ctx is not None else ""
    _say(f"grasptwist: error: {message}{where}")
    return exc.exit_code


if __name__ == "__main__":
    main()
