"""Per-grasp status codes, tolerances and their messages.

The engine never raises on a bad grasp: each row of a batch gets a
:class:`Status` and a *culprit* (the index 0, 1 or 2 of the contact the
condition is about, or -1 when it is about the grasp as a whole), and its
numbers are NaN.  :func:`status_message` turns that pair into one sentence.

All tolerances are relative: the engine measures every condition in the
grasp's own frame (origin at the contacts' centroid, lengths divided by the
grasp's size), so a grasp scaled by 1e-3 or 1e3, or moved anywhere, gets
the same verdict.
"""

from __future__ import annotations

import numpy as np

from ..codes import status_enum, status_messages

__all__ = [
    "Status",
    "DEGENERACY_TOL",
    "CONDITION_WARNING",
    "IN_PLANE_TOL",
    "NOISE_FLOOR",
    "status_message",
    "conditioning_warning",
    "skipped_warning",
    "outward_normals_warning",
    "normal_disagrees_warning",
    "radians_warning",
]

#: A dimensionless measure at or below this makes the grasp degenerate.
#: Amplitudes carry a relative error of about ``1e-16 / conditioning``, so at
#: the threshold they still have about 6 correct digits.
DEGENERACY_TOL = 1e-9

#: A figure computed to double precision (a residual, a tip's distance to its
#: contact, a conditioning) below this is round-off: each processor's BLAS
#: kernel gives other digits there, and may give ``0.0`` or ``-0.0``, so what
#: people read shows it as below this and no more (``output/numbers.py``).
NOISE_FLOOR = 1e-12

#: A conditioning figure below this is worth a warning: amplitudes may be
#: more than a thousand times the twist's own size.
CONDITION_WARNING = 1e-3

#: Normal velocities this small, relative to the contacts' speeds, count as
#: zero when deciding whether a twist keeps every contact in its tangent plane.
IN_PLANE_TOL = 1e-9


# the twist engine's statuses of grasptwist.codes.STATUSES, each with its stable kebab-case ``code``
Status = status_enum(
    "Status",
    "twist",
    __name__,
    (
        "Why a grasp could not be resolved by a method (0: it could); a member's ``code`` is its stable kebab-case "
        "name in JSON output, e.g. ``wrist-coplanar``."
    ),
)

_MESSAGES = status_messages("twist")


def status_message(status, culprit=-1, names=("1", "2", "3")) -> str:
    """One sentence saying which condition failed and for which contacts.

    Parameters
    ----------
    status : int or Status
    culprit : int
        Contact index 0..2 the condition is about (its name is ``i`` in the
        message, ``j`` and ``k`` follow it cyclically, and basis screws are
        numbered 1..3 by position), or -1.
    names : sequence of 3 str
        Contact names to use in the message.

    Examples
    --------
    >>> status_message(Status.COINCIDENT_CONTACTS, 0)
    'contacts 2 and 3 coincide, so Sigma_1 has no axis: three distinct contacts are needed'
    """
    i = int(culprit) if int(culprit) >= 0 else 0
    return _MESSAGES[Status(int(status))].format(i=names[i], j=names[(i + 1) % 3], k=names[(i + 2) % 3], n=i + 1)


def conditioning_warning(conditioning, basis: str) -> str | None:
    """A warning sentence when ``conditioning`` is below :data:`CONDITION_WARNING`.

    >>> conditioning_warning(2e-5, "off-tangent")
    'off-tangent basis is nearly degenerate (conditioning 2e-05 < 0.001): amplitudes are large and sensitive'
    >>> conditioning_warning(0.6, "tangent") is None
    True
    """
    c = float(conditioning)
    if not np.isfinite(c) or c >= CONDITION_WARNING:
        return None
    return (
        f"{basis} basis is nearly degenerate (conditioning {c:.3g} < {CONDITION_WARNING:g}): "
        "amplitudes are large and sensitive"
    )


