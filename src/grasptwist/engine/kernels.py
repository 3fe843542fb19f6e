"""The paper's two decompositions in closed form, written once for one grasp or a chunk of rows.

:mod:`~grasptwist.engine.formulas` states the paper's formulas on screws;
this module computes the same numbers with fewer operations, and
:mod:`~grasptwist.engine.decompose` runs it (tests hold the two equal).

Every kernel takes its inputs as *components*: a point is a tuple ``(x, y,
z)``, a twist six numbers ``(omega; v)``, and each component is either a
plain Python float (one grasp: the fastest form for a single call) or a
numpy array over the rows of a chunk (the fastest form for millions).  Only
arithmetic operators and the few functions of :class:`Ops` are used, so both
forms run the same IEEE operations in the same order and give the same bits.
A kernel returns the values it computed and its degeneracy *checks*; the
caller turns the checks into a status per row (:func:`settle_one`, or the
row-wise driver in :mod:`~grasptwist.engine.decompose`).

How it is computed
------------------
Eqs. 14 and 27 divide Klein products.  For a unit line ``L`` through ``a``
along ``d``, ``[T|L] = d . T(a)``; with ``U_i = p_k - p_j`` (the side
opposite contact ``i``), ``E_i = p_i - c`` and ``m = (p_2 - p_1) x (p_3 - p_1)``
(twice the contacts' area, normal to their plane), the products reduce to
closed forms that need no 6-vector algebra:

* ``[Sigma_i|Psi_i] = D / (|U_i| |E_i|)`` with ``D = m . (p_1 - c)``, the same
  ``D`` for every ``i``, so
  ``x_i = |U_i| E_i . T(p_i) / D`` and ``y_i = |E_i| U_i . T(p_j) / D``;
* ``Sigma_i(p_i) = m / |U_i|``, so ``[Theta_i|Sigma_i] = w^_i . m / |U_i|``
  and ``alpha_i = U_i . T(p_j) / (w^_i . m)``;
* every ``Theta_j`` and ``Sigma_j`` (``j != i``) keeps ``p_i`` in its tangent
  plane, so the normal velocity ``T(p_i) . n_i`` is ``beta_i Sigma_i(p_i) . n_i``:
  ``beta_i = |U_i| T(p_i) . n_i / (m . n_i)`` (README, "The tangent method
  beyond the paper").

Only differences of points enter the tests and amplitudes, and every
degeneracy measure is a ratio of like quantities, so verdicts do not depend
on the grasp's scale or position.  Coordinates must stay within about
1e-150..1e150 in size (squares of lengths are formed); a row whose numbers
overflow gets the status ``overflow``.

The tangent method is degenerate exactly when some normal lies in the
contacts' plane (``m . n_i = 0``): a normal line set of rank < 3, a
``Theta_i`` that is not unique, and ``[Theta_i|Sigma_i] = 0`` each imply it
(README, "Degenerate grasps").  So the kernel gates on ``m . n_i`` and then
names the specific condition: the normal lines' rank < 3 (a grasp-wide
condition); else exactly one normal in the plane, named (tilting it is the
cure; ``[Theta_j|Sigma_j] = 0`` follows from it for some ``j``, whose axis
passes through another contact); else a ``Theta_i`` that is not unique (two
or three normals in the plane); else ``[Theta_i|Sigma_i]`` within the
tolerance with every normal just outside it.

Plain floats raise ``ZeroDivisionError`` where numpy returns ``inf`` or
``NaN``: that happens only for an exactly degenerate grasp, which the caller
then runs again with :data:`ARRAYS` on numpy scalars (IEEE division, same
operations, so the same result as in a chunk).
"""

from __future__ import annotations

import math
import operator
from collections.abc import Callable
from typing import Any, NamedTuple

import numpy as np

from .degeneracy import IN_PLANE_TOL, Status
from .screws import J, K, add3, cross3, div3, dot3, mul3, sub3

__all__ = [
    "Ops",
    "FLOATS",
    "ARRAYS",
    "off_tangent",
    "tangent",
    "velocities",
    "resolve",
    "settle_one",
    "AMPLITUDES",
    "FAILED",
]


class Ops(NamedTuple):
    """What a kernel needs beyond ``+ - * /``, ``abs`` and comparisons, for one kind of scalar.

    The extrema propagate NaN and the arg-extrema pick the first NaN, as numpy's do.
    """

    sqrt: Callable
    isfinite: Callable
    nonfinite: Callable  # whether any of a sequence is NaN or infinite
    not_: Callable
    minimum: Callable  # of two
    max3: Callable  # of a triple
    min3: Callable
    argmin3: Callable  # index in a triple
    argmax3: Callable


