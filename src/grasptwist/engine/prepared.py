"""Many twists on one grasp: the grasp's part done once, each twist a matrix product.

The bases, their Klein products, the conditioning and the degeneracy
verdicts of a grasp do not depend on the twist, and every amplitude is
linear in it (eqs. 14 and 27 divide Klein products with the twist by
numbers of the grasp).  :func:`prepare` runs the engine once on the six
unit twists, which gives the columns of that linear map; then
:meth:`PreparedGrasp.resolve` costs one ``(24, 6)`` matrix product per twist,
for a hand controller that resolves a new twist at every tick.
"""

from __future__ import annotations

import math
from dataclasses import fields

import numpy as np

from .checks import check_normals, check_points, check_twist, check_wrist
from .decompose import OffTangentResult, Resolution, TangentResult, contact_velocities, resolve
from .degeneracy import DEGENERACY_TOL, IN_PLANE_TOL, Status
from .screws import dot, dot3

__all__ = ["PreparedGrasp", "prepare"]


def _frozen(a):
    """``a`` as a read-only array: the results of different twists share it."""
    a = np.array(a)
    a.flags.writeable = False
    return a


_TRUE, _FALSE = _frozen(True), _frozen(False)
#: Bound on the map product's terms on the fast path: far from overflow.
_LARGEST = 1e300
_AMPLITUDES = {"off_tangent": ("x", "y"), "tangent": ("alpha", "beta", "normal_velocity")}
_RESULTS = {"off_tangent": OffTangentResult, "tangent": TangentResult}


