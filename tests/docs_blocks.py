"""The fenced blocks of the project's Markdown pages, found by a Markdown parser, and the ``console``
blocks' commands run as a reader would type them (docs/reference/development.md has the rules).

``python tests/docs_blocks.py --update`` rewrites every ``console`` block's output with what its
commands print now (blocks with a ``...`` excerpt line are left alone and named)."""

import difflib
import re
import shlex
import sys
from dataclasses import dataclass, field
from pathlib import Path

from markdown_it import MarkdownIt

from places import ROOT

#: What a ``console`` block's commands see: a terminal 100 columns wide, without colour.
CONSOLE_ENV = {"COLUMNS": "100", "NO_COLOR": "1", "FORCE_COLOR": None, "LINES": None}
#: The lines a console command may not hold: a shell would treat them, the test runs no shell.
SHELL = {"|", "||", "&&", ";", ">", ">>", "<", "2>", "2>&1", "&"}


def name(page: Path) -> str:
    """``page`` as the tests name it: relative to the repository root when it is in it."""
    return str(page.relative_to(ROOT)) if page.is_relative_to(ROOT) else str(page)


def pages() -> list[Path]:
    """Every Markdown page whose examples run: README.md, ARCHITECTURE.md and docs/**/*.md."""
    return [p for p in (ROOT / "README.md", ROOT / "ARCHITECTURE.md") if p.exists()] + sorted(
        (ROOT / "docs").rglob("*.md")
    )


@dataclass(frozen=True)
class Block:
    """One fenced block: its page, the 1-based line of its opening fence, the info string's first
    word (``lang``) and the words after it (``options``: ``slow``, ``file=NAME``, ``requires=A,B``,
    ``session=NAME``)."""

    page: Path
    line: int
    end: int  # 1-based line of the closing fence
    lang: str
    options: dict = field(hash=False)
    text: str
    indent: str = ""

    @property
    def where(self) -> str:
        return f"{name(self.page)}:{self.line}"


#: CommonMark's block rules only: a fence is a block, and the inline pass (links, emphasis) was two thirds
#: of the parse, paid by each test worker at collection (docs/reference/development.md, Test time).
FENCES = MarkdownIt("commonmark").disable("inline")


def blocks(page: Path) -> list[Block]:
    """The fenced blocks of ``page``, in page order (those nested in lists too)."""
    text = page.read_text("utf-8")
    lines = text.splitlines()
    found = []
    for token in FENCES.parse(text):
        if token.type != "fence":
            continue
        lang, *words = token.info.split() or [""]
        options = dict(w.split("=", 1) if "=" in w else (w, True) for w in words)
        start, end = token.map
        opening = lines[start]
        indent = opening[: len(opening) - len(opening.lstrip())]
        found.append(Block(page, start + 1, end, lang, options, token.content, indent))
    return found


def all_blocks() -> list[Block]:
    return [b for page in pages() for b in blocks(page)]


@dataclass(frozen=True)
class Command:
    args: list
    expected: str  # what a terminal shows: stdout, then stderr


def commands(block: Block) -> list[Command]:
    """The ``$ grasptwist ...`` commands of a ``console`` block, each with the output shown under it."""
    found, current, output = [], None, []

    def close():
        if current is not None:
            found.append(Command(current, "".join(line + "\n" for line in output)))

    lines = iter(block.text.splitlines())
    for line in lines:
        if line.startswith("$ "):
            close()
            command = line[2:]
            while command.endswith("\\"):
                command = command[:-1] + next(lines, "")
            args = shlex.split(command)
            if args[:1] != ["grasptwist"] or SHELL & set(args):
                raise ValueError(
                    f"{block.where}: a console block runs `$ grasptwist ARGS` alone, not {command!r}: "
                    "show a pipeline or another program as ```sh"
                )
            current, output = args[1:], []
        elif current is None:
            raise ValueError(f"{block.where}: a console block starts with a `$ grasptwist ...` line")
        else:
            output.append(line)
    close()
    if not found:
        raise ValueError(f"{block.where}: a console block without a command")
    return found


def scratch(folder: Path, page: Path) -> Path:
    """``folder`` made to look like the repository root (a link to each top-level entry), with the
    ``file=NAME`` blocks of ``page`` written in it: where a page's examples run and write."""
    for entry in ROOT.iterdir():
        if not entry.name.startswith("."):
            (folder / entry.name).symlink_to(entry)
    for b in blocks(page):
        if "file" in b.options:
            (folder / b.options["file"]).write_text(b.text, "utf-8")
    return folder


def run(args: list) -> str:
    """What ``grasptwist ARGS`` shows in a terminal (stdout, then stderr), run in-process; a Python
    exception other than the command's exit is raised, so its traceback shows where it came from."""
    from typer.testing import CliRunner

    from grasptwist.cli import app

    result = CliRunner().invoke(app, [str(a) for a in args], env=CONSOLE_ENV)
    if result.exception is not None and not isinstance(result.exception, SystemExit):
        raise result.exception
    return result.stdout + result.stderr


def pattern(expected: str) -> re.Pattern:
    """``expected`` as a pattern: each line literally, a line ``...`` for any number of lines."""
    parts = ["(?:.*\n)*?" if line == "..." else re.escape(line) + "\n" for line in expected.splitlines()]
    return re.compile("".join(parts))


def mismatch(where: str, args: list, expected: str, actual: str) -> str | None:
    """None when ``actual`` is what ``expected`` shows, else a message with a unified diff."""
    if pattern(expected).fullmatch(actual):
        return None
    diff = difflib.unified_diff(
        expected.splitlines(keepends=True), actual.splitlines(keepends=True), f"{where} (expected)", "actual"
    )
    return f"`grasptwist {shlex.join(map(str, args))}` printed other output than {where} shows:\n" + "".join(diff)


def update(page: Path, folder: Path) -> list[str]:
    """Rewrite the output of ``page``'s console blocks with what their commands print now (run in
    ``folder``, a scratch copy); the blocks left alone because they hold an excerpt."""
    import os

    lines = page.read_text("utf-8").splitlines(keepends=True)
    skipped = []
    os.chdir(scratch(folder, page))
    for b in reversed([b for b in blocks(page) if b.lang == "console"]):
        cmds = commands(b)
        if any(line == "..." for c in cmds for line in c.expected.splitlines()):
            skipped.append(b.where)
            continue
        text = "".join(f"$ grasptwist {shlex.join(c.args)}\n" + run(c.args) for c in cmds)
        lines[b.line : b.end - 1] = [b.indent + line if line.strip() else line for line in text.splitlines(True)]
    page.write_text("".join(lines), "utf-8")
    return skipped


if __name__ == "__main__":
    import tempfile

    if sys.argv[1:] != ["--update"]:
        sys.exit(__doc__)
    for page in pages():
        if any(b.lang == "console" for b in blocks(page)):
            with tempfile.TemporaryDirectory() as tmp:
                for where in update(page, Path(tmp)):
                    print(f"{where}: an excerpt (`...`): update it by hand", file=sys.stderr)
