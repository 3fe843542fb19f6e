"""Collision checks of the TriFinger Pro's finger links against a mesh object: configurations per second.

The object is the 65 mm cube of ``grasps/trifinger-cube.yaml`` as a closed
mesh of 12,288 triangles (each face cut into 1,024); the fingertips are
10 mm spheres (left out of the check where they touch: their contacts).
The configurations are the grasp's joint positions plus noise: ``--near``
rad (path samples about a grasp: links close to the object, few inside it)
and ``--spread`` rad (the hard case: many links deep inside, whose vertices
the object's search tree answers slowly).  Far configurations are culled in
microseconds and not measured.  Each configuration's 12 link meshes (the
URDF's collision geometry: some 21,000 vertices) are checked.

Measured, in this process, on the same configurations:

* grasptwist (:func:`grasptwist.run.collisions.finger_collisions_along`:
  the depths of :func:`grasptwist.engine.collision.penetration_depths`);
* naive: the same depths from every vertex of every link, no culling (the
  answers must agree exactly);
* trimesh's ``CollisionManager`` rebuilt per configuration (python-fcl:
  whether link and object surfaces meet, no depth), and python-fcl with its
  BVHs built once and only the poses set per configuration, when python-fcl
  is installed (``pip install python-fcl``).

Run: ``python bench/collisions.py [--n 2000]``.  Target: at least 1,000
configurations/s.  Needs yourdfpy, robot-properties-fingers and the mesh
extra (the test extra has them).
"""

import argparse
import time
from dataclasses import replace

import numpy as np
import trimesh

import grasptwist as gt
from grasptwist.engine.collision import link_poses
from grasptwist.io.urdf_meshes import link_geometry
from grasptwist.model import GraspObject, Shape
from grasptwist.run.collisions import finger_collisions_along

GRASP = "grasps/trifinger-cube.yaml"
EDGE = 0.065
TIP_RADIUS = 0.01
OBJECT_POSE = np.eye(4)
OBJECT_POSE[2, 3] = EDGE / 2  # on the table


def cube_object(subdivisions=5):
    """The bundled cube as a closed mesh, each of its 12 triangles cut into ``4**subdivisions``."""
    mesh = trimesh.creation.box((EDGE, EDGE, EDGE))
    for _ in range(subdivisions):
        mesh = mesh.subdivide()
    shape = Shape("mesh", np.zeros(0), np.asarray(mesh.vertices, dtype=float), np.asarray(mesh.faces))
    return GraspObject(shape, OBJECT_POSE), mesh


def best(fn, repeats=3):
    """The best of ``repeats`` wall-clock times of ``fn()``, and its result."""
    times, out = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), out


def naive(grasp, geometry, poses):
    """Every vertex of every link (tip spheres left out) through the object's signed distance, one by one."""
    depth = np.zeros(poses.shape[:2])
    for k in range(len(poses)):
        for i, g in enumerate(geometry):
            finger = grasp.hand.fingers[g.finger]
            v = g.vertices
            if g.link == finger.tip:
                v = v[np.linalg.norm(v - finger.tip_pose[:3, 3], axis=1) > TIP_RADIUS + 1e-3 * EDGE * 3**0.5]
            v = v @ poses[k, i, :3, :3].T + poses[k, i, :3, 3]
            depth[k, i] = max(0.0, -gt.objects.project_to_surface(grasp.object, v).distance.min())
    return depth


def manager_rebuilt(mesh, geometry, poses):
    """trimesh's CollisionManager built anew per configuration: does any link meet the object?"""
    links = [trimesh.Trimesh(g.vertices, g.faces, process=False) for g in geometry]
    hits = np.zeros(len(poses), dtype=bool)
    for k in range(len(poses)):
        manager = trimesh.collision.CollisionManager()
        for i, link in enumerate(links):
            manager.add_object(str(i), link, transform=poses[k, i])
        hits[k] = manager.in_collision_single(mesh, transform=OBJECT_POSE)
    return hits


