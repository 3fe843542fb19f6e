"""Records: the JSON contract, and the stderr lines they call for.

A *record* is one (grasp, twist) row as a dict of plain values, exactly the
contract documented in the README.  :func:`records` builds them a block at
a time (arrays are turned into lists once per block, which is what makes a
million records a second-scale job).  Every result kind's object is built
from its fields in the registry (:data:`grasptwist.results.KINDS`); nothing
here computes: every number and verdict comes from the engine.  JSON goes
through orjson: floats at full precision (shortest round-trip form), NaN
never (failed methods carry an ``error`` object instead of numbers).
"""

from __future__ import annotations

import numpy as np
import orjson

from ..engine.degeneracy import (
    CONDITION_WARNING,
    Status,
    conditioning_warning,
    outward_normals_warning,
    skipped_warning,
    status_message,
)
from ..model import InputError
from ..results import CONDITIONING, CULPRIT, KINDS, STATUS, Field
from . import kind_records
from .columns import ORDERS, in_order
from .names import escaped, escaped_each

__all__ = [
    "ORDERS",
    "records",
    "outward_warning",
    "surface_distances",
    "clearances",
    "basis_record",
    "check_record",
    "error_record",
    "diagnostics",
    "failure_codes",
    "talking_rows",
    "json_values",
    "present",
    "dumps",
]


def records(block, order: str = "omega-v") -> list[dict]:
    """The output records of a block's rows (see the README's output contract).

    Built column-wise for speed (this runs for every record of a
    million-grasp data set): numbers stay in numpy, each record holding
    views of contiguous rows, which orjson writes without making a Python
    float of each.  Consumers that need lists call ``.tolist()``.
    """
    warnings = [[] for _ in range(len(block))]
    for i in np.flatnonzero(block.outward().any(axis=-1)):
        warnings[i].append(outward_warning(block, i))
    for i, said in enumerate(block.grasp_warnings or ()):
        warnings[i] += said
    objects = [(k.key, _kind_rows(block, k, order, warnings)) for k in block.kinds() if k.record is None]
    written = [(k.key, _written(k)(block, order, warnings)) for k in block.kinds() if k.record is not None]
    ok = (~block.failed_rows()).tolist()
    out = []
    rows = zip(
        escaped_each(block.file),
        escaped_each(block.grasp),
        block.units,
        escaped_each(block.twist_name),
        _rows(in_order(block.twist, order)),
        _contact_names(block),
        _rows(block.points),
        _rows(block.normals),
        surface_distances(block),
        _wrists(block),
        _rows(block.velocity),
        clearances(block),
    )
    for i, (file, grasp, units, twist_name, screw, names, p, q, d, c, v, e) in enumerate(rows):
        rec = {
            "file": file,
            "grasp": grasp,
            "units": units,
            "twist": {"name": twist_name, "screw": screw},
            "contacts": [
                {"name": names[0], "point": p[0], "normal": q[0], "surface_distance": d[0]},
                {"name": names[1], "point": p[1], "normal": q[1], "surface_distance": d[1]},
                {"name": names[2], "point": p[2], "normal": q[2], "surface_distance": d[2]},
            ],
            "wrist": c,
            "contact_velocity": v,
            "clearance": e,
        }
        for key, rows_of_kind in objects:
            rec[key] = rows_of_kind[i]
        for key, rows_of_kind in written:
            obj, more = rows_of_kind[i]
            if obj is None:  # the row has none: its record is as without the kind
                continue
            rec[key] = obj
            for owner, fields in more.items():  # fields the kind adds to other kinds' objects
                if isinstance(rec.get(owner), dict) and "error" not in rec[owner]:
                    rec[owner].update(fields)
        rec["warnings"] = warnings[i]
        rec["ok"] = ok[i]
        out.append(rec)
    return out


def outward_warning(block, i: int) -> str | None:
    """Row ``i``'s warning naming the contacts whose normals point out of the object
    (:meth:`~grasptwist.run.batch.Block.outward`), or None; a :class:`~grasptwist.run.forces.ForceBlock`
    does too."""
    center = block.center_of_mass is not None and not np.isnan(block.center_of_mass[i]).any()
    return outward_normals_warning(block.outward()[i].tolist(), escaped_each(block.contact_names[i]), center)


def clearances(block) -> list:
    """Each row's ``clearance`` from its grasp's environment, None where it has none."""
    if block.clearance is None:
        return [None] * len(block)
    return [None if e != e else e for e in (block.clearance + 0.0).tolist()]


def surface_distances(block) -> list:
    """Each row's three ``surface_distance`` values, None where the grasp has no object."""
    if block.surface_distance is None:
        return [(None, None, None)] * len(block)
    return [[None if d != d else d for d in row] for row in (block.surface_distance + 0.0).tolist()]


def _contact_names(block) -> list:
    """Each row's contact names, escaped (:func:`~grasptwist.output.names.escaped`)."""
    safe = {names: tuple(escaped_each(names)) for names in set(block.contact_names)}
    return [safe[names] for names in block.contact_names]


