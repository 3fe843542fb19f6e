"""Grasps that hold in MuJoCo: the fraction of ``synthesize``'s grasps that hold in all six
directions, and one hold test's CPU.

Run: ``python bench/simulate.py [-n 10] [-j 2] [--candidates 2000] [--seconds 120] [--hand]``.

1. For each object (the bundled ball, box and cylinder grasp files, with ``--hand`` the TriFinger
   cube too), ``grasptwist synthesize -n N -o FOLDER/NAME.yaml``: the grasps found, as a grasp
   file; then ``grasptwist simulate FOLDER -j J -f jsonl``, a file a process: how many hold in all
   six directions, and which directions the others lose (a direction without a grip is not
   simulated: the search asks only for the object's weight, downwards).
2. One hold test of the TriFinger holding the cube on its table (``grasps/trifinger-cube.yaml``,
   94 g, ``mu = 1``): the process CPU of ``simulate_grasp``, best of five (6 s of simulated time).
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
GRASPS = ROOT / "grasps"
OBJECTS = {"sphere": "sphere.yaml", "box": "box-edge.yaml", "cylinder": "cylinder.yaml"}


def _grasptwist(*args) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "grasptwist", *map(str, args)], capture_output=True, text=True)


def held_fraction(objects, count, workers, candidates, seconds, mass=0.1, friction=0.8):
    with tempfile.TemporaryDirectory() as folder:
        for name, file in objects.items():
            found = _grasptwist(
                "synthesize", GRASPS / file, "-n", count, "--mass", mass, "--friction", friction,
                "--candidates", candidates, "--seconds", seconds, "-o", Path(folder) / f"{name}.yaml", "-q",
            )  # fmt: skip
            if found.returncode not in (0, 1):
                sys.exit(found.stderr)
        start = time.perf_counter()
        run = _grasptwist("simulate", folder, "-j", workers, "-f", "jsonl", "-q")
        wall = time.perf_counter() - start
    records = [json.loads(line) for line in run.stdout.splitlines()]
    lost = Counter()
    for rec in records:
        for d in rec.get("directions", ()):
            if not d["held"]:
                lost[d["direction"] + ("" if d["simulated"] else " (no grip)")] += 1
    held = sum(rec.get("held", False) for rec in records)
    return held, len(records), lost, wall


def trifinger_cpu(repeat=5):
    from grasptwist.run.options import SimulateOptions
    from grasptwist.run.placement import read
    from grasptwist.run.simulate import simulate_grasp

    grasp = read(str(GRASPS / "trifinger-cube.yaml"))[0]
    options = SimulateOptions(mass=0.094, friction=1.0, table=0.0)
    simulate_grasp(options, grasp)  # MuJoCo loaded, the grip compiled
    best = float("inf")
    for _ in range(repeat):
        start = time.process_time()
        sim = simulate_grasp(options, grasp)
        best = min(best, time.process_time() - start)
    return best, sim.test.held


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-n", type=int, default=10, help="grasps synthesized per object")
    parser.add_argument("-j", type=int, default=2, help="simulate's processes")
    parser.add_argument("--candidates", type=int, default=2000)
    parser.add_argument("--seconds", type=float, default=120.0)
    parser.add_argument("--hand", action="store_true", help="the TriFinger on its cube too (slow to synthesize)")
    args = parser.parse_args()
    objects = dict(OBJECTS, **({"trifinger-cube": "trifinger-cube.yaml"} if args.hand else {}))
    held, total, lost, wall = held_fraction(objects, args.n, args.j, args.candidates, args.seconds)
    print(f"held in all six directions: {held} of {total} synthesized grasps ({held / max(total, 1):.0%}), "
          f"simulated in {wall:.1f} s of wall with -j {args.j} on {os.cpu_count()} cores")  # fmt: skip
    print("directions lost: " + ", ".join(f"{d} {n}" for d, n in sorted(lost.items())))
    cpu, ok = trifinger_cpu()
    print(f"one TriFinger hold test (6 s simulated): {cpu:.3f} s of CPU, held: {ok}")


if __name__ == "__main__":
    main()