def _fmin(a, b):
    return a if a <= b or a != a else b


def _fmax(a, b):
    return a if a >= b or a != a else b


def _arg3(better):
    def arg(a):
        best = 0
        for i in (1, 2):
            if a[best] == a[best] and (a[i] != a[i] or better(a[i], a[best])):
                best = i
        return best

    return arg


def _nonfinite_floats(components):
    s = sum(components)  # finite only if every term is; else look closer (it may just overflow)
    return s - s != 0 and not all(map(math.isfinite, components))


def _nonfinite_arrays(components):
    finite = np.isfinite(components[0])
    for c in components[1:]:
        finite &= np.isfinite(c)
    return ~finite


#: Plain Python floats (one grasp).
FLOATS = Ops(
    math.sqrt,
    math.isfinite,
    _nonfinite_floats,
    operator.not_,
    _fmin,
    lambda a: _fmax(_fmax(a[0], a[1]), a[2]),
    lambda a: _fmin(_fmin(a[0], a[1]), a[2]),
    _arg3(operator.lt),
    _arg3(operator.gt),
)

#: numpy arrays over rows, or numpy scalars.
ARRAYS = Ops(
    np.sqrt,
    np.isfinite,
    _nonfinite_arrays,
    np.logical_not,
    np.minimum,
    lambda a: np.maximum(np.maximum(a[0], a[1]), a[2]),
    lambda a: np.minimum(np.minimum(a[0], a[1]), a[2]),
    lambda a: np.argmin(np.stack(a), 0),
    lambda a: np.argmax(np.stack(a), 0),
)


# A check is a tuple ``(code, failed, blame, gate)`` (plain tuples: they are made
# at every call).  The first check a row fails gives its status.  ``failed``
# is a boolean (a scalar, or one per row) when ``gate`` is None; a test worth
# running only where the boolean ``gate`` holds is instead a function of a
# row selection (``None`` for all rows; see :func:`at`).  ``blame`` maps a
# row selection to the culprit contact, or is None (culprit -1).


def at(x, rows):
    """``x`` (a component or nested tuples of them) restricted to ``rows`` (None: as it is)."""
    if rows is None:
        return x
    if type(x) is tuple:
        return tuple(at(a, rows) for a in x)
    return x[rows]


def _all_above(a, tol):
    return (a[0] > tol) & (a[1] > tol) & (a[2] > tol)


def _line(p, d):
    """The unit line ``(d; p x d)`` through ``p`` along the unit ``d`` (a tuple), as six components."""
    return d + cross3(p, d)


def _contact_velocities(t, p):
    """``T(p_i) = v + omega x p_i`` for the three contacts."""
    w, v = t[:3], t[3:]
    return (add3(cross3(w, p[0]), v), add3(cross3(w, p[1]), v), add3(cross3(w, p[2]), v))


class _Triangle(NamedTuple):
    side: tuple  # U_i = p_k - p_j
    side_len: tuple
    unit_side: tuple  # direction of Sigma_i
    size: Any  # the longest side
    m: tuple  # (p_2 - p_1) x (p_3 - p_1)
    m_len: Any
    checks: list


def _triangle(p, tol, ops) -> _Triangle:
    """Sides, area vector and the degeneracy checks of the contact triangle.

    Contacts coincide when the shortest side is ``<= tol`` times the longest;
    they are collinear when twice the area is ``<= tol`` times the longest
    side squared (a height ``<= tol`` times the size).
    """
    sqrt = ops.sqrt
    side = (sub3(p[K[0]], p[J[0]]), sub3(p[K[1]], p[J[1]]), sub3(p[K[2]], p[J[2]]))  # U_i = p_k - p_j
    side_len = (sqrt(dot3(side[0], side[0])), sqrt(dot3(side[1], side[1])), sqrt(dot3(side[2], side[2])))
    size = ops.max3(side_len)
    unit_side = (div3(side[0], side_len[0]), div3(side[1], side_len[1]), div3(side[2], side_len[2]))
    # m from unit sides: no fourth powers of lengths, so no under- or overflow
    m = cross3(unit_side[1], unit_side[2])
    area_scale = side_len[1] * side_len[2]
    m_len = sqrt(dot3(m, m)) * area_scale
    m = mul3(m, area_scale)
    checks = [
        (Status.NONFINITE_INPUT, ops.nonfinite((*p[0], *p[1], *p[2])), None, None),
        (Status.OVERFLOW, ops.not_(ops.isfinite(size * size)), None, None),
        # the pair that coincides is opposite the shortest side
        (
            Status.COINCIDENT_CONTACTS,
            ops.not_(ops.min3(side_len) > tol * size),
            lambda rows: ops.argmin3(at(side_len, rows)),
            None,
        ),
        # the contact between the other two is opposite the longest side
        (
            Status.COLLINEAR_CONTACTS,
            ops.not_(m_len > tol * size * size),
            lambda rows: ops.argmax3(at(side_len, rows)),
            None,
        ),
    ]
    return _Triangle(side, side_len, unit_side, size, m, m_len, checks)


