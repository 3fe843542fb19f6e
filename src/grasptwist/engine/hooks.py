"""What the engine runs around long one-time work, set by its callers: the engine itself says nothing.

Such work is a first load of compiled code in a process: the grip's kernel, and apart from it the
interior-point iterations on rows of any sizes (numba compiles them on a fresh install, about a minute
and some 20 s, and loads them from its cache after: :mod:`~grasptwist.engine.forces.compiled`).
The command line sets :func:`watching_first_load` so that a load that takes long says so on stderr;
a library caller may set its own.
"""

from __future__ import annotations

import contextlib
import threading
from collections.abc import Callable, Iterator
from contextlib import AbstractContextManager

__all__ = ["first_load", "watching_first_load"]

_first_load: list[Callable[[], AbstractContextManager]] = [contextlib.nullcontext]
_within = threading.local()  # a thread's first loads open: one inside another runs in the outer's context alone


@contextlib.contextmanager
def first_load() -> Iterator[None]:
    """The context the compiled kernel's first load runs in (nothing, unless a caller set one).

    A first load inside another (the grip's kernel and the soft contacts' iterations inside a
    search's warm-up) runs in the outer one's context alone: one watch, one notice.

    >>> with first_load():
    ...     with first_load():
    ...         pass
    """
    if getattr(_within, "open", 0):
        yield
        return
    _within.open = 1
    try:
        with _first_load[0]():
            yield
    finally:
        _within.open = 0


@contextlib.contextmanager
def watching_first_load(factory: Callable[[], AbstractContextManager]) -> Iterator[None]:
    """Within this block the compiled kernel's first load runs inside ``factory()``.

    >>> said = []
    >>> @contextlib.contextmanager
    ... def loud():
    ...     said.append("loading")
    ...     yield
    >>> with watching_first_load(loud):
    ...     with first_load():
    ...         pass
    >>> said
    ['loading']
    """
    was = _first_load[0]
    _first_load[0] = factory
    try:
        yield
    finally:
        _first_load[0] = was
