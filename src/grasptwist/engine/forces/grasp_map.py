r"""The grasp map, the manipulating forces and the squeezes.

Contact ``i`` pushes on the object with a force ``f_i`` at ``p_i``; as a wrench
``(f_i; p_i x f_i)`` (force; moment about the origin), so the fingers' resultant is

.. math:: w = G f = \sum_i \begin{pmatrix} f_i \\ p_i \times f_i \end{pmatrix}, \qquad G \in \mathbb{R}^{6 \times 9}.

* **Manipulating forces** (Yoshikawa-Nagai, as the paper describes them: pseudo-inverse
  plus null space): the minimum-norm ``f = G^+ w``.  With ``g`` the contacts' centroid,
  ``q_i = p_i - g`` and the moment taken about ``g`` (``M_g = M - g x F``), ``G G^T`` is
  block diagonal, ``diag(3 I, J)`` with ``J = sum_i (|q_i|^2 I - q_i q_i^T)``, so

  .. math:: f_i = \tfrac13 F + \omega \times q_i, \qquad
            \omega = J^{-1} M_g = \frac{m\,(m \cdot M_g)/t + 3 \sum_i q_i (q_i \cdot M_g)}{|m|^2}

  (``m = (p_2 - p_1) x (p_3 - p_1)``, ``t = sum |q_i|^2``): the forces are the
  "velocity field" of a rigid twist ``(omega; F/3)`` about the centroid.
* **Squeezes** (the null space of ``G``): ``squeeze[i]`` pushes contacts ``j`` and
  ``k`` towards each other along the side ``p_j p_k``, which is the axis of the paper's
  ``Sigma_i`` (eq. 8): ``f_j = s_i e_i``, ``f_k = -s_i e_i``, ``e_i = (p_k - p_j)/|p_k - p_j|``.
  As wrenches the two halves are ``+s_i Sigma_i`` and ``-s_i Sigma_i``.

The statuses (:class:`~grasptwist.forces.Status`) and the twist engine's
(:class:`~grasptwist.engine.degeneracy.Status`) are built from one table, :mod:`grasptwist.codes`:
a number is one condition in both.
"""

from __future__ import annotations

from dataclasses import replace
from typing import NamedTuple

import numpy as np

from ...codes import status_enum, status_messages
from ..checks import check_points
from ..degeneracy import DEGENERACY_TOL
from ..screws import J, K, cross
from . import set_up

__all__ = [
    "Status",
    "ForceStatus",
    "force_status_message",
    "check_wrench",
    "unit_normals",
    "check_friction",
    "check_torsion",
    "check_safety",
    "nonfinite_result",
    "checked_grip",
    "GRIP_NUMBERS",
    "wrench_scales",
    "WRENCH_SCALED_BEYOND",
    "grasp_map",
    "manipulating_reference",
    "squeeze_directions",
    "squeeze_forces",
    "tangent_bases",
    "contact_matrices",
    "manipulating_forces",
    "ManipulatingForces",
    "collinear_manipulating",
]


# the force engine's statuses of grasptwist.codes.STATUSES, each with its stable kebab-case ``code``
Status = status_enum(
    "Status",
    "force",
    __name__,
    (
        "Why a row of a force result has no numbers (0: it has); a member's ``code`` is its stable kebab-case "
        "name in JSON output, e.g. ``cannot-hold``."
    ),
)

#: The layers' name for it, beside the twist engine's :class:`~grasptwist.Status`.
ForceStatus = Status

_MESSAGES = status_messages("force")


