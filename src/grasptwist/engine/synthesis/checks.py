"""The checks of a search's options, one per option, shared by the library and the command line.

:func:`grasptwist.synthesize` (and :func:`~.search.search`) and ``grasptwist synthesize`` refuse
the same values with the same words: the command line's options call these (a ``ValueError``
becomes a usage error naming the option), the search calls them on its keywords.

>>> check_count(3), check_seed(7), check_min_spacing(None)
(3, 7, None)
>>> check_count(2.5)
Traceback (most recent call last):
ValueError: count must be an integer from 1 to 10000, got 2.5
"""

from __future__ import annotations

import numpy as np

from ..forces.grasp_map import check_wrench

__all__ = [
    "MAX_COUNT",
    "MAX_CANDIDATES",
    "MAX_SEED",
    "check_count",
    "check_candidates",
    "check_seconds",
    "check_seed",
    "check_min_spacing",
    "check_tip_radius",
    "check_mass",
    "check_search_friction",
    "check_wrenches",
]

#: Grasps one search may return at most (``-n``).
MAX_COUNT = 10_000

#: Candidates one search may score at most (``--candidates``).
MAX_CANDIDATES = 10**9

#: The largest seed: records carry it as a signed 64-bit integer (JSON readers, Parquet's int64).
MAX_SEED = 2**63 - 1


def _is_integer(value) -> bool:
    return isinstance(value, (int, np.integer)) and not isinstance(value, bool)


def _is_number(value) -> bool:
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool)


def _integer(value, name, low, high) -> int:
    """``value`` an integer from ``low`` to ``high``, else ValueError in the options' words."""
    if not (_is_integer(value) and low <= value <= high):
        raise ValueError(f"{name} must be an integer from {low} to {high}, got {value!r}")
    return int(value)


def _finite(value, name, positive) -> float:
    """``value`` a finite number ``> 0`` (``positive``) or ``>= 0``, else ValueError."""
    if not (_is_number(value) and (value > 0 if positive else value >= 0) and value < np.inf):
        raise ValueError(f"{name} must be a finite number {'>' if positive else '>='} 0, got {value!r}")
    return float(value)


def check_count(count) -> int:
    """The grasps wanted: an integer from 1 to :data:`MAX_COUNT` (``-n``).

    >>> check_count(0)
    Traceback (most recent call last):
    ValueError: count must be an integer from 1 to 10000, got 0
    """
    return _integer(count, "count", 1, MAX_COUNT)


def check_candidates(candidates) -> int:
    """The candidates scored at most: an integer from 1 to :data:`MAX_CANDIDATES` (``--candidates``).

    >>> check_candidates(0)
    Traceback (most recent call last):
    ValueError: candidates must be an integer from 1 to 1000000000, got 0
    """
    return _integer(candidates, "candidates", 1, MAX_CANDIDATES)


def check_seconds(seconds) -> float | None:
    """The time allowed: a finite number of seconds > 0, or None for no limit (``--seconds``).

    >>> check_seconds(float("inf"))
    Traceback (most recent call last):
    ValueError: seconds must be a finite number > 0, got inf
    """
    return None if seconds is None else _finite(seconds, "seconds", positive=True)


def check_seed(seed) -> int:
    """The random numbers' seed: an integer from 0 to :data:`MAX_SEED` (``--seed``; the records
    carry it as a 64-bit integer, so a larger one is refused rather than written wrong).

    >>> check_seed(2**64)
    Traceback (most recent call last):
    ValueError: seed must be an integer from 0 to 9223372036854775807, got 18446744073709551616
    """
    return _integer(seed, "seed", 0, MAX_SEED)


def check_min_spacing(spacing) -> float | None:
    """The least distance between grasps returned: a finite number >= 0, or None for the default
    (``--min-spacing``).

    >>> check_min_spacing(float("nan"))
    Traceback (most recent call last):
    ValueError: min_spacing must be a finite number >= 0, got nan
    """
    return None if spacing is None else _finite(spacing, "min_spacing", positive=False)


def check_tip_radius(radius) -> float | None:
    """Every fingertip's radius: a finite number >= 0 (0: point fingertips), or None for each
    finger's own (``--tip-radius``).

    >>> check_tip_radius(float("inf"))
    Traceback (most recent call last):
    ValueError: tip_radius must be a finite number >= 0, got inf
    """
    return None if radius is None else _finite(radius, "tip_radius", positive=False)


def check_mass(mass) -> float | None:
    """The object's mass, replacing its own: a finite number > 0, or None (``--mass``).

    >>> check_mass(0)
    Traceback (most recent call last):
    ValueError: mass must be a finite number > 0, got 0
    """
    return None if mass is None else _finite(mass, "mass", positive=True)


def check_search_friction(friction) -> float:
    """The friction ``mu`` of every contact the search places: a number >= 0, ``inf`` for no limit
    (``--friction``; NaN is no coefficient).

    >>> check_search_friction(float("inf"))
    inf
    >>> check_search_friction(float("nan"))
    Traceback (most recent call last):
    ValueError: friction must be a number >= 0 (inf: no limit), got nan
    """
    if not (_is_number(friction) and friction >= 0):
        raise ValueError(f"friction must be a number >= 0 (inf: no limit), got {friction!r}")
    return float(friction)


def check_search_torsion(torsion, friction) -> float | None:
    """Soft contacts' torsional radius ``e > 0`` (a finite length; None: point contacts), which needs a friction
    ``> 0`` (torsional friction is friction).

    >>> check_search_torsion(0.01, 0.5)
    0.01
    >>> check_search_torsion(0.01, 0.0)
    Traceback (most recent call last):
    ValueError: soft contacts (torsion=0.01) need friction > 0: their torsion is friction
    """
    if torsion is None:
        return None
    if not (_is_number(torsion) and 0 < torsion < np.inf):
        raise ValueError(f"torsion must be a finite length > 0 (soft contacts' radius), got {torsion!r}")
    if not friction > 0:
        raise ValueError(f"soft contacts (torsion={torsion!r}) need friction > 0: their torsion is friction")
    return float(torsion)


def check_wrenches(wrenches) -> np.ndarray:
    """The wrenches every grasp must exert, ``(W, 6)`` finite numbers (one ``(6,)`` is ``W = 1``).

    >>> check_wrenches([0, 0, 9.81, 0, 0, 0]).shape
    (1, 6)
    >>> check_wrenches([[0, 0, float("nan"), 0, 0, 0]])
    Traceback (most recent call last):
    ValueError: wrenches[0] must be finite, got [0.0, 0.0, nan, 0.0, 0.0, 0.0]
    """
    w = check_wrench(wrenches).reshape(-1, 6)
    bad = np.flatnonzero(~np.isfinite(w).all(axis=1))
    if len(bad):
        raise ValueError(f"wrenches[{bad[0]}] must be finite, got {w[bad[0]].tolist()}")
    return w
