"""A search's budget, a setting (candidates, seconds and the clock they are read on), and how it is spent.

The clock starts after the one-time work every search needs before its first candidate
(:func:`~.search.warm_up`: numba compiles the grip's kernels on a fresh install, about a minute),
so that work never eats the budget, and a first run returns what every later run returns.  A search says
which limit ended it (:data:`STOPPED_BY`): ``candidates``, every candidate scored and every grasp
selected verified (the same ``seed`` gives the same grasps bit for bit), or ``seconds``, the time
ran out first (the grasps depend on the machine's speed).

>>> b = Budget(candidates=500, seconds=2.0)
>>> b.candidates, b.seconds
(500, 2.0)
>>> Budget(candidates=0)
Traceback (most recent call last):
ValueError: candidates must be an integer from 1 to 1000000000, got 0
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

from .checks import check_candidates, check_seconds

__all__ = ["Budget", "Spending", "STOPPED_BY", "PROBE", "check_budget"]

#: What ended a search: every candidate scored and every grasp verified, or the time.
STOPPED_BY = ("candidates", "seconds")


@dataclass(frozen=True)
class Budget:
    """How much a search may spend: ``candidates`` scored at most, ``seconds`` (None: no limit) on ``clock``.

    Attributes
    ----------
    candidates : int, default 20000
        From 1 to :data:`~.checks.MAX_CANDIDATES`.
    seconds : float or None, default None
        A finite number > 0, or None.
    clock : callable, default ``time.perf_counter``
        ``clock() -> float`` seconds; a test gives a fake one.
    """

    candidates: int = 20000
    seconds: float | None = None
    clock: Callable[[], float] = time.perf_counter

    def __post_init__(self):
        object.__setattr__(self, "candidates", check_candidates(self.candidates))
        object.__setattr__(self, "seconds", check_seconds(self.seconds))


def check_budget(candidates, seconds) -> tuple[int, float | None]:
    """``(candidates, seconds)`` checked (:func:`~.checks.check_candidates`, :func:`~.checks.check_seconds`).

    >>> check_budget(1000, None)
    (1000, None)
    """
    return check_candidates(candidates), check_seconds(seconds)


#: The first take of a search with ``seconds``, before its rate is known (a hand scores a few hundred a second).
PROBE = 32


class Spending:
    """A :class:`Budget` as a search spends it: the clock starts here.

    The search stops taking candidates at ``share`` of ``seconds``; verification stops at
    ``seconds`` (:meth:`late`).  The first take is at most :data:`PROBE` (with ``seconds``, before
    any rate is measured; without, the same, so that the draws do not depend on a limit not
    reached).  With ``seconds``, a later take is sized to end by that deadline at the
    rate measured so far (seconds per candidate scored), so that a slow row (a hand's) overruns it by a fraction of one take, not
    by a whole chunk.  ``stopped_by`` becomes ``seconds`` when either deadline cut something short.

    >>> t = [0.0]
    >>> s = Spending(Budget(10000, 1.0, clock=lambda: t[0]), 0.8)
    >>> s.take(2048)  # no rate yet: a probe
    32
    >>> s.spent(32); t[0] = 0.16  # 5 ms a candidate
    >>> s.take(2048)  # 0.64 s left to 0.8 s: 128 more
    128
    """

    def __init__(self, budget: Budget, share: float):
        self.clock = budget.clock
        self.started = self.clock()
        self.left, self.used = budget.candidates, 0
        s = budget.seconds
        self.search_deadline = None if s is None else self.started + share * s
        self.deadline = None if s is None else self.started + s
        self.stopped_by = "candidates"

    def take(self, n) -> int:
        """Up to ``n`` candidates, 0 when the budget is spent (the time only when some are left).

        The first take is a probe with or without ``seconds``, and a later one is cut short only by a
        deadline it would pass (then ``stopped_by`` is ``seconds``): a search the candidates ended
        draws the same takes, so the same grasps, whether or not a time limit was set
        (``grasptwist synthesize``'s 60 s and ``grasptwist.synthesize``'s none).

        >>> s = Spending(Budget(10000), 0.8)  # no time limit: the same takes
        >>> s.take(2048), s.spent(32), s.take(2048)
        (32, None, 2048)
        """
        n = max(0, min(n, self.left))
        if not n:
            return n
        if not self.used:  # a first take, a probe (no rate yet where there is a deadline)
            n = min(n, PROBE)
        if self.search_deadline is None:
            return n
        now = self.clock()
        if now >= self.search_deadline:
            self.stopped_by = "seconds"
            return 0
        if not self.used:
            return n
        fits = int((self.search_deadline - now) * self.used / max(now - self.started, 1e-12))
        if fits < n:  # the time, not the candidates, sizes this take
            self.stopped_by = "seconds"
        return max(1, min(n, fits))

    def spent(self, n):
        self.left -= n
        self.used += n

    def late(self) -> bool:
        """Whether verification's deadline has passed (then ``stopped_by`` is ``seconds``)."""
        if self.deadline is not None and self.clock() >= self.deadline:
            self.stopped_by = "seconds"
            return True
        return False

    def seconds(self) -> float:
        """Seconds since the clock started."""
        return self.clock() - self.started
