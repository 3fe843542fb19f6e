"""The result kinds a record can hold, described once; every layer iterates over :data:`KINDS`.

A *result kind* (today the two decompositions, ``off_tangent`` and
``tangent``) crosses every layer: the engine computes it, :mod:`grasptwist.run`
stacks it into blocks, :mod:`grasptwist.output` writes its JSON fields and
flat columns, a table renders it.  Its one description therefore sits here,
at the top of the package beside :mod:`grasptwist.model`, below both ``run``
and ``output``, which read it: blocks, records (JSON, JSONL and the JSON
template), ``basis`` and ``check`` records, CSV and npz columns, tables and
the ``--method`` choices all loop over :data:`KINDS`.  This module imports
only the engine; a kind's table renderer is named, not imported, because
rich is loaded only when a table is asked for.

How to add a result kind
------------------------
1. Compute it in the engine: a function on arrays, batched over leading
   axes, returning a result with per-row ``status``, ``culprit`` and
   ``conditioning`` like :mod:`grasptwist.engine.decompose`'s.
2. Describe it here with a :class:`ResultKind` appended to :data:`KINDS`:
   its record key and label, ``compute`` (which block inputs it needs),
   ``applies`` (rows where it can run), for a method ``missing`` (the
   status of the other rows: a warning there, or a failure when the method
   was asked for by name), its :class:`Field` lists for ``resolve``, ``basis`` and
   ``check`` records, and its :class:`Column` groups.
3. Write its table renderer in :mod:`grasptwist.output.table`, the class
   that ``table`` names.

Nothing else in the output layer changes: records, the JSON template, CSV,
npz and the format registry take the new kind from this list.  A new kind
of *row* (not a (grasp, twist) row: a wrench's, a path's sample) is a family
of its own instead: :mod:`grasptwist.run.families` says how to add one.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace
from functools import partial
from typing import Any, NamedTuple

import numpy as np

from .engine import judgements
from .engine.decompose import decompose_off_tangent, decompose_tangent
from .engine.degeneracy import Status
from .engine.screws import klein_table

__all__ = [
    "Field",
    "Column",
    "ResultKind",
    "STATUS",
    "CULPRIT",
    "CONDITIONING",
    "KINDS",
    "BY_KEY",
    "METHOD_CHOICES",
    "ALL_METHODS",
    "joint_column_names",
    "selected",
]

#: How a field's values are written (see :class:`Field`).
FIELD_KINDS = ("numbers", "screws", "flag", "fingers")


@dataclass(frozen=True)
class Field:
    """One field of a kind's JSON object.

    Attributes
    ----------
    name : str
        The JSON key.
    kind : str
        How its values are written: ``numbers`` (floats, nested as the
        array), ``screws`` (``(N, 3, 6)`` 6-vectors, reordered by
        ``--order``), ``flag`` (``true``/``false``) or ``fingers`` (an
        ``(N, c, 3)`` bool mask, written per component as the list of the
        0-based indices of the fingers it holds).
    get : callable or None
        ``result -> (N, ...) array``, an engine output of the result; None
        for the result's attribute ``name``.
    bases : bool
        Needs the basis screws: left out of blocks resolved with
        ``bases=False``.
    """

    name: str
    kind: str = "numbers"
    get: Callable[[Any], np.ndarray] | None = None
    bases: bool = False

    def __post_init__(self):
        if self.kind not in FIELD_KINDS:
            raise ValueError(f"kind must be one of {FIELD_KINDS}, got {self.kind!r}")

    def values(self, result) -> np.ndarray:
        """This field's ``(N, ...)`` values from an engine result."""
        return np.asarray(getattr(result, self.name) if self.get is None else self.get(result))


class Column(NamedTuple):
    """A group of flat columns that one array holds (see :mod:`grasptwist.output.columns`).

    Attributes
    ----------
    name : str
        The array's name (npz stores it under this name).
    get : callable
        ``(result, block) -> (N, ...) array`` for a block where the kind
        was computed.
    flat : tuple of str
        Names of its flat columns (CSV, Parquet), one per value of a row in
        row-major order; empty for an array that only npz stores.
    dtype : str
        numpy type of its values (for columns of a kind not computed).
    array : bool
        npz stores it.
    only_where_ok : bool
        Flat columns are empty where the kind failed or does not apply
        (npz keeps the engine's values there).
    per_hand : bool
        Its values and names depend on the run's hand (the joints): ``get``
        is ``(result or None, block, hand) -> (N, ...) array`` (None: the
        kind was not computed for the block) and ``flat`` may be
        ``hand -> tuple of str``.
    """

    name: str
    get: Callable[..., np.ndarray]
    flat: tuple[str, ...] | Callable[[Any], tuple[str, ...]] = ()
    dtype: str = "f8"
    array: bool = True
    only_where_ok: bool = True
    per_hand: bool = False

    def names(self, hand=None) -> tuple[str, ...]:
        """Its flat columns' names (for the run's ``hand`` when it is per hand)."""
        return self.flat(hand) if callable(self.flat) else self.flat


