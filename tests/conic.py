"""An independent conic solver (Clarabel) for the force side: the least grip and the least
common friction of force closure, one grasp at a time, on the 9 contact-force numbers
(no squeezes, no planar reduction): what the batched engine is tested and timed against."""

import clarabel
import numpy as np
from scipy import sparse

from grasptwist.engine.forces.grasp_map import grasp_map, tangent_bases

SETTINGS = {"verbose": False, "tol_gap_abs": 1e-11, "tol_gap_rel": 1e-11, "tol_feas": 1e-11}


def _settings():
    s = clarabel.DefaultSettings()
    for k, v in SETTINGS.items():
        setattr(s, k, v)
    return s


def _unit(normals):
    n = np.asarray(normals, float)
    return n / np.linalg.norm(n, axis=-1, keepdims=True)


def least_grip(points, normals, wrench, friction, safety=1.0):
    """``(total normal force, forces (3, 3))`` of the least grip, or ``(None, None)`` when infeasible."""
    n = _unit(normals)
    mu = np.broadcast_to(np.asarray(friction, float), (3,)) / safety
    b1, b2 = tangent_bases(n)
    rows = []
    for i in range(3):
        block = np.zeros((3, 9))
        block[:, 3 * i : 3 * i + 3] = -np.stack((mu[i] * n[i], b1[i], b2[i]))
        rows.append(block)
    A = sparse.csc_matrix(np.vstack([grasp_map(points)] + rows))
    b = np.concatenate((np.asarray(wrench, float), np.zeros(9)))
    cones = [clarabel.ZeroConeT(6)] + [clarabel.SecondOrderConeT(3)] * 3
    solver = clarabel.DefaultSolver(sparse.csc_matrix((9, 9)), n.reshape(9), A, b, cones, _settings())
    sol = solver.solve()
    if str(sol.status) not in ("Solved", "AlmostSolved"):
        return None, None
    return float(sol.obj_val), np.array(sol.x).reshape(3, 3)


def closure_margin(points, normals, mu, torsion=None):
    """The largest ``min_i (mu_i n_i.f_i - |f_t,i|)`` over internal forces with ``sum_i n_i . f_i = 1``.

    ``torsion (3,)``: soft contacts (``e_i > 0``) add ``tau_i`` (the moment ``tau_i n_i``) and the margin is
    ``mu n_i . f_i - |(f_t,i, tau_i / e_i)|``.
    """
    n = _unit(normals)
    mu = np.broadcast_to(np.asarray(mu, float), (3,))
    e = np.zeros(3) if torsion is None else np.broadcast_to(np.asarray(torsion, float), (3,))
    b1, b2 = tangent_bases(n)
    # variables (f (9), tau (3), t): maximise t s.t. G f + (0; tau n) = 0, sum n.f = 1, tau_i = 0 at point
    # contacts, (mu n.f - t, f_t, tau / e) in SOC
    eq = np.zeros((7, 13))
    eq[:6, :9] = grasp_map(points)
    eq[3:6, 9:12] = n.T
    eq[6, :9] = n.reshape(9)
    fixed = [np.eye(13)[9 + i] for i in range(3) if not e[i] > 0]
    rows = []
    for i in range(3):
        block = np.zeros((4 if e[i] > 0 else 3, 13))
        block[:3, 3 * i : 3 * i + 3] = -np.stack((mu[i] * n[i], b1[i], b2[i]))
        block[0, 12] = 1.0
        if e[i] > 0:
            block[3, 9 + i] = -1 / e[i]
        rows.append(block)
    A = sparse.csc_matrix(np.vstack([eq] + fixed + rows))
    b = np.concatenate((np.zeros(6), [1.0], np.zeros(len(fixed)), np.zeros(sum(len(r) for r in rows))))
    q = np.zeros(13)
    q[12] = -1.0
    cones = [clarabel.ZeroConeT(7 + len(fixed))] + [clarabel.SecondOrderConeT(len(r)) for r in rows]
    sol = clarabel.DefaultSolver(sparse.csc_matrix((13, 13)), q, A, b, cones, _settings()).solve()
    if str(sol.status) not in ("Solved", "AlmostSolved"):
        return -np.inf
    return -float(sol.obj_val)


