"""The records of ``grasptwist synthesize``, their columns, their table and the grasp file they make.

A search's result (:class:`grasptwist.run.synthesize.Found`: its file, grasp name, wrench
names, contact names and the engine's :class:`~grasptwist.engine.synthesis.search.Synthesis`)
gives one record per grasp, best first::

    {"file", "grasp", "units", "rank", "ok": true,
     "contacts": [{"name", "point", "normal", "surface_distance"}, x3],
     "scores": {"total_normal_force": {wrench name: N}, "closure_friction",
                "epsilon" (or null), "conditioning": {"off_tangent", "tangent"} (null: not asked)},
     "contact_model": "point", or "soft" (--contact soft --torsion E, or the file's soft contacts),
     "joint_positions": {joint name: position} (null without a hand),
     "reach_error": [3] (null without a hand),
     "clearance": least distance of any finger from the environment (null without one),
     "simulation": {"held": true, "directions": [{"direction": "+x", "held",
                    "displacement", "rotation_deg"}, x 6]} (with --simulate; else null),
     "search": {"candidates", "seconds", "seed", "stopped_by"}, "warnings": [the object's]}

With a hand, finger ``f`` touches contact ``f``; ``reach_error`` is each finger's distance, by
forward kinematics at ``joint_positions``, from its tip link's origin to its fingertip's
centre ``point - tip_radius * normal``.

A search that finds nothing gives one error record (``no-grasp``) naming the tightest
constraint and how close the best candidate came.  The flat columns (CSV, Parquet)
give the largest total over the wrenches as ``total_normal_force``.  Nothing is computed
here: the records say what the search found.
"""

from __future__ import annotations

import os
from enum import IntEnum
from typing import IO

import numpy as np
import yaml

from ..engine.se3 import matrix_to_quaternion
from ..results import joint_column_names
from .columns import ColumnSet
from .csv_rows import lines
from .names import escaped
from .numbers import fmt_number

__all__ = [
    "NO_GRASP",
    "synthesis_records",
    "failure_record",
    "grasp_documents",
    "SYNTHESIS_COLUMNS",
    "SynthesisTable",
]

#: The error code of a search that found no feasible grasp.
NO_GRASP = "no-grasp"

_METHODS = ("off_tangent", "tangent")


def _float(v):
    return None if v is None or not np.isfinite(v) else float(v)


def synthesis_records(found) -> list[dict]:
    """One record per grasp found, best first (module docstring)."""
    s = found.synthesis
    search = _search(s)
    out = []
    for k in range(len(s.points)):
        contacts = [
            {
                "name": found.contact_names[i],
                "point": s.points[k, i].tolist(),
                "normal": s.normals[k, i].tolist(),
                "surface_distance": float(s.surface_distance[k, i]),
                "edge_distance": _float(s.edge_distance[k, i]),
                **({} if s.tip_center is None else {"tip_center": s.tip_center[k, i].tolist()}),
            }
            for i in range(3)
        ]
        scores = {
            "total_normal_force": {name: float(v) for name, v in zip(found.wrench_names, s.total_normal_force[k])},
            "closure_friction": _float(s.closure_friction[k]),
            "epsilon": None if s.epsilon is None else _float(s.epsilon[k]),
            "conditioning": {m: _float(c) for m, c in zip(_METHODS, s.conditioning[k])},
            "hold_friction": _float(s.hold_friction[k]),
            "robustness": float(s.robustness[k]),
        }
        out.append(
            {
                "file": escaped(found.file, controls=False),
                "grasp": escaped(found.name, controls=False),
                "units": found.units,
                "rank": k + 1,
                "ok": True,
                "contacts": contacts,
                "scores": scores,
                "contact_model": "point" if found.torsion is None else "soft",
                "joint_positions": _joint_positions(found, k),
                "reach_error": None if s.reach_error is None else s.reach_error[k].tolist(),
                "clearance": None if found.clearance is None else _float(found.clearance[k]),
                "simulation": None if found.simulated is None else _simulation(found.simulated[k]),
                "search": search,
                "warnings": list(found.warnings),
            }
        )
    return out


