"""How a command ends: where its records go (``-o``) and the exit status of every way out.

Exit codes (their numbers are :mod:`grasptwist.codes`'s ``EXIT``): 0 all records ok, 1 some record not ok (a method degenerate on a
grasp that was read, or an input that could not be read; the others are
still written in full), 2 usage error, 3 the output could not be written, 4 a
worker process died, 128 + the signal's number when SIGINT, SIGTERM or
SIGHUP stopped the run, 141 the reader of stdout went away.
"""

from __future__ import annotations

import os
import signal
import sys
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager

import typer

from ..codes import EXIT_BROKEN_PIPE, EXIT_FAILED, EXIT_OK, EXIT_USAGE, EXIT_WORKER, EXIT_WRITE
from .diagnostics import to_stderr

__all__ = [
    "EXIT_OK",
    "EXIT_FAILED",
    "EXIT_USAGE",
    "EXIT_WRITE",
    "EXIT_WORKER",
    "EXIT_BROKEN_PIPE",
    "CLICK_ERROR",
    "checked_output",
    "output_target",
    "drop_stdout",
    "failed",
    "to_stdout",
    "stopped",
    "run_command",
    "usage_error",
]


# The base of the usage errors of typer's click (typer 0.2x carries its own copy of click, so it is
# found from the one typer exports, whichever click that is).
CLICK_ERROR = next(c for c in typer.BadParameter.__mro__ if c.__name__ == "ClickException")


def checked_output(path: str | None, inputs: Iterable = ()):
    """How ``path`` (None: stdout) is written (a :class:`grasptwist.run.target.Target`);
    a usage error, before any work, when it cannot be the output: among other
    reasons when it is one of ``inputs``, the paths the run reads. A standard input
    closed by the shell (``<&-``) among ``inputs`` is, like a closed stdout, exit 3
    before any work."""
    from ..run.target import check_target

    inputs = list(inputs)
    if sys.stdin is None and any(str(p) == "-" for p in inputs):  # Python found descriptor 0 closed
        raise typer.Exit(failed(Exception("cannot read standard input: it is closed"), EXIT_WRITE))
    try:
        return check_target(path, inputs)
    except ValueError as exc:
        raise typer.BadParameter(str(exc), param_hint=None if path is None else "-o") from None


@contextmanager
def output_target(path: str | None, inputs: Iterable = ()) -> Iterator:
    """stdout, or ``path`` by the rule of :mod:`grasptwist.run.target`: a file
    replaced atomically on success only, a pipe or device written through;
    checked by :func:`checked_output` first."""
    from ..run.signals import finishing
    from ..run.target import opened

    with opened(checked_output(path, inputs)) as out:
        yield out
        finishing()  # all written: commit it and end normally, whatever signal comes now


def drop_stdout() -> None:
    """Send what stdout still buffers to /dev/null: after a failure it must
    neither block the exit on a stalled reader nor fail a second time."""
    try:
        fd = sys.stdout.fileno()
    except (AttributeError, OSError, ValueError):  # not a real file (tests' capture)
        return
    os.dup2(os.open(os.devnull, os.O_WRONLY), fd)


def to_stdout(text: str) -> None:
    """Text that is not records (the help, the version) on stdout, written as records
    are: a closed stdout is a :class:`~grasptwist.run.target.WriteError`."""
    from ..run.target import opened

    with opened(None) as out:
        out.write(text.encode())


def failed(exc: Exception, code: int) -> int:
    """Say in one line why the run could not go on (a write error, a dead worker); ``code``."""
    drop_stdout()
    to_stderr(f"grasptwist: error: {exc}")
    return code


def stopped(stop) -> int:
    """Say which signal stopped the run; the exit status a shell gives for it."""
    drop_stdout()
    to_stderr(f"grasptwist: stopped by {stop.name}")
    return stop.exit_status


def run_command(debug: bool, body: Callable[[], int]) -> None:
    """Run a command's body; turn every way it can end into one line and an exit status."""
    import numpy as np

    from ..extras import MissingExtra
    from ..run.pool import WorkerDied
    from ..run.signals import Interrupted
    from ..run.target import WriteError

    try:
        # numpy's RuntimeWarnings (overflow, invalid) would reach stderr with a file and a line of
        # ours; the engine turns what overflows into a status, so the run needs none of them
        with np.errstate(all="ignore"):
            code = body()
    except (typer.Exit, typer.Abort, typer.BadParameter):
        raise  # typer's own ways out: exit codes, usage errors (2)
    except (Interrupted, KeyboardInterrupt) as exc:  # KeyboardInterrupt: run without main(), as by tests
        raise typer.Exit(stopped(exc if isinstance(exc, Interrupted) else Interrupted(signal.SIGINT))) from None
    except BrokenPipeError:
        # The reader (e.g. `head`) went away: stop quietly with the status of a
        # Unix filter killed by SIGPIPE, and keep Python's final flush quiet too.
        drop_stdout()
        raise typer.Exit(EXIT_BROKEN_PIPE) from None
    except MissingExtra as exc:  # e.g. -f parquet without pyarrow, found before any output
        to_stderr(f"grasptwist: error: {exc}")
        raise typer.Exit(EXIT_USAGE) from None
    except (WriteError, WorkerDied) as exc:
        raise typer.Exit(failed(exc, EXIT_WRITE if isinstance(exc, WriteError) else EXIT_WORKER)) from None
    except Exception as exc:  # noqa: BLE001 - the one place a traceback is turned into a line
        if debug:
            raise
        to_stderr(f"grasptwist: internal error: {type(exc).__name__}: {exc} (rerun with --debug for the traceback)")
        raise typer.Exit(EXIT_FAILED) from None
    raise typer.Exit(code)


def usage_error(exc) -> int:
    """One line for a usage error (exit 2), as for every other diagnostic: what is wrong, and
    where help is, instead of click's four lines of usage, hint, blank and error."""
    if type(exc).__name__ == "NoArgsIsHelpError":  # `grasptwist` alone: the help is the answer,
        to_stdout(exc.format_message() + "\n")  # on stdout (`grasptwist | less`), a success
        return EXIT_OK
    ctx = getattr(exc, "ctx", None)
    message = " ".join(exc.format_message().split())  # on one line, whatever it quotes
    where = f" (see '{ctx.command_path} -h')" if ctx is not None else ""
    to_stderr(f"grasptwist: error: {message}{where}")
    return exc.exit_code
