"""Rigid motions: the SE(3) exponential and logarithm, adjoints and rotations.

A pose (a rigid motion) is a pair ``(R, x)``: a rotation matrix ``R`` of
shape ``(..., 3, 3)`` and a translation ``x`` of shape ``(..., 3)``, acting
on points as ``p -> R p + x``.  A pair rather than a ``4 x 4`` matrix: the
callers (paths, finger kinematics) need ``R`` and ``x`` apart, and a pair
never carries a fourth row that could drift from ``(0, 0, 0, 1)``.

Twists are ``(omega; v)`` as everywhere in grasptwist: ``v`` the velocity
of the point at the frame origin.  Quaternions are ``(w, x, y, z)``, scalar
first.  Every function takes any leading batch shape, and products are
written out component by component (as in :mod:`.screws`), so that a
row's result is bit-for-bit the same whatever batch it is computed in.

Formulas
--------
With ``phi = omega t``, ``theta = |phi|``, ``u = v t`` and ``[a]`` the
skew matrix of ``a`` (``[a] b = a x b``), the exponential is

.. math::

    R = I + A [\\phi] + B [\\phi]^2, \\qquad
    x = u + B\\, \\phi \\times u + C\\, \\phi \\times (\\phi \\times u),

    A = \\frac{\\sin\\theta}{\\theta}, \\quad
    B = \\frac{1 - \\cos\\theta}{\\theta^2}, \\quad
    C = \\frac{\\theta - \\sin\\theta}{\\theta^3}

(Rodrigues' formula and the screw motion's translation).  ``A`` and ``B``
are evaluated as ``sinc`` (``B = (sinc(theta/2))^2 / 2``, free of the
cancellation in ``1 - cos``); ``C`` by its Taylor series below
``theta = 1e-2``.  A pure translation (``omega = 0``) gives ``R = I``,
``x = v t`` exactly.

The logarithm goes through the quaternion (Shepperd's method, which
divides by the largest of ``|w|, |x|, |y|, |z|`` and so stays accurate at
every angle, ``theta = pi`` included): ``phi = 2 atan2(|q_v|, w) q_v / |q_v|``
with ``w >= 0`` gives ``theta`` in ``[0, pi]``, and

.. math::

    v = x - \\tfrac12\\, \\phi \\times x + D\\, \\phi \\times (\\phi \\times x),
    \\qquad D = \\frac{1}{\\theta^2}\\Bigl(1 - \\frac{\\theta}{2}\\cot\\frac{\\theta}{2}\\Bigr)

(``D`` by series below ``theta = 1e-2``), the inverse of ``x = V(phi) v``.
"""

from __future__ import annotations

import numpy as np

from .screws import cross, dot, norm, screw

__all__ = [
    "exp",
    "log",
    "adjoint",
    "skew",
    "compose",
    "inverse",
    "transform",
    "rotate",
    "rotvec_to_matrix",
    "quaternion_to_matrix",
    "matrix_to_quaternion",
    "rpy_to_matrix",
]

#: Below this angle the coefficients ``C`` and ``D`` come from their Taylor
#: series: three terms are exact to round-off there (the next is ~1e-18),
#: while the closed forms lose ~eps/theta^2 to cancellation.
_SERIES_BELOW = 1e-2


def _shaped(a, trailing, name):
    """``a`` as a float array whose shape ends in ``trailing``; ValueError naming ``name`` otherwise."""
    a = np.asarray(a, dtype=float)
    if a.ndim < len(trailing) or a.shape[a.ndim - len(trailing) :] != trailing:
        want = "(..., " + ", ".join(map(str, trailing)) + ")"
        raise ValueError(f"{name} must have shape {want}, got {a.shape}")
    return a


def skew(a):
    """The skew matrix ``[a]`` with ``[a] b = a x b``: ``(..., 3) -> (..., 3, 3)``.

    >>> skew([1.0, 2.0, 3.0]).tolist()
    [[0.0, -3.0, 2.0], [3.0, 0.0, -1.0], [-2.0, 1.0, 0.0]]
    """
    a = _shaped(a, (3,), "a")
    out = np.zeros(a.shape + (3,))  # filled in place: np.stack costs more than the entries
    out[..., 0, 1], out[..., 0, 2] = -a[..., 2], a[..., 1]
    out[..., 1, 0], out[..., 1, 2] = a[..., 2], -a[..., 0]
    out[..., 2, 0], out[..., 2, 1] = -a[..., 1], a[..., 0]
    return out


