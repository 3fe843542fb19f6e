"""Force-side speed: the batched engine against a per-grasp loop over Clarabel, on the same grasps.

Run: ``python bench/forces.py [--n 100000] [--loop 2000] [--epsilon 200]``.

Grasps: three contacts near a unit ball's equator, normals towards its centre tilted at
random, one friction per grasp (0.4..1), the wrench that holds a 0.2..2 kg weight plus a
disturbing moment.  The engine does ``gt.forces.grip`` (least total normal force, safety 1.5) and
``gt.forces.force_closure`` (closure friction and the verdict with the grasp's friction, no
epsilon) for all ``n`` at once.  The loop does the same with Clarabel for the first
``--loop`` grasps and is scaled to ``n``: the least grip is one solve on the nine
contact-force numbers; the closure friction is a bisection on ``mu`` of closure-margin
solves (tests/conic.py), since it is not itself a conic program.  Both ratios are
printed (grip alone, and grip + closure), with the largest differences on the loop's
grasps, and epsilon's cost per grasp (one Qhull call each).
"""

import argparse
import pathlib
import sys
import time

import numpy as np

import grasptwist as gt

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "tests"))
from conic import closure_friction, least_grip  # noqa: E402

SAFETY = 1.5


def grasps(n, seed=0):
    rng = np.random.default_rng(seed)
    angle = rng.uniform(0, 2 * np.pi, (n, 1)) + np.array([0, 2.1, 4.2]) + rng.normal(0, 0.3, (n, 3))
    p = np.stack((np.cos(angle), np.sin(angle), rng.normal(0, 0.3, (n, 3))), axis=-1)
    normals = -p + rng.normal(0, 0.3, (n, 3, 3))
    mass = rng.uniform(0.2, 2.0, n)
    wrench = np.concatenate((np.zeros((n, 2)), 9.81 * mass[:, None], rng.normal(0, 0.5, (n, 3))), axis=1)
    friction = rng.uniform(0.4, 1.0, (n, 1))
    return p, normals, wrench, friction


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=100_000)
    ap.add_argument("--loop", type=int, default=2000)
    ap.add_argument("--epsilon", type=int, default=200)
    args = ap.parse_args()
    p, n, w, mu = grasps(args.n)

    t0 = time.perf_counter()
    g = gt.forces.grip(p, n, w, mu, SAFETY)
    t1 = time.perf_counter()
    c = gt.forces.force_closure(p, n, mu)
    t2 = time.perf_counter()
    engine_grip, engine_closure = t1 - t0, t2 - t1
    held = g.ok.mean()
    print(
        f"engine, {args.n} grasps: grip {engine_grip:.2f} s, closure {engine_closure:.2f} s "
        f"({1e6 * (t2 - t0) / args.n:.1f} us a grasp); held {held:.1%}, force closure {c.force_closure.mean():.1%}"
    )

    k = args.loop
    t0 = time.perf_counter()
    ref_grip = [least_grip(p[i], n[i], w[i], mu[i], SAFETY)[0] for i in range(k)]
    t1 = time.perf_counter()
    ref_closure = np.array([closure_friction(p[i], n[i]) for i in range(k)])
    t2 = time.perf_counter()
    loop_grip, loop_closure = (t1 - t0) * args.n / k, (t2 - t1) * args.n / k
    print(
        f"Clarabel loop, {k} grasps scaled to {args.n}: grip {loop_grip:.1f} s, closure {loop_closure:.1f} s "
        f"({1e3 * (t2 - t0) / k:.2f} ms a grasp)"
    )
    print(
        f"ratio: grip {loop_grip / engine_grip:.0f}x, grip + closure {(loop_grip + loop_closure) / (engine_grip + engine_closure):.0f}x"
    )

    solved = np.array([r is not None for r in ref_grip])
    same = (g.ok[:k] == solved).mean()
    rel = np.abs(g.total_normal_force[:k][solved] / np.array([r for r in ref_grip if r is not None]) - 1).max()
    finite = np.isfinite(ref_closure)
    crel = np.abs(c.closure_friction[:k][finite] / ref_closure[finite] - 1).max()
    cnan = (np.isnan(c.closure_friction[:k]) == ~finite).mean()
    ok = g.ok
    made = np.concatenate((g.force[ok].sum(axis=1), np.cross(p[ok], g.force[ok]).sum(axis=1)), axis=1)
    print(
        f"agreement on the loop's grasps: held/cannot-hold {same:.2%}, total normal force max rel diff {rel:.1e}; "
        f"closure friction max rel diff {crel:.1e}, none-ness {cnan:.2%}"
    )
    print(
        f"all {args.n}: wrench reproduced to {np.abs(made - w[ok]).max() / np.abs(w).max():.1e} (relative), "
        f"largest friction_used / (mu / safety) {(g.friction_used[ok] / (mu[ok] / SAFETY)).max():.12f}"
    )

    m = args.epsilon
    t0 = time.perf_counter()
    e = gt.forces.force_closure(p[:m], n[:m], mu[:m], quality=True)
    t1 = time.perf_counter()
    print(
        f"epsilon (quality=True, 8 edges), {m} grasps: {1e3 * (t1 - t0) / m:.2f} ms a grasp; "
        f"median {np.median(e.epsilon[e.force_closure]):.3f} over those in closure"
    )


if __name__ == "__main__":
    main()
