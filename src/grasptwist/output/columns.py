"""Result blocks as named flat columns: the one definition CSV, npz (and Parquet) share.

A block's columns are groups (:class:`~grasptwist.results.Column`): first the
rows' own (file, grasp, twist name, ok, error, the twist, the wrist, the
contact velocities), then each result kind's from the registry
(:data:`grasptwist.results.KINDS`), each kind's ending with ``<key>_status``
(npz only) and ``<key>_error`` (CSV only).
:func:`columns` gives them as flat ``(N,)`` arrays named and ordered as the
CSV header (:data:`CSV_COLUMNS`); :func:`arrays` gives the groups whole, as
npz stores them.  Values that do not apply (a kind that failed, was skipped
or not asked for) are masked in the flat columns (``numpy.ma``): CSV writes
them empty, Parquet as nulls.
"""

from __future__ import annotations

from collections.abc import Callable
from enum import IntEnum
from typing import Any, NamedTuple

import numpy as np

from ..engine.degeneracy import Status, status_message
from ..results import CULPRIT, KINDS, STATUS, Column

__all__ = [
    "ColumnSet",
    "ORDERS",
    "in_order",
    "BLOCK_COLUMNS",
    "CSV_COLUMNS",
    "TYPED_COLUMNS",
    "header",
    "typed_header",
    "columns",
    "arrays",
    "error_texts",
    "FORCE_COLUMNS",
    "clearance",
    "FORCE_CSV_COLUMNS",
    "force_columns",
    "force_typed_header",
    "force_arrays",
    "grip_errors",
    "contact_models",
]


class ColumnSet(NamedTuple):
    """A family's rows as columns: the CSV header and lines, Parquet's typed columns, npz's arrays.

    Every function takes the run's ``hand`` (whose joints name columns of
    the twist and path families; the others ignore it).

    Attributes
    ----------
    header : callable
        ``hand -> bytes``: the CSV header line.
    flat : callable
        ``(rows, order, hand, typed=False) -> {name: (N,) array}``: the flat
        columns in header order (``typed``: of ``typed_header``), masked where
        they do not hold.
    arrays : callable
        ``(rows, order, hand) -> {name: (N, ...) array}``: what npz stores.
    error_row : callable
        ``(error record, hand) -> bytes``: the CSV line of an input that failed.
    statuses : IntEnum
        The statuses npz's ``status_legend`` names.
    typed_header : callable or None
        ``hand -> {name: numpy type}``: Parquet's columns (None: no Parquet).
    name_tables : bool
        npz writes its tables of distinct names even when empty.
    """

    header: Callable[[Any], bytes]
    flat: Callable[..., dict]
    arrays: Callable[..., dict]
    error_row: Callable[[dict, Any], bytes]
    statuses: type[IntEnum]
    typed_header: Callable[[Any], dict] | None = None
    name_tables: bool = True


#: Screw orders for output: the paper's ``(omega; v)`` or ``(v; omega)``.
ORDERS = ("omega-v", "v-omega")
_V_OMEGA = [3, 4, 5, 0, 1, 2]


def in_order(a: np.ndarray, order: str) -> np.ndarray:
    """``(..., 6)`` screws in the output order ``order`` (one of :data:`ORDERS`).

    >>> in_order(np.arange(6), "v-omega").tolist()
    [3, 4, 5, 0, 1, 2]
    """
    return a[..., _V_OMEGA] if order == "v-omega" else a


def _block(get):
    return lambda _, block: get(block)


#: The rows' own columns, before every kind's.  npz stores ``file`` and
#: ``twist_name`` as indices into tables of distinct names.
BLOCK_COLUMNS = (
    Column("file", _block(lambda b: b.file), ("file",), dtype="U", only_where_ok=False),
    Column("grasp", _block(lambda b: b.grasp), ("grasp",), dtype="U", only_where_ok=False),
    Column("twist_name", _block(lambda b: b.twist_name), ("twist",), dtype="U", only_where_ok=False),
    Column("ok", _block(lambda b: ~b.failed_rows()), ("ok",), dtype="?", array=False, only_where_ok=False),
    # an input that failed has only this (see records.error_record); rows of a block have none
    Column("error", _block(lambda b: np.full(len(b), "")), ("error",), dtype="U", array=False, only_where_ok=False),
    Column("twist", _block(lambda b: b.twist), tuple(f"twist{i}" for i in range(1, 7)), only_where_ok=False),
    Column("wrist", _block(lambda b: b.wrist), ("c_x", "c_y", "c_z"), only_where_ok=False),
    Column(
        "contact_velocity",
        _block(lambda b: b.velocity),
        tuple(f"v{i}_{a}" for i in range(1, 4) for a in "xyz"),
        only_where_ok=False,
    ),
    SURFACE_DISTANCE := Column(
        "surface_distance",
        _block(lambda b: surface_distance(b)),
        ("surface_distance1", "surface_distance2", "surface_distance3"),
        only_where_ok=False,
    ),
    CLEARANCE := Column("clearance", _block(lambda b: clearance(b)), ("clearance",), only_where_ok=False),
)

