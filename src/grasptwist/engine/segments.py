"""A path's segments, checked: what reading a grasp file's ``paths`` needs of
:mod:`~grasptwist.engine.path`, apart from it (a JSON resolve of a file with paths checks
them and never loads the path's engine, its results and their dataclasses).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from ..model import Segment

__all__ = ["FRAMES", "check_segments"]

#: Frames a segment's twist can be given in.
FRAMES = ("space", "body")

#: A rotation matrix of a pose target must be orthonormal to this.
_ROTATION_TOL = 1e-9


def check_segments(segments) -> tuple[Segment, ...]:
    """Validate a path and return its segments with float arrays.

    Parameters
    ----------
    segments : sequence of Segment

    Returns
    -------
    tuple of Segment
        The same segments, ``twist``, ``position``, ``rotation`` as float arrays.

    Raises
    ------
    ValueError
        Naming the bad field, e.g. ``segments[1].duration``.

    Examples
    --------
    >>> check_segments([Segment(2.0, twist=[0, 0, 1, 0, 0, 0])])[0].twist.tolist()
    [0.0, 0.0, 1.0, 0.0, 0.0, 0.0]
    >>> check_segments([Segment(0.0, twist=[0, 0, 1, 0, 0, 0])])
    Traceback (most recent call last):
    ...
    ValueError: segments[0].duration must be a finite number > 0, got 0.0
    """
    if isinstance(segments, Segment) or not hasattr(segments, "__iter__"):
        raise ValueError(f"segments must be a sequence of Segment, got {type(segments).__name__}")
    checked = []
    for k, s in enumerate(segments):
        where = f"segments[{k}]"
        if not isinstance(s, Segment):
            raise ValueError(f"{where} must be a Segment, got {type(s).__name__}")
        try:
            duration = float(s.duration)
        except (TypeError, ValueError):
            duration = math.nan
        if not (math.isfinite(duration) and duration > 0):
            raise ValueError(f"{where}.duration must be a finite number > 0, got {s.duration!r}")
        has_pose = s.position is not None or s.rotation is not None
        if s.twist is not None and has_pose:
            raise ValueError(f"{where} has both a twist and a pose target: give one")
        if s.twist is not None:
            if s.frame not in FRAMES:
                raise ValueError(f"{where}.frame must be 'space' or 'body', got {s.frame!r}")
            checked.append(replace(s, duration=duration, twist=_finite(s.twist, (6,), f"{where}.twist")))
            continue
        if s.position is None or s.rotation is None:
            raise ValueError(f"{where} needs a twist or a pose target (both position and rotation)")
        rotation = _finite(s.rotation, (3, 3), f"{where}.rotation")
        if not (np.abs(rotation.T @ rotation - np.eye(3)).max() <= _ROTATION_TOL and np.linalg.det(rotation) > 0):
            raise ValueError(f"{where}.rotation must be a rotation matrix (orthonormal, determinant +1)")
        # replace: what a segment carries besides (the rotation vector it was given by) stays
        checked.append(
            replace(s, duration=duration, position=_finite(s.position, (3,), f"{where}.position"), rotation=rotation)
        )
    if not checked:
        raise ValueError("segments must hold at least one segment")
    if not math.isfinite(sum(s.duration for s in checked)):
        raise ValueError("segments' durations add up beyond double precision (1.8e308)")
    return tuple(checked)


def _finite(a, shape, name):
    """``a`` as a float array of exactly ``shape`` with finite entries, else ValueError naming ``name``."""
    try:
        a = np.array(a, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be numbers of shape {shape}") from None
    if a.shape != shape:
        raise ValueError(f"{name} must have shape {shape}, got {a.shape}")
    if not np.isfinite(a).all():
        raise ValueError(f"{name} must be finite")
    return a
