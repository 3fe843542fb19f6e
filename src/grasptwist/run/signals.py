"""The signals that end a run, turned into an exception that unwinds it.

SIGINT (Ctrl-C), SIGTERM (``kill``, ``timeout``) and SIGHUP (the terminal
went away) raise :class:`Interrupted` in the main thread, so that every
``with`` block on the way out removes what it made (the temporary output,
the spool, the worker processes); the command then exits with 128 + the
signal's number, as shells report a process the signal killed.  Only the
first signal raises: a second Ctrl-C must not cut the clean-up short.
"""

from __future__ import annotations

import signal
from contextlib import contextmanager

from ..codes import EXIT_SIGNAL

__all__ = ["STOP_SIGNALS", "Interrupted", "stop_on_signals", "finishing", "signals_blocked"]

#: The signals that end a run; the parent handles them, workers ignore them.
STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


class Interrupted(BaseException):
    """A stop signal arrived (a BaseException, like KeyboardInterrupt: no
    ``except Exception`` may swallow it).

    >>> Interrupted(signal.SIGTERM).exit_status
    143
    """

    def __init__(self, signum: int):
        super().__init__(signum)
        self.signum = signum
        self.name = signal.Signals(signum).name
        self.exit_status = EXIT_SIGNAL + signum


class _Stop:
    """The handler: raise once, and not at all once the run is finishing."""

    def __init__(self):
        self.raised = False
        self.finishing = False

    def __call__(self, signum, frame):
        if not (self.raised or self.finishing):
            self.raised = True
            raise Interrupted(signum)


def stop_on_signals() -> None:
    """From now on, the first stop signal raises :class:`Interrupted` and later
    ones are ignored.  A signal that whoever started us ignores (``nohup``,
    a background job's SIGINT) stays ignored."""
    stop = _Stop()
    for sig in STOP_SIGNALS:
        if signal.getsignal(sig) is not signal.SIG_IGN:
            signal.signal(sig, stop)


def finishing() -> None:
    """The output is complete: stop signals no longer stop the run (an exit
    status of 130 must mean that the output is incomplete)."""
    for sig in STOP_SIGNALS:
        handler = signal.getsignal(sig)
        if isinstance(handler, _Stop):
            handler.finishing = True


@contextmanager
def signals_blocked():
    """Hold stop signals until the block ends (they are delivered then)."""
    old = signal.pthread_sigmask(signal.SIG_BLOCK, STOP_SIGNALS)
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)
