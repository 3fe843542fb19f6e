"""Object paths in grasp files and the ``follow`` command, end to end.

The bundled cylinder (the paper's Example 1) turns half a turn about the x
axis.  Its contacts' plane is z = 0 at the start and holds the x axis (contact
1 is on it, contacts 2 and 3 at z = 0), so after turning by ``t`` its normal is
``m(t) = R_x(t) e_z = (0, -sin t, cos t)`` and it still passes through the
origin.  The wrist ``c = (0, 0, 1)`` lies in it when ``m(t) . c = cos t = 0``:
at ``t = pi/2`` only, within ``[0, pi]``.  That is where the off-tangent method
must be degenerate, whatever the sampling.
"""

import csv
import io
import json
import math

import jsonschema
import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from grasptwist.cli import app
from grasptwist.io.grasp import grasp_schema, read_grasps
from grasptwist.output.follow_records import CSV_HEADER
from places import GRASPS

CYLINDER = GRASPS / "cylinder.yaml"
POLYHEDRON = GRASPS / "polyhedron.yaml"
CROSSING = math.pi / 2  # from the geometry (module docstring)
SAMPLE_KEYS = ["file", "grasp", "path", "segment", "t", "pose", "contacts", "twist"]
CONTACTS = """\
wrist: [0, 0, 1]
contacts:
  - {point: [1, 0, 0], normal: [-1, 0, 0]}
  - {point: [-0.5, 0.866, 0], normal: [0.5, -0.866, 0]}
  - {point: [-0.5, -0.866, 0], normal: [0.5, 0.866, 0]}
"""


def run(*args, input=None):
    return CliRunner().invoke(app, [str(a) for a in args], input=input)


def jsonl(text):
    return [json.loads(line) for line in text.splitlines()]


# --- grasp files ---------------------------------------------------------------------


def test_bundled_paths_are_read_with_their_frames_durations_and_targets():
    (cylinder,) = read_grasps(CYLINDER)
    (turn,) = cylinder.paths
    assert turn.name == "turn-x" and len(turn.segments) == 1
    assert turn.segments[0].twist.tolist() == [1, 0, 0, 0, 0, 0]
    assert turn.segments[0].duration == math.pi and turn.segments[0].frame == "space"
    (polyhedron,) = read_grasps(POLYHEDRON)
    lift, target = polyhedron.paths[0].segments
    assert lift.frame == "body" and lift.twist.tolist() == [0, 0, 0, 0, 0, 1]
    np.testing.assert_allclose(target.rotation, [[0, -1, 0], [1, 0, 0], [0, 0, 1]], atol=1e-15)
    assert target.position.tolist() == [0, 0, 0]


def test_a_pose_as_rotvec_quaternion_of_any_length_and_an_at_point():
    doc = CONTACTS + (
        "paths:\n"
        "  - segments:\n"
        "      - {pose: {rotvec: [0, 0, 1.5707963267948966]}, duration: 1}\n"
        "      - {pose: {rotation: [2, 0, 0, 2], position: [1, 2, 3]}, duration: 1}\n"
        "      - {angular: [0, 0, 1], at: [1, 0, 0], duration: 2}\n"
    )
    (grasp,) = read_grasps(doc.encode(), file="p.yaml")
    a, b, c = grasp.paths[0].segments
    np.testing.assert_allclose(a.rotation, b.rotation, atol=1e-15)
    assert grasp.paths[0].name == "1" and b.position.tolist() == [1, 2, 3]
    assert c.twist.tolist() == [0, 0, 1, 0, -1, 0]  # the origin's velocity: omega x (0 - at)


