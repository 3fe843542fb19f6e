"""``python -m grasptwist`` and the ``grasptwist`` script.

Stop signals are handled from here on, before numpy, typer and the rest
are imported, so that a Ctrl-C while starting up ends quietly too.
"""

import gc
import os
import sys


def main() -> None:
    """Entry point of the ``grasptwist`` script."""
    _hold_closed_stderr()
    # Python's cyclic collector is off while the start-up makes its objects (modules, classes,
    # functions: they live to the end, none is garbage); grasptwist.cli.main freezes them and turns
    # it back on before the command runs, so that neither the run's collections nor the one at exit
    # go through them (62 of the 780 million instructions a JSON resolve took, bench/startup.py)
    gc.disable()
    from grasptwist.run.signals import Interrupted, stop_on_signals

    stop_on_signals()
    try:
        from grasptwist import cli
    except Interrupted as stop:
        if sys.stderr is not None:
            sys.stderr.write(f"grasptwist: stopped by {stop.name}\n")
        raise SystemExit(stop.exit_status) from None
    cli.main()


def _hold_closed_stderr() -> None:
    """A stderr the shell closed (``2>&-``; Python's ``sys.stderr`` is then None) has its number
    held by ``/dev/null``: a file the run opens next would get descriptor 2 otherwise, and what a
    library's C code writes there would land in it.  ``sys.stderr`` stays None (diagnostics are
    dropped, and ``-o /dev/stderr`` is refused as closed)."""
    if sys.stderr is None:
        fd = os.open(os.devnull, os.O_WRONLY)
        if fd != 2:  # 0 or 1, closed too: leave them closed, as Python found them
            os.dup2(fd, 2)
            os.close(fd)


if __name__ == "__main__":
    main()
