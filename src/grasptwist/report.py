"""Output: records (the JSON contract), and writers for JSON, JSONL, CSV and tables.

A *record* is one (grasp, twist) row as a dict of plain values and numpy
arrays, exactly the contract documented in the README.  The writers turn
records into bytes or text; none of them computes anything.  JSON goes
through orjson, which writes numpy arrays natively, floats at full
precision (shortest round-trip form) and NaN as ``null``.
"""

from __future__ import annotations

import csv
import io
from typing import IO

import numpy as np
import orjson

from .batch import Resolution
from .degeneracy import Status, conditioning_warning, status_message
from .grasp_file import GraspFileError
from .screws import klein_table

__all__ = [
    "ORDERS",
    "record",
    "basis_record",
    "check_record",
    "error_record",
    "dumps",
    "writer",
    "CSV_COLUMNS",
]

#: Screw orders for output: the paper's ``(omega; v)`` or ``(v; omega)``.
ORDERS = ("omega-v", "v-omega")
_V_OMEGA = [3, 4, 5, 0, 1, 2]


def _screws(a, order):
    """Reorder the last axis of ``(..., 6)`` screws for output."""
    return a[..., _V_OMEGA] if order == "v-omega" else a


def record(res: Resolution, order: str = "omega-v") -> dict:
    """The output record of one resolution (see the README's output contract)."""
    g = res.grasp
    rec = _grasp_fields(g)
    rec["twist"] = {"name": res.twist.name, "screw": _screws(res.twist.screw, order)}
    rec["contacts"] = rec.pop("contacts")  # keep the documented key order
    rec["contact_velocity"] = res.velocity
    warnings = []
    if res.method != "tangent":
        rec["off_tangent"] = None if res.off_tangent is None else _off_tangent(res.off_tangent, g, order, warnings)
    if res.tangent is not None:
        rec["tangent"] = _tangent(res.tangent, g, order, warnings)
    rec["warnings"] = warnings
    rec["ok"] = _methods_ok(rec)
    return rec


def _grasp_fields(g):
    return {
        "file": g.file,
        "grasp": g.name,
        "units": g.units,
        "contacts": [{"name": n, "point": g.points[i], "normal": g.normals[i]} for i, n in enumerate(g.contact_names)],
    }


def basis_record(res: Resolution, order: str = "omega-v") -> dict:
    """The bases of one grasp with their tables of Klein products (``res`` resolves the zero twist)."""
    g = res.grasp
    rec = _grasp_fields(g)
    off, tan = res.off_tangent, res.tangent
    if res.method != "tangent":
        rec["off_tangent"] = None if off is None else _failure(off, g) if not off.ok else {
            "sigma": _screws(off.sigma, order),
            "psi": _screws(off.psi, order),
            "sigma_psi": klein_table(off.sigma, off.psi),
            "conditioning": float(off.conditioning),
        }
    if tan is not None:
        rec["tangent"] = _failure(tan, g) if not tan.ok else {
            "theta": _screws(tan.theta, order),
            "sigma": _screws(tan.sigma, order),
            "theta_sigma": klein_table(tan.theta, tan.sigma),
            "conditioning": float(tan.conditioning),
        }
    rec["warnings"] = _basis_warnings(res)
    rec["ok"] = _methods_ok(rec)
    return rec


def check_record(res: Resolution) -> dict:
    """Validation and degeneracy verdict of one grasp, per method."""
    g = res.grasp
    rec = {"file": g.file, "grasp": g.name}
    for key, r in (("off_tangent", res.off_tangent), ("tangent", res.tangent)):
        if key == "off_tangent" and res.method == "tangent" or key == "tangent" and r is None:
            continue
        if r is None:
            rec[key] = None
            continue
        rec[key] = {"conditioning": float(r.conditioning)} if r.ok else {**_failure(r, g), "conditioning": float(r.conditioning)}
    rec["warnings"] = _basis_warnings(res)
    rec["ok"] = _methods_ok(rec)
    return rec


def _basis_warnings(res):
    warnings = []
    for r, name in ((res.off_tangent, "off-tangent"), (res.tangent, "tangent")):
        if r is not None and r.ok:
            _warn(warnings, r.conditioning, name)
    return warnings


def _methods_ok(rec):
    return not any(isinstance(m, dict) and "error" in m for m in (rec.get("off_tangent"), rec.get("tangent")))


def _failure(result, grasp):
    status = Status(int(result.status))
    return {"error": {"code": status.code, "message": status_message(status, result.culprit, grasp.contact_names)}}


def _off_tangent(r, grasp, order, warnings):
    if not r.ok:
        return _failure(r, grasp)
    _warn(warnings, r.conditioning, "off-tangent")
    return {
        "sigma": _screws(r.sigma, order),
        "psi": _screws(r.psi, order),
        "sigma_psi": r.sigma_psi,
        "x": r.x,
        "y": r.y,
        "conditioning": float(r.conditioning),
        "residual": float(r.residual),
    }