@pytest.mark.parametrize(
    "path_yaml, located",
    [
        (
            "  - {frame: world, segments: [{angular: [1, 0, 0], duration: 1}]}",
            "7:13: error: invalid-frame: paths[0].frame",
        ),
        (
            "  - {segments: [{angular: [1, 0, 0], duration: 0}]}",
            "7:48: error: invalid-duration: paths[0].segments[0].duration",
        ),
        ("  - {segments: [{angular: [1, 0, 0]}]}", "7:17: error: missing-key: paths[0].segments[0].duration"),
        ("  - {segments: [{duration: 1}]}", "7:17: error: missing-key: paths[0].segments[0]: needs a twist"),
        ("  - {segments: []}", "7:16: error: empty-path: paths[0].segments"),
        ("  - {segments: [{pose: {rotation: [0, 0, 0, 0]}, duration: 1}]}", "7:35: error: invalid-rotation"),
        ("  - {segments: [{pose: {rotation: [1, 0, 0]}, duration: 1}]}", "7:35: error: vector-length"),
        ("  - {segments: [{pose: {rotvec: [0, 0, 1], rotation: [1, 0, 0, 0]}, duration: 1}]}", "conflicting-keys"),
        ("  - {segments: [{pose: {}, linear: [1, 0, 0], duration: 1}]}", "7:36: error: conflicting-keys"),
        ("  - {segments: [{pose: {positon: [0, 0, 0]}, duration: 1}]}", "did you mean 'position'?"),
        ("  - {name: a, segments: [{linear: [1, 0, 0], duration: 1}]}\n  - {name: a, segments: []}", "duplicate-name"),
    ],
)
def test_bad_paths_are_located_coded_errors(tmp_path, path_yaml, located):
    bad = tmp_path / "bad.yaml"
    bad.write_text(CONTACTS + "paths:\n" + path_yaml + "\n")
    r = run("follow", bad, "-f", "jsonl")
    assert r.exit_code == 1
    assert located in r.stderr
    assert all(rec["ok"] is False and "error" in rec for rec in jsonl(r.stdout))


def test_the_schema_takes_the_bundled_paths_and_refuses_a_zero_duration():
    validator = jsonschema.Draft202012Validator(grasp_schema())
    doc = yaml.safe_load(CYLINDER.read_text())
    validator.validate(doc)
    doc["paths"][0]["segments"][0]["duration"] = 0
    assert not validator.is_valid(doc)


# --- the follow command -------------------------------------------------------------


@pytest.mark.parametrize("samples", [2, 3, 4, 10])
def test_the_cylinder_crossing_is_where_the_geometry_puts_it_whatever_the_sampling(samples):
    # 2 and 4 samples straddle pi/2, 3 samples hit it, 10 straddle it closely
    r = run("follow", CYLINDER, "--method", "off-tangent", "--samples", samples, "-f", "jsonl")
    assert r.exit_code == 1  # the path is degenerate somewhere
    *rows, summary = jsonl(r.stdout)
    assert len(rows) == samples
    (crossing,) = summary["summary"]["degenerate"]
    assert crossing["method"] == "off-tangent" and crossing["code"] == "wrist-coplanar"
    assert crossing["t_start"] == crossing["t_end"]
    assert abs(crossing["t_start"] - CROSSING) <= 1e-9 * math.pi
    assert summary["summary"]["min_conditioning"]["off_tangent"]["value"] < 1e-9
    assert summary["ok"] is False and summary["summary"]["samples"] == samples
    assert "the wrist crosses the contacts' plane at t = 1.570796" in r.stderr


def test_sample_records_have_the_issue_fields_and_resolve_method_fields():
    r = run("follow", CYLINDER, "--samples", 3, "-f", "json")
    *rows, summary = json.loads(r.stdout)
    assert [list(rec) for rec in rows] == [SAMPLE_KEYS + ["off_tangent", "tangent", "clearance", "warnings", "ok"]] * 3
    start, middle, end = rows
    assert [rec["t"] for rec in rows] == [0, math.pi / 2, math.pi]
    np.testing.assert_allclose(middle["pose"]["rotation"], [math.cos(math.pi / 4), math.sin(math.pi / 4), 0, 0])
    # contact 2 turned by a quarter turn about x: (x, y, 0) -> (x, 0, y)
    np.testing.assert_allclose(middle["contacts"][1]["point"], [-0.5, 0, 0.866], atol=1e-15)
    assert middle["twist"] == {"screw": [1, 0, 0, 0, 0, 0]}
    assert middle["off_tangent"]["error"]["code"] == "wrist-coplanar"
    assert start["tangent"]["error"]["code"] == "normals-rank-deficient"
    resolved = json.loads(run("resolve", CYLINDER, "--twist", "1,0,0,0,0,0", "--json").stdout)[0]
    assert start["off_tangent"] == resolved["off_tangent"] and start["tangent"] == resolved["tangent"]
    assert list(summary) == ["file", "grasp", "path", "summary", "warnings", "ok"]
    s = summary["summary"]
    assert list(s) == ["duration", "samples", "min_conditioning", "degenerate", "first_warning"]
    assert [(c["method"], c["code"], c["t_start"], c["t_end"]) for c in s["degenerate"]][0] == (
        "tangent",
        "normals-rank-deficient",
        0,
        math.pi,
    )
    assert s["first_warning"] == {"method": "tangent", "t": 0}