def fcl_kept(mesh, geometry, poses):
    """python-fcl with every BVH built once: per configuration the links' poses set and each collided."""
    import fcl

    def bvh(v, f):
        model = fcl.BVHModel()
        model.beginModel(len(v), len(f))
        model.addSubModel(v, f)
        model.endModel()
        return model

    target = fcl.CollisionObject(bvh(mesh.vertices, mesh.faces), fcl.Transform(OBJECT_POSE[:3, :3], OBJECT_POSE[:3, 3]))
    links = [fcl.CollisionObject(bvh(g.vertices, g.faces)) for g in geometry]
    request, hits = fcl.CollisionRequest(), np.zeros(len(poses), dtype=bool)
    for k in range(len(poses)):
        for i, link in enumerate(links):
            link.setTransform(fcl.Transform(poses[k, i, :3, :3], poses[k, i, :3, 3]))
            if fcl.collide(link, target, request, fcl.CollisionResult()):
                hits[k] = True
    return hits


def measure(grasp, mesh, geometry, q, slow):
    """One spread's lines: grasptwist, then the baselines on the first ``slow`` configurations."""
    t_ours, found = best(lambda: finger_collisions_along(grasp, q))
    poses = link_poses(grasp.hand, geometry, q[:slow])
    t_naive, depth = best(lambda: naive(grasp, geometry, poses), 1)
    ours = np.zeros_like(depth)
    names = [g.link for g in geometry]
    for k, hits in enumerate(found[:slow]):
        for c in hits:
            ours[k, names.index(c.link)] = c.depth
    tol = 1e-3 * EDGE * 3**0.5
    rate = len(q) / t_ours
    print(
        f"  grasptwist: {rate:,.0f} configurations/s; {np.mean([bool(f) for f in found]):.0%} collide, "
        f"deepest {max((c.depth for f in found for c in f), default=0) * 1e3:.1f} mm"
    )
    print(
        f"  naive, every vertex: {slow / t_naive:,.0f} configurations/s "
        f"(largest difference {np.abs(np.where(depth > tol, depth, 0) - ours).max():.1e})"
    )
    try:
        import fcl  # noqa: F401 - only to say whether the fcl baselines run
    except ImportError:
        print("  python-fcl not installed: no fcl baselines (pip install python-fcl)")
        return
    t_manager, _ = best(lambda: manager_rebuilt(mesh, geometry, poses), 1)
    t_fcl, _ = best(lambda: fcl_kept(mesh, geometry, poses), 1)
    print(f"  trimesh CollisionManager rebuilt per configuration: {slow / t_manager:,.0f} configurations/s (no depth)")
    print(f"  python-fcl, BVHs built once: {slow / t_fcl:,.0f} configurations/s (no depth)")
    print(
        f"  speed-up: {rate * t_naive / slow:.0f}x the naive check, {rate * t_manager / slow:.0f}x the rebuilt "
        f"CollisionManager, {rate * t_fcl / slow:.1f}x kept fcl BVHs"
    )


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=2000)
    ap.add_argument("--near", type=float, default=0.02)
    ap.add_argument("--spread", type=float, default=0.15)
    ap.add_argument("--slow", type=int, default=100, help="configurations for the slow baselines")
    args = ap.parse_args()
    (grasp,) = gt.read_grasps(GRASP)
    obj, mesh = cube_object()
    hand = replace(grasp.hand, fingers=tuple(replace(f, tip_radius=TIP_RADIUS) for f in grasp.hand.fingers))
    grasp = replace(grasp, hand=hand, object=obj)
    geometry = link_geometry(hand)
    t_setup, _ = best(lambda: finger_collisions_along(grasp, grasp.joint_positions[None]), 1)  # loads, cuts, builds
    print(
        f"TriFinger: {len(geometry)} links, {sum(len(g.vertices) for g in geometry):,} vertices; object: "
        f"{len(mesh.faces):,} triangles; {args.n} configurations; first check (meshes read, search tree built): "
        f"{t_setup:.2f} s"
    )
    rng = np.random.default_rng(0)
    for label, spread in (("near the grasp", args.near), ("deep", args.spread)):
        q = grasp.joint_positions + rng.normal(0.0, spread, (args.n, len(hand.joint_names)))
        print(f"{label} (joint noise {spread} rad):")
        measure(grasp, mesh, geometry, q, min(args.slow, args.n))
    print("target: >= 1,000 configurations/s")


if __name__ == "__main__":
    main()