def force_status_message(status, culprit=-1, names=("1", "2", "3")) -> str:
    """One sentence for a row's status and culprit (a contact index, or -1).

    The force side's :func:`grasptwist.status_message`, with the same arguments
    (public as :func:`grasptwist.forces.status_message`).

    Parameters
    ----------
    status : int or Status
    culprit : int
        Contact index 0..2 the condition is about, or -1.  For ``cannot-hold``
        -1 means the wrench needs pulling; for ``no-closure`` a culprit is the
        contact whose normal is at right angles to the contacts' plane.
    names : sequence of 3 str
        Contact names to use in the message.

    Returns
    -------
    str

    Examples
    --------
    >>> from grasptwist import forces
    >>> forces.status_message(forces.Status.CANNOT_HOLD, 2)
    'cannot-hold: the friction cone at contact 3 is too narrow (mu/safety) for any forces that make the wrench'
    >>> forces.status_message(forces.Status.NO_CLOSURE, 0, ("thumb", "index", "middle"))
    "no friction makes the grasp force closure: the normal at contact thumb is at right angles to the contacts' plane"
    """
    s = ForceStatus(int(status))
    c = int(culprit)
    i, j, k = names[c if c >= 0 else 0], names[(c + 1) % 3], names[(c + 2) % 3]
    message = _MESSAGES[s]
    return (message[c < 0] if isinstance(message, tuple) else message).format(i=i, j=j, k=k)


# --- validators ------------------------------------------------------------------

_WHAT = {"b": "booleans", "c": "complex numbers"}


def _real(a, name):
    try:
        a = np.asarray(a)
    except ValueError:
        raise ValueError(f"{name} must be real numbers, got a ragged nested sequence") from None
    if a.dtype.kind not in "fiu":
        raise ValueError(f"{name} must hold real numbers, got {_WHAT.get(a.dtype.kind, f'dtype {a.dtype}')}")
    return a.astype(float)


def check_wrench(wrench) -> np.ndarray:
    """The wrench the fingers must exert, ``(force; moment about the origin)``, shape ``(..., 6)``.

    >>> check_wrench([0, 0, 9.81, 0, 0, 0]).shape
    (6,)
    >>> check_wrench([0, 0, 9.81])
    Traceback (most recent call last):
    ValueError: wrench must have shape (..., 6), got (3,)
    """
    a = _real(wrench, "wrench")
    if a.shape[-1:] != (6,):
        raise ValueError(f"wrench must have shape (..., 6), got {a.shape}")
    return a


def check_friction(friction) -> np.ndarray:
    """Friction coefficients ``mu_i >= 0`` (``inf`` allowed), broadcast against ``(..., 3)``.

    The last axis is the contact: a scalar is the same at every contact; one
    coefficient per grasp for ``N`` grasps is ``friction[:, None]``.  NaN is a
    row status, a negative value an error.

    >>> check_friction(0.5).tolist()
    0.5
    >>> check_friction([0.5, -1, 0.5])
    Traceback (most recent call last):
    ValueError: friction must be >= 0, got -1.0
    >>> check_friction([[0.5, 0.5], [0.5, 0.5]])
    Traceback (most recent call last):
    ValueError: friction must broadcast to (..., 3) (one per contact), got (2, 2)
    """
    a = _real(friction, "friction")
    if a.ndim and a.shape[-1] not in (1, 3):
        raise ValueError(f"friction must broadcast to (..., 3) (one per contact), got {a.shape}")
    bad = a < 0
    if bad.any():
        raise ValueError(f"friction must be >= 0, got {float(a[bad].flat[0])!r}")
    return a


def check_torsion(torsion) -> np.ndarray:
    """Torsional radii ``e_i >= 0`` (a length; ``0``: a point contact), broadcast against ``(..., 3)``.

    As :func:`check_friction`: NaN is a row status (``nonfinite-input``), a negative or infinite value an error.

    >>> check_torsion([0.01, 0, 0.01]).tolist()
    [0.01, 0.0, 0.01]
    >>> check_torsion(-0.01)
    Traceback (most recent call last):
    ValueError: torsion must be a finite length >= 0, got -0.01
    """
    a = _real(torsion, "torsion")
    if a.ndim and a.shape[-1] not in (1, 3):
        raise ValueError(f"torsion must broadcast to (..., 3) (one per contact), got {a.shape}")
    bad = (a < 0) | np.isinf(a)
    if bad.any():
        raise ValueError(f"torsion must be a finite length >= 0, got {float(a[bad].flat[0])!r}")
    return a