def test_the_polyhedron_reaches_its_pose_target_exactly_and_is_never_degenerate():
    r = run("follow", POLYHEDRON, "--samples", 7, "-f", "jsonl")
    assert r.exit_code == 0, r.stderr
    *rows, summary = jsonl(r.stdout)
    end = rows[-1]
    assert end["t"] == 3 and end["segment"] == 1
    np.testing.assert_allclose(end["pose"]["position"], [0, 0, 0], atol=1e-12)
    np.testing.assert_allclose(end["pose"]["rotation"], [math.sqrt(0.5), 0, 0, math.sqrt(0.5)], atol=1e-12)
    # the lift is in the body frame, which at t = 0 is the grasp frame: straight up by 1
    (lifted,) = [rec for rec in rows if rec["t"] == 1]
    np.testing.assert_allclose(lifted["pose"]["position"], [0, 0, 1], atol=1e-15)
    assert summary["summary"]["degenerate"] == [] and summary["ok"] is True
    assert all(rec["ok"] for rec in rows)


def test_a_path_on_the_command_line_matches_the_files_one():
    from_file = jsonl(run("follow", CYLINDER, "--method", "off-tangent", "--samples", 4, "-f", "jsonl").stdout)
    given = run(
        "follow", CYLINDER, "--method", "off-tangent", "--samples", 4, "-f", "jsonl",
        "--twist", "1,0,0,0,0,0", "--duration", 1, "--twist", "1,0,0,0,0,0", "--duration", math.pi - 1,
    )  # fmt: skip
    *rows, summary = jsonl(given.stdout)
    assert summary["path"] == "command-line" and summary["summary"]["duration"] == pytest.approx(math.pi)
    assert abs(summary["summary"]["degenerate"][0]["t_start"] - CROSSING) <= 1e-9 * math.pi
    for a, b in zip(rows, from_file[:-1]):
        np.testing.assert_allclose(a["pose"]["rotation"], b["pose"]["rotation"], atol=1e-15)


def test_body_and_space_frames_on_the_command_line_describe_the_same_motion():
    # a quarter turn about z, then a move along the object's own x axis (body), which after
    # the turn is the grasp frame's y axis (space)
    turn = ["--twist", "0,0,1,0,0,0", "--duration", math.pi / 2]
    body, space = (
        jsonl(run("follow", CYLINDER, *turn, "--twist", move, "--duration", 1, "--frame", frame, "-f", "jsonl").stdout)
        for move, frame in (("0,0,0,1,0,0", "body"), ("0,0,0,0,1,0", "space"))
    )
    for a, b in zip(body[:-1], space[:-1]):
        np.testing.assert_allclose(a["pose"]["position"], b["pose"]["position"], atol=1e-15)
        np.testing.assert_allclose(a["pose"]["rotation"], b["pose"]["rotation"], atol=1e-15)
        np.testing.assert_allclose(a["twist"]["screw"], b["twist"]["screw"], atol=1e-15)
    np.testing.assert_allclose(body[-2]["pose"]["position"], [0, 1, 0], atol=1e-15)


