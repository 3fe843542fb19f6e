"""Machine outputs on the bundled grasps against golden files.

Everything computed in closed form is compared byte for byte.  The numbers
of a hand (joint rates, residuals, conditioning, the velocity-limit ratio)
come through LAPACK's SVD, whose last bits depend on the CPU and the numpy
build; they are compared to a relative 1e-9 (absolute 1e-12 near zero), and
everything around them (keys, their order, every other number) still
exactly.  A change that alters a golden file must say why and regenerate it
(see tests/golden/README.md).
"""

import math

import orjson
import pytest
from typer.testing import CliRunner

from grasptwist.cli import app
from places import ROOT

GOLDEN = ROOT / "tests" / "golden"

CASES = {
    "resolve.jsonl": ["resolve", "grasps/", "-f", "jsonl"],
    "resolve.csv": ["resolve", "grasps/", "-f", "csv"],
    "resolve-v-omega.json": ["resolve", "grasps/", "-f", "json", "--order", "v-omega"],
    "basis.jsonl": ["basis", "grasps/", "-f", "jsonl"],
    "check.jsonl": ["check", "grasps/", "-f", "jsonl"],
}

#: JSON keys whose numbers (at any depth below them) pass through LAPACK.
#: The clearance of a hand placed by inverse kinematics (its joint positions solved) is one of them.
LAPACK_KEYS = {"hand", "joint_rates", "clearance"}


def close(a, b):
    return math.isclose(a, b, rel_tol=1e-9, abs_tol=1e-12)


def agree(ours, golden, loose=False, where="$"):
    """Whether two parsed JSON values agree: the same structure and key order,
    numbers equal (or close below a LAPACK key); raises with the place if not."""
    if isinstance(golden, dict):
        assert isinstance(ours, dict) and list(ours) == list(golden), where
        for key in golden:
            agree(ours[key], golden[key], loose or key in LAPACK_KEYS, f"{where}.{key}")
    elif isinstance(golden, list):
        assert isinstance(ours, list) and len(ours) == len(golden), where
        for k, (a, b) in enumerate(zip(ours, golden)):
            agree(a, b, loose, f"{where}[{k}]")
    elif loose and type(golden) is float:
        assert type(ours) is float and close(ours, golden), f"{where}: {ours} vs {golden}"
    else:
        assert type(ours) is type(golden) and ours == golden, f"{where}: {ours!r} vs {golden!r}"


def json_line(line):
    """A line of a JSON Lines file, or of a JSON array written a record a line."""
    return orjson.loads(line.strip().removeprefix("[").removesuffix(",").removesuffix("]") or "null")


@pytest.mark.parametrize("name", CASES)
def test_output_matches_the_golden_file(name, monkeypatch):
    monkeypatch.chdir(ROOT)
    result = CliRunner().invoke(app, CASES[name])
    assert result.exit_code == 1  # several bundled grasps are degenerate for the tangent method on purpose
    ours = result.stdout_bytes.decode().split("\n")
    golden = (GOLDEN / name).read_text().split("\n")
    assert len(ours) == len(golden)
    header = golden[0].split(",")
    for k, (line, expected) in enumerate(zip(ours, golden)):
        if line != expected:
            if name.endswith(".csv"):  # byte for byte but in the LAPACK columns (no hand columns in a folder's)
                csv_agree(line.split(","), expected.split(","), header, f"line {k + 1}")
                continue
            agree(json_line(line), json_line(expected), where=f"line {k + 1}")


def csv_agree(ours, golden, header, where):
    """Two CSV lines agree: the same cells, numbers close in the LAPACK columns (their names)."""
    assert len(ours) == len(golden), where
    for column, a, b in zip(header, ours, golden):
        if a != b:
            assert column in LAPACK_KEYS and close(float(a), float(b)), f"{where}.{column}: {a} vs {b}"


@pytest.mark.parametrize(
    "change, golden",
    [
        # the last digit of a joint rate: within the tolerance
        (
            '"joint_rates":[[[0.06624605678233438,0.004731861198738165',
            '"joint_rates":[[[0.06624605678233438,0.004731861198738169',
        ),
        # a closed-form number, one bit off: never
        ('"x":[-7.870370370370357', '"x":[-7.870370370370358'),
    ],
)
def test_only_lapack_numbers_are_compared_to_a_tolerance(change, golden):
    line = next(line for line in (GOLDEN / "resolve.jsonl").read_text().split("\n") if golden in line)
    changed = line.replace(golden, change)
    if "joint_rates" in golden:
        agree(json_line(changed), json_line(line))
    else:
        with pytest.raises(AssertionError, match="x"):
            agree(json_line(changed), json_line(line))
