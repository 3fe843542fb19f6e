"""Results as one Parquet file: the CSV's columns, typed, from the one columns definition.

Columns and their order are :func:`~grasptwist.output.columns.typed_header`
(the CSV's, a hand's joint columns included, and each kind's ``<key>_status``
after its conditioning): text
as dictionary-encoded strings, ``ok`` and ``in_tangent_planes`` as
booleans, statuses as int8 (-1: skipped), numbers as float64; a value that
does not apply (an empty CSV cell) is null.  Rows are written in row groups
of about :data:`ROW_GROUP_ROWS` as blocks arrive, so memory stays bounded.
pyarrow (the extra ``grasptwist[parquet]``) is imported only here.
"""

from __future__ import annotations

from typing import IO

import numpy as np

from ..extras import require
from .column_sets import TWIST_COLUMNS
from .columns import ColumnSet

__all__ = ["ROW_GROUP_ROWS", "write_options", "schema", "table", "ParquetWriter"]

#: Rows per row group written (about 25 MB of results before compression).
ROW_GROUP_ROWS = 65536


def write_options(hand=None, columns: ColumnSet = TWIST_COLUMNS) -> dict:
    """Options of pyarrow's Parquet writer for results: dictionary pages for text
    only (on floats they cost five times the write and save nothing)."""
    return {"use_dictionary": [name for name, dtype in columns.typed_header(hand).items() if dtype == "U"]}


def _arrow_type(pa, dtype: str):
    return pa.dictionary(pa.int32(), pa.string()) if dtype == "U" else pa.from_numpy_dtype(np.dtype(dtype))


def schema(hand=None, columns: ColumnSet = TWIST_COLUMNS):
    """The Arrow schema of results: :func:`~grasptwist.output.columns.typed_header` with their types.

    >>> s = schema()
    >>> str(s.field("ok").type), str(s.field("tangent_status").type), str(s.field("file").type)
    ('bool', 'int8', 'dictionary<values=string, indices=int32, ordered=0>')
    """
    pa = require("pyarrow", "Parquet output")
    return pa.schema([(name, _arrow_type(pa, dtype)) for name, dtype in columns.typed_header(hand).items()])


def _array(pa, values, arrow_type):
    """One column as an Arrow array: masked values null, text dictionary-encoded."""
    masked = np.ma.isMaskedArray(values)
    mask = np.ma.getmaskarray(values) if masked and np.ma.getmaskarray(values).any() else None
    data = np.ma.getdata(values) if masked else values  # labels may be lists or numpy text: both as they are
    if pa.types.is_dictionary(arrow_type):
        return pa.array(data, pa.string(), mask=mask).dictionary_encode()
    return pa.array(data, arrow_type, mask=mask)


def table(block, order: str = "omega-v", hand=None, columns: ColumnSet = TWIST_COLUMNS):
    """A result block as an Arrow table of :func:`schema` (``hand``: the run's, whose joint
    columns follow; ``columns``: its family's)."""
    pa = require("pyarrow", "Parquet output")
    s = schema(hand, columns)
    flat = columns.flat(block, order, hand, typed=True)
    return pa.Table.from_arrays([_array(pa, flat[f.name], f.type) for f in s], schema=s)


class ParquetWriter:
    """Result blocks into one Parquet file, a row group at a time.

    Blocks are held until they make :data:`ROW_GROUP_ROWS` rows (or the end),
    then written as one row group.
    """

    def __init__(
        self,
        out: IO[bytes],
        order: str = "omega-v",
        row_group_rows: int = ROW_GROUP_ROWS,
        hand=None,
        columns: ColumnSet = TWIST_COLUMNS,
    ):
        pq = require("pyarrow.parquet", "-f parquet")
        self.columns = columns
        self.order = order
        self.hand = hand
        self.row_group_rows = row_group_rows
        self.pending: list = []
        self.rows = 0
        self.writer = pq.ParquetWriter(out, schema(hand, columns), **write_options(hand, columns))

    def write(self, block) -> None:
        """Append a block's rows."""
        self.pending.append(table(block, self.order, self.hand, self.columns))
        self.rows += len(block)
        if self.rows >= self.row_group_rows:
            self._flush()

    def _flush(self) -> None:
        if self.rows:
            import pyarrow as pa

            self.writer.write_table(pa.concat_tables(self.pending), row_group_size=self.rows)
        self.pending, self.rows = [], 0

    def close(self) -> None:
        """Write what is held and the file's footer."""
        self._flush()
        self.writer.close()

    def __del__(self):
        # Never closed: the run failed and its output is being discarded; pyarrow's
        # own finaliser would write a footer to the closed output (a second error).
        # No writer at all: pyarrow was missing, which the run has already said.
        writer = getattr(self, "writer", None)
        if writer is not None:
            writer.is_open = False
