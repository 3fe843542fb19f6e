"""Array data sets in: ``.npz`` of named arrays, ``.npy`` of rows, ``.parquet`` of named columns.

Input layouts (see the README):

* ``.npz`` with ``points (N,3,3)``, ``normals (N,3,3)`` and optionally
  ``wrist (N,3)``, ``twist (N,6)`` or ``(6,)``, ``names (N,)``,
  ``joint_positions (N, n_joints)`` (of the hand given with ``--hand``);
* ``.npy`` of shape ``(N,18)`` or ``(N,21)``: per row ``p1 p2 p3 n1 n2 n3``
  (xyz each) and, with 21 columns, one more point whose role
  ``extra_point`` names: the ``wrist``, or the point ``at`` which the
  twists' linear velocity is given;
* ``.parquet`` of flat columns (:mod:`grasptwist.io.parquet`).

A ``.npy`` is memory-mapped and read a chunk of rows at a time, so a data
set larger than memory streams with bounded memory.  An ``.npz`` member is
read the same way, a block of rows at a time (:class:`Member`), after the
shapes, types and sizes it declares (zip directory and ``.npy`` header) have
been checked: a zip bomb is refused before a byte is inflated
(:data:`MAX_INFLATION`).  Problems with the file itself are
:class:`~grasptwist.model.InputError` (code ``bad-dataset``);
problems with a row (NaN, a degenerate grasp) are that row's status.
This module only reads: :func:`grasptwist.run.batch.dataset_blocks` runs
the engine over a data set's rows, and :mod:`grasptwist.output.npz` writes
results as arrays.
"""

from __future__ import annotations

import os
import zlib
from math import prod
from typing import TYPE_CHECKING

import numpy as np

from ..model import InputError
from .limits import MAX_INFLATION, check_inflation

if TYPE_CHECKING:  # zipfile and Dataset are imported where a data set is read (see open_dataset)
    import zipfile

    from .dataset import Dataset

__all__ = ["DATASET_SUFFIXES", "EXTRA_POINT_ROLES", "Member", "open_dataset", "MAX_INFLATION"]

DATASET_SUFFIXES = (".npz", ".npy", ".parquet")
EXTRA_POINT_ROLES = ("wrist", "at")
_NPZ_KEYS = ("points", "normals", "wrist", "twist", "names", "joint_positions", "wrench", "friction")


def _bad(path, message) -> InputError:
    return InputError(code="bad-dataset", message=message, file=path)


def open_dataset(path: str, extra_point: str = "wrist") -> Dataset:
    """Open a ``.npz``, ``.npy`` or ``.parquet`` data set and check its layout.

    Raises
    ------
    InputError
        ``read-error`` when it cannot be read, ``bad-dataset`` when its
        arrays do not have the documented names, shapes or a numeric type.
    """
    if path.endswith(".parquet"):
        from .parquet import open_parquet  # only when a Parquet file is read (its docstring)

        return open_parquet(path)
    import zipfile  # only when an .npz is read: it costs every other run's start-up 11 million instructions

    try:
        if path.endswith(".npy"):
            return _open_npy(path, _npy(path), extra_point)
        with zipfile.ZipFile(path) as zf:
            members = {}
            for info in zf.infolist():
                key = info.filename.removesuffix(".npy")
                # unknown members are reported by name, unread
                members[key] = Member.declared(path, zf, info, key) if key in _NPZ_KEYS else None
        return _open_npz(path, members)
    except InputError:
        raise
    # zipfile: RuntimeError for an encrypted member, NotImplementedError for an unknown compression
    except (OSError, ValueError, EOFError, zipfile.BadZipFile, NotImplementedError, RuntimeError) as exc:
        raise InputError(code="read-error", message=f"cannot read as a numpy file: {exc}", file=path) from None


_NPY_MAGIC = b"\x93NUMPY"


def _npy(path):
    """The array of a ``.npy`` file, memory-mapped; anything else (numpy would open an ``.npz``
    named ``.npy`` as an archive) is ``bad-dataset``."""
    with open(path, "rb") as f:
        start = f.read(len(_NPY_MAGIC))
    if start != _NPY_MAGIC:
        hint = " (it is a zip archive: an .npz named .npy?)" if start.startswith(b"PK") else ""
        raise _bad(path, f"not a .npy file: it does not start with numpy's {_NPY_MAGIC!r}{hint}")
    return np.load(path, mmap_mode="r", allow_pickle=False)


def _numeric(path, name, a, tail):
    if a.dtype.kind not in "fiu":
        raise _bad(path, f"{name}: expected numbers, got dtype {a.dtype}")
    if a.ndim != len(tail) + 1 or a.shape[1:] != tail:
        raise _bad(path, f"{name}: expected shape (N, {', '.join(map(str, tail))}), got {a.shape}")
    return a


