"""The records of ``grasptwist simulate`` and their table.

One record per grasp (:class:`grasptwist.run.simulate.Simulated`)::

    {"file", "grasp", "ok" (= held), "held", "mass", "load", "friction": [3], "duration",
     "tolerance": {"distance", "angle_deg"}, "safety", "contact_model", "torsion": [3] or null, "scene",
     "directions": [{"direction": "+x", "held", "simulated", "grip": "ok" or its status code,
                     "displacement", "rotation_deg",
                     "contact_forces": [[3] x 3], "planned_forces": [[3] x 3],
                     "contact_torsion": [3] or null, "planned_torsion": [3] or null}, x 6],
     "warnings": [...]}

A grasp read but not simulated (no object, mass or friction, ...) is an error record with its
``grasp`` and ``scene`` (:func:`not_simulated_record`).

With ``--path NAME`` a record per grasp says how its path went instead::

    {"file", "grasp", "ok" (= followed), "path", "followed", "mass", "friction", "tolerance",
     "safety", "contact_model", "torsion", "scene", "final": {"position_error", "angle_error_deg"},
     "samples": [{"time", "position_error", "angle_error_deg", "slip": [3], "slipped": [3]}, ...],
     "warnings": [...]}

``displacement`` is the object's centre's distance from where it started (length units),
``rotation_deg`` the angle it turned, at the end of the direction's ``duration``;
``contact_forces`` each finger's force on the object in MuJoCo then, ``planned_forces``
grasptwist's grip with the hold test's squeeze (null, with the grip's status, where none exists: not
simulated); with soft contacts (``contact_model`` ``soft``, ``torsion`` each contact's radius ``e``)
``contact_torsion`` and ``planned_torsion`` each contact's moment about its normal, in MuJoCo and
planned (null with point contacts); ``scene`` the MJCF file of its scene (``--mjcf``; null without).  A
warning names the directions that did not hold.  Nothing is computed here.
"""

from __future__ import annotations

import math
from enum import IntEnum
from typing import IO

import numpy as np

from ..engine.forces.grasp_map import ForceStatus
from ..engine.hold_test import DIRECTIONS
from .columns import ColumnSet
from .csv_rows import lines
from .names import escaped
from .numbers import fmt_number

__all__ = ["simulate_record", "not_simulated_record", "csv_line", "SIMULATE_COLUMNS", "SimulateTable"]


def _float(v):
    return None if v is None or not np.isfinite(v) else float(v)


def _forces(f):
    return None if f is None or not np.isfinite(f).all() else np.asarray(f, float).tolist()


def _contacts(sim) -> dict:
    """The contact model simulated, each contact's torsional radius (null: point contacts) and the scene's file."""
    e = sim.grasp.torsion
    soft = e is not None and bool(np.any(e > 0))
    return {
        "contact_model": "soft" if soft else "point",
        "torsion": np.asarray(e, float).tolist() if soft else None,
        "scene": None if sim.scene is None else escaped(sim.scene, controls=False),
    }


def not_simulated_record(rec: dict, grasp: str, scene: str | None) -> dict:
    """The error record ``rec`` of a grasp read but not simulated, with its ``grasp`` (after ``file``) and
    ``scene`` (the MJCF file written before it failed, or null).

    >>> not_simulated_record({"file": "a.yaml", "ok": False, "error": {}, "errors": []}, "g", None)
    {'file': 'a.yaml', 'grasp': 'g', 'ok': False, 'error': {}, 'errors': [], 'scene': None}
    """
    named = {"file": rec["file"], "grasp": escaped(grasp, controls=False)}
    return {**named, **rec, "scene": None if scene is None else escaped(scene, controls=False)}


def _direction(d) -> dict:
    return {
        "direction": d.name,
        "held": d.held,
        "simulated": d.simulated,
        "grip": ForceStatus(d.grip_status).code,
        "displacement": _float(d.displacement),
        "rotation_deg": _float(math.degrees(d.rotation)),
        "contact_forces": _forces(d.forces),
        "planned_forces": _forces(d.planned),
        "contact_torsion": _forces(d.torsion),
        "planned_torsion": _forces(d.planned_torsion),
    }