def test_the_table_shows_the_timeline_and_the_summary_in_words():
    r = run("follow", CYLINDER, "--method", "off-tangent", "--samples", 3)
    assert r.exit_code == 1
    lines = r.stdout.splitlines()
    assert lines[0] == "grasps/cylinder.yaml: grasp 'cylinder', path 'turn-x'" or lines[0].endswith(
        "cylinder.yaml: grasp 'cylinder', path 'turn-x'"
    )
    assert lines[1].split()[:4] == ["t", "seg", "position", "rotation"]
    assert lines[3].split()[:2] == ["1.5708", "0"] and "wrist-coplanar" in lines[3]
    assert "  the wrist crosses the contacts' plane at t = 1.5708 (off-tangent degenerate)" in lines
    assert "summary: duration 3.1416, 3 samples" in lines


def test_csv_and_npz_hold_the_samples_with_time_and_pose(tmp_path):
    r = run("follow", POLYHEDRON, "--samples", 5, "-f", "csv")
    assert r.exit_code == 0
    rows = list(csv.DictReader(io.StringIO(r.stdout)))
    assert r.stdout.encode().startswith(CSV_HEADER) and len(rows) == 5
    assert [float(row["t"]) for row in rows] == [0, 0.75, 1.5, 2.25, 3]
    assert rows[-1]["path"] == "lift-and-turn" and float(rows[-1]["rotation_z"]) == pytest.approx(math.sqrt(0.5))
    out = tmp_path / "f.npz"
    assert run("follow", POLYHEDRON, "--samples", 5, "-f", "npz", "-o", out).exit_code == 0
    with np.load(out) as z:
        assert z["t"].tolist() == [0, 0.75, 1.5, 2.25, 3]
        assert z["position"].shape == (5, 3) and z["rotation"].shape == (5, 4) and z["x"].shape == (5, 3)
        assert z["twist_names"].tolist() == ["lift-and-turn"]


@pytest.mark.parametrize(
    "args, hint",
    [
        (["--twist", "1,0,0,0,0,0"], "each --twist needs a --duration"),
        (["--twist", "1,0,0,0,0,0", "--duration", "-1"], "--duration number 1 must be a finite number > 0"),
        (["--samples", "3", "--dt", "0.1"], "give --samples or --dt, not both"),
        (["--dt", "0"], "must be a finite number > 0"),
        (["--frame", "body"], "applies to --twist segments"),
        (["--path", "x", "--twist", "1,0,0,0,0,0", "--duration", "1"], "--path picks one of the files' paths"),
    ],
)
def test_usage_errors_exit_2_before_any_work(args, hint):
    r = run("follow", CYLINDER, *args)
    assert r.exit_code == 2 and r.stdout == ""
    assert hint in " ".join(r.stderr.split())


def test_a_grasp_without_the_path_asked_for_is_a_located_error_and_the_others_still_run():
    r = run("follow", GRASPS, "--path", "turn-x", "--method", "off-tangent", "--dt", "0.5", "-f", "jsonl")
    assert r.exit_code == 1
    recs = jsonl(r.stdout)
    assert [rec["t"] for rec in recs if "t" in rec] == [0, 0.5, 1, 1.5, 2, 2.5, 3, math.pi]
    said = "polyhedron.yaml:17:1: error: no-path: grasp 'polyhedron' has no path named 'turn-x' (its paths: 'lift-and-turn')"
    assert said in " ".join(r.stderr.split())


def test_without_a_wrist_off_tangent_is_null_and_a_constant_failure_names_the_contacts(tmp_path):
    contacts = (
        "contacts:\n"
        "  - {name: a, point: [0, 0, 0], normal: [1, 0, 0]}\n"
        "  - {name: b, point: [1, 0, 0], normal: [0, 1, 0]}\n"
        "  - {name: c, point: [1, 0, 0], normal: [0, 0, 1]}\n"
        "paths:\n"
        "  - segments: [{angular: [0, 0, 1], duration: 2}]\n"
    )
    (tmp_path / "g.yaml").write_text(contacts)
    r = run("follow", tmp_path / "g.yaml", "--samples", 2, "-f", "jsonl")
    first, _, summary = jsonl(r.stdout)
    assert first["off_tangent"] is None and first["tangent"]["error"]["code"] == "coincident-contacts"
    s = summary["summary"]
    assert s["min_conditioning"]["off_tangent"] is None
    assert s["degenerate"] == [
        {"method": "tangent", "code": "coincident-contacts", "t_start": 0, "t_end": 2, "culprit": "a"}
    ]
    assert "tangent: coincident-contacts: from t = 0.000000 to t = 2.000000: contacts b and c coincide" in r.stderr


