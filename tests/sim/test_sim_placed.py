"""``grasptwist.simulate`` places a grasp's hand as every command does: a grasp read by
``grasptwist.read_grasps`` (a URDF hand at its seed, not yet on its contacts) and the same grasp
placed (``grasptwist.place_grasp``) give one result."""

from dataclasses import replace

import numpy as np
import pytest

import grasptwist as gt
from places import GRASPS

pytest.importorskip("mujoco")

SHORT = 0.05  # the least duration: an unplaced TriFinger's cube falls 12 mm in it, six times the tolerance


def test_a_grasp_read_is_simulated_as_its_placed_grasp():
    (read,) = gt.read_grasps(str(GRASPS / "trifinger-cube.yaml"))
    placed = gt.place_grasp(read)
    assert read.placement is not None and placed.placement is None  # read at its seed; placed on its contacts
    as_read = gt.simulate(read, mass=0.094, friction=1, duration=SHORT)
    as_placed = gt.simulate(placed, mass=0.094, friction=1, duration=SHORT)
    assert as_read.test.held and as_placed.test.held
    # the grasp simulated is the placed one: its joints, and each direction's motion, the same
    np.testing.assert_array_equal(as_read.grasp.joint_positions, placed.joint_positions)
    moved = [[d.displacement for d in s.test.directions] for s in (as_read, as_placed)]
    np.testing.assert_allclose(moved[0], moved[1], rtol=1e-9, atol=1e-12)
    assert max(moved[0]) < 5e-4  # a quarter of the 2 mm tolerance (unplaced: ~12 mm in every direction)


def test_a_hand_that_cannot_reach_its_contacts_is_the_placements_error():
    (read,) = gt.read_grasps(str(GRASPS / "trifinger-cube.yaml"))
    far = replace(read, points=read.points * 10)  # 10 times farther from the hand than its fingers reach
    with pytest.raises(gt.InputError) as err:
        gt.simulate(far, mass=0.094, friction=1, duration=SHORT)
    assert err.value.code == "unreachable" and err.value.file.endswith("trifinger-cube.yaml")
