"""Points put on an object's surface: 10^6 points on each primitive, 10^5 on a 10^5-triangle mesh.

``grasptwist.engine.objects.project_to_surface`` against a same-run baseline:

- primitives: the vectorised closed forms against a per-point Python loop of
  the same formulas in floats (``primitives.nearest_one``, ``--loop``
  points, scaled to ``--n``); the two must agree to round-off;
- a mesh (a torus of 10^5 triangles made by ``trimesh.creation``; non-convex,
  so the inside/outside sign is tested too): ours (libigl's AABB tree, built
  once and kept with the shape, then our edge and vertex normals and the
  pseudo-normal sign) against ``trimesh.proximity.closest_point`` on
  ``--mesh-loop`` points, scaled.  Distances are checked against a brute
  force over every triangle on ``--check`` points (trimesh's own are not a
  reference: on this torus it misses the nearest point of thin triangles by up
  to 1.5e-4, where ours and the brute force agree to round-off), signs against
  the torus's closed form.

Each timing is the best of ``--repeat`` runs (the machine may be shared); the
tree's one-off build is printed apart.  Query points lie within
``SURFACE_TOL`` (1 %) of the object's size of its surface, as contacts that
are put on it do; the mesh is also timed on points uniform in its bounding
box, the hard case of a tree search (points near the middle of the tube are
nearly as far from a whole ring of triangles).

The solid (issue 35), each against a same-run baseline:

- nearest points on a mesh of 20 overlapping spheres of 10^4 triangles in all (its outer surface:
  the faces another sphere crosses split where it does; signs from the winding number along the
  seams) against the closed torus's rate, near the surface;
- ``synthesize`` on that mesh (its solid found, then the search) against a closed mesh of the same
  size (a torus of 10^4 triangles), ``--candidates`` each; the issue asks within 1.5x;
- ``grasptwist resolve`` of the bundled bottle (a mesh object) against the same grasp on a box
  (whole commands, start-up included); the issue asks within 1.5x.

Run: ``python bench/objects.py [--n 1000000] [--mesh-n 100000]``.  Needs the
``mesh`` extra (trimesh, libigl).
"""

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import trimesh

from grasptwist.engine.objects import SURFACE_TOL, check_object, object_size, project_to_surface, sample_surface
from grasptwist.engine.objects.mesh import _derived
from grasptwist.engine.objects.primitives import nearest_one
from grasptwist.engine.objects.solid import winding_number
from grasptwist.engine.synthesis.search import synthesize
from grasptwist.model import GraspObject, Shape

PRIMITIVES = {"box": [0.065, 0.065, 0.065], "sphere": [0.04], "cylinder": [0.03, 0.1], "capsule": [0.02, 0.06]}


def best(f, repeat):
    """The least wall time and the least process CPU time of ``repeat`` calls of ``f``, and its result: on a
    machine shared with other jobs the wall time varies with their load, the CPU time of this single-threaded
    work much less."""
    times, cpu = [], []
    for _ in range(repeat):
        start, start_cpu = time.perf_counter(), time.process_time()
        result = f()
        times.append(time.perf_counter() - start)
        cpu.append(time.process_time() - start_cpu)
    return min(times), min(cpu), result


def near_surface(o, n, rng):
    """``n`` points within ``SURFACE_TOL`` of the object's size of its surface."""
    p, normals = sample_surface(o, n, rng)
    return p + normals * rng.uniform(-SURFACE_TOL, SURFACE_TOL, (n, 1)) * object_size(o)


def primitives(n, loop, repeat):
    rng = np.random.default_rng(0)
    for kind, size in PRIMITIVES.items():
        o = check_object(GraspObject(Shape(kind, np.array(size)), np.eye(4)))
        q = near_surface(o, n, rng)
        ours, cpu, s = best(lambda o=o, q=q: project_to_surface(o, q), repeat)
        start = time.perf_counter()
        slow = [nearest_one(kind, size, tuple(p)) for p in q[:loop].tolist()]
        base = (time.perf_counter() - start) * n / loop
        points = np.array([p for p, _, _ in slow])
        distance = np.array([d for _, _, d in slow])
        agree = max(np.abs(points - s.points[:loop]).max(), np.abs(distance - s.distance[:loop]).max())
        print(
            f"{kind:>8}: {n / ours:>12,.0f} points/s vectorised ({n / cpu:,.0f} per CPU second),"
            f" {n / base:>9,.0f} points/s per-point loop"
            f" ({base / ours:,.0f}x); largest difference {agree:.1e}"
        )


