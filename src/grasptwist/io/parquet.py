"""Parquet data sets in: flat number columns, read a row group at a time.

Columns (see docs/guide/data-sets.md, "Parquet"): ``p1_x p1_y p1_z ...
p3_z`` (the contact points) and ``n1_x ... n3_z`` (their normals); optional
``c_x c_y c_z`` (the wrist), ``w_x w_y w_z v_x v_y v_z`` (the twist ``(omega; v)``) and ``name``
(text or integers).  Numbers may be any float or integer type; nulls read
as NaN (that row's status says so).  Other columns are ignored, so a table
that carries more than grasps reads as it is.

Only the columns named above are read, a batch of :data:`BATCH_ROWS` rows
at a time (the last one held until rows past it are asked for), so memory is
bounded whatever the file's length or row-group size.  Before any row is
read, the footer's row counts must agree (the file's, each row group's, each
column chunk's), and the bytes its rows decode to must pass
:func:`~grasptwist.io.limits.check_inflation`, as an ``.npz`` member's must;
a row group holding fewer rows than it declares, or a page whose checksum
fails, is found as it is read.  Every problem is a ``bad-dataset`` error
naming the file.  pyarrow (the extra ``grasptwist[parquet]``) is imported
only when a Parquet file is read.
"""

from __future__ import annotations

import os

import numpy as np

from ..extras import MissingExtra, require
from ..model import InputError
from .dataset import Dataset
from .limits import check_inflation

__all__ = [
    "POINT_COLUMNS",
    "NORMAL_COLUMNS",
    "WRIST_COLUMNS",
    "TWIST_COLUMNS",
    "NAME_COLUMN",
    "open_parquet",
    "table_dataset",
    "grasp_table",
]


def _xyz(stem: str) -> tuple[str, ...]:
    return tuple(f"{stem}{i}_{a}" for i in range(1, 4) for a in "xyz")


#: The contact points, contact by contact: ``p1_x, p1_y, p1_z, p2_x, ..., p3_z``.
POINT_COLUMNS = _xyz("p")
#: The contact normals, ``n1_x ... n3_z``.
NORMAL_COLUMNS = _xyz("n")
#: The wrist (optional).
WRIST_COLUMNS = ("c_x", "c_y", "c_z")
#: The twist ``(omega; v)`` at the origin (optional).
TWIST_COLUMNS = ("w_x", "w_y", "w_z", "v_x", "v_y", "v_z")
#: The wrench ``(force; moment about the origin)`` (optional; grasptwist forces).
WRENCH_COLUMNS = ("f_x", "f_y", "f_z", "m_x", "m_y", "m_z")
#: The friction: one coefficient per row, or one per contact (optional; grasptwist forces).
FRICTION_COLUMN = ("mu",)
FRICTION_COLUMNS = ("mu1", "mu2", "mu3")
#: The grasp's name (optional; else the row index).
NAME_COLUMN = "name"
#: Rows decoded at a time: a few MB of numbers, whatever the file's row groups.
BATCH_ROWS = 1 << 16

_GROUPS = {
    "points": POINT_COLUMNS,
    "normals": NORMAL_COLUMNS,
    "wrist": WRIST_COLUMNS,
    "twist": TWIST_COLUMNS,
    "wrench": WRENCH_COLUMNS,
    "friction": FRICTION_COLUMNS,
    "mu": FRICTION_COLUMN,
}
_SHAPES = {
    "points": (3, 3),
    "normals": (3, 3),
    "wrist": (3,),
    "twist": (6,),
    "wrench": (6,),
    "friction": (3,),
    "mu": (),
}


