"""Grasp synthesis speed: candidate triples fully scored per second, against a same-run baseline.

Run: ``python bench/synthesize.py [--candidates 100000] [--baseline 2000] [--memory] [--hand]``.

The object is the TriFinger challenges' 65 mm cube of 100 g, ``mu = 0.8``, held against its
weight with closure required (no hand).  Two ways, in the same run:

- **the search** (:func:`grasptwist.engine.synthesis.search.synthesize`): candidates scored in
  chunks (degeneracy and conditioning, closure at ``mu``, then the batched grip), the best
  refined on the surface, every grasp returned verified by the exact grip;
- **the baseline**, the TriFinger challenge code's way: three random surface points a candidate,
  each scored on its own (its closure by ``gt.forces.force_closure``, its grip by one ``gt.grip``
  call), ``--baseline`` candidates, scaled; and the grip alone, one call a candidate, without
  the closure test (``force_closure`` bisects for the least friction: the slower part).

Both figures are candidates fully scored per second of wall time.

``--hand`` (needs ``robot-properties-fingers`` and the ``urdf`` extra) measures verified
grasps per second with the TriFinger Pro (its fingertip spheres of 10 mm, joint limits and
link meshes) on the same cube where ``grasps/trifinger-cube.yaml`` puts it, on its table:

- **the search** with the hand: ``--hand-grasps`` grasps wanted, every one reached within the
  joint limits (inverse kinematics over the finger assignments), fingertips on the surface, no
  finger link in the cube, and verified (the exact grip; the tips again by forward kinematics);
- **the baseline**, the TriFinger code's way, for ``--hand-baseline`` grasps: up to 40 tries a
  grasp, each three random surface points, closure with a square pyramid (Ferrari-Canny's
  epsilon over 4 cone edges > 0), the six finger assignments through the inverse kinematics one
  at a time until one reaches, then the collision check;
- **robustness**: the search ranked by robustness (``objective="robust"``, the default: 64
  perturbations of each finalist, batched) against the same search ranked by the least total
  normal force (robustness then only on the grasps returned), in CPU seconds;
- **the command line**: ``grasptwist synthesize grasps/trifinger-cube.yaml -n 20`` in a fresh
  process, with ``--hand-candidates`` (the synthesis guide's 4,000) and with the default 20,000,
  its wall and CPU seconds (start-up, the URDF and its meshes, numba's cache included; grasptwist
  byte-compiled first, as an install leaves it).

Every figure with its CPU time beside the wall time (the machine may be shared).  ``--memory``
also runs the search at 10x and 100x fewer candidates and prints the peak resident memory of each
(a fresh process each): flat in the number of candidates, as the chunks are.
"""

import argparse
import resource
import subprocess
import sys
import time

import numpy as np

import grasptwist as gt
from _data import byte_compiled
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


def trifinger():
    """The bundled TriFinger grasp file's grasp, its cube on its table (100 g: :func:`hand_search`'s ``mass``)."""
    return gt.read_grasps("grasps/trifinger-cube.yaml")[0]


def hand_search(grasp, count, candidates, seed=0, objective="robust"):
    """The search with the hand, as the command line makes it (``gt.synthesize`` of the grasp: its
    hand's link meshes, the fingers against each other, its table; the default options):
    ``(Synthesis, wall seconds, CPU seconds)``."""
    t, cpu = time.perf_counter(), time.process_time()
    s = gt.synthesize(grasp, MU, mass=0.1, count=count, candidates=candidates, seed=seed, objective=objective)
    return s, time.perf_counter() - t, time.process_time() - cpu


def command_line(count, candidates=None):
    """``grasptwist synthesize`` of the TriFinger cube on its table in a fresh process (the synthesis
    guide's command; ``candidates`` None: the default): ``(wall, CPU seconds)``."""
    args = ["grasps/trifinger-cube.yaml", "--friction", str(MU), "--mass", "0.1", "-n", str(count)]
    args += [] if candidates is None else ["--candidates", str(candidates)]
    args += ["-f", "jsonl", "-q"]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t = time.perf_counter()
    subprocess.run([sys.executable, "-m", "grasptwist", "synthesize", *args], capture_output=True, check=True)
    wall = time.perf_counter() - t
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)


def hand_baseline(grasp, wanted, seed=0, tries=40):
    """The TriFinger code's way (module docstring): grasps found, tries spent."""
    from dataclasses import replace
    from itertools import permutations

    rng = np.random.default_rng(seed)
    radii = gt.hand.tip_radii(grasp.hand)
    found = spent = 0
    t = time.perf_counter()
    for _ in range(wanted):
        for _ in range(tries):
            spent += 1
            p, n = sample_surface(grasp.object, 3, rng)
            if not gt.forces.force_closure(p, n, MU, quality=True, cone_edges=4).epsilon > 0:
                continue
            for order in permutations(range(3)):
                ik = gt.hand.hand_ik(grasp.hand, gt.hand.tip_centers(p[list(order)], n[list(order)], radii))
                if ik.ok:
                    break
            else:
                continue
            placed = replace(grasp, points=p[list(order)], normals=n[list(order)])
            if not gt.finger_collisions(placed, ik.positions):
                found += 1
                break
    return found, spent, time.perf_counter() - t


def hand_bench(args):
    grasp = trifinger()
    hand_search(grasp, 2, 300)  # the compiled grip and the link meshes loaded before any timing
    s, seconds, cpu = hand_search(grasp, args.hand_grasps, args.hand_candidates)
    rate = len(s.points) / seconds
    print(
        f"search with the hand:  {len(s.points)} verified grasps in {seconds:.2f} s ({cpu:.2f} s CPU): "
        f"{rate:.1f} a second, {len(s.points) / cpu:.1f} a CPU second "
        f"({s.candidates} candidates; largest tip error {np.max(s.reach_error):.1e} m)"
    )
    _, plain_seconds, plain_cpu = hand_search(
        grasp, args.hand_grasps, args.hand_candidates, objective="total_normal_force"
    )
    print(
        f"robustness (64 perturbations of the finalists): {cpu:.2f} s CPU against {plain_cpu:.2f} s ranked by "
        f"total normal force: {cpu / plain_cpu:.2f}x (wall {seconds / plain_seconds:.2f}x)"
    )
    byte_compiled()
    for candidates in (args.hand_candidates, None):
        wall, cli_cpu = command_line(args.hand_grasps, candidates)
        print(
            f"command line:  {args.hand_grasps} grasps in {wall:.2f} s wall, {cli_cpu:.2f} s CPU (a fresh process; "
            f"{'the default' if candidates is None else candidates} candidates)"
        )
    found, spent, base_seconds = hand_baseline(grasp, args.hand_baseline)
    base_rate = found / base_seconds
    print(
        f"baseline (TriFinger):  {found} grasps of {args.hand_baseline} wanted in {base_seconds:.2f} s "
        f"({spent} tries): {base_rate:.1f} a second"
    )
    print(f"speed-up: {rate / max(base_rate, 1e-9):.1f}x")


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
    parser.add_argument("--hand", action="store_true", help="the TriFinger Pro's verified grasps per second")
    parser.add_argument("--hand-grasps", type=int, default=20)
    parser.add_argument("--hand-candidates", type=int, default=4000)
    parser.add_argument("--hand-baseline", type=int, default=20)
    parser.add_argument("--peak", type=int, help=argparse.SUPPRESS)  # one search, then its peak memory in MB
    args = parser.parse_args()
    if args.peak:
        search(args.peak)
        print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024)
        return
    if args.hand:
        hand_bench(args)
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
