"""Fixtures shared by the loader's tests."""

import os
import sys
import tempfile

# Bytecode. Where PYTHONDONTWRITEBYTECODE is set (no __pycache__ beside the sources), each test
# worker compiled the package and pytest rewrote every test module anew, and so did each
# `grasptwist` process a test starts: some 4 s of every worker's collection and 50 ms of each of
# the default run's subprocesses (docs/reference/development.md, Test time). The run caches them
# outside the tree instead, in the temporary folder (Python checks each against its source).
if os.environ.get("PYTHONDONTWRITEBYTECODE") and not os.environ.get("PYTHONPYCACHEPREFIX"):
    os.environ["PYTHONPYCACHEPREFIX"] = sys.pycache_prefix = os.path.join(
        tempfile.gettempdir(), f"grasptwist-pycache-{os.getuid()}"
    )
    del os.environ["PYTHONDONTWRITEBYTECODE"]  # for the processes the tests start
    sys.dont_write_bytecode = False

# The grip's numpy path in every test and subprocess: numba's kernel (the `fast` extra) costs
# some 16 s of compiling per process on a fresh clone, so the tests that hold it to the numpy
# path (tests/engine/test_forces.py, `compiled`) are `slow` and switch it on themselves.
os.environ.setdefault("GRASPTWIST_NUMBA", "0")

import numpy as np  # noqa: E402
import pytest  # noqa: E402
import yaml  # noqa: E402

from grasptwist.io.grasp import Reading  # noqa: E402

# a script run in processes of its own (see its docstring), not a module for --doctest-modules to import
collect_ignore = ["dask_checks.py"]

#: The YAML parsers the loader can run on here: the pure one, and libyaml's when present.
LOADERS = [yaml.SafeLoader] + ([yaml.CSafeLoader] if yaml.__with_libyaml__ else [])

#: Three valid contacts (the paper's Example 1), to build test documents from.
CONTACTS = """\
contacts:
  - point: [1, 0, 0]
    normal: [-1, 0, 0]
  - point: [-0.5, 0.866, 0]
    normal: [0.5, -0.866, 0]
  - point: [-0.5, -0.866, 0]
    normal: [0.5, 0.866, 0]
"""


@pytest.fixture(params=LOADERS, ids=lambda loader: loader.__name__)
def loader(request):
    """Run the test once with each available YAML parser: the ``reading=`` to pass."""
    return Reading(parser=request.param)


def in_plane(points, normals, which, tilt):
    """``normals`` (``(N, 3, 3)``) with normal ``which[k]`` of grasp ``k`` turned into its contacts' plane,
    plus ``tilt[k]`` (a scalar or ``(N,)``) along that plane's unit normal: a tangent method at or near
    its ``normal-in-contact-plane`` threshold."""
    m = np.cross(points[:, 1] - points[:, 0], points[:, 2] - points[:, 0])
    m /= np.linalg.norm(m, axis=1, keepdims=True)
    rows = np.arange(len(points))
    n = normals[rows, which]
    n = n - np.sum(n * m, axis=1)[:, None] * m
    out = normals.copy()
    out[rows, which] = n / np.linalg.norm(n, axis=1, keepdims=True) + np.reshape(tilt, (-1, 1)) * m
    return out
