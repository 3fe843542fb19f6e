"""The paper's two decompositions of an object twist, for one grasp or batches of millions.

* :func:`decompose_off_tangent` -- Proposition 1 (eqs. 8-14): ``T = sum x_i
  Sigma_i + sum y_i Psi_i``, where ``Sigma_i`` (the line ``p_j p_k``) moves
  only contact ``i`` and ``Psi_i`` (the line from the wrist ``c`` through
  ``p_i``) keeps contact ``i`` fixed.
* :func:`decompose_tangent` -- Proposition 2 (eqs. 19-27) and its extension
  to any twist (docs/reference/conventions.md, "The tangent method beyond the paper"): ``T = sum
  alpha_i Theta_i + sum beta_i Sigma_i``, where ``Theta_i`` keeps contact
  ``i`` fixed and the other two sliding in their tangent planes.  ``beta =
  0`` exactly when ``T`` moves every contact in its tangent plane.
* :func:`contact_velocities` -- ``T(p_i)``.

Shapes: ``points`` and ``normals`` are ``(..., 3, 3)`` (contact, xyz),
``wrist`` is ``(..., 3)``, ``twist`` is ``(..., 6)`` as ``(omega; v)`` with
``v`` the velocity of the frame origin.  Leading shapes broadcast, so one
grasp can take many twists or many grasps one twist.  Arguments are checked
by :mod:`~grasptwist.engine.checks`.

The numbers come from the closed forms of :mod:`~grasptwist.engine.kernels`,
run one of two ways with the same operations, so a row gets the same bits
either way and whatever batch it is in:

* up to :data:`SMALL_BATCH` rows, each row in plain Python floats (a call
  for one grasp inside a control loop costs tens of microseconds, not the
  fixed cost of the batch machinery);
* above it, in chunks of :data:`CHUNK` rows whose temporaries stay in the
  CPU cache, each component of each vector one contiguous array over the
  chunk's rows.  Results are views of that components-first layout with the
  documented shapes.

A degenerate grasp never raises: its row gets a
:class:`~grasptwist.engine.degeneracy.Status` and NaN amplitudes, while every
other row is computed exactly as it would be alone.  For many twists on one
grasp, :func:`~grasptwist.engine.prepared.prepare` does the grasp's part once.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from functools import cached_property
from math import prod
from typing import NamedTuple

import numpy as np

from . import kernels
from .checks import SHAPES, check_normals, check_points, check_twist, check_wrist
from .degeneracy import DEGENERACY_TOL, Status
from .screws import field_at, norm

__all__ = [
    "Resolution",
    "resolve",
    "OffTangentResult",
    "TangentResult",
    "decompose_off_tangent",
    "decompose_tangent",
    "contact_velocities",
]

#: Rows per chunk: small enough for a chunk's temporaries to stay in cache,
#: large enough that numpy's per-call overhead is noise (each temporary is
#: 128 KiB; measured with bench/engine.py, smaller chunks lose to the allocator).
CHUNK = 16384

#: Batches of up to this many rows are computed row by row in plain floats:
#: below it that is faster than the chunked arrays' fixed cost.
SMALL_BATCH = 12


def contact_velocities(points, twist):
    """Velocities ``T(p_i) = v + omega x p_i`` of the three contacts.

    Parameters
    ----------
    points : (..., 3, 3) array
    twist : (..., 6) array, ``(omega; v)``

    Returns
    -------
    (..., 3, 3) array, row ``i`` the velocity of contact ``i``.

    Examples
    --------
    >>> contact_velocities([[1.0, 0, 0], [0, 1, 0], [0, 0, 1]], [0, 0, 1.0, 0, 0, 0]).tolist()
    [[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 0.0]]
    """
    inputs = {"points": check_points(points), "twist": check_twist(twist)}
    return _run(_velocities, ("velocity",), inputs, (), bases=True)[0]["velocity"]["velocity"]


def _index(a, i):
    return None if a is None else a[i]


@dataclass(frozen=True, eq=False, init=False, repr=False)  # never made itself: each result makes its own
class _Result:
    """What both results share: per-row status, conditioning and inputs (each result's
    Attributes list them), row access and the lazily computed residual."""

    status: np.ndarray
    culprit: np.ndarray
    conditioning: np.ndarray
    points: np.ndarray
    twist: np.ndarray

    @classmethod
    def _of(cls, values):
        """An instance from a dict of every field's value.  It skips the frozen
        dataclass ``__init__``, which only assigns them, one by one: for one
        grasp that is a noticeable part of the call."""
        r = object.__new__(cls)
        r.__dict__.update(values)
        return r

    @property
    def ok(self) -> np.ndarray:
        """``status == 0`` per row."""
        return self.status == Status.OK

    def _with_bases(self):
        """``self``, or a ValueError when it was computed with ``bases=False`` (amplitudes only)."""
        if self.sigma is None:
            raise ValueError("components need the basis screws: decompose with bases=True (the default)")
        return self

    def row(self, i):
        """Row ``i`` (an index into the leading axis) as a result of the same type.

        Raises
        ------
        ValueError
            For a result of one grasp and one twist, which has no rows.

        Examples
        --------
        Paper Example 1 with two twists (a spin about z, a lift along z):

        >>> p = [[1, 0, 0], [-0.5, 0.866, 0], [-0.5, -0.866, 0]]
        >>> r = decompose_off_tangent(p, [0, 0, 1], [[0, 0, 1, 0, 0, 0], [0, 0, 0, 0, 0, 1]])
        >>> r.row(1).x.round(4).tolist()
        [0.6667, 0.6667, 0.6667]
        >>> r.row(1).row(0)
        Traceback (most recent call last):
        ...
        ValueError: row(0): this result is for one grasp and one twist (no batch axis); use it as it is
        """
        if np.ndim(self.status) == 0:
            raise ValueError(f"row({i}): this result is for one grasp and one twist (no batch axis); use it as it is")
        r = type(self)(**{f.name: _index(getattr(self, f.name), i) for f in fields(self)})
        if "residual" in self.__dict__:  # carry a residual already computed for the batch
            r.__dict__["residual"] = self.__dict__["residual"][i]
        return r

    @cached_property
    def residual(self) -> np.ndarray:
        """``max_i |R(p_i)| / max_i |T(p_i)|``, ``R`` = the sum of the components minus ``T``.

        Computed on first access from the returned screws and amplitudes;
        NaN in failed rows, 0 for the zero twist.  The twist and the components
        are scaled by ``2^-e``, ``e`` the exponent of the twist's largest entry:
        exactly, so the ratio has the bits it has unscaled, but the components'
        sum stays finite for a twist near ``1e308`` (an ok row's residual is a number).

        >>> p = [[1, 0, 0], [-0.5, 0.866, 0], [-0.5, -0.866, 0]]
        >>> float(decompose_off_tangent(p, [0, 0, 1], [0, 0, 1e308, 0, 0, 0]).residual) < 1e-15
        True
        """
        with np.errstate(all="ignore"):  # failed rows hold NaN, overflowed ones inf
            e = -np.frexp(np.max(np.abs(self.twist), axis=-1))[1]
            r = sum(np.ldexp(a, e[..., None, None]).sum(axis=-2) for a in self.components())
            r = r - np.ldexp(self.twist, e[..., None])
            err = np.max(norm(field_at(r[..., None, :], self.points)), axis=-1)
            ref = np.max(norm(field_at(np.ldexp(self.twist, e[..., None])[..., None, :], self.points)), axis=-1)
            return np.where(ref > 0, err / np.where(ref > 0, ref, 1.0), err)


@dataclass(frozen=True, eq=False)
class OffTangentResult(_Result):
    """Proposition 1 for a batch: ``T = sum x_i Sigma_i + sum y_i Psi_i``.

    Attributes
    ----------
    sigma, psi : (..., 3, 6)
        Unit basis lines.  ``Sigma_i`` passes through ``p_j`` along
        ``p_k - p_j``; ``Psi_i`` passes through ``p_i`` along ``p_i - c``.
    sigma_psi : (..., 3)
        ``[Sigma_i | Psi_i]`` (eq. 14's denominators; a length).
    x, y : (..., 3)
        Amplitudes, eq. 14.  NaN where ``status != 0``.
    conditioning : (...)
        ``min_i |[Sigma_i|Psi_i]| / size`` (dimensionless; size = longest
        side of the contact triangle).
    status, culprit : (...) int8
        The :class:`~grasptwist.Status` of each row and the contact it is about
        (0..2, or -1).
    points, twist : (..., 3, 3), (..., 6)
        The inputs, broadcast to the batch shape.
    """

    sigma: np.ndarray
    psi: np.ndarray
    sigma_psi: np.ndarray
    x: np.ndarray
    y: np.ndarray

    def components(self):
        """The component twists ``(x_i Sigma_i, y_i Psi_i)``, each ``(..., 3, 6)``: their sums over
        the component axis (``-2``) add up to the twist.  A ValueError with ``bases=False``."""
        self._with_bases()
        return self.x[..., None] * self.sigma, self.y[..., None] * self.psi


@dataclass(frozen=True, eq=False)
class TangentResult(_Result):
    """Proposition 2 and its extension: ``T = sum alpha_i Theta_i + sum beta_i Sigma_i``.

    Attributes
    ----------
    theta : (..., 3, 6)
        Unit lines through ``p_i`` along ``w_i = (n_j x p_i p_j) x (n_k x p_i p_k)``
        (eq. 22): twists that fix ``p_i`` and slide ``p_j``, ``p_k`` in their
        tangent planes.
    sigma : (..., 3, 6)
        The same ``Sigma_i`` as :class:`OffTangentResult`.
    theta_sigma : (..., 3)
        ``[Theta_i | Sigma_i]`` (eq. 27's denominators).
    alpha : (..., 3)
        Tangent amplitudes, eq. 27.
    beta : (..., 3)
        Off-plane remainder amplitudes, ``beta_i = [R|Theta_i]/[Sigma_i|Theta_i]``
        with ``R = T - sum alpha_i Theta_i`` (docs/reference/conventions.md,
        "The tangent method beyond the paper").  Zero when ``T`` keeps every
        contact in its tangent plane.
    normal_velocity : (..., 3)
        ``[T | nu_i] = T(p_i) . n_i`` with unit normals.
    in_tangent_planes : (...) bool
        Every normal velocity is zero to ``IN_PLANE_TOL`` relative to the
        contacts' speeds: ``T`` is realisable by tangent sliding alone.
    conditioning : (...)
        The smaller of ``min_i |[Theta_i|Sigma_i]| / size`` and of
        ``min_i |sin|`` of the angle between normal ``i`` and the contacts'
        plane; both go to 0 at every degenerate grasp.
    status, culprit : (...) int8
        The :class:`~grasptwist.Status` of each row and the contact it is about
        (0..2, or -1).
    points, twist : (..., 3, 3), (..., 6)
        The inputs, broadcast to the batch shape.
    """

    theta: np.ndarray
    sigma: np.ndarray
    theta_sigma: np.ndarray
    alpha: np.ndarray
    beta: np.ndarray
    normal_velocity: np.ndarray
    in_tangent_planes: np.ndarray

    def components(self):
        """The component twists ``(alpha_i Theta_i, beta_i Sigma_i)``, each ``(..., 3, 6)``: their sums
        over the component axis (``-2``) add up to the twist.  A ValueError with ``bases=False``."""
        self._with_bases()
        return self.alpha[..., None] * self.theta, self.beta[..., None] * self.sigma

    def contact_split(self):
        """Each contact's velocity split by the screws that move it (the paper's second approach).

        ``Theta_i`` and ``Sigma_j`` (``j != i``) leave ``p_i`` fixed, so
        ``T(p_i) = sum_{j != i} alpha_j Theta_j(p_i) + beta_i Sigma_i(p_i)``.

        Returns
        -------
        theta_velocity : (..., 3, 3, 3)
            ``[..., i, j, :] = alpha_j Theta_j(p_i)``, zero for ``j == i``;
            each lies in the tangent plane at ``p_i``.
        sigma_velocity : (..., 3, 3)
            ``[..., i, :] = beta_i Sigma_i(p_i)``, normal to the contact plane.
        """
        theta_at = field_at(self.theta[..., None, :, :], self.points[..., :, None, :])
        sigma_at = field_at(self.sigma, self.points)
        return self.alpha[..., None, :, None] * theta_at, self.beta[..., None] * sigma_at


def decompose_off_tangent(points, wrist, twist, *, tol=DEGENERACY_TOL, bases=True) -> OffTangentResult:
    """Resolve ``twist`` on the off-tangent basis (Proposition 1).

    ``x_i = [T|Psi_i] / [Sigma_i|Psi_i]``, ``y_i = [T|Sigma_i] / [Sigma_i|Psi_i]``
    (eq. 14), valid when the wrist is off the contacts' plane.

    Parameters
    ----------
    points : (..., 3, 3) array
    wrist : (..., 3) array
        The point ``c`` (centre of the wrist's spherical joint).
    twist : (..., 6) array
        ``(omega; v)`` with ``v`` at the origin.
    tol : float
        Relative tolerance of the degeneracy tests (see ``grasptwist.engine.degeneracy``).
    bases : bool
        False leaves out the basis screws (``sigma``, ``psi`` are None, and
        so cannot give components or a residual): a third less work and
        memory when only amplitudes and statuses are wanted.

    Returns
    -------
    OffTangentResult

    Examples
    --------
    Paper Example 1b, a spin about z (corrected values: docs/reference/conventions.md):

    >>> p = [[1, 0, 0], [-0.5, 0.866, 0], [-0.5, -0.866, 0]]
    >>> r = decompose_off_tangent(p, [0, 0, 1], [0, 0, 1, 0, 0, 0])
    >>> np.round(r.y, 4).tolist(), bool(np.allclose(r.x, 0))
    ([-0.4714, -0.4714, -0.4714], True)
    """
    inputs = {"points": check_points(points), "wrist": check_wrist(wrist), "twist": check_twist(twist)}
    parts, inputs = _run(_off_tangent, ("off_tangent",), inputs, (tol, bases), bases)
    return _result(OffTangentResult, parts["off_tangent"], inputs)


def decompose_tangent(points, normals, twist, *, tol=DEGENERACY_TOL, bases=True) -> TangentResult:
    """Resolve ``twist`` on the tangent basis ``Theta`` plus the off-plane ``Sigma``.

    ``alpha_i = [T|Sigma_i] / [Theta_i|Sigma_i]`` (eq. 27) and
    ``beta_i = [T - sum alpha_j Theta_j | Theta_i] / [Sigma_i|Theta_i]``, so
    that ``sum alpha_i Theta_i + sum beta_i Sigma_i = T`` for any twist.

    Parameters
    ----------
    points : (..., 3, 3) array
    normals : (..., 3, 3) array
        Surface normals at the contacts, any non-zero length (normalised here).
    twist : (..., 6) array
        ``(omega; v)`` with ``v`` at the origin.
    tol : float
        Relative tolerance of the degeneracy tests.
    bases : bool
        False leaves out the basis screws (``theta``, ``sigma`` are None),
        as for :func:`decompose_off_tangent`.

    Returns
    -------
    TangentResult

    Examples
    --------
    Paper Example 2 (``alpha = 0.5774`` each, no off-plane part):

    >>> p = [[0, 2, 2], [2, 0, 2], [2, 2, 0]]
    >>> r = decompose_tangent(p, np.eye(3), [0.57735, 0.57735, 0.57735, 0, 0, 0])
    >>> np.round(r.alpha, 4).tolist(), (np.round(r.beta, 4) + 0.0).tolist(), bool(r.in_tangent_planes)
    ([0.5774, 0.5774, 0.5774], [0.0, 0.0, 0.0], True)
    """
    inputs = {"points": check_points(points), "normals": check_normals(normals), "twist": check_twist(twist)}
    parts, inputs = _run(_tangent, ("tangent",), inputs, (tol, bases), bases)
    return _result(TangentResult, parts["tangent"], inputs)


class Resolution(NamedTuple):
    """Both methods' results and the contact velocities of the same rows.

    Attributes
    ----------
    off_tangent : OffTangentResult or None
        None when no wrist was given.
    tangent : TangentResult
    velocity : (..., 3, 3)
        ``T(p_i)``, as :func:`contact_velocities`.
    """

    off_tangent: OffTangentResult | None
    tangent: TangentResult
    velocity: np.ndarray


def resolve(points, normals, wrist, twist, *, tol=DEGENERACY_TOL, bases=True) -> Resolution:
    """Both decompositions and the contact velocities in one call.

    The same numbers, bit for bit, as :func:`decompose_off_tangent`,
    :func:`decompose_tangent` and :func:`contact_velocities` called
    separately, for less: the contact triangle and the contact velocities are
    computed once.  For many twists on one grasp see :func:`prepare`.

    Parameters
    ----------
    points, normals : (..., 3, 3) array
        The contacts and their normals (any non-zero length), as for those.
    wrist : (..., 3) array or None
        None: no off-tangent result (``off_tangent`` is None).
    twist : (..., 6) array
        ``(omega; v)`` with ``v`` at the origin.
    tol, bases
        As for :func:`decompose_off_tangent`.

    Returns
    -------
    Resolution
        ``(off_tangent, tangent, velocity)``.

    Examples
    --------
    Paper Example 2 (no wrist given):

    >>> r = resolve([[0, 2, 2], [2, 0, 2], [2, 2, 0]], np.eye(3), None, [0.57735, 0.57735, 0.57735, 0, 0, 0])
    >>> r.off_tangent is None, np.round(r.tangent.alpha, 4).tolist(), r.velocity.shape
    (True, [0.5774, 0.5774, 0.5774], (3, 3))
    """
    if wrist is None:
        inputs = {"points": check_points(points), "normals": check_normals(normals), "twist": check_twist(twist)}
        parts, inputs = _run(_resolve_without_wrist, ("velocity", "tangent"), inputs, (tol, bases), bases)
    else:
        inputs = {"points": check_points(points), "normals": check_normals(normals), "wrist": check_wrist(wrist)}
        inputs["twist"] = check_twist(twist)
        parts, inputs = _run(kernels.resolve, ("velocity", "off_tangent", "tangent"), inputs, (tol, bases), bases)
    return Resolution(
        None if wrist is None else _result(OffTangentResult, parts["off_tangent"], inputs),
        _result(TangentResult, parts["tangent"], inputs),
        parts["velocity"]["velocity"],
    )


# --- running the kernels ------------------------------------------------------
# A kernel here maps its inputs (components), the scalar kind and ``args`` to
# ``{part: (values, checks)}``; each part becomes one result.


def _off_tangent(points, wrist, twist, ops, *args):
    return {"off_tangent": kernels.off_tangent(points, wrist, twist, ops, *args)}


def _tangent(points, normals, twist, ops, *args):
    return {"tangent": kernels.tangent(points, normals, twist, ops, *args)}


def _velocities(points, twist, ops):
    return {"velocity": kernels.velocities(points, twist, ops)}


def _resolve_without_wrist(points, normals, twist, ops, *args):
    return kernels.resolve(points, normals, None, twist, ops, *args)


#: Each part's outputs and their trailing shapes.
_OUTPUTS = {
    "off_tangent": {
        "sigma": (3, 6),
        "psi": (3, 6),
        "sigma_psi": (3,),
        "x": (3,),
        "y": (3,),
        "status": (),
        "culprit": (),
        "conditioning": (),
    },
    "tangent": {
        "theta": (3, 6),
        "sigma": (3, 6),
        "theta_sigma": (3,),
        "alpha": (3,),
        "beta": (3,),
        "normal_velocity": (3,),
        "in_tangent_planes": (),
        "status": (),
        "culprit": (),
        "conditioning": (),
    },
    "velocity": {"velocity": (3, 3)},
}
_LEAN_OUTPUTS = {
    part: {k: v for k, v in spec.items() if k not in ("sigma", "psi", "theta")} for part, spec in _OUTPUTS.items()
}
_DTYPES = {"status": np.int8, "culprit": np.int8, "in_tangent_planes": bool}
# How _row_by_row reads each output: (name, dtype, where in (values, status, culprit)).
_PLANS = {
    bases: {
        part: [(k, _DTYPES.get(k, float), 1 if k == "status" else 2 if k == "culprit" else 0) for k in spec]
        for part, spec in outputs.items()
    }
    for bases, outputs in ((True, _OUTPUTS), (False, _LEAN_OUTPUTS))
}


def _result(cls, out, inputs):
    """A result of type ``cls`` from a part's outputs (bases None if left out)."""
    return cls._of({**_NO_BASES[cls], **out, "points": inputs["points"], "twist": inputs["twist"]})


_NO_BASES = {OffTangentResult: {"sigma": None, "psi": None}, TangentResult: {"theta": None, "sigma": None}}


def _run(kernel, names, inputs, args, bases):
    """``kernel`` (whose parts are ``names``) over the broadcast batch of ``inputs``.

    Returns ``{part: {output: array with the batch shape in front}}`` and the
    inputs broadcast to the batch shape.
    """
    shape = ()
    for k, a in inputs.items():
        if a.ndim != len(SHAPES[k]):  # a batch axis: broadcast (else one grasp, nothing to do)
            shape = np.broadcast_shapes(*(a.shape[: a.ndim - len(SHAPES[k])] for k, a in inputs.items()))
            inputs = {k: np.broadcast_to(a, shape + SHAPES[k]) for k, a in inputs.items()}
            break
    n = prod(shape)
    if n <= SMALL_BATCH:
        return _row_by_row(kernel, inputs, args, {name: _PLANS[bool(bases)][name] for name in names}, shape, n), inputs
    return _chunked(
        kernel, inputs, args, {name: (_OUTPUTS if bases else _LEAN_OUTPUTS)[name] for name in names}, shape, n
    ), inputs


def _one(kernel, row, args):
    """``kernel`` on one row of nested lists: ``{part: (values, status, culprit)}``."""
    try:
        parts = kernel(*row, kernels.FLOATS, *args)
        return {k: (v, *kernels.settle_one(v, c, kernels.AMPLITUDES.get(k))) for k, (v, c) in parts.items()}
    except ZeroDivisionError:  # an exactly degenerate grasp: IEEE division on numpy scalars instead
        with np.errstate(all="ignore"):
            parts = kernel(*(np.array(a, dtype=float) for a in row), kernels.ARRAYS, *args)
            return {k: (v, *kernels.settle_one(v, c, kernels.AMPLITUDES.get(k))) for k, (v, c) in parts.items()}


def _row_by_row(kernel, inputs, args, plans, shape, n):
    """The small-batch path: each row in plain floats, no chunks and no layout change."""
    if shape == ():  # one grasp: its values straight into arrays
        settled = _one(kernel, [a.tolist() for a in inputs.values()], args)
        return {
            part: {k: np.array(settled[part][at][k] if at == 0 else settled[part][at], dtype) for k, dtype, at in plan}
            for part, plan in plans.items()
        }
    columns = [a.reshape((n,) + SHAPES[k]).tolist() for k, a in inputs.items()]
    rows = [_one(kernel, row, args) for row in zip(*columns)]
    return {
        part: {
            k: np.array([row[part][at][k] if at == 0 else row[part][at] for row in rows], dtype).reshape(
                shape + _OUTPUTS[part][k]
            )
            for k, dtype, at in plan
        }
        for part, plan in plans.items()
    }


def _chunked(kernel, inputs, args, outputs, shape, n):
    """The batched path: ``kernel`` over cache-sized chunks of rows, components-first.

    Each chunk's inputs are copied components-first (each component one
    contiguous array over the chunk's rows) and the kernel's values are
    written into components-first outputs, which come back as
    ``(batch..., ...)`` views.
    """
    flat = [a.reshape((n,) + SHAPES[k]) for k, a in inputs.items()]
    out = {
        name: {k: np.empty(comp + (n,), dtype=_DTYPES.get(k, float)) for k, comp in spec.items()}
        for name, spec in outputs.items()
    }
    with np.errstate(all="ignore"):
        for start in range(0, n, CHUNK):
            part = slice(start, min(start + CHUNK, n))
            parts = kernel(
                *(_components(np.ascontiguousarray(np.moveaxis(a[part], 0, -1))) for a in flat), kernels.ARRAYS, *args
            )
            for name, (values, checks) in parts.items():
                chunk = {k: o[..., part] for k, o in out[name].items()}
                failed = _settle_rows(values, checks, kernels.AMPLITUDES[name], chunk) if "status" in chunk else None
                for k, o in chunk.items():
                    if k in values:
                        _put(o, values[k])
                        if failed is not None and k in kernels.FAILED:
                            o[..., failed] = kernels.FAILED[k]
    return {
        name: {k: np.moveaxis(o, -1, 0).reshape(shape + outputs[name][k]) for k, o in arrays.items()}
        for name, arrays in out.items()
    }


def _components(a):
    """A components-first array ``(..., rows)`` as nested tuples of ``(rows,)`` arrays."""
    return tuple(_components(c) for c in a) if a.ndim > 1 else a


def _put(out, value):
    """Write a kernel value (nested tuples of row arrays) into ``out (..., rows)``."""
    if type(value) is tuple:
        for o, v in zip(out, value):
            _put(o, v)
    else:
        out[...] = value


def _settle_rows(values, checks, amplitudes, out):
    """:func:`~grasptwist.engine.kernels.settle_one` for a chunk: status and culprit
    per row (the first failed check wins, then overflow of the amplitudes) into
    ``out``; returns the failed rows as a mask."""
    status, culprit = out["status"], out["culprit"]
    status[...] = Status.OK
    culprit[...] = -1
    for code, failed, blame, gate in checks:
        todo = status == Status.OK
        if gate is not None:
            todo &= gate
            rows = np.flatnonzero(todo)
            if not rows.size:
                continue
            hit = rows[failed(None if rows.size == todo.size else rows)]
        else:
            hit = np.flatnonzero(failed & todo)
        if hit.size:
            status[hit] = code
            if blame is not None:
                culprit[hit] = blame(hit)
    finite = status == Status.OK
    for k in amplitudes:
        for c in values[k]:
            finite &= np.isfinite(c)
    status[(status == Status.OK) & ~finite] = Status.OVERFLOW
    return status != Status.OK
