"""What the engine runs around long one-time work, set by its callers: the engine itself says nothing.

The one such work is the compiled grip's first load in a process (numba compiles it on a fresh
install, about a minute, and loads it from its cache after: :mod:`~grasptwist.engine.forces.compiled`).
The command line sets :func:`watching_first_load` so that a load that takes long says so on stderr;
a library caller may set its own.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterator
from contextlib import AbstractContextManager

__all__ = ["first_load", "watching_first_load"]

_first_load: list[Callable[[], AbstractContextManager]] = [contextlib.nullcontext]


def first_load() -> AbstractContextManager:
    """The context the compiled kernel's first load runs in (nothing, unless a caller set one).

    >>> with first_load():
    ...     pass
    """
    return _first_load[0]()


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
