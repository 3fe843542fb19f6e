"""The search's archive: the best feasible candidates so far, kept apart, and how close the others came."""

from __future__ import annotations

import heapq
import math

import numpy as np

from ..degeneracy import DEGENERACY_TOL
from ..forces.closure import force_closure
from .candidates import triple_distance
from .scores import CONSTRAINTS

__all__ = ["Archive"]


class Archive:
    """The best feasible candidates so far and how close the others came.

    At most ``size`` grasps are kept, each ``spacing`` or more (:func:`~.candidates.triple_distance`)
    from every other, so that refinement and selection start from distinct grasps: a newcomer
    with a better (or as good and earlier) grasp within ``spacing`` is turned away, one better
    than every grasp within ``spacing`` of it takes their place, and once ``size`` are kept the
    worst leaves.  The kept grasps in order (:attr:`points`, ...) are therefore ``spacing`` apart
    already: the best ``count`` of them are the selection.

    Keeping costs O(log size) a candidate, whatever ``size`` (``4 count``: 40000 at ``-n 10000``):
    a heap finds the worst kept, and a grid of cubes ``spacing`` wide the grasps near a newcomer
    (each kept grasp is filed under its contacts' cubes; a grasp within ``spacing`` has a contact
    within ``spacing`` of the newcomer's first, so in one of the 27 cubes around it).  The
    candidates that beat the worst kept are offered best first, and the rest of a chunk is
    turned away at once.

    >>> from grasptwist.engine.synthesis.scores import Scores
    >>> a = Archive(size=2, spacing=0.5)
    >>> p = np.array([np.eye(3), np.eye(3) + 0.1, np.eye(3) + 1.0])  # the second within 0.5 of the first
    >>> a.add(p, -p, Scores(np.array([2.0, 1.0, 3.0]), np.zeros((3, 1)), np.ones((3, 2)), np.full(3, -1, np.int8)))
    >>> a.objective.tolist()  # the second replaced the first
    [1.0, 3.0]
    """

    def __init__(self, size, spacing, joints=None, tol=DEGENERACY_TOL, torsion=None):
        self.size, self.spacing, self.tol, self.torsion = size, spacing, tol, torsion
        slots = size + 1  # a newcomer's slot before the worst leaves
        self._points, self._normals = np.empty((slots, 3, 3)), np.empty((slots, 3, 3))
        self._objective = np.full(slots, np.inf)
        self._arrival = np.zeros(slots, np.int64)  # ties go to the earlier
        self._positions = None if joints is None else np.empty((slots, joints))  # with a hand
        self._kept = np.zeros(slots, bool)
        self._free = list(range(slots))
        self._worst = []  # a heap of (-objective, -arrival, slot), stale entries skipped
        self._cubes = {}  # a cube of the grid -> the slots with a contact in it
        self._arrivals = 0
        self.count = 0
        self.furthest = 0
        self.closest = np.inf  # the least closure friction of a row that failed closure, over every chunk
        self.best_conditioning = 0.0
        self.best_miss = {}  # a hand's constraint -> the closest a row failing it came

    @property
    def bound(self) -> float:
        """An objective no better than this is never kept: the worst kept once the archive is full."""
        return float(self._objective[self._worst_slot()]) if self.count >= self.size else np.inf

    def _order(self):
        kept = np.flatnonzero(self._kept)
        return kept[np.lexsort((self._arrival[kept], self._objective[kept]))]

    @property
    def points(self) -> np.ndarray:
        """The kept grasps' contacts, best first ``(K, 3, 3)``."""
        return self._points[self._order()]

    @property
    def normals(self) -> np.ndarray:
        return self._normals[self._order()]

    @property
    def objective(self) -> np.ndarray:
        return self._objective[self._order()]

    @property
    def positions(self) -> np.ndarray | None:
        """With a hand: where it reaches each kept grasp ``(K, n_joints)``."""
        return None if self._positions is None else self._positions[self._order()]

    def add(self, p, n, s):
        """Offer the candidates ``p, n (N, 3, 3)`` scored ``s`` (:class:`~.scores.Scores`)."""
        ok = s.failed == -1
        positions = None
        if s.order is not None:  # contact f is finger f's
            p, n = (np.take_along_axis(a, s.order[..., None], axis=1) for a in (p, n))
            positions = s.joint_positions[ok]
            tested = (s.failed > CONSTRAINTS.index("grip")) & (s.failed < len(CONSTRAINTS))
            for k in np.unique(s.failed[tested]):
                best = float(np.nanmin(s.miss[s.failed == k], initial=np.inf))
                self.best_miss[CONSTRAINTS[k]] = min(self.best_miss.get(CONSTRAINTS[k], np.inf), best)
        fp, fn, value = p[ok], n[ok], s.objective[ok]
        for i in np.argsort(value, kind="stable"):
            if value[i] >= self.bound:  # the bound only falls: the rest are no better
                break
            self._offer(fp[i], fn[i], value[i], None if positions is None else positions[i])
        reached = np.where(s.failed == -1, len(CONSTRAINTS), s.failed)
        self.furthest = max(self.furthest, int(reached.max(initial=0)))
        worst = np.fmin(s.conditioning[:, 0], s.conditioning[:, 1])  # the asked methods' smaller
        self.best_conditioning = max(self.best_conditioning, float(np.nanmax(worst, initial=0.0)))
        closure = CONSTRAINTS.index("force_closure")
        at = reached == closure
        # only while closure is the furthest constraint is it what a failed search reports
        if at.any() and self.furthest == closure:
            needed = force_closure(p[at], n[at], torsion=self.torsion, tol=self.tol).closure_friction
            self.closest = min(self.closest, float(np.nanmin(needed, initial=np.inf)))

    def _offer(self, p, n, value, positions):
        near = self._near(p)
        if len(near) and self._objective[near].min() <= value:  # a better one (or as good, earlier) is near
            return
        for slot in near:
            self._remove(slot)
        slot = self._free.pop()
        self._points[slot], self._normals[slot], self._objective[slot] = p, n, value
        if positions is not None:
            self._positions[slot] = positions
        self._arrival[slot], self._arrivals = self._arrivals, self._arrivals + 1
        self._kept[slot] = True
        self.count += 1
        heapq.heappush(self._worst, (-value, -self._arrival[slot], slot))
        for cube in self._cubes_of(p):
            self._cubes.setdefault(cube, set()).add(slot)
        if self.count > self.size:
            self._remove(self._worst_slot())

    def _worst_slot(self) -> int:
        """The worst kept grasp's slot (its heap entry is the first not stale)."""
        while True:
            value, arrival, slot = self._worst[0]
            if self._kept[slot] and self._arrival[slot] == -arrival:
                return slot
            heapq.heappop(self._worst)

    def _remove(self, slot):
        self._kept[slot] = False
        self.count -= 1
        self._free.append(slot)
        for cube in self._cubes_of(self._points[slot]):
            self._cubes.get(cube, set()).discard(slot)

    def _cube(self, point):
        """The grid cube of ``point (3,)``: a tuple of integers, None beyond them (a coordinate 1e300
        times the spacing)."""
        try:
            return tuple(math.floor(c / self.spacing) for c in point.tolist())
        except OverflowError:
            return None

    def _cubes_of(self, p):
        """The grid cubes of the contacts ``p (3, 3)`` (none without spacing)."""
        return {self._cube(c) for c in p} if self.spacing > 0 else set()

    def _near(self, p) -> np.ndarray:
        """The kept grasps' slots within ``spacing`` of the grasp ``p (3, 3)``."""
        if self.spacing <= 0:  # every distance is at least 0: none is near
            return _NONE
        first = self._cube(p[0])
        if first is None:  # beyond the grid: every kept grasp is looked at
            found = set(np.flatnonzero(self._kept).tolist())
        else:
            x, y, z = first
            found = set(self._cubes.get(None, ()))
            for i, j, k in _AROUND:
                found.update(self._cubes.get((x + i, y + j, z + k), ()))
        if not found:
            return _NONE
        slots = np.fromiter(found, int, len(found))
        return slots[triple_distance(p, self._points[slots]) < self.spacing]


#: The 27 cubes around one (itself included), as offsets.
_AROUND = tuple((i, j, k) for i in (-1, 0, 1) for j in (-1, 0, 1) for k in (-1, 0, 1))
_NONE = np.empty(0, int)
