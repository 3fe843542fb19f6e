"""Run the force engine over many (grasp, wrench) rows at once (``grasptwist forces``).

Like :mod:`.batch` for twists: grasps and loader errors come in file order,
their rows are stacked into a :class:`ForceBlock` per group and the engine
is called once per block (:func:`grasptwist.results.compute_forces`); the
errors stay in their places.  A grasp without a wrench gets one row (no
wrench: only its closure).  No math here: only stacking.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass, fields, replace

import numpy as np

from ..engine.judgements import outward_contacts
from ..engine.screws import direction
from ..model import Grasp, GraspFileError, Wrench
from ..results import ForceOptions, ForceResult, compute_forces

__all__ = ["ForceBlock", "force_blocks", "force_arrays", "force_dataset_blocks"]


@dataclass(frozen=True)
class ForceBlock:
    """Consecutive (grasp, wrench) rows and their force results, as columns."""

    file: list
    grasp: list
    units: list
    wrench_name: list  # None where the row has no wrench
    contact_names: list
    points: np.ndarray  # (n, 3, 3)
    normals: np.ndarray  # (n, 3, 3) unit
    wrench: np.ndarray  # (n, 6), NaN rows where there is none
    friction: np.ndarray  # (n, 3), NaN rows where there is none
    result: ForceResult
    center_of_mass: np.ndarray | None = None  # (n, 3), NaN rows where none; None: no row has one

    def __len__(self) -> int:
        return len(self.grasp)

    @property
    def has_wrench(self) -> np.ndarray:
        return np.array([name is not None for name in self.wrench_name], dtype=bool)

    @property
    def has_friction(self) -> np.ndarray:
        return ~np.isnan(self.friction).any(axis=-1)

    def part(self, start: int, stop: int) -> ForceBlock:
        """Rows ``start:stop`` as a block of their own (views)."""
        rows = slice(start, stop)
        cut = {
            f.name: getattr(self, f.name)[rows]
            for f in fields(self)
            if f.name != "result" and getattr(self, f.name) is not None
        }
        r = self.result
        result = replace(r, **{f.name: getattr(r, f.name)[rows] for f in fields(r) if f.name != "safety"})
        return ForceBlock(**cut, result=result)

    def outward(self) -> np.ndarray:
        """Per row and contact ``(n, 3)``: does its normal point out of the object
        (:func:`~grasptwist.engine.judgements.outward_contacts`, as for resolve's blocks)?"""
        return outward_contacts(self.points, self.normals, self.center_of_mass)

    def failed_rows(self) -> np.ndarray:
        """Rows whose manipulating forces or grip failed."""
        return (self.result.manipulating_status > 0) | (self.result.grip_status > 0)


def force_arrays(
    points, normals, wrench, wrench_name, friction, options: ForceOptions, center_of_mass=None, **labels
) -> ForceBlock:
    """One block from arrays of rows (``wrench``, ``friction`` and ``center_of_mass`` NaN rows where
    there is none; ``center_of_mass`` None: no row has one)."""
    n = len(points)
    has_friction = ~np.isnan(friction).any(axis=-1)
    has_wrench = np.array([name is not None for name in wrench_name], dtype=bool)
    result = compute_forces(points, normals, wrench, has_wrench, friction, has_friction, options)
    return ForceBlock(
        file=labels.get("file", [""] * n),
        grasp=labels.get("grasp", [str(i) for i in range(n)]),
        units=labels.get("units", [None] * n),
        wrench_name=list(wrench_name),
        contact_names=labels.get("contact_names", [("1", "2", "3")] * n),
        points=points,
        normals=normals,
        wrench=wrench,
        friction=friction,
        result=result,
        center_of_mass=center_of_mass,
    )


def force_blocks(
    items: Iterable[Grasp | GraspFileError],
    wrenches: Sequence[Wrench] | None,
    friction: float | None,
    options: ForceOptions,
) -> Iterator[ForceBlock | GraspFileError]:
    """Every grasp's rows (one per wrench: ``wrenches``, the command line's, replace
    each grasp's own) in one block per run of consecutive grasps, the loader's
    errors in their places.  ``friction`` (``--friction``) replaces the grasps' own."""
    rows = []
    for item in items:
        if isinstance(item, Grasp):
            own = wrenches if wrenches is not None else item.wrenches
            rows += [(item, w) for w in own] or [(item, None)]
            continue
        if rows:
            yield _stack(rows, friction, options)
            rows = []
        yield item
    if rows:
        yield _stack(rows, friction, options)


def _stack(rows, friction, options) -> ForceBlock:
    grasps = [g for g, _ in rows]
    nan3, nan6 = np.full(3, np.nan), np.full(6, np.nan)
    if friction is not None:
        mu = np.full((len(rows), 3), float(friction))
    else:
        mu = np.stack([nan3 if g.friction is None else g.friction for g in grasps])
    return force_arrays(
        np.stack([g.points for g in grasps]),
        np.stack([g.normals for g in grasps]),
        np.stack([nan6 if w is None else w.wrench for _, w in rows]),
        [None if w is None else w.name for _, w in rows],
        mu,
        options,
        None
        if all(g.center_of_mass is None for g in grasps)
        else np.stack([nan3 if g.center_of_mass is None else g.center_of_mass for g in grasps]),
        file=[g.file for g in grasps],
        grasp=[g.name for g in grasps],
        units=[g.units for g in grasps],
        contact_names=[g.contact_names for g in grasps],
    )


def force_dataset_blocks(
    ds, wrenches: Sequence[Wrench] | None, friction: float | None, options: ForceOptions,
    rows: int = 65536, start: int = 0, stop: int | None = None,
) -> Iterator[ForceBlock]:  # fmt: skip
    """The force rows of the grasps ``start:stop`` of a data set, about ``rows`` rows at a time.

    Each grasp is paired with every wrench of ``wrenches`` (the command
    line's), or else with the data set's own ``wrench`` (one for all rows,
    or one per row), or else with none (its closure only).  ``friction``
    (``--friction``) replaces the data set's (one for all, one per row, or
    one per contact).
    """
    k = len(wrenches) if wrenches else 1
    step = max(1, rows // k)
    end = len(ds) if stop is None else min(stop, len(ds))
    for first in range(start, end, step):
        last = min(end, first + step)
        index = np.repeat(np.arange(first, last), k)  # grasp, then its wrenches
        picked = index - first
        n = len(index)
        if wrenches:
            wrench = np.tile(np.stack([w.wrench for w in wrenches]), (last - first, 1))
            names = [w.name for w in wrenches] * (last - first)
        elif ds.wrench is not None:
            own = np.asarray(ds.wrench if ds.wrench.ndim == 1 else ds.wrench[first:last], dtype=float)
            wrench = np.broadcast_to(own, (n, 6)).copy()
            names = ["wrench"] * n
        else:
            wrench, names = np.full((n, 6), np.nan), [None] * n
        if friction is not None:
            mu = np.full((n, 3), float(friction))
        elif ds.friction is not None:
            own = np.asarray(ds.friction if ds.friction.ndim == 0 else ds.friction[first:last], dtype=float)
            own = own if own.ndim != 1 else own[:, None]
            mu = np.broadcast_to(own if own.ndim == 0 else own[picked], (n, 3)).copy()
        else:
            mu = np.full((n, 3), np.nan)
        _check_rows_friction(ds.path, mu, index, end)
        labels = ds.names[first:last][picked] if ds.names is not None else index
        yield force_arrays(
            np.asarray(ds.points[first:last], dtype=float)[picked],
            _unit(np.asarray(ds.normals[first:last], dtype=float))[picked],
            wrench,
            names,
            mu,
            options,
            file=[ds.path] * n,
            grasp=_texts(labels),
            units=[None] * n,
            contact_names=[("1", "2", "3")] * n,
        )


def _check_rows_friction(path, mu, index, end):
    """A negative friction in a data set's rows: its input error (the rows from its block on,
    to the end of the part being run, get that one error record; other files keep theirs)."""
    bad = (mu < 0).any(axis=1)
    if bad.any():
        row = int(np.argmax(bad))
        raise GraspFileError(
            code="bad-dataset",
            message=f"friction: row {index[row]}: {float(mu[row][mu[row] < 0][0])!r} must be >= 0 "
            f"(rows {index[0]} to {end - 1} not computed)",
            file=path,
        )


def _unit(normals):
    return direction(normals)  # as the grasp-file loader makes them


def _texts(labels) -> list:
    labels = np.asarray(labels)
    if labels.dtype.kind == "S":
        return np.char.decode(labels, "utf-8", "surrogateescape").tolist()
    return labels.astype(str).tolist()