def torus(sections):
    """A torus (major radius 0.05, minor 0.015) of ``2 * major * minor`` triangles, and its closed-form distance."""
    m = trimesh.creation.torus(0.05, 0.015, major_sections=sections[0], minor_sections=sections[1])

    def exact(q):
        return np.hypot(np.hypot(q[:, 0], q[:, 1]) - 0.05, q[:, 2]) - 0.015

    return m, exact


def brute_force(triangles, q):
    """Each point's distance to the nearest of all ``triangles (F, 3, 3)``: the plane inside a triangle, else
    the nearest of its three edges (Ericson, Real-Time Collision Detection, 5.1.5, by cases)."""
    a, b, c = triangles[:, 0], triangles[:, 1], triangles[:, 2]
    normal = np.cross(b - a, c - a)
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    out = np.empty(len(q))
    for i, p in enumerate(q):
        foot = p - np.einsum("ij,ij->i", p - a, normal)[:, None] * normal
        inside = np.ones(len(a), dtype=bool)
        for u, v in ((a, b), (b, c), (c, a)):
            inside &= np.einsum("ij,ij->i", np.cross(v - u, foot - u), normal) >= 0
        best = np.where(inside, np.linalg.norm(p - foot, axis=1), np.inf)
        for u, v in ((a, b), (b, c), (c, a)):
            t = np.clip(np.einsum("ij,ij->i", p - u, v - u) / np.einsum("ij,ij->i", v - u, v - u), 0, 1)
            best = np.minimum(best, np.linalg.norm(p - (u + t[:, None] * (v - u)), axis=1))
        out[i] = best.min()
    return out


def mesh(n, loop, check, repeat):
    m, exact = torus((400, 125))
    shape = Shape("mesh", np.zeros(0), np.asarray(m.vertices, dtype=float), np.asarray(m.faces))
    o = check_object(GraspObject(shape, np.eye(4)))
    build, _, _ = best(lambda: _derived(o.shape).nearest_faces(np.zeros((1, 3))), 1)  # normals and tree, once
    rng = np.random.default_rng(1)
    near = near_surface(o, n, rng)
    lower, upper = m.bounds
    anywhere = rng.uniform(lower, upper, (n, 3))
    for name, q in (("within 1 % of the surface", near), ("uniform in the bounding box", anywhere)):
        ours, cpu, s = best(lambda q=q: project_to_surface(o, q), repeat)
        start = time.perf_counter()
        trimesh.proximity.closest_point(m, q[:loop])
        base = (time.perf_counter() - start) * n / loop
        clear = np.abs(exact(q)) > 1e-3  # beyond the chord error
        error = np.abs(np.abs(s.distance[:check]) - brute_force(m.triangles, q[:check])).max()
        print(
            f"mesh of {len(m.faces):,} triangles, points {name}: {n / ours:,.0f} points/s ({n / cpu:,.0f} per CPU second),"
            f" trimesh.proximity.closest_point {n / base:,.0f} points/s ({base / ours:,.0f}x);"
            f" largest distance difference from a brute force {error:.1e};"
            f" signs as the closed form's: {(np.sign(s.distance) == np.sign(exact(q)))[clear].mean():.2%}"
        )
    print(f"(its tree and normals built once, in {build:.2f} s)")


def spheres(pieces=20):
    """``pieces`` spheres of 480 triangles each (9,600 for 20), along a gentle arc, each overlapping the next."""
    n = 11  # 480 triangles a sphere
    parts = []
    for k in range(pieces):
        m = trimesh.creation.uv_sphere(0.012, count=[n, n])
        t = k / (pieces - 1)
        m.apply_translation([0.016 * k, 0.02 * np.sin(np.pi * t), 0.004 * (k % 3)])
        parts.append(m)
    return trimesh.util.concatenate(parts)


