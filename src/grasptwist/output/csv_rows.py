"""CSV text of result blocks, from their flat columns (:func:`columns.columns`).

One line per record, the cells of a block made a column at a time: floats
in Python's shortest round-trip form (``repr``) with no ``-0.0``, booleans
``true``/``false``, masked values (what does not apply) empty, text quoted
by the :mod:`csv` module when it must be.
"""

from __future__ import annotations

import csv
import io

import numpy as np

from .columns import CSV_COLUMNS, FORCE_CSV_COLUMNS, columns, force_columns, header
from .names import escaped_each
from .records import records, talking_rows

__all__ = [
    "HEADER",
    "FORCE_HEADER",
    "header_line",
    "encode_rows",
    "error_row",
    "lines",
    "force_rows",
    "force_error_row",
]

#: The header line of a run without a hand.
HEADER = ",".join(CSV_COLUMNS).encode() + b"\n"


def header_line(hand=None) -> bytes:
    """The header line, with the joint columns of the run's ``hand``."""
    return HEADER if hand is None else ",".join(header(hand)).encode() + b"\n"


def _cells(a: np.ndarray) -> list:
    """The CSV cells of one flat column."""
    data = np.ma.getdata(a)
    if data.dtype.kind == "f":
        cells = list(map(repr, (data + 0.0).tolist()))  # + 0.0: no "-0.0"
    elif data.dtype.kind == "b":
        cells = ["true" if v else "false" for v in data.tolist()]
    elif data.dtype.kind in "UO":  # names: escaped as in the records
        cells = escaped_each(data.tolist())
    else:
        cells = data.tolist()
    for i in np.flatnonzero(np.ma.getmaskarray(a)):
        cells[i] = ""
    return cells


def _lines(rows) -> list[bytes]:
    """Each row as one CSV line."""
    text = io.StringIO()
    write = csv.writer(text, lineterminator="\n").writerow
    ends = np.cumsum([write(row) for row in rows]).tolist()
    whole = text.getvalue()
    return [whole[a:b].encode() for a, b in zip([0] + ends, ends)]


def encode_rows(block, order: str, hand=None) -> tuple[list[bytes], list[dict]]:
    """The CSV line of each row, and the records of the rows with something to say."""
    cells = [_cells(a) for a in columns(block, order, hand).values()]
    talking = np.flatnonzero(talking_rows(block))
    return _lines(zip(*cells)), records(block.take(talking), order) if talking.size else []


def lines(named: dict) -> list[bytes]:
    """The CSV line of each row of flat columns ``name -> (N,)`` array (masked: empty cells)."""
    return _lines(zip(*(_cells(a) for a in named.values())))


def error_row(rec: dict, hand=None) -> bytes:
    """The CSV line of an input that failed (:func:`records.error_record`)."""
    err = rec["error"]
    row = [rec["file"], "", "", "false", f"{err['code']}: {err['message']}"]  # file, grasp, twist, ok, error
    return _lines([row + [""] * (len(header(hand)) - len(row))])[0]


#: The header line of ``grasptwist forces``.
FORCE_HEADER = ",".join(FORCE_CSV_COLUMNS).encode() + b"\n"


def force_rows(block) -> tuple[list[bytes], list[dict]]:
    """The CSV line of each force row, and the records of the rows with something to say."""
    from .force_records import force_records

    recs = force_records(block)
    return lines(force_columns(block)), [rec for rec in recs if not rec["ok"] or rec["warnings"]]


def force_error_row(rec: dict, hand=None) -> bytes:
    """The CSV line of an input that failed, under :data:`FORCE_HEADER`."""
    err = rec["error"]
    row = [rec["file"], "", "", "false", f"{err['code']}: {err['message']}"]  # file, grasp, wrench, ok, error
    return _lines([row + [""] * (len(FORCE_CSV_COLUMNS) - len(row))])[0]
