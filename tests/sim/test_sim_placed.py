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
    sim = gt.simulate(read, mass=0.094, friction=1, duration=SHORT)
    # the grasp simulated is the placed one (its joints: a placed grasp is simulated as it is), and it holds
    np.testing.assert_array_equal(sim.grasp.joint_positions, placed.joint_positions)
    assert sim.grasp.placement is None and sim.test.held
    moved = [d.displacement for d in sim.test.directions]
    assert len(moved) == 6 and max(moved) < 5e-4  # a quarter of the 2 mm tolerance (unplaced: 12 mm in each)


def test_a_hand_that_cannot_reach_its_contacts_is_the_placements_error():
    (read,) = gt.read_grasps(str(GRASPS / "trifinger-cube.yaml"))
    far = replace(read, points=read.points * 10)  # 10 times farther from the hand than its fingers reach
    with pytest.raises(gt.InputError) as err:
        gt.simulate(far, mass=0.094, friction=1, duration=SHORT)
    assert err.value.code == "unreachable" and err.value.file.endswith("trifinger-cube.yaml")
