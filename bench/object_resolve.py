"""``grasptwist resolve`` of one grasp file with an object against the same grasp without one.

Run: ``python bench/object_resolve.py [--runs 11]``.  The bundled bottle
(``grasps/bottle.yaml``, two twists) five ways, start-up included, each the
median of alternating runs: its contacts with the normals it resolves to and
no object; the bottle's bounding box (its contacts put on the box); the bundled OBJ mesh and the
same mesh as a binary STL (both read by grasptwist); and as a binary PLY (parsed by
trimesh, the ``mesh`` extra).  Reported, no target: the issue asks how an
object compares.
"""

import argparse
import os
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

from _data import grasptwist_command

ROOT = Path(__file__).resolve().parent.parent
BOTTLE = ROOT / "grasps" / "bottle.yaml"


def wall(command):
    t0 = time.perf_counter()
    done = subprocess.run(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    if done.returncode not in (0, 1):  # 1: a method degenerate for a twist, the records written
        raise SystemExit(f"{' '.join(command)} failed: {done.stderr.decode()[-500:]}")
    return time.perf_counter() - t0


def variants(folder: Path) -> dict:
    """The five grasp files, written into ``folder``: name -> path."""
    import trimesh
    import yaml

    import grasptwist as gt

    (g,) = gt.load_grasps(BOTTLE)
    doc = yaml.safe_load(BOTTLE.read_text("utf-8"))
    mesh = trimesh.load(ROOT / "grasps" / "meshes" / "bottle.obj", force="mesh", process=False)
    mesh.export(folder / "bottle.stl")
    mesh.export(folder / "bottle.ply", encoding="binary")
    (folder / "bottle.obj").write_bytes((ROOT / "grasps" / "meshes" / "bottle.obj").read_bytes())
    plain = {k: v for k, v in doc.items() if k != "object"}
    plain["contacts"] = [
        {"name": c["name"], "point": p.tolist(), "normal": n.tolist()}
        for c, p, n in zip(doc["contacts"], g.points, g.normals)
    ]
    low, high = mesh.bounds
    files = {
        "no object": plain,
        # the bottle's bounding box, its contacts (points only) put on it: --surface-tol 1 below
        "box (primitive)": {
            **doc,
            "object": {
                "box": (high - low).tolist(),
                "pose": {"position": ((low + high) / 2).tolist()},
                "density": 1000,
            },
        },
        "mesh, OBJ (1,152 triangles)": {**doc, "object": {**doc["object"], "mesh": "bottle.obj"}},
        "mesh, binary STL": {**doc, "object": {**doc["object"], "mesh": "bottle.stl"}},
        "mesh, binary PLY": {**doc, "object": {**doc["object"], "mesh": "bottle.ply"}},
    }
    paths = {}
    for k, (name, text) in enumerate(files.items()):
        paths[name] = folder / f"grasp{k}.yaml"
        paths[name].write_text(yaml.safe_dump(text, sort_keys=False), "utf-8")
    return paths


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=11)
    args = ap.parse_args()
    import compileall

    import grasptwist

    compileall.compile_dir(os.path.dirname(grasptwist.__file__), quiet=1)
    with tempfile.TemporaryDirectory() as tmp:
        paths = variants(Path(tmp))
        commands = {name: grasptwist_command() + ["resolve", str(p), "-f", "json"] for name, p in paths.items()}
        commands["box (primitive)"] += ["--surface-tol", "1"]
        for command in commands.values():
            wall(command)  # warm the file cache; a failing file stops here
        times = {name: [] for name in commands}
        for _ in range(args.runs):
            for name, command in commands.items():
                times[name].append(wall(command))
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores, medians of {args.runs}")
    base = statistics.median(times["no object"])
    for name, t in times.items():
        m = statistics.median(t)
        print(f"{name:30s} {m * 1000:6.0f} ms  {m / base:4.2f}x  (+{(m - base) * 1000:.0f} ms)")


if __name__ == "__main__":
    main()
