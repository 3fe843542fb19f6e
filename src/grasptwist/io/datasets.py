"""Array data sets in and out: ``.npz`` of named arrays, ``.npy`` of rows, ``.npz`` results.

Input layouts (see the README):

* ``.npz`` with ``points (N,3,3)``, ``normals (N,3,3)`` and optionally
  ``wrist (N,3)``, ``twist (N,6)`` or ``(6,)``, ``names (N,)``;
* ``.npy`` of shape ``(N,18)`` or ``(N,21)``: per row ``p1 p2 p3 n1 n2 n3``
  (xyz each) and, with 21 columns, one more point whose role
  ``extra_point`` names: the ``wrist``, or the point ``at`` which the
  twists' linear velocity is given.

A ``.npy`` is memory-mapped and read a chunk of rows at a time, so a data
set larger than memory streams with bounded memory; ``.npz`` members are
read whole (numpy cannot map them).  Problems with the file itself are
:class:`~grasptwist.model.InputError` (code ``bad-dataset``);
problems with a row (NaN, a degenerate grasp) are that row's status.
"""

from __future__ import annotations

import os
import tempfile
import zipfile
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from typing import IO

import numpy as np

from ..engine.degeneracy import Status
from ..engine.screws import direction, twist_at
from ..model import GraspFileError, Twist
from ..run.batch import Block, resolve_arrays

__all__ = ["DATASET_SUFFIXES", "EXTRA_POINT_ROLES", "Dataset", "open_dataset", "dataset_blocks", "NpzWriter"]

DATASET_SUFFIXES = (".npz", ".npy")
EXTRA_POINT_ROLES = ("wrist", "at")
_NPZ_KEYS = ("points", "normals", "wrist", "twist", "names")

#: Rows per engine call on a data set: bounded memory, long vectors.
ROWS_PER_BLOCK = 65536

#: Result bytes an NpzWriter holds in memory before it spills to temporary files.
SPILL_BYTES = 512 << 20


@dataclass(frozen=True)
class Dataset:
    """A data set's arrays (``.npy`` columns are memory-mapped views)."""

    path: str
    points: np.ndarray  # (N, 3, 3)
    normals: np.ndarray  # (N, 3, 3)
    wrist: np.ndarray | None  # (N, 3)
    at: np.ndarray | None  # (N, 3): where each twist's linear part is given
    twist: np.ndarray | None  # (N, 6) or (6,)
    names: np.ndarray | None  # (N,)

    def __len__(self) -> int:
        return len(self.points)


def _bad(path, message) -> GraspFileError:
    return GraspFileError(code="bad-dataset", message=message, file=path)


def open_dataset(path: str, extra_point: str = "wrist") -> Dataset:
    """Open a ``.npz`` or ``.npy`` data set and check its layout.

    Raises
    ------
    GraspFileError
        ``read-error`` when it cannot be read, ``bad-dataset`` when its
        arrays do not have the documented names, shapes or a numeric type.
    """
    try:
        if path.endswith(".npy"):
            return _open_npy(path, np.load(path, mmap_mode="r", allow_pickle=False), extra_point)
        with np.load(path, allow_pickle=False) as npz:
            return _open_npz(path, {k: npz[k] for k in npz.files})
    except GraspFileError:
        raise
    except (OSError, ValueError, EOFError, zipfile.BadZipFile) as exc:
        raise GraspFileError(code="read-error", message=f"cannot read as a numpy file: {exc}", file=path) from None


def _numeric(path, name, a, tail):
    if a.dtype.kind not in "fiu":
        raise _bad(path, f"{name}: expected numbers, got dtype {a.dtype}")
    if a.ndim != len(tail) + 1 or a.shape[1:] != tail:
        raise _bad(path, f"{name}: expected shape (N, {', '.join(map(str, tail))}), got {a.shape}")
    return a


