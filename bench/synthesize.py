"""Grasp synthesis speed: candidate triples fully scored per second, against a same-run baseline.

Run: ``python bench/synthesize.py [--candidates 100000] [--baseline 2000] [--memory]``.

The object is the TriFinger challenges' 65 mm cube of 100 g, ``mu = 0.8``, held against its
weight with closure required (no hand).  Two ways, in the same run:

- **the search** (:func:`grasptwist.engine.synthesis.search.synthesize`): candidates scored in
  chunks (degeneracy and conditioning, closure at ``mu``, then the batched grip), the best
  refined on the surface, every grasp returned verified by the exact grip;
- **the baseline**, the TriFinger challenge code's way: three random surface points a candidate,
  each scored on its own (its closure by ``gt.forces.force_closure``, its grip by one ``gt.grip``
  call), ``--baseline`` candidates, scaled; and the grip alone, one call a candidate, without
  the closure test (``force_closure`` bisects for the least friction: the slower part).

Both figures are candidates fully scored per second of wall time.  ``--memory`` also runs the
search at 10x and 100x fewer candidates and prints the peak resident memory of each (a fresh
process each): flat in the number of candidates, as the chunks are.
"""

import argparse
import resource
import subprocess
import sys
import time

import numpy as np

import grasptwist as gt
from grasptwist.engine.forces.hold import hold_wrench
from grasptwist.engine.objects import sample_surface
from grasptwist.engine.synthesis.search import synthesize
from grasptwist.model import GraspObject, Shape

CUBE = GraspObject(Shape("box", np.full(3, 0.065)), np.eye(4), mass=0.1)
MU = 0.8


def search(candidates, seed=0):
    t = time.perf_counter()
    s = synthesize(CUBE, MU, count=5, candidates=candidates, seed=seed, min_conditioning=1e-3)
    return s, time.perf_counter() - t


def baseline(candidates, seed=0, closure=True):
    """Random triples, one engine call each (closure, then the grip): the best total normal force."""
    rng = np.random.default_rng(seed)
    weight = hold_wrench(0.1, np.zeros(3), np.array([0, 0, -9.81]))
    best = np.inf
    t = time.perf_counter()
    for _ in range(candidates):
        p, n = sample_surface(CUBE, 3, rng)
        if closure and not gt.forces.force_closure(p, n, MU).force_closure:
            continue
        g = gt.grip(p, n, weight, MU)
        if g.ok:
            best = min(best, float(g.total_normal_force))
    return best, time.perf_counter() - t


def peak_mb(candidates):
    """The peak resident memory of a fresh process that runs one search (``--peak``)."""
    out = subprocess.run(
        [sys.executable, __file__, "--peak", str(candidates)], capture_output=True, text=True, check=True
    )
    return float(out.stdout.split()[-1])


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--candidates", type=int, default=100_000)
    parser.add_argument("--baseline", type=int, default=2000)
    parser.add_argument("--memory", action="store_true")
    parser.add_argument("--peak", type=int, help=argparse.SUPPRESS)  # one search, then its peak memory in MB
    args = parser.parse_args()
    if args.peak:
        search(args.peak)
        print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024)
        return
    search(500)  # the compiled grip loaded (or compiled) before any timing
    s, seconds = search(args.candidates)
    rate = s.candidates / seconds
    print(f"search:   {s.candidates} candidates in {seconds:.2f} s: {rate:,.0f} a second")
    print(
        f"          best total normal force {s.total_normal_force[0, 0]:.4f} N (weight 0.981 N), {len(s.points)} grasps"
    )
    best, base_seconds = baseline(args.baseline)
    base_rate = args.baseline / base_seconds
    print(f"baseline: {args.baseline} candidates in {base_seconds:.2f} s: {base_rate:,.0f} a second")
    print(f"          best total normal force {best:.4f} N")
    print(f"speed-up: {rate / base_rate:.0f}x")
    best, grip_seconds = baseline(args.baseline, closure=False)
    grip_rate = args.baseline / grip_seconds
    print(f"the grip alone (no closure test), one call a candidate: {grip_rate:,.0f} a second: {rate / grip_rate:.1f}x")
    if args.memory:
        for n in (args.candidates // 100, args.candidates // 10, args.candidates):
            print(f"peak memory, {n} candidates: {peak_mb(n):.0f} MB")


if __name__ == "__main__":
    main()