def _tangent(r, grasp, order, warnings):
    if not r.ok:
        return _failure(r, grasp)
    _warn(warnings, r.conditioning, "tangent")
    return {
        "theta": _screws(r.theta, order),
        "theta_sigma": r.theta_sigma,
        "alpha": r.alpha,
        "beta": r.beta,
        "normal_velocity": r.normal_velocity,
        "in_tangent_planes": bool(r.in_tangent_planes),
        "conditioning": float(r.conditioning),
        "residual": float(r.residual),
    }


def _warn(warnings, conditioning, basis):
    text = conditioning_warning(conditioning, basis)
    if text:
        warnings.append(text)


def error_record(err: GraspFileError) -> dict:
    """The record of an input that could not be read, validated or paired with a twist."""
    return {
        "file": err.file,
        "ok": False,
        "error": {"code": err.code, "message": err.message, "line": err.line, "column": err.column},
    }


def _numpy_default(obj):
    # orjson serialises C-contiguous float arrays itself; broadcast views come here.
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    raise TypeError(f"cannot serialise {type(obj).__name__}")


_JSON_OPTS = orjson.OPT_SERIALIZE_NUMPY


def dumps(obj, indent: bool = False) -> bytes:
    """JSON bytes: full-precision floats, NaN and infinities as ``null``."""
    opts = _JSON_OPTS | orjson.OPT_INDENT_2 if indent else _JSON_OPTS
    return orjson.dumps(obj, default=_numpy_default, option=opts)


# --- writers -------------------------------------------------------------------


class _JsonArray:
    """One JSON array, written element by element so a batch streams."""

    def __init__(self, out: IO[bytes]):
        self.out = out
        self.count = 0

    def write(self, rec: dict) -> None:
        self.out.write(b"[\n" if self.count == 0 else b",\n")
        self.out.write(dumps(rec))
        self.count += 1

    def close(self) -> None:
        self.out.write(b"[]\n" if self.count == 0 else b"\n]\n")


class _JsonLines:
    """One compact JSON record per line, flushed per record."""

    def __init__(self, out: IO[bytes]):
        self.out = out

    def write(self, rec: dict) -> None:
        self.out.write(dumps(rec) + b"\n")
        self.out.flush()

    def close(self) -> None:
        pass


def _columns():
    cols = ["file", "grasp", "twist", "ok", "error"]
    cols += [f"twist{i}" for i in range(1, 7)]
    cols += [f"v{i}_{a}" for i in range(1, 4) for a in "xyz"]
    cols += [f"{n}{i}" for n in ("x", "y") for i in range(1, 4)] + ["off_tangent_conditioning", "off_tangent_error"]
    cols += [f"{n}{i}" for n in ("alpha", "beta", "normal_velocity") for i in range(1, 4)]
    cols += ["in_tangent_planes", "tangent_conditioning", "tangent_error"]
    return cols


#: CSV header, one column per field; the README documents each.
CSV_COLUMNS = _columns()


class _Csv:
    """One row per record; empty cells where a value does not apply."""

    def __init__(self, out: IO[bytes]):
        self.out = out
        self.text = io.StringIO()
        self.csv = csv.writer(self.text, lineterminator="\n")
        self.csv.writerow(CSV_COLUMNS)
        self._drain()

    def _drain(self):
        self.out.write(self.text.getvalue().encode())
        self.text.seek(0)
        self.text.truncate()

    def write(self, rec: dict) -> None:
        self.csv.writerow([_cell(v) for v in _csv_values(rec)])
        self._drain()

    def close(self) -> None:
        pass


def _csv_values(rec):
    if "error" in rec:
        err = rec["error"]
        return [rec["file"], "", "", False, f"{err['code']}: {err['message']}"] + [None] * (len(CSV_COLUMNS) - 5)
    off, tan = rec.get("off_tangent"), rec.get("tangent")
    values = [rec["file"], rec["grasp"], rec["twist"]["name"], rec["ok"], ""]
    values += list(rec["twist"]["screw"]) + list(np.ravel(rec["contact_velocity"]))
    values += _method_cells(off, ("x", "y"), 6)
    values += _method_cells(tan, ("alpha", "beta", "normal_velocity"), 9, extra=("in_tangent_planes",))
    return values


def _method_cells(m, names, n, extra=()):
    if not m or "error" in m:
        error = f"{m['error']['code']}: {m['error']['message']}" if m else ""
        return [None] * (n + len(extra) + 1) + [error]
    cells = [v for name in names for v in m[name]]
    return cells + [m[e] for e in extra] + [m["conditioning"], ""]


def _cell(v):
    if v is None:
        return ""
    if isinstance(v, (bool, np.bool_)):
        return "true" if v else "false"
    if isinstance(v, (float, np.floating)):
        return "" if not np.isfinite(v) else repr(float(v) + 0.0)  # + 0.0: no "-0.0"
    return v


def writer(fmt: str, out: IO[bytes], kind: str = "resolve", **table_options):
    """A writer with ``write(record)`` and ``close()``.

    ``fmt`` is ``json``, ``jsonl``, ``csv`` (resolve records only) or
    ``table``; ``kind`` says which records a table shows: ``resolve``,
    ``basis`` or ``check``.
    """
    if fmt == "table":
        from . import table  # rich is imported only for people-facing output

        return table.WRITERS[kind](out, **table_options)
    return {"json": _JsonArray, "jsonl": _JsonLines, "csv": _Csv}[fmt](out)
