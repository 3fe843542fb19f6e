"""Grasp synthesis with a hand (issue 31): every grasp reached within the joint limits, fingertips on the
surface, no finger link in the object; checked here by forward kinematics, independently of the search."""

from dataclasses import replace

import numpy as np
import pytest

from grasptwist.engine.ik import IK_TOL, joint_limits
from grasptwist.engine.kinematics import forward_kinematics
from grasptwist.engine.synthesis.problem import hand_reach
from grasptwist.engine.synthesis.reach import HAND_CONSTRAINTS, HandReach, check_hand_reach, reach
from grasptwist.engine.synthesis.search import synthesize
from grasptwist.io.grasp import read_grasps
from grasptwist.model import Finger, GraspObject, Hand, Joint, Shape
from places import GRASPS

INLINE = read_grasps(GRASPS / "three-finger-hand.yaml")[0]  # three 3R fingers around the cube [-1, 1]^3
CUBE = GraspObject(Shape("box", np.full(3, 2.0)), np.eye(4), mass=1.0)


def tips_of(grasp, radius):
    """Each inline finger's tip point at home: its sphere's centre on the file's contact."""
    tips = np.tile(np.eye(4), (3, 1, 1))
    tips[:, :3, 3] = grasp.points - radius * grasp.normals
    return tips


@pytest.mark.slow  # the default run's 40 s: development.md, Test time
def test_every_grasp_puts_each_tip_centre_one_radius_out_by_forward_kinematics():
    r = 0.1
    hand = replace(INLINE.hand, fingers=tuple(replace(f, tip_radius=r) for f in INLINE.hand.fingers))
    reach = hand_reach(CUBE, hand, tips=tips_of(INLINE, r))
    s = synthesize(CUBE, 0.8, hand=reach, count=2, candidates=150)
    assert s.failure is None and len(s.points) == 2 and s.joint_positions.shape == (2, 9)
    for k in range(2):
        for f, finger in enumerate(hand.fingers):
            q = s.joint_positions[k, list(finger.joint_index)]
            home = np.eye(4)
            home[:3, 3] = reach.tips[f][:3, 3]
            tip = forward_kinematics(finger.screws, finger.points, home, q).tip[:3, 3]
            centre = s.points[k, f] - r * s.normals[k, f]
            assert np.linalg.norm(tip - centre) <= IK_TOL * finger.length
            np.testing.assert_allclose(s.tip_center[k, f], centre, rtol=0, atol=1e-15)
            lower, upper = joint_limits(finger)
            assert ((q >= lower) & (q <= upper)).all()
    # each sphere touches the cube only at its contact: its centre is r outside the face
    assert np.all(np.abs(s.points - r * s.normals).max(axis=-1) >= 1 + r - 1e-12)
    assert (s.reach_error <= IK_TOL * 3).all()


def _slider(axis, point):
    """A finger that slides along ``axis`` through ``point``: it reaches a line, never a face."""
    tip = np.eye(4)
    tip[:3, 3] = point
    joint = (Joint("slide", "prismatic", None, -1.0, 1.0, None),)
    return Finger("s", None, joint, np.array([[0, 0, 0, *axis]], float), np.array([point], float), tip, 1.0, ())


def test_a_hand_that_reaches_no_candidate_names_the_reach_and_how_close_it_came():
    fingers = tuple(
        replace(_slider(a, p), joint_index=(i,))
        for i, (a, p) in enumerate((([-1, 0, 0], [1.0, 0.3, 0.4]), ([1, 0, 0], [-1, -0.2, 0]), ([0, 1, 0], [0, -1, 0])))
    )
    hand = Hand(fingers, ("a", "b", "c"), None, None)
    s = synthesize(CUBE, 0.8, hand=hand, count=1, candidates=300)
    assert len(s.points) == 0 and s.failure.constraint == "reach"
    assert 0 < s.failure.best < 2 and s.failure.needed == 0.0
    assert "the hand reaches no candidate's contacts within its joint limits" in s.failure.message


def test_a_hand_whose_fingers_share_a_joint_is_refused():
    f = INLINE.hand.fingers[0]
    shared = Hand((f, f, f), INLINE.hand.joint_names[:3], None, None)
    with pytest.raises(ValueError, match="three fingers that share no joint"):
        check_hand_reach(HandReach(shared, np.zeros((3, 4, 4)), np.zeros(3), None, 0.0))


def test_links_in_the_object_and_fingertips_in_it_are_named_with_how_close_they_came():
    home = tips_of(INLINE, 0.0)
    always_in = hand_reach(CUBE, INLINE.hand, tips=home, collide=lambda q: np.full(len(q), 0.25))
    s = synthesize(CUBE, 0.8, hand=always_in, count=1, candidates=100)
    # the least violation: 0.25 deep less the tolerance (0.1 % of the cube's diagonal)
    assert s.failure.constraint == "collision" and s.failure.best == 0.25 - 1e-3 * float(
        np.sqrt(3) * CUBE.shape.size[0]
    )
    assert "puts a finger link into the object or another finger" in s.failure.message
    # a surface whose every point is a crease: no sphere of radius 0.1 touches it at one point alone
    crease = HandReach(INLINE.hand, home, np.full(3, 0.1), lambda c: (c, c, np.zeros(c.shape[:-1])), 1e-6)
    r = reach(crease, INLINE.points[None], INLINE.normals[None])
    assert r.failed.tolist() == [HAND_CONSTRAINTS.index("fingertips")] and np.isnan(r.positions).all()