def _written(kind):
    """The record writer a kind names (:attr:`~grasptwist.results.ResultKind.record`)."""
    return getattr(kind_records, kind.record)


def _rows(a):
    """Row views of a C-contiguous copy of ``a`` (orjson writes contiguous arrays natively).

    Floats get ``+ 0.0``, which turns ``-0.0`` into ``0.0``: a round-off sign
    on zero means nothing and reads oddly (``jq`` prints ``-0``).
    """
    with np.errstate(invalid="ignore"):  # a signalling NaN from a data set's bytes is no news
        a = np.ascontiguousarray(a + 0.0 if a.dtype.kind == "f" else a)
    return list(a) if a.ndim > 1 else a.tolist()


def _wrists(block) -> list:
    """Per row, the wrist (a row view), or None where there is none or it is not finite."""
    wrists = _rows(block.wrist)
    return [c if has else None for c, has in zip(wrists, block.finite_wrist().tolist())]


def _fingers(mask):
    """Per row of an ``(N, c, 3)`` bool mask: per component, the indices of its fingers.

    Tuples, shared between rows with the same mask (few distinct ones occur).
    """
    n, c, f = mask.shape
    codes = (mask.reshape(n, c * f) @ (1 << np.arange(c * f))).tolist()
    seen = {}
    for code, row in zip(codes, mask):
        if code not in seen:
            seen[code] = tuple(tuple(np.flatnonzero(component).tolist()) for component in row)
    return [seen[code] for code in codes]


def json_values(values: np.ndarray, f: Field, order: str) -> list:
    """Per row, the JSON value of field ``f`` from its ``(N, ...)`` values."""
    if f.kind == "fingers":
        return _fingers(values)
    return _rows(in_order(values, order) if f.kind == "screws" else values)


def present(block, fields):
    """The fields a block can give (those that need bases only when it has them)."""
    return [f for f in fields if block.bases or not f.bases]


def _kind_rows(block, kind, order, warnings):
    """One kind's per-row objects (``error`` objects where it failed, None where
    it was skipped), warnings appended."""
    fields = present(block, kind.fields)
    values = [json_values(block.value(kind.key, f), f, order) for f in fields]
    names = [f.name for f in fields]
    rows = [dict(zip(names, row)) for row in zip(*values)]
    status, applies = block.value(kind.key, STATUS), block.applies(kind.key)
    culprit = block.value(kind.key, CULPRIT)
    for i in np.flatnonzero(status):
        rows[i] = _failure(status[i], culprit[i], block.contact_names[i])
    conditioning = block.value(kind.key, CONDITIONING)
    for i in np.flatnonzero((status == Status.OK) & (conditioning < CONDITION_WARNING) & applies):
        warnings[i].append(conditioning_warning(conditioning[i], kind.label))
    skipped = [skipped_warning(kind.missing, kind.label)] if kind.missing is not None else []
    for i in np.flatnonzero(~applies):
        rows[i] = None
        warnings[i] += skipped
    return rows


def talking_rows(block) -> np.ndarray:
    """Rows whose record has something for stderr: a failed or skipped kind, or a warning."""
    talk = block.outward().any(axis=-1)
    if block.grasp_warnings is not None:
        talk |= np.array([bool(said) for said in block.grasp_warnings])
    for kind in block.kinds():
        ok = block.value(kind.key, STATUS) == Status.OK
        applies = block.applies(kind.key)
        talk |= (~ok | (block.value(kind.key, CONDITIONING) < CONDITION_WARNING)) & applies
        if kind.missing is not None:  # skipped: a warning
            talk |= ~applies
    return talk


def _failure(status, culprit, names):
    status = Status(int(status))
    return {"error": {"code": status.code, "message": status_message(status, culprit, names)}}


def _methods_ok(rec):
    return not any(isinstance(rec.get(k.key), dict) and "error" in rec[k.key] for k in KINDS)


def _grasp_fields(block, i: int) -> dict:
    names = escaped_each(block.contact_names[i])
    distance = surface_distances(block.take([i]))[0]
    return {
        "file": escaped(block.file[i], controls=False),
        "grasp": escaped(block.grasp[i], controls=False),
        "units": block.units[i],
        "contacts": [
            {
                "name": names[c],
                "point": block.points[i, c].tolist(),
                "normal": block.normals[i, c].tolist(),
                "surface_distance": distance[c],
            }
            for c in range(3)
        ],
        "wrist": block.wrist[i].tolist() if np.isfinite(block.wrist[i]).all() else None,
    }


