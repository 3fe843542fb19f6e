"""Finger kinematics: joint rates against forward kinematics and an independent
least squares, rank-deficient and redundant fingers, prismatic joints, limits,
invariances, and the per-component split of the paper's decompositions."""

import numpy as np
import pytest

import grasptwist as gt
from grasptwist import hand
from grasptwist.engine import kinematics as kin
from grasptwist.engine.degeneracy import Status
from grasptwist.engine.screws import field_at, rigid_motion
from grasptwist.io.urdf import resolve_urdf
from hand_grasps import inline_screws, three_finger_hand, trifinger_cube

yourdfpy = pytest.importorskip("yourdfpy")
pytest.importorskip("robot_properties_fingers")


@pytest.fixture(scope="module")
def trifinger():
    g = trifinger_cube()
    h = hand.load_urdf_hand(g["urdf"], g["tips"])
    return h, g


def _random_finger(rng, n=3):
    """A revolute finger: ``n`` random unit lines through points near the origin."""
    return kin.joint_screw(rng.normal(size=(n, 3)), rng.uniform(-1, 1, (n, 3)))


# --------------------------------------------------------------------------
# Against forward kinematics and yourdfpy.


def _move(screws, points, tip, q, qdot, h, local):
    """The contact point (fixed to the tip link at ``local``) after joints move by ``qdot * h``."""
    pose = kin.forward_kinematics(screws, points, tip, q + qdot * h).tip
    return pose[:3, :3] @ local + pose[:3, 3]


def test_joint_rates_move_the_contact_with_its_velocity_to_second_order(trifinger):
    h, g = trifinger
    q = hand.joint_positions(h, g["joint_positions"])
    twist = g["twists"]["lift-tilt"]
    for finger, state in zip(h.fingers, hand.finger_states(h, q)):
        qf = q[list(finger.joint_index)]
        index = h.fingers.index(finger)
        p = g["points"][index]
        local = state.tip[:3, :3].T @ (p - state.tip[:3, 3])  # the contact in the tip link's frame
        velocity = field_at(twist, p)
        r = hand.joint_rates(state.screws, p, velocity)
        errors = []
        for step in (1e-2, 1e-3):
            moved = _move(finger.screws, finger.points, finger.tip_pose, qf, r.rates, step, local)
            errors.append(np.linalg.norm(moved - p - velocity * step))
        # O(h^2): ten times smaller a step, a hundred times smaller an error
        assert errors[1] < 2e-2 * np.linalg.norm(velocity) * 1e-3
        assert 70 < errors[0] / errors[1] < 130, errors


def test_forward_kinematics_matches_yourdfpy_transforms(trifinger):
    h, _ = trifinger
    robot = yourdfpy.URDF.load(str(resolve_urdf(h.source)), load_meshes=False)
    rng = np.random.default_rng(3)
    q = rng.uniform(-1.5, 1.5, (4, 9))
    states = hand.finger_states(h, q)
    for k in range(4):
        robot.update_cfg(q[k])
        for finger, state in zip(h.fingers, states):
            assert np.allclose(state.tip[k], robot.get_transform(finger.tip), rtol=0, atol=1e-14)
            for j, joint in enumerate(finger.joints):
                spec = robot.joint_map[joint.name]
                frame = robot.get_transform(spec.child)
                axis = frame[:3, :3] @ spec.axis
                assert np.allclose(state.screws[k, j], np.r_[axis, np.cross(frame[:3, 3], axis)], atol=1e-14)
                assert np.allclose(state.points[k, j], frame[:3, 3], atol=1e-14)


