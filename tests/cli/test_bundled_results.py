"""Every bundled grasp resolved end to end (loader, engine, records), its key numbers pinned.

The numbers are those the files' headers state; a grasp that is degenerate
for a method has that method's specific error instead.
"""

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from grasptwist.cli import app
from places import GRASPS

ZERO = [0, 0, 0]
RANK = "normals-rank-deficient"

# (file, grasp, twist): (x, y, alpha, beta, in_tangent_planes); a str is the method's error code
EXPECTED = {
    ("bottle.yaml", "bottle", "lift-z"): (
        [0.0969, -0.7018, -0.7018],
        [0, 1.2689, -1.2689],
        [0, -0.8598, 0.8676],
        [-0.5118, 0, 0],
        False,
    ),
    ("bottle.yaml", "bottle", "pour"): (
        [-0.7827, 0.2368, 0.2368],
        [0, 0.2396, -0.2396],
        [0, -0.1623, 0.1638],
        [-0.8976, 0.3693, 0.3693],
        False,
    ),
    ("box-edge.yaml", "box-edge", "tip-over-edge"): (
        [-1.2037, 0.2825, 0.1065],
        [0, -0.2515, 0.7922],
        [0, 10, -26.6667],
        [10.8333, 27.9682, 10.5475],
        False,
    ),
    ("box-edge.yaml", "box-edge", "slide-x"): (
        [0, -0.4238, 0.4262],
        [1.0879, -0.503, -0.5942],
        [40, 20, 20],
        ZERO,
        True,
    ),
    ("box-edge.yaml", "box-edge", "turn-y"): ([0, -0.5297, 0.5327], [0.0272, 0, 0], [1, 0, 0], ZERO, True),
    ("cylinder.yaml", "cylinder", "sigma-1"): ([1, 0, 0], ZERO, RANK, RANK, None),
    ("cylinder.yaml", "cylinder", "spin-z"): (ZERO, [-0.4714] * 3, RANK, RANK, None),
    ("cylinder.yaml", "cylinder", "lift-z"): ([0.6667] * 3, ZERO, RANK, RANK, None),
    ("handle.yaml", "mug-handle", "lift-z"): (
        [-7.8704, -1.9813, 5.0369],
        [38.7475, -54.6961, 16.0097],
        "theta-not-unique",
        "theta-not-unique",
        None,
    ),
    ("handle.yaml", "mug-handle", "pour"): ([7.5, 5.1515, -1.8133], ZERO, "theta-not-unique", "theta-not-unique", None),
    ("handle.yaml", "mug-handle", "turn-z"): (
        [-15.5556, -24.5687, -10.0335],
        ZERO,
        "theta-not-unique",
        "theta-not-unique",
        None,
    ),
    ("polyhedron.yaml", "polyhedron", "diagonal-spin"): (ZERO, [0.4082] * 3, [0.5774] * 3, ZERO, True),
    ("sphere.yaml", "sphere-tripod", "roll-x"): (
        [0.5877, -0.2938, -0.2938],
        [0, -0.2778, 0.2778],
        [0, 0.637, -0.637],
        ZERO,
        True,
    ),
    ("sphere.yaml", "sphere-tripod", "spin-z"): (ZERO, [-0.3439] * 3, [0.7887] * 3, ZERO, True),
    ("sphere.yaml", "sphere-tripod", "lift-z"): ([1.0508] * 3, ZERO, ZERO, [1.0508] * 3, False),
    ("sphere.yaml", "sphere-equator", "roll-x"): ([0.6667, -0.3333, -0.3333], ZERO, RANK, RANK, None),
    ("sphere.yaml", "sphere-equator", "lift-z"): ([0.9524] * 3, ZERO, RANK, RANK, None),
    ("three-finger-hand.yaml", "three-finger-hand", "roll-push"): (
        [0.0708, -0.0559, -0.3346],
        [0.0247, -0.1369, 0.0403],
        [-0.1503, -0.6302, 0.35],
        [0.2245, -0.1772, -0.6364],
        False,
    ),
    ("trifinger-cube.yaml", "trifinger-cube", "spin"): (
        ZERO,
        [-0.1871, -0.0931, -0.2241],
        [-1.0509, 0.2167, 1.2426],
        [-0.3375, 0.385, 0],
        False,
    ),
    ("trifinger-cube.yaml", "trifinger-cube", "lift-tilt"): (
        [-0.4387, -0.2919, -0.4596],
        [-0.0104, 0.2593, -0.1235],
        [-0.0585, -0.6033, 0.6851],
        [0, 0.3465, 0],
        False,
    ),
}

# (file, grasp, twist): each finger's joint rates as the header states them, and the velocity-limit ratio
JOINT_RATES = {
    ("three-finger-hand.yaml", "three-finger-hand", "roll-push"): (
        [[-0.14, 0.015, 0.105], [0.14, 0.01, -0.09], [-0.1, 0.21, -0.61]],
        0.2033,
    ),
    ("trifinger-cube.yaml", "trifinger-cube", "spin"): (
        [[0.0314, 0.083, -0.032], [0.0396, 0.0622, -0.0254], [0.0519, 0.0387, -0.0162]],
        8.3e-05,
    ),
}


@pytest.fixture(scope="module")
def records():
    result = CliRunner().invoke(app, ["resolve", str(GRASPS), "-f", "jsonl"])
    assert result.exit_code == 1  # the degenerate grasps fail their tangent method
    return {
        (Path(r["file"]).name, r["grasp"], r["twist"]["name"]): r for r in map(json.loads, result.stdout.splitlines())
    }


def test_every_bundled_grasp_and_twist_is_pinned(records):
    assert set(records) == set(EXPECTED)


