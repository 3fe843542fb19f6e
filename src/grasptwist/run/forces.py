"""Run the force engine over many (grasp, wrench) rows at once: the wrench family's compute.

Like :mod:`.batch` for twists: grasps and loader errors come in file order,
their rows are stacked into a :class:`ForceBlock` per group and the engine
is called once per block and kind of row (:func:`compute_forces`); the
errors stay in their places.  A grasp without a wrench gets one row (no
wrench: only its closure).  The family's contribution to ``check`` records,
each grasp's closure, is :func:`closure_fields`.  No math here: only
stacking and routing rows to the engine.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from dataclasses import dataclass, fields, replace

import numpy as np

from ..engine.forces.closure import force_closure
from ..engine.forces.grasp_map import GRIP_NUMBERS, manipulating_forces
from ..engine.forces.grip import grip
from ..engine.judgements import outward_contacts
from ..engine.screws import direction
from ..model import Grasp, InputError
from .batch import clearances, surface_distances
from .options import ForceOptions

__all__ = [
    "ForceResult",
    "compute_forces",
    "closure_fields",
    "ForceBlock",
    "force_blocks",
    "force_arrays",
    "force_dataset_blocks",
]


@dataclass(frozen=True)
class ForceResult:
    """The force side of ``N`` rows, each array over the rows.

    ``manipulating_status`` is -1 where the row has no wrench, ``grip_status``
    -1 where it has no wrench or no friction; their numbers are NaN there and
    where they failed.  ``closure_friction`` is NaN where no friction gives
    closure, ``force_closure`` and ``epsilon`` are meaningful only where the
    row has a friction (``epsilon``: and quality was asked for), and are judged
    with ``friction / safety``, the friction the grip may use.
    """

    manipulating: np.ndarray  # (N, 3, 3)
    manipulating_status: np.ndarray  # (N,) int8
    manipulating_culprit: np.ndarray
    force: np.ndarray  # (N, 3, 3)
    squeeze: np.ndarray  # (N, 3)
    normal_force: np.ndarray
    tangential_force: np.ndarray
    friction_used: np.ndarray
    total_normal_force: np.ndarray  # (N,)
    grip_status: np.ndarray
    grip_culprit: np.ndarray
    dual: np.ndarray  # (N, 6) the grip's certificate of optimality (NaN where it failed)
    gap: np.ndarray  # (N,)
    certificate: np.ndarray  # (N, 6) where no grip exists: the Farkas direction (else NaN)
    torsion: np.ndarray  # (N, 3) the grip's torsion about each normal (0: point contacts; NaN where it failed)
    closure_friction: np.ndarray
    force_closure: np.ndarray  # (N,) bool
    epsilon: np.ndarray
    closure_status: np.ndarray
    closure_culprit: np.ndarray
    safety: float
    contact_model: np.ndarray | None = None  # (N,) str: "soft" where a contact is soft, else "point"; None: all point


def compute_forces(
    points, normals, wrench, has_wrench, friction, has_friction, options: ForceOptions, torsion=None
) -> ForceResult:
    """The engine's force results for ``N`` rows (NaN wrench / friction rows where there is none).

    The engine is called once per kind of row (with and without a wrench, a
    friction), never once per row.  ``torsion (N, 3)``: the contacts' torsional radii (grasp
    files' ``model: soft``); the options' ``torsion`` (``--torsion``) replaces them; None: point contacts.
    """
    if options.torsion is not None:  # --contact: every contact soft, or every one a point (POINT_CONTACTS)
        torsion = np.full((len(points), 3), float(options.torsion)) if options.torsion else None
    n = len(points)
    out = {
        "manipulating": np.full((n, 3, 3), np.nan),
        "manipulating_status": np.full(n, -1, np.int8),
        "manipulating_culprit": np.full(n, -1, np.int8),
        "force": np.full((n, 3, 3), np.nan),
        "squeeze": np.full((n, 3), np.nan),
        "normal_force": np.full((n, 3), np.nan),
        "tangential_force": np.full((n, 3), np.nan),
        "friction_used": np.full((n, 3), np.nan),
        "total_normal_force": np.full(n, np.nan),
        "grip_status": np.full(n, -1, np.int8),
        "grip_culprit": np.full(n, -1, np.int8),
        "dual": np.full((n, 6), np.nan),
        "gap": np.full(n, np.nan),
        "certificate": np.full((n, 6), np.nan),
        "torsion": np.full((n, 3), np.nan),
        "closure_friction": np.full(n, np.nan),
        "force_closure": np.zeros(n, bool),
        "epsilon": np.full(n, np.nan),
        "closure_status": np.zeros(n, np.int8),
        "closure_culprit": np.full(n, -1, np.int8),
    }
    w = np.flatnonzero(has_wrench)
    if w.size:
        m = manipulating_forces(points[w], wrench[w])
        out["manipulating"][w], out["manipulating_status"][w], out["manipulating_culprit"][w] = (
            m.force,
            m.status,
            m.culprit,
        )
    g = np.flatnonzero(has_wrench & has_friction)
    if g.size:
        e = None if torsion is None else torsion[g]
        r = grip(points[g], normals[g], wrench[g], friction[g], safety=options.safety, torsion=e)
        for name in (*GRIP_NUMBERS, "certificate"):
            out[name][g] = getattr(r, name)
        out["torsion"][g] = np.where(r.ok[:, None], 0.0, np.nan) if r.torsion is None else r.torsion
        out["grip_status"][g], out["grip_culprit"][g] = r.status, r.culprit
    # closure and epsilon with the friction the forces may use, as the grip's (issue 31)
    usable = None if friction is None else friction / options.safety
    for rows, mu in ((np.flatnonzero(has_friction), usable), (np.flatnonzero(~has_friction), None)):
        if not rows.size:
            continue
        quality = options.quality and mu is not None
        c = force_closure(
            points[rows],
            normals[rows],
            None if mu is None else mu[rows],
            torsion=None if torsion is None else torsion[rows],
            quality=quality,
            cone_edges=options.cone_edges,
        )
        out["closure_friction"][rows], out["closure_status"][rows], out["closure_culprit"][rows] = (
            c.closure_friction,
            c.status,
            c.culprit,
        )
        if mu is not None:
            out["force_closure"][rows] = c.force_closure
        if quality:
            out["epsilon"][rows] = c.epsilon
    model = None if torsion is None else np.where((torsion > 0).any(axis=1), "soft", "point")
    return ForceResult(safety=float(options.safety), contact_model=model, **out)


def closure_fields(block, torsion=None) -> list[dict]:
    """The wrench family's contribution to ``check`` records: per row of a twist block its
    ``closure_friction`` (the least friction for force closure; None: none does) and, where the
    grasp gives a friction, ``force_closure`` with it.  With soft contacts (the grasps' ``model: soft``,
    or ``torsion``, ``--contact soft --torsion E``, for every contact) also each row's ``contact_model``."""
    n = len(block)
    friction = block.friction
    has = np.zeros(n, bool) if friction is None else ~np.isnan(friction).any(axis=-1)
    result = compute_forces(
        block.points,
        block.normals,
        np.full((n, 6), np.nan),
        np.zeros(n, bool),
        friction,
        has,
        ForceOptions(torsion=torsion),
        getattr(block, "torsion", None),  # a twist block's; a block of another family has no soft contacts
    )
    least = result.closure_friction.tolist()
    verdict = result.force_closure.tolist()
    model = [{}] * n if result.contact_model is None else [{"contact_model": m} for m in result.contact_model.tolist()]
    return [
        {"closure_friction": None if least[i] != least[i] else least[i]}
        | ({"force_closure": verdict[i]} if has[i] else {})
        | model[i]
        for i in range(n)
    ]


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
    surface_distance: np.ndarray | None = None  # (n, 3), as resolve's Block (run/batch.py's surface_distances)
    grasp_warnings: list | None = None  # per row its grasp's warnings (Grasp.warnings), as resolve's Block
    clearance: np.ndarray | None = None  # (n,), as resolve's Block (run/batch.py's clearances)

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
        result = replace(
            r,
            **{
                f.name: getattr(r, f.name)[rows]
                for f in fields(r)
                if f.name != "safety" and getattr(r, f.name) is not None
            },
        )
        return ForceBlock(**cut, result=result)

    def outward(self) -> np.ndarray:
        """Per row and contact ``(n, 3)``: does its normal point out of the object
        (:func:`~grasptwist.engine.judgements.outward_contacts`, as for resolve's blocks)?"""
        return outward_contacts(self.points, self.normals, self.center_of_mass)

    def failed_rows(self) -> np.ndarray:
        """Rows whose grip failed, or whose manipulating forces did where every contact is a point
        (with a soft contact the grip answers; the point contacts' ``G^+ w`` is a warning: :meth:`soft_rows`)."""
        r = self.result
        return ((r.manipulating_status > 0) & ~self.soft_rows()) | (r.grip_status > 0)

    def soft_rows(self) -> np.ndarray:
        """Rows with a soft contact (``contact_model`` ``soft``), ``(N,)`` bool."""
        model = self.result.contact_model
        return np.zeros(len(self.points), bool) if model is None else model == "soft"


