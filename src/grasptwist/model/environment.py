"""The data types of the world around the object: a table and boxes (a grasp file's ``environment``).

Apart from :mod:`grasptwist.model` (which names them) so that a run without an environment
compiles none of their dataclasses' methods at start-up (bench/startup.py).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Obstacle", "Environment"]


@dataclass(frozen=True, eq=False)
class Obstacle:
    """A box the fingers must keep clear of, in the grasp frame.

    Attributes
    ----------
    size : numpy.ndarray
        ``(3,)`` edge lengths along the box's own x, y, z (centred at its origin).
    pose : numpy.ndarray
        ``(4, 4)`` rigid transform from the box's frame to the grasp's frame.
    line : int or None
        1-based line of its entry in the file.
    """

    size: np.ndarray
    pose: np.ndarray
    line: int | None = None


@dataclass(frozen=True, eq=False)
class Environment:
    """The world around the object: a table under it and boxes beside it (a grasp file's ``environment``).

    The geometry (distances, which finger hits what) is in
    ``grasptwist.engine.environment``.

    Attributes
    ----------
    table_height : float or None
        The table, a horizontal plane ``z = table_height`` of the grasp frame (gravity along
        -z) that the object rests on or above; None: no table.
    boxes : tuple of Obstacle
        Obstacles.
    clearance : float or None
        The least distance every part of a finger keeps from the table and the boxes (its
        ``clearance``, or ``--clearance``); None: ``grasptwist.engine.environment.CLEARANCE``.
    line : int or None
        1-based line where the ``environment``'s mapping starts in the file.
    """

    table_height: float | None = None
    boxes: tuple[Obstacle, ...] = ()
    clearance: float | None = None
    line: int | None = None