def rotate(rotation, v):
    """``R v`` over the last axes: ``(..., 3, 3), (..., 3) -> (..., 3)``.

    >>> rotate(rotvec_to_matrix([0, 0, np.pi / 2]), [1.0, 0, 0]).round(12).tolist()
    [0.0, 1.0, 0.0]
    """
    r = _shaped(rotation, (3, 3), "rotation")
    v = _shaped(v, (3,), "v")
    return r[..., 0] * v[..., 0, None] + r[..., 1] * v[..., 1, None] + r[..., 2] * v[..., 2, None]


def transform(rotation, translation, p):
    """Apply the pose ``(R, x)`` to points: ``R p + x``.

    ``(..., 3, 3), (..., 3), (..., 3) -> (..., 3)``.

    >>> transform(np.eye(3), [1.0, 2, 3], [1.0, 0, 0]).tolist()
    [2.0, 2.0, 3.0]
    """
    return rotate(rotation, p) + _shaped(translation, (3,), "translation")


def _matmul(a, b):
    """``a @ b`` for ``(..., 3, 3)`` stacks, written out so that every row sums in the same order."""
    return (
        a[..., :, 0, None] * b[..., None, 0, :]
        + a[..., :, 1, None] * b[..., None, 1, :]
        + a[..., :, 2, None] * b[..., None, 2, :]
    )


def compose(rotation_1, translation_1, rotation_2, translation_2):
    """The pose ``H_1 H_2`` (first ``H_2``, then ``H_1``): ``(R_1 R_2, R_1 x_2 + x_1)``.

    Returns ``(rotation (..., 3, 3), translation (..., 3))``.

    >>> r, x = compose(np.eye(3), [1.0, 0, 0], rotvec_to_matrix([0, 0, np.pi]), [0, 1.0, 0])
    >>> x.tolist()
    [1.0, 1.0, 0.0]
    """
    r1 = _shaped(rotation_1, (3, 3), "rotation_1")
    r2 = _shaped(rotation_2, (3, 3), "rotation_2")
    return _matmul(r1, r2), transform(r1, translation_1, translation_2)


def inverse(rotation, translation):
    """The inverse pose ``(R^T, -R^T x)``.

    >>> r, x = inverse(rotvec_to_matrix([0, 0, np.pi / 2]), [1.0, 0, 0])
    >>> (x.round(12) + 0.0).tolist()  # + 0.0: no round-off sign on zero
    [0.0, 1.0, 0.0]
    """
    rt = np.swapaxes(_shaped(rotation, (3, 3), "rotation"), -1, -2)
    return rt, -rotate(rt, translation)


def _coefficients(theta):
    """``A = sin(t)/t``, ``B = (1 - cos t)/t^2``, ``C = (t - sin t)/t^3`` for angles ``theta >= 0``."""
    a = np.sinc(theta / np.pi)
    b = 0.5 * np.sinc(theta / (2 * np.pi)) ** 2
    t2 = theta * theta
    small = theta < _SERIES_BELOW
    with np.errstate(invalid="ignore", divide="ignore"):
        closed = (theta - np.sin(theta)) / (t2 * theta)
    c = np.where(small, 1 / 6 - t2 / 120 + t2 * t2 / 5040, closed)
    return a, b, c


def _rotation(phi, a, b):
    """``I + A [phi] + B [phi]^2`` with ``[phi]^2 = phi phi^T - |phi|^2 I``, per component."""
    k = skew(phi)
    outer = phi[..., :, None] * phi[..., None, :]
    t2 = dot(phi, phi)[..., None, None]
    return np.eye(3) + a[..., None, None] * k + b[..., None, None] * (outer - t2 * np.eye(3))


def exp(twist, t=1.0):
    """The rigid motion of the constant twist ``twist`` held for time ``t``.

    .. math:: H(t) = \\exp([V] t), \\qquad p \\mapsto R p + x

    is the screw motion that moves every body point ``p`` along the
    twist's field (``dp/dt = v + omega x p``) for time ``t``; see the module
    docstring for the formulas.

    Parameters
    ----------
    twist : (..., 6) array
        ``(omega; v)``, ``v`` the velocity of the point at the origin.
    t : float or (...) array
        Times, broadcast against the twists' batch shape.

    Returns
    -------
    rotation : (..., 3, 3) array
    translation : (..., 3) array
        The pose ``(R, x)`` (the position of the body point that started at
        the origin is ``x``).

    Examples
    --------
    A quarter turn (unit rate for ``pi/2``) about the z axis through
    ``(1, 0, 0)`` carries the origin to ``(1, -1, 0)`` and leaves ``(1, 0, 0)``:

    >>> r, x = exp([0, 0, 1.0, 0, -1.0, 0], np.pi / 2)
    >>> x.round(12).tolist(), (r @ [1.0, 0, 0] + x).round(12).tolist()
    ([1.0, -1.0, 0.0], [1.0, 0.0, 0.0])
    """
    twist = _shaped(twist, (6,), "twist")
    t = np.asarray(t, dtype=float)[..., None]
    phi, u = twist[..., :3] * t, twist[..., 3:] * t
    theta = norm(phi)
    a, b, c = _coefficients(theta)
    pu = cross(phi, u)
    x = u + b[..., None] * pu + c[..., None] * cross(phi, pu)
    return _rotation(phi, a, b), x


