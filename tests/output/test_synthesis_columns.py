"""The flat columns of ``synthesize`` (CSV, Parquet): a run's hand adds reach errors and joint positions."""

import numpy as np

from grasptwist.engine.synthesis.search import Synthesis
from grasptwist.io.grasp import read_grasps
from grasptwist.output.synthesis_records import SYNTHESIS_COLUMNS
from grasptwist.run.synthesize import Found
from places import GRASPS


def _found(hand, k=2):
    (g,) = read_grasps(GRASPS / "three-finger-hand.yaml")
    q = np.arange(k * 9, dtype=float).reshape(k, 9) / 10
    error = np.full((k, 3), 1e-12)
    z = np.zeros((k, 3, 3))
    s = Synthesis(
        *(z, z, np.zeros((k, 3)), np.ones((k, 1)), np.ones(k), None, np.ones((k, 2)), (), 10, 0.1, 0, None, q, error),
        hold_friction=np.zeros(k),
        edge_distance=np.ones((k, 3)),
        robustness=np.ones(k),
    )
    return g.hand, Found(
        "f.yaml", "g", 1, None, None, g.object, 0.8, ("hold",), np.zeros((1, 6)), None, s, hand=hand and g.hand
    )


def test_a_run_hand_adds_each_finger_s_reach_error_and_each_joint_s_position():
    hand, found = _found(True)
    header = SYNTHESIS_COLUMNS.header(hand).decode().strip().split(",")
    joints = [f"q_{f}_{f}.{j}" for f in ("east", "west", "south") for j in (1, 2, 3)]
    assert header[-12:] == ["reach_error1", "reach_error2", "reach_error3", *joints]
    flat = SYNTHESIS_COLUMNS.flat(found, hand=hand)
    assert list(flat)[-12:] == header[-12:]
    np.testing.assert_array_equal(np.column_stack([flat[n] for n in joints]), found.synthesis.joint_positions)
    assert flat["reach_error2"].tolist() == [1e-12, 1e-12]
    assert SYNTHESIS_COLUMNS.typed_header(hand)["q_south_south.3"] == "float64"
    row = SYNTHESIS_COLUMNS.error_row({"file": "f", "grasp": "g", "error": {"code": "c", "message": "m"}}, hand)
    assert row.count(b",") == len(header) - 1


def test_a_grasp_without_the_run_s_hand_leaves_its_columns_empty():
    hand, found = _found(None)
    flat = SYNTHESIS_COLUMNS.flat(found, hand=hand)
    assert flat["reach_error1"].mask.all() and flat["q_east_east.1"].mask.all()
    assert "reach_error1" not in SYNTHESIS_COLUMNS.header(None).decode()


def test_the_columns_say_which_limit_stopped_the_search_after_the_seed():
    _, found = _found(None)
    header = SYNTHESIS_COLUMNS.header(None).decode().strip().split(",")
    assert header[-4:] == ["candidates", "seconds", "seed", "stopped_by"]
    assert SYNTHESIS_COLUMNS.flat(found)["stopped_by"].tolist() == ["candidates", "candidates"]
    assert SYNTHESIS_COLUMNS.typed_header(None)["stopped_by"] == "U"