def _simulation(test) -> dict:
    """A grasp's hold test in MuJoCo (``synthesize --simulate``): held, and each direction's movement."""
    return {
        "held": test.held,
        "directions": [
            {
                "direction": d.name,
                "held": d.held,
                "displacement": _float(d.displacement),
                "rotation_deg": _float(np.degrees(d.rotation)),
            }
            for d in test.directions
        ],
    }


def _joint_positions(found, k):
    if found.hand is None:
        return None
    return {name: float(q) for name, q in zip(found.hand.joint_names, found.synthesis.joint_positions[k])}


def failure_record(found) -> dict:
    """The one record of a search that found nothing: why, as an error (exit 1)."""
    f, s = found.synthesis.failure, found.synthesis
    error = {
        "code": NO_GRASP,
        "message": f"grasp '{found.name}': no feasible grasp in {s.candidates} candidates: {f.message}",
        "line": found.line,
        "column": None,
        "constraint": f.constraint,
        "best": _float(f.best),
        "needed": _float(f.needed),
    }
    return {
        "file": escaped(found.file, controls=False),
        "grasp": escaped(found.name, controls=False),
        "ok": False,
        "error": error,
        "errors": [error],
        "search": _search(s),
    }


def _search(s) -> dict:
    """What the search spent, its seed, and which limit stopped it (``candidates`` or ``seconds``)."""
    return {
        "candidates": int(s.candidates),
        "seconds": float(s.seconds),
        "seed": int(s.seed),
        "stopped_by": s.stopped_by,
    }


def _object_node(obj, folder, file):
    """The ``object`` section of a grasp file for ``obj``, read from the grasp (or mesh) file
    ``file``: a mesh's path, which ``file`` names from its own folder, made relative to ``folder``
    (the new file's), so that the new file reads back from anywhere; with its scale, when not 1."""
    shape = obj.shape
    if shape.kind == "mesh":
        node = {"mesh": _mesh_path(shape.source, file, folder)}
        if shape.scale is not None and not (shape.scale == 1).all():
            scale = shape.scale.tolist()
            node["scale"] = scale[0] if len(scale) == 1 else scale
    elif shape.kind == "box":
        node = {"box": shape.size.tolist()}
    elif shape.kind == "sphere":
        node = {"sphere": float(shape.size[0])}
    else:
        node = {shape.kind: {"radius": float(shape.size[0]), "height": float(shape.size[1])}}
    rotation, position = obj.pose[:3, :3], obj.pose[:3, 3]
    if not np.array_equal(obj.pose, np.eye(4)):
        node["pose"] = {"position": position.tolist(), "rotation": _quaternion_of(rotation)}
    if obj.mass is not None:
        node["mass"] = float(obj.mass)
    elif obj.density is not None:
        node["density"] = float(obj.density)
    return node


def _mesh_path(source, file, folder):
    """A mesh's reference ``source``, named from the folder of ``file``, as a path from ``folder``
    (a ``package://`` reference is the same from anywhere).

    >>> _mesh_path("meshes/cube.stl", "objects/cube.yaml", os.path.abspath("out"))
    '../objects/meshes/cube.stl'
    """
    if source.startswith("package://"):
        return source
    return os.path.relpath(os.path.join(os.path.dirname(os.path.abspath(file)), source), folder)


def _environment_node(env) -> dict:
    """The ``environment`` section: the table, the boxes, the clearance (as the input gave them)."""
    node = {}
    if env.table_height is not None:
        node["table"] = {"height": float(env.table_height)}
    if env.boxes:
        node["boxes"] = [
            {
                "size": box.size.tolist(),
                "pose": {"position": box.pose[:3, 3].tolist(), "rotation": _quaternion_of(box.pose[:3, :3])},
            }
            for box in env.boxes
        ]
    if env.clearance is not None:
        node["clearance"] = float(env.clearance)
    return node


