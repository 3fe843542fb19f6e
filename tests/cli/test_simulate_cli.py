"""``grasptwist simulate`` (issue 38): records in every format, the scene written for MuJoCo's viewer,
inputs it cannot simulate, options it refuses, and MuJoCo missing."""

import csv
import io
import json
import subprocess
import sys

import numpy as np
import pytest

from grasptwist.output.simulate_records import SIMULATE_COLUMNS, csv_line
from hostile import jsonl, run
from places import GRASPS

CUBE = GRASPS / "trifinger-cube.yaml"
SPHERE = GRASPS / "sphere.yaml"
SHORT = ("--duration", "0.1")


def test_records_say_held_and_per_direction_how_far_the_object_moved_and_the_forces():
    r, _ = run("simulate", CUBE, "--mass", "0.094", "--friction", "1", "--table", "0", *SHORT, "-f", "jsonl")
    assert r.exit_code == 0, r.stderr
    (rec,) = jsonl(r.stdout)
    assert rec["ok"] and rec["held"] and rec["load"] == pytest.approx(0.094 * 9.81)
    assert rec["tolerance"] == {"distance": 0.002, "angle_deg": 2.0} and rec["safety"] == 1.25
    assert [d["direction"] for d in rec["directions"]] == ["+x", "-x", "+y", "-y", "+z", "-z"]
    for d in rec["directions"]:
        assert d["held"] and d["simulated"] and d["grip"] == "ok" and d["displacement"] < 5e-4
        assert len(d["contact_forces"]) == 3 and len(d["planned_forces"][0]) == 3


def test_a_grasp_without_a_grip_does_not_hold_and_says_so_on_stderr():
    r, _ = run("simulate", CUBE, "--mass", "0.094", "--friction", "0.5", *SHORT, "-f", "json")
    assert r.exit_code == 1
    (rec,) = json.loads(r.stdout)
    assert not rec["ok"] and not rec["held"]
    assert {(d["simulated"], d["grip"], d["displacement"]) for d in rec["directions"]} == {(False, "cannot-hold", None)}
    assert "no grip holds the load along +x, -x, +y, -y, +z, -z: not simulated there" in r.stderr
    # simulate's own words in the closing line (its Command's), not "with a degenerate method"
    assert r.stderr.splitlines()[-1] == "1 record: 1 not held, 0 inputs failed"
    # the table: each direction's row in its columns, what was not simulated said across the rest
    table, _ = run("simulate", CUBE, "--mass", "0.094", "--friction", "0.5", *SHORT)
    rows = table.stdout.splitlines()[2:]
    assert rows == [f"  {d:<9}  no    not simulated (grip: cannot-hold)" for d in ("+x", "-x", "+y", "-y", "+z", "-z")]


def test_csv_and_the_table(tmp_path):
    from grasptwist.output.simulate_records import SimulateTable

    # one simulation, its record in both (the command line's -f csv and table: the --mjcf test and the
    # grip test below)
    r, _ = run("simulate", CUBE, "--mass", "0.094", "--friction", "1", *SHORT, "-f", "jsonl")
    assert r.exit_code == 0, r.stderr
    (rec,) = jsonl(r.stdout)
    (row,) = csv.DictReader(io.StringIO((SIMULATE_COLUMNS.header() + csv_line(rec)).decode()))
    assert row["held"] == "true" and row["held_mz"] == "true" and float(row["displacement_px"]) < 5e-4
    out = io.BytesIO()
    SimulateTable(out).write(rec)
    table = out.getvalue().decode()
    assert "grasp 'trifinger-cube': held" in table and table.count(" yes ") == 6


