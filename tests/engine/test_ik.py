"""Inverse kinematics of a grasp (grasptwist.engine.ik): tips on contacts by forward kinematics,
within limits, nearest the seed, unreachable contacts with their distance; the contact-off-finger check."""

import numpy as np
import pytest

from grasptwist.engine.degeneracy import Status
from grasptwist.engine.ik import IK_TOL, chain_ik, contact_off_finger, hand_ik, home_tips, joint_limits, place_hand
from grasptwist.engine.kinematics import forward_kinematics
from grasptwist.io.grasp import load_grasps
from places import GRASPS, ROOT


def tip_points(hand, positions, tips):
    """Each finger's tip point by forward kinematics: ``(..., 3, 3)``."""
    return np.stack(
        [
            forward_kinematics(f.screws, f.points, tips[i], positions[..., list(f.joint_index)]).tip[..., :3, 3]
            for i, f in enumerate(hand.fingers)
        ],
        axis=-2,
    )


def lengths(hand):
    return np.array([f.length for f in hand.fingers])


@pytest.fixture(scope="module")
def trifinger():
    pytest.importorskip("yourdfpy")
    pytest.importorskip("robot_properties_fingers")
    return load_grasps(GRASPS / "trifinger-cube.yaml")[0]


@pytest.fixture(scope="module")
def inline():
    return load_grasps(GRASPS / "three-finger-hand.yaml")[0]


def reachable(hand, tips, rng, n, spread):
    """Contacts the hand reaches: its tips at random joint positions within the limits
    (within ``spread`` of home where a joint has no limit), and those positions."""
    q = np.empty((n, len(hand.joint_names)))
    for f in hand.fingers:
        lower, upper = joint_limits(f)
        lo, hi = np.fmax(lower, -spread), np.fmin(upper, spread)
        q[:, list(f.joint_index)] = rng.uniform(lo, hi, (n, len(lo)))
    return tip_points(hand, q, tips), q


def test_trifinger_tips_land_on_reachable_contacts_within_limits(trifinger):
    hand, tips = trifinger.hand, home_tips(trifinger.hand)
    targets, _ = reachable(hand, tips, np.random.default_rng(3), 400, np.pi)
    r = hand_ik(hand, targets)
    assert (r.status == Status.OK).all()
    reached = tip_points(hand, r.positions, tips)
    error = np.linalg.norm(reached - targets, axis=-1)
    assert (error <= IK_TOL * lengths(hand)).all()
    np.testing.assert_allclose(r.tip_error, error, rtol=0, atol=1e-15)
    for f in hand.fingers:
        lower, upper = joint_limits(f)
        q = r.positions[:, list(f.joint_index)]
        assert np.isfinite(lower).all() and ((q >= lower) & (q <= upper)).all()
    assert r.within_limits.all()


#: The joint positions the bundled TriFinger file gave by hand before its tip radius was read from
#: the URDF: each sphere's centre at contact - 0.01 * normal, computed outside grasptwist.
HAND_TYPED = [0.181390037, 0.5904426439, -1.4828803827, 0.19893411, 0.5545414034]
HAND_TYPED += [-1.3054491805, 0.2399650693, 0.5570307797, -1.2184725163]


def test_trifinger_tip_centres_go_one_radius_behind_the_contacts(trifinger):
    """From home, inverse kinematics on the centres ``p - r n`` (r = 10 mm from the URDF) finds the
    positions once typed into the file, to 1e-8 rad; from a seed 0.1 rad off, the same."""
    hand = trifinger.hand
    assert [f.tip_radius for f in hand.fingers] == [0.01] * 3
    centres = trifinger.points - 0.01 * trifinger.normals
    for seed in (None, np.array(HAND_TYPED) + 0.1 * np.resize([1, -1, 1], 9)):
        r = hand_ik(hand, centres, seed=seed)
        assert r.ok
        np.testing.assert_allclose(r.positions, HAND_TYPED, atol=1e-8)


def test_inline_hand_reaches_moved_contacts(inline):
    """The inline fingers' tip points are the file's contacts at home; contacts moved by up to
    a fifth of the fingers' length are reached to 1e-9 of it, and at home every joint is 0."""
    hand, tips = inline.hand, home_tips(inline.hand, inline.points)
    at_home = hand_ik(hand, inline.points, tips=tips)
    assert at_home.ok and np.abs(at_home.positions).max() == 0.0
    rng = np.random.default_rng(5)
    targets, _ = reachable(hand, tips, rng, 300, 0.6)
    r = hand_ik(hand, targets, tips=tips)
    assert (r.status == Status.OK).all()
    error = np.linalg.norm(tip_points(hand, r.positions, tips) - targets, axis=-1)
    assert (error <= IK_TOL * lengths(hand)).all()
    assert np.abs(r.positions).max() <= np.pi + 1e-12  # unlimited revolute joints stay within pi of the seed


