"""Following a path: ``grasptwist.path.follow`` against a Python loop over the samples.

Run: ``python bench/follow.py [--samples 10000] [--grasps 1000]``.  Both sides
compute the same things for every sample and grasp on a three-segment path
(a space twist, a body twist, a pose target): the moved contacts and
normals, both decompositions (``bases=False``) and the contact velocities.
The loop calls the public engine once per sample, on all the grasps moved
to that sample's pose (the poses come from ``integrate`` for both).  A second
case is one grasp over the same samples, the ``follow`` command's usual load.
Both sides hand each result to the same consumer and let it go, ``follow`` a
chunk of ``--chunk`` samples at a time (as the ``follow`` command does), so
memory is bounded whatever the number of samples.  Peak memory is that of a
fresh process running the chunked ``follow`` alone.

The loop already resolves the 1,000 grasps of a sample in one engine call, so
the ratio is bounded by what ``follow`` can skip: the tangent method and the
contact velocities see no wrist, so ``follow`` resolves them once per segment
on the grasp at rest and carries them by each pose; the off-tangent method
sees the wrist move and costs an engine row per sample and grasp, as in the
loop.  What remains is that, and writing the moved grasps.
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


class Kept:
    """The consumer: keeps sample ``k``'s amplitudes to compare the two sides, drops the rest."""

    def __init__(self, k):
        self.k, self.rows = k, 0

    def take(self, first, off, tan):
        """Results of samples ``first, first + 1, ...`` (leading axis)."""
        n = len(off.x)
        self.rows += off.x.size // 3
        if first <= self.k < first + n:
            i = self.k - first
            self.x, self.alpha = off.x[i].copy(), tan.alpha[i].copy()
            self.well = (off.conditioning[i] > 1e-3) & (tan.conditioning[i] > 1e-3)


def chunked(points, normals, wrist, times, chunk):
    """``follow`` over the samples, ``chunk`` at a time."""
    kept = Kept(len(times) // 2)
    for first in range(0, len(times), chunk):
        f = follow(points, normals, wrist, PATH, times[first : first + chunk])
        kept.take(first, f.off_tangent, f.tangent)
    return kept


def loop(points, normals, wrist, times):
    """One engine call per sample, as a user without ``follow`` would write it."""
    kept = Kept(len(times) // 2)
    poses = integrate(PATH, times)
    for i, (r, x, twist) in enumerate(zip(poses.rotation, poses.position, poses.twist)):
        moved, turned = se3.transform(r, x, points), se3.rotate(r, normals)
        off = gt.decompose_off_tangent(moved, wrist, twist, bases=False)
        tan = gt.decompose_tangent(moved, turned, twist, bases=False)
        gt.contact_velocities(moved, twist)
        kept.take(i, off.row(None), tan.row(None))
    return kept


def timed(fn, *args):
    t0 = time.perf_counter()
    out = fn(*args)
    return time.perf_counter() - t0, out


def peak_memory_mib(samples, grasps, chunk):
    """Peak resident memory of a fresh process that builds the data and runs the chunked ``follow``."""
    subprocess.run([sys.executable, __file__, "--child", str(samples), str(grasps), str(chunk)], check=True)
    return resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=10_000)
    ap.add_argument("--grasps", type=int, default=1_000)
    ap.add_argument("--chunk", type=int, default=256, help="samples per follow call")
    ap.add_argument("--child", type=int, nargs=3, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        points, normals, wrist, _ = grasp_arrays(args.child[1])
        chunked(points, normals, wrist, np.linspace(0, 3, args.child[0]), args.child[2])
        return
    peak = peak_memory_mib(args.samples, args.grasps, args.chunk)
    points, normals, wrist, _ = grasp_arrays(args.grasps)
    times = np.linspace(0, 3, args.samples)
    t_follow, a = timed(chunked, points, normals, wrist, times, args.chunk)
    t_loop, b = timed(loop, points, normals, wrist, times)
    # the same numbers to round-off where well conditioned (follow moves the grasps by one matrix
    # product and solves the tangent method at rest), and the same failures
    assert a.rows == b.rows and np.array_equal(a.well, b.well)
    for mine, theirs in ((a.x, b.x), (a.alpha, b.alpha)):
        assert np.allclose(mine[a.well], theirs[a.well], rtol=1e-9, atol=1e-12)
        assert np.array_equal(np.isnan(mine), np.isnan(theirs))
    t_one, _ = timed(chunked, points[:1], normals[:1], wrist[:1], times, args.samples)
    t_one_loop, _ = timed(loop, points[:1], normals[:1], wrist[:1], times)
    rows = args.samples * args.grasps
    print(f"{args.samples:,} samples x {args.grasps:,} grasps = {rows:,} rows, both methods + contact velocities")
    print(
        f"{'follow, ' + str(args.chunk) + ' samples a call':34s} {t_follow:8.2f} s  ({t_follow / rows * 1e9:.0f} ns per row)"
    )
    print(
        f"{'loop over samples (engine per sample)':34s} {t_loop:8.2f} s  ratio {t_loop / t_follow:.1f}x (target >= 20)"
    )
    print(f"one grasp x {args.samples:,} samples:")
    print(f"{'follow':34s} {t_one:8.3f} s")
    print(f"{'loop over samples':34s} {t_one_loop:8.3f} s  ratio {t_one_loop / t_one:.0f}x")
    print(f"{'peak memory, chunked follow':34s} {peak:8.0f} MiB")


if __name__ == "__main__":
    main()
