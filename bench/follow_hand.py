"""A hand following a path: ``grasptwist follow --samples 2`` of the bundled inline-hand grasp
against ``grasptwist resolve`` of the same file.

Run: ``python bench/follow_hand.py [--runs 9]``.  CPU time (user + sys) of each child
process, medians of alternating runs (the machine may be shared: CPU time, not wall
clock).  The follow integrates every finger along the path (two segments, 64
Runge-Kutta steps each, :func:`grasptwist.engine.hands.track`) on top of what
resolve does.  Target: within 2x.  The package is byte-compiled first, as in
``bench/startup.py``.
"""

import argparse
import os
import resource
import statistics
import subprocess

from _data import grasptwist_command

GRASP = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "grasps", "three-finger-hand.yaml")


def cpu(command):
    """User + sys seconds of running ``command`` to its end."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=9)
    args = ap.parse_args()
    import compileall

    import grasptwist

    compileall.compile_dir(os.path.dirname(grasptwist.__file__), quiet=1)
    resolve = grasptwist_command() + ["resolve", GRASP, "--format", "json"]
    follow = grasptwist_command() + ["follow", GRASP, "--samples", "2", "--format", "json"]
    cpu(resolve), cpu(follow)  # warm the file cache
    a, b = [], []
    for _ in range(args.runs):
        a.append(cpu(resolve))
        b.append(cpu(follow))
    r, f = statistics.median(a), statistics.median(b)
    print(f"resolve three-finger-hand.yaml            CPU median {r * 1000:6.0f} ms")
    print(
        f"follow  three-finger-hand.yaml --samples 2 CPU median {f * 1000:6.0f} ms   ratio {f / r:4.2f} (target <= 2)"
    )


if __name__ == "__main__":
    main()