def check_safety(safety) -> float:
    """The safety factor ``s >= 1`` (finite): the grip keeps every force within ``mu_i / s``.

    >>> check_safety(1.5)
    1.5
    >>> check_safety(0.5)
    Traceback (most recent call last):
    ValueError: safety must be a finite number >= 1, got 0.5
    """
    try:
        s = float(safety)
    except (TypeError, ValueError):
        raise ValueError(f"safety must be a finite number >= 1, got {safety!r}") from None
    if isinstance(safety, bool) or not np.isfinite(s) or s < 1:
        raise ValueError(f"safety must be a finite number >= 1, got {safety!r}")
    return s


def nonfinite_result(status, *parts) -> np.ndarray:
    """``status`` with ``nonfinite-result`` where a row is ok but a part of its result is NaN or infinite.

    The one place an ok row's numbers are held to be finite (huge wrenches, masses or
    coordinates overflow inside the formulas).  ``status (...)``; each part ``(..., *)``
    with the same leading axes.

    >>> nonfinite_result(np.array([0, 0, 20]), np.array([[1.0, 2.0], [1.0, np.inf], [np.nan, 0.0]])).tolist()
    [0, 9, 20]
    """
    out = np.array(status, copy=True)
    bad = np.zeros(out.shape, bool)
    for part in parts:
        part = np.asarray(part)
        bad |= ~np.isfinite(part.reshape(out.shape + (-1,))).all(axis=-1)
    out[(out == ForceStatus.OK) & bad] = ForceStatus.NONFINITE_RESULT
    return out


#: The numbers of a grip (:class:`~grasptwist.engine.forces.grip.Grip`) held finite on its ok rows.
GRIP_NUMBERS = (
    "force",
    "squeeze",
    "normal_force",
    "tangential_force",
    "friction_used",
    "total_normal_force",
    "dual",
    "gap",
)


#: A grip row as the compiled kernel fills it (:func:`~grasptwist.engine.forces.kernel.grip_rows`): the
#: :class:`~grasptwist.engine.forces.grip.Grip` fields in this order, of these widths.
GRIP_COLUMNS = (
    ("force", 9),
    ("manipulating", 9),
    ("squeeze", 3),
    ("normal_force", 3),
    ("tangential_force", 3),
    ("friction_used", 3),
    ("total_normal_force", 1),
    ("conditioning", 1),
    ("dual", 6),
    ("gap", 1),
    ("certificate", 6),
)


def checked_grip(g):
    """A grip whose ok rows are finite: ``nonfinite-result`` (and NaN numbers) where they are not.

    Where a force has no tangential part (no wrench: no force at all; a bare contact
    whose tangential force is round-off, below ``1e-12`` of the row's largest force) it
    uses no friction, ``friction_used = 0`` rather than ``0 / 0`` or ``1e-18 / 0``.
    :func:`~grasptwist.engine.forces.grip.grip` returns its result through here.

    >>> from grasptwist.engine.forces.grip import grip
    >>> p = [[1, 0, 0], [-0.5, 0.75**0.5, 0], [-0.5, -(0.75**0.5), 0]]
    >>> g = grip(p, -np.array(p), [[0, 0, 0, 0, 0, 0], [0, 0, 1e308, 0, 0, 1e308]], 0.5)
    >>> g.status.tolist(), g.friction_used[0].tolist()
    ([0, 9], [0.0, 0.0, 0.0])
    """
    ok = (g.status == ForceStatus.OK)[..., None]
    # a bare contact's tangential force is round-off of the row's forces, not friction used
    scale = np.max(np.abs(g.force), axis=(-2, -1), initial=0.0)[..., None]
    used = np.where(ok & (g.tangential_force <= 1e-12 * scale), 0.0, g.friction_used)
    # a squeeze is NaN by definition on collinear contacts (their internal forces are not three squeezes)
    checked = (name for name in GRIP_NUMBERS if name != "squeeze")
    status = nonfinite_result(g.status, *(used if name == "friction_used" else getattr(g, name) for name in checked))
    failed = status != ForceStatus.OK
    numbers = {name: getattr(g, name) for name in GRIP_NUMBERS} | {"friction_used": used}
    numbers = {
        k: np.where(failed.reshape(failed.shape + (1,) * (v.ndim - failed.ndim)), np.nan, v) for k, v in numbers.items()
    }
    return replace(g, status=status, **numbers)