class PreparedGrasp:
    """One grasp, ready to resolve any number of twists (made by :func:`prepare`).

    Attributes
    ----------
    points, normals, wrist : (3, 3), (3, 3), (3,) or None
        The grasp (read-only).
    off_tangent, tangent : OffTangentResult or None, TangentResult
        The results for the zero twist: the bases, their Klein products,
        the conditioning, status and culprit (``off_tangent`` is None
        without a wrist).
    map : (k, 6)
        The linear map from a twist to its amplitudes and contact
        velocities: rows ``x``, ``y`` (with a wrist), ``alpha``, ``beta``,
        ``normal_velocity``, then ``T(p_1)``, ``T(p_2)``, ``T(p_3)``.
    """

    def __init__(self, points, normals, wrist, zero: Resolution, unit: Resolution):
        self.points, self.normals, self.wrist = points, normals, wrist
        self.off_tangent, self.tangent = zero.off_tangent, zero.tangent
        columns, self._rows, self._status, self._templates = [], {}, {}, {}
        for name, amplitudes in _AMPLITUDES.items():
            r, u = getattr(zero, name), getattr(unit, name)
            if r is None:
                continue
            self._rows[name] = slice(3 * len(columns), 3 * (len(columns) + len(amplitudes)))
            columns += [getattr(u, a) for a in amplitudes]
            status = Status(int(r.status))
            if status == Status.OK and (u.status == Status.OVERFLOW).any():
                status = Status.OVERFLOW  # a twist's amplitudes overflow where a unit twist's do
            self._status[name] = status
            template = {f.name: _frozen(getattr(r, f.name)) for f in fields(r) if f.name not in amplitudes}
            self._templates[name] = {**template, "status": _frozen(np.int8(status))}
        self._rows["velocity"] = slice(3 * len(columns), 3 * len(columns) + 9)
        self.map = _frozen(np.concatenate([*columns, unit.velocity.reshape(6, 9)], axis=1).T)
        # For the fast path, per method: its result type, the values no twist changes (NaN
        # amplitudes for a failed method) and, for a working one, which row of three each
        # amplitude is.
        self._fast = []
        for name, template in self._templates.items():
            failed = self._status[name] != Status.OK
            nan = _frozen(np.full(3, np.nan))
            template = {**template, "points": self.points, **({a: nan for a in _AMPLITUDES[name]} if failed else {})}
            rows = (
                () if failed else tuple((a, self._rows[name].start // 3 + i) for i, a in enumerate(_AMPLITUDES[name]))
            )
            self._fast.append((_RESULTS[name], template, rows))
        # ... the map with a failed method's rows zeroed (the fast path does not read them),
        # and its largest |entry|: a twist whose sum of |components| stays below _LARGEST / gain
        # can neither overflow the product (nor any partial sum of it) nor meet a non-finite entry.
        used = np.zeros(len(self.map), bool)
        for name, rows in self._rows.items():
            used[rows] = self._status.get(name, Status.OK) == Status.OK
        self._used_map = np.where(used[:, None], self.map, 0.0)
        gain = float(np.abs(self._used_map).max())
        self._largest_twist = _LARGEST / gain if math.isfinite(gain) and gain > 0 else 0.0
        # The largest |p_i| as the kernel forms it: in_tangent_planes compares the normal
        # velocities with |v| + |omega| |p_i|, which is largest for the largest |p_i|.
        self._reach = max(math.sqrt(dot3(p, p)) for p in points.tolist())
        self._nv = self._rows["tangent"].start + 6  # the normal velocities' first row of the map
        self._slots = (0, 1) if len(self._fast) == 2 else (1,)  # where each method goes in a Resolution
        self._tangent_works = self._status["tangent"] == Status.OK

    def resolve(self, twist) -> Resolution:
        """Both decompositions and the contact velocities of ``twist`` on this grasp.

        Parameters
        ----------
        twist : (..., 6) array
            ``(omega; v)`` with ``v`` at the origin; one twist or many.

        Returns
        -------
        Resolution
            What :func:`~grasptwist.resolve` gives for this
            grasp and twist: the same statuses, bases and Klein products,
            and amplitudes and velocities equal but for the last few units
            in the last place (the matrix product adds the same terms in
            another order).  Arrays that do not depend on the twist are
            shared, read-only, by every result.

        Examples
        --------
        Paper Example 1; a spin about z, then a spin and a lift at once:

        >>> g = prepare([[1, 0, 0], [-0.5, 0.866, 0], [-0.5, -0.866, 0]], np.eye(3), [0, 0, 1])
        >>> np.round(g.resolve([0, 0, 1, 0, 0, 0]).off_tangent.y, 4).tolist()
        [-0.4714, -0.4714, -0.4714]
        >>> r = g.resolve([[0, 0, 1, 0, 0, 0], [0, 0, 0, 0, 0, 1]])
        >>> (np.round(r.off_tangent.x, 4) + 0.0).tolist()
        [[0.0, 0.0, 0.0], [0.6667, 0.6667, 0.6667]]
        """
        t = check_twist(twist)
        if t.ndim == 1:
            values = t.tolist()
            if sum(map(abs, values)) < self._largest_twist:  # no product can overflow (NaN fails too)
                return self._one(t, values)
        return self._many(t)

    def _one(self, t, twist):
        """One twist whose amplitudes are sure to be finite: the hot path of a control loop."""
        r = self._used_map.dot(t)
        triples = r.reshape(-1, 3)  # x, y, ..., T(p_3): one row each
        parts = [None, None]  # off-tangent, tangent
        for slot, (cls, template, rows) in zip(self._slots, self._fast):
            result = parts[slot] = object.__new__(cls)  # as cls._of does, without the call
            values = result.__dict__
            values.update(template)
            values["twist"] = t
            for a, i in rows:
                values[a] = triples[i]
        if self._tangent_works:
            parts[1].__dict__["in_tangent_planes"] = self._in_tangent_planes(twist, r)
        return tuple.__new__(Resolution, (*parts, triples[-3:]))  # Resolution's own __new__ is Python

    def _in_tangent_planes(self, twist, r):
        """The kernel's verdict for one twist: every normal velocity within ``IN_PLANE_TOL``
        of the largest contact speed's bound ``|v| + |omega| max |p_i|``."""
        w, v = twist[:3], twist[3:]
        speed, spin = math.sqrt(dot3(v, v)), math.sqrt(dot3(w, w))
        i = self._nv
        return (
            _TRUE
            if max(abs(r.item(i)), abs(r.item(i + 1)), abs(r.item(i + 2)))
            <= IN_PLANE_TOL * (speed + spin * self._reach)
            else _FALSE
        )

    def _many(self, t):
        """Twists with any leading axes ``(..., 6)``, including a non-finite one."""
        with np.errstate(all="ignore"):
            r = np.einsum("ij,...j->...i", self.map, t)
        shape = t.shape[:-1]
        with np.errstate(invalid="ignore", over="ignore"):
            bad_twist = ~np.isfinite(t).all(axis=-1)
            reach = np.sqrt(dot(t[..., 3:], t[..., 3:])) + np.sqrt(dot(t[..., :3], t[..., :3])) * self._reach
        parts = {}
        for name, template in self._templates.items():
            block = r[..., self._rows[name]]
            status = np.full(shape, self._status[name], dtype=np.int8)
            if self._status[name] == Status.OK:
                status[bad_twist] = Status.NONFINITE_INPUT
                status[(status == Status.OK) & ~np.isfinite(block).all(axis=-1)] = Status.OVERFLOW
            failed = status != Status.OK
            block = np.where(failed[..., None], np.nan, block)
            out = {k: np.broadcast_to(v, shape + v.shape) for k, v in template.items()}
            out.update(status=status, points=np.broadcast_to(self.points, shape + (3, 3)), twist=t)
            out.update({a: block[..., 3 * i : 3 * i + 3] for i, a in enumerate(_AMPLITUDES[name])})
            if name == "tangent":
                with np.errstate(invalid="ignore"):
                    out["in_tangent_planes"] = ~failed & (
                        np.max(np.abs(out["normal_velocity"]), -1) <= IN_PLANE_TOL * reach
                    )
            parts[name] = _RESULTS[name]._of(out)
        # in closed form, as fresh calls: a map row's 0 * inf would make a velocity
        # NaN that a non-finite twist leaves finite
        return Resolution(parts.get("off_tangent"), parts["tangent"], contact_velocities(self.points, t))


def prepare(points, normals, wrist=None, *, tol=DEGENERACY_TOL) -> PreparedGrasp:
    """One grasp's bases, verdicts and linear map, for resolving many twists cheaply.

    Parameters
    ----------
    points : (3, 3) array
        The contacts of one grasp (no batch axis).
    normals : (3, 3) array
        Their surface normals, any non-zero length.
    wrist : (3,) array or None
        The wrist point; without it there is no off-tangent result.
    tol : float
        Relative tolerance of the degeneracy tests.

    Returns
    -------
    PreparedGrasp
        Its :meth:`~PreparedGrasp.resolve` gives, for any twist, what
        :func:`~grasptwist.resolve` gives on this grasp.

    Examples
    --------
    Paper Example 2: a spin about the diagonal, then a lift (a degenerate grasp
    still prepares: its results carry the status):

    >>> g = prepare([[0, 2, 2], [2, 0, 2], [2, 2, 0]], np.eye(3))
    >>> np.round(g.resolve([0.57735, 0.57735, 0.57735, 0, 0, 0]).tangent.alpha, 4).tolist()
    [0.5774, 0.5774, 0.5774]
    >>> (g.resolve([0, 0, 0, 0, 0, 1]).tangent.beta.round(4) + 0.0).tolist()
    [0.0, 0.0, 0.7071]
    >>> flat = prepare([[1, 0, 0], [-0.5, 0.866, 0], [-0.5, -0.866, 0]], np.eye(3), [0, 0, 0])
    >>> Status(int(flat.resolve([0, 0, 1, 0, 0, 0]).off_tangent.status)).code
    'wrist-coplanar'
    """
    points, normals = check_points(points), check_normals(normals)
    wrist = None if wrist is None else check_wrist(wrist)
    for name, a, ndim in (("points", points, 2), ("normals", normals, 2), ("wrist", wrist, 1)):
        if a is not None and a.ndim != ndim:
            raise ValueError(f"prepare takes one grasp: {name} must have no batch axis, got shape {a.shape}")
    points, normals = _frozen(points), _frozen(normals)
    wrist = None if wrist is None else _frozen(wrist)
    zero = resolve(points, normals, wrist, np.zeros(6), tol=tol)
    unit = resolve(points, normals, wrist, np.eye(6), tol=tol, bases=False)  # the map's columns
    return PreparedGrasp(points, normals, wrist, zero, unit)
