"""Engine speed: the public API against batched numpy.linalg.solve and a Python loop.

Run: ``python bench/engine.py [--n 1000000]``.  All three compute the same
things on the same grasps in this one process: both decompositions and the
contact velocities.  The baseline builds the basis screws by the paper's
formulas (``grasptwist.engine.formulas``) and solves the 6x6 systems with
``numpy.linalg.solve`` (``_data.solve_baseline``); the loop calls the public
API once per grasp (which takes the small-batch path) on a sample and is
scaled to ``n``; since that path (issue 15) a call costs ~45 us, not 0.1's
~1 ms, so this ratio fell from 0.1's ~1,600x to ~170x and its target from
300 to 100.  Peak memory is that of a fresh process running the engine
part alone.  The memory-traffic floor is numpy copying the engine's input
and output arrays once (every byte read and written once, output freshly
allocated, as the engine's is): no engine can take less; ``--profile``
shows where the engine's time goes.
"""

import argparse
import cProfile
import dataclasses
import pstats
import resource
import subprocess
import sys
import time

import numpy as np

import grasptwist as gt
from _data import grasp_arrays, solve_baseline


def engine(points, normals, wrist, twist):
    off = gt.decompose_off_tangent(points, wrist, twist)
    tan = gt.decompose_tangent(points, normals, twist)
    return off, tan, gt.contact_velocities(points, twist)


def outputs(inputs, results):
    """The arrays the engine made: every array of its results that is not a view of an input."""
    made = [getattr(r, f.name) for r in results[:2] for f in dataclasses.fields(r)] + [results[2]]
    return [a for a in made if isinstance(a, np.ndarray) and not any(np.may_share_memory(a, i) for i in inputs)]


def copy_once(arrays):
    return [a.copy() for a in arrays]


def profile(data, top=15):
    """The engine's functions by their own time, on stdout."""
    prof = cProfile.Profile()
    prof.runcall(engine, *data)
    pstats.Stats(prof, stream=sys.stdout).sort_stats("tottime").print_stats(top)


def best_of(repeats, fn, *args):
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn(*args)
        times.append(time.perf_counter() - t0)
    return min(times), out


def peak_memory_mib(n):
    """Peak resident memory of a fresh process that builds the data and runs the engine once."""
    subprocess.run([sys.executable, __file__, "--child", str(n)], check=True)
    return resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=1_000_000, help="grasps (default 10^6)")
    ap.add_argument("--loop", type=int, default=2000, help="grasps in the Python-loop sample")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--profile", action="store_true", help="print where the engine's time goes")
    ap.add_argument("--child", type=int, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        engine(*grasp_arrays(args.child))
        return
    peak = peak_memory_mib(args.n)  # first: a child forked from a large parent inherits its peak
    data = grasp_arrays(args.n)
    t_engine, (off, tan, vel) = best_of(args.repeats, engine, *data)
    traffic = [*data, *outputs(data, (off, tan, vel))]
    t_floor, _ = best_of(args.repeats, copy_once, traffic)
    nbytes = sum(a.nbytes for a in traffic)
    t_solve, (xy, ab, vel_b) = best_of(max(1, args.repeats - 1), solve_baseline, *data)
    sample = [a[: args.loop] for a in data]
    t0 = time.perf_counter()
    for row in zip(*sample):
        engine(*row)
    t_loop = (time.perf_counter() - t0) * args.n / args.loop

    ok = off.ok & tan.ok & (off.conditioning > gt.CONDITION_WARNING) & (tan.conditioning > gt.CONDITION_WARNING)
    agree = max(
        np.max(np.abs(np.c_[off.x, off.y][ok] - xy[ok])),
        np.max(np.abs(np.c_[tan.alpha, tan.beta][ok] - ab[ok])),
        np.max(np.abs(vel - vel_b)),
    )
    print(f"grasps: {args.n:,} ({ok.mean():.1%} well-conditioned for both methods; max |difference| there {agree:.1e})")
    print(f"{'engine (public API)':32s} {t_engine:8.3f} s")
    print(
        f"{'batched numpy.linalg.solve':32s} {t_solve:8.3f} s   engine is {t_solve / t_engine:6.1f}x faster (target >= 4)"
    )
    print(
        f"{f'Python loop (from {args.loop} grasps)':32s} {t_loop:8.1f} s   engine is {t_loop / t_engine:6.0f}x faster (target >= 100)"
    )
    print(
        f"{'memory-traffic floor':32s} {t_floor:8.3f} s   engine takes {t_engine / t_floor:6.1f}x the floor "
        f"(numpy copying the {nbytes / 2**20:,.0f} MiB of input and output once)"
    )
    print(f"{'peak memory, engine process':32s} {peak:8.0f} MiB (target < 2048)")
    if args.profile:
        profile(data)


if __name__ == "__main__":
    main()
