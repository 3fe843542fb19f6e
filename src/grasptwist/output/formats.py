"""The output formats, described once: what each writes and how, for any command.

A format either encodes records where they are made (in worker processes
too) and writes the encoded bytes in order (``json``, ``jsonl``, ``csv``,
``table``), or takes whole result blocks in the writing process (``npz``,
``parquet``: ``takes_blocks``).  Which formats a command offers, and what
its records, columns and table are, is the command's entry in the family
registry (:mod:`grasptwist.run.families`); a format reads them from the
run's job, never from the command's name:

* ``job.command.records(block, job)``: the records of a block's rows;
  ``job.command.json_rows`` a faster way to their JSON (or None);
  ``job.command.talking(block, job)`` the records with something for stderr;
* ``job.command.table``: its table writer, ``"module.Class"`` in this package,
  and ``job.command.contributions``: the columns other families add to it;
* ``job.family.columns()``: its :class:`~grasptwist.output.columns.ColumnSet`;
* ``job.order``, ``job.hand``: the screw order and the run's hand.
"""

from __future__ import annotations

from collections.abc import Callable
from importlib import import_module
from typing import IO, Any, NamedTuple

from .records import dumps
from .writers import JsonArray, Lines

__all__ = ["OutputFormat", "FORMATS", "json_rows", "csv_lines"]


class OutputFormat(NamedTuple):
    """One output format.

    Attributes
    ----------
    name : str
        Its ``-f`` value.
    open : callable
        ``(out, job, order, **table_options) -> writer`` with ``write`` and
        ``close``.
    rows : callable or None
        ``(block, job) -> (encoded rows, records with something to say)``,
        a block at a time.
    error : callable or None
        ``(error record, job) -> encoded``: an input that failed.
    join : callable or None
        ``list of encoded -> bytes``, one write for many records; None when
        the writer takes records one by one.
    binary : bool
        Its bytes are not for a terminal: it needs ``-o`` there.
    takes_blocks : bool
        Its writer takes result blocks (``write(block)``) rather than
        encoded records.
    bases : bool
        It shows basis screws (False: resolve without them, a third less work).
    per_hand : bool
        Its columns depend on the run's hand (the joints of ``--hand``).
    """

    name: str
    open: Callable[..., Any]
    rows: Callable[[Any, Any], tuple[list, list[dict]]] | None = None
    error: Callable[[dict, Any], Any] | None = None
    join: Callable[[list], bytes] | None = None
    binary: bool = False
    takes_blocks: bool = False
    bases: bool = True
    per_hand: bool = False


def _table(out: IO[bytes], job, order: str = "omega-v", **table_options):
    # rich is imported only for people-facing output: the writer is named, not imported
    module, name = job.command.table.rsplit(".", 1)
    writer = getattr(import_module(f".{module}", __package__), name)
    return writer(out, order=order, contributions=job.command.contributions, **table_options)


def _csv(out: IO[bytes], job, **_):
    return Lines(out, header=job.family.columns().header(job.hand), newline=b"")


def _npz(out: IO[bytes], job, order: str = "omega-v", **_):
    from .npz import NpzWriter

    return NpzWriter(out, order, hand=job.hand, columns=job.family.columns())


def _parquet(out: IO[bytes], job, order: str = "omega-v", **_):
    from .parquet_writer import ParquetWriter  # pyarrow only when Parquet is asked for

    return ParquetWriter(out, order, hand=job.hand, columns=job.family.columns())


def json_rows(block, job) -> tuple[list[bytes], list[dict]]:
    """The JSON of each row's record, and the records with something to say."""
    if job.command.json_rows is not None:
        return job.command.json_rows(block, job)
    recs = job.command.records(block, job)
    return [dumps(rec) for rec in recs], [rec for rec in recs if not rec["ok"] or rec["warnings"]]


def csv_lines(block, job) -> tuple[list[bytes], list[dict]]:
    """The CSV line of each row (the family's columns), and the records with something to say."""
    from . import csv_rows  # the csv module only when CSV is asked for (start-up, bench/startup.py)

    return csv_rows.lines(job.family.columns().flat(block, job.order, job.hand)), job.command.talking(block, job)


def _json_error(rec, job):
    return dumps(rec)


def _csv_error(rec, job):
    return job.family.columns().error_row(rec, job.hand)


#: Every output format by name, in the order ``--help`` lists them.
FORMATS: dict[str, OutputFormat] = {
    f.name: f
    for f in (
        # table records travel as JSON (a worker's records cost the parent far less to take than as objects)
        OutputFormat("table", _table, json_rows, _json_error),
        OutputFormat("json", lambda out, job, **_: JsonArray(out), json_rows, _json_error, join=b",\n".join),
        OutputFormat("jsonl", lambda out, job, **_: Lines(out), json_rows, _json_error, join=b"\n".join),
        OutputFormat("csv", _csv, csv_lines, _csv_error, join=b"".join, per_hand=True),
        OutputFormat("npz", _npz, binary=True, takes_blocks=True, bases=False, per_hand=True),
        OutputFormat("parquet", _parquet, binary=True, takes_blocks=True, bases=False, per_hand=True),
    )
}