def mesh_object(m, **kw):
    return check_object(
        GraspObject(Shape("mesh", np.zeros(0), np.asarray(m.vertices, float), np.asarray(m.faces)), np.eye(4), **kw)
    )


def solid(n, repeat, candidates):
    pieces = spheres()
    closed, _ = torus((100, 50))
    o = mesh_object(pieces)
    rng = np.random.default_rng(2)
    q = near_surface(o, n, rng)
    ours, cpu, s = best(lambda: project_to_surface(o, q), repeat)
    v, f = o.shape.vertices, o.shape.faces
    agree = (s.distance < 0) == (winding_number(v, f, q) > 0.5)
    print(
        f"mesh of {len(pieces.faces):,} triangles in 20 overlapping spheres, points within 1 % of the surface:"
        f" {n / ours:,.0f} points/s ({n / cpu:,.0f} per CPU second); signs as the winding number's: {agree.mean():.2%}"
    )
    times = {}
    for name, m in (("20 overlapping spheres", pieces), ("a closed torus", closed)):
        wall, cpu, found = best(
            lambda m=m: synthesize(mesh_object(m, density=700.0), 0.8, candidates=candidates, count=1), repeat
        )
        times[name] = cpu
        print(
            f"synthesize on {name} ({len(m.faces):,} triangles), {candidates} candidates: {wall:.2f} s ({cpu:.2f} s of CPU), {len(found.points)} grasp"
        )
    print(f"  ratio {times['20 overlapping spheres'] / times['a closed torus']:.2f} (CPU; the issue asks <= 1.5)")


def resolve(repeat):
    """``grasptwist resolve`` of one grasp on a 65 mm cube given as a box and as a closed mesh of it, and on
    the same cube as an open mesh (its bottom missing: its solid found by its winding number)."""
    with tempfile.TemporaryDirectory() as folder:
        cube = trimesh.creation.box((0.065, 0.065, 0.065))
        cube.export(Path(folder) / "cube.obj")
        bottom = cube.face_normals[:, 2] < -0.5  # its bottom left open: no contact is there
        trimesh.Trimesh(cube.vertices, cube.faces[~bottom], process=False).export(Path(folder) / "open.obj")
        grasp = (
            "object:\n  {shape}\n  density: 700\nfriction: 0.8\ncontacts:\n"
            "  - {{point: [0.0325, 0.01, 0.005]}}\n  - {{point: [-0.0325, -0.01, 0.0]}}\n"
            "  - {{point: [0.0, 0.0325, -0.01]}}\ntwists:\n  - {{name: lift, linear: [0, 0, 0.05]}}\n"
        )
        times = {}
        for name, shape in (
            ("a box", "box: [0.065, 0.065, 0.065]"),
            ("a closed mesh", "mesh: cube.obj"),
            ("an open mesh", "mesh: open.obj"),
        ):
            path = Path(folder) / f"{name.split()[-2]}.yaml"
            path.write_text(grasp.format(shape=shape))
            command = [sys.executable, "-m", "grasptwist", "resolve", str(path), "-f", "json"]
            wall, _, done = best(
                lambda c=command: subprocess.run(c, capture_output=True, env=os.environ.copy()), repeat
            )
            times[name] = wall
            print(f"grasptwist resolve of a cube as {name}: {wall:.2f} s (exit {done.returncode})")
    for name in ("a closed mesh", "an open mesh"):
        print(f"  {name} / a box: {times[name] / times['a box']:.2f} (the issue asks <= 1.5)")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=1_000_000, help="points per primitive")
    parser.add_argument("--loop", type=int, default=20_000, help="points of the per-point loop (scaled)")
    parser.add_argument("--mesh-n", type=int, default=100_000, help="points on the mesh")
    parser.add_argument("--mesh-loop", type=int, default=2_000, help="points given to trimesh (scaled)")
    parser.add_argument("--check", type=int, default=200, help="mesh points checked by a brute force")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--candidates", type=int, default=5000, help="candidates of each synthesize timed")
    a = parser.parse_args()
    primitives(a.n, a.loop, a.repeat)
    mesh(a.mesh_n, a.mesh_loop, a.check, a.repeat)
    solid(a.mesh_n, a.repeat, a.candidates)
    resolve(a.repeat)


if __name__ == "__main__":
    main()
