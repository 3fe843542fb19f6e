"""Latency of one grasp per call, against a per-grasp ``numpy.linalg.solve`` baseline.

Run: ``python bench/latency.py [--calls 3000]``.  Everything runs in this one
process, the candidates taking turns in blocks of calls over a cycle of
random grasps; each figure is the median of ``--calls`` calls.  The baseline is
``_data.solve_baseline`` on one grasp: the basis screws by the paper's
formulas and both 6x6 systems solved with ``numpy.linalg.solve``.

(a) one grasp, both methods and the contact velocities: ``grasptwist.resolve``
    (the three separate calls and ``bases=False`` for reference); target:
    at least 3x faster than the baseline.
(b) one new twist on a prepared grasp, as a controller holding its grasp does
    at every tick: ``PreparedGrasp.resolve`` of the cycle's twists on one
    prepared grasp (and for reference, a different prepared grasp at every
    call, whose arrays are then out of the CPU's caches, and the bare matrix
    product ``map @ twist``); target: at least 20x.
(c) the command line's per-file path: ``bench/startup.py``, run and quoted.
(d) ``resolve GRASP --twists-from - -f jsonl`` behind a pipe: the sustained
    rate of a producer that writes ``--lines`` twists as fast as it can
    (from the first record to the last, so without the start-up; the best of
    three runs, and per second of the filter's CPU time), and the
    round trip of one line when the producer waits for each record before
    writing the next; target: at least 10,000 lines/s sustained.
"""

import argparse
import os
import statistics
import subprocess
import sys
import threading
import time

import grasptwist as gt
from _data import grasp_arrays, grasptwist_command, solve_baseline

HERE = os.path.dirname(os.path.abspath(__file__))
GRASP = os.path.join(HERE, "..", "grasps", "polyhedron.yaml")


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
    ap.add_argument("--lines", type=int, default=20000, help="twists streamed in (d) (default 20000)")
    args = ap.parse_args()
    points, normals, wrist, twist = grasp_arrays(args.grasps, seed=1)
    cycle = [
        (points[i], normals[i], wrist[i], twist[i], gt.prepare(points[i], normals[i], wrist[i]))
        for i in range(args.grasps)
    ]
    held = cycle[0][4]  # the grasp a controller holds

    candidates = {
        "baseline: formulas + 2 x numpy.linalg.solve": lambda p, n, c, t, g: solve_baseline(p, n, c, t),
        "(a) grasptwist.resolve": lambda p, n, c, t, g: gt.resolve(p, n, c, t),
        "    ... with bases=False": lambda p, n, c, t, g: gt.resolve(p, n, c, t, bases=False),
        "    three calls: off-tangent, tangent, velocities": lambda p, n, c, t, g: (
            gt.decompose_off_tangent(p, c, t),
            gt.decompose_tangent(p, n, t),
            gt.contact_velocities(p, t),
        ),
        "(b) PreparedGrasp.resolve(twist)": lambda p, n, c, t, g: held.resolve(t),
        "    ... a different prepared grasp at each call": lambda p, n, c, t, g: g.resolve(t),
        "    the bare product map @ twist": lambda p, n, c, t, g: held.map @ t,
    }
    times = medians(candidates, args.calls, cycle)
    base = times.pop("baseline: formulas + 2 x numpy.linalg.solve")
    targets = {"(a) grasptwist.resolve": 3, "(b) PreparedGrasp.resolve(twist)": 20}
    print(f"one grasp per call, medians of {args.calls:,} calls")
    print(f"{'baseline: formulas + 2 x numpy.linalg.solve':50s} {base * 1e6:8.1f} us")
    for name, t in times.items():
        target = f"   (target >= {targets[name]})" if name in targets else ""
        print(f"{name:50s} {t * 1e6:8.1f} us   {base / t:6.1f}x faster{target}")
    print("(c) the command line, one file per run (bench/startup.py):")
    startup = subprocess.run([sys.executable, os.path.join(HERE, "startup.py"), "--runs", "9"], capture_output=True)
    print("".join(f"    {line}\n" for line in startup.stdout.decode().splitlines()), end="")
    twists = [f"[{t[0]:.6f},{t[1]:.6f},{t[2]:.6f},{t[3]:.6f},{t[4]:.6f},{t[5]:.6f}]\n".encode() for t in twist]
    rate, cpu_rate = max(sustained(twists, args.lines) for _ in range(3))  # the best of three runs
    trip = round_trip(twists, 300)
    print(f"(d) resolve {os.path.basename(GRASP)} --twists-from - -f jsonl, through pipes:")
    print(f"    sustained, {args.lines:,} lines written at once, best of 3 {rate:6,.0f} lines/s   (target >= 10,000)")
    print(f"    ... per second of its CPU time, start-up included {cpu_rate:7,.0f} lines/s")
    print(f"    one line at a time, median round trip         {trip * 1e6:10.0f} us")


def _filter():
    command = grasptwist_command() + ["resolve", GRASP, "--twists-from", "-", "-f", "jsonl", "-q"]
    return subprocess.Popen(command, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL)


def sustained(twists, lines):
    """Lines per second from the first record to the last, a producer writing as fast as
    it can; and lines per second of the process's CPU time (user + system, start-up
    included: on a loaded machine the wall clock also counts other processes' turns)."""
    p = _filter()
    feed = b"".join(twists[i % len(twists)] for i in range(lines))
    writer = threading.Thread(target=lambda: (p.stdin.write(feed), p.stdin.close()))
    p.stdin.write(twists[0])  # the start-up is not part of the rate: its record starts the clock
    p.stdin.flush()
    p.stdout.readline()
    t0 = time.perf_counter()
    writer.start()
    n = sum(1 for _ in p.stdout)
    t = time.perf_counter() - t0
    writer.join()
    _, _, usage = os.wait4(p.pid, 0)
    p.returncode = 0
    return n / t, (n + 1) / (usage.ru_utime + usage.ru_stime)


def round_trip(twists, lines):
    """Median seconds from writing a line to reading its record, one line at a time."""
    p = _filter()
    times = []
    for i in range(lines):
        t0 = time.perf_counter()
        p.stdin.write(twists[i % len(twists)])
        p.stdin.flush()
        p.stdout.readline()
        times.append(time.perf_counter() - t0)
    p.stdin.close()
    p.wait()
    return statistics.median(times[10:])  # past the start-up


if __name__ == "__main__":
    main()
