"""Latency of one grasp per call, against a per-grasp ``numpy.linalg.solve`` baseline.

Run: ``python bench/latency.py [--calls 3000]``.  Everything runs in this one
process, the candidates taking turns in blocks of calls over a cycle of
random grasps; each figure is the median of ``--calls`` calls.  The baseline is
``_data.solve_baseline`` on one grasp: the basis screws by the paper's
formulas and both 6x6 systems solved with ``numpy.linalg.solve``.

(a) one grasp, both methods and the contact velocities: ``grasptwist.resolve``
    (the three separate calls and ``bases=False`` for reference); target:
    at least 3x faster than the baseline.
(b) one new twist on a prepared grasp: ``PreparedGrasp.resolve`` (and the bare
    matrix product ``map @ twist`` for reference); target: at least 20x.
(c) the command line's per-file path: ``python bench/startup.py``.
(d) ``resolve --twists-from -``, the per-line cost through a pipe: to come with
    the streaming input.
"""

import argparse
import statistics
import time

import grasptwist as gt
from _data import grasp_arrays, solve_baseline


def medians(candidates, calls, cycle, block=25):
    """Median seconds per call of each candidate on ``cycle``'s arguments in turn.

    The candidates take turns in blocks of ``block`` calls: long enough for a
    candidate to run warm, as in a loop, short enough that a change in the
    machine's load hits every candidate alike.
    """
    times = {name: [] for name in candidates}
    clock = time.perf_counter
    for start in range(0, calls, block):
        for name, fn in candidates.items():
            for k in range(start, min(start + block, calls)):
                args = cycle[k % len(cycle)]
                t0 = clock()
                fn(*args)
                times[name].append(clock() - t0)
    return {name: statistics.median(t) for name, t in times.items()}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--calls", type=int, default=3000, help="calls per candidate (default 3000)")
    ap.add_argument("--grasps", type=int, default=100, help="random grasps in the cycle")
    args = ap.parse_args()
    points, normals, wrist, twist = grasp_arrays(args.grasps, seed=1)
    cycle = [
        (points[i], normals[i], wrist[i], twist[i], gt.prepare(points[i], normals[i], wrist[i]))
        for i in range(args.grasps)
    ]

    candidates = {
        "baseline: formulas + 2 x numpy.linalg.solve": lambda p, n, c, t, g: solve_baseline(p, n, c, t),
        "(a) grasptwist.resolve": lambda p, n, c, t, g: gt.resolve(p, n, c, t),
        "    ... with bases=False": lambda p, n, c, t, g: gt.resolve(p, n, c, t, bases=False),
        "    three calls: off-tangent, tangent, velocities": lambda p, n, c, t, g: (
            gt.decompose_off_tangent(p, c, t),
            gt.decompose_tangent(p, n, t),
            gt.contact_velocities(p, t),
        ),
        "(b) PreparedGrasp.resolve(twist)": lambda p, n, c, t, g: g.resolve(t),
        "    the bare product map @ twist": lambda p, n, c, t, g: g.map @ t,
    }
    times = medians(candidates, args.calls, cycle)
    base = times.pop("baseline: formulas + 2 x numpy.linalg.solve")
    targets = {"(a) grasptwist.resolve": 3, "(b) PreparedGrasp.resolve(twist)": 20}
    print(f"one grasp per call, medians of {args.calls:,} calls")
    print(f"{'baseline: formulas + 2 x numpy.linalg.solve':50s} {base * 1e6:8.1f} us")
    for name, t in times.items():
        target = f"   (target >= {targets[name]})" if name in targets else ""
        print(f"{name:50s} {t * 1e6:8.1f} us   {base / t:6.1f}x faster{target}")


if __name__ == "__main__":
    main()
