"""Output: records (the JSON contract), their diagnostics, and writers.

A *record* is one (grasp, twist) row as a dict of plain values, exactly the
contract documented in the README.  :func:`records` builds them a block at
a time (arrays are turned into lists once per block, which is what makes a
million records a second-scale job).  Encoders turn a record into bytes for
JSON, JSONL or CSV; writers put encoded records on a stream.  Nothing here
computes: every number comes from the engine.  JSON goes through orjson:
floats at full precision (shortest round-trip form), NaN never (failed
methods carry an ``error`` object instead of numbers).
"""

from __future__ import annotations

import csv
import io
import os
from typing import IO

import numpy as np
import orjson

from ..engine.degeneracy import CONDITION_WARNING, Status, conditioning_warning, status_message
from ..engine.screws import klein_table
from ..model import GraspFileError
from ..run.batch import Block

__all__ = [
    "ORDERS",
    "records",
    "basis_record",
    "check_record",
    "error_record",
    "diagnostics",
    "talking_rows",
    "dumps",
    "ENCODERS",
    "writer",
    "CSV_COLUMNS",
]

#: Screw orders for output: the paper's ``(omega; v)`` or ``(v; omega)``.
ORDERS = ("omega-v", "v-omega")
_V_OMEGA = [3, 4, 5, 0, 1, 2]


def _screws(a, order):
    """Reorder the last axis of ``(..., 6)`` screws for output."""
    return a[..., _V_OMEGA] if order == "v-omega" else a


_OFF_TANGENT_FIELDS = ("sigma", "psi", "sigma_psi", "x", "y", "conditioning", "residual")
_TANGENT_FIELDS = (
    "theta",
    "theta_sigma",
    "alpha",
    "beta",
    "normal_velocity",
    "in_tangent_planes",
    "conditioning",
    "residual",
)


def records(block: Block, order: str = "omega-v") -> list[dict]:
    """The output records of a block's rows (see the README's output contract).

    Built column-wise for speed (this runs for every record of a
    million-grasp data set): numbers stay in numpy, each record holding
    views of contiguous rows, which orjson writes without making a Python
    float of each.  Consumers that need lists call ``.tolist()``.
    """
    n = len(block)
    warnings = [[] for _ in range(n)]
    off = _method_rows(block, block.off_tangent, order, _OFF_TANGENT_FIELDS, "off-tangent", warnings)
    tan = _method_rows(block, block.tangent, order, _TANGENT_FIELDS, "tangent", warnings)
    if off is not None:
        off = [m if has else None for m, has in zip(off, block.has_wrist.tolist())]
    failed = _failed_rows(block)
    out = []
    rows = zip(
        block.file,
        block.grasp,
        block.units,
        block.twist_name,
        _rows(_screws(block.twist, order)),
        block.contact_names,
        _rows(block.points),
        _rows(block.normals),
        _rows(block.velocity),
    )
    for i, (file, grasp, units, twist_name, screw, names, p, q, v) in enumerate(rows):
        rec = {
            "file": file,
            "grasp": grasp,
            "units": units,
            "twist": {"name": twist_name, "screw": screw},
            "contacts": [
                {"name": names[0], "point": p[0], "normal": q[0]},
                {"name": names[1], "point": p[1], "normal": q[1]},
                {"name": names[2], "point": p[2], "normal": q[2]},
            ],
            "contact_velocity": v,
        }
        if off is not None:
            rec["off_tangent"] = off[i]
        if tan is not None:
            rec["tangent"] = tan[i]
        rec["warnings"] = warnings[i]
        rec["ok"] = not failed[i]
        out.append(rec)
    return out


def _rows(a):
    """Row views of a C-contiguous copy of ``a`` (orjson writes contiguous arrays natively).

    Floats get ``+ 0.0``, which turns ``-0.0`` into ``0.0``: a round-off sign
    on zero means nothing and reads oddly (``jq`` prints ``-0``).
    """
    a = np.ascontiguousarray(a + 0.0 if a.dtype.kind == "f" else a)
    return list(a) if a.ndim > 1 else a.tolist()