def _quaternion_of(r) -> list:
    """``(w, x, y, z)``, ``w >= 0``, of a rotation matrix, as a YAML list (the engine's Shepperd)."""
    return matrix_to_quaternion(np.asarray(r, float)).tolist()


def _hand_node(found, k, folder):
    """The ``hand`` section of grasp ``k``: a URDF at its joint positions (the reference relative to
    ``folder``), or inline joints moved to them (inline joints are given at the configuration)."""
    hand, q = found.hand, found.synthesis.joint_positions[k]
    if hand.source is not None:
        urdf = hand.source
        if not urdf.startswith("package://") and not os.path.isabs(urdf):
            urdf = os.path.relpath(os.path.join(os.path.dirname(os.path.abspath(found.hand_file)), urdf), folder)
        return {
            "urdf": urdf,
            "joint_positions": {name: float(v) for name, v in zip(hand.joint_names, q)},
            "fingers": [{"name": f.name, "tip": f.tip, "tip_radius": float(f.tip_radius)} for f in hand.fingers],
        }
    fingers = []
    for f, (screws, points) in zip(hand.fingers, found.joints_at[k]):
        joints = []
        for joint, screw, point in zip(f.joints, screws, points):
            axis = screw[:3] if joint.type == "revolute" else screw[3:]
            node = {"name": joint.name, "type": joint.type, "axis": axis.tolist(), "point": point.tolist()}
            if joint.velocity_limit is not None:
                node["velocity_limit"] = float(joint.velocity_limit)
            joints.append(node)
        fingers.append({"name": f.name, "tip_radius": float(f.tip_radius), "joints": joints})
    return {"fingers": fingers}


def _path_node(path) -> dict:
    """An object path as a grasp file writes it: each segment a screw, or a pose target (its rotation as given)."""
    segments = []
    for seg in path.segments:
        node = {"duration": float(seg.duration)}
        if seg.twist is not None:
            node["screw"] = np.asarray(seg.twist).tolist()
        else:
            pose = {"position": np.asarray(seg.position).tolist()}
            if seg.rotvec is not None:
                pose["rotvec"] = np.asarray(seg.rotvec).tolist()  # as written: its size is judged on reading
            else:
                pose["rotation"] = _quaternion_of(np.asarray(seg.rotation))
            node["pose"] = pose
        segments.append(node)
    frames = {seg.frame for seg in path.segments if seg.twist is not None}
    return {"name": path.name, **({"frame": "body"} if frames == {"body"} else {}), "segments": segments}


def grasp_documents(found, folder: str) -> str:
    """The grasps found as grasp-file documents (YAML, ``---`` between them), read back by every command.

    Each keeps the input's object, units, wrist and friction, its wrenches by name (the weight as
    the object's mass, or ``mass`` and ``center_of_mass``, when one of them is ``hold``), its twists
    and paths (in the grasp frame, as the contacts: valid for any contacts), and gives the contacts
    found.
    """
    s = found.synthesis
    docs = []
    for k in range(len(s.points)):
        doc = {"name": f"{found.name}-{k + 1}"}
        if found.units is not None:
            doc["units"] = found.units
        if found.wrist is not None:
            doc["wrist"] = np.asarray(found.wrist).tolist()
        doc["object"] = _object_node(found.object, folder, found.file)
        soft = {} if found.torsion is None else {"model": "soft", "torsion": float(found.torsion)}
        doc["contacts"] = [
            {"name": found.contact_names[i], "point": s.points[k, i].tolist(), "normal": s.normals[k, i].tolist()}
            | soft
            for i in range(3)
        ]
        if found.twists:
            doc["twists"] = [{"name": t.name, "screw": np.asarray(t.screw).tolist()} for t in found.twists]
        if found.paths:
            doc["paths"] = [_path_node(path) for path in found.paths]
        doc["friction"] = float(found.friction)
        wrenches = [
            {"name": name, "wrench": np.asarray(w).tolist()}
            for name, w in zip(found.wrench_names, found.wrenches)
            if name != found.hold_name
        ]
        if found.hold is not None:
            mass, center, gravity = found.hold
            if found.object.mass is None and found.object.density is None:  # else the object's weight is the hold
                doc.update(mass=float(mass), center_of_mass=np.asarray(center).tolist())
            doc["gravity"] = np.asarray(gravity).tolist()
        if wrenches:
            doc["wrenches"] = wrenches
        if found.hand is not None:
            doc["hand"] = _hand_node(found, k, folder)
        if found.environment is not None:
            doc["environment"] = _environment_node(found.environment)
        docs.append(yaml.safe_dump(doc, sort_keys=False, default_flow_style=None))
    return "---\n".join(docs)