def _row_objects(block, i, fields_of, order, warnings, with_failure=()):
    """Row ``i``'s object of every kind computed, from the fields ``fields_of(kind)``;
    a failed kind's object is its error plus the fields ``with_failure(kind)``."""
    out = {}
    if block.outward()[i].any():
        warnings.append(outward_warning(block, i))
    warnings += block.grasp_warnings[i] if block.grasp_warnings is not None else ()
    for kind in block.kinds():
        key = kind.key
        if kind.record is not None:  # a resolve-only kind (a hand's joint rates)
            continue
        if not block.applies(key)[i]:
            out[key] = None
            if kind.missing is not None:
                warnings.append(skipped_warning(kind.missing, kind.label))
            continue
        status = Status(int(block.value(key, STATUS)[i]))

        def value(f, i=i, key=key):
            v = block.value(key, f)[i]
            if f.kind == "fingers":
                return _fingers(v[None])[0]
            return (in_order(v, order) if f.kind == "screws" else v).tolist()  # as 0.1 wrote them: no + 0.0

        if status != Status.OK:
            extra = {f.name: value(f) for f in with_failure}
            out[key] = {**_failure(status, block.value(key, CULPRIT)[i], block.contact_names[i]), **extra}
            continue
        out[key] = {f.name: value(f) for f in present(block, fields_of(kind))}
        text = conditioning_warning(block.value(key, CONDITIONING)[i], kind.label)
        if text:
            warnings.append(text)
    return out


def basis_record(block, i: int, order: str = "omega-v") -> dict:
    """The bases of row ``i``'s grasp with their Klein products (cf. eq. 18)."""
    warnings = []
    rec = {**_grasp_fields(block, i), **_row_objects(block, i, lambda k: k.basis_fields, order, warnings)}
    rec["warnings"] = warnings
    rec["ok"] = _methods_ok(rec)
    return rec


def check_record(block, i: int, contributed: dict | None = None) -> dict:
    """Validation and degeneracy verdict of row ``i``'s grasp, per kind, then the fields other
    families ``contributed`` to the row (the wrench family's closure: see
    :data:`grasptwist.run.families.COMMANDS`)."""
    warnings = []
    objects = _row_objects(block, i, lambda k: k.check_fields, "omega-v", warnings, with_failure=(CONDITIONING,))
    rec = {"file": escaped(block.file[i], controls=False), "grasp": escaped(block.grasp[i], controls=False), **objects}
    rec.update(contributed or {})
    rec["warnings"] = warnings
    rec["ok"] = _methods_ok(rec)
    return rec


def error_record(err: InputError) -> dict:
    """The record of an input that could not be read, validated or paired with a twist:
    its first problem under ``error``, every problem (that one first) under ``errors``."""
    errors = [
        {"code": p.code, "message": escaped(p.message, controls=False), "line": p.line, "column": p.column}
        for p in err.problems
    ]
    return {"file": escaped(err.file, controls=False), "ok": False, "error": errors[0], "errors": errors}


#: The parts of a ``forces`` record that can fail, as its stderr lines name them.
FORCE_PARTS = ("manipulating", "grip")


def diagnostics(rec: dict) -> tuple[list[str], list[str]]:
    """The stderr lines a record calls for: ``(errors, warnings)``, one line each.

    ``path:line:col: error: code: message`` for an input that failed;
    ``path: grasp 'g'[, twist 't']: error: kind: code: message`` for a
    kind that failed; the same with ``warning:`` for each warning.
    """
    if rec["ok"] and not rec.get("warnings"):
        return [], []
    file = escaped(rec["file"])
    if "error" in rec:
        lines = []
        for err in rec["errors"]:
            where = ":".join(str(x) for x in (file, err["line"], err["column"]) if x is not None)
            lines.append(f"{where}: error: {err['code']}: {escaped(err['message'])}")
        return lines, []
    where = f"{file}: grasp '{escaped(rec['grasp'])}'"
    if "twist" in rec:
        where += f", twist '{escaped(rec['twist']['name'])}'"
    if rec.get("wrench"):  # a forces record
        where += f", wrench '{escaped(rec['wrench']['name'])}'"
    labels = [(k.key, k.label) for k in KINDS] + [(part, part) for part in FORCE_PARTS]
    errors = [
        f"{where}: error: {label}: {m['error']['code']}: {m['error']['message']}"
        for key, label in labels
        if isinstance(m := rec.get(key), dict) and "error" in m
    ]
    return errors, [f"{where}: warning: {w}" for w in rec["warnings"]]


def failure_codes(rec: dict) -> list[tuple[str, str]]:
    """``(kind label, code)`` of each kind that failed in a record of a grasp that was read
    (a resolve, basis, check or forces record; the summary of a followed path).

    >>> failure_codes({"ok": False, "off_tangent": {"x": 1}, "tangent": {"error": {"code": "normals-rank-deficient"}}})
    [('tangent', 'normals-rank-deficient')]
    """
    if "summary" in rec:
        return [(c["method"], c["code"]) for c in rec["summary"]["degenerate"]]
    labels = [(k.key, k.label) for k in KINDS] + [(part, part) for part in FORCE_PARTS]
    return [
        (label, m["error"]["code"]) for key, label in labels if isinstance(m := rec.get(key), dict) and "error" in m
    ]


def dumps(obj, indent: bool = False) -> bytes:
    """JSON bytes at full precision (numpy arrays allowed)."""
    return orjson.dumps(obj, option=orjson.OPT_SERIALIZE_NUMPY | (orjson.OPT_INDENT_2 if indent else 0))
