"""stderr: diagnostic lines (counted, coloured on a terminal, summarised) and the progress bar.

Every diagnostic is one line ``path:line:col: error: message``; stdout
carries data only.
"""

from __future__ import annotations

import os
import sys
from contextlib import contextmanager
from enum import Enum

from ..output.formats import names_for

__all__ = [
    "Warnings",
    "WARNINGS_SHOWN",
    "TABLE_HINT_AT",
    "Diagnostics",
    "to_stderr",
    "warning_kind",
    "table_hint",
    "progress_bar",
]


class Warnings(str, Enum):
    """``--warnings``: which warning lines stderr prints."""

    all = "all"
    summary = "summary"
    none = "none"


#: Warnings ``--warnings summary`` prints before it only counts them.
WARNINGS_SHOWN = 20

#: Records of a table from which stderr suggests the machine formats, once.
TABLE_HINT_AT = 50


def to_stderr(line: str) -> None:
    """One line on stderr; if stderr is gone (a hung-up terminal), there is nobody to tell."""
    try:
        sys.stderr.write(line + "\n")
        sys.stderr.flush()
    except (OSError, ValueError):
        pass


class Diagnostics:
    """Diagnostics on stderr: one line each, counted; colour only on a terminal.

    Errors are all printed; warnings as ``--warnings`` asks (``summary``: the
    first :data:`WARNINGS_SHOWN`, then one line counting the rest by kind);
    ``-q`` drops warnings, the table hint and the summary.  ``hint`` is the
    line said once when a table passes :data:`TABLE_HINT_AT` records.
    """

    def __init__(self, quiet: bool = False, warnings: Warnings = Warnings.summary, hint: str | None = None):
        self.failed = 0
        self.records = 0
        self.quiet = quiet
        self.shown = {Warnings.all: None, Warnings.summary: WARNINGS_SHOWN, Warnings.none: 0}[Warnings(warnings)]
        self.counting = warnings == Warnings.summary
        self.unshown: dict[str, int] = {}  # warnings not printed, by kind
        self.hint = None if quiet else hint
        self.color = sys.stderr.isatty() and not os.environ.get("NO_COLOR")

    def take(self, out) -> None:
        """Count a pipeline Output and print its lines."""
        self.records += out.records
        self.failed += out.failed
        for line in out.errors:
            self.say(line, ": error: ", "31")
        if not self.quiet:
            for line in out.warnings:
                self.warn(line)
        if self.hint and self.records > TABLE_HINT_AT:
            to_stderr(self.hint)
            self.hint = None

    def warn(self, line: str) -> None:
        """Print a warning line, or count it by kind once the first ``shown`` are out."""
        if self.shown is None or self.shown > 0:
            self.say(line, ": warning: ", "33")
            self.shown = None if self.shown is None else self.shown - 1
        elif self.counting:
            kind = warning_kind(line)
            self.unshown[kind] = self.unshown.get(kind, 0) + 1

    def say(self, line: str, label: str, colour: str) -> None:
        """Print one diagnostic line, its label coloured on a terminal."""
        if self.color:
            line = line.replace(label, f": \x1b[{colour}m{label[2:-2]}\x1b[0m: ", 1)
        to_stderr(line)

    def summary(self) -> None:
        if self.quiet:
            return
        if self.unshown:
            total = sum(self.unshown.values())
            kinds = ", ".join(f"{n} {kind}" for kind, n in sorted(self.unshown.items(), key=lambda kv: -kv[1]))
            to_stderr(
                f"grasptwist: {total} more warning{'' if total == 1 else 's'} not shown (--warnings all): {kinds}"
            )
        to_stderr(f"{self.records} record{'' if self.records == 1 else 's'}, {self.failed} failed")


def warning_kind(line: str) -> str:
    """What a warning line is about, without its place and numbers: its message
    up to the first parenthesis or colon (``tangent basis is nearly degenerate``).

    >>> warning_kind("a.yaml: grasp 'g': warning: tangent basis is nearly degenerate (conditioning 2e-05 < 0.001): ...")
    'tangent basis is nearly degenerate'
    """
    message = line.rpartition(": warning: ")[2]
    return message.split(" (", 1)[0].split(":", 1)[0].strip()


def table_hint(command: str) -> str:
    """The line that points a reader of a long table to the machine formats."""
    others = [f for f in names_for(command) if f != "table"]
    listed = ", ".join(others[:-1]) + f" or {others[-1]}"
    return f"grasptwist: hint: more than {TABLE_HINT_AT} records: -f {listed} writes them far faster, for programs"


@contextmanager
def progress_bar(inputs: list, command: str, out):
    """A rich progress bar on stderr, named after ``command``, when it is a
    terminal and there is more than one input or a data set (whose records
    are counted as they come); not when the output ``out`` goes to a
    terminal too, where it shows the progress itself (and a bar would be
    drawn between its lines).  Yields the function that advances it by a
    pipeline Output."""
    from ..io.datasets import DATASET_SUFFIXES

    big = len(inputs) > 1 or any(isinstance(p, str) and p.endswith(DATASET_SUFFIXES) for p in inputs)
    if not big or not sys.stderr.isatty() or out.isatty():
        yield lambda output: None
        return
    from rich.progress import Progress

    from ..output.table import console

    # the console never wraps: lines printed under the bar (stderr is redirected
    # through it) stay one line each, folded only by the terminal
    with Progress(console=console(sys.stderr), transient=True) as bar:
        task = bar.add_task(f"grasptwist {command}", total=len(inputs))

        def advance(output):
            if output.extra_work:
                bar.update(task, total=bar.tasks[0].total + output.extra_work)
            bar.advance(task, output.done)

        yield advance
