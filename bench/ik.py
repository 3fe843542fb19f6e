"""Inverse kinematics of 10^5 TriFinger Pro grasps: batched damped least squares against a loop.

``grasptwist.engine.ik.hand_ik`` solves every finger of every grasp at once
(numpy over the rows, a Python loop over fingers and iterations only), from
the home configuration, within the joints' limits.  The grasps' contacts
are the tip links' origins at random joint positions within the limits, so
every one is reachable.

The baseline, in this process, is a per-grasp loop over a general optimiser:
``scipy.optimize.least_squares`` (trust-region reflective, bounded by the
limits, given the analytic Jacobian) per finger, from the same seed and, while
it misses, the same spread seeds (:func:`~grasptwist.engine.ik.spread_seeds`), on
``--loop`` of the grasps, scaled to ``--n``.  The two must agree: both put
every tip on its contact (to ``IK_TOL`` of the finger's length for ours), and
where they end in the same configuration, to 1e-6 rad.

Run: ``python bench/ik.py [--n 100000] [--loop 300]``.  Needs yourdfpy,
robot-properties-fingers and scipy (the test extra).
"""

import argparse
import time

import numpy as np
from scipy.optimize import least_squares

from grasptwist.engine.ik import IK_TOL, hand_ik, joint_limits, spread_seeds
from grasptwist.engine.kinematics import finger_jacobian, forward_kinematics
from grasptwist.io.urdf import load_urdf_hand

URDF = "package://robot_properties_fingers/urdf/pro/trifingerpro.urdf"
TIPS = ["finger_tip_link_0", "finger_tip_link_120", "finger_tip_link_240"]


def grasps(h, n, seed=0):
    """``n`` grasps' contacts ``(n, 3, 3)``: the tips at random joint positions within the limits."""
    rng = np.random.default_rng(seed)
    points = np.empty((n, 3, 3))
    for f, finger in enumerate(h.fingers):
        lower, upper = joint_limits(finger)
        q = rng.uniform(lower, upper, (n, len(lower)))
        points[:, f] = forward_kinematics(finger.screws, finger.points, finger.tip_pose, q).tip[:, :3, 3]
    return points


def scipy_finger(finger, target, seed):
    """One finger's inverse kinematics by ``least_squares`` from ``seed``, then (while it misses) from
    the same spread seeds as ours, nearest first: its positions and tip error."""
    spread = spread_seeds(finger)
    order = np.argsort(np.linalg.norm(spread - seed, axis=-1))
    best = None
    for start in (seed, *spread[order]):
        got = _least_squares(finger, target, start)
        if best is None or got[1] < best[1]:
            best = got
        if best[1] <= IK_TOL * finger.length:
            break
    return best


def _least_squares(finger, target, seed):
    lower, upper = joint_limits(finger)
    chain = (finger.screws, finger.points, finger.tip_pose)

    def residual(q):
        return forward_kinematics(*chain, q).tip[:3, 3] - target

    def jacobian(q):
        state = forward_kinematics(*chain, q)
        return finger_jacobian(state.screws, state.tip[:3, 3])

    r = least_squares(
        residual, np.clip(seed, lower, upper), jac=jacobian, bounds=(lower, upper), ftol=1e-15, xtol=1e-15, gtol=1e-15
    )
    return r.x, float(np.linalg.norm(r.fun))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=100_000)
    parser.add_argument("--loop", type=int, default=300, help="grasps the scipy loop solves (then scaled)")
    args = parser.parse_args()
    h = load_urdf_hand(URDF, TIPS)
    points = grasps(h, args.n)

    start = time.perf_counter()
    ours = hand_ik(h, points)
    batched = time.perf_counter() - start

    start = time.perf_counter()
    loop_q = np.empty((args.loop, 9))
    loop_error = np.empty((args.loop, 3))
    for i in range(args.loop):
        for f, finger in enumerate(h.fingers):
            index = list(finger.joint_index)
            loop_q[i, index], loop_error[i, f] = scipy_finger(finger, points[i, f], np.zeros(3))
    looped = (time.perf_counter() - start) * args.n / args.loop

    length = np.array([f.length for f in h.fingers])
    reached = ours.tip_error <= IK_TOL * length
    print(f"batched hand_ik, {args.n} grasps: {batched:.2f} s ({batched / args.n * 1e6:.1f} us a grasp)")
    print(f"scipy least_squares loop, {args.loop} grasps scaled to {args.n}: {looped:.1f} s")
    print(f"ratio: {looped / batched:.0f}x")
    print(
        f"ours: {reached.all(axis=-1).mean():.2%} of grasps with every tip within {IK_TOL:g} L, "
        f"largest tip error {ours.tip_error.max():.2e} m, all within limits: {bool(ours.within_limits.all())}"
    )
    ok = loop_error <= IK_TOL * length
    print(f"scipy: {ok.all(axis=-1).mean():.2%} of its {args.loop} grasps with every tip within {IK_TOL:g} L")
    same = np.abs(ours.positions[: args.loop] - loop_q).max(axis=-1) < 1e-6
    print(f"same configuration (to 1e-6 rad) on {same.mean():.1%} of those grasps", end="")
    if not same.all():
        print(
            f"; the others both on the contacts (largest tip error ours "
            f"{ours.tip_error[: args.loop][~same].max():.1e} m, scipy {loop_error[~same].max():.1e} m), another branch",
            end="",
        )
    print()


if __name__ == "__main__":
    main()