def test_mjcf_writes_the_scene_mujoco_reads_back(tmp_path):
    mujoco = pytest.importorskip("mujoco")
    out = tmp_path / "scene.xml"
    # the handle has no object (no scene): the sphere's two grasps' scenes are scene.xml and scene-2.xml
    inputs = (GRASPS / "handle.yaml", SPHERE)
    r, _ = run("simulate", *inputs, "--mass", "0.1", "--friction", "0.8", *SHORT, "--mjcf", out, "-f", "jsonl")
    assert r.exit_code == 1, r.stderr
    records = jsonl(r.stdout)
    assert [rec["scene"] for rec in records] == [None, str(out), str(tmp_path / "scene-2.xml")]
    assert sorted(p.name for p in tmp_path.glob("*.xml")) == ["scene-2.xml", "scene.xml"]
    for rec in records[1:]:  # one file per grasp: sphere-tripod, sphere-equator
        model = mujoco.MjModel.from_xml_path(rec["scene"])
        assert model.body("object").id > 0 and model.ngeom == 4  # the ball, its three tips, no table
        assert model.names.decode().split("\0")[0] == rec["grasp"]  # the scene's model is its grasp
    # and in CSV, the last column
    r, _ = run("simulate", *inputs, "--mass", "0.1", "--friction", "0.8", *SHORT, "--mjcf", out, "-f", "csv")
    assert [row["scene"] for row in csv.DictReader(io.StringIO(r.stdout))] == [
        "",
        str(out),
        str(tmp_path / "scene-2.xml"),
    ]


@pytest.mark.parametrize(
    ("args", "code"),
    [
        (("--friction", "1"), "no-mass"),
        (("--mass", "1"), "no-friction"),
    ],
)
def test_a_grasp_it_cannot_simulate_is_an_error_record(args, code):
    r, _ = run("simulate", CUBE, *args, *SHORT, "-f", "jsonl")
    assert r.exit_code == 1
    (rec,) = jsonl(r.stdout)
    assert rec["error"]["code"] == code and rec["error"]["line"] == 17
    assert rec["grasp"] == "trifinger-cube" and rec["scene"] is None  # read: its name, as stderr says it
    assert f"trifinger-cube.yaml:17: error: {code}: grasp 'trifinger-cube'" in r.stderr
    # read but not simulated, by code: not "0 not held, 1 input failed"
    assert r.stderr.splitlines()[-1] == f"1 record: 0 not held, 1 not simulated (1 {code}), 0 inputs failed"
    (row,) = csv.DictReader(io.StringIO((SIMULATE_COLUMNS.header() + csv_line(rec)).decode()))
    assert row["grasp"] == "trifinger-cube" and row["error"].startswith(f"{code}: ")


def test_a_grasp_without_an_object_is_an_error_record(tmp_path):
    bare = tmp_path / "bare.yaml"
    bare.write_text(
        "contacts:\n  - {point: [1, 0, 0], normal: [-1, 0, 0]}\n  - {point: [-1, 0, 0], normal: [1, 0, 0]}\n"
        "  - {point: [0, 1, 0], normal: [0, -1, 0]}\nfriction: 0.5\nmass: 1\ncenter_of_mass: [0, 0, 0]\n"
    )
    r, _ = run("simulate", bare, tmp_path / "missing.yaml", "-f", "jsonl")
    assert r.exit_code == 1 and jsonl(r.stdout)[0]["error"]["code"] == "no-object"
    # a grasp read but not simulated, and an input that could not be read (no grasp to name)
    assert jsonl(r.stdout)[0]["grasp"] == "bare" and "grasp" not in jsonl(r.stdout)[1]
    assert r.stderr.splitlines()[-1] == "2 records: 0 not held, 1 not simulated (1 no-object), 1 input failed"


@pytest.mark.parametrize(
    "args",
    [
        ("--duration", "0"),
        ("--duration", "nan"),
        ("--duration", "1e9"),
        ("--duration", "1e-9"),  # under one step: every grasp "held"
        ("--duration", "0.049"),  # under 50 steps
        ("--tolerance", "0.002"),
        ("--tolerance", "0,2"),
        ("--tolerance", "0.002,200"),
        ("--tolerance", "1e6,179"),
        ("--tolerance", "0.002,45.5"),
        ("--tolerance", "inf,2"),
        ("--mass", "-1"),
        ("--table", "inf"),
        ("--mjcf", "no-such-folder/scene.xml"),
    ],
)
def test_absurd_values_are_refused_before_any_work(args):
    r, _ = run("simulate", CUBE, *args)
    assert r.exit_code == 2 and args[0] in r.stderr