def rotvec_to_matrix(rotvec):
    """The rotation by ``|r|`` radians about ``r / |r|`` (Rodrigues): ``(..., 3) -> (..., 3, 3)``.

    >>> rotvec_to_matrix([0, 0, np.pi / 2]).round(12).tolist()
    [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
    """
    phi = _shaped(rotvec, (3,), "rotvec")
    a, b, _ = _coefficients(norm(phi))
    return _rotation(phi, a, b)


def quaternion_to_matrix(quaternion):
    """The rotation of a quaternion ``(w, x, y, z)`` of any non-zero length.

    ``(..., 4) -> (..., 3, 3)``; the quaternion is normalised first, and a
    zero quaternion gives NaN.

    .. math::

        R = \\begin{pmatrix}
        1 - 2(y^2+z^2) & 2(xy - wz) & 2(xz + wy) \\\\
        2(xy + wz) & 1 - 2(x^2+z^2) & 2(yz - wx) \\\\
        2(xz - wy) & 2(yz + wx) & 1 - 2(x^2+y^2)
        \\end{pmatrix}

    >>> quaternion_to_matrix([0.0, 0, 0, 2]).tolist()
    [[-1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0]]
    """
    q = _shaped(quaternion, (4,), "quaternion")
    with np.errstate(invalid="ignore", divide="ignore"):
        q = q / np.sqrt((q * q).sum(-1))[..., None]
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    rows = (
        (1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)),
        (2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)),
        (2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)),
    )
    return np.stack([np.stack(row, -1) for row in rows], -2)


def rpy_to_matrix(rpy):
    """The rotation of a URDF ``rpy`` (roll, pitch, yaw about the fixed x, y, z axes): ``(..., 3) -> (..., 3, 3)``.

    .. math::

        R = R_z(y)\\, R_y(p)\\, R_x(r) = \\begin{pmatrix}
        c_p c_y & s_r s_p c_y - c_r s_y & c_r s_p c_y + s_r s_y \\\\
        c_p s_y & s_r s_p s_y + c_r c_y & c_r s_p s_y - s_r c_y \\\\
        -s_p & s_r c_p & c_r c_p
        \\end{pmatrix}

    written term for term as ``trimesh.transformations.euler_matrix(r, p, y, "sxyz")`` (which
    yourdfpy reads a URDF's origins with), so that both give the same bits.

    >>> (rpy_to_matrix([0, 0, np.pi / 2]).round(12) + 0.0).tolist()
    [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
    >>> bool(np.allclose(rpy_to_matrix([0.3, 0, 0]) @ [0, 1, 0], [0, np.cos(0.3), np.sin(0.3)]))
    True
    """
    a = _shaped(rpy, (3,), "rpy")
    si, sj, sk = np.sin(a[..., 0]), np.sin(a[..., 1]), np.sin(a[..., 2])
    ci, cj, ck = np.cos(a[..., 0]), np.cos(a[..., 1]), np.cos(a[..., 2])
    cc, cs, sc, ss = ci * ck, ci * sk, si * ck, si * sk
    rows = (
        (cj * ck, sj * sc - cs, sj * cc + ss),
        (cj * sk, sj * ss + cc, sj * cs - sc),
        (-sj, cj * si, cj * ci),
    )
    return np.stack([np.stack(row, -1) for row in rows], -2)


