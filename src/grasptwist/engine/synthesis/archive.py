"""The search's archive: the best feasible candidates so far, kept apart, and how close the others came."""

from __future__ import annotations

import numpy as np

from ..degeneracy import DEGENERACY_TOL
from ..forces.closure import force_closure
from .candidates import triple_distance
from .scores import CONSTRAINTS

__all__ = ["Archive", "spread"]


class Archive:
    """The best feasible candidates so far (at most ``size``, each ``spacing`` or more from the better
    ones, so that refinement and selection start from distinct grasps), and the furthest any got."""

    def __init__(self, size, spacing, joints=None, tol=DEGENERACY_TOL):
        self.size, self.spacing, self.tol = size, spacing, tol
        self.points = np.empty((0, 3, 3))
        self.normals = np.empty((0, 3, 3))
        self.objective = np.empty(0)
        self.furthest = 0
        self.closest = np.inf  # the least closure friction of a row that failed closure, over every chunk
        self.best_conditioning = 0.0
        self.positions = None if joints is None else np.empty((0, joints))  # with a hand: (N, n_joints)
        self.best_miss = {}  # a hand's constraint -> the closest a row failing it came

    @property
    def bound(self) -> float:
        """An objective no better than this is never kept: the worst kept once the archive is full."""
        return float(self.objective[-1]) if len(self.objective) >= self.size else np.inf

    def add(self, p, n, s):
        ok = s.failed == -1
        if s.order is not None:  # contact f is finger f's
            p, n = (np.take_along_axis(a, s.order[..., None], axis=1) for a in (p, n))
            self.positions = np.concatenate((self.positions, s.joint_positions[ok]))
            tested = (s.failed > CONSTRAINTS.index("grip")) & (s.failed < len(CONSTRAINTS))
            for k in np.unique(s.failed[tested]):
                best = float(np.nanmin(s.miss[s.failed == k], initial=np.inf))
                self.best_miss[CONSTRAINTS[k]] = min(self.best_miss.get(CONSTRAINTS[k], np.inf), best)
        self.points = np.concatenate((self.points, p[ok]))
        self.normals = np.concatenate((self.normals, n[ok]))
        self.objective = np.concatenate((self.objective, s.objective[ok]))
        order = np.argsort(self.objective, kind="stable")[: 8 * self.size]
        keep = order[spread(self.points[order], self.size, self.spacing)]
        self.points, self.normals, self.objective = self.points[keep], self.normals[keep], self.objective[keep]
        if self.positions is not None:
            self.positions = self.positions[keep]
        reached = np.where(s.failed == -1, len(CONSTRAINTS), s.failed)
        self.furthest = max(self.furthest, int(reached.max(initial=0)))
        worst = np.fmin(s.conditioning[:, 0], s.conditioning[:, 1])  # the asked methods' smaller
        self.best_conditioning = max(self.best_conditioning, float(np.nanmax(worst, initial=0.0)))
        closure = CONSTRAINTS.index("force_closure")
        at = reached == closure
        # only while closure is the furthest constraint is it what a failed search reports
        if at.any() and self.furthest == closure:
            needed = force_closure(p[at], n[at], tol=self.tol).closure_friction
            self.closest = min(self.closest, float(np.nanmin(needed, initial=np.inf)))


def spread(points, count, spacing):
    """Indices of up to ``count`` of the grasps ``points (N, 3, 3)``, in order, each ``spacing`` or more
    from those picked before it (:func:`~.candidates.triple_distance`)."""
    if spacing <= 0:  # every distance is at least 0: the first ``count`` (spared a quadratic loop)
        return np.arange(min(count, len(points)))
    picked = []
    for i in range(len(points)):
        if len(picked) == count:
            break
        if not picked or triple_distance(points[i], points[picked]).min() >= spacing:
            picked.append(i)
    return np.array(picked, int)
