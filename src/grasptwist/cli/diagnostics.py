"""stderr: diagnostic lines (counted, coloured on a terminal, summarised) and the progress bar.

Every diagnostic is one line ``path:line:col: error: message``; stdout
carries data only.
"""

from __future__ import annotations

import os
import sys
from contextlib import contextmanager
from enum import Enum

from ..results import KINDS

__all__ = [
    "Warnings",
    "WARNINGS_SHOWN",
    "TABLE_HINT_AT",
    "Diagnostics",
    "to_stderr",
    "error_code",
    "summary_line",
    "warning_kind",
    "table_hint",
    "progress_bar",
    "COMPILE_NOTICE_AFTER",
    "compile_notices",
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
    """One line on stderr; if stderr is gone (a hung-up terminal, or closed by the shell,
    ``2>&-``: ``sys.stderr`` is None), there is nobody to tell."""
    if sys.stderr is None:
        return
    try:
        sys.stderr.write(line + "\n")
        sys.stderr.flush()
    except (OSError, ValueError):
        pass


def _stderr_is_terminal() -> bool:
    return sys.stderr is not None and sys.stderr.isatty()


class Diagnostics:
    """Diagnostics on stderr: one line each, counted; colour only on a terminal.

    Errors of inputs are all printed; warnings, and the errors of a data
    set's or stream's rows, as ``--warnings`` asks (``summary``: the first
    :data:`WARNINGS_SHOWN` of each, then one line counting the rest by kind
    or code); ``-q`` drops warnings, the table hint and the summary.
    ``hint`` is the line said once when a table passes :data:`TABLE_HINT_AT`
    records; ``failed_words`` what the summary says of the records not ok, ``apart`` the kinds
    of them counted on their own (the command's, :class:`~grasptwist.run.families.Command`).
    """

    def __init__(
        self,
        quiet: bool = False,
        warnings: Warnings = Warnings.summary,
        hint: str | None = None,
        failed_words: str = "with a degenerate method",
        apart: tuple[str, ...] = (),
    ):
        self.failed = 0  # records not ok
        self.inputs_failed = 0  # of ``failed``: inputs that could not be read
        self.degenerate: dict[tuple[str, str], int] = {}  # the other failed records, per (kind, code)
        self.records = 0
        self.quiet = quiet
        self.shown = {Warnings.all: None, Warnings.summary: WARNINGS_SHOWN, Warnings.none: 0}[Warnings(warnings)]
        self.rows_shown = self.shown
        self.counting = warnings == Warnings.summary
        self.unshown: dict[str, int] = {}  # warnings not printed, by kind
        self.rows_unshown: dict[str, int] = {}  # row errors not printed, by code
        self.hint = None if quiet else hint
        self.color = _stderr_is_terminal() and not os.environ.get("NO_COLOR")
        self.failed_words = failed_words
        self.apart = apart

    def take(self, out) -> None:
        """Count a pipeline Output and print its lines."""
        self.records += out.records
        self.failed += out.failed
        self.inputs_failed += out.inputs_failed
        for code, n in out.degenerate.items():
            self.degenerate[code] = self.degenerate.get(code, 0) + n
        for line in out.errors:
            self.say(line, ": error: ", "31")
        for line in out.row_errors:
            self.row_error(line)
        if not self.quiet:
            for line in out.warnings:
                self.warn(line)
            for line in out.notes:
                to_stderr(line)
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

    def row_error(self, line: str) -> None:
        """Print the error of a data set's or stream's row, or count it by code once the first are out."""
        if self.rows_shown is None or self.rows_shown > 0:
            self.say(line, ": error: ", "31")
            self.rows_shown = None if self.rows_shown is None else self.rows_shown - 1
        elif self.counting:
            code = error_code(line)
            self.rows_unshown[code] = self.rows_unshown.get(code, 0) + 1

    def say(self, line: str, label: str, colour: str) -> None:
        """Print one diagnostic line, its label coloured on a terminal."""
        if self.color:
            line = line.replace(label, f": \x1b[{colour}m{label[2:-2]}\x1b[0m: ", 1)
        to_stderr(line)

    def summary(self) -> None:
        if self.quiet:
            return
        if self.rows_unshown:
            to_stderr(_not_shown(self.rows_unshown, "row error"))
        if self.unshown:
            to_stderr(_not_shown(self.unshown, "warning"))
        to_stderr(
            summary_line(
                self.records,
                self.failed - self.inputs_failed,
                self.inputs_failed,
                self.degenerate,
                self.failed_words,
                self.apart,
            )
        )


def summary_line(
    records: int,
    degenerate: int = 0,
    inputs_failed: int = 0,
    codes=None,
    words: str = "with a degenerate method",
    apart: tuple[str, ...] = (),
) -> str:
    """The closing line: how many records were written, how many of them hold a degenerate
    method (a grasp, or a data set's row, that was read: the other methods' results are there;
    ``words`` say it, a command's own: ``not held``) and by which codes, and how many inputs
    could not be read (each one record).  The codes of a kind in ``apart`` are a clause of their
    own, ``N kind (codes)``, and not among ``words``' (``simulate``'s grasps read but not simulated).

    >>> summary_line(1), summary_line(4, 0, 1)
    ('1 record: all ok', '4 records: 0 with a degenerate method, 1 input failed')
    >>> summary_line(3, 3, 0, {("tangent", "normals-rank-deficient"): 2, ("tangent", "theta-not-unique"): 1})
    '3 records: 3 with a degenerate method (tangent: 2 normals-rank-deficient, 1 theta-not-unique), 0 inputs failed'
    >>> summary_line(2, 1, 0, words="not held")
    '2 records: 1 not held, 0 inputs failed'
    >>> summary_line(3, 3, 0, {("not simulated", "no-mass"): 2}, "not held", apart=("not simulated",))
    '3 records: 1 not held, 2 not simulated (2 no-mass), 0 inputs failed'
    """
    line = f"{records} record{'' if records == 1 else 's'}: "
    if not degenerate and not inputs_failed:
        return line + "all ok"
    kinds: dict[str, list[str]] = {}
    for (kind, code), n in sorted((codes or {}).items(), key=lambda kv: (-kv[1], kv[0])):
        kinds.setdefault(kind, []).append(f"{n} {code}")
    own = {kind: sum(n for (k, _), n in (codes or {}).items() if k == kind) for kind in apart if kind in kinds}
    line += f"{degenerate - sum(own.values())} {words}"
    if shared := {kind: counts for kind, counts in kinds.items() if kind not in own}:
        line += " (" + "; ".join(f"{kind}: {', '.join(counts)}" for kind, counts in shared.items()) + ")"
    for kind, n in own.items():
        line += f", {n} {kind} ({', '.join(kinds[kind])})"
    return line + f", {inputs_failed} input{'' if inputs_failed == 1 else 's'} failed"


def _not_shown(counts: dict[str, int], what: str) -> str:
    """The line that counts the ``what`` lines not printed, by kind, most first."""
    total = sum(counts.values())
    kinds = ", ".join(f"{n} {kind}" for kind, n in sorted(counts.items(), key=lambda kv: -kv[1]))
    return f"grasptwist: {total} more {what}{'' if total == 1 else 's'} not shown (--warnings all): {kinds}"


#: The labels that start a method's error (``tangent: coincident-contacts: ...``).
_KIND_LABELS = frozenset(k.label for k in KINDS)


def error_code(line: str) -> str:
    """An error line's code, after the method's label when a method failed.

    >>> error_code("a.npz: grasp '7', twist 't': error: tangent: coincident-contacts: contacts 2 and 3 coincide")
    'tangent coincident-contacts'
    >>> error_code("a.jsonl:3:1: error: vector-length: normal needs 3 numbers")
    'vector-length'
    """
    parts = line.rpartition(": error: ")[2].split(": ", 2)
    return " ".join(parts[:2]) if parts[0] in _KIND_LABELS and len(parts) > 1 else parts[0]


def warning_kind(line: str) -> str:
    """What a warning line is about, without its place and numbers: its message
    up to the first parenthesis or colon (``tangent basis is nearly degenerate``).

    >>> warning_kind("a.yaml: grasp 'g': warning: tangent basis is nearly degenerate (conditioning 2e-05 < 0.001): ...")
    'tangent basis is nearly degenerate'
    """
    message = line.rpartition(": warning: ")[2]
    return message.split(" (", 1)[0].split(":", 1)[0].strip()


def table_hint(formats) -> str:
    """The line that points a reader of a long table to the machine formats (of a command's ``formats``).

    >>> table_hint(("table", "json", "jsonl"))
    'grasptwist: hint: more than 50 records: -f json or jsonl writes them far faster, for programs'
    """
    others = [f for f in formats if f != "table"]
    listed = ", ".join(others[:-1]) + f" or {others[-1]}"
    return f"grasptwist: hint: more than {TABLE_HINT_AT} records: -f {listed} writes them far faster, for programs"


@contextmanager
def progress_bar(inputs: list, command: str, out, shown: bool = True, long_inputs: bool = False):
    """A rich progress bar on stderr, named after ``command``, when it is a
    terminal and there is more than one input, a data set (whose records
    are counted as they come) or ``long_inputs`` (each input long work); not when the output ``out`` goes to a
    terminal too, where it shows the progress itself (and a bar would be
    drawn between its lines), nor when not ``shown`` (a command whose
    outputs do not count the inputs done).  Yields the function that
    advances it by a pipeline Output."""
    from ..io.datasets import DATASET_SUFFIXES

    big = long_inputs or len(inputs) > 1 or any(isinstance(p, str) and p.endswith(DATASET_SUFFIXES) for p in inputs)
    if not shown or not big or not _stderr_is_terminal() or out.isatty():
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


#: Seconds the compiled grip's first load may take before the command line says it is compiling: numba's
#: import and its cache take under 2 s on this project's machine, even at a load of 9 on 2 cores; a compile
#: a minute or more.
COMPILE_NOTICE_AFTER = 10.0


def compile_notices(quiet: bool, more: str = ""):
    """One command's factory for :func:`~grasptwist.engine.hooks.watching_first_load`: a :func:`_compile_notice`
    around each first load, of which one at most says its line (the grip's kernel and the soft contacts'
    iterations compile apart, one after the other, on a fresh install)."""
    said: list = []
    return lambda: _compile_notice(quiet, more, said)


@contextmanager
def _compile_notice(quiet: bool, more: str, said: list):
    """Around one first load: one line on stderr once it outlasts :data:`COMPILE_NOTICE_AFTER` (a fresh install's
    compile), ending with ``more``; none with ``quiet`` or once ``said`` (appended to when the line is said)
    holds one."""
    import threading

    def notice():
        to_stderr(
            "grasptwist: compiling the grip's numba kernels, once per install (20 s to a minute and a half, longer on a busy "
            f"machine){more}"
        )
        said.append(True)

    timer = threading.Timer(COMPILE_NOTICE_AFTER, notice)
    timer.daemon = True
    if not (quiet or said):
        timer.start()
    try:
        yield
    finally:
        timer.cancel()
