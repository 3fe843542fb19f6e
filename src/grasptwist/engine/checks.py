"""Validation of the engine's array arguments, done once where they enter.

Each ``check_*`` returns its argument as a float array and raises
``ValueError`` naming the argument when it cannot be one of the documented
shape: a wrong trailing shape, a ragged nested list, or values that are not
real numbers (strings, None, complex numbers, booleans).  Leading (batch)
axes are free.  Values are not judged here: NaN, infinities, zero normals
and degenerate grasps are per-row statuses of the result
(:class:`~grasptwist.engine.degeneracy.Status`), never exceptions.
"""

from __future__ import annotations

import numpy as np

__all__ = ["SHAPES", "check_points", "check_normals", "check_wrist", "check_twist"]

#: Trailing shape of each engine argument (after any leading batch axes).
SHAPES = {"points": (3, 3), "normals": (3, 3), "wrist": (3,), "twist": (6,)}

_WHAT = {"b": "booleans", "c": "complex numbers"}


def _check(a, name):
    trailing = SHAPES[name]
    if type(a) is not np.ndarray:
        try:
            a = np.asarray(a)
        except ValueError:  # numpy refuses ragged nesting
            raise ValueError(f"{name} must have shape {_want(trailing)}, got a ragged nested sequence") from None
    kind = a.dtype.kind
    if kind not in "fiu":
        raise ValueError(f"{name} must hold real numbers, got {_WHAT.get(kind, f'dtype {a.dtype}')}")
    if a.shape[-len(trailing) :] != trailing:  # also when a has fewer axes
        raise ValueError(f"{name} must have shape {_want(trailing)}, got {a.shape}")
    return a if a.dtype is _FLOAT else a.astype(_FLOAT)


_FLOAT = np.dtype(np.float64)


def _want(trailing):
    return "(..., " + ", ".join(map(str, trailing)) + ")"


def check_points(points) -> np.ndarray:
    """The contact points ``p_1, p_2, p_3`` of each grasp as floats, shape ``(..., 3, 3)`` (contact, xyz).

    >>> check_points([[0, 2, 2], [2, 0, 2], [2, 2, 0]]).dtype
    dtype('float64')
    >>> check_points([[0, 0], [1, 0], [0, 1]])
    Traceback (most recent call last):
    ValueError: points must have shape (..., 3, 3), got (3, 2)
    """
    return _check(points, "points")


def check_normals(normals) -> np.ndarray:
    """The surface normals at the contacts as floats, shape ``(..., 3, 3)``; any length (zero is a status).

    >>> check_normals(["x", "y", "z"])
    Traceback (most recent call last):
    ValueError: normals must hold real numbers, got dtype <U1
    """
    return _check(normals, "normals")


def check_wrist(wrist) -> np.ndarray:
    """The wrist point ``c`` as floats, shape ``(..., 3)``.

    >>> check_wrist([0, 0, 1]).tolist()
    [0.0, 0.0, 1.0]
    """
    return _check(wrist, "wrist")


def check_twist(twist) -> np.ndarray:
    """The object twist ``(omega; v)`` as floats, shape ``(..., 6)``, ``v`` the velocity at the origin.

    >>> check_twist([0, 0, 1, 0, 0])
    Traceback (most recent call last):
    ValueError: twist must have shape (..., 6), got (5,)
    """
    return _check(twist, "twist")