# --- reference formulas (readable; the tests hold the fast forms to them) -----------


def grasp_map(points) -> np.ndarray:
    r"""The grasp map ``G`` (6 x 9): column block ``i`` is ``[I; [p_i]_x]``.

    .. math:: G = \begin{pmatrix} I & I & I \\ [p_1]_\times & [p_2]_\times & [p_3]_\times \end{pmatrix}

    ``(..., 3, 3) -> (..., 6, 9)``; ``G @ f.reshape(9)`` is the wrench of the forces ``f (3, 3)``.

    >>> G = grasp_map([[0, 2, 2], [2, 0, 2], [2, 2, 0]])
    >>> (G @ np.array([1.0, 0, 0, 0, 0, 0, 0, 0, 0])).tolist()
    [1.0, 0.0, 0.0, 0.0, 2.0, -2.0]
    """
    p = np.asarray(points, dtype=float)
    g = np.zeros(p.shape[:-2] + (6, 9))
    eye = np.eye(3)
    for i in range(3):
        g[..., :3, 3 * i : 3 * i + 3] = eye
        g[..., 3:, 3 * i : 3 * i + 3] = cross(p[..., i, None, :], eye)  # columns p_i x e_c
        g[..., 3:, 3 * i : 3 * i + 3] = np.swapaxes(g[..., 3:, 3 * i : 3 * i + 3], -1, -2)
    return g


def manipulating_reference(points, wrench) -> np.ndarray:
    """``G^+ w`` by LAPACK's pseudo-inverse: the definition :func:`manipulating_forces` is tested against.

    ``(..., 3, 3), (..., 6) -> (..., 3, 3)``.

    >>> f = manipulating_reference([[1, 0, 0], [-0.5, 0.75**0.5, 0], [-0.5, -(0.75**0.5), 0]], [0, 0, 3, 0, 0, 0])
    >>> (f.round(6) + 0.0).tolist()  # + 0.0: no -0 (LAPACK's sign of a zero differs between CPUs)
    [[0.0, 0.0, 1.0], [0.0, 0.0, 1.0], [0.0, 0.0, 1.0]]
    """
    w = np.asarray(wrench, dtype=float)
    f = np.linalg.pinv(grasp_map(points)) @ w[..., None]
    return f[..., 0].reshape(w.shape[:-1] + (3, 3))


def squeeze_directions(points) -> np.ndarray:
    """Unit vectors ``e_i = (p_k - p_j) / |p_k - p_j|`` along the axis of ``Sigma_i`` (eq. 8).

    ``(..., 3, 3) -> (..., 3, 3)``; a squeeze ``s_i`` is the force ``s_i e_i`` on
    contact ``j`` and ``-s_i e_i`` on contact ``k``.

    >>> squeeze_directions([[0, 0, 0], [2.0, 0, 0], [0, 2.0, 0]])[0].round(4).tolist()
    [-0.7071, 0.7071, 0.0]
    """
    p = np.asarray(points, dtype=float)
    flat = np.ascontiguousarray(p.reshape(-1, 3, 3))
    e, sides = np.empty(flat.shape), np.empty((len(flat), 3))
    set_up.on_rows("squeeze_directions", flat, e, sides, len(flat))
    return e.reshape(p.shape)


