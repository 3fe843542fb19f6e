r"""Length units: a grasp file's unit in metres, and whether an object's size fits its unit and its hand.

Lengths are never converted: every command computes and reports in the grasp file's own unit
(``units``; metres when the file names none).  Three things do depend on how long that unit is,
and go through :func:`unit_length`:

- a ``density`` is in kg/m^3 and a ``mass`` in kg whatever ``units`` says, so a volume
  :math:`V` in cubed file units weighs

  .. math::

      m = \rho\, V\, s^3, \qquad s = \text{metres per file unit};

- a mesh file in a unit of its own (``mesh: {file, units}``) is scaled by
  :math:`s_\text{mesh} / s` into the grasp file's unit;
- the judgements below, which warn (never refuse) when a size looks like a unit mix-up.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "LENGTH_UNITS",
    "HAND_FIT",
    "METRE_SPAN",
    "unit_length",
    "largest_extent",
    "fingers_reach",
    "hand_fit_warning",
    "mesh_span_warning",
]

#: The length units a grasp file's ``units`` (and a mesh's own) may name, in metres.  Another
#: label is still a label (echoed in outputs), but nothing that needs its length can use it.
LENGTH_UNITS = {
    "km": 1e3,
    "m": 1.0,
    "dm": 1e-1,
    "cm": 1e-2,
    "mm": 1e-3,
    "um": 1e-6,
    "µm": 1e-6,
    "nm": 1e-9,
    "in": 0.0254,
    "ft": 0.3048,
}

#: An object whose largest extent is over this many times the fingers' reach, or under its
#: inverse, does not fit the hand (a warning): one of the two is most likely in another unit.
HAND_FIT = 10.0

#: Without a hand, a mesh read in metres whose largest extent is outside this range (1 mm to
#: 5 m) is most likely in another unit (a warning): objects held by three fingers are neither.
METRE_SPAN = (1e-3, 5.0)


def unit_length(units: str | None) -> float | None:
    """How many metres one ``units`` is: 1 for no unit (metres), None for a label that is no length unit.

    >>> unit_length("mm"), unit_length(None), unit_length("furlong")
    (0.001, 1.0, None)
    """
    if units is None:
        return 1.0
    return LENGTH_UNITS.get(units)


def largest_extent(kind: str, size, vertices=None) -> float:
    """The longest edge of a shape's bounding box in its own frame.

    A box's longest edge, a sphere's diameter, a cylinder's ``max(2 r, h)``, a capsule's
    ``max(2 r, h + 2 r)`` (``h`` between its caps' centres), a mesh's longest extent along x, y or z.

    >>> largest_extent("box", [0.065, 0.065, 0.1]), largest_extent("capsule", [0.01, 0.05])
    (0.1, 0.07)
    """
    if kind == "mesh":
        v = np.asarray(vertices, dtype=float)
        return float((v.max(axis=0) - v.min(axis=0)).max())
    s = np.asarray(size, dtype=float).reshape(-1)
    if kind == "box":
        return float(s.max())
    if kind == "sphere":
        return float(2 * s[0])
    return float(max(2 * s[0], s[1] + (2 * s[0] if kind == "capsule" else 0.0)))


def fingers_reach(hand) -> float:
    """The longest finger of a :class:`~grasptwist.model.Hand` (``Finger.length``: first joint to tip)."""
    return max(float(f.length) for f in hand.fingers)


def hand_fit_warning(extent: float, reach: float, units: str | None, urdf: bool = False) -> str | None:
    r"""The warning for an object that does not fit its hand, None when it does.

    It does not fit when its largest extent :math:`e` and the fingers' reach :math:`L`
    (as numbers, in the grasp frame: lengths are never converted) are far apart, :math:`e > 10 L`
    or :math:`e < L / 10` (:data:`HAND_FIT`): a URDF is in metres, so an object in millimetres
    is 1000 times too big for it.  ``urdf``: the hand is a URDF's, its reach in metres, said
    in metres and in the object's unit too.  It starts with its code.

    >>> print(hand_fit_warning(65.0, 0.382, "mm", urdf=True))
    hand-size-mismatch: the object's largest extent (65 mm) is 170 times the fingers' reach (the URDF's 0.382 m, 382 mm, taken as 0.382 mm: lengths are never converted): is the object in another unit than the hand (a URDF is in metres)?
    >>> print(hand_fit_warning(200.0, 1.5, "mm"))  # an inline hand: in the file's unit
    hand-size-mismatch: the object's largest extent (200 mm) is 133 times the fingers' reach (1.5 mm): is the object in another unit than the hand (a URDF is in metres)?
    >>> hand_fit_warning(0.065, 0.3, "m") is None
    True
    """
    if not (reach > 0 and extent > 0) or 1 / HAND_FIT <= extent / reach <= HAND_FIT:
        return None
    unit = f" {units}" if units else ""
    ratio = extent / reach
    times = f"{ratio:.3g} times" if ratio > 1 else f"1/{1 / ratio:.3g} of"
    said = f"{reach:.3g}{unit}"
    metres = unit_length(units)
    if urdf and metres is not None and metres != 1.0:
        said = f"the URDF's {reach:.3g} m, {reach / metres:.3g}{unit}, taken as {reach:.3g}{unit}: lengths are never converted"
    elif urdf:
        said = f"the URDF's {reach:.3g} m"
    return (
        f"hand-size-mismatch: the object's largest extent ({extent:.3g}{unit}) is {times} the fingers' reach "
        f"({said}): is the object in another unit than the hand (a URDF is in metres)?"
    )


def mesh_span_warning(extent: float, units: str | None) -> str | None:
    """The warning for a mesh whose largest extent, ``extent`` in ``units`` (metres when None),
    is outside :data:`METRE_SPAN` in metres, None otherwise or when the unit is not known.

    >>> print(mesh_span_warning(65.0, None))
    mesh-size-unlikely: the mesh spans 65 m: is it in millimetres? (give its units: the grasp file's 'units', the mesh's own 'units: mm', or synthesize --units)
    >>> mesh_span_warning(65.0, "mm") is None
    True
    """
    metres = unit_length(units)
    if metres is None:
        return None
    span = extent * metres
    low, high = METRE_SPAN
    if low <= span <= high:
        return None
    guess = "is it in millimetres?" if span > high else "is its unit right?"
    return (
        f"mesh-size-unlikely: the mesh spans {span:.3g} m: {guess} (give its units: the grasp file's "
        "'units', the mesh's own 'units: mm', or synthesize --units)"
    )