def _open_npy(path, a, extra_point):
    if a.ndim != 2 or a.shape[1] not in (18, 21):
        raise _bad(path, f"expected rows of 18 or 21 numbers (p1 p2 p3 n1 n2 n3 [point]), got shape {a.shape}")
    _numeric(path, "rows", a, (a.shape[1],))
    if extra_point == "at" and a.shape[1] != 21:
        raise _bad(path, "--extra-point at needs rows of 21 numbers (the point is the last 3)")
    n = len(a)
    extra = a[:, 18:21] if a.shape[1] == 21 else None
    return Dataset(
        path=path,
        points=a[:, 0:9].reshape(n, 3, 3),
        normals=a[:, 9:18].reshape(n, 3, 3),
        wrist=extra if extra_point == "wrist" else None,
        at=extra if extra_point == "at" else None,
        twist=None,
        names=None,
    )


def _open_npz(path, arrays):
    unknown = sorted(set(arrays) - set(_NPZ_KEYS))
    if unknown:
        raise _bad(path, f"unknown array(s) {', '.join(unknown)}; expected {', '.join(_NPZ_KEYS)}")
    for key in ("points", "normals"):
        if key not in arrays:
            raise _bad(path, f"missing array '{key}' (N, 3, 3)")
    points = _numeric(path, "points", arrays["points"], (3, 3))
    n = len(points)
    normals = _numeric(path, "normals", arrays["normals"], (3, 3))
    wrist = _numeric(path, "wrist", arrays["wrist"], (3,)) if "wrist" in arrays else None
    twist = arrays.get("twist")
    if twist is not None and not (twist.shape == (6,) and twist.dtype.kind in "fiu"):
        _numeric(path, "twist", twist, (6,))
    names = arrays.get("names")
    if names is not None and (names.ndim != 1 or names.dtype.kind not in "USiu"):
        raise _bad(path, f"names: expected a 1-D array of strings or numbers, got {names.dtype} {names.shape}")
    for key, a in (
        ("normals", normals),
        ("wrist", wrist),
        ("twist", twist if twist is not None and twist.ndim == 2 else None),
        ("names", names),
    ):
        if a is not None and len(a) != n:
            raise _bad(path, f"{key}: {len(a)} rows, but points has {n}")
    return Dataset(path, points, normals, wrist, None, twist, names)


