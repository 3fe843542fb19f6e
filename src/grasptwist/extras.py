"""Optional dependencies (the extras ``parquet``, ``dask``, ``mesh``, ...): imported only when used.

A missing one is a :class:`MissingExtra` whose message is the one line to
show: what needs it and how to install it.
"""

from __future__ import annotations

from importlib import import_module
from types import ModuleType

__all__ = ["EXTRAS", "MissingExtra", "require"]

#: Top-level module -> (what pip installs, the grasptwist extra that brings it).
EXTRAS = {
    "pyarrow": ("pyarrow", "parquet"),
    "pandas": ("'dask[dataframe]' distributed", "dask"),
    "dask": ("'dask[dataframe]' distributed", "dask"),
    "distributed": ("'dask[dataframe]' distributed", "dask"),
    "scipy": ("scipy", "quality"),
    "igl": ("libigl", "mesh"),
    "trimesh": ("trimesh", "mesh"),
    "mujoco": ("'grasptwist[sim]'", "sim"),
    "coacd": ("'grasptwist[sim]'", "sim"),
}


class MissingExtra(ImportError):
    """An optional dependency is not installed.

    >>> str(MissingExtra("-f parquet", "pyarrow"))
    "-f parquet needs pyarrow: pip install pyarrow (from a clone of grasptwist: pip install -e '.[parquet]')"
    """

    def __init__(self, what: str, module: str):
        package, extra = EXTRAS[module]
        super().__init__(
            f"{what} needs {module}: pip install {package} (from a clone of grasptwist: pip install -e '.[{extra}]')"
        )


def require(module: str, what: str) -> ModuleType:
    """``import module`` (a dotted name whose top is in :data:`EXTRAS`), or :class:`MissingExtra` for ``what``."""
    try:
        return import_module(module)
    except ImportError:
        raise MissingExtra(what, module.partition(".")[0]) from None