def squeeze_forces(points, squeeze) -> np.ndarray:
    r"""The internal forces of the squeezes ``s``: an element of the null space of ``G``.

    .. math:: f_j \mathrel{+}= s_i e_i, \qquad f_k \mathrel{-}= s_i e_i \qquad (i, j, k \text{ cyclic})

    ``s_i > 0`` pushes contacts ``j`` and ``k`` towards each other (compresses the
    object along the side ``p_j p_k``).  The side is the axis of ``Sigma_i`` (eq. 8), so
    the two halves are the wrenches ``+-s_i Sigma_i``; each does the power
    ``+-s_i [Sigma_i | T]`` on a twist ``T``, which vanishes for every ``Sigma_m`` and for
    ``Psi_m``, ``Theta_m`` with ``m != i`` (lines meeting the side), not for ``Psi_i``,
    ``Theta_i``.  ``(..., 3, 3), (..., 3) -> (..., 3, 3)``.

    >>> p = np.array([[0, 2, 2], [2, 0, 2], [2, 2, 0]], float)
    >>> f = squeeze_forces(p, [1.0, 2.0, 3.0])
    >>> bool(np.allclose(grasp_map(p) @ f.reshape(9), 0))
    True
    """
    e = squeeze_directions(points)
    s = np.asarray(squeeze, dtype=float)[..., None]
    # contact i gets +s_k e_k (it is the j of side k) and -s_j e_j (it is the k of side j)
    return s[..., K, :] * e[..., K, :] - s[..., J, :] * e[..., J, :]


# --- the closed form ------------------------------------------------------------------


class Geometry(NamedTuple):
    """What every force computation needs of the contacts (shapes for a batch ``...``)."""

    centroid: np.ndarray  # (..., 3)
    q: np.ndarray  # (..., 3, 3) contacts about the centroid
    m: np.ndarray  # (..., 3) (p2 - p1) x (p3 - p1)
    t: np.ndarray  # (...) sum |q_i|^2
    size: np.ndarray  # (...) largest distance from the centroid to a contact
    conditioning: np.ndarray  # (...)
    e: np.ndarray  # (..., 3, 3) squeeze directions
    status: np.ndarray  # (...) int8
    culprit: np.ndarray  # (...) int8


def geometry(points, tol=DEGENERACY_TOL) -> Geometry:
    """The contacts' frame, conditioning and geometric status (non-finite, coincident, collinear).

    The numbers are :func:`set_up.contact_geometry`'s and :func:`set_up.squeeze_directions`' (their numpy twins).
    """
    p = np.asarray(points, dtype=float)
    shape = p.shape[:-2]
    flat = np.ascontiguousarray(p.reshape(-1, 3, 3))
    rows = len(flat)
    g, q, m, sizes = np.empty((rows, 3)), np.empty((rows, 3, 3)), np.empty((rows, 3)), np.empty((rows, 3))
    squeezes, sides = np.empty((rows, 3, 3)), np.empty((rows, 3))
    set_up.on_rows("contact_geometry", flat, g, q, m, sizes, rows)
    set_up.on_rows("squeeze_directions", flat, squeezes, sides, rows)
    t, conditioning = sizes[:, 0].copy(), sizes[:, 2]
    with np.errstate(all="ignore"):
        size = np.sqrt(sizes[:, 1])
        status = np.zeros(rows, np.int8)
        culprit = np.full(rows, -1, np.int8)
        coincident = sides <= tol * np.sqrt(t)[:, None]
        worst = np.argmax(coincident, axis=-1).astype(np.int8)
        status[~(conditioning > tol)] = ForceStatus.COLLINEAR_CONTACTS
        hit = coincident.any(axis=-1) | ~(t > 0)
        status[hit] = ForceStatus.COINCIDENT_CONTACTS
        culprit[hit] = worst[hit]
        # finite contacts whose spread overflows (coordinates near 1e154 and beyond) have no
        # geometry to judge: an overflow, not the coincident contacts an infinite size would mimic
        over = ~np.isfinite(t)
        status[over] = ForceStatus.NONFINITE_RESULT
        bad = ~np.isfinite(flat).all(axis=(-1, -2))
        status[bad] = ForceStatus.NONFINITE_INPUT
        culprit[over | bad] = -1
        conditioning = np.where(status == 0, conditioning, np.where(bad | over, np.nan, 0.0))
    g, q, m, conditioning, squeezes, status, culprit = (
        a.reshape(shape + a.shape[1:]) for a in (g, q, m, conditioning, squeezes, status, culprit)
    )
    t, size = t.reshape(shape)[()], size.reshape(shape)[()]  # [()]: one grasp's sums as numbers, as numpy's sums are
    return Geometry(g, q, m, t, size, conditioning, squeezes, status, culprit)


