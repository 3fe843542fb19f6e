"""Absurd finite numbers (1e308 twists, 1e300 coordinates, paths turning 1e308 radians): every
command gives statuses and located errors, never NaN in an ok record, never a numpy warning.

Each run is in process with numpy's RuntimeWarnings raised as errors (``-W
error::RuntimeWarning``), so a warning that would reach stderr fails the run with an internal
error instead of passing unseen.
"""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from grasptwist.cli import app
from grasptwist.cli.exits import EXIT_FAILED, EXIT_OK, EXIT_USAGE
from grasptwist.engine.degeneracy import Status
from grasptwist.path import Segment, degeneracies, follow
from hostile import run_installed
from places import ROOT

POLY = str(ROOT / "grasps" / "polyhedron.yaml")
HAND = str(ROOT / "grasps" / "three-finger-hand.yaml")
SPHERE = str(ROOT / "grasps" / "sphere.yaml")
POSE = Status.NONFINITE_POSE.code

#: The parts of a record that hold numbers: an ok record has no null in any of them.
NUMBERS = ("pose", "contacts", "off_tangent", "tangent", "hand", "grip", "manipulating")

HUGE = """\
name: huge
wrist: [1e300, -1e300, 1e300]
mass: 1e300
center_of_mass: [0, 0, 0]
friction: 0.5
contacts:
  - {point: [0, 1e300, 1e300], normal: [1e300, 0, 0]}
  - {point: [1e300, 0, 1e300], normal: [0, 1e300, 0]}
  - {point: [1e300, 1e300, 0], normal: [0, 0, 1e300]}
twists:
  - {name: big, angular: [1e308, 1e308, 1e308], linear: [1e308, -1e308, 1e308]}
paths:
  - name: spin
    segments:
      - {angular: [0, 0, 1e308], duration: 1}
      - {linear: [1e308, 0, 0], duration: 1e300}
"""


def run(*args):
    """``grasptwist ARGS -f jsonl`` in process, numpy's RuntimeWarnings raised: (exit, records, stderr lines)."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        r = CliRunner().invoke(app, [*map(str, args), "-f", "jsonl"])
    assert "RuntimeWarning" not in r.stderr and "internal error" not in r.stderr, r.stderr
    records = [json.loads(line) for line in r.stdout.splitlines()]
    for rec in records:
        if rec.get("ok"):
            assert None not in _leaves([rec[k] for k in NUMBERS if rec.get(k) is not None]), rec
    return r.exit_code, records, r.stderr.splitlines()


def _leaves(value):
    if isinstance(value, dict):
        return [x for v in value.values() for x in _leaves(v)]
    if isinstance(value, list):
        return [x for v in value for x in _leaves(v)]
    return [value]


def codes(rec):
    """The error codes of a sample's methods, by method."""
    return {k: rec[k]["error"]["code"] for k in ("off_tangent", "tangent", "hand") if "error" in rec.get(k, {})}


def test_a_twist_of_1e308_overflows_the_pose_and_every_part_says_so():
    code, records, stderr = run("follow", POLY, "--twist", "0,0,1e308,0,0,0", "--duration", "1")
    *samples, summary = records
    assert code == EXIT_FAILED
    # at t = 0 the pose is the identity: the twist itself overflows the amplitudes
    assert codes(samples[0]) == {"off_tangent": "overflow", "tangent": "overflow"}
    assert all(codes(s) == {"off_tangent": POSE, "tangent": POSE} for s in samples[1:])
    assert all(s["pose"]["position"] == [None] * 3 for s in samples[1:])
    stretches = summary["summary"]["degenerate"]
    assert sorted((s["method"], s["code"], s["t_end"]) for s in stretches) == [
        ("off-tangent", POSE, 1.0),
        ("tangent", POSE, 1.0),
    ]
    # the turn exceeds 1e154 radians after 1e-154: the start is located to 1e-10 of the segment
    assert all(0 < s["t_start"] <= 1e-10 for s in stretches)
    assert summary["ok"] is False
    assert sum(f"error: off-tangent: {POSE}: from t = 0.000000 to t = 1.000000" in line for line in stderr) == 1
    assert not any("wrist-coplanar" in line for line in stderr)


def test_a_huge_duration_overflows_the_pose_only_where_the_turn_does():
    code, records, _ = run("follow", POLY, "--twist", "0,0,1,0,0,0", "--duration", "1e308", "--samples", "3")
    *samples, summary = records
    assert code == EXIT_FAILED
    assert [codes(s) for s in samples] == [
        {},
        {"off_tangent": POSE, "tangent": POSE},
        {"off_tangent": POSE, "tangent": POSE},
    ]
    assert samples[0]["ok"] is True
    (start,) = {s["t_start"] for s in summary["summary"]["degenerate"]}
    assert {s["code"] for s in summary["summary"]["degenerate"]} == {POSE}
    assert 1.3e154 <= start <= 1e-10 * 1e308  # the turn's square passes 1.8e308 at t = 1.34e154


def test_a_huge_duration_of_no_motion_is_all_ok():
    code, records, _ = run("follow", POLY, "--twist", "0,0,0,0,0,0", "--duration", "1e308")
    assert code == EXIT_OK
    assert all(r["ok"] for r in records) and len(records) == 22
    assert records[-1]["summary"]["degenerate"] == []