# -- columns ------------------------------------------------------------------------

_XYZ = ("x", "y", "z")
_OWN = ("file", "grasp", "rank", "ok", "error")
_COLUMNS = (
    *(f"p{i}_{a}" for i in (1, 2, 3) for a in _XYZ),
    *(f"n{i}_{a}" for i in (1, 2, 3) for a in _XYZ),
    *(f"surface_distance{i}" for i in (1, 2, 3)),
    "total_normal_force",
    "closure_friction",
    "epsilon",
    "conditioning_off_tangent",
    "conditioning_tangent",
    "hold_friction",
    "robustness",
    *(f"edge_distance{i}" for i in (1, 2, 3)),
    "clearance",
    "candidates",
    "seconds",
    "seed",
    "stopped_by",
)
_HEADER = ",".join((*_OWN, *_COLUMNS)).encode() + b"\n"
_REACH = tuple(f"reach_error{i}" for i in (1, 2, 3))


def _hand_columns(hand) -> tuple[str, ...]:
    """The columns a run's hand adds: each finger's reach error, then its joints' positions ``q_<finger>_<joint>``."""
    return () if hand is None else (*_REACH, *joint_column_names("q", hand))


def _header(hand=None) -> bytes:
    return _HEADER if hand is None else ",".join((*_OWN, *_COLUMNS, *_hand_columns(hand))).encode() + b"\n"


def _typed(hand=None) -> dict:
    types = {"file": "U", "grasp": "U", "rank": "int64", "ok": "?", "error": "U"}
    types.update({name: "float64" for name in (*_COLUMNS, *_hand_columns(hand))})
    types.update(candidates="int64", seed="int64", stopped_by="U")
    return types


def _joint_values(found, hand) -> dict:
    """The hand's columns of ``found``'s grasps: NaN where its hand is not the run's (another file's)."""
    s, k = found.synthesis, len(found)
    names = joint_column_names("q", hand)
    same = found.hand is not None and joint_column_names("q", found.hand) == names
    out = {name: s.reach_error[:, i] if same else np.full(k, np.nan) for i, name in enumerate(_REACH)}
    joints = [j for f in found.hand.fingers for j in f.joint_index] if same else [None] * len(names)
    out.update({n: s.joint_positions[:, j] if same else np.full(k, np.nan) for n, j in zip(names, joints)})
    return out


