"""An independent check of the TriFinger's joint positions and joint rates against pinocchio.

pinocchio (``pin`` on the package index, in the test extra) reads the same URDF with its
own parser and computes forward kinematics and frame Jacobians with its own code.  The
contact point's Jacobian comes from the tip frame's (rows ``(v_o; omega)``, axes of the
root frame): ``J_p = J_v - [p - o]_x J_omega`` (the point ``p`` of the tip link at the
contact moves with ``v_o + omega x (p - o)``).  The tolerances:

* positions: grasptwist's inverse kinematics stops within ``IK_TOL = 1e-9`` of the
  finger's length (0.38 m), and pinocchio's tip is then within 1e-12 m of the centre;
  configurations are compared to 1e-7 rad (conditioning ~0.3: some 1e-9 m / (0.3 * 0.1 m));
* rates: both solve the same 3x3 system in float64 with conditioning above 0.1, so
  they agree to a relative 1e-9 (a generous bound: seen 1e-13).
"""

from importlib.resources import files

import numpy as np
import pytest

from grasptwist.engine.kinematics import finger_jacobian
from grasptwist.hand import finger_states, hand_ik, joint_rates
from grasptwist.run.placement import read_grasps
from places import GRASPS

pin = pytest.importorskip("pinocchio", reason="needs pinocchio (pip install pin; in the test extra)")
pytest.importorskip("robot_properties_fingers", reason="needs the TriFinger URDF")
pytest.importorskip("yourdfpy", reason="needs the urdf extra")

TIPS = ["finger_tip_link_0", "finger_tip_link_120", "finger_tip_link_240"]


@pytest.fixture(scope="module")
def model():
    urdf = files("robot_properties_fingers") / "urdf" / "pro" / "trifingerpro.urdf"
    m = pin.buildModelFromUrdf(str(urdf))
    return m, m.createData()


@pytest.fixture(scope="module")
def grasp():
    (g,) = read_grasps(GRASPS / "trifinger-cube.yaml")  # placed: positions solved by grasptwist's IK
    return g


def pin_q(m, hand, q):
    """grasptwist's joint positions (``hand.joint_names`` order) in pinocchio's order."""
    out = np.zeros(m.nq)
    for name, value in zip(hand.joint_names, q):
        out[m.joints[m.getJointId(name)].idx_q] = value
    return out


def pin_tips(m, d, q):
    """Each tip frame's ``(R, o)`` and its ``(6, nv)`` Jacobian ``(v_o; omega)`` in root axes."""
    pin.computeJointJacobians(m, d, q)
    pin.updateFramePlacements(m, d)
    out = []
    for tip in TIPS:
        fid = m.getFrameId(tip)
        placement = d.oMf[fid]
        jac = pin.getFrameJacobian(m, d, fid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
        out.append((placement.rotation.copy(), placement.translation.copy(), jac.copy()))
    return out


def contact_jacobian(jac, origin, point):
    """The ``(3, nv)`` Jacobian of the tip link's point at ``point``: ``J_v - [p - o]_x J_omega``."""
    r = point - origin
    skew = np.array([[0, -r[2], r[1]], [r[2], 0, -r[0]], [-r[1], r[0], 0]])
    return jac[:3] - skew @ jac[3:]


def test_tip_centres_are_one_radius_behind_the_contacts_by_pinocchios_kinematics(model, grasp):
    m, d = model
    q = pin_q(m, grasp.hand, grasp.joint_positions)
    pin.forwardKinematics(m, d, q)
    for f, (_, origin, _) in enumerate(pin_tips(m, d, q)):
        np.testing.assert_allclose(origin, grasp.points[f] - 0.01 * grasp.normals[f], rtol=0, atol=1e-12)


def test_joint_rates_agree_with_pinocchios_contact_point_jacobians(model, grasp):
    """For the file's twists and 20 random ones: grasptwist's Jacobian at the contact point equals
    pinocchio's to 1e-12 m/rad, and the joint rates that move the contact with T(p) agree."""
    m, d = model
    hand = grasp.hand
    q = pin_q(m, hand, grasp.joint_positions)
    pin.forwardKinematics(m, d, q)
    tips = pin_tips(m, d, q)
    states = finger_states(hand, grasp.joint_positions)
    twists = np.vstack([t.screw for t in grasp.twists] + [np.random.default_rng(5).normal(size=(20, 6))])
    for f, finger in enumerate(hand.fingers):
        p = grasp.points[f]
        cols = [m.joints[m.getJointId(j.name)].idx_v for j in finger.joints]
        theirs = contact_jacobian(tips[f][2], tips[f][1], p)[:, cols]
        np.testing.assert_allclose(finger_jacobian(states[f].screws, p), theirs, rtol=0, atol=1e-12)
        velocity = twists[:, 3:] + np.cross(twists[:, :3], p)  # T(p) = v + omega x p
        ours = joint_rates(states[f].screws, p, velocity).rates
        np.testing.assert_allclose(ours, np.linalg.solve(theirs, velocity.T).T, rtol=1e-9, atol=0)


def test_inverse_kinematics_recovers_pinocchios_configurations(model, grasp):
    """Contacts made by pinocchio: at 30 random configurations within the limits, each tip
    sphere (10 mm) touches a point ``o + r n`` for a random direction ``n``; grasptwist, seeded
    0.05 rad away, finds the configurations again."""
    m, d = model
    hand = grasp.hand
    rng = np.random.default_rng(11)
    lower, upper = np.array([-0.33, 0.0, -2.7] * 3), np.array([1.0, 1.57, 0.0] * 3)
    want = rng.uniform(lower + 0.1, upper - 0.1, size=(30, 9))
    normals = rng.normal(size=(30, 3, 3))
    normals /= np.linalg.norm(normals, axis=-1, keepdims=True)
    points = np.empty((30, 3, 3))
    for k, qk in enumerate(want):
        pin.forwardKinematics(m, d, pin_q(m, hand, qk))
        origins = np.array([o for _, o, _ in pin_tips(m, d, pin_q(m, hand, qk))])
        points[k] = origins + 0.01 * normals[k]
    solved = hand_ik(hand, points - 0.01 * normals, seed=want + rng.uniform(-0.05, 0.05, want.shape))
    assert solved.ok.all()
    np.testing.assert_allclose(solved.positions, want, rtol=0, atol=1e-7)