def _method_rows(block, result, order, names, label, warnings):
    """One method's per-row dicts (``error`` objects where it failed), warnings appended."""
    if result is None:
        return None
    if result.sigma is None:  # resolved without bases (bases=False): numbers and verdicts only
        names = tuple(n for n in names if n not in ("sigma", "psi", "theta", "residual"))
    columns = [_rows(_screws(a, order) if a.ndim == 3 else a) for a in (np.asarray(getattr(result, n)) for n in names)]
    rows = [dict(zip(names, values)) for values in zip(*columns)]
    status = np.asarray(result.status)
    for i in np.flatnonzero(status):
        rows[i] = _failure(status[i], result.culprit[i], block.contact_names[i])
    asked = block.has_wrist if result is block.off_tangent else True
    for i in np.flatnonzero((status == Status.OK) & (result.conditioning < CONDITION_WARNING) & asked):
        warnings[i].append(conditioning_warning(result.conditioning[i], label))
    return rows


def talking_rows(block: Block) -> np.ndarray:
    """Rows whose record has something for stderr: a failed method or a warning."""
    talk = np.zeros(len(block), bool)
    for r, asked in ((block.off_tangent, block.has_wrist), (block.tangent, True)):
        if r is not None:
            talk |= (~r.ok | (r.conditioning < CONDITION_WARNING)) & asked
    return talk


def _failed_rows(block):
    """Per row: did a method that applies fail?"""
    failed = np.zeros(len(block), bool)
    if block.off_tangent is not None:
        failed |= ~block.off_tangent.ok & block.has_wrist
    if block.tangent is not None:
        failed |= ~block.tangent.ok
    return failed.tolist()


def _failure(status, culprit, names):
    status = Status(int(status))
    return {"error": {"code": status.code, "message": status_message(status, culprit, names)}}


def _warn(warnings, conditioning, basis):
    text = conditioning_warning(conditioning, basis)
    if text:
        warnings.append(text)


def _methods_ok(rec):
    return not any(isinstance(m, dict) and "error" in m for m in (rec.get("off_tangent"), rec.get("tangent")))


def _grasp_fields(block: Block, i: int) -> dict:
    names = block.contact_names[i]
    return {
        "file": block.file[i],
        "grasp": block.grasp[i],
        "units": block.units[i],
        "contacts": [
            {"name": names[c], "point": block.points[i, c].tolist(), "normal": block.normals[i, c].tolist()}
            for c in range(3)
        ],
    }


def basis_record(block: Block, i: int, order: str = "omega-v") -> dict:
    """The bases of row ``i``'s grasp with their Klein products (cf. eq. 18)."""
    rec = _grasp_fields(block, i)
    names = block.contact_names[i]
    warnings = []
    if block.off_tangent is not None:
        off = block.off_tangent.row(i)
        rec["off_tangent"] = (
            None
            if not block.has_wrist[i]
            else _failure(off.status, off.culprit, names)
            if not off.ok
            else {
                "sigma": _screws(off.sigma, order).tolist(),
                "psi": _screws(off.psi, order).tolist(),
                "sigma_psi": klein_table(off.sigma, off.psi).tolist(),
                "conditioning": float(off.conditioning),
            }
        )
        if block.has_wrist[i] and off.ok:
            _warn(warnings, off.conditioning, "off-tangent")
    if block.tangent is not None:
        tan = block.tangent.row(i)
        rec["tangent"] = (
            _failure(tan.status, tan.culprit, names)
            if not tan.ok
            else {
                "theta": _screws(tan.theta, order).tolist(),
                "sigma": _screws(tan.sigma, order).tolist(),
                "theta_sigma": klein_table(tan.theta, tan.sigma).tolist(),
                "conditioning": float(tan.conditioning),
            }
        )
        if tan.ok:
            _warn(warnings, tan.conditioning, "tangent")
    rec["warnings"] = warnings
    rec["ok"] = _methods_ok(rec)
    return rec