def _open_npy(path, a, extra_point):
    from .dataset import Dataset  # only when a data set is read: a grasp file's run never needs it (start-up)

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
    from .dataset import Dataset  # only when a data set is read (see _open_npy)

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
    positions = arrays.get("joint_positions")
    if positions is not None and (positions.ndim != 2 or positions.dtype.kind not in "fiu"):
        raise _bad(
            path, f"joint_positions: expected numbers of shape (N, n_joints), got {positions.dtype} {positions.shape}"
        )
    wrench = arrays.get("wrench")
    if wrench is not None and not (wrench.shape == (6,) and wrench.dtype.kind in "fiu"):
        _numeric(path, "wrench", wrench, (6,))
    friction = arrays.get("friction")
    if friction is not None and (friction.dtype.kind not in "fiu" or friction.shape[1:] not in ((), (3,))):
        raise _bad(
            path, f"friction: expected numbers of shape (), (N,) or (N, 3), got {friction.dtype} {friction.shape}"
        )
    for key, a in (
        ("wrench", wrench if wrench is not None and wrench.ndim == 2 else None),
        ("friction", friction if friction is not None and friction.ndim >= 1 else None),
        ("joint_positions", positions),
        ("normals", normals),
        ("wrist", wrist),
        ("twist", twist if twist is not None and twist.ndim == 2 else None),
        ("names", names),
    ):
        if a is not None and len(a) != n:
            raise _bad(path, f"{key}: {len(a)} rows, but points has {n}")
    return Dataset(path, points, normals, wrist, None, twist, names, positions, wrench, friction)


class Member:
    """One array of an ``.npz``, read a block of rows at a time, never whole.

    Built from what the file declares (:meth:`declared`); ``a[start:stop]``
    inflates just those rows.  Each process opens the file for itself (the
    workers of a parallel run are forked, and must not share a file offset);
    reading forward, as a run does, inflates each byte once per process.
    """

    def __init__(self, path: str, name: str, shape: tuple, dtype: np.dtype, offset: int):
        self.path, self.name, self.shape, self.dtype, self.offset = path, name, shape, dtype, offset
        self.ndim = len(shape)
        self._open = None  # (pid, ZipFile, member file)

    @classmethod
    def declared(cls, path: str, zf: zipfile.ZipFile, info: zipfile.ZipInfo, key: str) -> Member:
        """The member ``info`` of ``zf`` as its ``.npy`` header and the zip directory declare it.

        Raises
        ------
        InputError
            ``bad-dataset`` when it would inflate more than :data:`MAX_INFLATION`
            times, when its header's shape and type do not match its size, or
            when it holds Python objects or is stored column-major.
        """
        try:
            check_inflation(info.file_size, info.compress_size, "zip bomb")
        except ValueError as exc:
            raise _bad(path, f"{key}: {exc}") from None
        with zf.open(info) as f:
            version = np.lib.format.read_magic(f)
            read_header = (
                np.lib.format.read_array_header_1_0 if version == (1, 0) else np.lib.format.read_array_header_2_0
            )
            shape, fortran, dtype = read_header(f)
            offset = f.tell()
        if dtype.hasobject:
            raise _bad(path, f"{key}: holds Python objects ({dtype}), which are never read")
        if fortran and len(shape) > 1:
            raise _bad(path, f"{key}: stored column-major; save it with np.ascontiguousarray")
        size = prod(shape) * dtype.itemsize
        if size != info.file_size - offset:
            raise _bad(
                path,
                f"{key}: shape {shape} of {dtype} needs {size:,} bytes, the member holds {info.file_size - offset:,}",
            )
        return cls(path, info.filename, tuple(shape), dtype, offset)

    def __len__(self) -> int:
        return self.shape[0] if self.shape else 0

    def __getitem__(self, rows: slice) -> np.ndarray:
        """Rows ``rows`` (a slice with step 1), read from the file."""
        start, stop, _ = rows.indices(len(self))
        stop = max(start, stop)
        row = prod(self.shape[1:]) * self.dtype.itemsize
        import zipfile  # loaded by open_dataset already

        try:
            f = self._file()
            f.seek(self.offset + start * row)
            data = f.read((stop - start) * row)
        except (OSError, EOFError, zipfile.BadZipFile, zlib.error) as exc:
            # the archive's checksum is checked only once a member has been read to its end
            raise InputError(
                code="read-error", message=f"{self.name}: {exc} (damaged, or changed while being read)", file=self.path
            ) from None
        return np.frombuffer(data, self.dtype).reshape((stop - start, *self.shape[1:]))

    def __array__(self, dtype=None, copy=None):
        """Every row: only for the members a run reads whole, one ``twist (6,)`` or ``friction ()``."""
        # a 0-d member (one value for every row) is read as one row of its own shape
        whole = self[:] if self.shape else Member(self.path, self.name, (1,), self.dtype, self.offset)[:].reshape(())
        return whole if dtype is None else whole.astype(dtype)

    def _file(self):
        import zipfile  # loaded by open_dataset already

        pid = os.getpid()
        if self._open is None or self._open[0] != pid:
            zf = zipfile.ZipFile(self.path)
            self._open = (pid, zf, zf.open(self.name))
        return self._open[2]