def _flat(found, order="omega-v", hand=None, typed=False) -> dict:
    s, k = found.synthesis, len(found)
    nan = np.full(k, np.nan)
    columns = {
        "file": np.array([found.file] * k, dtype=object),
        "grasp": np.array([found.name] * k, dtype=object),
        "rank": np.arange(1, k + 1),
        "ok": np.ones(k, bool),
        "error": np.ma.masked_all(k, dtype=object),
    }
    columns.update({f"p{i + 1}_{a}": s.points[:, i, j] for i in range(3) for j, a in enumerate(_XYZ)})
    columns.update({f"n{i + 1}_{a}": s.normals[:, i, j] for i in range(3) for j, a in enumerate(_XYZ)})
    columns.update({f"surface_distance{i + 1}": s.surface_distance[:, i] for i in range(3)})
    columns["total_normal_force"] = s.total_normal_force.max(axis=1, initial=-np.inf) if k else nan
    columns["closure_friction"] = s.closure_friction
    columns["epsilon"] = nan if s.epsilon is None else s.epsilon
    columns["conditioning_off_tangent"] = s.conditioning[:, 0]
    columns["conditioning_tangent"] = s.conditioning[:, 1]
    columns["hold_friction"] = s.hold_friction
    columns["robustness"] = s.robustness
    columns.update({f"edge_distance{i + 1}": s.edge_distance[:, i] for i in range(3)})
    columns["clearance"] = nan if found.clearance is None else np.asarray(found.clearance, float)
    columns["candidates"] = np.full(k, s.candidates)
    columns["seconds"] = np.full(k, s.seconds)
    columns["seed"] = np.full(k, s.seed)
    columns["stopped_by"] = np.array([s.stopped_by] * k, dtype=object)
    if hand is not None:
        columns.update(_joint_values(found, hand))
    for name, a in columns.items():
        if a.dtype.kind == "f":
            columns[name] = np.ma.masked_invalid(a)
    return columns


def _arrays(found, order="omega-v", hand=None) -> dict:
    return {name: np.ma.getdata(a) for name, a in _flat(found, hand=hand).items()}


def _error_row(rec: dict, hand=None) -> bytes:
    err = rec["error"]
    row = [rec["file"], rec.get("grasp", ""), "", "false", f"{err['code']}: {err['message']}"]
    pad = [""] * (len(_COLUMNS) + len(_hand_columns(hand)))
    return lines({str(j): np.array([v], dtype=object) for j, v in enumerate(row + pad)})[0]


class _Statuses(IntEnum):
    OK = 0


#: The synthesis family's columns (CSV and Parquet; no npz).
SYNTHESIS_COLUMNS = ColumnSet(
    header=_header,
    flat=_flat,
    arrays=_arrays,
    error_row=_error_row,
    statuses=_Statuses,
    typed_header=_typed,
)


# -- table ----------------------------------------------------------------------------


class SynthesisTable:
    """The grasps found as a plain table (``write(record)``, ``close()``): per object its grasps, best
    first, each with its scores and contacts."""

    def __init__(self, out: IO[bytes], digits: int = 4, **_):
        self.out = out
        self.digits = digits
        self.current = None

    def _line(self, text: str = "") -> None:
        self.out.write(text.encode() + b"\n")

    def _number(self, v) -> str:
        return fmt_number(v, self.digits)

    def write(self, rec: dict) -> None:
        if "error" in rec:  # its line is on stderr; tables carry results only
            return
        here = (rec["file"], rec["grasp"])
        if here != self.current:
            if self.current is not None:
                self._line()
            self._line(f"{escaped(rec['file'])}: grasp '{escaped(rec['grasp'])}'")
            self.current = here
        scores = rec["scores"]
        totals = ", ".join(f"{escaped(n)} {self._number(v)}" for n, v in scores["total_normal_force"].items())
        cond = ", ".join(f"{m} {self._number(c)}" for m, c in scores["conditioning"].items() if c is not None)
        extra = f"  robustness {self._number(scores['robustness'])}  hold mu {self._number(scores['hold_friction'])}"
        extra += "" if scores["epsilon"] is None else f"  epsilon {self._number(scores['epsilon'])}"
        extra += f"  conditioning: {cond}" if cond else ""  # none: the off-tangent method alone, no wrist
        self._line(
            f"  #{rec['rank']}  total normal force: {totals}  closure mu {self._number(scores['closure_friction'])}"
            f"{extra}"
        )
        for c in rec["contacts"]:
            point = ", ".join(self._number(v) for v in c["point"])
            normal = ", ".join(self._number(v) for v in c["normal"])
            self._line(f"    {escaped(c['name'])}: point ({point})  normal ({normal})")
        if rec.get("joint_positions"):
            joints = ", ".join(f"{escaped(n)} {self._number(q)}" for n, q in rec["joint_positions"].items())
            self._line(f"    joints: {joints}")

    def close(self) -> None:
        pass
