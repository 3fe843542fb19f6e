"""Whether the grip runs compiled (numba, the ``fast`` extra) and the switch the tests and the bench use.

numba is imported, and :mod:`~grasptwist.engine.forces.kernel` compiled, on the first grip
that needs it, never when ``grasptwist`` is imported.  Compiled functions are cached on
disk (numba's ``cache=True``: in ``__pycache__`` beside the source, or where that is not
writable in numba's per-user cache directory; ``NUMBA_CACHE_DIR`` chooses another), so
only a fresh install pays the compile (about a minute).  ``GRASPTWIST_NUMBA=0`` in the
environment, or :func:`numpy_path`, keeps to the numpy path, which is the reference.
"""

from __future__ import annotations

import importlib.util
import os
import warnings
from contextlib import contextmanager

__all__ = ["kernel", "numpy_path"]


_state = {"on": os.environ.get("GRASPTWIST_NUMBA", "1") != "0", "module": None}


def kernel():
    """The compiled module (:mod:`~grasptwist.engine.forces.kernel`), or None: numba missing or switched off."""
    if not _state["on"]:
        return None
    if _state["module"] is None:
        if importlib.util.find_spec("numba") is None:
            _state["on"] = False
            return None
        try:
            from . import kernel as module
        except (ImportError, RuntimeError, OSError) as error:  # e.g. no directory numba may cache in
            _state["on"] = False
            warnings.warn(f"the compiled grip is unavailable ({error}); the numpy path is used", stacklevel=3)
            return None
        _state["module"] = module
    return _state["module"]


@contextmanager
def numpy_path():
    """Within this block every grip takes the numpy path (the reference the compiled one is held to)."""
    was = _state["on"]
    _state["on"] = False
    try:
        yield
    finally:
        _state["on"] = was