def _shared(points, twist, ops, tol, bases):
    """What both methods use: the contact triangle, the contact velocities
    ``T(p_i)``, the lines ``Sigma_i`` (if ``bases``) and whether the twist is finite."""
    tri = _triangle(points, tol, ops)
    sigma = _sigma_lines(points, tri) if bases else None
    return tri, _contact_velocities(twist, points), sigma, ops.nonfinite(twist)


def velocities(points, twist, ops):
    """The contact velocities ``T(p_i)``: values ``{"velocity"}``, no checks."""
    return {"velocity": _contact_velocities(twist, points)}, []


def resolve(points, normals, wrist, twist, ops, tol, bases=True):
    """Both methods (the off-tangent one only with a ``wrist``) and the contact
    velocities, computing what they share once: ``{part: (values, checks)}``."""
    shared = _shared(points, twist, ops, tol, bases)
    parts = {"velocity": ({"velocity": shared[1]}, [])}
    if wrist is not None:
        parts["off_tangent"] = off_tangent(points, wrist, twist, ops, tol, bases, shared)
    parts["tangent"] = tangent(points, normals, twist, ops, tol, bases, shared)
    return parts


def off_tangent(points, wrist, twist, ops, tol, bases=True, shared=None):
    """Proposition 1 (eq. 14) in closed form: values ``sigma``, ``psi`` (if ``bases``),
    ``sigma_psi``, ``x``, ``y``, ``conditioning``, and the checks."""
    p, c, t = points, wrist, twist
    sqrt = ops.sqrt
    tri, v, sigma, bad_twist = shared or _shared(p, t, ops, tol, bases)
    e = (sub3(p[0], c), sub3(p[1], c), sub3(p[2], c))  # E_i
    e_len = (sqrt(dot3(e[0], e[0])), sqrt(dot3(e[1], e[1])), sqrt(dot3(e[2], e[2])))
    d = dot3(tri.m, e[0])  # D, the same for every i
    ls = tri.side_len
    le = (ls[0] * e_len[0], ls[1] * e_len[1], ls[2] * e_len[2])
    conditioning = abs(d) / (ops.max3(le) * tri.size)
    u = tri.side
    values = {
        "sigma_psi": (d / le[0], d / le[1], d / le[2]),
        "x": (ls[0] * dot3(e[0], v[0]) / d, ls[1] * dot3(e[1], v[1]) / d, ls[2] * dot3(e[2], v[2]) / d),
        "y": (
            e_len[0] * dot3(u[0], v[J[0]]) / d,
            e_len[1] * dot3(u[1], v[J[1]]) / d,
            e_len[2] * dot3(u[2], v[J[2]]) / d,
        ),
        "conditioning": conditioning,
    }
    if bases:
        values["sigma"] = sigma
        values["psi"] = (
            _line(p[0], div3(e[0], e_len[0])),
            _line(p[1], div3(e[1], e_len[1])),
            _line(p[2], div3(e[2], e_len[2])),
        )
    checks = tri.checks + [
        (Status.NONFINITE_INPUT, ops.nonfinite(c), None, None),
        (Status.WRIST_COPLANAR, ops.not_(conditioning > tol), None, None),
        (Status.NONFINITE_INPUT, bad_twist, None, None),
    ]
    return values, checks


def _sigma_lines(p, tri):
    """``Sigma_i``: the line through ``p_j`` along ``p_k - p_j``."""
    us = tri.unit_side
    return (_line(p[J[0]], us[0]), _line(p[J[1]], us[1]), _line(p[J[2]], us[2]))