def _warnings(sim) -> list[str]:
    said = list(sim.grasp.warnings)
    no_grip = [d.name for d in sim.test.directions if not d.simulated]
    if no_grip:
        said.append(f"no grip holds the load along {', '.join(no_grip)}: not simulated there")
    slipped = [
        f"{d.name} ({fmt_number(d.displacement, 4)} / {fmt_number(math.degrees(d.rotation), 2)} deg)"
        for d in sim.test.directions
        if d.simulated and not d.held
    ]
    if slipped:
        said.append(f"not held along {', '.join(slipped)}")
    return said


def _path_record(ps) -> dict:
    """The record of one grasp's path executed (``simulate --path``)."""
    o, r = ps.options, ps.run
    slipped = r.slip >= o.distance_tol
    angles = np.degrees(r.angle_error)
    followed = bool(r.position_error[-1] < o.distance_tol and angles[-1] < o.angle_tol and not slipped.any())
    said = list(ps.grasp.warnings)
    names = ps.grasp.contact_names
    if slipped.any():
        worst = r.slip.max(axis=0)
        said.append(
            "contacts slipped: "
            + ", ".join(f"{escaped(n)} ({fmt_number(w, 4)})" for n, w, s in zip(names, worst, slipped.any(axis=0)) if s)
        )
    if not followed:
        said.append(
            f"path '{escaped(ps.path)}' ended {fmt_number(r.position_error[-1], 4)} and "
            f"{fmt_number(angles[-1], 2)} deg from the plan"
        )
    return {
        "file": escaped(ps.grasp.file, controls=False),
        "grasp": escaped(ps.grasp.name, controls=False),
        "ok": followed,
        "path": escaped(ps.path, controls=False),
        "followed": followed,
        "mass": ps.mass,
        "friction": ps.friction.tolist(),
        "tolerance": {"distance": o.distance_tol, "angle_deg": o.angle_tol},
        "safety": o.safety,
        **_contacts(ps),
        "final": {"position_error": float(r.position_error[-1]), "angle_error_deg": float(angles[-1])},
        "samples": [
            {
                "time": float(t),
                "position_error": float(p),
                "angle_error_deg": float(a),
                "slip": s.tolist(),
                "slipped": k.tolist(),
            }
            for t, p, a, s, k in zip(r.times, r.position_error, angles, r.slip, slipped)
        ],
        "warnings": said,
    }


def simulate_record(sim) -> dict:
    """The record of one grasp's hold test, or of its path executed (module docstring)."""
    if hasattr(sim, "run"):
        return _path_record(sim)
    o = sim.options
    return {
        "file": escaped(sim.grasp.file, controls=False),
        "grasp": escaped(sim.grasp.name, controls=False),
        "ok": sim.test.held,
        "held": sim.test.held,
        "mass": sim.mass,
        "load": sim.test.load,
        "friction": sim.friction.tolist(),
        "duration": o.duration,
        "tolerance": {"distance": o.distance_tol, "angle_deg": o.angle_tol},
        "safety": o.safety,
        **_contacts(sim),
        "directions": [_direction(d) for d in sim.test.directions],
        "warnings": _warnings(sim),
    }


#: Each direction's name in a column: ``+x`` is ``px``, ``-x`` is ``mx``.
_SAFE = {d: ("p" if d[0] == "+" else "m") + d[1] for d in DIRECTIONS}
_OWN = ("file", "grasp", "ok", "error", "held", "mass", "load")
_PER = ("held", "displacement", "rotation_deg")
_COLUMNS = _OWN + tuple(f"{c}_{_SAFE[d]}" for d in DIRECTIONS for c in _PER) + ("scene",)


def _cells(rec: dict) -> dict:
    row = dict.fromkeys(_COLUMNS)
    if "error" in rec:
        err = rec["error"]
        row.update(file=rec["file"], grasp=rec.get("grasp"), scene=rec.get("scene"), ok=False)
        row.update(error=f"{err['code']}: {err['message']}")
        return row
    row.update({c: rec[c] for c in ("file", "grasp", "ok", "held", "mass", "load", "scene")})
    for d in rec["directions"]:
        row.update({f"{c}_{_SAFE[d['direction']]}": d[c] for c in _PER})
    return row


