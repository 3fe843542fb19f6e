"""Machine outputs on the bundled grasps, byte for byte against golden files.

The golden files were written by grasptwist 0.1 before the code was split
into subpackages; a change that alters one must say why and regenerate it
(see tests/golden/README.md).
"""

from pathlib import Path

import pytest
from typer.testing import CliRunner

from grasptwist.cli import app

ROOT = Path(__file__).resolve().parents[1]
GOLDEN = ROOT / "tests" / "golden"

CASES = {
    "resolve.jsonl": ["resolve", "grasps/", "-f", "jsonl"],
    "resolve.csv": ["resolve", "grasps/", "-f", "csv"],
    "resolve-v-omega.json": ["resolve", "grasps/", "-f", "json", "--order", "v-omega"],
    "basis.jsonl": ["basis", "grasps/", "-f", "jsonl"],
    "check.jsonl": ["check", "grasps/", "-f", "jsonl"],
}


@pytest.mark.parametrize("name", CASES)
def test_output_is_byte_for_byte_the_golden_file(name, monkeypatch):
    monkeypatch.chdir(ROOT)
    result = CliRunner().invoke(app, CASES[name])
    assert result.exit_code == 1  # several bundled grasps are degenerate for the tangent method on purpose
    assert result.stdout_bytes == (GOLDEN / name).read_bytes()
