"""A data set's arrays, whatever file they come from (:mod:`.datasets` opens ``.npz`` and
``.npy``, :mod:`.parquet` ``.parquet``; both build this)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Dataset"]


@dataclass(frozen=True)
class Dataset:
    """A data set's arrays: ``.npy`` columns are memory-mapped views, ``.npz``
    members :class:`Member` objects, Parquet columns read their row groups;
    all are read by slicing rows."""

    path: str
    points: np.ndarray  # (N, 3, 3)
    normals: np.ndarray  # (N, 3, 3)
    wrist: np.ndarray | None  # (N, 3)
    at: np.ndarray | None  # (N, 3): where each twist's linear part is given
    twist: np.ndarray | None  # (N, 6) or (6,)
    names: np.ndarray | None  # (N,)
    joint_positions: np.ndarray | None = None  # (N, n_joints): the hand's configuration per row
    wrench: np.ndarray | None = None  # (N, 6) or (6,): (force; moment about the origin), grasptwist forces
    friction: np.ndarray | None = None  # (), (N,) or (N, 3): mu per row or per contact, grasptwist forces

    def __len__(self) -> int:
        return len(self.points)
