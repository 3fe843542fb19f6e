"""``python -m grasptwist`` and the ``grasptwist`` script.

Stop signals are handled from here on, before numpy, typer and the rest
are imported, so that a Ctrl-C while starting up ends quietly too.
"""

import sys


def main() -> None:
    """Entry point of the ``grasptwist`` script."""
    from grasptwist.run.signals import Interrupted, stop_on_signals

    stop_on_signals()
    try:
        from grasptwist import cli
    except Interrupted as stop:
        sys.stderr.write(f"grasptwist: stopped by {stop.name}\n")
        raise SystemExit(stop.exit_status) from None
    cli.main()


if __name__ == "__main__":
    main()
