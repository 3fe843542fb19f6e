"""Screw algebra on numpy arrays.

A screw (twist or wrench) is six numbers ``(omega; v)``: ``omega`` its
angular part and ``v`` the value of its field at the frame origin, so that
the field at a point ``p`` is ``V(p) = v + omega x p`` (paper, eq. 2).

Every function takes any leading batch shape: screws are ``(..., 6)``,
points and vectors ``(..., 3)``; leading shapes broadcast.  Products are
written out component by component rather than through ``einsum`` or
``matmul`` so that each row's result is bit-for-bit the same whatever batch
it is computed in (BLAS kernels may change their summation order with the
array's size), and because this is the fastest form for long batches.

The functions ending in ``3`` take vectors as three separate components
(a tuple ``(x, y, z)``), each a plain float or an array over rows, and use
nothing but arithmetic operators: one formula then serves one grasp in
plain Python floats (fast for a single call) and a chunk of rows in numpy
(fast for millions), with the same IEEE operations in the same order, so the
same bits.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "J",
    "K",
    "dot",
    "cross",
    "norm",
    "unit",
    "direction",
    "screw",
    "klein",
    "klein_table",
    "field_at",
    "constant_field",
    "line_through",
    "line_between",
    "twist_at",
    "pitch",
    "axis_point",
    "rigid_motion",
    "add3",
    "sub3",
    "mul3",
    "div3",
    "dot3",
    "cross3",
    "twist_at3",
    "direction3",
]

#: Cyclic contact indices of the paper: for contact ``i`` (0-based), the other
#: two are ``j = J[i]`` and ``k = K[i]``, so ``(i, j, k)`` runs over
#: ``(0, 1, 2), (1, 2, 0), (2, 0, 1)``.
J = (1, 2, 0)
K = (2, 0, 1)


def dot(a, b):
    """Dot product over the last axis: ``(..., 3), (..., 3) -> (...)``.

    >>> float(dot([1.0, 2.0, 3.0], [4.0, 5.0, 6.0]))
    32.0
    """
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    return a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1] + a[..., 2] * b[..., 2]


def cross(a, b):
    """Cross product over the last axis: ``(..., 3), (..., 3) -> (..., 3)``.

    >>> cross([1.0, 0, 0], [0, 1.0, 0]).tolist()
    [0.0, 0.0, 1.0]
    """
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    out = np.empty(np.broadcast_shapes(a.shape, b.shape))  # filled in place: np.stack costs more than the sums
    out[..., 0] = a1 * b2 - a2 * b1
    out[..., 1] = a2 * b0 - a0 * b2
    out[..., 2] = a0 * b1 - a1 * b0
    return out


def norm(a):
    """Euclidean length over the last axis: ``(..., 3) -> (...)``.

    >>> float(norm([3.0, 4.0, 0.0]))
    5.0
    """
    return np.sqrt(dot(a, a))


def unit(a):
    """``a / |a|`` over the last axis; a zero vector gives NaN (no warning).

    ``(..., k) -> (..., k)``.

    >>> unit([0.0, 0.0, 2.0]).tolist()
    [0.0, 0.0, 1.0]
    """
    a = np.asarray(a, dtype=float)
    with np.errstate(invalid="ignore", divide="ignore"):
        return a / norm(a)[..., None]


def direction(a):
    """Unit vector along ``a`` for any finite size of ``a``; zero stays zero.

    Dividing by the largest component first keeps the squares in the norm
    from overflowing (``1e200``) or underflowing (``1e-200``).
    ``(..., 3) -> (..., 3)``.

    >>> direction([0.0, 3e200, 4e200]).tolist()
    [0.0, 0.6, 0.8]
    """
    a = np.asarray(a, dtype=float)
    m = np.abs(a)
    big = np.maximum(np.maximum(m[..., 0], m[..., 1]), m[..., 2])[..., None]  # faster than max over a short axis
    with np.errstate(invalid="ignore", divide="ignore"):
        scaled = np.where(big > 0, a / big, a)
        length = norm(scaled)[..., None]
        return np.where(length > 0, scaled / length, scaled)


def screw(omega, v):
    """Join an angular part and an origin velocity into ``(omega; v)``.

    ``(..., 3), (..., 3) -> (..., 6)``.

    >>> screw([0, 0, 1], [1, 0, 0]).tolist()
    [0.0, 0.0, 1.0, 1.0, 0.0, 0.0]
    """
    omega, v = np.broadcast_arrays(np.asarray(omega, float), np.asarray(v, float))
    return np.concatenate((omega, v), axis=-1)


def klein(x, y):
    """Klein form (paper eq. 4): ``[X|Y] = omega_X . v_Y + omega_Y . v_X``.

    ``(..., 6), (..., 6) -> (...)``.  Independent of the origin; zero when the
    screws are reciprocal.  For two unit lines it is ``-d sin(angle)``, with
    ``d`` the distance between their axes.

    >>> float(klein([0, 0, 1, 0, 0, 0], [0, 0, 0, 0, 0, 1]))
    1.0
    """
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    return dot(x[..., :3], y[..., 3:]) + dot(y[..., :3], x[..., 3:])


def klein_table(a, b):
    """All products ``[A_i | B_j]`` of two lists of screws (like the paper's eq. 18).

    ``(..., m, 6), (..., n, 6) -> (..., m, n)``.

    >>> klein_table([[0, 0, 1.0, 0, 0, 0]], [[0, 0, 0, 0, 0, 1.0], [0, 0, 0, 1.0, 0, 0]]).tolist()
    [[1.0, 0.0]]
    """
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    return klein(a[..., :, None, :], b[..., None, :, :])


def field_at(s, p):
    """Value of a screw's field at a point (paper eq. 2): ``v + omega x p``.

    ``(..., 6), (..., 3) -> (..., 3)``.  For a twist this is the velocity of
    the body point at ``p``.

    >>> field_at([0, 0, 1, 0, 0, 0], [1.0, 0, 0]).tolist()
    [0.0, 1.0, 0.0]
    """
    s = np.asarray(s, dtype=float)
    return s[..., 3:] + cross(s[..., :3], p)


def constant_field(s):
    """The paper's operator Omega (eq. 5): the constant field ``omega_X``.

    As a screw it is the pure translation ``(0; omega)``, so ``Omega^2 = 0``
    and a unit line ``L`` has ``[L | Omega L] = 1`` (eq. 6).
    ``(..., 6) -> (..., 6)``.

    >>> constant_field([1.0, 2, 3, 4, 5, 6]).tolist()
    [0.0, 0.0, 0.0, 1.0, 2.0, 3.0]
    """
    s = np.asarray(s, dtype=float)
    return np.concatenate((np.zeros_like(s[..., :3]), s[..., :3]), axis=-1)


def line_through(p, d):
    """Unit zero-pitch screw through ``p`` along ``d`` (eq. 15, normalised).

    ``(d/|d|; p x d/|d|)``; its field vanishes on the axis.  A zero ``d``
    gives NaN.  ``(..., 3), (..., 3) -> (..., 6)``.

    >>> line_through([0, 1.0, 0], [2.0, 0, 0]).tolist()
    [1.0, 0.0, 0.0, 0.0, 0.0, -1.0]
    """
    e = unit(d)
    return screw(e, cross(p, e))


def line_between(p, q):
    """Unit line through ``p`` and ``q``, directed from ``p`` to ``q``.

    ``(..., 3), (..., 3) -> (..., 6)``; coincident points give NaN.

    >>> line_between([0, 1.0, 0], [3.0, 1, 0]).tolist()
    [1.0, 0.0, 0.0, 0.0, 0.0, -1.0]
    """
    p = np.asarray(p, dtype=float)
    return line_through(p, np.asarray(q, dtype=float) - p)


def twist_at(omega, velocity, point):
    """The twist with angular velocity ``omega`` whose point ``point`` moves
    with ``velocity``, as ``(omega; v)`` at the origin.

    ``v = velocity + omega x (o - point)``.  ``(..., 3) x3 -> (..., 6)``.

    >>> twist_at([0, 0, 1.0], [0, 0, 0], [1.0, 0, 0]).tolist()
    [0.0, 0.0, 1.0, 0.0, -1.0, 0.0]
    """
    omega = np.asarray(omega, dtype=float)
    point = np.asarray(point, dtype=float)
    return screw(omega, np.asarray(velocity, dtype=float) - cross(omega, point))


def pitch(s):
    """Pitch ``h = omega . v / |omega|^2``; ``inf`` for a pure translation.

    ``(..., 6) -> (...)``.

    >>> float(pitch([0, 0, 1.0, 0, 0, 2.0]))
    2.0
    """
    s = np.asarray(s, dtype=float)
    w2 = dot(s[..., :3], s[..., :3])
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(w2 > 0, dot(s[..., :3], s[..., 3:]) / np.where(w2 > 0, w2, 1.0), np.inf)


def axis_point(s):
    """Point of the screw axis nearest the origin: ``omega x v / |omega|^2``.

    NaN for a pure translation.  ``(..., 6) -> (..., 3)``.

    >>> (axis_point([0, 0, 1.0, 0, -1.0, 0]) + 0.0).tolist()
    [1.0, 0.0, 0.0]
    """
    s = np.asarray(s, dtype=float)
    w2 = dot(s[..., :3], s[..., :3])
    with np.errstate(invalid="ignore", divide="ignore"):
        return cross(s[..., :3], s[..., 3:]) / w2[..., None]


def rigid_motion(s, rotation, translation):
    """Screw carried by the rigid motion ``x -> R x + t`` (the adjoint map).

    ``omega' = R omega``, ``v' = R v + t x R omega``.
    ``(..., 6), (..., 3, 3), (..., 3) -> (..., 6)``.

    >>> rigid_motion([0, 0, 1.0, 0, 0, 0], np.eye(3), [1.0, 0, 0]).tolist()
    [0.0, 0.0, 1.0, 0.0, -1.0, 0.0]
    """
    s = np.asarray(s, dtype=float)
    rotation = np.asarray(rotation, dtype=float)
    w = np.einsum("...ij,...j->...i", rotation, s[..., :3])
    v = np.einsum("...ij,...j->...i", rotation, s[..., 3:])
    return screw(w, v + cross(translation, w))


# --- vectors as three components ------------------------------------------------


def add3(a, b):
    """``a + b`` for vectors given as three components.

    >>> add3((1.0, 2.0, 3.0), (0.5, 0.5, 0.5))
    (1.5, 2.5, 3.5)
    """
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def sub3(a, b):
    """``a - b`` for vectors given as three components.

    >>> sub3((1.0, 2.0, 3.0), (0.5, 0.5, 0.5))
    (0.5, 1.5, 2.5)
    """
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def mul3(a, s):
    """``a * s`` for a vector given as three components and a scalar.

    >>> mul3((1.0, 2.0, 3.0), 2.0)
    (2.0, 4.0, 6.0)
    """
    return (a[0] * s, a[1] * s, a[2] * s)


def div3(a, s):
    """``a / s`` for a vector given as three components and a scalar.

    Plain floats raise ``ZeroDivisionError`` for ``s == 0``; arrays give
    ``inf``/``NaN`` as IEEE says.

    >>> div3((1.0, 2.0, 3.0), 2.0)
    (0.5, 1.0, 1.5)
    """
    return (a[0] / s, a[1] / s, a[2] / s)


def dot3(a, b):
    """``a . b`` for vectors given as three components: the same operations as :func:`dot`.

    >>> dot3((1.0, 2.0, 3.0), (4.0, 5.0, 6.0))
    32.0
    """
    s = a[0] * b[0]
    s += a[1] * b[1]  # in place for arrays (one temporary less), the same sums
    s += a[2] * b[2]
    return s


def cross3(a, b):
    """``a x b`` for vectors given as three components: the same operations as :func:`cross`.

    >>> cross3((1.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    (0.0, 0.0, 1.0)
    """
    x = a[1] * b[2]
    x -= a[2] * b[1]  # in place for arrays (one temporary less), the same differences
    y = a[2] * b[0]
    y -= a[0] * b[2]
    z = a[0] * b[1]
    z -= a[1] * b[0]
    return (x, y, z)


def twist_at3(omega, velocity, point):
    """:func:`twist_at` for three-component vectors: the origin velocity ``velocity - omega x point``.

    Returns the three components of ``v`` (``omega`` is unchanged).

    >>> twist_at3((0.0, 0.0, 1.0), (0.0, 0.0, 0.0), (1.0, 0.0, 0.0))
    (0.0, -1.0, 0.0)
    """
    return sub3(velocity, cross3(omega, point))


def direction3(x, y, z):
    """:func:`direction` of one vector of three plain floats, the same operations in the same order.

    A zero vector raises ``ZeroDivisionError`` (callers reject it first).

    >>> direction3(0.0, 3e200, 4e200)
    (0.0, 0.6, 0.8)
    """
    big = max(abs(x), abs(y), abs(z))
    x /= big
    y /= big
    z /= big
    length = math.sqrt(x * x + y * y + z * z)  # correctly rounded, like np.sqrt (** 0.5 is not)
    return (x / length, y / length, z / length)