#: Columns that hold screws, written in the order asked for.
_SCREWS = {"twist"}

#: Columns with NaN rows where there is no value (a grasp without a wrist, or without an object):
#: npz keeps the NaN, flat columns are empty there.
_OPTIONAL = {"wrist", "surface_distance", "clearance"}


def surface_distance(block) -> np.ndarray:
    """``(N, 3)`` each contact's distance from its grasp's object, NaN rows without one."""
    if block.surface_distance is None:
        return np.full((len(block), 3), np.nan)
    return block.surface_distance


def clearance(block) -> np.ndarray:
    """``(N,)`` each grasp's clearance from its environment, NaN where it has none."""
    if block.clearance is None:
        return np.full(len(block), np.nan)
    return block.clearance


def _status(key: str, block) -> np.ndarray:
    """The engine's status of kind ``key``, -1 where it does not apply or was not computed (skipped)."""
    if key not in block.results:
        return np.full(len(block), -1, np.int8)
    return np.where(block.applies(key), block.value(key, STATUS), -1).astype(np.int8)


def _status_column(key: str, per_hand: bool = False) -> Column:
    """``<key>_status``: the engine's status, -1 where the kind does not apply (skipped)."""
    get = (lambda r, block, hand: _status(key, block)) if per_hand else (lambda r, block: _status(key, block))
    return Column(f"{key}_status", get, dtype="i1", only_where_ok=False, per_hand=per_hand)


def _error_column(key: str, per_hand: bool = False) -> Column:
    name = f"{key}_error"
    if per_hand:
        return Column(name, lambda r, block, hand: error_texts(block, key), (name,), "U", False, False, True)
    return Column(name, lambda r, block: error_texts(block, key), (name,), "U", array=False, only_where_ok=False)


def _groups(hand=None):
    """Every column group with the key of its kind (None for the rows' own); the
    kinds that need a hand (joint columns) only when the run has one."""
    groups = [(None, c) for c in BLOCK_COLUMNS]
    for kind in KINDS:
        if kind.needs and hand is None:
            continue
        per_hand = bool(kind.needs)
        own = (*kind.columns, _status_column(kind.key, per_hand), _error_column(kind.key, per_hand))
        groups += [(kind.key, c) for c in own]
    return groups


_GROUPS = _groups()

#: CSV header without a hand: every flat column, in order; the README documents each.
CSV_COLUMNS = [name for _, c in _GROUPS for name in c.flat]


def header(hand=None) -> list[str]:
    """The CSV header of a run, with the joint columns of its ``hand`` (None: :data:`CSV_COLUMNS`).

    >>> header() == CSV_COLUMNS
    True
    """
    if hand is None:
        return CSV_COLUMNS
    return [name for _, c in _groups(hand) for name in c.names(hand)]


_STATUSES = {f"{kind.key}_status" for kind in KINDS}


def _typed_names(column: Column, hand=None) -> tuple[str, ...]:
    """Flat names of a group in typed outputs: a status (no CSV column) is one column under its own name."""
    return (column.name,) if column.name in _STATUSES else column.names(hand)


def typed_header(hand=None) -> dict[str, str]:
    """Typed flat outputs (Parquet): the CSV's columns of a run (:func:`header`) and each
    kind's ``<key>_status`` (after its conditioning), ``name -> numpy type`` (``U`` text).

    >>> h = typed_header()
    >>> h["ok"], h["tangent_status"], [n for n in h if n not in CSV_COLUMNS] == ["off_tangent_status", "tangent_status"]
    ('?', 'i1', True)
    """
    return {name: c.dtype for _, c in (_GROUPS if hand is None else _groups(hand)) for name in _typed_names(c, hand)}


#: :func:`typed_header` of a run without a hand.
TYPED_COLUMNS = typed_header()


def error_texts(block, key: str) -> np.ndarray:
    """``code: message`` of kind ``key`` where it failed and applies, else empty."""
    texts = np.full(len(block), "", dtype=object)
    if key not in block.results:
        return texts
    status, culprit = block.value(key, STATUS), block.value(key, CULPRIT)
    for i in np.flatnonzero((status != Status.OK) & block.applies(key)):
        s = Status(int(status[i]))
        texts[i] = f"{s.code}: {status_message(s, culprit[i], block.contact_names[i])}"  # a finger is its contact
    return texts


