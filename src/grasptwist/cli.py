"""The ``grasptwist`` command line (typer).

A thin layer: it parses options, asks :mod:`inputs` for files, the loader
for grasps, :mod:`batch` for resolutions and :mod:`report` for output.
stdout carries data only; every diagnostic goes to stderr as one line
``path:line:col: error: message``.  Exit codes: 0 all records ok, 1 some
record failed (the others are still written in full), 2 usage error.
"""

from __future__ import annotations

import os
import sys
import tempfile
from contextlib import contextmanager
from enum import Enum
from typing import Iterator, List, Optional

import typer

from . import __version__

EXIT_OK, EXIT_FAILED, EXIT_USAGE = 0, 1, 2

app = typer.Typer(
    name="grasptwist",
    help="Resolve a desired object twist into finger-tip twists for a three-fingered grasp (screw theory).",
    no_args_is_help=True,
    add_completion=True,
    rich_markup_mode=None,
    pretty_exceptions_enable=False,
)


class Method(str, Enum):
    both = "both"
    off_tangent = "off-tangent"
    tangent = "tangent"


class Format(str, Enum):
    table = "table"
    json = "json"
    jsonl = "jsonl"
    csv = "csv"


class Order(str, Enum):
    omega_v = "omega-v"
    v_omega = "v-omega"


def _floats(text: str, n: int, what: str) -> list[float]:
    try:
        values = [float(x) for x in text.replace(" ", "").split(",")]
    except ValueError:
        values = []
    if len(values) != n or not all(v == v and abs(v) != float("inf") for v in values):
        raise typer.BadParameter(f"{what} needs {n} finite comma-separated numbers, got {text!r}")
    return values


def _cli_twists(texts: list[str] | None, at: str | None):
    """``--twist`` values as loader twists at the origin (``--at`` names the reference point)."""
    if not texts:
        if at is not None:
            raise typer.BadParameter("--at applies to --twist; give at least one --twist", param_hint="--at")
        return None
    from .grasp_file import Twist
    from .screws import twist_at

    point = _floats(at, 3, "--at") if at is not None else [0.0, 0.0, 0.0]
    twists = []
    for text in texts:
        w = _floats(text, 6, "--twist")
        twists.append(Twist(name=text.replace(" ", ""), screw=twist_at(w[:3], w[3:], point), line=None))
    return twists


class _Diagnostics:
    """One line per problem on stderr, counted; a progress bar on a terminal."""

    def __init__(self, quiet: bool = False):
        self.failed = 0
        self.records = 0
        self.quiet = quiet
        self.color = sys.stderr.isatty() and "NO_COLOR" not in os.environ

    def error(self, where: str, message: str) -> None:
        label = "\x1b[31merror\x1b[0m" if self.color else "error"
        sys.stderr.write(f"{where}: {label}: {message}\n")

    def warning(self, where: str, message: str) -> None:
        if not self.quiet:
            label = "\x1b[33mwarning\x1b[0m" if self.color else "warning"
            sys.stderr.write(f"{where}: {label}: {message}\n")

    def summary(self) -> None:
        sys.stderr.write(f"{self.records} records, {self.failed} failed\n")


def _where(file, line=None, column=None) -> str:
    return ":".join(str(x) for x in (file, line, column) if x is not None)


@contextmanager
def _output(path: str | None) -> Iterator:
    """stdout, or ``path`` written atomically: a temporary file renamed on success only."""
    if path is None or path == "-":
        yield sys.stdout.buffer
        sys.stdout.buffer.flush()
        return
    folder = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(prefix=".grasptwist-", dir=folder)
    try:
        with os.fdopen(fd, "wb") as out:
            yield out
        os.replace(tmp, path)
    except BaseException:
        os.unlink(tmp)
        raise


