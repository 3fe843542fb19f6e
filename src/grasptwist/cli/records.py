"""Files in, records out: the one loop that writes the records of every command."""

from __future__ import annotations

import os
from dataclasses import replace
from typing import NamedTuple

from ..engine.hooks import watching_first_load
from ..output.formats import FORMATS
from .diagnostics import Diagnostics, Warnings, compile_notices, error_code, progress_bar, table_hint
from .exits import EXIT_FAILED, EXIT_OK, EXIT_USAGE, failed, output_target

__all__ = ["OutputSettings", "worker_count", "write_records"]


class OutputSettings(NamedTuple):
    """What a command takes beyond its job: where the records go,
    how many processes make them, what stderr says, and how tables print numbers."""

    output: str | None
    quiet: bool
    warnings: Warnings
    workers: int
    table_options: dict = {}  # read, never written: a table writer's keywords
    reads: tuple = ()  # files read besides the paths (--twists-from, --hand): never the output either


def worker_count(requested: int) -> int:
    """Processes: as asked, or every core (the pipeline uses them only for big batches)."""
    return requested if requested > 0 else min(os.cpu_count() or 1, 8)


def write_records(job, paths: list[str], settings: OutputSettings) -> int:
    """Read ``paths``, write the job's records, report on stderr; the exit status."""
    import typer

    from ..io.inputs import expand
    from ..io.limits import OUTPUT_IS_INPUT
    from ..run.pipeline import outputs
    from ..run.target import replaced_file

    counted = job.family.tells_progress
    hint = table_hint(job.command.formats) if job.fmt == "table" and counted else None
    stderr = Diagnostics(
        settings.quiet, settings.warnings, hint=hint, failed_words=job.command.failed_words, apart=job.command.apart
    )
    inputs = list(expand(paths, job.family.suffixes))
    fmt = FORMATS[job.fmt]
    replaced = replaced_file(settings.output)
    if replaced is not None:  # a mesh or URDF a grasp file names is read, never replaced
        job = replace(job, reading=replace(job.reading, output=replaced))
    reads_output = False
    with (
        watching_first_load(compile_notices(settings.quiet)),  # a fresh install's first grip compiles
        output_target(settings.output, [*inputs, *settings.reads]) as out,
        progress_bar(inputs, job.command.name, out, counted, job.family.long_inputs) as advance,
    ):
        w = fmt.open(out, job, **settings.table_options)
        # block writers (npz) take results in the run; the others get records encoded where they were made
        for o in outputs(job, inputs, w, worker_count(settings.workers)):
            for encoded in o.encoded:
                w.write(encoded)
            if o.spool:
                w.write_spooled(o.spool)
            out.flush()  # a batch streams: each group is out as soon as it is ready
            stderr.take(o)
            advance(o)
            reads_output = reads_output or any(error_code(line) == OUTPUT_IS_INPUT for line in o.errors)
        if reads_output:  # leaving the block by an exception keeps the file as it was
            raise typer.Exit(
                failed(Exception(f"-o: not written: it is a file the run reads ({OUTPUT_IS_INPUT}, above)"), EXIT_USAGE)
            )
        w.close()
    stderr.summary()
    return EXIT_FAILED if stderr.failed else EXIT_OK