def matrix_to_quaternion(rotation):
    """The unit quaternion ``(w, x, y, z)`` with ``w >= 0`` of a rotation matrix.

    ``(..., 3, 3) -> (..., 4)``.  Shepperd's method: of ``4w^2 = 1 + tr R``
    and ``4x^2 = 1 + R_00 - R_11 - R_22`` (and the like for ``y``, ``z``) it
    takes the square root of the largest and gets the other three
    components from sums and differences of off-diagonal pairs divided by
    it, so no division is by a small number, at any angle.

    >>> matrix_to_quaternion(rotvec_to_matrix([np.pi, 0, 0])).round(12).tolist()
    [0.0, 1.0, 0.0, 0.0]
    """
    r = _shaped(rotation, (3, 3), "rotation")
    r00, r11, r22 = r[..., 0, 0], r[..., 1, 1], r[..., 2, 2]
    d21, d02, d10 = r[..., 2, 1] - r[..., 1, 2], r[..., 0, 2] - r[..., 2, 0], r[..., 1, 0] - r[..., 0, 1]
    s01, s02, s12 = r[..., 0, 1] + r[..., 1, 0], r[..., 0, 2] + r[..., 2, 0], r[..., 1, 2] + r[..., 2, 1]
    squares = np.stack((1 + r00 + r11 + r22, 1 + r00 - r11 - r22, 1 - r00 + r11 - r22, 1 - r00 - r11 + r22), -1)
    # each candidate is 4 q_k q scaled by 1 / (4 q_k), row k of this table being 4 q_k (w, x, y, z)
    table = np.stack(
        (
            np.stack((squares[..., 0], d21, d02, d10), -1),
            np.stack((d21, squares[..., 1], s01, s02), -1),
            np.stack((d02, s01, squares[..., 2], s12), -1),
            np.stack((d10, s02, s12, squares[..., 3]), -1),
        ),
        -2,
    )
    k = np.argmax(squares, axis=-1)[..., None, None]
    row = np.take_along_axis(table, k, axis=-2)[..., 0, :]
    big = np.sqrt(np.take_along_axis(squares, k[..., 0], axis=-1))  # 2 |q_k| of a unit quaternion
    q = 0.5 * row / big
    return np.where(q[..., :1] < 0, -q, q)


def log(rotation, translation):
    """The twist whose screw motion reaches the pose ``(R, x)`` in unit time.

    The inverse of :func:`exp`: ``exp(log(R, x)) = (R, x)``, with
    ``|omega| <= pi``.  It is both the body and the space twist of the
    motion ``t -> exp(V t)`` (a screw motion's twist is the same in both).
    Accurate at every angle; at exactly ``pi`` either of the two opposite
    axes is returned.

    .. math:: V = \\log(H), \\qquad \\exp([V]) = H

    Parameters
    ----------
    rotation : (..., 3, 3) array, a rotation matrix
    translation : (..., 3) array

    Returns
    -------
    (..., 6) array, ``(omega; v)``.

    Examples
    --------
    >>> r, x = exp([0, 0, 1.0, 0.5, -1.0, 0.25])
    >>> log(r, x).round(12).tolist()
    [0.0, 0.0, 1.0, 0.5, -1.0, 0.25]
    """
    translation = _shaped(translation, (3,), "translation")
    q = matrix_to_quaternion(rotation)
    qv = q[..., 1:]
    s = norm(qv)
    with np.errstate(invalid="ignore", divide="ignore"):
        # 2 atan2(s, w) / s -> 2 / w = 2 as s -> 0 (w -> 1): no cancellation, only 0/0 at s = 0
        scale = np.where(s > 0, 2 * np.arctan2(s, q[..., 0]) / s, 2.0)
    phi = scale[..., None] * qv
    theta = norm(phi)
    t2 = theta * theta
    half = theta / 2
    with np.errstate(invalid="ignore", divide="ignore"):
        closed = (1 - half / np.tan(half)) / t2
    d = np.where(theta < _SERIES_BELOW, 1 / 12 + t2 / 720 + t2 * t2 / 30240, closed)
    px = cross(phi, translation)
    v = translation - 0.5 * px + d[..., None] * cross(phi, px)
    return screw(phi, v)


def adjoint(rotation, translation):
    """The adjoint of the pose ``(R, x)`` in ``(omega; v)`` order.

    .. math::

        \\mathrm{Ad}_H = \\begin{pmatrix} R & 0 \\\\ [x] R & R \\end{pmatrix}

    maps a twist given in the moved frame to the same twist in the fixed
    frame (``V_s = Ad_H V_b``); it is the matrix of
    :func:`.screws.rigid_motion`.  ``(..., 3, 3), (..., 3) -> (..., 6, 6)``.

    >>> adjoint(np.eye(3), [0, 0, 1.0])[3:, :3].tolist()
    [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]]
    """
    r = _shaped(rotation, (3, 3), "rotation")
    xr = _matmul(skew(translation), r)
    top = np.concatenate((r, np.zeros_like(r)), axis=-1)
    return np.concatenate((top, np.concatenate((xr, r), axis=-1)), axis=-2)