def test_joint_rates_match_lstsq_on_yourdfpy_jacobian(trifinger):
    h, g = trifinger
    robot = yourdfpy.URDF.load(str(resolve_urdf(h.source)), load_meshes=False)
    rng = np.random.default_rng(5)
    lower = np.array([j.lower for f in h.fingers for j in f.joints])
    upper = np.array([j.upper for f in h.fingers for j in f.joints])
    q = rng.uniform(lower, upper, (6, 9))
    twist = rng.normal(size=(6, 6))
    states = hand.finger_states(h, q)
    for k in range(6):
        robot.update_cfg(q[k])
        for finger, state in zip(h.fingers, states):
            tip = robot.get_transform(finger.tip)
            p = tip[:3, 3] - 0.01 * tip[:3, 2]
            columns = []
            for joint in finger.joints:
                spec = robot.joint_map[joint.name]
                frame = robot.get_transform(spec.child)
                columns.append(np.cross(frame[:3, :3] @ spec.axis, p - frame[:3, 3]))
            velocity = twist[k, 3:] + np.cross(twist[k, :3], p)
            expected, _, rank, s = np.linalg.lstsq(np.array(columns).T, velocity, rcond=None)
            r = hand.joint_rates(state.screws[k], p, velocity)
            assert np.allclose(r.rates, expected, rtol=1e-9, atol=1e-12 * np.abs(expected).max())
            assert r.rank == rank == 3
            assert r.conditioning == pytest.approx(s[-1] / s[0], rel=1e-9)
            assert r.residual < 1e-12


def test_the_trifinger_grasp_touches_the_cube_with_its_tip_spheres(trifinger):
    h, g = trifinger
    q = hand.joint_positions(h, g["joint_positions"])
    for finger, state, p, n in zip(h.fingers, hand.finger_states(h, q), g["points"], g["normals"]):
        assert np.allclose(state.tip[:3, 3], p - 0.01 * n, atol=1e-9)  # sphere centre a radius out of the face
        assert all(j.lower <= q[i] <= j.upper for j, i in zip(finger.joints, finger.joint_index))
        assert np.linalg.norm(p - state.tip[:3, 3]) < finger.length
    spin = hand.joint_rates(
        np.stack([s.screws for s in hand.finger_states(h, q)]), g["points"], field_at(g["twists"]["spin"], g["points"])
    )
    assert spin.rank.tolist() == [3, 3, 3]
    assert np.all(spin.residual < 1e-14)
    assert np.all(spin.conditioning > 0.2)


# --------------------------------------------------------------------------
# Fingers that cannot follow, redundant fingers, prismatic joints.


def test_planar_finger_has_rank_two_and_cannot_follow_out_of_its_plane():
    screws = kin.joint_screw([[0, 0, 1.0]] * 3, [[0, 0, 0], [1.0, 0, 0], [2.0, 0.5, 0]])
    p = np.array([3.0, 0.2, 0])
    out = hand.joint_rates(screws, p, [0.1, 0.2, 0.5])
    assert out.rank == 2
    assert out.conditioning == 0.0
    # the in-plane part is followed, the out-of-plane part is the whole residual
    assert out.residual == pytest.approx(0.5 / np.linalg.norm([0.1, 0.2, 0.5]), rel=1e-12)
    assert out.residual > kin.FOLLOW_TOL
    inplane = hand.joint_rates(screws, p, [0.1, 0.2, 0.0])
    assert inplane.rank == 2 and inplane.residual < 1e-15
    assert np.allclose(inplane.rates, out.rates, atol=1e-15)


def test_redundant_finger_gets_the_minimum_norm_rates():
    rng = np.random.default_rng(11)
    screws = _random_finger(rng, 4)
    p, v = rng.normal(size=3), rng.normal(size=3)
    r = hand.joint_rates(screws, p, v)
    jac = hand.finger_jacobian(screws, p)
    assert jac.shape == (3, 4)
    assert np.allclose(jac @ r.rates, v, atol=1e-13)
    assert np.allclose(r.rates, np.linalg.pinv(jac) @ v, atol=1e-13)
    null = np.linalg.svd(jac)[2][-1]  # J null = 0: adding it keeps J qdot
    assert abs(null @ r.rates) < 1e-13
    assert np.linalg.norm(r.rates + 0.1 * null) > np.linalg.norm(r.rates)
    assert r.rank == 3 and 0 < r.conditioning <= 1