class ResultKind(NamedTuple):
    """One result kind: how it is computed, named, recorded and shown.

    Attributes
    ----------
    key : str
        Its field in records and blocks, prefix of its columns
        (``off_tangent``).
    label : str
        Its name for people and on the command line (``off-tangent``).
    compute : callable
        ``(inputs, bases) -> result``: the engine call on a block's inputs
        (``points``, ``normals``, ``wrist`` (NaN rows where none),
        ``twist``, ...); ``bases=False`` may leave the basis screws out.
    applies : callable
        ``block -> (N,) bool``: rows where the kind can run; its record
        field is ``null`` elsewhere (see ``missing``).
    fields, basis_fields, check_fields : tuple of Field
        Its object in ``resolve``, ``basis`` and ``check`` records, in order.
    columns : tuple of Column
        Its column groups in CSV order; the output adds ``<key>_status``
        (npz: the engine's status, -1 where the kind does not apply) and
        ``<key>_error`` (CSV: ``code: message`` where it failed) after them.
    table : str
        Name of its renderer class in :mod:`grasptwist.output.table`.
    method : bool
        Offered by ``--method`` (``both`` runs every method).
    needs : tuple of str
        Inputs beyond every block's that it needs (``joint_screws``): it is
        computed only for blocks that have them, and its columns are not in
        the fixed CSV header.
    record : str or None
        Name of a function in :mod:`grasptwist.output.kind_records` that
        writes its objects into a block's records (``(block, records,
        order) -> None``), for an object whose shape depends on the row (a
        hand's joints); None: the object of its ``fields``.
    missing : Status or None
        Why a method cannot run where it does not apply (``no-wrist``):
        its status there.  Asked for by name (``--method``), those rows
        fail with it; under ``both`` the method is skipped there with a
        warning.  None: nothing to say where the kind does not apply (a
        hand's joint rates on a grasp without a hand).
    """

    key: str
    label: str
    compute: Callable[[Mapping[str, np.ndarray], bool], Any]
    applies: Callable[[Any], np.ndarray]
    fields: tuple[Field, ...]
    basis_fields: tuple[Field, ...]
    check_fields: tuple[Field, ...]
    columns: tuple[Column, ...]
    table: str
    method: bool = True
    needs: tuple[str, ...] = ()
    record: str | None = None
    missing: Status | None = None


def _numbered(name: str, n: int = 3) -> tuple[str, ...]:
    return tuple(f"{name}{i}" for i in range(1, n + 1))


def _attribute(name):
    return lambda r, block: getattr(r, name)


def _everywhere(block) -> np.ndarray:
    return np.ones(len(block), bool)


#: Fields every kind's result has: per-row status, the contact it is about, conditioning.
STATUS = Field("status")
CULPRIT = Field("culprit")
CONDITIONING = Field("conditioning")
_RESIDUAL = Field("residual", bases=True)

OFF_TANGENT = ResultKind(
    key="off_tangent",
    label="off-tangent",
    compute=lambda inputs, bases: decompose_off_tangent(
        inputs["points"], inputs["wrist"], inputs["twist"], bases=bases
    ),
    applies=lambda block: block.has_wrist,
    missing=Status.NO_WRIST,
    fields=(
        Field("sigma", "screws", bases=True),
        Field("psi", "screws", bases=True),
        Field("sigma_psi"),
        Field("x"),
        Field("y"),
        CONDITIONING,
        _RESIDUAL,
        Field("moves", "fingers", get=lambda r: judgements.off_tangent_moves(r.x, r.y)),
        Field("about_wrist", "flag", get=lambda r: judgements.about_wrist(r.x, r.y)),
    ),
    basis_fields=(
        Field("sigma", "screws", bases=True),
        Field("psi", "screws", bases=True),
        Field("sigma_psi", get=lambda r: klein_table(r.sigma, r.psi), bases=True),  # [Sigma_i|Psi_j]
        CONDITIONING,
    ),
    check_fields=(CONDITIONING,),
    columns=(
        Column("x", _attribute("x"), _numbered("x")),
        Column("y", _attribute("y"), _numbered("y")),
        Column("off_tangent_conditioning", _attribute("conditioning"), ("off_tangent_conditioning",)),
    ),
    table="OffTangentTable",
)