def _manipulating(geo: Geometry, wrench):
    """``G^+ w`` in closed form for prepared contacts (NaN where the contacts are degenerate):
    :func:`set_up.manipulating`'s numpy twin."""
    shape = geo.t.shape
    w = np.broadcast_to(np.asarray(wrench, dtype=float), shape + (6,)).reshape(-1, 6)
    f = np.empty(shape + (3, 3))
    rows = len(w)
    g, q, m, t = geo.centroid.reshape(-1, 3), geo.q.reshape(-1, 3, 3), geo.m.reshape(-1, 3), np.reshape(geo.t, (-1, 1))
    set_up.on_rows("manipulating", g, q, m, t, w, f.reshape(-1, 3, 3), np.empty((rows, 3)), rows)
    return np.where((geo.status == 0)[..., None, None], f, np.nan)


class CollinearMap(NamedTuple):
    """The grasp map of collinear contacts (rank 5), its moment rows divided by the grasp's size ``L``.

    ``u (n, 6, 5)``, ``s (n, 5)``, ``v (n, 9, 5)``: the thin SVD of ``D G`` with
    ``D = diag(1, 1, 1, 1/L, 1/L, 1/L)`` (forces and moments compare); ``null (n, 9, 4)``
    the internal forces: pushes along the line and pairs across it.
    """

    u: np.ndarray
    s: np.ndarray
    v: np.ndarray
    null: np.ndarray
    size: np.ndarray


def collinear_map(points, size) -> CollinearMap:
    """:class:`CollinearMap` of ``points (n, 3, 3)`` with ``size (n)``."""
    g = grasp_map(points)
    g[:, 3:] /= size[:, None, None]
    u, s, vt = np.linalg.svd(g)
    return CollinearMap(u[..., :5], s[:, :5], np.swapaxes(vt[:, :5], -1, -2), np.swapaxes(vt[:, 5:], -1, -2), size)


def _scaled(wrench, size):
    return np.concatenate((wrench[..., :3], wrench[..., 3:] / size[:, None]), axis=-1)


def collinear_manipulating(cmap: CollinearMap, wrench, tol=1e-9):
    r"""``G^+ w`` for collinear contacts, and where ``w`` is out of ``G``'s range the part that is.

    Returns ``force (n, 3, 3)`` (NaN where ``w`` is out of range), ``made (n)`` bool and
    ``y (n, 6)``: ``y = D r`` with ``r`` the part of ``D w`` outside the range, so
    ``y . w = |r|^2 > 0`` and ``y . G f = 0`` for every ``f``: the moment about the
    contacts' line that no finger force makes (zero where ``made``).
    """
    dw = _scaled(wrench, cmap.size)
    coef = np.einsum("nji,nj->ni", cmap.u, dw)
    r = dw - np.einsum("nji,ni->nj", cmap.u, coef)
    with np.errstate(all="ignore"):
        made = np.linalg.norm(r, axis=-1) <= tol * np.linalg.norm(dw, axis=-1)
        f = np.einsum("nji,ni->nj", cmap.v, coef / cmap.s).reshape(-1, 3, 3)
    y = _scaled(r, cmap.size)
    return np.where(made[:, None, None], f, np.nan), made, np.where(made[:, None], 0.0, y)


