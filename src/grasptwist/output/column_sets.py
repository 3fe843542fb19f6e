"""Each family's rows as columns (:class:`~grasptwist.output.columns.ColumnSet`): what CSV,
Parquet and npz write of the twist, wrench and path families, named by the family registry
(:mod:`grasptwist.run.families`)."""

from __future__ import annotations

from ..engine.degeneracy import Status
from ..engine.forces.grasp_map import ForceStatus
from . import csv_rows
from . import follow_records as fr
from .columns import ColumnSet, arrays, columns, force_arrays, force_columns, force_typed_header, typed_header

__all__ = ["TWIST_COLUMNS", "WRENCH_COLUMNS", "PATH_COLUMNS"]

#: The twist family's columns (resolve rows; basis and check write no columns).
TWIST_COLUMNS = ColumnSet(
    header=csv_rows.header_line,
    flat=columns,
    arrays=arrays,
    error_row=csv_rows.error_row,
    statuses=Status,
    typed_header=typed_header,
)

#: The wrench family's columns (``forces`` rows): no joints; npz's tables of names only where there are names.
WRENCH_COLUMNS = ColumnSet(
    header=lambda hand=None: csv_rows.FORCE_HEADER,
    flat=lambda block, order="omega-v", hand=None, typed=False: force_columns(block, typed),
    arrays=lambda block, order="omega-v", hand=None: force_arrays(block),
    error_row=csv_rows.force_error_row,
    statuses=ForceStatus,
    typed_header=lambda hand=None: force_typed_header(),
    name_tables=False,
)

#: The path family's columns (``follow`` samples: the path's own, then resolve's; no Parquet).
PATH_COLUMNS = ColumnSet(
    header=fr.csv_header,
    flat=fr.sample_columns,
    arrays=fr.sample_arrays,
    error_row=fr.csv_error_row,
    statuses=Status,
)