@pytest.mark.parametrize("key", sorted(EXPECTED), ids=lambda k: f"{k[1]}/{k[2]}")
def test_bundled_numbers(records, key):
    rec = records[key]
    x, y, alpha, beta, in_planes = EXPECTED[key]
    np.testing.assert_allclose(rec["off_tangent"]["x"], x, atol=1e-4)
    np.testing.assert_allclose(rec["off_tangent"]["y"], y, atol=1e-4)
    if isinstance(alpha, str):
        assert rec["tangent"]["error"]["code"] == alpha and rec["ok"] is False
    else:
        np.testing.assert_allclose(rec["tangent"]["alpha"], alpha, atol=1e-4)
        np.testing.assert_allclose(rec["tangent"]["beta"], beta, atol=1e-4)
        assert rec["tangent"]["in_tangent_planes"] is in_planes and rec["ok"] is True


@pytest.mark.parametrize("key", sorted(EXPECTED), ids=lambda k: f"{k[1]}/{k[2]}")
def test_bundled_judgements_follow_the_pinned_amplitudes(records, key):
    """``moves`` lists a component's fingers exactly where its pinned amplitude is not 0."""
    rec = records[key]
    x, y, alpha, beta, _ = EXPECTED[key]
    off = rec["off_tangent"]
    assert [bool(m) for m in off["moves"]] == [a != 0 for a in x + y]
    assert off["moves"] == [[0], [1], [2], [1, 2], [0, 2], [0, 1]] or not all(x + y)
    assert off["about_wrist"] is (not any(x) and any(y))
    if not isinstance(alpha, str):
        assert [bool(m) for m in rec["tangent"]["moves"]] == [a != 0 for a in alpha + beta]


def test_the_spins_about_the_wrist_are_the_ones_the_files_say(records):
    spins = {(k[1], k[2]) for k, rec in records.items() if rec["off_tangent"]["about_wrist"]}
    assert spins == {
        ("cylinder", "spin-z"),
        ("polyhedron", "diagonal-spin"),
        ("sphere-tripod", "spin-z"),
        ("trifinger-cube", "spin"),  # about the vertical through the cube, which the wrist is on
    }


@pytest.mark.parametrize("key", sorted(JOINT_RATES), ids=lambda k: f"{k[1]}/{k[2]}")
def test_bundled_hand_joint_rates(records, key):
    rec = records[key]
    rates, ratio = JOINT_RATES[key]
    hand = rec["hand"]
    assert hand["ok"] and rec["ok"]
    assert [f["contact"] for f in hand["fingers"]] == [c["name"] for c in rec["contacts"]]
    np.testing.assert_allclose([f["joint_rates"] for f in hand["fingers"]], rates, atol=5e-5)
    assert [f["rank"] for f in hand["fingers"]] == [3, 3, 3]
    assert max(f["residual"] for f in hand["fingers"]) < 1e-12
    assert hand["velocity_limit_ratio"] == pytest.approx(ratio, rel=1e-3)
    assert hand["velocity_limit_ratio"] == max(f["velocity_limit_ratio"] for f in hand["fingers"])


@pytest.mark.parametrize("key", sorted(JOINT_RATES), ids=lambda k: f"{k[1]}/{k[2]}")
def test_bundled_component_joint_rates_add_up_and_vanish_where_they_must(records, key):
    rec = records[key]
    total = np.array([f["joint_rates"] for f in rec["hand"]["fingers"]])
    # components in basis order: Sigma_1..3, Psi_1..3 / Theta_1..3, Sigma_1..3; [c][finger][joint]
    still = {"off_tangent": np.vstack((~np.eye(3, dtype=bool), np.eye(3, dtype=bool))),
             "tangent": np.vstack((np.eye(3, dtype=bool), ~np.eye(3, dtype=bool)))}  # fmt: skip
    parts = {}
    for key_, fixed in still.items():
        parts[key_] = rates = np.array(rec[key_]["joint_rates"])
        assert rates.shape == (6, 3, 3)
        np.testing.assert_allclose(rates.sum(axis=0), total, atol=1e-12)
        assert (rates[fixed] == 0.0).all()  # exactly, not to round-off
        assert (np.abs(rates[~fixed]).max(axis=-1) > 0).sum() >= 1
    assert not np.allclose(parts["off_tangent"], parts["tangent"])  # the methods split the rates differently


def test_the_hand_table_names_the_components_that_move_each_finger():
    """Per finger, the components whose joint rates for it are not zero, as the records give them."""
    rec = json.loads(CliRunner().invoke(app, ["resolve", str(GRASPS / "three-finger-hand.yaml"), "-f", "json"]).stdout)[
        0
    ]
    wide = {"COLUMNS": "200"}  # one line each
    table = CliRunner().invoke(app, ["resolve", str(GRASPS / "three-finger-hand.yaml")], env=wide).stdout
    names = {"off_tangent": ("Sigma", "Psi"), "tangent": ("Theta", "Sigma")}
    for f, finger in enumerate(rec["hand"]["fingers"]):
        parts = []
        for key, label in (("off_tangent", "off-tangent"), ("tangent", "tangent")):
            rates = rec[key]["joint_rates"]  # [component][finger][joint]
            moving = [f"{names[key][c // 3]}_{c % 3 + 1}" for c in range(6) if np.any(rates[c][f])]
            parts.append(f"{label} {' '.join(moving)}")
        assert f"finger {finger['contact']} is moved by: {'; '.join(parts)}" in table  # named by its contact
    assert "finger 1 is moved by: off-tangent Sigma_1 Psi_2 Psi_3; tangent Theta_2 Theta_3 Sigma_1" in table
