"""docs/guide/pictures-html.md runs as printed: each ``console`` command prints what the page shows,
and its ``pycon`` session gives the outputs shown."""

import doctest
import re
import shlex
from pathlib import Path

import pytest
from typer.testing import CliRunner

from grasptwist.cli import app

pytest.importorskip("plotly")
ROOT = Path(__file__).parent.parent
PAGE = ROOT / "docs" / "guide" / "pictures-html.md"
TEXT = PAGE.read_text("utf-8")


def blocks(language):
    return re.findall(rf"^```{language}\n(.*?)^```$", TEXT, flags=re.M | re.S)


def commands():
    """``(command, expected stdout)`` of every console block; a folder's (every bundled grasp
    and path, half a minute) and the URDF hand's run with -m slow."""
    out = []
    for block in blocks("console"):
        for command in re.split(r"^\$ ", block, flags=re.M)[1:]:
            line, _, expected = command.partition("\n")
            slow = "grasps/ " in line or "trifinger" in line
            out.append(pytest.param(line, expected, id=line[:60], marks=[pytest.mark.slow] if slow else []))
    return out


@pytest.fixture
def in_tmp(tmp_path, monkeypatch):
    """The examples name the bundled grasps/ by relative path and write beside it."""
    (tmp_path / "grasps").symlink_to(ROOT / "grasps")
    monkeypatch.chdir(tmp_path)
    return tmp_path


def test_there_are_examples():
    assert len(commands()) >= 4 and len(blocks("pycon")) == 1


@pytest.mark.parametrize(("line", "expected"), commands())
def test_each_command_prints_what_the_page_shows(line, expected, in_tmp):
    if "trifinger" in line or "grasps/ " in line:
        pytest.importorskip("yourdfpy")
        pytest.importorskip("robot_properties_fingers")
    args = shlex.split(line)
    assert args[0] == "grasptwist"
    r = CliRunner().invoke(app, args[1:])
    assert r.exit_code == 0, r.output
    assert r.stdout == expected


def test_the_python_session_prints_what_the_page_shows(in_tmp):
    test = doctest.DocTestParser().get_doctest(blocks("pycon")[0], {}, PAGE.name, str(PAGE), 0)
    runner = doctest.DocTestRunner()
    report = []
    runner.run(test, out=report.append)
    assert runner.failures == 0 and runner.tries == len(test.examples) > 5, "".join(report)