class ManipulatingForces(NamedTuple):
    """Yoshikawa-Nagai's manipulating forces of a batch of (grasp, wrench) rows.

    Attributes
    ----------
    force : (..., 3, 3)
        ``G^+ w``, row ``i`` the force contact ``i`` exerts on the object; NaN
        where ``status != 0``.
    conditioning : (...)
        ``sqrt(lambda_min / mean(lambda))`` of the contacts' second moment
        ``sum_i q_i q_i^T`` about their centroid (its two in-plane eigenvalues):
        1 for an equilateral triangle, falling like the offset from a line to 0
        for collinear contacts.  ``G^+ w`` grows like ``1 / conditioning`` there.
    status, culprit : (...) int8
        :class:`~grasptwist.forces.Status` and the contact it is about (or -1).  Collinear contacts
        (conditioning 0) are ``collinear-contacts`` only when the wrench has a moment about
        their line, which no finger force makes; otherwise ``force`` is ``G^+ w``.
    """

    force: np.ndarray
    conditioning: np.ndarray
    status: np.ndarray
    culprit: np.ndarray


#: Wrenches whose largest entry lies outside these bounds are solved scaled to about 1 by a
#: power of two (exact): the solver squares forces, which overflow from about 1e154 where
#: the grip itself (linear in the wrench) is still a double.
WRENCH_SCALED_BEYOND = (1e-100, 1e100)


def wrench_scales(w) -> np.ndarray | None:
    """Per row of ``w (..., 6)``, the power of two to divide it by before the solve (1 for most);
    None when no row needs it (the common case, decided in two reductions: a hot path).

    >>> wrench_scales(np.array([[0, 0, 9.81, 0, 0, 0], [0, 0, 0, 0, 0, 0], [0, 0, np.inf, 0, 0, 0]])) is None
    True
    >>> wrench_scales(np.array([[0, 0, 9.81, 0, 0, 0], [0, 0, 1e300, 0, 0, 0]])).tolist()[0]
    1.0
    >>> bool(1 <= 1e300 / wrench_scales(np.array([[0, 0, 1e300, 0, 0, 0]]))[0] < 2)
    True
    """
    low, high = WRENCH_SCALED_BEYOND
    largest = np.abs(w).max(axis=-1)
    big, small = largest > high, (largest < low) & (largest > 0)
    if not (big.any() or small.any()):  # NaN compares false: no scale
        return None
    extreme = np.isfinite(largest) & (big | small)  # an infinite wrench keeps its own status
    if not extreme.any():
        return None
    return np.where(extreme, np.exp2(np.floor(np.log2(np.where(extreme, largest, 1.0)))), 1.0)


def manipulating_forces(points, wrench, *, tol=DEGENERACY_TOL) -> ManipulatingForces:
    r"""The minimum-norm finger forces that exert ``wrench``: ``f = G^+ w`` (Yoshikawa-Nagai).

    .. math:: f_i = \tfrac13 F + \omega \times (p_i - g), \qquad \omega = J^{-1} (M - g \times F)

    (module docstring).  Every other solution of ``G f = w`` is ``f`` plus
    squeezes (:func:`squeeze_forces`), orthogonal to it.

    Parameters
    ----------
    points : (..., 3, 3) array
    wrench : (..., 6) array, ``(force; moment about the origin)``
    tol : float
        Below this conditioning the contacts count as collinear.

    Returns
    -------
    ManipulatingForces

    Examples
    --------
    Three fingers around a 1 kg ball's equator hold its weight, a third each:

    >>> p = [[1, 0, 0], [-0.5, 0.75**0.5, 0], [-0.5, -(0.75**0.5), 0]]
    >>> r = manipulating_forces(p, [0, 0, 9.81, 0, 0, 0])
    >>> r.force[:, 2].round(4).tolist(), round(float(r.conditioning), 6)
    ([3.27, 3.27, 3.27], 1.0)
    """
    p = check_points(points)
    w = check_wrench(wrench)
    shape = np.broadcast_shapes(p.shape[:-2], w.shape[:-1])
    p, w = np.broadcast_to(p, shape + (3, 3)), np.broadcast_to(w, shape + (6,))
    geo = geometry(p, tol)
    k = wrench_scales(w)  # G^+ is linear: a wrench beyond 1e100 is solved scaled
    if k is None:
        f = _manipulating(geo, w)
    else:
        with np.errstate(over="ignore", invalid="ignore"):
            f = _manipulating(geo, w / k[..., None]) * k[..., None, None]
    status, culprit = geo.status.copy(), geo.culprit.copy()
    line = np.flatnonzero(status.reshape(-1) == ForceStatus.COLLINEAR_CONTACTS)
    if line.size:  # rank 5: G^+ w still makes w when w has no moment about the contacts' line
        flat = (p.reshape(-1, 3, 3)[line], w.reshape(-1, 6)[line])
        lf, made, _ = collinear_manipulating(collinear_map(flat[0], geo.size.reshape(-1)[line]), flat[1])
        made &= np.isfinite(flat[1]).all(axis=-1)
        f.reshape(-1, 3, 3)[line[made]] = lf[made]
        status.reshape(-1)[line[made]] = ForceStatus.OK
    status[(status == 0) & ~np.isfinite(w).all(axis=-1)] = ForceStatus.NONFINITE_INPUT
    status = nonfinite_result(status, f)
    f[status != 0] = np.nan
    return ManipulatingForces(f, geo.conditioning, status, culprit)


