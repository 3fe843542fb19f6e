"""Records of ``follow``: one per sample of a path, then the path's summary.

A sample record is a ``resolve`` record of the moved grasp (built by
:func:`grasptwist.output.records.records`, so the method fields, warnings and
``ok`` are exactly resolve's) with the path's fields in place of the twist's
name, the units and the contact velocities.  The summary record reports
what :func:`grasptwist.engine.path.degeneracies` found.  CSV rows and npz
arrays are the block's columns (:mod:`grasptwist.output.columns`) after the
path's own.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import partial
from typing import NamedTuple

import numpy as np

from ..engine.degeneracy import CONDITION_WARNING, Status, status_message
from ..engine.forces.grasp_map import ForceStatus
from ..engine.se3 import matrix_to_quaternion
from ..results import KINDS
from .columns import CSV_COLUMNS, ColumnSet, arrays, columns, header
from .csv_rows import lines
from .force_records import GRIP_FIELDS
from .force_records import _error as grip_error  # the forces record's error object, shared
from .names import escaped
from .numbers import fmt_number
from .records import dumps, records

__all__ = [
    "PATH_COLUMNS",
    "ENCODINGS",
    "Encoding",
    "sample_records",
    "summary_record",
    "diagnostics",
    "CSV_HEADER",
    "csv_header",
    "encodings",
    "csv_rows",
    "sample_columns",
    "sample_arrays",
    "crossing_text",
    "hand_event_texts",
    "hand_summary",
    "grip_record",
    "hold_text",
    "unjudged_text",
]

#: The block columns a follow CSV row leaves out (the path's own replace them).
_NOT_IN_CSV = ("file", "grasp", "twist")

#: The path's own CSV columns, first in a row.
_OWN = (
    ("file", "grasp", "path", "segment", "t")
    + tuple(f"position_{a}" for a in "xyz")
    + tuple(f"rotation_{a}" for a in "wxyz")
)

#: The CSV header of ``follow``.
CSV_HEADER = ",".join(_OWN + tuple(c for c in CSV_COLUMNS if c not in _NOT_IN_CSV)).encode() + b"\n"

#: A status by its code.
_STATUS = {s.code: s for s in Status}

#: A kind's label -> its key (``off-tangent`` -> ``off_tangent``).
_KEY = {k.label: k.key for k in KINDS}


def _pose(samples):
    """Per sample ``(position (N, 3), quaternion w first (N, 4))``, no ``-0.0``."""
    p = samples.poses
    return p.position + 0.0, matrix_to_quaternion(p.rotation) + 0.0


def sample_records(samples, order: str = "omega-v") -> list[dict]:
    """The record of each sample of a :class:`~grasptwist.run.follow.Samples`."""
    position, quaternion = _pose(samples)
    segment, time = samples.poses.segment.tolist(), samples.poses.time.tolist()
    out = []
    for i, rec in enumerate(records(samples.block, order)):
        new = {
            "file": rec["file"],
            "grasp": rec["grasp"],
            "path": samples.path,
            "segment": segment[i],
            "t": time[i],
            "pose": {"position": position[i], "rotation": quaternion[i]},
            "contacts": rec["contacts"],
            "twist": {"screw": rec["twist"]["screw"]},
        }
        for kind in KINDS:
            if kind.key in rec:
                new[kind.key] = rec[kind.key]
        if samples.joint_positions is not None:
            new["joint_positions"] = _finger_positions(samples.block.hands[i], samples.joint_positions[i])
        if samples.grip is not None:
            new["grip"] = grip_record(samples.grip, i)
        new["clearance"] = rec["clearance"]
        new["warnings"] = rec["warnings"]
        new["ok"] = rec["ok"]
        out.append(new)
    return out


def grip_record(grip, i) -> dict:
    """Row ``i`` of a :class:`~grasptwist.engine.forces.grip.Grip` as the ``forces`` record's
    ``grip`` object: the forces (row ``j`` contact ``j``), squeezes, normal and tangential
    forces, friction used, their total and the safety factor; or ``{"error": {code, message}}``.  With soft
    contacts (a grasp file's ``model: soft``) also its ``contact_model`` and each contact's ``torsion``."""
    if grip.status[i] != ForceStatus.OK:
        return grip_error(grip.status[i], grip.culprit[i])
    rec = {**{k: getattr(grip, k)[i] + 0.0 for k in GRIP_FIELDS}, "safety": grip.safety}
    if grip.torsion is not None:
        rec |= {"contact_model": "soft", "torsion": (grip.torsion[i] + 0.0).tolist()}
    return rec


def hold_text(c: dict, digits: int = 4) -> str:
    """A ``cannot_hold`` stretch of a summary in words.

    >>> hold_text({"t_start": 0.4636476, "t_end": 5.8195377, "culprit": "thumb", "reason": "friction"})
    "cannot hold the weight from t = 0.4636 to t = 5.8195: the friction cone at contact 'thumb' is too narrow"
    """
    why = (
        "a finger would have to pull"
        if c["reason"] == "pulling"
        else f"the friction cone at contact '{escaped(c['culprit'])}' is too narrow"
    )
    a, b = fmt_number(c["t_start"], digits), fmt_number(c["t_end"], digits)
    return f"cannot hold the weight from t = {a} to t = {b}: {why}"


def unjudged_text(u: dict, digits: int = 4) -> str:
    """A ``hold_unjudged`` stretch of a summary in words.

    >>> unjudged_text({"t_start": 5.8e-11, "t_end": 1.0, "code": "nonfinite-pose"})
    'cannot judge whether the weight is held from t = 0.0000 to t = 1.0000: the grip fails there (nonfinite-pose)'
    """
    a, b = fmt_number(u["t_start"], digits), fmt_number(u["t_end"], digits)
    return f"cannot judge whether the weight is held from t = {a} to t = {b}: the grip fails there ({u['code']})"


def _finger_positions(hand, positions) -> list[list[float]]:
    """Per finger of ``hand``, its joints' positions from a ``(n_joints,)`` row in ``hand.joint_names`` order."""
    return [(positions[list(f.joint_index)] + 0.0).tolist() for f in hand.fingers]


def hand_summary(grasp, tracked, tip_error) -> dict:
    """The ``hand`` object of a path's summary: the first time a joint leaves its position
    limits, and per finger its own first events and ``tip_error``, its largest at the samples
    (the samples' records give each: a summary that says less than they do would hide it)."""
    fingers, first = [], None
    for finger, track, error in zip(grasp.hand.fingers, tracked.fingers, tip_error.tolist()):
        exit_ = None
        if track.limit_exit is not None:
            t, j = track.limit_exit
            exit_ = {"joint": finger.joints[j].name, "t": t}
            if first is None or t < first["t"]:
                first = {"finger": finger.name, **exit_}
        fingers.append(
            {
                "name": finger.name,
                "joint_limit": exit_,
                "rank_loss": track.rank_loss,
                "first_warning": track.warning,
                "tip_error": error,
            }
        )
    return {"joint_limit": first, "fingers": fingers}


def summary_record(summary) -> dict:
    """The record closing a path: its duration, samples, smallest conditioning
    per method, degenerate stretches and first warning, and with a hand its
    fingers' events (README "Paths")."""
    found, names = summary.found, summary.grasp.contact_names
    labels = [k.label for k in KINDS if k.method and k.label in summary.labels]
    smallest = {}
    for label in labels:
        value = found.min_conditioning.get(label)
        smallest[_KEY[label]] = None if value is None else {"value": value[0], "t": value[1]}
    degenerate = [
        {
            "method": c.method,
            "code": c.code,
            "t_start": c.t_start,
            "t_end": c.t_end,
            "culprit": names[c.culprit] if c.culprit >= 0 else None,
        }
        for c in found.crossings
        if c.method in labels
    ]
    started = [(t, m) for m, t in found.warning_start.items() if t is not None and m in labels]
    first = min(started, default=None)
    out = {
        "duration": found.duration,
        "samples": summary.samples,
        "min_conditioning": smallest,
        "degenerate": degenerate,
        "first_warning": None if first is None else {"method": first[1], "t": first[0]},
    }
    ok = not degenerate
    if summary.cannot_hold is not None:
        out["cannot_hold"] = [
            {
                "t_start": c.t_start,
                "t_end": c.t_end,
                "culprit": names[c.culprit] if c.culprit >= 0 else None,
                "reason": "friction" if c.culprit >= 0 else "pulling",
            }
            for c in summary.cannot_hold
        ]
        out["hold_unjudged"] = [
            {"t_start": u.t_start, "t_end": u.t_end, "code": ForceStatus(u.status).code} for u in summary.unjudged
        ]
        # the object falls, or no one knows whether it does
        ok = ok and not summary.cannot_hold and not summary.unjudged
    if summary.hand is not None:
        out["hand"] = hand_summary(summary.grasp, summary.hand, summary.tip_error)
        # a joint out of its limits, or a finger that cannot follow, stops the motion too
        ok = ok and out["hand"]["joint_limit"] is None and all(f["rank_loss"] is None for f in out["hand"]["fingers"])
    return {
        "file": escaped(summary.file, controls=False),
        "grasp": escaped(summary.grasp.name, controls=False),
        "path": escaped(summary.path, controls=False),
        "summary": out,
        "warnings": list(summary.warnings),
        "ok": ok,
    }


def crossing_text(c: dict, names=("1", "2", "3"), digits: int = 4) -> str:
    """A degenerate stretch of a summary in words (the condition and when).

    >>> crossing_text({"method": "off-tangent", "code": "wrist-coplanar", "t_start": 1.5707963, "t_end": 1.5707963})
    "the wrist crosses the contacts' plane at t = 1.5708"
    """
    a, b = fmt_number(c["t_start"], digits), fmt_number(c["t_end"], digits)
    if c["code"] == Status.WRIST_COPLANAR.code:
        if c["t_start"] == c["t_end"]:
            return f"the wrist crosses the contacts' plane at t = {a}"
        return f"the wrist is in the contacts' plane from t = {a} to t = {b}"
    culprit = names.index(c["culprit"]) if c.get("culprit") in names else -1
    return f"from t = {a} to t = {b}: {status_message(_STATUS[c['code']], culprit, names)}"


def hand_event_texts(hand: dict, names=("1", "2", "3"), digits: int = 4) -> tuple[list[str], list[str]]:
    """A summary's hand events in words: ``(errors, warnings)``, the joint-limit exit and the
    rank losses (the motion cannot be made), then the fingers' conditioning warnings.  Finger
    ``f`` is named by its contact, ``names[f]`` (the records keep the hand's own finger names).

    >>> hand_event_texts({"joint_limit": {"finger": "east", "joint": "e2", "t": 0.5},
    ...                   "fingers": [{"name": "east", "rank_loss": None, "first_warning": 0.25}]})
    (["joint 'e2' of finger 1 leaves its position limits at t = 0.5000"], ['finger 1: conditioning below 0.001 from t = 0.2500'])
    """
    errors, warnings = [], []
    fingers = [f["name"] for f in hand["fingers"]]
    if hand["joint_limit"] is not None:
        j = hand["joint_limit"]
        finger = escaped(names[fingers.index(j["finger"])])
        errors.append(
            f"joint '{escaped(j['joint'])}' of finger {finger} leaves its position limits at t = {fmt_number(j['t'], digits)}"
        )
    for f, name in zip(hand["fingers"], names):
        if f["rank_loss"] is not None:
            errors.append(
                f"finger {escaped(name)} loses rank (its Jacobian) at t = {fmt_number(f['rank_loss'], digits)}"
            )
        if f["first_warning"] is not None:
            warnings.append(
                f"finger {escaped(name)}: conditioning below {CONDITION_WARNING:g} from t = {fmt_number(f['first_warning'], digits)}"
            )
    return errors, warnings


def diagnostics(rec: dict, names=("1", "2", "3")) -> tuple[list[str], list[str]]:
    """The stderr lines of a summary record (its grasp's contacts named ``names``): one error per
    degenerate stretch, one warning for the first time a conditioning falls below the warning level."""
    where = f"{escaped(rec['file'])}: grasp '{escaped(rec['grasp'])}', path '{escaped(rec['path'])}'"
    s = rec["summary"]
    errors = [f"{where}: error: {c['method']}: {c['code']}: {crossing_text(c, names, 6)}" for c in s["degenerate"]]
    warnings = []
    if s["first_warning"] is not None:
        w = s["first_warning"]
        warnings.append(
            f"{where}: warning: {w['method']}: conditioning below {CONDITION_WARNING:g} from t = {w['t']:.6g}"
        )
    warnings += [f"{where}: warning: {w}" for w in rec.get("warnings", ())]
    errors += [f"{where}: error: {hold_text(c, 6)}" for c in s.get("cannot_hold", ())]
    errors += [f"{where}: error: {unjudged_text(u, 6)}" for u in s.get("hold_unjudged", ())]
    if "hand" in s:
        hand_errors, hand_warnings = hand_event_texts(s["hand"], names, 6)
        errors += [f"{where}: error: hand: {text}" for text in hand_errors]
        warnings += [f"{where}: warning: hand: {text}" for text in hand_warnings]
    return errors, warnings


def csv_header(hand=None) -> bytes:
    """The CSV header of ``follow`` for a run's ``hand`` (None: :data:`CSV_HEADER`): resolve's
    joint columns (the joint positions ``q_<finger>_<joint>`` among them) in their place."""
    if hand is None:
        return CSV_HEADER
    rest = tuple(c for c in header(hand) if c not in _NOT_IN_CSV)
    return ",".join(_OWN + rest).encode() + b"\n"


def sample_columns(samples, order: str = "omega-v", hand=None, typed: bool = False) -> dict[str, np.ndarray]:
    """The flat columns of each sample, in the order of :func:`csv_header` of the run's ``hand``."""
    block = samples.block
    position, quaternion = _pose(samples)
    own = {
        "file": np.asarray(block.file, dtype=object),
        "grasp": np.asarray(block.grasp, dtype=object),
        "path": np.asarray(block.twist_name, dtype=object),
        "segment": samples.poses.segment,
        "t": samples.poses.time,
    }
    own.update({f"position_{a}": position[:, j] for j, a in enumerate("xyz")})
    own.update({f"rotation_{a}": quaternion[:, j] for j, a in enumerate("wxyz")})
    rest = {k: v for k, v in columns(block, order, hand).items() if k not in _NOT_IN_CSV}
    return {**own, **rest}


def csv_rows(samples, order: str = "omega-v", hand=None) -> list[bytes]:
    """The CSV line of each sample (header :func:`csv_header` of the run's ``hand``)."""
    return lines(sample_columns(samples, order, hand))


def sample_arrays(samples, order: str = "omega-v", hand=None) -> dict[str, np.ndarray]:
    """The arrays a follow npz holds: the block's (with the run's ``hand``, the
    ``joint_positions (N, n_joints)``), its ``twist`` the instantaneous space twist, then
    ``t``, ``segment``, ``position`` and ``rotation`` (quaternions, w first)."""
    position, quaternion = _pose(samples)
    path = {"t": samples.poses.time, "segment": samples.poses.segment, "position": position, "rotation": quaternion}
    return {**arrays(samples.block, order, hand), **path}


def csv_error_row(rec: dict, hand=None) -> bytes:
    """The CSV line of an input that failed: its file, ``ok`` false and the error."""
    err = rec["error"]
    row = [rec["file"]] + [""] * (len(_OWN) - 1) + ["false", f"{err['code']}: {err['message']}"]
    width = csv_header(hand).count(b",") + 1
    return lines({str(j): np.array([v], dtype=object) for j, v in enumerate(row + [""] * (width - len(row)))})[0]


class Encoding(NamedTuple):
    """How one output format encodes follow's records (None: the format does not write them)."""

    samples: Callable | None  # (Samples, order) -> encoded rows
    summary: Callable | None  # summary record -> encoded
    error: Callable | None  # error record -> encoded


def _json_samples(samples, order):
    return [dumps(r) for r in sample_records(samples, order)]


def encodings(hand=None) -> dict:
    """Per output format (:data:`grasptwist.output.formats.FORMATS`): how follow's records are
    encoded, CSV with the joint columns of the run's ``hand``.  CSV and npz hold the samples only;
    their summaries are the stderr lines (:func:`diagnostics`)."""
    return {
        "table": Encoding(sample_records, lambda rec: rec, lambda rec: rec),
        "json": Encoding(_json_samples, dumps, dumps),
        "jsonl": Encoding(_json_samples, dumps, dumps),
        "csv": Encoding(partial(csv_rows, hand=hand), None, partial(csv_error_row, hand=hand)),
        "npz": Encoding(None, None, None),  # takes the samples (sample_arrays)
    }


#: :func:`encodings` of a run without a hand.
ENCODINGS = encodings()


#: The path family's columns (``follow`` samples: the path's own, then resolve's; no Parquet).
PATH_COLUMNS = ColumnSet(
    header=csv_header,
    flat=sample_columns,
    arrays=sample_arrays,
    error_row=csv_error_row,
    statuses=Status,
)