def test_the_bounds_are_said_and_met_at_their_edges():
    r, _ = run("simulate", CUBE, "--duration", "1e-9")
    assert "must be at least 0.05 s (50 time steps) and at most 600 s, got 1e-09" in r.stderr
    r, _ = run("simulate", CUBE, "--tolerance", "0.002,46")
    assert "the angle must be in degrees, > 0 and at most 45, got 46" in r.stderr
    # at the edges: 0.05 s and 45 degrees are run
    r, _ = run("simulate", CUBE, "--mass", "0.094", "--friction", "1", "--duration", "0.05", "--tolerance", "0.002,45")
    assert r.exit_code == 0, r.stderr


def test_a_distance_tolerance_as_large_as_the_object_is_an_error_record():
    # the cube's size (its bounding box's diagonal) is 0.065 sqrt(3) = 0.113: 1e6 is refused for it,
    # where before it reported held for a cube that moved 4.8 m
    r, _ = run("simulate", CUBE, "--mass", "0.094", "--friction", "1", *SHORT, "--tolerance", "1e6,2", "-f", "jsonl")
    assert r.exit_code == 1
    (rec,) = jsonl(r.stdout)
    assert rec["error"]["code"] == "tolerance-too-large"
    assert "the distance tolerance 1e+06 is not less than the object's size 0.113" in rec["error"]["message"]
    ok, _ = run("simulate", CUBE, "--mass", "0.094", "--friction", "1", *SHORT, "--tolerance", "0.11,2", "-f", "jsonl")
    assert ok.exit_code == 0, ok.stderr


