"""The ``grasptwist`` command line (typer).

A thin layer: it parses options (:mod:`.options`), hands files to the
pipeline (:mod:`grasptwist.run`) and writes what comes back.  One module
per command (:mod:`.resolve`, :mod:`.basis`, :mod:`.check`, :mod:`.follow`,
:mod:`.schema`, :mod:`.plot`); stderr lines, their counts and the progress
bar in :mod:`.diagnostics`; ``-o`` and exit codes in :mod:`.exits`.
stdout carries data only; every diagnostic goes to stderr as one line
``path:line:col: error: message``.
"""

import gc
import importlib
import sys

import typer

from .._version import __version__
from .exits import CLICK_ERROR, EXIT_OK, EXIT_WRITE, failed, stopped, to_stdout, usage_error

__all__ = ["app", "app_for", "command", "COMMANDS", "main"]

#: The commands by name, in the order of ``grasptwist -h``: each is the function of the same
#: name in the module of the same name, imported only when a command line needs it (a run of
#: one command does not pay for the others' modules at start-up).
COMMANDS = ("resolve", "basis", "check", "follow", "forces", "synthesize", "simulate", "schema", "plot")


def command(name: str):
    """The function of command ``name`` (one of :data:`COMMANDS`)."""
    return getattr(importlib.import_module(f".{name}", __name__), name)


def _version(value: bool) -> None:
    if value:
        to_stdout(f"grasptwist {__version__}\n")
        raise typer.Exit(EXIT_OK)


def _root(
    version: bool = typer.Option(
        False, "--version", callback=_version, is_eager=True, help="Print the version and exit."
    ),
) -> None:
    """Resolve a desired object twist into finger-tip twists for a three-fingered grasp (screw theory)."""


def _app(commands) -> typer.Typer:
    """The ``grasptwist`` command group holding ``commands``."""
    made = typer.Typer(
        name="grasptwist",
        help="Resolve a desired object twist into finger-tip twists for a three-fingered grasp (screw theory).",
        no_args_is_help=True,
        add_completion=True,
        rich_markup_mode=None,
        pretty_exceptions_enable=False,
        context_settings={"help_option_names": ["-h", "--help"]},
    )
    made.callback()(_root)
    for command in commands:
        made.command()(command)
    return made


_every = []  # the group of every command, made once when first asked for


def __getattr__(name: str):
    if name == "app":  # every command (``grasptwist -h``, completion, tests)
        if not _every:
            _every.append(_app([command(c) for c in COMMANDS]))
        return _every[0]
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def app_for(args: list[str]) -> typer.Typer:
    """The group a command line needs: typer builds the options of every command it holds
    before it runs one (about 10 ms for seven), so a line naming a command (the first word
    not an option: the group's own options take no value) holds that one alone.

    >>> from grasptwist.cli import app
    >>> app_for(["-h"]) is app_for([]) is app_for(["fly", "a.yaml"]) is app
    True
    >>> [c.callback.__name__ for c in app_for(["--debug", "check", "a.yaml"]).registered_commands]
    ['check']
    """
    name = next((a for a in args if not a.startswith("-")), None)
    return _app([command(name)]) if name in COMMANDS else __getattr__("app")


def main() -> None:
    """Run the command line (the ``grasptwist`` script is :func:`grasptwist.__main__.main`)."""
    from ..run.signals import Interrupted, stop_on_signals
    from ..run.target import WriteError

    stop_on_signals()
    try:
        try:
            app = app_for(sys.argv[1:])
            if not gc.isenabled():  # the script's start (grasptwist.__main__ turned the collector off)
                # its objects, the command's modules loaded, out of the cyclic collector's sight, and
                # the collector on for the run's; a caller in Python keeps its own collector as it is
                gc.freeze()
                gc.enable()
            code = app(standalone_mode=False)
        except CLICK_ERROR as exc:
            code = usage_error(exc)
    except Interrupted as stop:  # while typer parsed the command line
        code = stopped(stop)
    except WriteError as exc:  # the version or the help on a closed stdout
        code = failed(exc, EXIT_WRITE)
    sys.exit(code if isinstance(code, int) else EXIT_OK)
