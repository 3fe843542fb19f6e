"""The tree stays clean under ruff (configuration in pyproject.toml): lint and format."""

import subprocess
import sys

import pytest

from places import ROOT


@pytest.mark.parametrize(
    "args", [["check", "--output-format", "concise"], ["format", "--check"]], ids=["lint", "format"]
)
def test_ruff_is_clean(args):
    # Through this interpreter, not PATH: CI runs `.venv/bin/python -m pytest` without activating the venv.
    done = subprocess.run(
        [sys.executable, "-m", "ruff", *args, "src", "tests", "bench"], cwd=ROOT, capture_output=True, text=True
    )
    assert done.returncode == 0, done.stdout + done.stderr