def force_arrays(
    points, normals, wrench, wrench_name, friction, options: ForceOptions, center_of_mass=None, torsion=None, **labels
) -> ForceBlock:
    """One block from arrays of rows (``wrench``, ``friction`` and ``center_of_mass`` NaN rows where
    there is none; ``center_of_mass`` None: no row has one)."""
    n = len(points)
    has_friction = ~np.isnan(friction).any(axis=-1)
    has_wrench = np.array([name is not None for name in wrench_name], dtype=bool)
    result = compute_forces(points, normals, wrench, has_wrench, friction, has_friction, options, torsion)
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


def force_blocks(items: Iterable[Grasp | InputError], options: ForceOptions) -> Iterator[ForceBlock | InputError]:
    """Every grasp's rows (one per wrench: the options' ``wrenches``, the command line's, replace
    each grasp's own) in one block per run of consecutive grasps, the loader's errors in their
    places.  The options' ``friction`` (``--friction``) replaces the grasps' own."""
    rows = []
    for item in items:
        if isinstance(item, Grasp):
            own = options.wrenches if options.wrenches is not None else item.wrenches
            rows += [(item, w) for w in own] or [(item, None)]
            continue
        if rows:
            yield _stack(rows, options)
            rows = []
        yield item
    if rows:
        yield _stack(rows, options)