def dataset_blocks(
    ds: Dataset,
    twists: Sequence[Twist] | None,
    method: str,
    rows: int | None = None,
    start: int = 0,
    stop: int | None = None,
    bases: bool = True,
) -> Iterator[Block]:
    """Resolve the grasps ``start:stop`` of a data set, a chunk of ``rows`` rows at a time.

    Each grasp is paired with every twist of ``twists`` (the command line's)
    or else with the data set's own twist; with ``at`` points, a twist's
    linear part is the velocity of the row's ``at`` point.  ``bases=False``
    leaves the basis screws out (see :func:`~grasptwist.run.batch.resolve_arrays`).

    Raises
    ------
    GraspFileError
        ``no-twist`` when neither gives a twist.
    """
    if twists is None and ds.twist is None:
        raise GraspFileError(
            code="no-twist",
            message="the data set has no 'twist' array: pass --twist W1,W2,W3,V1,V2,V3 (repeatable)",
            file=ds.path,
        )
    given = np.stack([t.screw for t in twists]) if twists is not None else None
    k = len(given) if given is not None else 1
    step = max(1, (rows or ROWS_PER_BLOCK) // k)
    end = len(ds) if stop is None else min(stop, len(ds))
    for first in range(start, end, step):
        yield _block(ds, given, twists, method, first, min(end, first + step), k, bases)


def _block(ds, given, twists, method, start, stop, k, bases):
    """Rows ``start:stop`` of ``ds``, each paired with its ``k`` twists."""
    index = np.repeat(np.arange(start, stop), k)  # row-major: grasp, then its twists
    # each grasp's row repeated for its twists (no copy when there is one twist)
    rows = slice(None) if k == 1 else index - start

    def column(a):
        return None if a is None else np.asarray(a[start:stop], dtype=float)[rows]

    if given is not None:
        screw = np.tile(given, (stop - start, 1))
        names = [t.name for t in twists] * (stop - start)
    else:
        own = np.asarray(ds.twist, dtype=float)
        screw = np.broadcast_to(own, (stop - start, 6)) if own.ndim == 1 else own[start:stop]
        names = ["twist"] * (stop - start)
    if ds.at is not None:
        at = column(ds.at)
        screw = twist_at(screw[:, :3], screw[:, 3:], at)
    # labels stay a numpy string array: a million Python strings cost more than the engine
    label = ds.names[start:stop][rows].astype(str) if ds.names is not None else index.astype(str)
    return resolve_arrays(
        column(ds.points),
        # unit normals exactly as the grasp-file loader makes them
        direction(np.asarray(ds.normals[start:stop], dtype=float))[rows],
        column(ds.wrist),
        np.ascontiguousarray(screw, dtype=float),
        method,
        file=ds.path,
        grasp=label,
        twist_name=names,
        bases=bases,
    )


class NpzWriter:
    """Results as arrays in one ``.npz``, with bounded memory.

    Arrays over all rows: ``grasp`` (labels), ``file_index`` into ``files``
    and ``twist_index`` into ``twist_names`` (each distinct name once),
    ``twist (N,6)``, ``contact_velocity (N,3,3)``, and per method asked for
    ``x``, ``y``, ``off_tangent_status``, ``off_tangent_conditioning`` /
    ``alpha``, ``beta``, ``normal_velocity``, ``in_tangent_planes``,
    ``tangent_status``, ``tangent_conditioning``; ``status_legend[k]`` is
    the name of status ``k``, and status -1 means "skipped" (no wrist).
    Amplitudes are NaN where a method failed.

    Columns are kept in memory up to :data:`SPILL_BYTES`, then spilled to
    temporary files; :meth:`close` streams everything into the archive.
    """

    def __init__(self, out: IO[bytes], order: str = "omega-v"):
        self.out = out
        self.order = order
        self.chunks: dict[str, list[np.ndarray]] = {}
        self.spilled: dict[str, IO[bytes]] = {}
        self.widths: dict[str, int] = {}  # string columns: the widest value
        self.kinds: dict[str, tuple] = {}  # dtype and trailing shape of each column
        self.names = {"files": {}, "twist_names": {}}
        self.held = 0
        self.rows = 0
        self.tmp = None

    def write(self, block: Block) -> None:
        from ..output.records import _screws  # the one definition of the output order

        cols = {
            "grasp": np.asarray(block.grasp, dtype=str),
            "file_index": self._index("files", block.file),
            "twist_index": self._index("twist_names", block.twist_name),
            "twist": _screws(block.twist, self.order),
            "contact_velocity": block.velocity,
        }
        if block.off_tangent is not None:
            r = block.off_tangent
            cols.update(x=r.x, y=r.y, off_tangent_status=np.where(block.has_wrist, r.status, -1).astype(np.int8))
            cols["off_tangent_conditioning"] = r.conditioning
        if block.tangent is not None:
            r = block.tangent
            cols.update(alpha=r.alpha, beta=r.beta, normal_velocity=r.normal_velocity)
            cols.update(
                in_tangent_planes=r.in_tangent_planes, tangent_status=r.status, tangent_conditioning=r.conditioning
            )
        for name, a in cols.items():
            a = np.ascontiguousarray(a)
            if a.dtype.kind == "U":
                self.widths[name] = max(self.widths.get(name, 1), a.dtype.itemsize // 4)
            self.kinds.setdefault(name, (a.dtype, a.shape[1:]))
            self.chunks.setdefault(name, []).append(a)
            self.held += a.nbytes
        self.rows += len(block)
        if self.held > SPILL_BYTES:
            self._spill()

    def _index(self, table, values):
        """Indices of ``values`` in a growing table of distinct names."""
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
            tables = {"status_legend": [s.code for s in Status], **{k: list(v) for k, v in self.names.items()}}
            for name, values in tables.items():
                with z.open(name + ".npy", "w") as member:
                    np.lib.format.write_array(member, np.array(values, dtype=str), allow_pickle=False)
        if self.tmp is not None:
            for fh in self.spilled.values():
                fh.close()
            self.tmp.cleanup()
