"""Record objects of result kinds whose shape depends on the row (see :attr:`ResultKind.record`).

A hand's fingers have their own joints, so its object cannot be a fixed
list of fields: :func:`hand_objects` writes it from the engine's
:class:`~grasptwist.engine.kinematics.HandRates`.  Nothing is computed
here: every number and verdict comes from the engine.
"""

from __future__ import annotations

import numpy as np

from ..engine.degeneracy import CONDITION_WARNING, Status, status_message
from .numbers import fmt_figure

__all__ = ["hand_objects"]


def _number(x):
    """A float, or None for NaN (no value)."""
    x = float(x)
    return None if np.isnan(x) else x + 0.0


def _finger_rates(rates, finger):
    """One finger's rates (or positions) from the padded ``(..., J)`` row: its own joints only."""
    return (rates[..., : len(finger.joints)] + 0.0).tolist()


def _vector(v):
    """A 3-vector as a list, or None where it is not finite (no value)."""
    return (v + 0.0).tolist() if np.isfinite(v).all() else None


def _placement(r, i, f, finger) -> dict:
    """Where finger ``f`` of row ``i`` is: its ``joint_positions`` (given, solved or tracked), its
    ``tip_error`` (null: a finger given inline has no tip link), ``within_limits``, its fingertip's
    ``tip_radius``, ``tip_center`` and ``tip_gap``, and ``tip_contact``, where its sphere faces the
    contact in its tip link's frame."""
    if r.joint_positions is None:
        return {}
    out = {
        "joint_positions": _finger_rates(r.joint_positions[i, f], finger),
        "tip_error": _number(r.tip_error[i, f]),
        "within_limits": bool(r.within_limits[i, f]),
    }
    if r.tip_center is not None:
        out["tip_radius"] = finger.tip_radius
        out["tip_center"] = _vector(r.tip_center[i, f])
        out["tip_gap"] = _number(r.tip_gap[i, f])
        out["tip_contact"] = _vector(r.tip_contact[i, f])
    return out


def hand_objects(block, order, warnings):
    """Per row, ``(hand object or None, {method key: {"joint_rates": ...}})``.

    The hand object is the README's ``hand`` (fingers in contact order);
    each method computed gains ``joint_rates``: per component in basis
    order, per finger, that component's joint rates.  Rows whose finger
    is near a singularity get a warning in ``warnings``.
    """
    r = block.results["hand"]
    applies = block.applies("hand")
    out = []
    for i in range(len(block)):
        hand = block.hands[i] if applies[i] else None
        if hand is None:
            out.append((None, {}))
            continue
        names = block.contact_names[i]
        fingers = []
        for f, finger in enumerate(hand.fingers):
            conditioning = float(r.finger_conditioning[i, f])
            fingers.append(
                {
                    "name": finger.name,
                    "contact": names[f],
                    "tip": finger.tip,
                    "joints": [j.name for j in finger.joints],
                    **_placement(r, i, f, finger),
                    "joint_rates": _finger_rates(r.rates[i, f], finger),
                    "rank": int(r.finger_rank[i, f]),
                    "residual": _number(r.finger_residual[i, f]),
                    "conditioning": _number(conditioning),
                    "velocity_limit_ratio": _number(r.finger_limit_ratio[i, f]),
                }
            )
            if conditioning < CONDITION_WARNING and r.status[i] == Status.OK:
                warnings[i].append(
                    f"hand: finger {names[f]} is near a singularity (conditioning {fmt_figure(conditioning)} < "
                    f"{CONDITION_WARNING:g}): its joint rates are large and sensitive"
                )
        obj = {"fingers": fingers, "velocity_limit_ratio": _number(r.velocity_limit_ratio[i]), "ok": bool(r.ok[i])}
        if not r.ok[i]:
            status = Status(int(r.status[i]))
            obj["error"] = {"code": status.code, "message": status_message(status, r.culprit[i], names)}
        more = {
            key: {"joint_rates": [[_finger_rates(c[f], fi) for f, fi in enumerate(hand.fingers)] for c in parts[i]]}
            for key, parts in r.components.items()
        }
        out.append((obj, more))
    return out
