"""The ``paths`` section: object paths, each a list of segments (a constant twist or a pose target)."""

from __future__ import annotations

import numpy as np

from ...engine import screws
from ...model import ObjectPath, Segment
from .problems import Reject, join, located
from .twists import twist_parts
from .values import Section, describe, read_entry_name, read_mapping, read_number, read_sequence, read_vector

__all__ = ["PATH_KEYS", "SEGMENT_KEYS", "POSE_KEYS", "SECTION", "read_paths", "read_pose"]

PATH_KEYS = ("name", "frame", "segments")
SEGMENT_KEYS = ("duration", "screw", "angular", "linear", "at", "pose")
POSE_KEYS = ("position", "rotation", "rotvec")


def read_paths(node, problems):
    """The object paths, their segments checked (None after a problem)."""
    items = read_sequence(node, "paths", problems)
    if items is None:
        return None
    names, found = {}, []
    for i, item in enumerate(items):
        path = f"paths[{i}]"
        fields = read_mapping(item, path, PATH_KEYS, ("segments",), problems)
        if fields is None:
            continue
        read_entry_name(fields, item, "paths", i, names, problems)
        frame = _frame(fields["frame"], path + ".frame", problems) if "frame" in fields else "space"
        if "segments" in fields:  # checked whatever the frame, so that every problem is found
            found.append(_segments(fields["segments"], path + ".segments", frame or "space", problems))
    if problems.count:
        return None
    return tuple(ObjectPath(name, segments, item.line) for name, segments, item in zip(names, found, items))


def _frame(node, path, problems):
    """``space`` or ``body``."""
    if node.kind == "invalid":
        return None
    from ...engine.segments import FRAMES  # paths checked only for documents with paths

    if node.kind != "scalar" or node.value not in FRAMES:
        problems.add(Reject("invalid-frame", path, f"expected space or body, got {describe(node)}", **located(node)))
        return None
    return node.value


def _segments(node, path, frame, problems):
    """A path's segments (None after a problem)."""
    items = read_sequence(node, path, problems)
    if items is None:
        return None
    if not items:
        problems.add(Reject("empty-path", path, "a path needs at least one segment", **located(node)))
        return None
    segments = [_segment(item, f"{path}[{k}]", frame, problems) for k, item in enumerate(items)]
    if problems.count:
        return None
    from ...engine.segments import check_segments

    try:
        return check_segments(segments)
    except ValueError as exc:  # what only the whole path shows: its durations adding up beyond 1.8e308
        problems.add(Reject("invalid-duration", path, str(exc), **located(node)))
        return None


def _segment(item, path, frame, problems):
    """One segment: a ``duration`` and a constant twist or a ``pose`` target."""
    fields = read_mapping(item, path, SEGMENT_KEYS, ("duration",), problems)
    if fields is None:
        return None
    duration = read_number(fields["duration"], path + ".duration", problems) if "duration" in fields else None
    if duration is not None and not duration > 0:
        problems.add(
            Reject(
                "invalid-duration", path + ".duration", f"must be > 0, got {duration!r}", **located(fields["duration"])
            )
        )
    if "pose" in fields:
        _conflicts(
            fields, path, ("screw", "angular", "linear", "at"), "'pose' (give a twist or a pose target)", problems
        )
        pose = read_pose(fields["pose"], path + ".pose", problems)
        return None if pose is None else Segment(duration, position=pose[0], rotation=pose[1], **pose[2])
    if not {"screw", "angular", "linear"} & set(fields):
        problems.add(
            Reject(
                "missing-key",
                path,
                "needs a twist ('screw', or 'angular' and/or 'linear') or a 'pose'",
                **located(item),
            )
        )
        return None
    parts = twist_parts(fields, item, path, problems)
    if parts is None:
        return None
    with np.errstate(over="ignore", invalid="ignore"):
        screw = screws.twist_at(*(np.array(p) for p in parts))
    if not np.isfinite(screw).all():
        problems.add(
            Reject(
                "non-finite",
                path,
                "the velocity of the origin overflows (linear + angular x (origin - at))",
                **located(item),
            )
        )
        return None
    return Segment(duration, twist=screw, frame=frame)


def _conflicts(fields, path, others, what, problems):
    """A ``conflicting-keys`` problem for each key of ``others`` given beside ``what``."""
    for other in others:
        if other in fields:
            problems.add(
                Reject(
                    "conflicting-keys", join(path, other), f"cannot be combined with {what}", **located(fields[other])
                )
            )


def read_pose(node, path, problems):
    """``(position, rotation matrix, given)`` of a pose (a path's target, an object's place): position default zero, rotation a
    quaternion ``(w, x, y, z)`` or a rotation vector, default none; ``given`` the rotation vector
    as written and where (the :class:`~grasptwist.model.Segment` keywords), if one was."""
    from ...engine import se3

    fields = read_mapping(node, path, POSE_KEYS, (), problems)
    if fields is None:
        return None
    position = read_vector(fields["position"], 3, path + ".position", problems) if "position" in fields else [0.0] * 3
    rotation, given = np.eye(3), {}
    if "rotation" in fields:
        _conflicts(fields, path, ("rotvec",), "'rotation' (give a quaternion or a rotation vector)", problems)
        quaternion = read_vector(fields["rotation"], 4, path + ".rotation", problems)
        if quaternion is not None and any(quaternion):
            # scaled first: the engine normalises it, and a huge one must not overflow on the way
            rotation = se3.quaternion_to_matrix(np.divide(quaternion, np.abs(quaternion).max()))
        elif quaternion is not None:
            problems.add(
                Reject(
                    "invalid-rotation",
                    path + ".rotation",
                    "a quaternion (w, x, y, z) of zero length has no rotation",
                    **located(fields["rotation"]),
                )
            )
    elif "rotvec" in fields:
        rotvec = read_vector(fields["rotvec"], 3, path + ".rotvec", problems)
        if rotvec is not None:
            with np.errstate(over="ignore", invalid="ignore"):
                rotation = se3.rotvec_to_matrix(rotvec)
            given = {"rotvec": np.array(rotvec), **located(fields["rotvec"])}
            if not np.isfinite(rotation).all():
                problems.add(
                    Reject(
                        "non-finite",
                        path + ".rotvec",
                        "the rotation overflows double precision (an angle beyond about 1e154 radians)",
                        **located(fields["rotvec"]),
                    )
                )
    if position is None or problems.count:
        return None
    return np.array(position), rotation, given


def _read(fields, found, problems):
    paths = read_paths(fields["paths"], problems) if "paths" in fields else ()
    return None if paths is None else {"paths": paths}


SECTION = Section(("paths",), _read)
