"""The output formats, described once: what each writes, for which commands, and how.

The command line offers, per command, the formats whose ``commands`` name
it, and runs a command by looking its format up in :data:`FORMATS` rather
than comparing names.  A format either encodes records where they are
made (in worker processes too) and writes the encoded bytes in order
(``json``, ``jsonl``, ``csv``, ``table``), or takes whole result blocks in
the writing process (``npz``, ``parquet``: ``takes_blocks``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import IO, Any

from . import csv_rows
from .json_rows import encode_records
from .records import dumps, records
from .writers import JsonArray, Lines

__all__ = ["OutputFormat", "FORMATS", "names_for"]


@dataclass(frozen=True)
class OutputFormat:
    """One output format.

    Attributes
    ----------
    name : str
        Its ``-f`` value.
    commands : tuple of str
        The commands that offer it (``resolve``, ``basis``, ``check``,
        ``follow``; how ``follow`` encodes its records in each format is in
        :data:`grasptwist.output.follow_records.ENCODINGS`).
    open : callable
        ``(out, kind, order, **table_options) -> writer`` with ``write`` and
        ``close``; ``kind`` is the command.
    encode : callable or None
        ``record -> encoded`` for records built one at a time (inputs that
        failed; ``basis`` and ``check`` records).
    encode_rows : callable or None
        ``(block, order) -> (encoded rows, records with something to say)``
        for ``resolve`` rows, a block at a time.
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
        Its columns depend on the run's hand (the joints of ``--hand``):
        ``open``, ``encode`` and ``encode_rows`` take ``hand=``.
    encode_forces, encode_force_error : callable or None
        For ``forces`` rows when they are not encoded record by record
        (CSV): ``block -> (encoded rows, records with something to say)``,
        and ``error record -> encoded``.
    """

    name: str
    commands: tuple[str, ...]
    open: Callable[..., Any]
    encode: Callable[[dict], Any] | None = None
    encode_rows: Callable[[Any, str], tuple[list, list[dict]]] | None = None
    join: Callable[[list], bytes] | None = None
    binary: bool = False
    takes_blocks: bool = False
    bases: bool = True
    per_hand: bool = False
    encode_forces: Callable[[Any], tuple[list, list[dict]]] | None = None
    encode_force_error: Callable[[dict], Any] | None = None

    def hand_options(self, hand) -> dict:
        """The keyword arguments that give ``open``/``encode``/``encode_rows`` the run's hand."""
        return {"hand": hand} if self.per_hand else {}


def _table(out: IO[bytes], kind: str, order: str = "omega-v", **table_options):
    if kind == "follow":  # plain text, its own module (no rich)
        from .follow_table import FollowTable

        return FollowTable(out, order=order, **table_options)
    from . import table  # rich is imported only for people-facing output

    return table.WRITERS[kind](out, order=order, **table_options)


def _csv(out: IO[bytes], kind: str, hand=None, **_):
    if kind == "forces":
        return Lines(out, header=csv_rows.FORCE_HEADER, newline=b"")
    if kind == "follow":
        from .follow_records import csv_header

        return Lines(out, header=csv_header(hand), newline=b"")
    return Lines(out, header=csv_rows.header_line(hand), newline=b"")


def _npz(out: IO[bytes], kind: str, order: str = "omega-v", hand=None, **_):
    from .npz import NpzWriter

    return NpzWriter(out, order, hand=hand, forces=kind == "forces")


def _parquet(out: IO[bytes], kind: str, order: str = "omega-v", hand=None, **_):
    from .parquet_writer import ParquetWriter  # pyarrow only when Parquet is asked for

    return ParquetWriter(out, order, hand=hand, forces=kind == "forces")


def _json_rows(block, order):
    return encode_records(block, order, records, dumps)


_ALL = ("resolve", "basis", "check", "follow", "forces")

#: Every output format by name, in the order ``--help`` lists them.
FORMATS: dict[str, OutputFormat] = {
    f.name: f
    for f in (
        # table records travel as JSON (a worker's records cost the parent far less to take than as objects)
        OutputFormat("table", _ALL, _table, dumps, _json_rows),
        OutputFormat("json", _ALL, lambda out, kind, **_: JsonArray(out), dumps, _json_rows, join=b",\n".join),
        OutputFormat("jsonl", _ALL, lambda out, kind, **_: Lines(out), dumps, _json_rows, join=b"\n".join),
        OutputFormat(
            "csv",
            ("resolve", "follow", "forces"),
            _csv,
            csv_rows.error_row,
            csv_rows.encode_rows,
            join=b"".join,
            per_hand=True,
            encode_forces=csv_rows.force_rows,
            encode_force_error=csv_rows.force_error_row,
        ),
        OutputFormat(
            "npz", ("resolve", "follow", "forces"), _npz, binary=True, takes_blocks=True, bases=False, per_hand=True
        ),
        OutputFormat(
            "parquet", ("resolve", "forces"), _parquet, binary=True, takes_blocks=True, bases=False, per_hand=True
        ),
    )
}


def names_for(command: str) -> list[str]:
    """The ``-f`` values ``command`` offers.

    >>> names_for("check")
    ['table', 'json', 'jsonl']
    """
    return [f.name for f in FORMATS.values() if command in f.commands]
