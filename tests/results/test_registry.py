"""A third result kind, added to the registry alone, reaches every output.

The kind (each contact's speed ``|T(p_i)|``) and its table renderer are
defined in a fresh interpreter before the output modules are imported, as
an entry in ``grasptwist/results.py`` and a class in ``output/table.py``
would be; nothing else changes.
"""

import csv
import io
import json
import subprocess
import sys

import numpy as np
import pytest

import grasptwist as gt
from places import ROOT

SETUP = """
import sys
from dataclasses import dataclass, fields

import numpy as np

import grasptwist.results as R
from grasptwist.engine.decompose import contact_velocities


@dataclass(frozen=True)
class SpeedResult:
    speed: np.ndarray
    status: np.ndarray
    culprit: np.ndarray
    conditioning: np.ndarray

    @property
    def ok(self):
        return self.status == 0

    def row(self, i):
        return SpeedResult(**{f.name: getattr(self, f.name)[i] for f in fields(self)})


def compute(inputs, bases):
    speed = np.linalg.norm(contact_velocities(inputs["points"], inputs["twist"]), axis=-1)
    n = len(speed)
    return SpeedResult(speed, np.zeros(n, np.int8), np.full(n, -1, np.int8), np.ones(n))


SPEED = R.ResultKind(
    key="speed",
    label="speed",
    compute=compute,
    applies=lambda block: np.ones(len(block), bool),
    fields=(R.Field("speed"), R.CONDITIONING),
    basis_fields=(R.CONDITIONING,),
    check_fields=(R.CONDITIONING,),
    columns=(R.Column("speed", lambda r, block: r.speed, ("speed1", "speed2", "speed3")),),
    table="SpeedTable",
)
R.KINDS += (SPEED,)
R.BY_KEY["speed"] = SPEED
R.METHOD_CHOICES += ("speed",)

import grasptwist.output.numbers as N
import grasptwist.output.table as T


class SpeedTable:
    skipped = "never"

    @staticmethod
    def contact_columns(m, d):
        return [("speed", [N.fmt_number(v, d) for v in m["speed"]])]

    @staticmethod
    def resolve(m, names, d, rec):
        return "speeds shown with the contacts"

    @staticmethod
    def verdict(m, names):
        return ["speed: fastest finger " + names[max(range(3), key=m["speed"].__getitem__)]]

    @staticmethod
    def basis(m, names, d):
        return ["speed: no basis"]


T.SpeedTable = SpeedTable

import json
from typer.testing import CliRunner
from grasptwist.cli import app

runs = [CliRunner().invoke(app, args) for args in json.loads(sys.argv[1])]
print(json.dumps([(r.exit_code, r.stdout, r.stderr) for r in runs]))
"""

POLY = "grasps/polyhedron.yaml"
COMMANDS = {
    "jsonl": ["resolve", POLY, "--method", "speed", "-f", "jsonl"],
    "json": ["resolve", POLY, "-f", "json"],
    "csv": ["resolve", POLY, "-f", "csv"],
    "npz": ["resolve", POLY, "-f", "npz", "-o", "{tmp}/out.npz"],
    "table": ["resolve", POLY, "--method", "speed", "--digits", "3"],
    "basis": ["basis", POLY, "--json"],
    "basis table": ["basis", POLY],
    "check": ["check", POLY, "--json"],
}


@pytest.fixture(scope="module")
def out(tmp_path_factory):
    """Each command's stdout, run in one fresh interpreter with the kind registered."""
    tmp = tmp_path_factory.mktemp("registry")
    commands = [[a.format(tmp=tmp) for a in args] for args in COMMANDS.values()]
    done = subprocess.run(
        [sys.executable, "-c", SETUP, json.dumps(commands)], cwd=ROOT, capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 0, done.stderr
    runs = json.loads(done.stdout)
    assert all(code == 0 for code, _, _ in runs), runs
    return {name: stdout for name, (_, stdout, _) in zip(COMMANDS, runs)} | {"tmp": tmp}


@pytest.fixture(scope="module")
def expected():
    """The speeds of the polyhedron's diagonal spin, from the engine."""
    points = np.array([[0, 2, 2], [2, 0, 2], [2, 2, 0.0]])
    twist = np.array([0.5773502691896258] * 3 + [0, 0, 0])
    return np.linalg.norm(gt.contact_velocities(points, twist), axis=-1)


def test_a_new_kind_is_in_records_csv_and_npz(expected, out):
    [rec] = map(json.loads, out["jsonl"].splitlines())
    assert "off_tangent" not in rec and "tangent" not in rec and rec["ok"] is True
    assert rec["speed"] == {"speed": expected.tolist(), "conditioning": 1.0}
    both = json.loads(out["json"])[0]
    assert list(both)[-5:] == ["off_tangent", "tangent", "speed", "warnings", "ok"]
    [row] = csv.DictReader(io.StringIO(out["csv"]))
    assert [float(row[f"speed{i}"]) for i in (1, 2, 3)] == expected.tolist() and row["speed_error"] == ""
    assert list(row)[-5:] == ["tangent_error", "speed1", "speed2", "speed3", "speed_error"]
    z = np.load(out["tmp"] / "out.npz")
    np.testing.assert_array_equal(z["speed"], [expected])
    assert z["speed_status"].tolist() == [0] and "x" in z.files


def test_a_new_kind_is_in_tables_basis_and_check(out):
    table = out["table"]
    assert "speeds shown with the contacts" in table and "speed: fastest finger" in table and "1.633" in table
    assert json.loads(out["basis"])[0]["speed"] == {"conditioning": 1.0} and "speed: no basis" in out["basis table"]
    assert json.loads(out["check"])[0]["speed"] == {"conditioning": 1.0}
