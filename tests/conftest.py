"""Fixtures shared by the tests: both YAML parsers; the bytecode cache and the numpy grip of the run;
the collected objects frozen out of the cyclic collector's sight; the command line built once."""

import functools
import gc
import os
import sys

# Bytecode. Where PYTHONDONTWRITEBYTECODE is set (no __pycache__ written), each test worker
# compiled the package and pytest rewrote every test module anew, and so did each `grasptwist`
# process a test starts: some 4 s of every worker's collection and 50 ms of each of the default
# run's subprocesses (docs/reference/development.md, Test time). The run writes bytecode as
# Python does by default, in `__pycache__` beside the sources (git ignores it); a cache prefix
# elsewhere would also hide the bytecode pip compiled for the libraries and have them all
# compiled again, 13 s of CPU on a fresh clone.
if os.environ.get("PYTHONDONTWRITEBYTECODE"):
    del os.environ["PYTHONDONTWRITEBYTECODE"]  # for the processes the tests start
    sys.dont_write_bytecode = False

# The grip's numpy path in every test and subprocess: numba's kernel (the `fast` extra) costs
# some 16 s of compiling per process on a fresh clone, so the tests that hold it to the numpy
# path (tests/engine/test_forces.py, `compiled`) are `slow` and switch it on themselves.
os.environ.setdefault("GRASPTWIST_NUMBA", "0")

# One OpenBLAS thread in every test and subprocess, set before numpy loads: the grip's matrices are
# 6 by 6 or so, and OpenBLAS starting (and spinning) a thread per core cost each `grasptwist`
# process the tests start 0.1 s of CPU more than its whole import (docs/reference/development.md, Test time).
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import pytest  # noqa: E402

from loaders import LOADERS  # noqa: E402

# a script run in processes of its own (see its docstring), not a module for --doctest-modules to import
collect_ignore = ["dask_checks.py"]


def pytest_collection_finish(session):
    """In each process that runs tests, once they are collected (docs/reference/development.md, Test time):
    what collection made (the modules, the test functions, their parameters: all live to the run's end)
    frozen out of the cyclic collector's sight, as the ``grasptwist`` script freezes its start-up's
    (``grasptwist.cli.main``): each oldest-generation collection during the tests went through them all
    again, some 0.1 s a pass in a worker; and the command line built once."""
    gc.freeze()
    _build_the_command_line_once()


def _build_the_command_line_once():
    """typer's ``CliRunner.invoke(app, ...)`` builds the click group of ``app`` (its every command's options)
    at each call, 10 ms for the nine commands: some 8 s of the default run's CPU over its ~800 in-process
    command lines.  Built once per app here (typer builds it from the app's declarations alone: the
    commands, their functions and options are fixed when the app is made), and run as before, a context
    a call (``tests/cli/test_cli.py`` holds that it is built once)."""
    import typer.main
    import typer.testing

    typer.testing._get_command = functools.cache(typer.main.get_command)


@pytest.fixture(params=LOADERS, ids=lambda loader: loader.__name__)
def loader(request):
    """Run the test once with each available YAML parser: the ``reading=`` to pass."""
    # imported here: xdist's controlling process loads this file too, and runs no test
    from grasptwist.io.grasp import Reading

    return Reading(parser=request.param)
