"""Start-up: ``grasptwist resolve grasps/polyhedron.yaml --format json`` against
``python -c "import numpy, yaml, typer"``.

Run: ``python bench/startup.py [--runs 15]``.  Medians of alternating runs, of the
wall clock and of the child's CPU time (user + sys: what a machine shared with
other jobs does not inflate).  Target: within 1.25x.  The package is byte-compiled first, as ``pip install``
does (an editable install under PYTHONDONTWRITEBYTECODE would otherwise
recompile every module at every run).
"""

import argparse
import os
import resource
import statistics
import subprocess
import sys
import time

from _data import byte_compiled, grasptwist_command

EXAMPLE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "grasps", "polyhedron.yaml")


def wall(command):
    """Wall-clock and CPU (user + sys) seconds of running ``command`` to its end."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    subprocess.run(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
    t1 = time.perf_counter()
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return t1 - t0, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=15)
    args = ap.parse_args()
    byte_compiled()
    base_cmd = [sys.executable, "-c", "import numpy, yaml, typer"]
    ours_cmd = grasptwist_command() + ["resolve", EXAMPLE, "--format", "json"]
    wall(base_cmd), wall(ours_cmd)  # warm the file cache
    base, ours = [], []
    for _ in range(args.runs):
        base.append(wall(base_cmd))
        ours.append(wall(ours_cmd))
    for i, clock in enumerate(("wall", "CPU")):
        b, o = statistics.median(r[i] for r in base), statistics.median(r[i] for r in ours)
        print(f"{clock:4s} python -c 'import numpy, yaml, typer'          median {b * 1000:6.0f} ms")
        print(
            f"{clock:4s} grasptwist resolve polyhedron.yaml --format json median {o * 1000:6.0f} ms"
            f"   ratio {o / b:4.2f} (target <= 1.25)"
        )


if __name__ == "__main__":
    main()
