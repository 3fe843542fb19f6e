"""Records of ``grasptwist forces``: one per (grasp, wrench), the JSON contract.

Built from a :class:`~grasptwist.run.forces.ForceBlock`'s columns; nothing
here computes: every number and status comes from the engine.  A part that
failed holds ``{"error": {"code", "message"}}``, a part that does not apply
(no wrench, no friction) is ``null``.
"""

from __future__ import annotations

import numpy as np

from ..engine.forces.grasp_map import ForceStatus, force_status_message
from ..engine.forces.grip import load_words
from .columns import ColumnSet, contact_models, force_arrays, force_columns, force_typed_header
from .csv_rows import FORCE_HEADER, force_error_row
from .names import escaped, escaped_each
from .records import clearances, outward_warning, surface_distances

__all__ = ["WRENCH_COLUMNS", "force_records", "GRIP_FIELDS", "CLOSURE_FIELDS", "NO_FRICTION_WARNING"]

#: The grip object's numbers, in order (then ``safety``, ``dual`` and ``gap``: its certificate).
GRIP_FIELDS = ("force", "squeeze", "normal_force", "tangential_force", "friction_used", "total_normal_force")

#: The closure object's fields (``force_closure`` and ``epsilon`` judged with ``mu / safety``).
CLOSURE_FIELDS = ("force_closure", "closure_friction", "epsilon", "safety", "contact_model")

NO_FRICTION_WARNING = "grip skipped: the grasp has no friction (give 'friction:' in the file or --friction MU)"


def _lists(a):
    """Row lists of ``a`` with no ``-0.0`` (a round-off sign on zero reads oddly)."""
    with np.errstate(invalid="ignore"):
        return (a + 0.0).tolist()


def _error(status, culprit):
    s = ForceStatus(int(status))
    message = force_status_message(s, culprit)
    # cannot-hold's sentence starts with its code already
    return {"error": {"code": s.code, "message": message.removeprefix(f"{s.code}: ")}}


def _soft_manipulating(status, culprit) -> str:
    """The warning of a soft grip's manipulating forces that failed: they are the point contacts' ``G^+ w``
    (``collinear-contacts`` for a pinch the soft pads' torsions hold), so the record stays ok on its grip."""
    s = ForceStatus(int(status))
    message = force_status_message(s, culprit).removeprefix(f"{s.code}: ")
    return f"manipulating: {s.code}: {message} (G^+ w of point contacts, not the soft ones': the record's ok is its grip's)"


def _grip_error(status, culprit, certificate, points):
    """The grip's error object; with a Farkas ``certificate`` (where one exists) in numbers and in words."""
    rec = _error(status, culprit)
    if certificate is not None:
        rec["error"]["message"] += f"; it {load_words(certificate, points)}"
        rec["error"]["certificate"] = certificate
    return rec


def _number(x):
    return None if x != x else x  # NaN -> null


def force_records(block) -> list[dict]:
    """The records of a block's rows."""
    r = block.result
    has_wrench, has_friction = block.has_wrench.tolist(), block.has_friction.tolist()
    points, normals, wrench, friction = (_lists(a) for a in (block.points, block.normals, block.wrench, block.friction))
    manipulating = _lists(r.manipulating)
    grip = {name: _lists(getattr(r, name)) for name in GRIP_FIELDS + ("dual", "gap", "torsion")}
    certificate = [None if c[0] != c[0] else c for c in _lists(r.certificate)]
    closure_friction, epsilon = r.closure_friction.tolist(), r.epsilon.tolist()
    force_closure = r.force_closure.tolist()
    model = contact_models(block).tolist()
    outward = block.outward().any(axis=-1).tolist()
    soft, ok = block.soft_rows().tolist(), (~block.failed_rows()).tolist()
    distance = surface_distances(block)
    clearance = clearances(block)
    out = []
    for i in range(len(block)):
        names = escaped_each(block.contact_names[i])
        warnings = [outward_warning(block, i)] if outward[i] else []
        warnings += block.grasp_warnings[i] if block.grasp_warnings is not None else ()
        rec = {
            "file": escaped(block.file[i], controls=False),
            "grasp": escaped(block.grasp[i], controls=False),
            "units": block.units[i],
            "wrench": {"name": escaped(block.wrench_name[i], controls=False), "wrench": wrench[i]}
            if has_wrench[i]
            else None,
            "contacts": [
                {"name": names[c], "point": points[i][c], "normal": normals[i][c], "surface_distance": distance[i][c]}
                for c in range(3)
            ],
            "friction": friction[i] if has_friction[i] else None,
            "clearance": clearance[i],
        }
        if not has_wrench[i]:
            rec["manipulating"] = None
        elif r.manipulating_status[i] and soft[i]:  # the point contacts' G^+ w: a warning, the grip answers
            rec["manipulating"] = None
            warnings.append(_soft_manipulating(r.manipulating_status[i], r.manipulating_culprit[i]))
        elif r.manipulating_status[i]:
            rec["manipulating"] = _error(r.manipulating_status[i], r.manipulating_culprit[i])
        else:
            rec["manipulating"] = {"force": manipulating[i]}
        if not has_wrench[i]:
            rec["grip"] = None
        elif not has_friction[i]:
            rec["grip"] = None
            warnings.append(NO_FRICTION_WARNING)
        elif r.grip_status[i]:
            rec["grip"] = _grip_error(r.grip_status[i], r.grip_culprit[i], certificate[i], points[i])
        else:
            rec["grip"] = {name: grip[name][i] for name in GRIP_FIELDS}
            if rec["grip"]["squeeze"][0] != rec["grip"]["squeeze"][0]:  # collinear contacts: no three squeezes
                rec["grip"]["squeeze"] = None
            rec["grip"]["safety"] = r.safety
            rec["grip"]["dual"], rec["grip"]["gap"] = grip["dual"][i], grip["gap"][i]
            rec["grip"]["contact_model"] = model[i]
            rec["grip"]["torsion"] = grip["torsion"][i]
        rec["closure"] = {
            "force_closure": force_closure[i] if has_friction[i] else None,
            "closure_friction": _number(closure_friction[i]),
            "epsilon": _number(epsilon[i]),
            "safety": r.safety,
            "contact_model": model[i],
        }
        status = ForceStatus(int(r.closure_status[i]))
        if status not in (ForceStatus.OK, ForceStatus.NO_CLOSURE):
            warnings.append(f"closure: {status.code}: {force_status_message(status, r.closure_culprit[i])}")
        rec["warnings"] = warnings
        rec["ok"] = ok[i]
        out.append(rec)
    return out


#: The wrench family's columns (``forces`` rows): no joints; npz's tables of names only where there are names.
WRENCH_COLUMNS = ColumnSet(
    header=lambda hand=None: FORCE_HEADER,
    flat=lambda block, order="omega-v", hand=None, typed=False: force_columns(block, typed),
    arrays=lambda block, order="omega-v", hand=None: force_arrays(block),
    error_row=lambda rec, hand=None: force_error_row(rec),
    statuses=ForceStatus,
    typed_header=lambda hand=None: force_typed_header(),
    name_tables=False,
)