def test_a_grip_along_the_path_says_nonfinite_pose_where_the_methods_do():
    code, records, _ = run("follow", SPHERE, "--twist", "0,0,1e308,0,0,0", "--duration", "1", "--samples", "3")
    held = [r for r in records if r.get("grasp") == "sphere-equator" and "grip" in r]  # it has mass and friction
    assert code == EXIT_FAILED and len(held) == 3
    assert "error" not in held[0]["grip"]
    assert [r["grip"]["error"]["code"] for r in held[1:]] == [POSE, POSE]


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_a_hand_follows_into_the_overflow_with_the_same_status():
    code, records, _ = run("follow", HAND, "--twist", "0,0,1e308,0,0,0", "--duration", "1", "--samples", "3")
    assert code == EXIT_FAILED
    assert all(codes(s) == {"off_tangent": POSE, "tangent": POSE, "hand": POSE} for s in records[1:-1])


def test_durations_adding_up_beyond_double_precision_are_refused():
    args = ["--twist", "0,0,1,0,0,0", "--duration", "1e308"] * 2
    r = CliRunner().invoke(app, ["follow", POLY, *args])
    assert r.exit_code == EXIT_USAGE
    assert "durations add up beyond double precision" in r.stderr


def test_a_rotation_vector_of_1e308_and_durations_that_overflow_are_located(tmp_path):
    text = Path(POLY).read_text().split("paths:")[0] + "paths:\n  - name: p\n    segments:\n"
    line = text.count("\n") + 1
    turned, long = tmp_path / "turned.yaml", tmp_path / "long.yaml"
    turned.write_text(text + "      - pose: {rotvec: [0, 0, 1e308]}\n        duration: 1\n")
    long.write_text(text + "      - {angular: [0, 0, 1], duration: 1e308}\n" * 2)
    for command in ("check", "follow", "resolve"):
        code, records, stderr = run(command, turned, long, POLY)
        assert code == EXIT_FAILED
        assert [r["error"]["code"] for r in records[:2]] == ["non-finite", "invalid-duration"]
        assert records[2:] and all("error" not in r for r in records[2:])  # the other file keeps its records
        assert stderr[0].startswith(f"{turned}:{line}:") and "rotvec" in stderr[0]
        assert stderr[1].startswith(f"{long}:{line}:7:") and "durations add up beyond double precision" in stderr[1]


@pytest.mark.parametrize(
    "args",
    [
        ["resolve", POLY, "--twist", ",".join(["1e308"] * 6)],
        ["resolve", POLY, "--twist", "1e308,0,0,0,0,1e308", "--method", "tangent"],
        ["resolve", SPHERE, "--twist", "0,0,1e308,0,0,0"],  # the tripod's record is ok: its residual a number
        ["forces", POLY, "--wrench", ",".join(["1e308"] * 6), "--friction", "0.5"],
        ["forces", SPHERE, "--wrench", "1e308,0,0,0,0,1e308", "--quality"],
        ["follow", SPHERE, "--twist", "0,0,0,1e308,0,0", "--duration", "10"],
    ],
    ids=["resolve", "resolve-tangent", "resolve-ok-residual", "forces", "forces-quality", "follow-translation"],
)
def test_absurd_options_give_statuses_not_warnings(args):
    code, records, _ = run(*args)
    assert code == EXIT_FAILED
    assert records and not all(r["ok"] for r in records)


@pytest.mark.parametrize("command", ["resolve", "basis", "check", "forces", "follow"])
def test_a_file_of_huge_numbers_gives_statuses_not_warnings(tmp_path, command):
    (tmp_path / "huge.yaml").write_text(HUGE)
    code, records, _ = run(command, tmp_path / "huge.yaml")
    assert code == EXIT_FAILED
    assert records and not any(r["ok"] for r in records)


@pytest.mark.parametrize(
    "args",
    [
        ["follow", "--twist", "0,0,1e308,0,0,0", "--duration", "1"],
        ["check", "-j", "2"],
    ],
    ids=["follow", "check-j2"],
)
def test_stderr_of_a_real_process_carries_only_grasptwist_lines(tmp_path, args):
    """The runs as a user makes them: no numpy warning, its file or its line, on stderr."""
    (tmp_path / "huge.yaml").write_text(HUGE)
    done, _ = run_installed(args[0], tmp_path / "huge.yaml", POLY, *args[1:], "-f", "jsonl")
    assert done.returncode == EXIT_FAILED
    assert all(line.startswith((str(tmp_path), POLY)) or " records: " in line for line in done.stderr.splitlines())
    assert "Warning" not in done.stderr and "error: tangent: " in done.stderr


def test_the_engine_marks_overflowed_poses_and_the_summary_agrees():
    p, n, c = np.array([[0, 2, 2], [2, 0, 2], [2, 2, 0.0]]), np.eye(3), np.zeros(3)
    path = [Segment(1.0, twist=[0, 0, 1e200, 0, 0, 0])]
    with np.errstate(all="ignore"):
        f = follow(p, n, c, path, [0.0, 0.5, 1.0])
        found = degeneracies(p, n, c, path, [0.0, 0.5, 1.0])
    assert f.overflowed.tolist() == [False, True, True]
    for r in (f.off_tangent, f.tangent):
        assert [Status(s) for s in r.status] == [Status.OK, Status.NONFINITE_POSE, Status.NONFINITE_POSE]
        assert np.isnan(r.conditioning[1:]).all() and np.isfinite(r.conditioning[0])
    assert f.tangent.alpha[0].tolist() != [None] * 3 and np.isnan(f.tangent.alpha[1:]).all()
    assert {(c.method, c.code) for c in found.crossings} == {("off-tangent", POSE), ("tangent", POSE)}
    assert found.min_conditioning["off-tangent"][1] == 0.0  # the analysis of the finite stretch alone
