"""Results as arrays in one ``.npz``, from the blocks' column groups (:func:`columns.arrays`)."""

from __future__ import annotations

import os
import tempfile
import zipfile
from typing import IO

import numpy as np

from .column_sets import TWIST_COLUMNS
from .columns import ColumnSet

__all__ = ["NpzWriter", "SPILL_BYTES"]

#: Result bytes an NpzWriter holds in memory before it spills to temporary files.
SPILL_BYTES = 512 << 20

#: Label columns stored as an index into a table of their distinct values: ``column: (index, table)``.
_INDEXED = {
    "file": ("file_index", "files"),
    "twist_name": ("twist_index", "twist_names"),
    "wrench_name": ("wrench_index", "wrench_names"),
}


class NpzWriter:
    """Results as arrays in one ``.npz``, with bounded memory.

    Arrays over all rows, one per column group that npz stores (see the
    README): ``grasp`` (labels), ``file_index`` into ``files`` and
    ``twist_index`` into ``twist_names`` (each distinct name once),
    ``twist (N,6)``, ``wrist (N,3)`` (NaN rows for grasps without one),
    ``contact_velocity (N,3,3)``, then each result kind's
    (e.g. ``x``, ``y``, ``off_tangent_status``, ``off_tangent_conditioning``)
    and, with a ``hand``, its joint arrays (``joint_rates`` in the order of
    ``joint_names``, ``finger_rank`` ...);
    ``status_legend[k]`` is the name of status ``k``, and status -1 means
    "skipped" (a method not asked for by name that cannot run).  Amplitudes
    are NaN where a kind failed.

    Columns are kept in memory up to ``spill_bytes``, then spilled to
    temporary files; :meth:`close` streams everything into the archive.
    """

    def __init__(
        self,
        out: IO[bytes],
        order: str = "omega-v",
        spill_bytes: int = SPILL_BYTES,
        hand=None,
        columns: ColumnSet = TWIST_COLUMNS,
    ):
        self.out = out
        self.columns = columns  # the arrays of the family's rows
        self.order = order
        self.hand = hand
        self.spill_bytes = spill_bytes
        self.chunks: dict[str, list[np.ndarray]] = {}
        self.spilled: dict[str, IO[bytes]] = {}
        self.widths: dict[str, int] = {}  # string columns: the widest value
        self.kinds: dict[str, tuple] = {}  # dtype and trailing shape of each column
        self.names = {table: {} for _, table in _INDEXED.values()}
        self.held = 0
        self.rows = 0
        self.tmp = None

    def write(self, block) -> None:
        """Append a block's rows."""
        cols = {}
        for name, a in self.columns.arrays(block, self.order, self.hand).items():
            if name in _INDEXED:
                index, table = _INDEXED[name]
                cols[index] = self._index(table, a)
            else:
                cols[name] = a if isinstance(a, np.ndarray) and a.dtype.kind not in "UO" else np.asarray(a, dtype=str)
        for name, a in cols.items():
            a = np.ascontiguousarray(a)
            if a.dtype.kind == "U":
                self.widths[name] = max(self.widths.get(name, 1), a.dtype.itemsize // 4)
            self.kinds.setdefault(name, (a.dtype, a.shape[1:]))
            self.chunks.setdefault(name, []).append(a)
            self.held += a.nbytes
        self.rows += len(block)
        if self.held > self.spill_bytes:
            self._spill()

    def _index(self, table, values):
        """Indices of ``values`` in a growing table of distinct names."""
        values = values.tolist() if isinstance(values, np.ndarray) else values
        seen = self.names[table]
        distinct = dict.fromkeys(values)  # usually one file and one twist name per block
        for v in distinct:
            seen.setdefault(v, len(seen))
        if len(distinct) == 1:
            return np.full(len(values), seen[values[0]], dtype=np.int32)
        return np.fromiter(map(seen.__getitem__, values), dtype=np.int32, count=len(values))

    def _spill(self):
        if self.tmp is None:
            self.tmp = tempfile.TemporaryDirectory(prefix="grasptwist-npz-")
        for name, chunks in self.chunks.items():
            if name not in self.spilled:
                self.spilled[name] = open(os.path.join(self.tmp.name, name), "w+b")  # noqa: SIM115 - closed by close()
            for a in chunks:
                np.save(self.spilled[name], a, allow_pickle=False)
            chunks.clear()
        self.held = 0

    def _parts(self, name):
        fh = self.spilled.get(name)
        if fh is not None:
            end = fh.tell()
            fh.seek(0)
            while fh.tell() < end:
                yield np.load(fh, allow_pickle=False)
        yield from self.chunks[name]

    def close(self) -> None:
        """Write the archive."""
        with zipfile.ZipFile(self.out, "w", zipfile.ZIP_STORED, allowZip64=True) as z:
            for name, (dtype, tail) in self.kinds.items():
                dtype = np.dtype(f"<U{self.widths[name]}") if name in self.widths else dtype
                header = {
                    "descr": np.lib.format.dtype_to_descr(dtype),
                    "fortran_order": False,
                    "shape": (self.rows, *tail),
                }
                with z.open(name + ".npy", "w", force_zip64=True) as member:
                    np.lib.format.write_array_header_2_0(member, header)
                    for a in self._parts(name):
                        member.write(np.ascontiguousarray(a.astype(dtype, copy=False)).data)
            statuses = self.columns.statuses
            legend = [""] * (max(statuses) + 1)  # legend[k] names status k (ForceStatus has gaps)
            for status in statuses:
                legend[status] = status.code
            tables = {k: list(v) for k, v in self.names.items() if v or self.columns.name_tables}
            tables = {"status_legend": legend, **tables}
            if self.hand is not None:
                tables["joint_names"] = list(self.hand.joint_names)
            for name, values in tables.items():
                with z.open(name + ".npy", "w") as member:
                    np.lib.format.write_array(member, np.array(values, dtype=str), allow_pickle=False)
        if self.tmp is not None:
            for fh in self.spilled.values():
                fh.close()
            self.tmp.cleanup()
