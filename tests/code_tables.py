"""The index of every code, generated from ``grasptwist.codes`` into docs/reference/bad-input-and-faults.md.

``python tests/code_tables.py --update`` rewrites the page's section between its two markers;
``tests/model/test_codes.py`` fails while the page and the table differ."""

import re
import sys
from pathlib import Path

from grasptwist.codes import ERRORS, EXIT, EXIT_SIGNAL, NO_GRASP_CONSTRAINTS, STATUSES, WARNINGS
from places import ROOT

#: The page that holds the index, and the markers around it.
PAGE = ROOT / "docs" / "reference" / "bad-input-and-faults.md"
BEGIN = "<!-- codes: generated from grasptwist/codes.py by `python tests/code_tables.py --update` -->"
END = "<!-- codes: end -->"


def link(page: str) -> str:
    """A link from the index's page to ``page`` (relative to ``docs/``), named after its file.

    >>> link("guide/grasp-files.md")
    '[grasp files](../guide/grasp-files.md)'
    """
    here = PAGE.parent.relative_to(ROOT / "docs")
    target = Path(page)
    href = target.name if target.parent == here else f"../{page}"
    return f"[{target.stem.replace('-', ' ')}]({href})"


def _cells(meaning: str) -> str:
    return meaning.replace("|", "\\|")


def index() -> str:
    """The index's Markdown, between the markers (both excluded)."""
    out = [
        "Every code a record, a stderr line or an exit status carries, generated from",
        "`grasptwist.codes`, which the engines and the command line read theirs from;",
        "`tests/model/test_codes.py` holds every module's codes and the pages below to it.",
        "Numbers, codes and exit statuses never change.",
        "",
        "### Statuses",
        "",
        "A row's status (`status` in records, the code in `error`): its number is the same in every",
        "engine; `twist` statuses are [the decompositions'](conventions.md#degenerate-grasps),",
        "`force` ones [the force engine's](../guide/forces.md).",
        "",
        "| number | code | engine |",
        "|---|---|---|",
    ]
    for s in STATUSES:
        engines = ", ".join(e for e in ("twist", "force") if getattr(s, e) is not None)
        out.append(f"| {s.number} | `{s.code}` | {engines} |")
    out += [
        "",
        "### Errors",
        "",
        "An input, or a grasp, that a command cannot use: an error record and a stderr line",
        "(`file:line:column: error: code: message`, the message in that input's words).",
        "",
        "| code | exit | what is wrong | explained in |",
        "|---|---|---|---|",
    ]
    for code, c in sorted(ERRORS.items()):
        out.append(f"| `{code}` | {c.exit} | {_cells(c.meaning)} | {', '.join(map(link, c.pages))} |")
    out += [
        "",
        "### Why a search found no grasp",
        "",
        "The `constraint` of a `no-grasp` record ([above](#a-search-that-cannot-start-or-finds-nothing)).",
        "",
        "| constraint | what held the search back |",
        "|---|---|",
    ]
    out += [f"| `{name}` | {_cells(meaning)} |" for name, meaning in NO_GRASP_CONSTRAINTS.items()]
    out += [
        "",
        "### Warnings",
        "",
        "The start of a record's `warnings` entry and of its stderr line; a warning never changes the",
        "exit status.",
        "",
        "| warning | when | explained in |",
        "|---|---|---|",
    ]
    for code, c in sorted(WARNINGS.items()):
        out.append(f"| `{code}` | {_cells(c.meaning)} | {', '.join(map(link, c.pages))} |")
    out += [
        "",
        "### Exit statuses",
        "",
        "([The command line](../guide/command-line.md#exit-codes-and-diagnostics) says more.)",
        "",
        "| exit | when |",
        "|---|---|",
    ]
    out += [f"| {number} | {_cells(meaning)} |" for number, meaning in sorted(EXIT.items())]
    out.append(f"| {EXIT_SIGNAL} + n | stopped by signal n (SIGHUP, SIGINT, SIGTERM) |")
    return "\n".join(out)


_REGION = re.compile(re.escape(BEGIN) + r"\n(.*?)" + re.escape(END), re.S)


def written(text: str) -> str:
    """What ``text`` (the page) holds between the markers."""
    match = _REGION.search(text)
    return match.group(1).removesuffix("\n") if match else ""


def updated(text: str) -> str:
    """``text`` with the index between the markers rewritten."""
    return _REGION.sub(lambda _: f"{BEGIN}\n{index()}\n{END}", text)


if __name__ == "__main__":
    if sys.argv[1:] != ["--update"]:
        sys.exit("usage: python tests/code_tables.py --update")
    PAGE.write_text(updated(PAGE.read_text("utf-8")), "utf-8")