def _values(block, key, column: Column, order: str, hand=None):
    """A group's ``(N, ...)`` values (labels may be a list), or None for a kind not computed."""
    if column.per_hand:  # the run's hand fixes its shape: values (blank) even where not computed
        return column.get(block.results.get(key), block, hand)
    if key is not None and key not in block.results:
        return None
    values = column.get(block.results.get(key), block)
    return in_order(values, order) if column.name in _SCREWS else values


def columns(block, order: str = "omega-v", hand=None, typed: bool = False) -> dict[str, np.ndarray]:
    """The block's flat columns, ``name -> (N,)`` array, in the order of :data:`CSV_COLUMNS`
    (``typed``: of :func:`typed_header`, statuses included).

    Values that do not apply are masked (a :class:`numpy.ma.MaskedArray`):
    every value of a kind not computed, and of a group marked
    ``only_where_ok``, where its kind failed or does not apply.  Flat
    columns of a group are views of its array (no copies).  ``hand``: the
    run's hand, whose joint columns follow (:func:`header`).
    """
    n = len(block)
    out = {}
    for key, column in _GROUPS if hand is None else _groups(hand):
        names = _typed_names(column, hand) if typed else column.names(hand)
        if not names:
            continue
        values = _values(block, key, column, order, hand)
        if values is None:
            blank = np.ma.masked_all((n,), dtype=column.dtype if column.dtype != "U" else object)
            out.update(dict.fromkeys(names, blank))
            continue
        flat = np.asarray(values).reshape(n, -1)
        valid = None
        if key is not None and column.only_where_ok:
            computed = key in block.results
            valid = block.results[key].ok & block.applies(key) if computed else np.zeros(n, bool)
        if column.name in _OPTIONAL:
            valid = np.isfinite(flat).all(axis=1)
        for j, name in enumerate(names):
            out[name] = flat[:, j] if valid is None else np.ma.masked_array(flat[:, j], mask=~valid)
    return out


def arrays(block, order: str = "omega-v", hand=None) -> dict[str, np.ndarray]:
    """The block's column groups that npz stores, ``name -> (N, ...)`` array, for the kinds computed.

    Labels (``file``, ``grasp``, ``twist_name``) may come as lists.  Values are the engine's everywhere (NaN amplitudes where a kind failed;
    statuses say which rows those are).  ``hand``: the run's hand, whose
    joint arrays follow (NaN in rows without it).
    """
    out = {}
    for key, column in _GROUPS if hand is None else _groups(hand):
        if column.array:
            values = _values(block, key, column, order, hand)
            if values is not None:
                out[column.name] = values
    return out


# --------------------------------------------------------------------------
# ``grasptwist forces``: one row per (grasp, wrench) (see run/forces.py).
# Each group: ``(block) -> (N, ...) values`` and, for flat columns, the rows
# where they hold (masked elsewhere).


def _xyz(prefix, suffix=""):
    return tuple(f"{prefix}{i}{suffix}_{a}" for i in range(1, 4) for a in "xyz")


def _r(name):
    return lambda _, b: getattr(b.result, name)


def _manipulated(b):
    return b.result.manipulating_status == 0


def _gripped(b):
    return b.result.grip_status == 0


def _squeezed(b):
    """Rows whose grip has three squeezes: none for collinear contacts, none over soft cones (the grip's ``squeeze``)."""
    return _gripped(b) & ~np.isnan(b.result.squeeze).any(axis=-1)


def contact_models(block) -> np.ndarray:
    """``(N,)`` each row's contact model, ``soft`` where a contact is soft, else ``point`` (the records' ``contact_model``)."""
    return np.where(block.soft_rows(), "soft", "point")


