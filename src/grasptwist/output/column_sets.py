"""The twist family's rows as columns (:class:`~grasptwist.output.columns.ColumnSet`): what CSV,
Parquet and npz write of ``resolve``; the wrench family's are in :mod:`.force_records`, the path
family's in :mod:`.follow_records`, each loaded with its family's first run."""

from __future__ import annotations

from ..engine.degeneracy import Status
from . import csv_rows
from .columns import ColumnSet, arrays, columns, typed_header

__all__ = ["TWIST_COLUMNS"]

#: The twist family's columns (resolve rows; basis and check write no columns).
TWIST_COLUMNS = ColumnSet(
    header=csv_rows.header_line,
    flat=columns,
    arrays=arrays,
    error_row=csv_rows.error_row,
    statuses=Status,
    typed_header=typed_header,
)
