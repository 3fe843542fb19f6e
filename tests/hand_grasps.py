"""Two hand grasps for the joint-rate tests (and, later, the bundled grasp files).

* :func:`trifinger_cube` -- the TriFinger Pro (robot-properties-fingers) holding
  a 65 mm cube on its table by three side faces, each touched by a fingertip
  sphere (radius 10 mm, centred on the tip link's origin);
* :func:`three_finger_hand` -- three 3R fingers (yaw at the knuckle, then two
  flexion joints) hanging from a palm around a cube of side 2.

Each returns a dict with the keys of a grasp file (``contacts`` as points and
normals into the object, ``wrist``, ``twists``) and the hand.
"""

import numpy as np

from grasptwist.engine.kinematics import joint_screw

TRIFINGER_URDF = "package://robot_properties_fingers/urdf/pro/trifingerpro.urdf"
TRIFINGER_TIPS = ("finger_tip_link_0", "finger_tip_link_120", "finger_tip_link_240")
#: The fingertip mesh (tip_sim.stl) is a sphere of this radius about the tip link's origin.
TRIFINGER_TIP_RADIUS = 0.01
#: The cube of the TriFinger challenges: 65 mm, on the table (z = 0), centred on the arena.
CUBE_HALF = 0.0325


def trifinger_cube():
    """The TriFinger Pro's three fingertips on faces +x, -y and -x of the cube.

    Each finger reaches its face from its own side (the fingers' bases are at
    about 30, -90 and 150 degrees around the vertical axis); the contacts are
    at different heights so that neither method is degenerate (conditioning
    0.49 off-tangent, 0.11 tangent).  The joint positions put each tip
    sphere's centre at ``contact - radius * normal`` (solved by Newton's method
    on the forward kinematics, to 1e-16 m); all are within the joints' limits.
    The wrist is the point where the three fingers' base joints meet, the
    upper holder's origin 0.29 m above the table.
    """
    h = CUBE_HALF
    names = [
        f"finger_{part}_joint_{angle}"
        for angle in (0, 120, 240)
        for part in ("base_to_upper", "upper_to_middle", "middle_to_lower")
    ]
    positions = [
        0.181390037, 0.5904426439, -1.4828803827,
        0.19893411, 0.5545414034, -1.3054491805,
        0.2399650693, 0.5570307797, -1.2184725163,
    ]  # fmt: skip
    return {
        "urdf": TRIFINGER_URDF,
        "tips": TRIFINGER_TIPS,
        "joint_positions": dict(zip(names, positions)),
        "points": np.array([[h, 0.015, 0.045], [0.005, -h, 0.025], [-h, 0.0, 0.015]]),
        "normals": np.array([[-1.0, 0, 0], [0, 1.0, 0], [1.0, 0, 0]]),
        "wrist": np.array([0, 0, 0.29]),
        "twists": {
            # turn the cube about the vertical through its centre, 0.5 rad/s
            "spin": np.array([0, 0, 0.5, 0, 0, 0]),
            # lift it at 2 cm/s while tilting it about x through its centre
            "lift-tilt": np.array([0.3, 0, 0, 0, -0.3 * h, 0.02]),
        },
    }


def three_finger_hand():
    """Three 3R fingers around the cube ``[-1, 1]^3``, on faces +x, -x and -y.

    Finger ``f`` touching ``c`` on the face with outward normal ``o`` has its
    knuckle ``b = c + o + 2 z`` and middle joint ``k = c + o``: joint 1 turns
    about the vertical through ``b`` (spread), joints 2 and 3 about the
    horizontal ``z x o`` through ``b`` and ``k`` (flexion).  Its Jacobian at ``c``
    has columns ``-(z x o)``, ``z - 2 o`` and ``z``: rank 3.  Velocity limits
    2, 2 and 3 (rad per unit time).  The wrist is above the palm.
    """
    points = np.array([[1.0, 0.3, 0.4], [-1.0, -0.2, -0.1], [0.2, -1.0, -0.5]])
    outward = np.array([[1.0, 0, 0], [-1.0, 0, 0], [0, -1.0, 0]])
    up = np.array([0, 0, 1.0])
    fingers = []
    for c, o in zip(points, outward):
        knuckle, middle, flex = c + o + 2 * up, c + o, np.cross(up, o)
        fingers.append(
            [
                {"axis": up, "point": knuckle, "velocity_limit": 2.0},
                {"axis": flex, "point": knuckle, "velocity_limit": 2.0},
                {"axis": flex, "point": middle, "velocity_limit": 3.0},
            ]
        )
    return {
        "fingers": fingers,
        "points": points,
        "normals": -outward,
        "wrist": np.array([0, 0, 3.0]),
        # roll the cube about x through its centre while pushing it along y
        "twists": {"roll-push": np.array([0.4, 0, 0.1, 0, 0.2, 0])},
    }


def inline_screws(finger):
    """The ``(n, 6)`` joint screws of an inline finger (list of joint dicts)."""
    return np.array([joint_screw(j["axis"], j["point"], j.get("type") == "prismatic") for j in finger])