def test_prismatic_joints():
    # A Cartesian finger follows any velocity, with rates equal to it.
    cartesian = kin.joint_screw(np.eye(3) * 2.0, np.zeros((3, 3)), prismatic=True)
    assert cartesian.tolist() == np.hstack((np.zeros((3, 3)), np.eye(3))).tolist()
    r = hand.joint_rates(cartesian, [5.0, -1, 2], [0.3, -0.2, 0.1])
    assert np.allclose(r.rates, [0.3, -0.2, 0.1], rtol=0, atol=1e-16)
    assert r.conditioning == 1.0
    # revolute base, prismatic slide along the arm, revolute wrist: check through forward kinematics
    screws = kin.joint_screw(
        [[0, 0, 1.0], [1.0, 0, 0], [0, 1.0, 0]], [[0, 0, 0], [0, 0, 0], [2.0, 0, 0]], [False, True, False]
    )
    points = np.array([[0, 0, 0], [0.0, 0, 0], [2.0, 0, 0]])
    tip = np.eye(4)
    tip[:3, 3] = [2.0, 0, -0.5]
    q = np.array([0.3, 0.2, -0.4])
    state = kin.forward_kinematics(screws, points, tip, q)
    p = state.tip[:3, 3]
    v = np.array([0.05, 0.1, -0.02])
    rates = hand.joint_rates(state.screws, p, v).rates
    step = 1e-4
    moved = kin.forward_kinematics(screws, points, tip, q + rates * step).tip[:3, 3]
    assert np.linalg.norm(moved - p - v * step) < step**2  # a first-order error would be ~ |v| step = 1e-5
    # the slide moved the wrist joint along the arm
    assert np.allclose(state.points[2], [2.2 * np.cos(0.3), 2.2 * np.sin(0.3), 0], atol=1e-15)


def test_finger_without_joints_and_non_finite_rows():
    r = hand.joint_rates(np.zeros((0, 6)), [1.0, 0, 0], [[0, 1.0, 0], [0, 0, 0]])
    assert r.rates.shape == (2, 0) and r.rank.tolist() == [0, 0] and r.residual.tolist() == [1.0, 0.0]
    rng = np.random.default_rng(2)
    screws = np.stack([_random_finger(rng) for _ in range(3)])
    screws[1, 0, 0] = np.nan
    r = hand.joint_rates(screws, rng.normal(size=(3, 3)), rng.normal(size=(3, 3)))
    assert np.isnan(r.rates[1]).all() and np.isnan(r.residual[1]) and r.rank[1] == 0
    alone = hand.joint_rates(screws[2], [1.0, 2, 3], [0, 0, 0])
    assert alone.residual == 0.0 and not np.any(alone.rates)
    assert np.isfinite(r.rates[[0, 2]]).all()


def test_batches_broadcast_and_match_rows():
    rng = np.random.default_rng(4)
    screws = np.stack([_random_finger(rng) for _ in range(5)])
    points, velocities = rng.normal(size=(5, 3)), rng.normal(size=(2, 5, 3))
    batch = hand.joint_rates(screws, points, velocities)
    assert batch.rates.shape == (2, 5, 3) and batch.rank.shape == (2, 5)
    for a in range(2):
        for b in range(5):
            row = hand.joint_rates(screws[b], points[b], velocities[a, b])
            assert np.array_equal(row.rates, batch.rates[a, b])
            assert row.conditioning == batch.conditioning[a, b]


