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

from .columns import CSV_COLUMNS, FORCE_CSV_COLUMNS, header
from .names import escaped_each

__all__ = [
    "HEADER",
    "FORCE_HEADER",
    "header_line",
    "error_row",
    "lines",
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


def force_error_row(rec: dict, hand=None) -> bytes:
    """The CSV line of an input that failed, under :data:`FORCE_HEADER`."""
    err = rec["error"]
    row = [rec["file"], "", "", "false", f"{err['code']}: {err['message']}"]  # file, grasp, wrench, ok, error
    return _lines([row + [""] * (len(FORCE_CSV_COLUMNS) - len(row))])[0]