def _report_record(diag: _Diagnostics, rec: dict) -> None:
    diag.records += 1
    if "error" in rec:
        err = rec["error"]
        diag.failed += 1
        diag.error(_where(rec["file"], err["line"], err["column"]), f"{err['code']}: {err['message']}")
        return
    where = f"{rec['file']}: grasp '{rec['grasp']}'" + (f", twist '{rec['twist']['name']}'" if "twist" in rec else "")
    for method in ("off_tangent", "tangent"):
        m = rec.get(method)
        if isinstance(m, dict) and "error" in m:
            diag.error(where, f"{method.replace('_', '-')}: {m['error']['code']}: {m['error']['message']}")
    if not rec["ok"]:
        diag.failed += 1
    for w in rec["warnings"]:
        diag.warning(where, w)


def _progress(paths: list, enabled: bool):
    """Wrap the file list in a rich progress bar on a terminal (rich imported only then)."""
    if not enabled or len(paths) < 2 or not sys.stderr.isatty():
        return paths, None
    from rich.progress import Progress

    from .table import console

    progress = Progress(console=console(sys.stderr, width=None), transient=True)
    return progress.track(paths, description="resolving"), progress


def _grasps(paths: list, max_bytes: Optional[int]):
    from .inputs import read

    for path in paths:
        if isinstance(path, str):
            yield from read(path, max_bytes)
        else:
            yield path  # an error found while expanding folders


_PATHS = typer.Argument(..., metavar="PATH...", help="Grasp files, folders (searched for *.yaml, *.yml) or - for stdin.")
_METHOD = typer.Option(Method.both, "--method", help="Decomposition(s) to run.")
_OUTPUT = typer.Option(None, "-o", "--output", metavar="FILE", help="Write to FILE (atomically) instead of stdout.")
_DIGITS = typer.Option(4, "--digits", min=0, max=17, help="Decimals in tables (JSON and CSV keep full precision).")
_ORDER = typer.Option(Order.omega_v, "--order", help="Order of every printed 6-vector: (omega; v) or (v; omega).")
_MAX_BYTES = typer.Option(None, "--max-bytes", min=1, help="Refuse grasp files larger than this many bytes (default 1 MiB).")
_QUIET = typer.Option(False, "-q", "--quiet", help="No warnings or summary on stderr (errors still).")
_DEBUG = typer.Option(False, "--debug", help="Show the Python traceback of an internal error.")
_JSON = typer.Option(False, "--json", help="Same as --format json.")


@app.command()
def resolve(
    paths: List[str] = _PATHS,
    twist: Optional[List[str]] = typer.Option(None, "--twist", metavar="W1,W2,W3,V1,V2,V3", help="Object twist (omega; v); repeatable; replaces the files' twists."),
    at: Optional[str] = typer.Option(None, "--at", metavar="X,Y,Z", help="Point whose velocity the --twist linear part gives (default: the origin)."),
    method: Method = _METHOD,
    fmt: Format = typer.Option(Format.table, "-f", "--format", help="table for people; json, jsonl or csv for programs."),
    json_: bool = _JSON,
    output: Optional[str] = _OUTPUT,
    digits: int = _DIGITS,
    order: Order = _ORDER,
    max_bytes: Optional[int] = _MAX_BYTES,
    quiet: bool = _QUIET,
    debug: bool = _DEBUG,
) -> None:
    """Resolve object twists into finger-tip twists and amplitudes: one record per (grasp, twist).

    Example: spin the paper's cylinder about z and read the Psi amplitudes:

        grasptwist resolve grasps/cylinder.yaml --twist 0,0,1,0,0,0 --json | jq '.[0].off_tangent.y'
    """
    from .report import record

    twists = _cli_twists(twist, at)
    fmt = Format.json if json_ else fmt
    job = _Job(paths, twists, method.value, max_bytes, quiet)
    _run(debug, lambda: job.emit(fmt.value, output, "resolve", lambda r: record(r, order.value), digits=digits))


@app.command()
def basis(
    paths: List[str] = _PATHS,
    method: Method = _METHOD,
    fmt: Format = typer.Option(Format.table, "-f", "--format", help="table, json or jsonl."),
    json_: bool = _JSON,
    output: Optional[str] = _OUTPUT,
    digits: int = _DIGITS,
    order: Order = _ORDER,
    max_bytes: Optional[int] = _MAX_BYTES,
    quiet: bool = _QUIET,
    debug: bool = _DEBUG,
) -> None:
    """Show each grasp's basis screws Sigma, Psi, Theta, their Klein products and conditioning.

    Example (the paper's eqs. 16-18, with unit Psi):

        grasptwist basis grasps/cylinder.yaml --method off-tangent
    """
    from .report import basis_record

    fmt = _not_csv(Format.json if json_ else fmt)
    job = _Job(paths, None, method.value, max_bytes, quiet)
    _run(debug, lambda: job.emit(fmt.value, output, "basis", lambda r: basis_record(r, order.value), digits=digits))


