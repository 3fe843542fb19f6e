"""Run the engine over a stream of loaded grasps, many rows per call.

Front ends hand this module grasps (and loader errors) in file order; it
pairs every grasp with its twists, stacks the rows of many grasps into one
array per input, calls the engine once per chunk and hands back one
:class:`Resolution` per (grasp, twist), or the error in its place, in the
order the grasps came.  No math here: only stacking and slicing.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Iterable, Iterator, Sequence

import numpy as np

from .decompose import (
    OffTangentResult,
    TangentResult,
    contact_velocities,
    decompose_off_tangent,
    decompose_tangent,
)
from .grasp_file import Grasp, GraspFileError, Twist

__all__ = ["METHODS", "Resolution", "resolve", "NO_TWIST", "ZERO_TWIST"]

METHODS = ("both", "off-tangent", "tangent")

#: Error code of a grasp that has no twist to resolve.
NO_TWIST = "no-twist"

#: The twist whose resolution carries just the bases (``basis`` and ``check``).
ZERO_TWIST = Twist(name="0", screw=np.zeros(6), line=None)


@dataclass(frozen=True)
class Resolution:
    """One (grasp, twist) row: each method's result for that row, or None.

    ``off_tangent`` is None when the method was not asked for or the grasp
    has no wrist (see ``off_tangent_skipped``).
    """

    grasp: Grasp
    twist: Twist
    velocity: np.ndarray  # (3, 3)
    off_tangent: OffTangentResult | None
    tangent: TangentResult | None
    method: str

    @property
    def off_tangent_skipped(self) -> bool:
        """The off-tangent method was asked for but the grasp has no wrist."""
        return self.method != "tangent" and self.grasp.wrist is None


def resolve(
    items: Iterable[Grasp | GraspFileError],
    twists: Sequence[Twist] | None = None,
    method: str = "both",
    chunk: int = 2048,
) -> Iterator[Resolution | GraspFileError]:
    """Resolve every grasp against its twists, in order.

    Parameters
    ----------
    items : grasps and loader errors, in the order to report them.
    twists : twists that replace each grasp's own (the command line's ``--twist``).
    method : ``"both"``, ``"off-tangent"`` or ``"tangent"``.
    chunk : rows per engine call; a chunk is flushed when full or at the end.

    Yields
    ------
    Resolution per (grasp, twist); a loader's GraspFileError as it came; a
    GraspFileError with code :data:`NO_TWIST` for a grasp with no twist.
    """
    if method not in METHODS:
        raise ValueError(f"method must be one of {METHODS}, got {method!r}")
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
    jobs = []  # (grasp, twist) in order
    for item in pending:
        if isinstance(item, Grasp):
            for twist in twists if twists is not None else item.twists:
                jobs.append((item, twist))
    results = _run(jobs, method) if jobs else None
    row = 0
    for item in pending:
        if not isinstance(item, Grasp):
            yield item
            continue
        own = twists if twists is not None else item.twists
        if not own:
            yield _no_twist(item)
        for twist in own:
            yield _resolution(item, twist, method, results, row)
            row += 1


def _run(jobs, method):
    """The engine on all rows at once; the off-tangent method on rows with a wrist only."""
    points = np.stack([g.points for g, _ in jobs])
    normals = np.stack([g.normals for g, _ in jobs])
    screws = np.stack([t.screw for _, t in jobs])
    out = {"velocity": contact_velocities(points, screws)}
    if method != "off-tangent":
        out["tangent"] = decompose_tangent(points, normals, screws)
        out["tangent"].residual  # once for the whole chunk; rows share it
    if method != "tangent":
        with_wrist = np.array([g.wrist is not None for g, _ in jobs])
        if with_wrist.any():
            wrists = np.stack([g.wrist for g, _ in jobs if g.wrist is not None])
            out["off_tangent"] = decompose_off_tangent(points[with_wrist], wrists, screws[with_wrist])
            out["off_tangent"].residual
            out["off_row"] = np.cumsum(with_wrist) - 1
    return out


def _resolution(grasp, twist, method, results, row):
    off = None
    if "off_tangent" in results and grasp.wrist is not None:
        off = results["off_tangent"].row(results["off_row"][row])
    tan = results["tangent"].row(row) if "tangent" in results else None
    return Resolution(grasp, twist, results["velocity"][row], off, tan, method)


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
