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
   ``applies`` (rows where it can run) with ``missing`` (the status of the
   other rows: a warning there, or a failure when the kind was asked for
   by name), its :class:`Field` lists for ``resolve``, ``basis`` and
   ``check`` records, and its :class:`Column` groups.
3. Write its table renderer in :mod:`grasptwist.output.table`, the class
   that ``table`` names.

Nothing else in the output layer changes: records, the JSON template, CSV,
npz and the format registry take the new kind from this list.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

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


@dataclass(frozen=True)
class Column:
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
    """

    name: str
    get: Callable[[Any, Any], np.ndarray]
    flat: tuple[str, ...] = ()
    dtype: str = "f8"
    array: bool = True
    only_where_ok: bool = True


@dataclass(frozen=True)
class ResultKind:
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
        ``block -> (N,) bool``: rows where the kind can run.  Elsewhere its
        status is ``missing``: asked for by name (``--method``), the row
        fails with it; under ``both`` the kind is skipped there (its record
        field is ``null``) with a warning.
    missing : Status
        Why the kind cannot run where it does not apply.
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
    missing: Status = Status.NONFINITE_INPUT


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

#: Every result kind, in the order records hold them.
KINDS: tuple[ResultKind, ...] = (OFF_TANGENT, TANGENT)

#: The kinds by key.
BY_KEY: dict[str, ResultKind] = {k.key: k for k in KINDS}

#: ``--method`` value that runs every method.
ALL_METHODS = "both"

#: The ``--method`` choices: every method, or one by its label.
METHOD_CHOICES: tuple[str, ...] = (ALL_METHODS, *(k.label for k in KINDS if k.method))


def selected(method: str) -> tuple[ResultKind, ...]:
    """The kinds a ``--method`` value runs (kinds that are not methods always run).

    >>> [k.key for k in selected("tangent")], [k.key for k in selected("both")]
    (['tangent'], ['off_tangent', 'tangent'])
    """
    if method not in METHOD_CHOICES:
        raise ValueError(f"method must be one of {METHOD_CHOICES}, got {method!r}")
    return tuple(k for k in KINDS if not k.method or method in (ALL_METHODS, k.label))