def grasp_table(points, normals, wrist=None, twist=None, names=None):
    """Grasps as an Arrow table with the columns above: what ``pyarrow.parquet.write_table`` makes a data set of.

    Needs pyarrow (the extra ``grasptwist[parquet]``).

    Parameters
    ----------
    points, normals : (N, 3, 3) array_like
        Contact points and normals: columns ``p1_x ... p3_z``, ``n1_x ... n3_z``.
    wrist : (N, 3) array_like, optional
        Columns ``c_x c_y c_z``; without them no row has a wrist.
    twist : (N, 6) array_like, optional
        ``(omega; v)``, columns ``w_x ... v_z``; without them the command's ``--twist``.
    names : sequence of N str or int, optional
        Column ``name``; without it a row is named by its index.

    Returns
    -------
    pyarrow.Table

    Examples
    --------
    >>> t = grasp_table(np.zeros((2, 3, 3)), np.ones((2, 3, 3)), twist=np.zeros((2, 6)), names=["a", "b"])
    >>> t.num_rows, t.column_names[:2], t.column_names[-7:]
    (2, ['p1_x', 'p1_y'], ['w_x', 'w_y', 'w_z', 'v_x', 'v_y', 'v_z', 'name'])
    """
    pa = require("pyarrow", "writing Parquet")
    n = len(points)
    groups = {"points": points, "normals": normals, "wrist": wrist, "twist": twist}
    columns = {}
    for key, values in groups.items():
        if values is not None:
            flat = np.asarray(values, dtype=float).reshape(n, -1)
            columns.update({name: flat[:, j] for j, name in enumerate(_GROUPS[key])})
    if names is not None:
        columns[NAME_COLUMN] = pa.array(names)
    return pa.table(columns)


def _bad(path: str, message: str) -> InputError:
    return InputError(code="bad-dataset", message=message, file=path)


def open_parquet(path: str):
    """Open a Parquet data set and check its columns (no rows are read yet).

    Returns a :class:`~grasptwist.io.dataset.Dataset` whose arrays read
    their rows when sliced.

    Raises
    ------
    InputError
        ``bad-dataset`` when the file is not Parquet, or lacks a column, or
        a column has the wrong type; ``read-error`` when it cannot be opened
        or without pyarrow.
    """
    try:
        require("pyarrow", "reading Parquet")
    except MissingExtra as exc:
        raise InputError(code="read-error", message=str(exc), file=path) from None
    reader = _RowGroups(path)
    return _dataset(path, reader.file.schema_arrow, reader)


def table_dataset(table, path: str = ""):
    """A data set of an Arrow table in memory with the columns of a Parquet data set (for Dask partitions).

    Raises
    ------
    InputError
        ``bad-dataset`` as :func:`open_parquet`.
    """
    return _dataset(path, table.schema, _Table(table, path))


def _dataset(path: str, schema, reader):
    """The data set of ``reader``'s rows once ``schema`` has the documented columns; ``reader`` learns which to read."""
    import pyarrow as pa

    twice = sorted({n for n in schema.names if schema.names.count(n) > 1} & _READ)
    if twice:
        raise _bad(path, f"column(s) {', '.join(twice)} given more than once")
    present = {}
    for key, names in _GROUPS.items():
        found = [n for n in names if n in schema.names]
        if found and len(found) < len(names) or not found and key in ("points", "normals"):
            missing = [n for n in names if n not in schema.names]
            raise _bad(path, f"missing column(s) {', '.join(missing)} (the {key})")
        for n in found:
            t = schema.field(n).type
            if not (pa.types.is_floating(t) or pa.types.is_integer(t)):
                raise _bad(path, f"column {n}: expected numbers, got {t}")
        if found:
            present[key] = names
    if "mu" in present and "friction" in present:
        raise _bad(path, "give the friction as mu or as mu1, mu2, mu3, not both")
    labels = None
    if NAME_COLUMN in schema.names:
        t = schema.field(NAME_COLUMN).type
        t = t.value_type if pa.types.is_dictionary(t) else t
        if not (pa.types.is_string(t) or pa.types.is_large_string(t) or pa.types.is_integer(t)):
            raise _bad(path, f"column {NAME_COLUMN}: expected text or integers, got {t}")
        labels = _Names(reader)
    reader.choose([n for names in present.values() for n in names] + ([NAME_COLUMN] if labels else []))
    arrays = {key: _Numbers(reader, cols, _SHAPES[key]) for key, cols in present.items()}
    return Dataset(
        path,
        arrays["points"],
        arrays["normals"],
        arrays.get("wrist"),
        None,
        arrays.get("twist"),
        labels,
        wrench=arrays.get("wrench"),
        friction=arrays.get("friction", arrays.get("mu")),
    )