@app.command()
def check(
    paths: List[str] = _PATHS,
    method: Method = _METHOD,
    fmt: Format = typer.Option(Format.table, "-f", "--format", help="table, json or jsonl."),
    json_: bool = _JSON,
    output: Optional[str] = _OUTPUT,
    max_bytes: Optional[int] = _MAX_BYTES,
    quiet: bool = _QUIET,
    debug: bool = _DEBUG,
) -> None:
    """Validate grasp files and report degenerate grasps without resolving; exit 1 if any fails.

    Example, over a folder, listing only the failures:

        grasptwist check grasps/ -f jsonl | jq -c 'select(.ok | not)'
    """
    from .report import check_record

    fmt = _not_csv(Format.json if json_ else fmt)
    job = _Job(paths, None, method.value, max_bytes, quiet)
    _run(debug, lambda: job.emit(fmt.value, output, "check", check_record))


@app.command()
def schema(output: Optional[str] = _OUTPUT, debug: bool = _DEBUG) -> None:
    """Print the JSON Schema of grasp files (for editors with a YAML language server).

    Example: grasptwist schema -o grasp.schema.json
    """
    from .grasp_file import grasp_schema
    from .report import dumps

    def job():
        with _output(output) as out:
            out.write(dumps(grasp_schema(), indent=True) + b"\n")
        return EXIT_OK

    _run(debug, job)


def _not_csv(fmt: Format) -> Format:
    if fmt == Format.csv:
        raise typer.BadParameter("csv is for resolve records; use table, json or jsonl", param_hint="--format")
    return fmt


class _Job:
    """Files in, grasps through the engine, one record each out: shared by resolve, basis and check."""

    def __init__(self, paths, twists, method, max_bytes, quiet):
        self.paths = paths
        self.twists = twists
        self.method = method
        self.max_bytes = max_bytes
        self.diag = _Diagnostics(quiet)

    def emit(self, fmt, output, kind, to_record, **table_options) -> int:
        from .batch import ZERO_TWIST
        from .batch import resolve as resolve_all
        from .inputs import expand
        from .report import error_record, writer

        # basis and check resolve the zero twist: the bases do not depend on the twist
        twists = self.twists if kind == "resolve" else [ZERO_TWIST]
        files, progress = _progress(list(expand(self.paths)), enabled=True)
        with _output(output) as out, (progress or _nothing()):
            w = writer(fmt, out, kind, **table_options)
            for item in resolve_all(_grasps(files, self.max_bytes), twists, self.method):
                rec = error_record(item) if not hasattr(item, "grasp") else to_record(item)
                _report_record(self.diag, rec)
                w.write(rec)
            w.close()
        if not self.diag.quiet:
            self.diag.summary()
        return EXIT_FAILED if self.diag.failed else EXIT_OK


@contextmanager
def _nothing():
    yield


def _run(debug: bool, job) -> None:
    """Run a command body; turn anything unexpected into one line and exit 1."""
    try:
        code = job()
    except (typer.Exit, typer.Abort, KeyboardInterrupt):
        raise
    except BrokenPipeError:
        # the reader (e.g. `head`) went away: not an error of ours
        sys.stderr.close()
        raise typer.Exit(EXIT_FAILED)
    except Exception as exc:  # noqa: BLE001 - the one place a traceback is turned into a line
        if debug:
            raise
        sys.stderr.write(f"grasptwist: internal error: {type(exc).__name__}: {exc} (rerun with --debug for the traceback)\n")
        raise typer.Exit(EXIT_FAILED)
    raise typer.Exit(code)


def main() -> None:
    """Entry point of the ``grasptwist`` script."""
    app()


if __name__ == "__main__":
    main()
