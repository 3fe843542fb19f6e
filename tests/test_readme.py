"""The README's code runs as printed: Python blocks execute, ``pycon`` sessions
give the outputs shown, and the output contract's example names a real file."""

import doctest
import json
import re
from pathlib import Path

import pytest

from hostile import run_installed

ROOT = Path(__file__).parent.parent
README = (ROOT / "README.md").read_text("utf-8")


def blocks(language):
    """The text of every fenced block of ``language``, in file order."""
    return re.findall(rf"^```{language}\n(.*?)^```$", README, flags=re.M | re.S)


def test_there_are_snippets_to_run():
    assert len(blocks("python")) >= 1 and len(blocks("pycon")) >= 5


def python_blocks():
    """The Python blocks as parameters; those drawing images or starting a Dask cluster (seconds each)
    run with ``-m slow``."""
    slow = ("plot.render", "import dask")
    return [
        pytest.param(
            code, id=code.splitlines()[0][:40], marks=[pytest.mark.slow] if any(s in code for s in slow) else []
        )
        for code in blocks("python")
    ]


@pytest.mark.parametrize("code", python_blocks())
def test_each_python_block_runs(code, tmp_path, monkeypatch):
    if "import dask" in code:
        pytest.importorskip("distributed")
        from test_dask import check  # a cluster in a process of its own (why: dask_checks.py)

        assert check("readme_block", tmp_path) == ["3000 rows in results/"]
        return
    if "plot.render" in code:
        pytest.importorskip("matplotlib")
    # the snippets name the bundled grasps/ by relative path, and write their images beside it
    (tmp_path / "grasps").symlink_to(ROOT / "grasps")
    monkeypatch.chdir(tmp_path)
    exec(compile(code, "README.md", "exec"), {})


def test_the_python_sessions_print_what_the_readme_shows(monkeypatch):
    monkeypatch.chdir(ROOT)
    session = "\n".join(blocks("pycon"))
    test = doctest.DocTestParser().get_doctest(session, {}, "README.md", "README.md", 0)
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS)
    report = []
    runner.run(test, out=report.append)
    assert runner.failures == 0 and runner.tries == len(test.examples) > 10, "".join(report)


def test_the_output_contract_example_is_a_record_of_a_bundled_grasp():
    contract = README.split("## Output contract")[1]
    example = re.search(r"^```\n(\{.*?)^```$", contract, flags=re.M | re.S).group(1)
    names = dict(re.findall(r'"(file|grasp|units)": "([^"]+)"', example))
    twist = re.search(r'"twist": \{"name": "([^"]+)"', example).group(1)
    keys = top_level_keys(example)
    p, _ = run_installed("resolve", names["file"], "-f", "jsonl", cwd=ROOT)
    recs = {r["twist"]["name"]: r for r in map(json.loads, p.stdout.splitlines())}
    rec = recs[twist]
    assert (rec["file"], rec["grasp"], rec["units"]) == (names["file"], names["grasp"], names["units"])
    assert list(rec) == keys, example


def top_level_keys(text):
    """The keys of the outermost object of JSON-like ``text``, in order."""
    depth, keys = 0, []
    for m in re.finditer(r'[{}\[\]]|"(\w+)":', text):
        if m.group(1) is None:
            depth += 1 if m.group() in "{[" else -1
        elif depth == 1:
            keys.append(m.group(1))
    return keys