_READ = {n for names in _GROUPS.values() for n in names} | {NAME_COLUMN}


class _Table:
    """An Arrow table's rows (the reader of :func:`table_dataset`)."""

    def __init__(self, table, path: str):
        self.table, self.path = table, path
        self.columns: list[str] = []

    def __len__(self) -> int:
        return self.table.num_rows

    def choose(self, columns: list[str]) -> None:
        self.columns = columns

    def rows(self, start: int, stop: int):
        return self.table.slice(start, stop - start).select(self.columns)


class _RowGroups:
    """A Parquet file's chosen columns, read forward a batch of rows at a time; the last batch read is kept."""

    def __init__(self, path: str):
        self.path = path
        self.columns: list[str] = []
        self._open()

    def _open(self):
        pq = require("pyarrow.parquet", "reading Parquet")
        self.pid = os.getpid()  # a forked worker opens the file anew (no shared offsets or threads)
        try:
            # a page written with a checksum is read only if it matches (a file without them reads as it is)
            self.file = pq.ParquetFile(self.path, page_checksum_verification=True)
        except OSError as exc:  # the file itself: gone, a folder, no permission
            raise InputError(code="read-error", message=f"cannot read: {exc}", file=self.path) from None
        except Exception as exc:  # noqa: BLE001 - pyarrow raises several kinds for a file that is not Parquet
            raise _bad(self.path, f"cannot read as Parquet: {exc}") from None
        meta = self.file.metadata
        counts = [meta.row_group(i).num_rows for i in range(meta.num_row_groups)]
        negative = next((g for g, n in enumerate(counts) if n < 0), None)
        if negative is not None:  # a count no file can have: before anything sizes itself by it
            raise _bad(self.path, f"row group {negative}: declares {counts[negative]:,} rows, fewer than none")
        self.starts = np.cumsum([0] + counts)
        self.cursor: _Cursor | None = None

    def __len__(self) -> int:
        return int(self.starts[-1])

    def choose(self, columns: list[str]) -> None:
        """Read ``columns`` from now on, once the footer's counts of them agree and the
        bytes their rows decode to are not a likely decompression bomb.

        Raises
        ------
        InputError
            ``bad-dataset`` saying which count disagrees, or what the rows would decode to.
        """
        self.columns = columns
        meta = self.file.metadata
        if meta.num_rows != len(self):
            raise _bad(self.path, f"the footer declares {meta.num_rows:,} rows, its row groups {len(self):,}")
        at = {meta.schema.column(j).path: j for j in range(meta.num_columns)}
        decoded = 0
        for g in range(meta.num_row_groups):
            group = meta.row_group(g)
            for name in columns:
                chunk = group.column(at[name])
                if chunk.num_values != group.num_rows:
                    raise _bad(
                        self.path,
                        f"row group {g}: declares {group.num_rows:,} rows, its column {name} {chunk.num_values:,}",
                    )
                # numbers are read as float64; text as the bytes its pages hold
                decoded += chunk.total_uncompressed_size if name == NAME_COLUMN else 8 * group.num_rows
        try:
            check_inflation(decoded, os.path.getsize(self.path), "decompression bomb")
        except ValueError as exc:
            raise _bad(self.path, f"its {len(columns)} columns read {exc}") from None

    def rows(self, start: int, stop: int):
        """Rows ``start:stop`` of the chosen columns, as an Arrow table."""
        import pyarrow as pa

        if self.pid != os.getpid():
            self._open()
        parts = []
        group = int(np.searchsorted(self.starts, start, side="right")) - 1
        while group < len(self.starts) - 1 and self.starts[group] < stop:
            first = int(self.starts[group])
            parts += self._part(group, max(start, first) - first, min(stop, int(self.starts[group + 1])) - first)
            group += 1
        if not parts:
            return self.file.schema_arrow.empty_table().select(self.columns)
        return pa.Table.from_batches(parts)

    def _part(self, group: int, lo: int, hi: int) -> list:
        """Rows ``lo:hi`` of row group ``group``, as record batches."""
        if self.cursor is None or self.cursor.group != group or self.cursor.first > lo:
            self.cursor = _Cursor(self, group)
        try:
            return self.cursor.take(lo, hi)
        except InputError:
            raise
        except Exception as exc:  # noqa: BLE001 - corrupt pages, failed checksums: any of pyarrow's errors
            raise _bad(self.path, f"row group {group}: cannot read: {exc}") from None