def skipped_warning(status, method: str) -> str:
    """The warning for a method that could not run on a grasp and was not asked for by name.

    >>> skipped_warning(Status.NO_WRIST, "off-tangent")[:53]
    'off-tangent skipped: no-wrist: the grasp has no wrist'
    """
    s = Status(int(status))
    return f"{method} skipped: {s.code}: {status_message(s)}"


def outward_normals_warning(outward, names=("1", "2", "3"), center=False) -> str | None:
    """The warning for normals that point out of the object, naming their contacts; None when none does.

    ``outward`` is :func:`~grasptwist.engine.judgements.outward_contacts`'s
    row, judged against the centre of mass when ``center`` (the grasp gives
    one), else against the other contacts.  It starts with its code.

    >>> outward_normals_warning([False, False, True], ("east", "west", "south"))[:82]
    'outward-normals: the normal at contact south points away from the other contacts ('
    >>> outward_normals_warning([True, True, True], center=True)[:80]
    'outward-normals: the normals at contacts 1, 2 and 3 point away from the centre o'
    >>> outward_normals_warning([False] * 3) is None
    True
    """
    which = [name for name, out in zip(names, outward) if out]
    if not which:
        return None
    away = (
        "the centre of mass (n . (c - p) < 0, c the grasp's center_of_mass)"
        if center
        else "the other contacts (n . (p_j - p) < 0: they lie behind the tangent plane)"
    )
    if len(which) == 1:
        return (
            f"outward-normals: the normal at contact {which[0]} points away from {away}, "
            "but normals point into the object: flip it, unless that finger pushes outward from inside a hollow"
        )
    return (
        f"outward-normals: the normals at contacts {', '.join(which[:-1])} and {which[-1]} point away from {away}, "
        "but normals point into the object: flip them, unless the fingers push outward from inside a hollow"
    )


def normal_disagrees_warning(contact: int, angle, line=None, column=None, limit=10.0) -> str:
    """The warning for contact ``contact``'s given normal (0-based, named by its place in the file,
    ``contacts[i].normal``, as the file's errors name it), ``angle`` degrees (to a tenth) from the
    object's surface normal, more than ``limit``, with where it is written.  It starts with its code.

    >>> normal_disagrees_warning(1, 14.04, 6, 41, limit=10)[:90]
    "normal-disagrees: contacts[1].normal (line 6, column 41) is 14.0 degrees from the object's"
    """
    where = _place(line, column)
    return (
        f"normal-disagrees: contacts[{contact}].normal{where and f' ({where})'} is {float(angle):.1f} degrees from "
        f"the object's surface normal there (more than {limit:g}): check it, or leave it out to take the surface's"
    )


def _place(line, column) -> str:
    """Where a value is written, ``line 6, column 41``, as a warning in a record says it.

    >>> _place(6, 41), _place(6, None)
    ('line 6, column 41', 'line 6')
    """
    return ", ".join(f"{name} {n}" for name, n in (("line", line), ("column", column)) if n is not None)


def radians_warning(rotvec, line=None, column=None) -> str:
    """The warning for a rotation vector over pi (:func:`~grasptwist.engine.judgements.rotation_over_pi`),
    with where it is written; it starts with its code.

    >>> radians_warning([0, 0, 90], 10, 24)
    'rotation-over-pi: rotation of 90 (rotvec [0, 0, 90], line 10, column 24) is over pi: rotations are in radians (this one is a turn of 116.6 degrees)'
    """
    r = np.asarray(rotvec, dtype=float)
    angle = float(np.sqrt(r @ r))
    turn = np.degrees(abs((angle + np.pi) % (2 * np.pi) - np.pi))  # the rotation's own angle, in [0, 180]
    where = _place(line, column)
    return (
        f"rotation-over-pi: rotation of {angle:g} (rotvec [{', '.join(f'{x:g}' for x in r)}]{where and ', ' + where}) is over pi: "
        f"rotations are in radians (this one is a turn of {turn:.1f} degrees)"
    )
