"""Following a path: ``grasptwist.path.follow`` against a Python loop over the samples.

Run: ``python bench/follow.py [--samples 10000] [--grasps 1000]``.  Both sides
compute the same things for every sample and grasp on a three-segment path
(a space twist, a body twist, a pose target): the moved contacts and
normals, both decompositions (``bases=False``) and the contact velocities.
The loop calls the public engine once per sample, on all the grasps moved
to that sample's pose (the poses come from ``integrate`` for both).  A second
case is one grasp over the same samples, the ``follow`` command's usual load.
Peak memory is that of a fresh process running ``follow`` alone.
"""

import argparse
import resource
import subprocess
import sys
import time

import numpy as np

import grasptwist as gt
from _data import grasp_arrays
from grasptwist.engine import se3
from grasptwist.path import Segment, follow, integrate

PATH = [
    Segment(1.0, twist=[0, 0, 1.5, 0.1, 0, 0.2]),
    Segment(1.0, twist=[0.4, -0.3, 0, 0, 0.1, 0], frame="body"),
    Segment(1.0, position=[0, 0, 0.3], rotation=se3.rotvec_to_matrix([0.5, 0, 0.2])),
]


def loop(points, normals, wrist, times):
    """One engine call per sample, as a user without ``follow`` would write it."""
    poses = integrate(PATH, times)
    out = []
    for r, x, twist in zip(poses.rotation, poses.position, poses.twist):
        moved, turned = se3.transform(r, x, points), se3.rotate(r, normals)
        out.append(
            (
                gt.decompose_off_tangent(moved, wrist, twist, bases=False),
                gt.decompose_tangent(moved, turned, twist, bases=False),
                gt.contact_velocities(moved, twist),
            )
        )
    return out


def timed(fn, *args):
    t0 = time.perf_counter()
    out = fn(*args)
    return time.perf_counter() - t0, out


def peak_memory_mib(samples, grasps):
    """Peak resident memory of a fresh process that builds the data and runs ``follow`` once."""
    subprocess.run([sys.executable, __file__, "--child", str(samples), str(grasps)], check=True)
    return resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=10_000)
    ap.add_argument("--grasps", type=int, default=1_000)
    ap.add_argument("--child", type=int, nargs=2, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        points, normals, wrist, _ = grasp_arrays(args.child[1])
        follow(points, normals, wrist, PATH, np.linspace(0, 3, args.child[0]))
        return
    peak = peak_memory_mib(args.samples, args.grasps)
    points, normals, wrist, _ = grasp_arrays(args.grasps)
    times = np.linspace(0, 3, args.samples)
    t_follow, f = timed(follow, points, normals, wrist, PATH, times)
    k = args.samples // 2  # a sample to check that both sides computed the same numbers
    x, alpha = f.off_tangent.x[k].copy(), f.tangent.alpha[k].copy()
    del f  # one side's results in memory at a time
    t_loop, rows = timed(loop, points, normals, wrist, times)
    assert np.array_equal(x, rows[k][0].x, equal_nan=True) and np.array_equal(alpha, rows[k][1].alpha, equal_nan=True)
    del rows
    t_one, _ = timed(follow, points[0], normals[0], wrist[0], PATH, times)
    t_one_loop, _ = timed(loop, points[0], normals[0], wrist[0], times)
    rows = args.samples * args.grasps
    print(f"{args.samples:,} samples x {args.grasps:,} grasps = {rows:,} rows, both methods + contact velocities")
    print(f"{'follow':34s} {t_follow:8.2f} s  ({t_follow / rows * 1e9:.0f} ns per row)")
    print(
        f"{'loop over samples (engine per sample)':34s} {t_loop:8.2f} s  ratio {t_loop / t_follow:.1f}x (target >= 20)"
    )
    print(f"one grasp x {args.samples:,} samples:")
    print(f"{'follow':34s} {t_one:8.3f} s")
    print(f"{'loop over samples':34s} {t_one_loop:8.3f} s  ratio {t_one_loop / t_one:.0f}x")
    print(f"{'peak memory, follow process':34s} {peak:8.0f} MiB")


if __name__ == "__main__":
    main()
