"""Array data sets in: ``.npz`` of named arrays, ``.npy`` of rows.

Input layouts (see the README):

* ``.npz`` with ``points (N,3,3)``, ``normals (N,3,3)`` and optionally
  ``wrist (N,3)``, ``twist (N,6)`` or ``(6,)``, ``names (N,)``,
  ``joint_positions (N, n_joints)`` (of the hand given with ``--hand``);
* ``.npy`` of shape ``(N,18)`` or ``(N,21)``: per row ``p1 p2 p3 n1 n2 n3``
  (xyz each) and, with 21 columns, one more point whose role
  ``extra_point`` names: the ``wrist``, or the point ``at`` which the
  twists' linear velocity is given.

A ``.npy`` is memory-mapped and read a chunk of rows at a time, so a data
set larger than memory streams with bounded memory; ``.npz`` members are
read whole (numpy cannot map them).  Problems with the file itself are
:class:`~grasptwist.model.InputError` (code ``bad-dataset``);
problems with a row (NaN, a degenerate grasp) are that row's status.
This module only reads: :func:`grasptwist.run.batch.dataset_blocks` runs
the engine over a data set's rows, and :mod:`grasptwist.output.npz` writes
results as arrays.
"""

from __future__ import annotations

import zipfile
from dataclasses import dataclass

import numpy as np

from ..model import GraspFileError

__all__ = ["DATASET_SUFFIXES", "EXTRA_POINT_ROLES", "Dataset", "open_dataset"]

DATASET_SUFFIXES = (".npz", ".npy")
EXTRA_POINT_ROLES = ("wrist", "at")
_NPZ_KEYS = ("points", "normals", "wrist", "twist", "names", "joint_positions")


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
    joint_positions: np.ndarray | None = None  # (N, n_joints): the hand's configuration per row

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
    positions = arrays.get("joint_positions")
    if positions is not None and (positions.ndim != 2 or positions.dtype.kind not in "fiu"):
        raise _bad(
            path, f"joint_positions: expected numbers of shape (N, n_joints), got {positions.dtype} {positions.shape}"
        )
    for key, a in (
        ("joint_positions", positions),
        ("normals", normals),
        ("wrist", wrist),
        ("twist", twist if twist is not None and twist.ndim == 2 else None),
        ("names", names),
    ):
        if a is not None and len(a) != n:
            raise _bad(path, f"{key}: {len(a)} rows, but points has {n}")
    return Dataset(path, points, normals, wrist, None, twist, names, positions)