#: A margin (of unit total normal force) above this is strict: Clarabel returns ~1e-12 for a margin
#: that is 0, e.g. when one cone meets the contacts' plane only at its apex and that finger carries nothing.
STRICT = 1e-10


def closure_friction(points, normals, hi=1e3, iterations=45, torsion=None):
    """The least common ``mu`` with a positive closure margin, by bisection on ``mu``; NaN when none below ``hi``
    (``torsion``: soft contacts, as :func:`closure_margin`'s; the grasp map of the forces and torsions must
    have rank 6, by numpy's ``matrix_rank``)."""
    if torsion is not None and np.linalg.matrix_rank(soft_grasp_map(points, normals, torsion)) < 6:
        return np.nan
    if closure_margin(points, normals, hi, torsion) <= STRICT:
        return np.nan
    lo = 0.0
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if closure_margin(points, normals, mid, torsion) > STRICT else (mid, hi)
    return hi


def soft_grasp_map(points, normals, torsion):
    """``(6, 9 + s)``: the grasp map of the forces and the ``s`` soft contacts' torsions (``e_i > 0``)."""
    n = _unit(normals)
    e = np.broadcast_to(np.asarray(torsion, float), (3,))
    torsions = np.zeros((6, 3))
    torsions[3:] = n.T
    return np.hstack((grasp_map(points), torsions[:, e > 0]))


def least_soft_grip(points, normals, wrench, friction, torsion, safety=1.0):
    """:func:`least_grip` with soft-finger contacts: ``(total, forces (3, 3), torsions (3,))``, ``(None,) * 3``
    when infeasible, ``(nan, None, None)`` when Clarabel cannot decide (a numerical error).

    Variables ``(f_1, f_2, f_3, tau_1, tau_2, tau_3)``: ``sum_i (f_i; p_i x f_i + tau_i n_i) = w`` and
    ``(mu_i n_i . f_i, b1 . f_i, b2 . f_i, tau_i / e_i)`` in ``SOC(4)`` (``e_i = 0``: ``SOC(3)`` and ``tau_i = 0``).
    """
    n = _unit(normals)
    mu = np.broadcast_to(np.asarray(friction, float), (3,)) / safety
    e = np.broadcast_to(np.asarray(torsion, float), (3,))
    b1, b2 = tangent_bases(n)
    eq = np.zeros((6, 12))
    eq[:, :9] = grasp_map(points)
    for i in range(3):
        eq[3:, 9 + i] = n[i]
    rows, cones, fixed = [], [], []
    for i in range(3):
        soft = e[i] > 0
        block = np.zeros((4 if soft else 3, 12))
        block[:3, 3 * i : 3 * i + 3] = -np.stack((mu[i] * n[i], b1[i], b2[i]))
        if soft:
            block[3, 9 + i] = -1 / e[i]
        else:
            zero = np.zeros(12)
            zero[9 + i] = 1.0
            fixed.append(zero)
        rows.append(block)
        cones.append(clarabel.SecondOrderConeT(len(block)))
    zeros = np.vstack([eq] + fixed)
    A = sparse.csc_matrix(np.vstack([zeros] + rows))
    b = np.concatenate((np.asarray(wrench, float), np.zeros(len(fixed)), np.zeros(sum(len(r) for r in rows))))
    q = np.concatenate((n.reshape(9), np.zeros(3)))
    solver = clarabel.DefaultSolver(
        sparse.csc_matrix((12, 12)), q, A, b, [clarabel.ZeroConeT(len(zeros))] + cones, _settings()
    )
    sol = solver.solve()
    if str(sol.status) in ("NumericalError", "InsufficientProgress"):
        return np.nan, None, None  # undecided (1 of 1000 random grasps: a cone's edge at 258 N)
    if str(sol.status) not in ("Solved", "AlmostSolved"):
        return None, None, None
    x = np.array(sol.x)
    return float(sol.obj_val), x[:9].reshape(3, 3), x[9:]