def test_the_solution_nearest_the_seed_is_chosen(inline):
    """A 3R finger reaches most points two ways (elbow up or down): from a seed near either,
    the iteration ends at that one, not the other."""
    hand, tips = inline.hand, home_tips(inline.hand, inline.points)
    _, q = reachable(hand, tips, np.random.default_rng(8), 50, 0.8)
    q[:, 2::3] = np.where(np.abs(q[:, 2::3]) < 0.3, 0.5, q[:, 2::3])  # a clearly bent elbow
    targets = tip_points(hand, q, tips)
    r = hand_ik(hand, targets, seed=q + 0.05, tips=tips)
    assert r.ok.all()
    np.testing.assert_allclose(r.positions, q, atol=1e-7)


def test_unreachable_contacts_report_their_distance(inline):
    """A contact moved away from its finger's base beyond the finger's reach: ``unreachable``,
    and the tip error is the distance left, at least the excess over the reach."""
    hand, tips = inline.hand, home_tips(inline.hand, inline.points)
    far = inline.points.copy()
    base = hand.fingers[0].points[0]
    out = (far[0] - base) / np.linalg.norm(far[0] - base)
    far[0] = base + out * (hand.fingers[0].length + 0.5)
    r = hand_ik(hand, far, tips=tips)
    assert r.status.tolist() == [Status.UNREACHABLE, Status.OK, Status.OK]
    assert not r.ok and int(r.culprit) == 0
    # the tip stretched straight towards the contact: 0.5 away, and at most that
    assert 0.5 - 1e-6 <= r.tip_error[0] <= 0.5 + 1e-6
    reached = tip_points(hand, r.positions, tips)
    np.testing.assert_allclose(np.linalg.norm(reached[0] - far[0]), r.tip_error[0], rtol=1e-12)


def test_a_contact_reachable_only_outside_the_limits_is_outside_limits(trifinger):
    """Finger 0's tip with its base joint 0.6 rad beyond its upper limit (1.0): reached there,
    flagged; a tip put by an elbow bent the wrong way (+0.4, limits [-2.7, 0]) is reached within
    the limits by the other elbow, and is ok."""
    hand, tips = trifinger.hand, home_tips(trifinger.hand)
    index = list(hand.fingers[0].joint_index)
    q = trifinger.joint_positions.copy()
    q[index] = [1.6, 0.8, -1.2]
    targets = tip_points(hand, q, tips)
    r = hand_ik(hand, targets)
    assert r.status.tolist() == [Status.OUTSIDE_LIMITS, Status.OK, Status.OK]
    assert r.within_limits.tolist() == [False, True, True]
    assert r.positions[index[0]] == pytest.approx(1.6, abs=1e-7)  # the base's yaw is the only one that fits
    error = np.linalg.norm(tip_points(hand, r.positions, tips) - targets, axis=-1)
    assert (error <= IK_TOL * lengths(hand)).all()
    q[index] = [0.2, 0.6, 0.4]
    r = hand_ik(hand, tip_points(hand, q, tips))
    assert r.ok and r.within_limits.all() and r.positions[index[2]] < 0


def test_nonfinite_contacts_are_nonfinite_input(inline):
    points = inline.points.copy()
    points[2, 1] = np.nan
    r = hand_ik(inline.hand, points, tips=home_tips(inline.hand, inline.points))
    assert r.status.tolist() == [Status.OK, Status.OK, Status.NONFINITE_INPUT]


def test_an_inline_finger_without_tip_points_is_refused(inline):
    with pytest.raises(ValueError, match="has no tip link: give the points"):
        hand_ik(inline.hand, inline.points)


def test_chain_ik_stays_within_limits_and_gives_the_closest_it_can():
    """A planar 2R arm whose elbow may bend at most 0.5 rad cannot reach a point that needs a
    right angle: it ends at the limit with the elbow at 0.5, and reports how far it is."""
    s = [[0, 0, 1.0, 0, 0, 0], [0, 0, 1.0, 0, -1.0, 0]]
    tip = np.eye(4)
    tip[0, 3] = 2.0
    r = chain_ik(s, [[0, 0, 0], [1.0, 0, 0]], tip, [[1.0, 1.0, 0]], [[0.0, 0.0]], [-0.5, -0.5], [0.5, 0.5])
    assert np.abs(r.positions).max() <= 0.5
    reached = forward_kinematics(s, [[0, 0, 0], [1.0, 0, 0]], tip, r.positions).tip[0, :3, 3]
    assert r.error[0] == pytest.approx(np.linalg.norm(reached - [1.0, 1.0, 0]), rel=1e-12)
    assert r.error[0] > 0.1


def test_contact_off_finger_is_the_loaders_check(trifinger):
    """The grasp file's positions pass; a contact moved 0.9 m away fails, the others do not."""
    hand = trifinger.hand
    tips = tip_points(hand, trifinger.joint_positions, home_tips(hand))
    assert not contact_off_finger(tips, trifinger.points, lengths(hand)).any()
    far = trifinger.points.copy()
    far[0, 0] += 0.9
    assert contact_off_finger(tips, far, lengths(hand)).tolist() == [True, False, False]