#: The force rows' column groups, CSV order; ``valid(block) -> (N,) bool`` rows where the flat values hold.
FORCE_COLUMNS = (
    (Column("file", _block(lambda b: b.file), ("file",), dtype="U", only_where_ok=False), None),
    (Column("grasp", _block(lambda b: b.grasp), ("grasp",), dtype="U", only_where_ok=False), None),
    (Column("wrench_name", _block(lambda b: np.array([n or "" for n in b.wrench_name], dtype=object)), ("wrench",), dtype="U"), None),
    (Column("ok", _block(lambda b: ~b.failed_rows()), ("ok",), dtype="?", array=False), None),
    (Column("error", _block(lambda b: np.full(len(b), "")), ("error",), dtype="U", array=False), None),
    (Column("wrench", _block(lambda b: b.wrench), ("f_x", "f_y", "f_z", "m_x", "m_y", "m_z")), lambda b: b.has_wrench),
    (Column("friction", _block(lambda b: b.friction), ("mu1", "mu2", "mu3")), lambda b: b.has_friction),
    (SURFACE_DISTANCE, lambda b: ~np.isnan(surface_distance(b)).any(axis=-1)),
    (CLEARANCE, lambda b: ~np.isnan(clearance(b))),
    (Column("manipulating", _r("manipulating"), _xyz("fm")), _manipulated),
    (Column("force", _r("force"), _xyz("f")), _gripped),
    (Column("squeeze", _r("squeeze"), ("squeeze1", "squeeze2", "squeeze3")), _squeezed),
    (Column("normal_force", _r("normal_force"), ("fn1", "fn2", "fn3")), _gripped),
    (Column("tangential_force", _r("tangential_force"), ("ft1", "ft2", "ft3")), _gripped),
    (Column("friction_used", _r("friction_used"), ("friction_used1", "friction_used2", "friction_used3")), _gripped),
    (Column("total_normal_force", _r("total_normal_force"), ("total_normal_force",)), _gripped),
    (Column("manipulating_status", _r("manipulating_status"), dtype="i1"), None),
    (Column("grip_status", _r("grip_status"), dtype="i1"), None),
    (Column("grip_error", _block(lambda b: grip_errors(b)), ("grip_error",), dtype="U", array=False), None),
    (Column("force_closure", _r("force_closure"), ("force_closure",), dtype="?"), lambda b: b.has_friction),
    (Column("closure_friction", _r("closure_friction"), ("closure_friction",)), lambda b: ~np.isnan(b.result.closure_friction)),
    (Column("epsilon", _r("epsilon"), ("epsilon",)), lambda b: ~np.isnan(b.result.epsilon)),
    (Column("contact_model", _block(contact_models), ("contact_model",), dtype="U"), None),
)  # fmt: skip

#: The CSV header of ``grasptwist forces``.
FORCE_CSV_COLUMNS = [name for c, _ in FORCE_COLUMNS for name in c.flat]


def grip_errors(block) -> np.ndarray:
    """``code: message`` where the grip failed, or the manipulating forces did where every contact is a point
    (the contacts' degeneracy; the rows that are not ok, ``failed_rows``)."""
    from ..engine.forces.grasp_map import ForceStatus, force_status_message  # with the first force run

    r = block.result
    texts = np.full(len(block), "", dtype=object)
    for i in np.flatnonzero(block.failed_rows()):
        status, culprit = (
            (r.grip_status[i], r.grip_culprit[i])
            if r.grip_status[i] > 0
            else (r.manipulating_status[i], r.manipulating_culprit[i])
        )
        s = ForceStatus(int(status))
        texts[i] = f"{s.code}: {force_status_message(s, culprit).removeprefix(s.code + ': ')}"
    return texts


_FORCE_STATUSES = ("manipulating_status", "grip_status")


def _force_names(column, typed):
    return (column.name,) if typed and column.name in _FORCE_STATUSES else column.flat


def force_typed_header() -> dict[str, str]:
    """Typed flat outputs of ``forces`` (Parquet): the CSV's columns and the two statuses, ``name -> numpy type``.

    >>> h = force_typed_header()
    >>> h["grip_status"], h["force_closure"], [n for n in h if n not in FORCE_CSV_COLUMNS]
    ('i1', '?', ['manipulating_status', 'grip_status'])
    """
    return {name: c.dtype for c, _ in FORCE_COLUMNS for name in _force_names(c, True)}


def force_columns(block, typed: bool = False) -> dict[str, np.ndarray]:
    """A force block's flat columns, ``name -> (N,)``, in CSV order (``typed``: of
    :func:`force_typed_header`, statuses included); masked where they do not hold."""
    n = len(block)
    out = {}
    for column, valid in FORCE_COLUMNS:
        names = _force_names(column, typed)
        if not names:
            continue
        flat = np.asarray(column.get(None, block)).reshape(n, -1)
        mask = None if valid is None else ~np.asarray(valid(block), bool)
        for j, name in enumerate(names):
            out[name] = flat[:, j] if mask is None else np.ma.masked_array(flat[:, j], mask=mask)
    return out


def force_arrays(block) -> dict[str, np.ndarray]:
    """A force block's arrays as npz stores them (the engine's values, NaN where none)."""
    return {c.name: c.get(None, block) for c, _ in FORCE_COLUMNS if c.array}
