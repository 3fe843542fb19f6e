"""``grasptwist check``: validate grasp files and report degenerate grasps without resolving."""

from .diagnostics import Warnings
from .exits import run_command
from .options import (
    ALL,
    AllowOutside,
    ContactOption,
    Debug,
    Json,
    MaxBytes,
    Method,
    Output,
    Paths,
    Quiet,
    RecordFormat,
    RecordFormatOption,
    SurfaceTol,
    Torsion,
    WarningsOption,
    Workers,
    contact_torsion,
    reading_option,
)
from .records import OutputSettings, write_records

__all__ = ["check"]


def check(
    paths: Paths,
    method: Method = ALL,
    fmt: RecordFormatOption = RecordFormat.table,
    json_: Json = False,
    output: Output = None,
    max_bytes: MaxBytes = None,
    surface_tol: SurfaceTol = None,
    allow_outside: AllowOutside = False,
    contact: ContactOption = None,
    torsion: Torsion = None,
    workers: Workers = 0,
    quiet: Quiet = False,
    warnings: WarningsOption = Warnings.summary,
    debug: Debug = False,
) -> None:
    """Validate grasp files and report degenerate grasps without resolving; exit 1 if any fails.

    Example, over a folder, listing only the failures:

    \b
        grasptwist check grasps/ -f jsonl | jq -c 'select(.ok | not)'
    """
    from ..run.families import COMMANDS
    from ..run.options import TwistOptions
    from ..run.pipeline import Job

    torsion = contact_torsion(contact, torsion)
    job = Job(
        command=COMMANDS["check"],
        fmt="json" if json_ else fmt.value,
        max_bytes=max_bytes,
        reading=reading_option(surface_tol, allow_outside),
        options=TwistOptions(method=method.value, torsion=torsion),
    )
    run_command(debug, lambda: write_records(job, paths, OutputSettings(output, quiet, warnings, workers)))