def test_place_hand_checks_given_positions_and_solves_missing_ones(trifinger, inline):
    hand = trifinger.hand
    far = trifinger.points.copy()
    far[2, 2] += 0.9
    checked = place_hand(hand, far, trifinger.joint_positions)
    assert checked.status.tolist() == [Status.OK, Status.OK, Status.CONTACT_OFF_FINGER]
    assert checked.tip_error[2] > hand.fingers[2].length
    np.testing.assert_array_equal(checked.positions, trifinger.joint_positions)
    centres = trifinger.points - 0.01 * trifinger.normals
    solved = place_hand(hand, centres, seed=trifinger.joint_positions + 0.05)
    assert solved.ok and solved.tip_error.max() <= IK_TOL * lengths(hand).min()
    # an inline hand without tip points: as given, unchecked
    taken = place_hand(inline.hand, far)
    assert taken.ok and np.isnan(taken.tip_error).all() and not taken.positions.any()


def test_the_guide_page_runs_as_printed(monkeypatch):
    """docs/guide/inverse-kinematics.md's sessions give the outputs shown."""
    import doctest
    import re

    monkeypatch.chdir(ROOT)
    text = (ROOT / "docs" / "guide" / "inverse-kinematics.md").read_text("utf-8")
    sessions = re.findall(r"^```pycon\n(.*?)^```$", text, flags=re.M | re.S)
    assert sessions
    for session in sessions:
        test = doctest.DocTestParser().get_doctest(session, {}, "inverse-kinematics.md", None, 0)
        runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS)
        runner.run(test)
        assert runner.summarize(verbose=False).failed == 0


def test_fingers_stepped_together_solve_each_row_as_alone(trifinger, inline):
    # fingers_ik (one chain a row, the search's batch) against finger_ik one finger at a time:
    # the same positions, errors and statuses, bit for bit, reached targets and unreachable ones
    from grasptwist.engine.ik import finger_ik, fingers_ik

    rng = np.random.default_rng(5)
    for grasp in (trifinger, inline):
        hand, tips = grasp.hand, home_tips(grasp.hand, grasp.points)
        targets, _ = reachable(hand, tips, rng, 40, np.pi)
        targets = targets.reshape(-1, 3)
        targets[::7] *= 3.0  # beyond the fingers' reach: unreachable, their least distance
        which = np.tile(np.arange(3), 40)
        q, error, status = fingers_ik(hand.fingers, tips, which, targets, seeds=2)
        assert (status == Status.UNREACHABLE).any() and (status == Status.OK).any()
        for f, finger in enumerate(hand.fingers):
            alone = finger_ik(finger, tips[f], targets[which == f], seeds=2, classify=False)
            np.testing.assert_array_equal(q[which == f, : len(finger.joints)], alone[0])
            np.testing.assert_array_equal(error[which == f], alone[1])
            np.testing.assert_array_equal(status[which == f], alone[3])


def test_the_iterations_forward_kinematics_is_the_product_of_exponentials(trifinger):
    """The inverse kinematics' prepared chain (each joint's Rodrigues terms formed once, every joint's motion at
    once) gives forward_kinematics' tip point and finger_jacobian's columns, for one chain over the rows and for
    one chain a row (the TriFinger's three fingers stacked); a chain with a prismatic joint keeps the general path."""
    from grasptwist.engine.ik import _prepared, _Revolute, _tip_and_jacobian
    from grasptwist.engine.kinematics import finger_jacobian

    hand, tips = trifinger.hand, home_tips(trifinger.hand)
    rng = np.random.default_rng(5)
    q = rng.uniform(-2, 2, (40, 3))
    which = rng.integers(0, 3, 40)
    for stacked in (False, True):
        f = [hand.fingers[0]] * 40 if not stacked else [hand.fingers[k] for k in which]
        t = tips[[0] * 40 if not stacked else which]
        screws, points = np.array([g.screws for g in f]), np.array([g.points for g in f])
        chain = (screws[0], points[0], t[0]) if not stacked else (screws, points, t)
        prepared = _prepared(chain)
        assert isinstance(prepared, _Revolute)
        tip, jacobian = _tip_and_jacobian(prepared, q)
        state = forward_kinematics(screws, points, t, q)
        np.testing.assert_allclose(tip, state.tip[:, :3, 3], rtol=0, atol=1e-14)
        np.testing.assert_allclose(jacobian, finger_jacobian(state.screws, tip), rtol=0, atol=1e-14)
        assert np.abs(jacobian).max() > 0.05  # a real finger's columns, not zeros
    slide = (np.array([[0, 0, 0, 0, 0, 1.0], [0, 0, 1.0, 0, 0, 0]]), np.zeros((2, 3)), np.eye(4))
    assert _prepared(slide) is slide
    tip, jacobian = _tip_and_jacobian(slide, np.array([[0.5, 0.0]]))
    assert tip.tolist() == [[0.0, 0.0, 0.5]] and jacobian[0, 2].tolist() == [1.0, 0.0]