def check_record(block: Block, i: int) -> dict:
    """Validation and degeneracy verdict of row ``i``'s grasp, per method."""
    rec = {"file": block.file[i], "grasp": block.grasp[i]}
    names = block.contact_names[i]
    warnings = []
    for key, label, result in (
        ("off_tangent", "off-tangent", block.off_tangent),
        ("tangent", "tangent", block.tangent),
    ):
        if result is None:
            continue
        r = result.row(i)
        if key == "off_tangent" and not block.has_wrist[i]:
            rec[key] = None
        elif r.ok:
            rec[key] = {"conditioning": float(r.conditioning)}
            _warn(warnings, r.conditioning, label)
        else:
            rec[key] = {**_failure(r.status, r.culprit, names), "conditioning": float(r.conditioning)}
    rec["warnings"] = warnings
    rec["ok"] = _methods_ok(rec)
    return rec


def error_record(err: GraspFileError) -> dict:
    """The record of an input that could not be read, validated or paired with a twist."""
    return {
        "file": err.file,
        "ok": False,
        "error": {"code": err.code, "message": err.message, "line": err.line, "column": err.column},
    }


def diagnostics(rec: dict) -> tuple[list[str], list[str]]:
    """The stderr lines a record calls for: ``(errors, warnings)``, one line each.

    ``path:line:col: error: code: message`` for an input that failed;
    ``path: grasp 'g'[, twist 't']: error: method: code: message`` for a
    method that failed; the same with ``warning:`` for each warning.
    """
    if rec["ok"] and not rec.get("warnings"):
        return [], []
    file = _printable(rec["file"])
    if "error" in rec:
        err = rec["error"]
        where = ":".join(str(x) for x in (file, err["line"], err["column"]) if x is not None)
        return [f"{where}: error: {err['code']}: {_printable(err['message'])}"], []
    where = f"{file}: grasp '{_printable(rec['grasp'])}'"
    if "twist" in rec:
        where += f", twist '{_printable(rec['twist']['name'])}'"
    errors = [
        f"{where}: error: {label}: {m['error']['code']}: {m['error']['message']}"
        for key, label in (("off_tangent", "off-tangent"), ("tangent", "tangent"))
        if isinstance(m := rec.get(key), dict) and "error" in m
    ]
    return errors, [f"{where}: warning: {w}" for w in rec["warnings"]]


def _printable(text) -> str:
    """``text`` with control and separator characters escaped: file and data-set
    names come from whoever filled the folder, and a newline or an escape
    sequence in one must not split a diagnostic or reach the terminal."""
    text = str(text)
    if text.isprintable():
        return text
    return "".join(c if c.isprintable() else c.encode("unicode_escape").decode("ascii") for c in text)


def dumps(obj, indent: bool = False) -> bytes:
    """JSON bytes at full precision (numpy arrays allowed)."""
    return orjson.dumps(obj, option=orjson.OPT_SERIALIZE_NUMPY | (orjson.OPT_INDENT_2 if indent else 0))


# --- encoders and writers ------------------------------------------------------


def _columns_csv():
    cols = ["file", "grasp", "twist", "ok", "error"]
    cols += [f"twist{i}" for i in range(1, 7)]
    cols += [f"v{i}_{a}" for i in range(1, 4) for a in "xyz"]
    cols += [f"{n}{i}" for n in ("x", "y") for i in range(1, 4)] + ["off_tangent_conditioning", "off_tangent_error"]
    cols += [f"{n}{i}" for n in ("alpha", "beta", "normal_velocity") for i in range(1, 4)]
    cols += ["in_tangent_planes", "tangent_conditioning", "tangent_error"]
    return cols


#: CSV header, one column per field; the README documents each.
CSV_COLUMNS = _columns_csv()


def _csv_line(rec: dict) -> bytes:
    text = io.StringIO()
    csv.writer(text, lineterminator="\n").writerow([_cell(v) for v in _csv_values(rec)])
    return text.getvalue().encode()