def test_bad_shapes_name_the_argument():
    with pytest.raises(ValueError, match="joint_screws must have shape"):
        hand.joint_rates(np.zeros((3, 5)), [0, 0, 0], [0, 0, 0])
    with pytest.raises(ValueError, match="velocities"):
        hand.joint_rates(np.zeros((3, 6)), [0, 0, 0], [0, 0])
    with pytest.raises(ValueError, match="limits"):
        hand.velocity_limit_ratio([1.0, 2.0], [1.0, -1.0])
    with pytest.raises(ValueError, match="positions"):
        hand.finger_states(hand.load_urdf_hand(trifinger_cube()["urdf"], ["finger_tip_link_0"]), np.zeros(4))


def test_velocity_limit_ratio(trifinger):
    rates = np.array([[1.0, -4.0, 0.5], [0.1, 0.1, 9.0]])
    assert hand.velocity_limit_ratio(rates, [2.0, 2.0, 3.0]).tolist() == [2.0, 3.0]
    assert hand.velocity_limit_ratio(rates, [2.0, None, None]).tolist() == [0.5, 0.05]
    assert np.isnan(hand.velocity_limit_ratio(rates, [None, None, None])).all()
    limits = hand.velocity_limits(trifinger[0].fingers[1])  # <limit velocity="1000"> on every joint
    assert limits.tolist() == [1000.0] * 3
    assert hand.velocity_limit_ratio([[-2500.0, 10, 0]], limits).tolist() == [2.5]


# --------------------------------------------------------------------------
# Invariances.


def test_joint_rates_do_not_depend_on_scale_or_rigid_motion():
    g = three_finger_hand()
    screws, p, v = inline_screws(g["fingers"][1]), g["points"][1], np.array([0.3, -0.1, 0.2])
    base = hand.joint_rates(screws, p, v)
    for s in (1e-3, 7.0, 1e3):  # lengths and velocities scale; revolute rates do not
        scaled = hand.joint_rates(np.concatenate((screws[:, :3], s * screws[:, 3:]), axis=1), s * p, s * v)
        assert np.allclose(scaled.rates, base.rates, rtol=1e-12, atol=0)
        assert scaled.conditioning == pytest.approx(base.conditioning, rel=1e-12)
    angle = 0.7
    axis = np.array([1.0, 2, 2]) / 3
    k = np.cross(np.eye(3), axis)
    rotation = np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k
    t = np.array([3.0, -1, 0.5])
    moved = hand.joint_rates(rigid_motion(screws, rotation, t), rotation @ p + t, rotation @ v)
    assert np.allclose(moved.rates, base.rates, rtol=1e-12, atol=0)
    assert moved.rank == base.rank and moved.residual < 1e-13


# --------------------------------------------------------------------------
# Per-component joint rates.


def _inline_hand_components():
    g = three_finger_hand()
    twist = g["twists"]["roll-push"]
    off = gt.decompose_off_tangent(g["points"], g["wrist"], twist)
    tan = gt.decompose_tangent(g["points"], g["normals"], twist)
    assert off.ok and tan.ok
    return (
        g,
        twist,
        {
            "off-tangent": (np.concatenate(off.components(), axis=-2), kin.OFF_TANGENT_FIXED),
            "tangent": (np.concatenate(tan.components(), axis=-2), kin.TANGENT_FIXED),
        },
    )


def test_the_masks_say_which_contacts_each_component_leaves_still():
    g, _, methods = _inline_hand_components()
    for components, fixed in methods.values():
        speeds = np.linalg.norm(field_at(components[:, None, :], g["points"]), axis=-1)  # (component, contact)
        assert np.all(speeds[fixed] < 1e-15)
        assert np.all(speeds[~fixed] > 1e-3)


