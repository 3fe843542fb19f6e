"""Joint rates of the TriFinger Pro at 10^5 configurations, data set to npz.

``grasptwist resolve rows.npz --hand trifinger.yaml -f npz -o out.npz`` (the
command, start-up included): per row forward kinematics from the data set's
``joint_positions``, joint rates, rank, residual, conditioning and
velocity-limit ratio, and the tangent decomposition on top.  The contacts
are on the fingertip spheres.

Run: ``python bench/hand.py [--n 100000] [--loop 2000]``.  The baseline, in
this process, is a plain loop over yourdfpy's own forward kinematics
(``update_cfg`` + ``get_transform``) and ``numpy.linalg.lstsq`` per finger, on
``--loop`` of the rows, scaled to ``--n``.  Target: at least 20x faster.
Needs yourdfpy and robot-properties-fingers (the test extra).
"""

import argparse
import os
import tempfile
import time

import numpy as np
import yourdfpy

from _data import grasptwist_command, timed
from grasptwist import hand
from grasptwist.io.urdf import resolve_urdf

URDF = "package://robot_properties_fingers/urdf/pro/trifingerpro.urdf"
TIPS = ["finger_tip_link_0", "finger_tip_link_120", "finger_tip_link_240"]
#: The fingertip sphere's radius (its mesh is a 10 mm sphere about the tip link's origin).
TIP_RADIUS = 0.01


def configurations(h, n, seed=0):
    """``n`` joint positions within the joints' limits, and an object twist per row."""
    rng = np.random.default_rng(seed)
    joints = [j for f in h.fingers for j in f.joints]
    lower = np.array([j.lower for j in joints])
    upper = np.array([j.upper for j in joints])
    return rng.uniform(lower, upper, (n, len(joints))), rng.normal(size=(n, 6)) * [1, 1, 1, 0.1, 0.1, 0.1]


def contact(tip):
    """The contact on the fingertip sphere: its lowest point in the tip link's frame."""
    return tip[..., :3, 3] - TIP_RADIUS * tip[..., :3, 2]


def data_set(h, q, twist, folder):
    """The rows as a data set (contacts on the tip spheres) and the hand file, for the command."""
    states = hand.finger_states(h, q)
    points = np.stack([contact(s.tip) for s in states], axis=1)
    normals = np.stack([s.tip[..., :3, 2] for s in states], axis=1)  # into the object, below each tip
    rows = os.path.join(folder, "rows.npz")
    np.savez(rows, points=points, normals=normals, twist=twist, joint_positions=q)
    hand_file = os.path.join(folder, "trifinger.yaml")
    with open(hand_file, "w") as f:
        f.write(f"hand:\n  urdf: {URDF}\n  fingers:\n" + "".join(f"    - {{tip: {t}}}\n" for t in TIPS))
    return rows, hand_file, points


def command(rows, hand_file, out):
    """``grasptwist resolve`` of the data set to npz: its best time and joint rates."""
    seconds = timed([*grasptwist_command(), "resolve", rows, "--hand", hand_file, "-f", "npz", "-o", out], 2)
    with np.load(out) as z:
        return seconds, z["joint_rates"]


def loop(h, robot, q, twist):
    """Joint rates and their verdicts per row with yourdfpy's forward kinematics and numpy.linalg.lstsq."""
    t0 = time.perf_counter()
    rates = np.empty_like(q)
    for row in range(len(q)):
        robot.update_cfg(q[row])
        for finger, tip in zip(h.fingers, TIPS):
            p = contact(robot.get_transform(tip))
            columns = []
            for joint in finger.joints:
                spec = robot.joint_map[joint.name]
                frame = robot.get_transform(spec.child)
                axis = frame[:3, :3] @ spec.axis
                columns.append(np.cross(axis, p - frame[:3, 3]))
            jac = np.array(columns).T
            velocity = twist[row, 3:] + np.cross(twist[row, :3], p)
            qdot, _, rank, s = np.linalg.lstsq(jac, velocity, rcond=None)
            rates[row, list(finger.joint_index)] = qdot
            residual = np.linalg.norm(jac @ qdot - velocity) / np.linalg.norm(velocity)
            conditioning = s[-1] / s[0] if rank == 3 else 0.0
            limits = hand.velocity_limits(finger)
            ratio = np.max(np.abs(qdot) / limits)
            del residual, conditioning, ratio  # computed, as the vectorised run does
    return time.perf_counter() - t0, rates


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=100_000)
    ap.add_argument("--loop", type=int, default=2_000)
    args = ap.parse_args()
    h = hand.load_urdf_hand(URDF, TIPS)
    robot = yourdfpy.URDF.load(str(resolve_urdf(URDF)), build_scene_graph=True, load_meshes=False)
    q, twist = configurations(h, args.n)
    with tempfile.TemporaryDirectory() as tmp:
        rows, hand_file, _ = data_set(h, q, twist, tmp)
        out = os.path.join(tmp, "out.npz")
        t_fast, fast = command(rows, hand_file, out)
        size = os.path.getsize(out)
    m = min(args.loop, args.n)
    t_loop, slow = loop(h, robot, q[:m], twist[:m])
    t_scaled = t_loop * args.n / m
    agree = np.max(np.abs(fast[:m] - slow)) / np.max(np.abs(slow))
    print(f"rows: {args.n}  (npz {size / 1e6:.1f} MB)")
    print(f"grasptwist resolve rows.npz --hand -f npz: {t_fast:.3f} s  ({t_fast / args.n * 1e6:.2f} us/row)")
    print(f"yourdfpy + lstsq loop: {t_loop:.2f} s for {m} rows, scaled {t_scaled:.1f} s")
    print(f"largest relative difference of the rates: {agree:.1e}")
    print(f"speed-up: {t_scaled / t_fast:.0f}x  (target >= 20x)")


if __name__ == "__main__":
    main()