def _stack(rows, options) -> ForceBlock:
    grasps = [g for g, _ in rows]
    nan3, nan6 = np.full(3, np.nan), np.full(6, np.nan)
    if options.friction is not None:
        mu = np.full((len(rows), 3), float(options.friction))
    else:
        mu = np.stack([nan3 if g.friction is None else g.friction for g in grasps])
    block = force_arrays(
        np.stack([g.points for g in grasps]),
        np.stack([g.normals for g in grasps]),
        np.stack([nan6 if w is None else w.wrench for _, w in rows]),
        [None if w is None else w.name for _, w in rows],
        mu,
        options,
        None
        if all(g.center_of_mass is None for g in grasps)
        else np.stack([nan3 if g.center_of_mass is None else g.center_of_mass for g in grasps]),
        None
        if all(g.torsion is None for g in grasps)
        else np.stack([g.torsion if g.torsion is not None else np.zeros(3) for g in grasps]),
        file=[g.file for g in grasps],
        grasp=[g.name for g in grasps],
        units=[g.units for g in grasps],
        contact_names=[g.contact_names for g in grasps],
    )
    said = [g.warnings for g in grasps] if any(g.warnings for g in grasps) else None
    return replace(block, surface_distance=surface_distances(grasps), grasp_warnings=said, clearance=clearances(grasps))


def force_dataset_blocks(
    ds, options: ForceOptions, rows: int = 65536, start: int = 0, stop: int | None = None
) -> Iterator[ForceBlock]:
    """The force rows of the grasps ``start:stop`` of a data set, about ``rows`` rows at a time.

    Each grasp is paired with every wrench of the options' ``wrenches`` (the
    command line's), or else with the data set's own ``wrench`` (one for all
    rows, or one per row), or else with none (its closure only).  The
    options' ``friction`` (``--friction``) replaces the data set's (one for
    all, one per row, or one per contact).
    """
    wrenches, friction = options.wrenches, options.friction
    k = options.rows_per_grasp()
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
        negative = (mu < 0).any(axis=1)
        refused = [
            InputError("invalid-friction", _negative(index[r], mu[r]), ds.path) for r in np.flatnonzero(negative)
        ]
        mu[negative] = np.nan  # computed as rows without a friction, then cut out
        labels = ds.names[first:last][picked] if ds.names is not None else index
        block = force_arrays(
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
        yield from _cut(block, negative, refused)


def _negative(row, mu) -> str:
    """What is wrong with a data set's ``row`` whose friction ``mu`` (3,) has a negative value."""
    return f"friction: row {row}: {float(mu[mu < 0][0])!r} must be >= 0"


def _cut(block, refused_rows, errors):
    """``block`` without its ``refused_rows``, each run of them replaced by its grasp's error
    (``errors``, one a refused row: a grasp's rows, one a wrench, share its friction), in order."""
    start = 0
    for k, row in enumerate(np.flatnonzero(refused_rows)):
        if row > start:
            yield block.part(start, row)
        if row == 0 or not refused_rows[row - 1] or block.grasp[row] != block.grasp[row - 1]:
            yield errors[k]
        start = row + 1
    if start < len(block):
        yield block.part(start, len(block)) if start else block


def _unit(normals):
    return direction(normals)  # as the grasp-file loader makes them


def _texts(labels) -> list:
    labels = np.asarray(labels)
    if labels.dtype.kind == "S":
        return np.char.decode(labels, "utf-8", "surrogateescape").tolist()
    return labels.astype(str).tolist()
