"""Run the engine over many (grasp, twist) rows at once.

Front ends hand this module loaded grasps (and loader errors) in file order,
or the arrays of a data set; it stacks the rows into blocks, calls the
engine once per block and hands back :class:`Block` objects (columns of
results for consecutive rows) with the errors in their places.  No math
here: only stacking and slicing.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass, replace

import numpy as np

from ..engine.decompose import (
    OffTangentResult,
    TangentResult,
    contact_velocities,
    decompose_off_tangent,
    decompose_tangent,
)
from ..model import CONTACT_NAMES, Grasp, GraspFileError, Twist

__all__ = ["METHODS", "Block", "resolve", "resolve_arrays", "NO_TWIST", "ZERO_TWIST", "CONTACT_NAMES"]

METHODS = ("both", "off-tangent", "tangent")

#: Error code of a grasp that has no twist to resolve.
NO_TWIST = "no-twist"

#: The twist whose resolution carries just the bases (``basis`` and ``check``).
ZERO_TWIST = Twist(name="0", screw=np.zeros(6), line=None)


@dataclass(frozen=True)
class Block:
    """Consecutive (grasp, twist) rows with every method's results, as columns.

    Per-row labels are lists (or numpy string arrays); ``points`` ...
    ``velocity`` are arrays over the rows.  ``off_tangent`` is None when the method was not asked for;
    rows without a wrist (``has_wrist`` False) carry the status
    ``nonfinite-input`` there and are reported as skipped.
    """

    file: list
    grasp: list
    units: list
    twist_name: list
    contact_names: list
    points: np.ndarray  # (n, 3, 3)
    normals: np.ndarray  # (n, 3, 3) unit
    twist: np.ndarray  # (n, 6)
    has_wrist: np.ndarray  # (n,) bool
    velocity: np.ndarray  # (n, 3, 3)
    off_tangent: OffTangentResult | None
    tangent: TangentResult | None
    method: str

    def __len__(self) -> int:
        return len(self.grasp)

    def part(self, start: int, stop: int) -> Block:
        """Rows ``start:stop`` as a block of their own (views, no copies)."""
        return self.take(slice(start, stop))

    def take(self, rows) -> Block:
        """The rows ``rows`` (a slice, or an array of indices) as a block of their own."""
        cut = {f: _pick(getattr(self, f), rows) for f in _ROW_FIELDS}
        return replace(self, **cut, off_tangent=_take(self.off_tangent, rows), tangent=_take(self.tangent, rows))


_ROW_FIELDS = (
    "file",
    "grasp",
    "units",
    "twist_name",
    "contact_names",
    "points",
    "normals",
    "twist",
    "has_wrist",
    "velocity",
)


def _pick(column, rows):
    if isinstance(column, list) and not isinstance(rows, slice):  # numpy arrays index themselves
        return [column[i] for i in rows]
    return column[rows]


def _take(result, rows):
    return None if result is None else result.row(rows)


def resolve_arrays(
    points, normals, wrist, twist, method="both", *, file="", grasp=None, twist_name=None, units=None, bases=True
) -> Block:
    """One block from arrays of rows (a data set, or stacked grasps).

    ``wrist`` may be None (no row has one) or hold NaN rows for grasps
    without one; ``grasp`` and ``twist_name`` are per-row labels
    (default: the row index and ``"0"``).  ``normals`` should be unit
    already (records show them as given).  ``bases=False`` leaves out the
    basis screws, for outputs that do not show them (npz).
    """
    if method not in METHODS:
        raise ValueError(f"method must be one of {METHODS}, got {method!r}")
    n = len(points)
    has_wrist = np.zeros(n, bool) if wrist is None else np.isfinite(wrist).all(axis=-1)
    off = tan = None
    if method != "off-tangent":
        tan = decompose_tangent(points, normals, twist, bases=bases)
    if method != "tangent":
        off = decompose_off_tangent(points, np.full((n, 3), np.nan) if wrist is None else wrist, twist, bases=bases)
    return Block(
        file=file if isinstance(file, list) else [file] * n,
        grasp=grasp if grasp is not None else [str(i) for i in range(n)],
        units=units if isinstance(units, list) else [units] * n,
        twist_name=twist_name if twist_name is not None else ["0"] * n,
        contact_names=[CONTACT_NAMES] * n,
        points=points,
        normals=normals,
        twist=twist,
        has_wrist=has_wrist,
        velocity=contact_velocities(points, twist),
        off_tangent=off,
        tangent=tan,
        method=method,
    )


def resolve(
    items: Iterable[Grasp | GraspFileError],
    twists: Sequence[Twist] | None = None,
    method: str = "both",
    chunk: int = 2048,
) -> Iterator[Block | GraspFileError]:
    """Resolve every grasp against its twists, in order.

    Parameters
    ----------
    items : grasps and loader errors, in the order to report them.
    twists : twists that replace each grasp's own (the command line's ``--twist``).
    method : ``"both"``, ``"off-tangent"`` or ``"tangent"``.
    chunk : rows per engine call; a chunk is flushed when full or at the end.

    Yields
    ------
    Blocks of consecutive rows and, in their places, the loader's errors and
    an error with code :data:`NO_TWIST` for each grasp without a twist.
    """
    pending: list[Grasp | GraspFileError] = []
    rows = 0
    for item in items:
        pending.append(item)
        if isinstance(item, Grasp):
            rows += len(twists if twists is not None else item.twists)
        if rows >= chunk:
            yield from _flush(pending, twists, method)
            pending, rows = [], 0
    yield from _flush(pending, twists, method)


def _flush(pending, twists, method):
    jobs = [(g, t) for g in pending if isinstance(g, Grasp) for t in (twists if twists is not None else g.twists)]
    block = _stack(jobs, method) if jobs else None
    start = row = 0
    for item in pending:
        own = () if not isinstance(item, Grasp) else twists if twists is not None else item.twists
        if own:
            row += len(own)
            continue
        if row > start:
            yield block.part(start, row)
        start = row
        yield item if not isinstance(item, Grasp) else _no_twist(item)
    if block is not None and row > start:
        yield block.part(start, row) if start else block


def _stack(jobs, method) -> Block:
    grasps = [g for g, _ in jobs]
    nan = np.full(3, np.nan)
    block = resolve_arrays(
        np.stack([g.points for g in grasps]),
        np.stack([g.normals for g in grasps]),
        None
        if all(g.wrist is None for g in grasps)
        else np.stack([nan if g.wrist is None else g.wrist for g in grasps]),
        np.stack([t.screw for _, t in jobs]),
        method,
        file=[g.file for g in grasps],
        grasp=[g.name for g in grasps],
        twist_name=[t.name for _, t in jobs],
        units=[g.units for g in grasps],
    )
    return replace(block, contact_names=[g.contact_names for g in grasps])


def _no_twist(grasp: Grasp) -> GraspFileError:
    return GraspFileError(
        code=NO_TWIST,
        message=(
            f"grasp '{grasp.name}' has no twist to resolve: add a 'twists:' list to the file "
            "or pass --twist W1,W2,W3,V1,V2,V3"
        ),
        file=grasp.file,
        line=grasp.line,
        column=1,
    )