def tangent(points, normals, twist, ops, tol, bases=True, shared=None):
    """Proposition 2 (eqs. 22, 27) and the off-plane rest in closed form: values
    ``theta``, ``sigma`` (if ``bases``), ``theta_sigma``, ``alpha``, ``beta``,
    ``normal_velocity``, ``in_tangent_planes``, ``conditioning``, and the checks."""
    p, t = points, twist
    sqrt = ops.sqrt
    tri, v, sigma, bad_twist = shared or _shared(p, t, ops, tol, bases)
    nr = normals
    n_len = (sqrt(dot3(nr[0], nr[0])), sqrt(dot3(nr[1], nr[1])), sqrt(dot3(nr[2], nr[2])))
    n = (div3(normals[0], n_len[0]), div3(normals[1], n_len[1]), div3(normals[2], n_len[2]))
    us = tri.unit_side
    # eqs. 21-22 with p_i p_j along U_k and p_i p_k along -U_j; unit sides keep
    # |w| free of the grasp's size (no underflow) and |a|, |b| sines
    a = (cross3(us[K[0]], n[J[0]]), cross3(us[K[1]], n[J[1]]), cross3(us[K[2]], n[J[2]]))
    b = (cross3(n[K[0]], us[J[0]]), cross3(n[K[1]], us[J[1]]), cross3(n[K[2]], us[J[2]]))
    w = (cross3(a[0], b[0]), cross3(a[1], b[1]), cross3(a[2], b[2]))
    w_len = (sqrt(dot3(w[0], w[0])), sqrt(dot3(w[1], w[1])), sqrt(dot3(w[2], w[2])))
    w = (div3(w[0], w_len[0]), div3(w[1], w_len[1]), div3(w[2], w_len[2]))
    m, ls, size = tri.m, tri.side_len, tri.size
    wm = (dot3(w[0], m), dot3(w[1], m), dot3(w[2], m))
    mn = (dot3(m, n[0]), dot3(m, n[1]), dot3(m, n[2]))
    plane_sine = (abs(mn[0]) / tri.m_len, abs(mn[1]) / tri.m_len, abs(mn[2]) / tri.m_len)
    theta_sigma = (abs(wm[0]) / (ls[0] * size), abs(wm[1]) / (ls[1] * size), abs(wm[2]) / (ls[2] * size))
    conditioning = ops.minimum(ops.min3(theta_sigma), ops.min3(plane_sine))
    nv = (dot3(v[0], n[0]), dot3(v[1], n[1]), dot3(v[2], n[2]))
    u = tri.side
    # Round-off in v + omega x p scales with |v| + |omega||p|, not with the result.
    speed, spin = sqrt(dot3(t[3:], t[3:])), sqrt(dot3(t[:3], t[:3]))
    reach = (
        speed + spin * sqrt(dot3(p[0], p[0])),
        speed + spin * sqrt(dot3(p[1], p[1])),
        speed + spin * sqrt(dot3(p[2], p[2])),
    )
    values = {
        "theta_sigma": (wm[0] / ls[0], wm[1] / ls[1], wm[2] / ls[2]),
        "alpha": (dot3(u[0], v[J[0]]) / wm[0], dot3(u[1], v[J[1]]) / wm[1], dot3(u[2], v[J[2]]) / wm[2]),
        "beta": (ls[0] * nv[0] / mn[0], ls[1] * nv[1] / mn[1], ls[2] * nv[2] / mn[2]),
        "normal_velocity": nv,
        "in_tangent_planes": ops.max3((abs(nv[0]), abs(nv[1]), abs(nv[2]))) <= IN_PLANE_TOL * ops.max3(reach),
        "conditioning": conditioning,
    }
    if bases:
        values["theta"] = (_line(p[0], w[0]), _line(p[1], w[1]), _line(p[2], w[2]))
        values["sigma"] = sigma

    def uniqueness(rows):
        """Sines that vanish when eq. 22's two constraints do not fix one axis."""
        out = []
        for i in range(3):
            ai, bi = at(a[i], rows), at(b[i], rows)
            a_len, b_len = sqrt(dot3(ai, ai)), sqrt(dot3(bi, bi))
            out.append(ops.minimum(ops.minimum(a_len, b_len), at(w_len[i], rows) / (a_len * b_len)))
        return tuple(out)

    degenerate = ops.not_(conditioning > tol)
    checks = tri.checks + [
        (Status.NONFINITE_INPUT, ops.nonfinite((*normals[0], *normals[1], *normals[2])), None, None),
        (
            Status.ZERO_NORMAL,
            ops.not_((n_len[0] > 0) & (n_len[1] > 0) & (n_len[2] > 0)),
            lambda rows: ops.argmin3(at(n_len, rows)),
            None,
        ),
        (
            Status.NORMALS_RANK_DEFICIENT,
            lambda rows: _rank_deficient(at(p, rows), at(n, rows), at(size, rows), tol, ops),
            None,
            degenerate,
        ),
        # one normal in the plane is the cause of the two conditions below, and names the contact
        # whose normal to tilt; they may blame another contact (the one their axis goes through)
        (
            Status.NORMAL_IN_CONTACT_PLANE,
            lambda rows: _just_one(at(plane_sine, rows), tol, ops),
            lambda rows: ops.argmin3(at(plane_sine, rows)),
            degenerate,
        ),
        (
            Status.THETA_NOT_UNIQUE,
            lambda rows: ops.not_(_all_above(uniqueness(rows), tol)),
            lambda rows: ops.argmin3(uniqueness(rows)),
            degenerate,
        ),
        (
            Status.THETA_SIGMA_ZERO,
            lambda rows: ops.not_(_all_above(at(theta_sigma, rows), tol)),
            lambda rows: ops.argmin3(at(theta_sigma, rows)),
            degenerate,
        ),
        (Status.NORMAL_IN_CONTACT_PLANE, degenerate, lambda rows: ops.argmin3(at(plane_sine, rows)), None),
        (Status.NONFINITE_INPUT, bad_twist, None, None),
    ]
    return values, checks