def _csv_values(rec):
    if "error" in rec:
        err = rec["error"]
        return [rec["file"], "", "", False, f"{err['code']}: {err['message']}"] + [None] * (len(CSV_COLUMNS) - 5)
    values = [rec["file"], rec["grasp"], rec["twist"]["name"], rec["ok"], ""]
    values += list(rec["twist"]["screw"]) + [v for row in rec["contact_velocity"] for v in row]
    values += _method_cells(rec.get("off_tangent"), ("x", "y"), 6)
    values += _method_cells(rec.get("tangent"), ("alpha", "beta", "normal_velocity"), 9, extra=("in_tangent_planes",))
    return values


def _method_cells(m, names, n, extra=()):
    if not m or "error" in m:
        error = f"{m['error']['code']}: {m['error']['message']}" if m else ""
        return [None] * (n + len(extra) + 1) + [error]
    return [v for name in names for v in m[name]] + [m[e] for e in extra] + [m["conditioning"], ""]


def _cell(v):
    if v is None:
        return ""
    if isinstance(v, (bool, np.bool_)):
        return "true" if v else "false"
    if isinstance(v, (float, np.floating)):
        return repr(float(v) + 0.0)  # + 0.0: no "-0.0"
    return v


#: Record -> bytes, per machine format (table records stay dicts: rich draws them).
ENCODERS = {"json": dumps, "jsonl": dumps, "csv": _csv_line, "table": lambda rec: rec}

#: Encoded records -> one bytes object that the format's writer takes as one record.
JOINERS = {"json": b",\n".join, "jsonl": b"\n".join, "csv": b"".join}


def _copy_file(out: IO[bytes], path: str) -> None:
    """Append the file at ``path`` to ``out`` (in the kernel when both are files or pipes), then delete it."""
    with open(path, "rb") as f:
        size = os.fstat(f.fileno()).st_size
        try:
            target = out.fileno()
        except (OSError, AttributeError, ValueError):  # not a real file (tests' buffers)
            out.write(f.read())
        else:
            out.flush()
            sent = 0
            while sent < size:
                sent += os.sendfile(target, f.fileno(), sent, size - sent)
    os.unlink(path)


class _JsonArray:
    """One JSON array, written element by element so a batch streams."""

    def __init__(self, out: IO[bytes]):
        self.out = out
        self.count = 0

    def write(self, encoded: bytes) -> None:
        self.out.write(b"[\n" if self.count == 0 else b",\n")
        self.out.write(encoded)
        self.count += 1

    def write_spooled(self, path: str) -> None:
        self.out.write(b"[\n" if self.count == 0 else b",\n")
        _copy_file(self.out, path)
        self.count += 1

    def close(self) -> None:
        self.out.write(b"[]\n" if self.count == 0 else b"\n]\n")


class _Lines:
    """One encoded record per line (JSONL, CSV rows after a header), flushed per batch."""

    def __init__(self, out: IO[bytes], header: bytes = b"", newline: bytes = b"\n"):
        self.out = out
        self.newline = newline
        out.write(header)

    def write(self, encoded: bytes) -> None:
        self.out.write(encoded + self.newline)

    def write_spooled(self, path: str) -> None:
        _copy_file(self.out, path)
        self.out.write(self.newline)

    def close(self) -> None:
        self.out.flush()


def writer(fmt: str, out: IO[bytes], kind: str = "resolve", **table_options):
    """A writer with ``write(encoded)`` and ``close()`` for records encoded by ``ENCODERS[fmt]``.

    ``fmt`` is ``json``, ``jsonl``, ``csv`` (resolve records only) or
    ``table``; ``kind`` says which records a table shows: ``resolve``,
    ``basis`` or ``check``.
    """
    if fmt == "table":
        from . import table  # rich is imported only for people-facing output

        return table.WRITERS[kind](out, **table_options)
    if fmt == "json":
        return _JsonArray(out)
    if fmt == "jsonl":
        return _Lines(out)
    return _Lines(out, header=",".join(CSV_COLUMNS).encode() + b"\n", newline=b"")
