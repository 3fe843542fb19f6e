r"""A grasp's margin for error: the friction it needs, how far its contacts are from a crease, how often it survives.

Three numbers per grasp ``(p, n)`` (``(K, 3, 3)`` contacts and unit inward normals), each from the
exact batched grip (:func:`~grasptwist.engine.forces.grip.grip`):

- **hold friction**: the least friction at which a grip still exists for every wrench,

  .. math:: \mu_\text{hold} = \min \{\mu : \forall w\; \exists f_i \in K_i(\mu),\; G f = w\},

  found by bisection on ``[0, mu / safety]`` (a grip at ``mu`` exists at every larger friction:
  the cones grow), :data:`HOLD_STEPS` halvings over every grasp and wrench at once, four a round (the
  fifteen frictions they could test, in one grip); the margin is
  ``mu / hold_friction``.  It is at most the closure friction (closure holds every wrench).
- **edge distance**: each contact's distance to the nearest crease of the surface
  (:func:`~grasptwist.engine.objects.creases.edge_distance`);
- **robustness** (Dex-Net's robust quality, with the exact grip instead of a sampled wrench
  space): the share of ``N`` seeded perturbations under which a grip still exists for every
  wrench.  Perturbation ``j`` moves contact ``i`` in its tangent plane by
  ``e sqrt(u_ij) (cos t_ij b1_i + sin t_ij b2_i)`` (uniform over the disc of radius
  ``e = position_error``), puts it back on the surface and takes the normal there, and lowers
  its friction to ``mu (1 - friction_error v_ij)``, with ``u, v`` uniform on ``[0, 1)`` and
  ``t`` on ``[0, 2 pi)``.  A contact put on a crease (no one normal) fails the perturbation.
  Every grasp meets the same ``N`` draws (common random numbers: the ranking compares grasps,
  not draws), seeded by the search's seed.

.. math:: \text{robustness} = \frac{1}{N} \sum_{j=1}^N [\text{a grip of every wrench exists at perturbation } j]
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..degeneracy import DEGENERACY_TOL
from ..forces.grasp_map import tangent_bases
from ..forces.grip import wrench_grips
from ..objects.tolerances import MESH_EDGE_TOL

__all__ = [
    "FRICTION_ERROR",
    "PERTURBATIONS",
    "POSITION_SHARE",
    "TIP_SHARE",
    "HOLD_STEPS",
    "Margins",
    "check_position_error",
    "check_friction_error",
    "check_perturbations",
    "default_position_error",
    "hold_friction",
    "perturbation_draws",
    "robustness",
    "margins",
]

#: The default share by which each perturbation may lower a contact's friction (``--friction-error``).
FRICTION_ERROR = 0.2

#: The default number of perturbations (``--perturbations``).
PERTURBATIONS = 64

#: The default position error with fingertips: this share of the smallest tip radius.
TIP_SHARE = 0.5

#: The default position error without fingertips: this share of the object's size (the diagonal of
#: its bounding box): 2.3 mm on the bundled 65 mm cube, 1.4 mm on a 70 mm ball.
POSITION_SHARE = 0.02

#: Halvings of the bisection of the hold friction: ``2^-30`` of ``mu / safety``, about 1e-9.
HOLD_STEPS = 30

#: Halvings a round of the bisection takes at once: 15 frictions a grasp in one batched grip, 8 rounds for
#: :data:`HOLD_STEPS` instead of 30 grips (a small batch's grip costs its call, not its rows, on the numpy path).
_AT_ONCE = 4

#: The stream of the perturbations' random numbers beside the search's seed.
_STREAM = 37


class Margins(NamedTuple):
    """The margins of ``K`` grasps (module docstring).

    Attributes
    ----------
    hold_friction : (K,)
    edge_distance : (K, 3)
    robustness : (K,)
    """

    hold_friction: np.ndarray
    edge_distance: np.ndarray
    robustness: np.ndarray


def _number(value) -> bool:
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool)


def check_position_error(value) -> float | None:
    """None (the default: :func:`default_position_error`) or a finite length ``>= 0``.

    >>> check_position_error(0.002)
    0.002
    >>> check_position_error(-1)
    Traceback (most recent call last):
    ValueError: position_error must be a finite number >= 0 or None, got -1
    """
    if value is not None and not (_number(value) and 0 <= value < np.inf):
        raise ValueError(f"position_error must be a finite number >= 0 or None, got {value!r}")
    return None if value is None else float(value)


def check_friction_error(value) -> float:
    """A share of the friction from 0 to less than 1.

    >>> check_friction_error(0.2)
    0.2
    >>> check_friction_error(1)
    Traceback (most recent call last):
    ValueError: friction_error must be a number from 0 to less than 1, got 1
    """
    if not (_number(value) and 0 <= value < 1):
        raise ValueError(f"friction_error must be a number from 0 to less than 1, got {value!r}")
    return float(value)


def check_perturbations(value) -> int:
    """A positive integer.

    >>> check_perturbations(64)
    64
    >>> check_perturbations(0)
    Traceback (most recent call last):
    ValueError: perturbations must be a positive integer, got 0
    """
    if not (isinstance(value, (int, np.integer)) and not isinstance(value, bool) and value > 0):
        raise ValueError(f"perturbations must be a positive integer, got {value!r}")
    return int(value)


def default_position_error(size, radii=None) -> float:
    """Half the smallest fingertip radius (``radii (3,)``, ignored when all are 0), else 2% of ``size``.

    >>> default_position_error(0.1126, np.full(3, 0.0095)), round(default_position_error(0.1126), 6)
    (0.00475, 0.002252)
    """
    if radii is not None and np.max(radii) > 0:
        return TIP_SHARE * float(np.min(radii))
    return POSITION_SHARE * float(size)


def _held(points, normals, wrenches, friction, safety, tol, torsion=None):
    """``(N,)`` whether a grip of every wrench ``(W, 6)`` exists, rows ``(N, 3, 3)``, ``friction (N,)`` or ``(N, 3)``
    (``torsion``: soft contacts' radius, as :func:`~grasptwist.engine.forces.grip.grip`'s).

    Two grips: the first wrench (the weight, where there is one: what fails most) of every row, then the
    others of the rows that hold it, all at once (a grip a wrench cost the numpy path its steps' time
    each; every wrench of every row, the compiled path the rows already lost)."""
    w = np.asarray(wrenches, float).reshape(-1, 6)
    mu = np.asarray(friction, float)
    held = np.ones(len(points), bool)
    for some in (w[:1], w[1:]):
        rows = np.flatnonzero(held)
        ok = wrench_grips(points[rows], normals[rows], some, mu[rows], safety=safety, torsion=torsion, tol=tol)[1]
        held[rows] = ok.all(axis=1)
    return held


def hold_friction(
    points, normals, wrenches, upper, *, steps=HOLD_STEPS, torsion=None, tol=DEGENERACY_TOL
) -> np.ndarray:
    r"""The least friction at which a grip of every wrench exists (module docstring), by bisection.

    The largest of each wrench's least, found one wrench after another: a wrench held at the least
    friction of those before it costs one grip, and only the others are bisected (a grasp's hold test
    loads, :func:`~grasptwist.engine.hold_test.direction_loads`, cost about one bisection, not six).

    ``points, normals (K, 3, 3)``, ``wrenches (W, 6)``, ``upper`` a friction at which to start
    (every grasp is held there, else its answer is NaN; ``inf``: a bracket is found first,
    doubling from 1 at most ``steps`` times) -> ``(K,)``, to ``2^-steps`` of the bracket above
    the least (0 where no friction is needed); ``torsion``: soft contacts' radius (the grips over the soft
    cones, :func:`~grasptwist.engine.forces.grip.grip`'s).

    Three contacts at latitude ``phi`` above a ball's equator lift its weight when
    ``mu cos phi > sin phi``: the hold friction is ``tan phi``.

    >>> phi = np.radians(20)
    >>> a = np.radians([90, 210, 330])
    >>> p = np.stack([np.cos(phi) * np.cos(a), np.cos(phi) * np.sin(a), np.full(3, np.sin(phi))], axis=1)
    >>> h = hold_friction(p[None], -p[None], [[0, 0, 9.81, 0, 0, 0]], 1.0)
    >>> round(float(h[0]), 6), round(float(np.tan(phi)), 6)
    (0.36397, 0.36397)
    """
    p, n = np.asarray(points, float), np.asarray(normals, float)
    least = np.zeros(len(p))  # the least friction holding the wrenches so far: 0 before any
    for wrench in np.asarray(wrenches, float).reshape(-1, 1, 6):
        rows = np.flatnonzero(~np.isnan(least))
        rows = rows[~_held(p[rows], n[rows], wrench, least[rows], 1.0, tol, torsion)]  # it needs more
        least[rows] = _bisected(p[rows], n[rows], wrench, least[rows], float(upper), steps, tol, torsion)
    return least


def _bisected(p, n, wrench, lo, upper, steps, tol, torsion):
    """:func:`hold_friction` of one wrench ``(1, 6)`` on rows not held at ``lo (K,)``: bisection between ``lo``
    and ``upper`` (NaN where ``upper`` does not hold; ``inf``: a bracket found first, doubling from 1)."""
    hi = np.full(len(p), upper)
    if np.isinf(upper):  # no limit (the half-spaces f . n >= 0): a finite bracket first
        hi = np.maximum(1.0, 2 * lo)
        out = np.arange(len(p))
        for _ in range(steps):
            out = out[~_held(p[out], n[out], wrench, hi[out], 1.0, tol, torsion)]
            if not out.size:
                break
            lo[out], hi[out] = hi[out], 2 * hi[out]
    hi[~_held(p, n, wrench, hi, 1.0, tol, torsion)] = np.nan
    live = np.flatnonzero(~np.isnan(hi))
    done = 0
    while done < steps and live.size:
        # a round's halvings at once: the 2^b - 1 frictions between lo and hi that b halvings could test,
        # in one grip of every row (the same bracket as the halvings where being held grows with friction)
        b = min(_AT_ONCE, steps - done)
        width = (hi[live] - lo[live]) / 2**b
        grid = lo[live, None] + width[:, None] * np.arange(1, 2**b)
        ok = _held(
            np.repeat(p[live], 2**b - 1, axis=0),
            np.repeat(n[live], 2**b - 1, axis=0),
            wrench,
            grid.reshape(-1),
            1.0,
            tol,
            torsion,
        ).reshape(grid.shape)
        first = np.where(ok.any(axis=1), ok.argmax(axis=1), 2**b - 1)  # the first held; none: hi stays
        held = first < 2**b - 1
        hi[live[held]] = grid[held, first[held]]
        lo[live] = np.where(first > 0, grid[np.arange(len(live)), np.maximum(first - 1, 0)], lo[live])
        done += b
    return hi


def perturbation_draws(count, friction_error, seed):
    """The draws of ``count`` perturbations: ``offsets (count, 3, 2)`` in the unit disc (uniform over
    it, per contact) and ``factors (count, 3)`` of the friction, uniform on ``(1 - friction_error, 1]``.

    >>> d, f = perturbation_draws(1000, 0.2, 0)
    >>> bool((np.linalg.norm(d, axis=-1) <= 1).all()), bool((f > 0.8).all() and (f <= 1).all())
    (True, True)
    """
    rng = np.random.default_rng((int(seed), _STREAM))
    radius, turn, lower = rng.random((3, count, 3))
    offsets = np.sqrt(radius)[..., None] * np.stack([np.cos(2 * np.pi * turn), np.sin(2 * np.pi * turn)], axis=-1)
    return offsets, 1.0 - friction_error * lower


def robustness(
    surface,
    points,
    normals,
    wrenches,
    friction,
    *,
    safety=1.0,
    position_error=0.0,
    friction_error=FRICTION_ERROR,
    perturbations=PERTURBATIONS,
    seed=0,
    torsion=None,
    tol=DEGENERACY_TOL,
) -> np.ndarray:
    """The share of perturbations under which each grasp is still held (module docstring).

    Parameters
    ----------
    surface : Surface
        :class:`~grasptwist.engine.synthesis.problem.Surface`: its ``project`` puts the moved
        contacts back, its ``edges`` (None: no creases) says which landed on a crease.
    points, normals : (K, 3, 3)
    wrenches : (W, 6)
    friction, safety : float
        The stated ``mu`` (lowered by each perturbation) and the safety factor (the grip keeps
        within ``mu' / safety``).
    position_error, friction_error : float
        ``e`` and the largest share of ``mu`` lost.
    perturbations, seed : int
    torsion : None or float
        Soft contacts' torsional radius (the grips over the soft cones); None: point contacts.

    Returns
    -------
    (K,) array
        In ``[0, 1]``, a multiple of ``1 / perturbations``.

    Examples
    --------
    Three fingers on a unit ball at latitude 20 degrees need ``tan 20 = 0.364``: with
    ``mu = 0.5`` the grasp survives every loss of up to 20% of it (0.4 at worst), with
    ``mu = 0.35`` none.

    >>> phi = np.radians(20)
    >>> a = np.radians([90, 210, 330])
    >>> p = np.stack([np.cos(phi) * np.cos(a), np.cos(phi) * np.sin(a), np.full(3, np.sin(phi))], axis=1)
    >>> def project(q):
    ...     r = np.linalg.norm(q, axis=-1, keepdims=True)
    ...     return q / r, -q / r, r[..., 0] - 1, np.zeros(q.shape[:-1], dtype=bool)
    >>> ball = type("Ball", (), {"project": staticmethod(project), "edges": None, "size": 3.46})
    >>> lift = [[0, 0, 9.81, 0, 0, 0]]
    >>> robustness(ball, p[None], -p[None], lift, 0.5, friction_error=0.2).tolist()
    [1.0]
    >>> robustness(ball, p[None], -p[None], lift, 0.35, friction_error=0.2).tolist()
    [0.0]
    """
    p, n = np.asarray(points, float), np.asarray(normals, float)
    w = np.asarray(wrenches, float).reshape(-1, 6)
    k = len(p)
    if not k:
        return np.empty(0)
    offsets, factors = perturbation_draws(perturbations, friction_error, seed)
    b1, b2 = tangent_bases(n)  # (K, 3, 3) each
    step = position_error * (offsets[None, ..., :1] * b1[:, None] + offsets[None, ..., 1:] * b2[:, None])
    q, m, _, on_edge = surface.project((p[:, None] + step).reshape(-1, 3, 3))  # (K N, 3, 3)
    crease = on_edge.copy()
    if surface.edges is None:
        crease[:] = False
    elif on_edge.any():  # on an edge: a crease, or one between faces that barely turn (a mesh's)
        crease[on_edge] = surface.edges(q[on_edge]) <= MESH_EDGE_TOL * surface.size
    mu = np.tile(friction * factors, (k, 1))  # (K N, 3)
    held = ~crease.any(axis=1)
    rows = np.flatnonzero(held)
    held[rows] = _held(q[rows], m[rows], w, mu[rows], safety, tol, torsion)
    return held.reshape(k, perturbations).mean(axis=1)


def margins(
    surface, points, normals, wrenches, friction, *, safety=1.0, torsion=None, tol=DEGENERACY_TOL, **perturbation
):
    """The :class:`Margins` of ``K`` grasps each held at ``friction / safety``; ``perturbation``:
    :func:`robustness`'s ``position_error``, ``friction_error``, ``perturbations`` and ``seed``; ``torsion``:
    soft contacts' radius."""
    p, n = np.asarray(points, float), np.asarray(normals, float)
    edges = np.full(p.shape[:2], np.inf) if surface.edges is None else surface.edges(p)
    return Margins(
        hold_friction(p, n, wrenches, friction / safety, torsion=torsion, tol=tol),
        edges,
        robustness(surface, p, n, wrenches, friction, safety=safety, torsion=torsion, tol=tol, **perturbation),
    )
