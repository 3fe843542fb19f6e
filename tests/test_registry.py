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
from pathlib import Path

import numpy as np
import pytest

import grasptwist as gt

ROOT = Path(__file__).resolve().parents[1]

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

import grasptwist.output.table as T


class SpeedTable:
    skipped = "never"

    @staticmethod
    def contact_columns(m, d):
        return [("speed", [T.fmt_number(v, d) for v in m["speed"]])]

    @staticmethod
    def resolve(m, names, d):
        return "speeds shown with the contacts"

    @staticmethod
    def verdict(m, names):
        return ["speed: fastest finger " + names[max(range(3), key=m["speed"].__getitem__)]]

    @staticmethod
    def basis(m, names, d):
        return ["speed: no basis"]


T.SpeedTable = SpeedTable
from grasptwist.cli import main

sys.argv = ["grasptwist"] + sys.argv[1:]
main()
"""


def grasptwist(*args, tmp=None):
    done = subprocess.run(
        [sys.executable, "-c", SETUP, *map(str, args)], cwd=ROOT, capture_output=True, text=tmp is None, timeout=60
    )
    assert done.returncode == 0, done.stderr
    return done.stdout


@pytest.fixture(scope="module")
def expected():
    """The speeds of the polyhedron's diagonal spin, from the engine."""
    points = np.array([[0, 2, 2], [2, 0, 2], [2, 2, 0.0]])
    twist = np.array([0.5773502691896258] * 3 + [0, 0, 0])
    return np.linalg.norm(gt.contact_velocities(points, twist), axis=-1)


def test_a_new_kind_is_in_records_csv_and_npz(expected, tmp_path):
    g = "grasps/polyhedron.yaml"
    [rec] = map(json.loads, grasptwist("resolve", g, "--method", "speed", "-f", "jsonl").splitlines())
    assert "off_tangent" not in rec and "tangent" not in rec and rec["ok"] is True
    assert rec["speed"] == {"speed": expected.tolist(), "conditioning": 1.0}
    both = json.loads(grasptwist("resolve", g, "-f", "json"))[0]
    assert list(both)[-5:] == ["off_tangent", "tangent", "speed", "warnings", "ok"]
    [row] = csv.DictReader(io.StringIO(grasptwist("resolve", g, "-f", "csv")))
    assert [float(row[f"speed{i}"]) for i in (1, 2, 3)] == expected.tolist() and row["speed_error"] == ""
    assert list(row)[-5:] == ["tangent_error", "speed1", "speed2", "speed3", "speed_error"]
    grasptwist("resolve", g, "-f", "npz", "-o", tmp_path / "out.npz")
    z = np.load(tmp_path / "out.npz")
    np.testing.assert_array_equal(z["speed"], [expected])
    assert z["speed_status"].tolist() == [0] and "x" in z.files


def test_a_new_kind_is_in_tables_basis_and_check():
    g = "grasps/polyhedron.yaml"
    table = grasptwist("resolve", g, "--method", "speed", "--digits", "3")
    assert "speeds shown with the contacts" in table and "speed: fastest finger" in table and "1.633" in table
    basis = json.loads(grasptwist("basis", g, "--json"))[0]
    assert basis["speed"] == {"conditioning": 1.0} and "speed: no basis" in grasptwist("basis", g)
    check = json.loads(grasptwist("check", g, "--json"))[0]
    assert check["speed"] == {"conditioning": 1.0}