def _flat(records, order="omega-v", hand=None, typed=False) -> dict:
    """The flat columns of records (empty cells where a value is null)."""
    cells = [_cells(r) for r in records]
    columns = {}
    for c in _COLUMNS:
        values = [row[c] for row in cells]
        missing = [v is None for v in values]
        kind = (
            bool
            if c == "ok" or c.startswith("held")
            else (object if c in ("file", "grasp", "error", "scene") else float)
        )
        filled = [(kind() if kind is not object else "") if m else v for v, m in zip(values, missing)]
        columns[c] = np.ma.masked_array(np.array(filled, dtype=kind), mask=missing)
    return columns


def csv_line(rec: dict) -> bytes:
    """The CSV line of one grasp's record, or of an input that failed: the verdict, and per direction
    whether it held and how far the object moved and turned (``held_px``, ``displacement_px``,
    ``rotation_deg_px``, ...: ``px`` is ``+x``, ``mx`` is ``-x``), and its ``scene``'s file (``--mjcf``)."""
    return lines(_flat([rec]))[0]


class _Statuses(IntEnum):
    OK = 0


#: The simulation family's columns (CSV).
SIMULATE_COLUMNS = ColumnSet(
    header=lambda hand=None: ",".join(_COLUMNS).encode() + b"\n",
    flat=_flat,
    arrays=_flat,
    error_row=lambda rec, hand=None: csv_line(rec),
    statuses=_Statuses,
)


def _small(v) -> str:
    """A movement, of any size, to two significant digits (``-`` when not simulated).

    >>> _small(2.7123e-05), _small(None)
    ('2.7e-05', '-')
    """
    return "-" if v is None else f"{v:.2g}"


class SimulateTable:
    """The hold tests as a plain table (``write(record)``, ``close()``): per grasp whether it held, and per
    direction how far the object moved and turned, and the contact forces beside the planned ones."""

    def __init__(self, out: IO[bytes], digits: int = 4, **_):
        self.out = out
        self.digits = digits

    def _line(self, text: str = "") -> None:
        self.out.write(text.encode() + b"\n")

    def _number(self, v) -> str:
        return fmt_number(v, self.digits)

    def _norms(self, forces) -> str:
        if forces is None:
            return "-"
        return ", ".join(self._number(float(np.linalg.norm(f))) for f in forces)

    def _path(self, rec: dict) -> None:
        final = rec["final"]
        self._line(
            f"{escaped(rec['file'])}: grasp '{escaped(rec['grasp'])}', path '{escaped(rec['path'])}': "
            f"{'followed' if rec['followed'] else 'NOT followed'} (ends {_small(final['position_error'])} and "
            f"{_small(final['angle_error_deg'])} deg from the plan)"
        )
        self._line("  time      position error  angle error (deg)  slip (each contact)")
        for s in rec["samples"]:
            slips = ", ".join(_small(v) for v in s["slip"])
            self._line(
                f"  {self._number(s['time']):<8}  {_small(s['position_error']):<14}  {_small(s['angle_error_deg']):<17}  {slips}"
            )

    def write(self, rec: dict) -> None:
        if "error" in rec:  # its line is on stderr; tables carry results only
            return
        if "path" in rec:
            self._path(rec)
            return
        verdict = "held" if rec["held"] else "NOT held"
        self._line(
            f"{escaped(rec['file'])}: grasp '{escaped(rec['grasp'])}': {verdict} "
            f"(load {self._number(rec['load'])} N for {rec['duration']:g} s, tolerance "
            f"{rec['tolerance']['distance']:g} / {rec['tolerance']['angle_deg']:g} deg)"
        )
        self._line("  direction  held  moved       turned (deg)  |f| MuJoCo (each finger)  |f| planned")
        for d in rec["directions"]:
            held = "yes" if d["held"] else "no"
            if not d["simulated"]:  # no grip: what it is, across the columns of what was not simulated
                self._line(f"  {d['direction']:<9}  {held:<4}  not simulated (grip: {d['grip']})")
                continue
            self._line(
                f"  {d['direction']:<9}  {held:<4}  {_small(d['displacement']):<10}  "
                f"{_small(d['rotation_deg']):<12}  {self._norms(d['contact_forces']):<24}  "
                f"{self._norms(d['planned_forces'])}"
            )

    def close(self) -> None:
        pass