class _Cursor:
    """One row group of a :class:`_RowGroups` read forward in batches; holds rows ``first:end``."""

    def __init__(self, reader: _RowGroups, group: int):
        self.reader, self.group = reader, group
        self.declared = int(reader.starts[group + 1] - reader.starts[group])
        self.batches = reader.file.iter_batches(
            batch_size=BATCH_ROWS, row_groups=[group], columns=reader.columns, use_threads=False
        )
        self.batch, self.first, self.end = None, 0, 0

    def take(self, lo: int, hi: int) -> list:
        """Rows ``lo:hi`` (``lo >= first``), reading on as far as ``hi``."""
        out = []
        while lo < hi:
            if lo < self.end:
                part = self.batch.slice(lo - self.first, min(hi, self.end) - lo)
                out.append(part)
                lo += part.num_rows
                continue
            batch = next(self.batches, None)
            if batch is None or not batch.num_rows:  # pyarrow stops where the pages do
                raise _bad(
                    self.reader.path, f"row group {self.group}: declares {self.declared:,} rows, holds {self.end:,}"
                )
            self.batch, self.first, self.end = batch, self.end, self.end + batch.num_rows
        return out


class _Rows:
    """Rows of a data set that are read when sliced (``a[start:stop]``)."""

    ndim = 2

    def __init__(self, reader):
        self.reader = reader

    def __len__(self) -> int:
        return len(self.reader)

    def __getitem__(self, rows: slice) -> np.ndarray:
        start, stop, _ = rows.indices(len(self))
        return self._values(self.reader.rows(start, max(start, stop)), start)


class _Numbers(_Rows):
    """``(N, *shape)`` floats from a group of columns."""

    def __init__(self, reader, columns: tuple[str, ...], shape: tuple[int, ...]):
        super().__init__(reader)
        self.columns = columns
        self.shape = (len(reader), *shape)
        self.ndim = 1 + len(shape)

    def _values(self, table, start: int) -> np.ndarray:
        import pyarrow as pa

        cols = []
        for c in self.columns:
            try:
                cols.append(table.column(c).cast(pa.float64()).to_numpy(zero_copy_only=False))
            except pa.ArrowInvalid:  # the only integers a safe cast refuses
                raise _bad(
                    self.reader.path,
                    f"column {c}: an integer beyond 2^53 in rows {start:,}-{start + len(table) - 1:,}, "
                    "which a float cannot hold exactly",
                ) from None
        return np.stack(cols, axis=-1).reshape(len(table), *self.shape[1:])


class _Names(_Rows):
    """``(N,)`` names as text (a null name is the row's index)."""

    ndim = 1

    def _values(self, table, start: int) -> np.ndarray:
        import pyarrow as pa

        column = table.column(NAME_COLUMN).cast(pa.string())
        names = column.to_numpy(zero_copy_only=False)
        nulls = np.flatnonzero(column.is_null().to_numpy(zero_copy_only=False))
        names[nulls] = (start + nulls).astype(str)
        return names.astype(str)