TANGENT = ResultKind(
    key="tangent",
    label="tangent",
    compute=lambda inputs, bases: decompose_tangent(inputs["points"], inputs["normals"], inputs["twist"], bases=bases),
    applies=_everywhere,
    fields=(
        Field("theta", "screws", bases=True),
        Field("theta_sigma"),
        Field("alpha"),
        Field("beta"),
        Field("normal_velocity"),
        Field("in_tangent_planes", "flag"),
        CONDITIONING,
        _RESIDUAL,
        Field(
            "moves",
            "fingers",
            get=lambda r: judgements.tangent_moves(r.alpha, r.beta, r.normal_velocity, r.in_tangent_planes),
        ),
    ),
    basis_fields=(
        Field("theta", "screws", bases=True),
        Field("sigma", "screws", bases=True),
        Field("theta_sigma", get=lambda r: klein_table(r.theta, r.sigma), bases=True),  # [Theta_i|Sigma_j]
        CONDITIONING,
    ),
    check_fields=(CONDITIONING,),
    columns=(
        Column("alpha", _attribute("alpha"), _numbered("alpha")),
        Column("beta", _attribute("beta"), _numbered("beta")),
        Column("normal_velocity", _attribute("normal_velocity"), _numbered("normal_velocity")),
        Column("in_tangent_planes", _attribute("in_tangent_planes"), ("in_tangent_planes",), dtype="?"),
        Column("tangent_conditioning", _attribute("conditioning"), ("tangent_conditioning",)),
    ),
    table="TangentTable",
)


def _decompositions(inputs) -> dict:
    """The component twists of the methods computed before, for their joint rates, with the
    contacts each component leaves still (in basis order)."""
    from .engine.kinematics import OFF_TANGENT_FIXED, TANGENT_FIXED

    fixed = {"off_tangent": OFF_TANGENT_FIXED, "tangent": TANGENT_FIXED}
    return {key: (np.concatenate(inputs[key].components(), axis=-2), fixed[key]) for key in fixed if key in inputs}


def _hand_joint_rates(inputs, bases):
    # the kinematics are imported with the first hand: runs without one never load them
    from .engine.kinematics import hand_joint_rates

    rates = hand_joint_rates(
        inputs["joint_screws"],
        inputs["points"],
        inputs["twist"],
        inputs["joint_limits"],
        _decompositions(inputs) if bases else None,
    )
    # where the hand is (joint positions, tip errors): records and columns show what the rates are at
    return rates if inputs.get("placement") is None else replace(rates, **inputs["placement"])


def _same_hand(block, hand) -> np.ndarray:
    """Rows whose hand has the run's hand's joints (their joint columns fit)."""
    if block.hands is None:
        return np.zeros(len(block), bool)
    return np.array([h is hand or (h is not None and h.joint_names == hand.joint_names) for h in block.hands])


def _per_joint(name):
    """``(N, total joints)`` of the hand result's padded ``(N, 3, J)`` attribute ``name`` (rates,
    positions): each finger's in ``hand.joint_names`` order; NaN in rows of another hand, or none."""

    def get(r, block, hand):
        out = np.full((len(block), len(hand.joint_names)), np.nan)
        values = None if r is None else getattr(r, name)
        if values is not None:
            same = _same_hand(block, hand)
            for f, finger in enumerate(hand.fingers):
                out[np.ix_(same, finger.joint_index)] = values[same, f, : len(finger.joints)]
        return out

    return get


def _per_finger(name, fill):
    """``(N, 3, ...)`` attribute ``name`` of the hand result (per finger: a value or a vector), ``fill``
    where there is none."""

    def get(r, block, hand):
        values = None if r is None else getattr(r, name)
        if values is None:
            return np.full((len(block), 3, 3) if name in _FINGER_VECTORS else (len(block), 3), fill)
        has = block.has_hand.reshape((-1,) + (1,) * (np.ndim(values) - 1))
        return np.where(has, values, fill)

    return get


