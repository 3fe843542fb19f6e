"""Whether the grip runs compiled (numba, the ``fast`` extra) and the switch the tests and the bench use.

numba is imported, and :mod:`~grasptwist.engine.forces.kernel` compiled, on the first grip
that needs it, never when ``grasptwist`` is imported.  Compiled functions are cached on
disk (numba's ``cache=True``: in ``__pycache__`` beside the source, or where that is not
writable in numba's per-user cache directory; ``NUMBA_CACHE_DIR`` chooses another), so
only a fresh install pays the compile (about a minute), inside
:func:`~grasptwist.engine.hooks.first_load` (the command line's notice).  The interior-point
iterations of :mod:`~grasptwist.engine.forces.socp` (soft contacts' cones, and the rows the
kernel leaves to numpy) are compiled apart, for any sizes, at their first use
(:func:`iteration`: some 20 s more on a fresh install, inside the same notice).  ``GRASPTWIST_NUMBA=0``
in the environment, or :func:`numpy_path`, keeps to the numpy path, which is the reference.
"""

from __future__ import annotations

import importlib.util
import os
import threading
import warnings
from contextlib import contextmanager

import numpy as np

from ..hooks import first_load

__all__ = ["kernel", "iteration", "numpy_path", "read_only"]


_state = {"on": os.environ.get("GRASPTWIST_NUMBA", "1") != "0", "module": None}

# one load at a time: threads that need a part while another loads it wait for it, and none loads it again
_LOADING = threading.RLock()


def kernel():
    """The compiled module (:mod:`~grasptwist.engine.forces.kernel`), or None: numba missing or switched off."""
    if _state["on"] and not _state.get("grip") and _numba():
        with _LOADING, first_load():  # the caller's watch (the command line's notice of a long compile)
            if _state["on"] and not _state.get("grip"):  # not loaded by another thread meanwhile
                _loaded(_first_grip, "grip", "the compiled grip")
    return _state["module"] if _state["on"] else None


def _numba():
    """Whether numba is installed (if not, the numpy path for good)."""
    if importlib.util.find_spec("numba") is None:
        _state["on"] = False
    return _state["on"]


def _loaded(first, part, name):
    """``first(kernel)`` (the kernel's module imported where it is not yet): ``part`` compiled on a fresh
    install, else loaded from numba's cache.  Where that fails, the numpy path, warned: for ``part`` alone,
    or for everything where the grip fails or the module cannot be imported."""
    try:
        if _state["module"] is None:
            from . import kernel as module

            _state["module"] = module
        first(_state["module"])
        _state[part] = True
    except (ImportError, RuntimeError, OSError) as error:  # e.g. no directory numba may cache in
        _state[part] = False
        if part == "grip" or _state["module"] is None:
            _state["on"], _state["module"] = False, None
        warnings.warn(f"{name} is unavailable ({error}); the numpy path is used", stacklevel=4)


def _first_grip(module):
    """One grip of a tripod, in the kernel's one signature (:func:`read_only`): compiled on a fresh install, or
    loaded from numba's cache, here, inside the watched first load, not in the middle of the caller's first grip."""
    p = np.array([[[1.0, 0, 0], [-0.5, 0.866, 0], [-0.5, -0.866, 0]]])
    grasp = [read_only(a) for a in (p, -p, np.full((1, 3), 0.5))]
    wrench, out, codes = np.array([[0, 0, 1.0, 0, 0, 0]]), np.empty((1, module.WIDTH)), np.empty((1, 3), np.int8)
    module.grip_rows(*grasp, wrench, 1e-9, out, codes)


def iteration():
    """The compiled module, where its iteration on rows of any sizes is loaded (:func:`kernel.iterate_rows`,
    :func:`kernel.polish_rows`: :mod:`~grasptwist.engine.forces.socp`'s), or None.

    Compiled (some 20 s on a fresh install) or loaded from numba's cache at the first use in a process,
    apart from the grip's kernel (:func:`kernel`): a process whose grips the kernel solves whole
    (point contacts with friction, not collinear) never pays it, unless a search's warm-up loads
    both (:func:`~grasptwist.engine.synthesis.search.warm_up`: no compile inside its clock), and one
    that grips soft contacts only never pays the kernel's.  Inside :func:`~grasptwist.engine.hooks.first_load` too (the
    command line's notice).
    """
    if _state["on"] and _state.get("iteration") is None and _numba():
        with _LOADING, first_load():
            if _state["on"] and _state.get("iteration") is None:  # not loaded by another thread meanwhile
                _loaded(_first_iteration, "iteration", "the compiled iteration")
    return _state["module"] if _state["on"] and _state.get("iteration") else None


def _first_iteration(module):
    """One phase I and one dual polish of a row with two cones ``t >= |z|``, ``z`` one unknown: in the
    signatures :mod:`~grasptwist.engine.forces.socp` calls (C-contiguous writable floats)."""
    A = np.array([[[[0.0], [1.0]], [[1.0], [0.0]]]])
    b, c = np.array([[[1.0, 0.0], [1.0, 0.0]]]), np.ones((1, 1))
    x, z = np.zeros((1, 1)), np.full((1, 2, 2), 0.25)
    module.iterate_rows(A, b, c, x, z, True)
    module.polish_rows(A, b, c, x, z)


def read_only(a):
    """``a`` as :func:`kernel.grip_rows` takes its grasp: C-contiguous floats, read-only (a view).

    numba compiles, and loads from its cache, one function per signature, and an array's
    writeable flag is part of it: the grasp read-only and the wrenches writable (the grip copies
    them, a prepared grip has a copy) keep every call to one signature, one load
    (50 ms of a process's start) and never a compile for a caller's flags.

    >>> a = read_only([[0, 0, 1]])
    >>> a.dtype, a.flags.c_contiguous, a.flags.writeable
    (dtype('float64'), True, False)
    """
    a = np.ascontiguousarray(a, dtype=float).view()
    a.flags.writeable = False
    return a


@contextmanager
def numpy_path():
    """Within this block every grip takes the numpy path (the reference the compiled one is held to)."""
    was = _state["on"]
    _state["on"] = False
    try:
        yield
    finally:
        _state["on"] = was
