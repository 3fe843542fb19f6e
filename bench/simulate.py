"""Grasps that hold in MuJoCo: the fraction of ``synthesize``'s grasps that hold in all six
directions, and one hold test's CPU.

Run: ``python bench/simulate.py [-n 10] [-j 2] [--candidates 2000] [--seconds 120]``.

1. For each object (the bundled ball's two grasp files, box, cylinder and bottle (a mesh), with
   fingertip spheres on slides, no hand; and the TriFinger on the bundled cube on its table),
   ``grasptwist synthesize -n N -o FOLDER/NAME.yaml`` (100 g, ``mu = 0.8``; the cube 94 g,
   ``mu = 1``): the grasps the search returns by default (``--loads six``: a grip for the weight
   and for each of the hold test's other loads, BODex's protocol), as a grasp file; then
   ``grasptwist simulate FOLDER -j J -f jsonl``, a file a process: how many hold in all six
   directions, and which directions the others lose (a direction without a grip is not
   simulated).
2. The same with ``--loads weight`` (the search asks for the weight alone, downwards).
3. One hold test of the TriFinger holding the cube on its table (``grasps/trifinger-cube.yaml``,
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
#: name: (file, mass, friction)
FINGERTIPS = {
    "sphere": ("sphere.yaml", 0.1, 0.8),
    "box": ("box-edge.yaml", 0.1, 0.8),
    "cylinder": ("cylinder.yaml", 0.1, 0.8),
    "bottle": ("bottle.yaml", 0.1, 0.8),
}
TRIFINGER = {"trifinger-cube": ("trifinger-cube.yaml", 0.094, 1.0)}


def _grasptwist(*args) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "grasptwist", *map(str, args)], capture_output=True, text=True)


def _search(file, mass, friction, count, candidates, seconds, *more):
    return _grasptwist(
        "synthesize", GRASPS / file, "-n", count, "--mass", mass, "--friction", friction,
        "--candidates", candidates, "--seconds", seconds, "-q", *more,
    )  # fmt: skip


def held_fraction(objects, count, workers, candidates, seconds, loads):
    """Of the grasps the search returns for ``--loads``: how many hold, which directions the others lose."""
    with tempfile.TemporaryDirectory() as folder:
        for name, (file, mass, friction) in objects.items():
            grasps = Path(folder) / f"{name}.yaml"
            found = _search(file, mass, friction, count, candidates, seconds, "--loads", loads, "-o", grasps)
            if found.returncode not in (0, 1):
                sys.exit(found.stderr)
        start = time.perf_counter()
        run = _grasptwist("simulate", folder, "-j", workers, "-f", "jsonl", "-q", "--allow-outside")
        wall = time.perf_counter() - start
    records = [json.loads(line) for line in run.stdout.splitlines()]
    errors = [rec["error"]["message"] for rec in records if rec.get("error")]
    if errors:
        sys.exit("\n".join(errors))
    lost = Counter()
    for rec in records:
        for d in rec.get("directions", ()):
            if not d["held"]:
                lost[d["direction"] + ("" if d["simulated"] else " (no grip)")] += 1
    no_grip = sum(any(not d["simulated"] for d in rec["directions"]) for rec in records)
    no_grip_held = sum(rec["held"] and any(not d["simulated"] for d in rec["directions"]) for rec in records)
    held = sum(rec.get("held", False) for rec in records)
    return held, len(records), lost, no_grip, no_grip_held, wall


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
    args = parser.parse_args()
    for title, objects in (
        ("fingertips on slides (ball, box, cylinder, bottle)", FINGERTIPS),
        ("TriFinger", TRIFINGER),
    ):
        for loads in ("six", "weight"):
            held, total, lost, no_grip, no_grip_held, wall = held_fraction(
                objects, args.n, args.j, args.candidates, args.seconds, loads
            )
            print(f"{title}, --loads {loads}: {held} of {total} hold in all six directions "
                  f"({held / max(total, 1):.0%}; {no_grip} without a grip in some direction, {no_grip_held} of them held), "
                  f"simulated in {wall:.1f} s of wall with -j {args.j} on {os.cpu_count()} cores")  # fmt: skip
            print("  directions lost: " + (", ".join(f"{d} {n}" for d, n in sorted(lost.items())) or "none"))
    cpu, ok = trifinger_cpu()
    print(f"one TriFinger hold test (6 s simulated): {cpu:.3f} s of CPU, held: {ok}")


if __name__ == "__main__":
    main()