def unit_normals(normals):
    r"""The contacts' unit normals, which contacts' normals are zero, and which rows hold a non-finite normal.

    ``(n, 3, 3) -> unit (n, 3, 3), zero (n, 3), nonfinite (n)``.  A normal whose squares
    would overflow (``1e200``) or underflow (``1e-200``) is first scaled by a power of two
    (exact; :func:`set_up.unit_normals`, whose twin this is): ``n / |n|`` to the last bit
    wherever they do not, and the same direction for any finite non-zero length.  A NaN or
    infinite normal is non-finite, not zero (``unit`` is NaN there).

    >>> u, zero, bad = unit_normals(np.array([[[3e200, 4e200, 0], [0, 0, 1e-200], [0, 0, 0]]]))
    >>> u[0].round(12).tolist(), zero.tolist(), bad.tolist()
    ([[0.6, 0.8, 0.0], [0.0, 0.0, 1.0], [nan, nan, nan]], [[False, False, True]], [False])
    """
    n = np.asarray(normals, dtype=float)
    flat = n.reshape(-1, 3, 3)
    unit = np.empty(flat.shape)
    set_up.on_rows("unit_normals", flat, unit, len(flat))
    finite = np.isfinite(n).all(axis=-1)
    zero = finite & (n == 0).all(axis=-1)
    return unit.reshape(n.shape), zero, ~finite.all(axis=-1)


def tangent_bases(normals):
    """Two unit tangents ``(b1, b2)`` at each contact, ``b2 = n x b1``: ``(..., 3, 3) -> 2 x (..., 3, 3)``.

    >>> b1, b2 = tangent_bases(np.eye(3))
    >>> (b1[2] + 0.0).tolist(), (b2[2] + 0.0).tolist()
    ([0.0, 1.0, 0.0], [-1.0, 0.0, 0.0])
    """
    n = np.asarray(normals, dtype=float)
    with np.errstate(invalid="ignore", divide="ignore"):
        b = set_up.twins()["tangents"](n[..., 0], n[..., 1], n[..., 2])
    return np.stack(b[:3], axis=-1), np.stack(b[3:], axis=-1)


def contact_matrices(e):
    """``M[..., i, :, l]``: the force on contact ``i`` of a unit squeeze ``l``: ``(..., 3, 3) -> (..., 3, 3, 3)``.

    Squeeze ``l`` pushes contact ``i`` (``i != l``) towards the third contact; ``M[i, :, i] = 0``.
    """
    flat = np.ascontiguousarray(np.asarray(e, dtype=float).reshape(-1, 3, 3))
    m = np.empty((len(flat), 3, 3, 3))
    set_up.on_rows("squeeze_map", flat, m, len(flat))
    return m.reshape(e.shape[:-2] + (3, 3, 3))