def test_o_follows_the_resolve_rule_and_a_data_set_is_refused_without_costing_the_others(tmp_path):
    r = run("follow", CYLINDER, "-o", tmp_path / "missing" / "out.jsonl")
    assert r.exit_code == 2 and "no folder" in r.stderr
    np.savez(tmp_path / "d.npz", points=np.zeros((1, 3, 3)), normals=np.ones((1, 3, 3)))
    out = tmp_path / "out.jsonl"
    r = run("follow", tmp_path / "d.npz", POLYHEDRON, "--samples", 2, "-f", "jsonl", "-o", out)
    assert r.exit_code == 1 and r.stdout == ""
    refused, *rows, summary = jsonl(out.read_text())
    assert refused["error"]["code"] == "read-error" and "not data sets" in refused["error"]["message"]
    assert len(rows) == 2 and summary["ok"] is True


def test_the_table_escapes_a_file_name_that_would_drive_the_terminal(tmp_path):
    name = tmp_path / "cyl\x1b[31m.yaml"  # a file name is whatever whoever filled the folder chose
    name.write_bytes(CYLINDER.read_bytes())
    out = run("follow", name, "--samples", 2, "--method", "off-tangent").stdout
    assert "\x1b" not in out and f"{tmp_path}/cyl\\x1b[31m.yaml: grasp 'cylinder', path 'turn-x'" in out


# issue 26: rotvec [0, 0, 90] (degrees, surely) turned the object 116.6 degrees without a word
DEGREES = """\
name: turned
wrist: [0, 0, 1]
contacts:
  - {point: [1, 0, 0], normal: [-1, 0, 0.3]}
  - {point: [-0.5, 0.866, 0], normal: [0.5, -0.866, 0.2]}
  - {point: [-0.5, -0.866, 0], normal: [0.5, 0.866, 0.1]}
paths:
  - name: turn
    segments:
      - pose: {rotvec: [0, 0, 90]}
        duration: 1
      - pose: {rotvec: [0, 0, 3.141592653589793]}
        duration: 1
      - pose: {position: [0, 0, 0.5], rotvec: [3, 2, 0]}
        duration: 1
      - pose: {rotation: [0, 0, 0, 1]}
        duration: 1
"""


def test_a_rotation_vector_over_pi_is_a_warning_naming_the_value_and_its_place(tmp_path):
    path = tmp_path / "turned.yaml"
    path.write_text(DEGREES)
    r = run("follow", path, "--samples", 2, "--method", "tangent", "-f", "jsonl")
    assert r.exit_code == 0, r.output
    summary = json.loads(r.stdout.splitlines()[-1])
    assert summary["ok"] and summary["warnings"] == [
        "rotation-over-pi: rotation of 90 (rotvec [0, 0, 90], line 10, column 24) is over pi: "
        "rotations are in radians (this one is a turn of 116.6 degrees)",
        "rotation-over-pi: rotation of 3.60555 (rotvec [3, 2, 0], line 14, column 47) is over pi: "
        "rotations are in radians (this one is a turn of 153.4 degrees)",
    ]  # a half turn (pi) and a quaternion are not
    assert r.stderr.splitlines()[:2] == [
        f"{path}: grasp 'turned', path 'turn': warning: {w}" for w in summary["warnings"]
    ]
    # a path without one has none
    summary = json.loads(run("follow", POLYHEDRON, "--samples", 2, "-f", "jsonl").stdout.splitlines()[-1])
    assert summary["warnings"] == []
