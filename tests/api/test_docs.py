"""The docs' examples run as printed: README.md, ARCHITECTURE.md and docs/**/*.md, every fenced block
by its info string (docs/reference/development.md, "Examples in the docs run"): ``python`` blocks
execute, ``pycon`` sessions give the outputs shown, ``console`` commands print the output shown; and
the pages' relative links lead somewhere."""

import doctest
import functools
import json
import re
from pathlib import Path

import pytest
from markdown_it import MarkdownIt
from typer.testing import CliRunner

from docs_blocks import ROOT, all_blocks, blocks, commands, mismatch, name, pages, run, scratch
from grasptwist.cli import app

BLOCKS = all_blocks()


def params(lang):
    """The blocks of ``lang`` as parameters named by page and line, marked and skipped as their
    options say."""
    out = []
    for b in BLOCKS:
        if b.lang != lang:
            continue
        marks = [pytest.mark.slow] if b.options.get("slow") else []
        out.append(pytest.param(b, id=b.where, marks=marks))
    return out


def needs(block):
    for module in str(block.options.get("requires", "")).split(","):
        if module:
            pytest.importorskip(module)


def test_every_block_says_what_it_is_and_there_are_examples_of_each_kind():
    bare = [b.where for b in BLOCKS if not b.lang]
    assert bare == [], "a fence without an info string (```text for output, ```sh for commands not run)"
    kinds = [b.lang for b in BLOCKS]
    assert kinds.count("console") >= 5 and kinds.count("pycon") >= 5 and kinds.count("python") >= 3


@pytest.mark.parametrize("block", params("python"))
def test_each_python_block_runs(block, tmp_path, monkeypatch):
    needs(block)
    if block.options.get("runner") == "dask":
        from test_dask import check  # a cluster in a process of its own (why: dask_checks.py)

        assert check("readme_block", tmp_path) == ["3000 rows in results/"]
        return
    monkeypatch.chdir(scratch(tmp_path, block.page))
    exec(compile(block.text, block.where, "exec"), {"__name__": "__docs__"})


def sessions():
    """``(page, session)`` of every ``pycon`` session, in page order, from the blocks already read (reading
    the pages again cost each test worker 0.1 s): a page's blocks are one session, but those with
    ``session=NAME`` (a topic that needs nothing above it) are the session ``NAME``."""
    found = dict.fromkeys((b.page, b.options.get("session", "")) for b in BLOCKS if b.lang == "pycon")
    return [pytest.param(page, session, id=name(page) + (f"[{session}]" if session else "")) for page, session in found]


@pytest.mark.parametrize(("page", "session"), sessions())
def test_the_python_sessions_print_what_the_page_shows(page, session, tmp_path, monkeypatch):
    monkeypatch.chdir(scratch(tmp_path, page))
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS)
    report, names = [], {}
    parser = doctest.DocTestParser()
    for b in blocks(page):
        if b.lang == "pycon" and b.options.get("session", "") == session:  # a block uses the names above it
            test = parser.get_doctest(b.text, names, b.where, str(page), b.line)
            runner.run(test, out=report.append, clear_globs=False)
            names = test.globs
    assert runner.failures == 0 and runner.tries > 0, "".join(report)


@pytest.mark.parametrize("block", params("console"))
def test_each_console_command_prints_what_the_block_shows(block, tmp_path, monkeypatch):
    needs(block)
    monkeypatch.chdir(scratch(tmp_path, block.page))
    for command in commands(block):
        problem = mismatch(block.where, command.args, command.expected, run(command.args))
        if problem:
            pytest.fail(problem, pytrace=False)


def test_a_console_block_runs_grasptwist_alone_and_an_excerpt_matches_its_ends(tmp_path):
    page = tmp_path / "page.md"
    page.write_text("```console\n$ grasptwist check x.yaml | head\n```\n")
    (block,) = blocks(page)
    with pytest.raises(ValueError, match=r"runs `\$ grasptwist ARGS` alone, not 'grasptwist check x.yaml \| head'"):
        commands(block)
    assert mismatch("p", [], "a\n...\nd\n", "a\nb\nc\nd\n") is None
    assert mismatch("p", [], "a\n...\n", "a\n") is None
    said = mismatch("p.md:3", ["check"], "a\n...\nd\n", "a\nb\nc\n")
    assert "`grasptwist check` printed other output than p.md:3 shows" in said and "\n-d\n" in said


def slug(heading: str) -> str:
    """A heading's anchor as a code host makes it (GitHub's rule)."""
    return re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")


@functools.cache
def links_and_anchors(page):
    tokens = MarkdownIt("commonmark").parse(page.read_text("utf-8"))
    anchors = {slug(tokens[i + 1].content) for i, t in enumerate(tokens) if t.type == "heading_open"}
    hrefs = [
        c.attrs["src" if c.type == "image" else "href"]
        for t in tokens
        if t.type == "inline"
        for c in t.children or []
        if c.type in ("link_open", "image")
    ]
    return hrefs, anchors


def test_relative_links_lead_to_a_file_and_a_heading_that_are_there():
    broken = []
    for page in pages():
        hrefs, _ = links_and_anchors(page)
        for href in hrefs:
            if re.match(r"[a-z]+:", href):
                continue  # a web address
            path, _, anchor = href.partition("#")
            target = (page.parent / path).resolve() if path else page
            if not target.exists():
                broken.append(f"{name(page)}: {href}: no such file")
            elif anchor and target.suffix == ".md" and anchor not in links_and_anchors(target)[1]:
                broken.append(f"{name(page)}: {href}: no such heading")
    assert broken == []


def test_the_output_contract_example_is_a_record_of_a_bundled_grasp(monkeypatch):
    page = ROOT / "docs" / "reference" / "output-contract.md"
    (example,) = [b.text for b in blocks(page) if b.lang == "text" and b.text.startswith('{"file": "grasps/')]
    names = dict(re.findall(r'"(file|grasp|units)": "([^"]+)"', example))
    twist = re.search(r'"twist": \{"name": "([^"]+)"', example).group(1)
    monkeypatch.chdir(ROOT)  # the example's file name is relative to the repository
    done = CliRunner().invoke(app, ["resolve", names["file"], "-f", "jsonl"])
    assert done.exit_code == 0, done.stderr
    recs = {r["twist"]["name"]: r for r in map(json.loads, done.stdout.splitlines())}
    rec = recs[twist]
    assert (rec["file"], rec["grasp"], rec["units"]) == (names["file"], names["grasp"], names["units"])
    assert list(rec) == top_level_keys(example), example


def top_level_keys(text):
    """The keys of the outermost object of JSON-like ``text``, in order."""
    depth, keys = 0, []
    for m in re.finditer(r'[{}\[\]]|"(\w+)":', text):
        if m.group(1) is None:
            depth += 1 if m.group() in "{[" else -1
        elif depth == 1:
            keys.append(m.group(1))
    return keys


def test_the_quick_start_commands_are_those_ci_runs():
    readme = [b.text.strip() for b in blocks(ROOT / "README.md") if b.lang == "sh"]
    ci = (ROOT / ".ci" / "run").read_text("utf-8").strip().splitlines()[-1]
    assert ci in readme and any(".venv/bin/grasptwist resolve grasps/polyhedron.yaml" in b for b in readme)
    assert Path(ROOT / "README.md").read_text("utf-8").count("\n") < 250