#: The hand result's attributes that hold a 3-vector per finger.
_FINGER_VECTORS = ("tip_center", "tip_contact")


def finger_column_names(prefix, axes, hand) -> tuple[str, ...]:
    """Flat column names of a value (``axes`` empty) or a vector per finger of ``hand``:
    ``<prefix>_<finger>[_<axis>]``.

    >>> from grasptwist.model import Finger, Hand
    >>> f = Finger("a", None, (), None, None, None, 1.0, ())
    >>> h = Hand((f, f, f), (), None, None)
    >>> finger_column_names("tip_center", "xy", h)[:2], finger_column_names("tip_gap", "", h)[:1]
    (('tip_center_a_x', 'tip_center_a_y'), ('tip_gap_a',))
    """
    return tuple(f"{prefix}_{f.name}" + (f"_{a}" if a else "") for f in hand.fingers for a in (axes or [""]))


def joint_column_names(prefix, hand) -> tuple[str, ...]:
    """Flat column names of one value per joint of ``hand``: ``<prefix>_<finger>_<joint>``.

    >>> from grasptwist.model import Finger, Hand, Joint
    >>> f = Finger("a", None, (Joint("j", "revolute", None, None, None, None),), None, None, None, 1.0, (0,))
    >>> joint_column_names("q", Hand((f, f, f), ("j",), None, None))[:1]
    ('q_a_j',)
    """
    return tuple(f"{prefix}_{f.name}_{j.name}" for f in hand.fingers for j in f.joints)


def _tip_column(name, axes):
    """A fingertip's value (``axes`` empty) or vector per finger (engine/fingertips.py): shown even
    where the hand failed, as the joint positions are."""
    return Column(
        name, _per_finger(name, np.nan), partial(finger_column_names, name, axes), only_where_ok=False, per_hand=True
    )


HAND = ResultKind(
    key="hand",
    label="hand",
    compute=_hand_joint_rates,
    applies=lambda block: block.has_hand,
    fields=(),
    basis_fields=(),
    check_fields=(),
    columns=(
        Column("joint_rates", _per_joint("rates"), partial(joint_column_names, "qdot"), per_hand=True),
        # the configuration the rates are at (given, solved or tracked): shown even where the hand failed
        Column(
            "joint_positions",
            _per_joint("joint_positions"),
            partial(joint_column_names, "q"),
            only_where_ok=False,
            per_hand=True,
        ),
        Column("tip_error", _per_finger("tip_error", np.nan), per_hand=True),
        *(_tip_column(name, axes) for name, axes in (("tip_center", "xyz"), ("tip_gap", ""), ("tip_contact", "xyz"))),
        Column("within_limits", _per_finger("within_limits", False), dtype="?", per_hand=True),
        Column("finger_rank", _per_finger("finger_rank", -1), dtype="i8", per_hand=True),
        Column("finger_residual", _per_finger("finger_residual", np.nan), per_hand=True),
        Column("finger_conditioning", _per_finger("finger_conditioning", np.nan), per_hand=True),
        Column(
            "velocity_limit_ratio",
            lambda r, block, hand: (
                np.full(len(block), np.nan) if r is None else np.where(block.has_hand, r.velocity_limit_ratio, np.nan)
            ),
            per_hand=True,
        ),
    ),
    table="HandTable",
    method=False,
    needs=("joint_screws",),
    record="hand_objects",
)

#: Every result kind, in the order records hold them (a kind may use those before it).
KINDS: tuple[ResultKind, ...] = (OFF_TANGENT, TANGENT, HAND)

#: The kinds by key.
BY_KEY: dict[str, ResultKind] = {k.key: k for k in KINDS}

#: ``--method`` value that runs every method.
ALL_METHODS = "both"

#: The ``--method`` choices: every method, or one by its label.
METHOD_CHOICES: tuple[str, ...] = (ALL_METHODS, *(k.label for k in KINDS if k.method))


def selected(method: str) -> tuple[ResultKind, ...]:
    """The kinds a ``--method`` value runs (kinds that are not methods always run).

    >>> [k.key for k in selected("tangent")], [k.key for k in selected("both")]
    (['tangent', 'hand'], ['off_tangent', 'tangent', 'hand'])
    """
    if method not in METHOD_CHOICES:
        raise ValueError(f"method must be one of {METHOD_CHOICES}, got {method!r}")
    return tuple(k for k in KINDS if not k.method or method in (ALL_METHODS, k.label))
