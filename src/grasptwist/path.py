"""Following an object path (gross manipulation): the public API.

>>> import numpy as np
>>> from grasptwist.path import Segment, integrate
>>> integrate([Segment(1.0, twist=[0, 0, 0, 1, 0, 0])], [0.5]).position.tolist()
[[0.5, 0.0, 0.0]]

The math is in ``grasptwist.engine.path`` (a path's segments checked in ``grasptwist.engine.segments``); rigid motions in ``grasptwist.engine.se3``.
"""

from .engine.path import (
    METHODS,
    Crossing,
    FollowResult,
    PathDegeneracies,
    Poses,
    degeneracies,
    follow,
    integrate,
)
from .engine.segments import FRAMES, check_segments
from .engine.tracking import FingerTrack, track_finger
from .model import ObjectPath, Segment

__all__ = [
    "Segment",
    "ObjectPath",
    "integrate",
    "follow",
    "degeneracies",
    "track_finger",
    "FingerTrack",
    "check_segments",
    "Poses",
    "FollowResult",
    "Crossing",
    "PathDegeneracies",
    "FRAMES",
    "METHODS",
]