def _just_one(sines, tol, ops):
    """Whether exactly one of three sines is ``<= tol`` (NaN counts as ``<= tol``).

    >>> _just_one((0.5, 1e-12, 0.3), 1e-9, FLOATS), _just_one((0.0, 0.0, 0.3), 1e-9, FLOATS)
    (True, False)
    """
    a, b, c = (ops.not_(s > tol) for s in sines)
    return (a ^ b ^ c) & ops.not_(a & b & c)


def _rank_deficient(p, n, size, tol, ops):
    """Whether the normal lines ``nu_i = (n_i; p_i x n_i)`` have rank < 3.

    Gram-Schmidt on the three 6-vectors, taken about ``p_1`` in units of the
    size: the product of the orthogonalised lengths over the original ones is
    in ``[0, 1]`` and accurate to round-off even near 0.
    """

    def dot6(x, y):
        return x[0] * y[0] + x[1] * y[1] + x[2] * y[2] + x[3] * y[3] + x[4] * y[4] + x[5] * y[5]

    def minus(x, y, s):  # x - s y
        return tuple(xi - s * yi for xi, yi in zip(x, y))

    r1, r2, r3 = ((*n[i], *cross3(div3(sub3(p[i], p[0]), size), n[i])) for i in range(3))
    u1 = tuple(c / ops.sqrt(dot6(r1, r1)) for c in r1)
    r2o = minus(r2, u1, dot6(r2, u1))
    u2 = tuple(c / ops.sqrt(dot6(r2o, r2o)) for c in r2o)
    r3o = minus(minus(r3, u1, dot6(r3, u1)), u2, dot6(r3, u2))
    volume = ops.sqrt(dot6(r2o, r2o) * dot6(r3o, r3o) / (dot6(r2, r2) * dot6(r3, r3)))
    return ops.not_(volume > tol)


#: Each method's amplitudes: NaN where the method failed; a row that passes
#: every check but has a non-finite amplitude has overflowed.
AMPLITUDES = {"off_tangent": ("x", "y"), "tangent": ("alpha", "beta", "normal_velocity")}

#: What the values of a failed row become.
FAILED = {
    **{name: math.nan for names in AMPLITUDES.values() for name in names},
    "in_tangent_planes": False,  # unknown where the method failed
}


def settle_one(values, checks, amplitudes):
    """``(status, culprit)`` of one grasp from its checks (the first failure wins),
    then overflow of the values named in ``amplitudes``; the values of a failed
    grasp are replaced as :data:`FAILED` says."""
    for code, failed, blame, gate in checks:
        if failed if gate is None else gate and failed(None):
            status, culprit = code, (-1 if blame is None else int(blame(None)))
            break
    else:
        status, culprit = Status.OK, -1
        if amplitudes and _nonfinite_floats(sum((values[name] for name in amplitudes), ())):
            status = Status.OVERFLOW
    if status != Status.OK:
        for name in values.keys() & FAILED.keys():
            blank = FAILED[name]
            values[name] = tuple(blank for _ in values[name]) if type(values[name]) is tuple else blank
    return status, culprit
