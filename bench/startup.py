"""Start-up: ``grasptwist resolve grasps/polyhedron.yaml --format json`` against
``python -c "import numpy, yaml, typer"``.

Run: ``python bench/startup.py [--runs 15]``.  Medians of alternating runs.
Target: within 1.25x.  The package is byte-compiled first, as ``pip install``
does (an editable install under PYTHONDONTWRITEBYTECODE would otherwise
recompile every module at every run).
"""

import argparse
import os
import statistics
import subprocess
import sys
import time

from _data import grasptwist_command

EXAMPLE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "grasps", "polyhedron.yaml")


def wall(command):
    t0 = time.perf_counter()
    subprocess.run(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
    return time.perf_counter() - t0


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=15)
    args = ap.parse_args()
    import compileall

    import grasptwist

    compileall.compile_dir(os.path.dirname(grasptwist.__file__), quiet=1)
    base_cmd = [sys.executable, "-c", "import numpy, yaml, typer"]
    ours_cmd = grasptwist_command() + ["resolve", EXAMPLE, "--format", "json"]
    wall(base_cmd), wall(ours_cmd)  # warm the file cache
    base, ours = [], []
    for _ in range(args.runs):
        base.append(wall(base_cmd))
        ours.append(wall(ours_cmd))
    b, o = statistics.median(base), statistics.median(ours)
    print(f"python -c 'import numpy, yaml, typer'          median {b * 1000:6.0f} ms")
    print(
        f"grasptwist resolve polyhedron.yaml --format json median {o * 1000:6.0f} ms   ratio {o / b:4.2f} (target <= 1.25)"
    )


if __name__ == "__main__":
    main()