def test_component_rates_add_up_and_vanish_exactly_where_they_must():
    g, twist, methods = _inline_hand_components()
    per_method = {}
    for name, (components, fixed) in methods.items():
        rates = []
        for f, finger in enumerate(g["fingers"]):
            screws = inline_screws(finger)
            total, split = hand.component_joint_rates(screws, g["points"][f], twist, components, fixed[:, f])
            assert split.shape == (6, 3)
            assert np.allclose(split.sum(axis=0), total.rates, rtol=0, atol=1e-14)
            assert np.all(split[fixed[:, f]] == 0.0)  # exactly, not rounding noise
            assert np.all(np.abs(split[~fixed[:, f]]).max(axis=-1) > 1e-3)
            assert total.rank == 3 and total.residual < 1e-15
            rates.append(split)
        per_method[name] = np.stack(rates)
    # the two methods split the same totals differently
    assert np.allclose(per_method["off-tangent"].sum(axis=1), per_method["tangent"].sum(axis=1), atol=1e-14)
    assert np.abs(per_method["off-tangent"] - per_method["tangent"]).max() > 0.1


def test_component_rates_batch_over_grasps():
    g, twist, methods = _inline_hand_components()
    components, fixed = methods["tangent"]
    screws = inline_screws(g["fingers"][0])
    total, split = hand.component_joint_rates(
        np.stack([screws, screws]),
        np.stack([g["points"][0]] * 2),
        np.stack([twist, 2 * twist]),
        np.stack([components, 2 * components]),
        fixed[:, 0],
    )
    assert split.shape == (2, 6, 3) and total.rates.shape == (2, 3)
    assert np.allclose(split[1], 2 * split[0], rtol=1e-14, atol=0)


def test_hand_joint_rates_pad_short_fingers_without_changing_them():
    rng = np.random.default_rng(5)
    fingers = [rng.normal(size=(n, 6)) for n in (3, 2, 4)]
    fingers = [np.hstack((s[:, :3] / np.linalg.norm(s[:, :3], axis=1, keepdims=True), s[:, 3:])) for s in fingers]
    padded = np.zeros((3, 4, 6))
    limits = np.full((3, 4), np.nan)
    for f, s in enumerate(fingers):
        padded[f, : len(s)] = s
        limits[f, : len(s)] = 0.5
    points, twist = rng.normal(size=(3, 3)), rng.normal(size=6)
    r = kin.hand_joint_rates(padded, points, twist, limits)
    for f, s in enumerate(fingers):
        alone = hand.joint_rates(s, points[f], twist[3:] + np.cross(twist[:3], points[f]))
        np.testing.assert_allclose(r.rates[f, : len(s)], alone.rates, atol=1e-13)
        assert (r.rates[f, len(s) :] == 0).all()
        assert r.finger_rank[f] == alone.rank
        assert r.finger_residual[f] == pytest.approx(float(alone.residual), abs=1e-13)
        assert r.finger_limit_ratio[f] == pytest.approx(np.abs(alone.rates).max() / 0.5)
    assert r.finger_rank.tolist() == [3, 2, 3]
    assert r.status == Status.FINGER_CANNOT_FOLLOW and r.culprit == 1  # two joints cannot reach every velocity
    assert r.conditioning == r.finger_conditioning.min() == 0.0
    assert r.velocity_limit_ratio == r.finger_limit_ratio.max()


def test_joint_motion_is_the_exponential_of_a_revolute_and_a_prismatic_joint():
    from grasptwist.engine import se3
    from grasptwist.engine.kinematics import joint_motion

    rng = np.random.default_rng(7)
    q = 3 * rng.normal(size=(50,))
    for _ in range(4):
        w = rng.normal(size=3)
        w /= np.linalg.norm(w)
        for screw in (np.concatenate([w, np.cross(rng.normal(size=3), w)]), np.concatenate([np.zeros(3), w])):
            r, x = joint_motion(screw, q)
            r_exp, x_exp = se3.exp(screw, q)
            np.testing.assert_allclose(r, r_exp, atol=1e-14)
            np.testing.assert_allclose(x, x_exp, atol=1e-14)
    pitched = np.array([0, 0, 1.0, 0, 0, 0.5])  # a screw with pitch: the general exponential
    np.testing.assert_array_equal(joint_motion(pitched, q)[1], se3.exp(pitched, q)[1])