def test_without_mujoco_one_line_says_how_to_install_it():
    code = (
        "import sys; sys.modules['mujoco'] = None\n"
        "from typer.testing import CliRunner; from grasptwist.cli import app\n"
        f"r = CliRunner().invoke(app, ['simulate', {str(CUBE)!r}])\n"
        "print(r.exit_code); print(r.stderr, end='')\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    status, line = out.stdout.splitlines()
    assert status == "2"
    assert line == (
        "grasptwist: error: grasptwist simulate needs mujoco: pip install 'grasptwist[sim]' "
        "(from a clone of grasptwist: pip install -e '.[sim]')"
    )


@pytest.mark.slow  # a search and four hold tests: over a second
def test_synthesize_simulate_keeps_only_the_grasps_that_hold_and_counts_the_others(tmp_path):
    found = tmp_path / "found.yaml"
    args = ("synthesize", GRASPS / "cylinder.yaml", "--friction", "0.8", "--mass", "0.1", "-n", "4")
    r, _ = run(*args, "--candidates", "400", "--simulate", "-o", found, "-f", "jsonl")
    assert r.exit_code in (0, 1), r.stderr
    kept = [rec for rec in jsonl(r.stdout) if rec["ok"]]
    # the search finds 4 (seeded), each with a grip for the six loads of the hold test beside the weight (the
    # default, --loads six);
    # MuJoCo drops those that do not hold, and stderr counts them (measured: none is dropped; before the
    # search asked for the six loads and the hold test squeezed, 1 to 3 were)
    dropped = 4 - len(kept)
    assert dropped == 0
    assert "4 grasps from 400 candidates" in r.stderr  # all wanted found: no spacing hint
    assert "; 0 dropped: they did not hold in all six directions in MuJoCo (--simulate)" in r.stderr
    for rec in kept:
        loads = ["hold"] + [f"load {d}" for d in ("+x", "-x", "+y", "-y", "+z")]
        assert list(rec["scores"]["total_normal_force"]) == loads
    for rec in kept:  # each record says how it held
        sim = rec["simulation"]
        assert sim["held"] and [d["direction"] for d in sim["directions"]] == ["+x", "-x", "+y", "-y", "+z", "-z"]
        assert all(d["held"] and d["displacement"] < 0.002 and d["rotation_deg"] < 2 for d in sim["directions"])
    plain, _ = run(*args, "--candidates", "400", "-f", "jsonl")  # without --simulate: null
    assert {rec["simulation"] for rec in jsonl(plain.stdout)} == {None}
    # --simulate changes nothing in the search (the six loads are the default, --loads six): the same grasps
    assert [r["contacts"] for r in jsonl(plain.stdout)] == [r["contacts"] for r in kept]
    sims, _ = run("simulate", found, *SHORT, "-f", "jsonl")  # each grasp kept holds, simulated from the file
    assert [s["held"] for s in jsonl(sims.stdout)] == [True] * len(kept)


def test_path_lifts_the_ball_as_planned_and_the_record_has_its_samples():
    # lift-z: 5 cm/s for one unit of time, the three slid tips carrying the ball (no turning: no rolling)
    r, _ = run("simulate", SPHERE, "--mass", "0.1", "--friction", "0.8", "--path", "lift-z", "-f", "jsonl")
    assert r.exit_code == 0, r.stderr
    rec = jsonl(r.stdout)[1]  # sphere-equator
    assert rec["followed"] and rec["path"] == "lift-z" and len(rec["samples"]) == 21
    assert rec["samples"][-1]["time"] == 1.0 and rec["final"]["position_error"] < 5e-4
    assert max(max(s["slip"]) for s in rec["samples"]) < 1e-3 and not any(any(s["slipped"]) for s in rec["samples"])


def test_a_path_the_grasp_does_not_have_is_an_error_record():
    r, _ = run("simulate", SPHERE, "--mass", "0.1", "--friction", "0.8", "--path", "nope", "-f", "jsonl")
    assert r.exit_code == 1
    rec = jsonl(r.stdout)[0]
    assert rec["error"]["code"] == "no-path" and "'roll-x', 'spin-z', 'lift-z'" in rec["error"]["message"]
    csv_run, _ = run("simulate", SPHERE, "--path", "lift-z", "-f", "csv")
    assert csv_run.exit_code == 2 and "--path" in csv_run.stderr


@pytest.mark.slow  # a second of tracking with the TriFinger
def test_the_trifinger_spins_the_cube_as_planned_as_the_guide_says():
    r, _ = run("simulate", CUBE, "--mass", "0.094", "--friction", "1", "--path", "spin", "-f", "jsonl")
    assert r.exit_code == 0, r.stderr
    (rec,) = jsonl(r.stdout)
    assert rec["followed"] and rec["final"]["angle_error_deg"] < 2  # measured 0.4 deg (9 before it rolled)
    assert not any(rec["samples"][-1]["slipped"])


@pytest.mark.slow  # two worker processes: a second
def test_workers_simulate_a_folder_file_by_file_with_the_same_records(tmp_path):
    for name in ("sphere.yaml", "cylinder.yaml"):
        (tmp_path / name).write_bytes((GRASPS / name).read_bytes())
    args = ("simulate", tmp_path, "--mass", "0.1", "--friction", "0.8", *SHORT, "-f", "jsonl")
    one, _ = run(*args)
    two, _ = run(*args, "-j", "2")
    assert one.exit_code == two.exit_code and one.stdout == two.stdout
    assert [(r["grasp"], r["held"]) for r in jsonl(two.stdout)] == [
        ("cylinder", True),
        ("sphere-tripod", True),
        ("sphere-equator", True),
    ]


def test_mujoco_reads_the_trifinger_from_its_urdf_and_the_scene_is_written_beside_its_meshes(tmp_path):
    mujoco = pytest.importorskip("mujoco")
    out = tmp_path / "cube.xml"
    r, _ = run("simulate", CUBE, "--mass", "0.094", "--friction", "1", *SHORT, "--mjcf", out, "-f", "jsonl")
    assert r.exit_code == 0, r.stderr
    assert {p.name for p in tmp_path.iterdir()} >= {"cube.xml", "tip_sim.stl", "prox-sim.stl"}
    model = mujoco.MjModel.from_xml_path(str(out))
    joints = [model.joint(k).name for k in range(model.njnt)]
    assert joints[1:4] == [f"hand/finger_{j}_joint_0" for j in ("base_to_upper", "upper_to_middle", "middle_to_lower")]
    np.testing.assert_allclose(model.jnt_range[model.joint("hand/finger_upper_to_middle_joint_0").id], [0, 1.57])
    # the URDF's own link masses; only the object, the file's table, the fingertip spheres (10 mm) collide
    assert model.body_mass[model.body("hand/finger_upper_link_0").id] == pytest.approx(0.26689)  # the URDF says
    colliding = sorted(model.geom(k).name for k in range(model.ngeom) if model.geom_contype[k])
    assert (
        colliding == ["piece0", "table", "tip0", "tip1", "tip2"] and model.geom_size[model.geom("tip0").id][0] == 0.01
    )
