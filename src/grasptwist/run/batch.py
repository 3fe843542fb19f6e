"""Run the engine over many (grasp, twist) rows at once.

Front ends hand this module loaded grasps (and loader errors) in file order,
or the arrays of a data set; it stacks the rows into blocks, calls the
engine once per block for every result kind asked for (the registry,
:data:`grasptwist.results.KINDS`) and hands back :class:`Block` objects
(columns of results for consecutive rows) with the errors in their places.
No math here: only stacking and slicing.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from ..engine.decompose import contact_velocities
from ..engine.degeneracy import Status
from ..engine.judgements import outward_contacts
from ..engine.screws import direction, twist_at
from ..model import CONTACT_NAMES, Grasp, InputError, Twist
from ..results import ALL_METHODS, BY_KEY, KINDS, METHOD_CHOICES, STATUS, Field, ResultKind, selected

if TYPE_CHECKING:  # a data set's type, for its annotation: a grasp file's run never loads it (start-up)
    from ..io.dataset import Dataset

__all__ = [
    "METHODS",
    "Block",
    "resolve",
    "resolve_arrays",
    "with_reasons",
    "dataset_blocks",
    "check_positions",
    "ROWS_PER_BLOCK",
    "NO_TWIST",
    "UNKNOWN_TWIST",
    "ZERO_TWIST",
    "CONTACT_NAMES",
]

#: The ``--method`` choices (from the registry).
METHODS = METHOD_CHOICES

#: Error code of a grasp that has no twist to resolve.
NO_TWIST = "no-twist"

#: Error code of a grasp that has no twist of a name ``--select`` gives.
UNKNOWN_TWIST = "unknown-twist"

#: The twist whose resolution carries just the bases (``basis`` and ``check``).
ZERO_TWIST = Twist(name="0", screw=np.zeros(6), line=None)


#: Key of :meth:`Block.outward`'s verdicts among a block's computed values.
OUTWARD = (None, "outward_contacts")

#: Rows per engine call on a data set: bounded memory, long vectors.
ROWS_PER_BLOCK = 65536


@dataclass(frozen=True, eq=False)  # arrays: equality would fail; a block is compared by identity
class Block:
    """Consecutive (grasp, twist) rows with every result kind's results, as columns.

    Per-row labels are lists (or numpy string arrays); ``points`` ...
    ``velocity`` are arrays over the rows.  ``results`` maps the key of each
    kind computed (in registry order) to its engine result; a kind's rows
    where it cannot run (no wrist) hold its ``missing`` status
    (``no-wrist``): failures when ``method`` named the kind, else skipped
    (see :meth:`applies`).
    """

    file: list
    grasp: list
    units: list
    twist_name: list
    contact_names: list
    points: np.ndarray  # (n, 3, 3)
    normals: np.ndarray  # (n, 3, 3) unit
    twist: np.ndarray  # (n, 6)
    wrist: np.ndarray  # (n, 3), NaN rows where there is none
    has_wrist: np.ndarray  # (n,) bool
    velocity: np.ndarray  # (n, 3, 3)
    results: dict[str, Any]
    hands: list | None = None  # per row its Hand or None; None: no row has one
    bases: bool = True  # False: resolved without the basis screws (fields that need them are left out)
    method: str = ALL_METHODS  # the --method asked for
    friction: np.ndarray | None = None  # (n, 3) the grasps' friction, NaN rows where none; None: no row has one
    torsion: np.ndarray | None = None  # (n, 3) soft contacts' torsional radii (0: a point contact); None: none soft
    center_of_mass: np.ndarray | None = (
        None  # (n, 3) the grasps' centre of mass, NaN rows where none; None: no row has one
    )
    # (n, 3) each contact's distance from the grasp's object, NaN rows without an object; None: no row has one
    surface_distance: np.ndarray | None = None
    grasp_warnings: list | None = None  # per row its grasp's warnings (Grasp.warnings); None: no row has one
    clearance: np.ndarray | None = (
        None  # (n,) its grasp's clearance (Grasp.clearance), NaN where none; None: no row has one
    )
    # field values computed so far, by (kind key, Field); a block cut from another keeps its rows of them
    values: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    def __len__(self) -> int:
        return len(self.grasp)

    @property
    def has_hand(self) -> np.ndarray:
        """Rows whose grasp has a hand."""
        if self.hands is None:
            return np.zeros(len(self), bool)
        return np.array([h is not None for h in self.hands], dtype=bool)

    def kinds(self) -> list[ResultKind]:
        """The kinds computed for this block, in registry order."""
        return [k for k in KINDS if k.key in self.results]

    def applies(self, key: str) -> np.ndarray:
        """Rows where kind ``key`` has a result or a failure: where it can run, and
        everywhere when ``method`` named it; elsewhere it is skipped (null)."""
        kind = BY_KEY[key]
        return np.asarray(kind.applies(self), dtype=bool) | (kind.method and self.method == kind.label)

    def value(self, key: str, f: Field) -> np.ndarray:
        """Field ``f`` of kind ``key`` over the rows, computed once per block."""
        got = self.values.get((key, f))
        if got is None:
            got = self.values[(key, f)] = f.values(self.results[key])
        return got

    def finite_wrist(self) -> np.ndarray:
        """Per row: is there a finite wrist (records write it, else null)?"""
        return np.isfinite(self.wrist).all(axis=-1)

    def outward(self) -> np.ndarray:
        """Per row and contact ``(n, 3)``: does its normal point out of the object, away from the
        centre of mass or else from the other contacts
        (:func:`~grasptwist.engine.judgements.outward_contacts`)?  Judged once per block."""
        got = self.values.get(OUTWARD)
        if got is None:
            got = self.values[OUTWARD] = outward_contacts(self.points, self.normals, self.center_of_mass)
        return got

    def failed_rows(self) -> np.ndarray:
        """Per row: did a kind that applies fail?"""
        failed = np.zeros(len(self), bool)
        for key, r in self.results.items():
            failed |= ~r.ok & self.applies(key)
        return failed

    def failure_codes(self) -> dict[tuple[str, str], int]:
        """Rows per ``(kind label, status code)`` where a kind that applies failed."""
        counts = {}
        for kind in self.kinds():
            status = self.value(kind.key, STATUS)[~self.results[kind.key].ok & self.applies(kind.key)]
            for code, n in zip(*np.unique(status, return_counts=True)):
                counts[(kind.label, Status(int(code)).code)] = int(n)
        return counts

    def part(self, start: int, stop: int) -> Block:
        """Rows ``start:stop`` as a block of their own (views, no copies)."""
        return self.take(slice(start, stop))

    def take(self, rows) -> Block:
        """The rows ``rows`` (a slice, or an array of indices) as a block of their own."""
        cut = {f: _pick(getattr(self, f), rows) for f in _ROW_FIELDS if getattr(self, f) is not None}
        block = replace(self, **cut, results={k: r.row(rows) for k, r in self.results.items()})
        block.values.update({k: v[rows] for k, v in self.values.items()})  # what is known stays known
        return block


_ROW_FIELDS = (
    "file",
    "grasp",
    "units",
    "twist_name",
    "contact_names",
    "points",
    "normals",
    "twist",
    "wrist",
    "has_wrist",
    "velocity",
    "hands",
    "friction",
    "torsion",
    "center_of_mass",
    "surface_distance",
    "grasp_warnings",
    "clearance",
)


def _pick(column, rows):
    if isinstance(column, list) and not isinstance(rows, slice):  # numpy arrays index themselves
        return [column[i] for i in rows]
    return column[rows]


def resolve_arrays(
    points,
    normals,
    wrist,
    twist,
    method="both",
    *,
    file="",
    grasp=None,
    twist_name=None,
    units=None,
    bases=True,
    hands=None,
    joint_screws=None,
    joint_limits=None,
    placement=None,
    has_wrist=None,
) -> Block:
    """One block from arrays of rows (a data set, or stacked grasps).

    ``wrist`` may be None (no row has one) or hold NaN rows for grasps
    without one; ``grasp`` and ``twist_name`` are per-row labels
    (default: the row index and ``"0"``).  ``normals`` should be unit
    already (records show them as given).  ``method`` is one of
    :data:`METHODS`.  ``bases=False`` leaves out the basis screws, for
    outputs that do not show them (npz).  ``hands`` (per row a Hand or None)
    with ``joint_screws (N, 3, J, 6)`` and ``joint_limits (N, 3, J)``
    (:func:`grasptwist.engine.hands.padded`) adds the kinds that need them;
    ``placement`` (:meth:`~grasptwist.engine.placement.Placement.fields`) says where the hands are.
    ``has_wrist`` (per row) says which rows have a wrist; by default those
    whose wrist is finite.
    """
    kinds = selected(method)
    n = len(points)
    if has_wrist is None:
        has_wrist = np.zeros(n, bool) if wrist is None else np.isfinite(wrist).all(axis=-1)
    wrist = np.full((n, 3), np.nan) if wrist is None else wrist
    inputs = {"points": points, "normals": normals, "wrist": wrist, "twist": twist}
    if hands is not None:
        inputs.update(joint_screws=joint_screws, joint_limits=joint_limits, placement=placement)
    results = {}
    for k in kinds:
        if all(name in inputs for name in k.needs):
            results[k.key] = inputs[k.key] = k.compute(inputs, bases)  # later kinds may use earlier ones
    block = Block(
        file=file if isinstance(file, list) else [file] * n,
        grasp=grasp if grasp is not None else [str(i) for i in range(n)],
        units=units if isinstance(units, list) else [units] * n,
        twist_name=twist_name if twist_name is not None else ["0"] * n,
        contact_names=[CONTACT_NAMES] * n,
        points=points,
        normals=normals,
        twist=twist,
        wrist=wrist,
        has_wrist=has_wrist,
        velocity=contact_velocities(points, twist),
        results=results,
        bases=bases,
        method=method,
        hands=hands,
    )
    return with_reasons(block)


def with_reasons(block: Block) -> Block:
    """``block`` with each method's status, in rows where it cannot run, set to
    the reason (its ``missing``, ``no-wrist``) instead of what the engine made
    of the NaN standing in for the missing input; returns ``block``."""
    for k in block.kinds():
        can = np.asarray(k.applies(block), dtype=bool)
        if k.missing is not None and not can.all():
            r = block.results[k.key]
            block.results[k.key] = replace(r, status=np.where(can, r.status, np.int8(k.missing)))
    return block


def resolve(
    items: Iterable[Grasp | InputError],
    twists: Sequence[Twist] | None = None,
    method: str = "both",
    chunk: int = 2048,
    select: Sequence[str] | None = None,
) -> Iterator[Block | InputError]:
    """Resolve every grasp against its twists, in order.

    Parameters
    ----------
    items : grasps and loader errors, in the order to report them.
    twists : twists that replace each grasp's own (the command line's ``--twist``).
    method : one of :data:`METHODS`.
    chunk : rows per engine call; a chunk is flushed when full or at the end.
    select : names of each grasp's own twists to resolve, in this order (``--select``).

    Yields
    ------
    Blocks of consecutive rows and, in their places, the loader's errors, an
    error with code :data:`NO_TWIST` for each grasp without a twist and one
    with code :data:`UNKNOWN_TWIST` for each grasp without a twist ``select`` names.
    """
    pending: list[Grasp | InputError] = []
    rows = 0
    for item in items:
        if select is not None and isinstance(item, Grasp):
            item = selected_twists(item, select)
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
        **_hand_inputs(grasps),
    )
    friction = center = torsion = None
    if any(g.torsion is not None for g in grasps):
        torsion = np.stack([np.zeros(3) if g.torsion is None else g.torsion for g in grasps])
    if any(g.friction is not None for g in grasps):
        friction = np.stack([nan if g.friction is None else g.friction for g in grasps])
    if any(g.center_of_mass is not None for g in grasps):
        center = np.stack([nan if g.center_of_mass is None else g.center_of_mass for g in grasps])
    said = [g.warnings for g in grasps] if any(g.warnings for g in grasps) else None
    return replace(
        block,
        contact_names=[g.contact_names for g in grasps],
        friction=friction,
        torsion=torsion,
        center_of_mass=center,
        surface_distance=surface_distances(grasps),
        grasp_warnings=said,
        clearance=clearances(grasps),
    )


def clearances(grasps) -> np.ndarray | None:
    """``(n,)`` each grasp's clearance from its environment (``Grasp.clearance``), NaN where it has
    none; None when none has one."""
    if all(g.clearance is None for g in grasps):
        return None
    return np.array([np.nan if g.clearance is None else g.clearance for g in grasps], dtype=float)


def surface_distances(grasps) -> np.ndarray | None:
    """``(n, 3)`` each contact's distance from its grasp's object as read (``Grasp.surface_distance``),
    NaN rows for grasps without one; None when none has one."""
    if all(g.object is None for g in grasps):
        return None
    return np.stack([np.full(3, np.nan) if g.surface_distance is None else g.surface_distance for g in grasps])


def _hand_inputs(grasps) -> dict:
    """The hand keywords of :func:`resolve_arrays` for grasps (none when no grasp has a hand)."""
    if all(g.hand is None for g in grasps):
        return {}

    # the hand math loads with the first hand: runs without one never pay for it (bench/startup.py)
    from ..engine import hands
    from ..engine.placement import home_at, place

    width = max(len(f.joints) for g in grasps if g.hand is not None for f in g.hand.fingers)
    made = {}  # each grasp's fingers once, whatever its number of twists
    for g in grasps:
        if g.hand is not None and id(g) not in made:
            states = hands.finger_states(g.hand, g.joint_positions)
            # the loader placed the hand (given and checked, or solved): its tip errors at those positions
            home = home_at(g.hand, g.points, g.normals)
            placement = place(g.hand, g.points, g.normals, g.joint_positions, home=home).fields(width)
            made[id(g)] = (hands.padded(g.hand, [s.screws for s in states], width), placement)
    nan3 = np.full(3, np.nan)
    none = ((np.zeros((3, width, 6)), np.full((3, width), np.nan)), {})
    rows = [made.get(id(g), none) for g in grasps]
    screws, limits = (np.stack(a) for a in zip(*(r[0] for r in rows)))
    empty = {
        "joint_positions": np.full((3, width), np.nan),
        "tip_error": nan3,
        "within_limits": np.zeros(3, bool),
        "tip_center": np.full((3, 3), np.nan),
        "tip_gap": nan3,
        "tip_contact": np.full((3, 3), np.nan),
    }
    placement = {k: np.stack([r[1].get(k, v) for r in rows]) for k, v in empty.items()}
    return {"hands": [g.hand for g in grasps], "joint_screws": screws, "joint_limits": limits, "placement": placement}


def selected_twists(grasp: Grasp, names: Sequence[str]) -> Grasp | InputError:
    """The grasp with its twists named ``names`` only, in that order, or an error with code
    :data:`UNKNOWN_TWIST` naming those it lacks and those it has."""
    own = {t.name: t for t in grasp.twists}
    missing = [n for n in dict.fromkeys(names) if n not in own]
    if not missing:
        return replace(grasp, twists=tuple(own[n] for n in dict.fromkeys(names)))
    has = ", ".join(f"'{n}'" for n in own) or "none"
    return InputError(
        code=UNKNOWN_TWIST,
        message=f"grasp '{grasp.name}' has no twist {', '.join(repr(n) for n in missing)} (its twists: {has})",
        file=grasp.file,
        line=grasp.line,
        column=1,
    )


def _no_twist(grasp: Grasp) -> InputError:
    return InputError(
        code=NO_TWIST,
        message=(
            f"grasp '{grasp.name}' has no twist to resolve: add a 'twists:' list to the file "
            "or pass --twist W1,W2,W3,V1,V2,V3"
        ),
        file=grasp.file,
        line=grasp.line,
        column=1,
    )


def dataset_blocks(
    ds: Dataset,
    twists: Sequence[Twist] | None,
    method: str,
    rows: int = ROWS_PER_BLOCK,
    start: int = 0,
    stop: int | None = None,
    bases: bool = True,
    hand_of_rows=None,
) -> Iterator[Block]:
    """Resolve the grasps ``start:stop`` of a data set, about ``rows`` rows at a time.

    Each grasp is paired with every twist of ``twists`` (the command line's)
    or else with the data set's own twist; with ``at`` points, a twist's
    linear part is the velocity of the row's ``at`` point.  ``bases=False``
    leaves the basis screws out (see :func:`resolve_arrays`).
    ``hand_of_rows`` (a Hand, e.g. from ``--hand``) holds every row: at the
    data set's ``joint_positions``, each row's checked (``contact-off-finger``; a warning
    ``tip-off-contact`` where a tip is off its contact by over 1% of its finger's length),
    or without them at joint positions solved per row by inverse kinematics
    (``unreachable``, ``outside-limits`` where they fail; a hand given inline
    is at the configuration its screws describe), its joint rates are computed
    per row.

    Raises
    ------
    InputError
        ``no-twist`` when neither gives a twist; ``bad-dataset`` when
        ``joint_positions`` does not fit the hand, or comes without one.
    """
    check_positions(ds, hand_of_rows)
    if twists is None and ds.twist is None:
        raise InputError(
            code=NO_TWIST,
            message="the data set has no 'twist' array: pass --twist W1,W2,W3,V1,V2,V3 (repeatable)",
            file=ds.path,
        )
    given = np.stack([t.screw for t in twists]) if twists is not None else None
    k = len(given) if given is not None else 1
    step = max(1, rows // k)
    end = len(ds) if stop is None else min(stop, len(ds))
    for first in range(start, end, step):
        yield _dataset_block(ds, given, twists, method, first, min(end, first + step), k, bases, hand_of_rows)


def check_positions(ds, hand_of_rows) -> None:
    """Raise ``bad-dataset`` when a data set's ``joint_positions`` do not fit ``hand_of_rows``."""
    if ds.joint_positions is None:
        return
    if hand_of_rows is None:
        raise InputError("bad-dataset", "joint_positions: give the hand they belong to with --hand FILE.yaml", ds.path)
    if ds.joint_positions.shape[1] != len(hand_of_rows.joint_names):
        raise InputError(
            "bad-dataset",
            f"joint_positions: {ds.joint_positions.shape[1]} columns, but the hand has "
            f"{len(hand_of_rows.joint_names)} joints ({', '.join(hand_of_rows.joint_names)})",
            ds.path,
        )


def _rows_hand(ds, hand_of_rows, start, stop, rows, points, normals):
    """The hand keywords of :func:`resolve_arrays` for rows ``start:stop`` of a data set, and the
    hand placed on each row's contacts (:func:`~grasptwist.engine.placement.place`: the rows' joint
    positions checked, or solved for when the data set has none)."""
    if hand_of_rows is None:
        return {}, None
    from ..engine import hands

    q = None if ds.joint_positions is None else np.asarray(ds.joint_positions[start:stop], dtype=float)[rows]
    from ..engine.placement import place

    placement = place(hand_of_rows, points, normals, q)
    placed = placement.ik
    states = hands.finger_states(hand_of_rows, placed.positions)
    screws, limits = hands.padded(hand_of_rows, [s.screws for s in states])
    n = len(points)
    return {
        "hands": [hand_of_rows] * n,
        "joint_screws": screws,
        "joint_limits": np.broadcast_to(limits, (n, *limits.shape)),
        "placement": placement.fields(),
    }, placed


def _placed(block, placed):
    """``block`` with its hand status, where a hand is not on its contacts, saying so (that
    finger the culprit): a row's joint rates are only worth what its joint positions are."""
    if placed is None or "hand" not in block.results:
        return block
    r = block.results["hand"]
    off = ~placed.ok
    culprit = placed.culprit
    status = np.take_along_axis(placed.status, np.maximum(culprit, 0)[:, None].astype(np.intp), axis=-1)[:, 0]
    block.results["hand"] = replace(
        r, status=np.where(off, status, r.status).astype(np.int8), culprit=np.where(off, culprit, r.culprit)
    )
    return block


def _dataset_block(ds, given, twists, method, start, stop, k, bases, hand_of_rows=None):
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
        own = ds.twist  # one (6,) for every row, or (N, 6) read a block at a time (npz, Parquet)
        screw = np.broadcast_to(np.asarray(own, dtype=float), (stop - start, 6)) if own.ndim == 1 else own[start:stop]
        names = ["twist"] * (stop - start)
    if ds.at is not None:
        at = column(ds.at)
        screw = twist_at(screw[:, :3], screw[:, 3:], at)
    # labels stay a numpy string array: a million Python strings cost more than the engine
    label = _labels(ds.names[start:stop][rows]) if ds.names is not None else index.astype(str)
    points = column(ds.points)
    # unit normals exactly as the grasp-file loader makes them
    normals = direction(np.asarray(ds.normals[start:stop], dtype=float))[rows]
    hand_inputs, placed = _rows_hand(ds, hand_of_rows, start, stop, rows, points, normals)
    block = resolve_arrays(
        points,
        normals,
        column(ds.wrist),
        np.ascontiguousarray(screw, dtype=float),
        method,
        file=ds.path,
        grasp=label,
        twist_name=names,
        bases=bases,
        # a data set's wrist column gives every row a wrist: NaN in it is a nonfinite-input, not "no wrist"
        has_wrist=None if ds.wrist is None else np.ones(len(index), bool),
        **hand_inputs,
    )
    return _tip_warned(_placed(block, placed), hand_of_rows, placed if ds.joint_positions is not None else None)


def _tip_warned(block, hand, placed):
    """``block`` with a ``tip-off-contact`` warning on each row whose given joint positions leave a
    tip off its contact (within its finger's reach: farther is the row's ``contact-off-finger``)."""
    if placed is None:
        return block
    from ..engine.ik import tip_off_contact
    from .placement import tip_warnings

    error = np.where(placed.status == Status.OK, placed.tip_error, np.nan)
    off = np.flatnonzero(tip_off_contact(error, [f.length for f in hand.fingers]).any(axis=-1))
    if not off.size:
        return block
    said = [()] * len(block)
    for i in off.tolist():
        said[i] = tip_warnings(hand, block.contact_names[i], error[i])
    return replace(block, grasp_warnings=said)


def _labels(names: np.ndarray) -> np.ndarray:
    """A data set's ``names`` as text; bytes that are not UTF-8 are kept as
    surrogates, which every output escapes like an undecodable file name."""
    return np.char.decode(names, "utf-8", "surrogateescape") if names.dtype.kind == "S" else names.astype(str)
