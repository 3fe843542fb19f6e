"""A mesh object against the primitives it approximates, against a torus's closed form (inside or outside), its
normals at faces, edges and vertices, its mass properties (closed forms; trimesh's in the slow run), and the
validators' mesh branches.  The default run builds its meshes itself: importing trimesh costs each test worker
over a second."""

import math
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

pytest.importorskip("igl")

from grasp_gen import rigid_pose  # noqa: E402
from grasptwist.engine.objects import (  # noqa: E402
    MESH_EDGE_TOL,
    check_object,
    check_shape,
    mass_properties,
    moved,
    object_size,
    project_to_surface,
    sample_surface,
    tessellate,
)
from grasptwist.extras import MissingExtra  # noqa: E402
from grasptwist.model import GraspObject, Shape  # noqa: E402


def mesh_object(vertices, faces, pose=None, **kw):
    shape = Shape("mesh", np.zeros(0), np.asarray(vertices, dtype=float), np.asarray(faces), source="test.stl")
    return check_object(GraspObject(shape, np.eye(4) if pose is None else pose, **kw))


def primitive(kind, *size, pose=None):
    return check_object(GraspObject(Shape(kind, np.array(size, dtype=float)), np.eye(4) if pose is None else pose))


def angle(a, b):
    return np.degrees(np.arctan2(np.linalg.norm(np.cross(a, b), axis=-1), np.einsum("...i,...i->...", a, b)))


def torus_mesh(big, small, m, n):
    """A torus about z (``m`` sections around, ``n`` around the tube), its vertices on the exact surface."""
    u = 2 * np.pi * np.arange(m)[:, None] / m
    v = 2 * np.pi * np.arange(n)[None, :] / n
    ring = big + small * np.cos(v)
    vertices = np.stack([ring * np.cos(u), ring * np.sin(u), np.broadcast_to(small * np.sin(v), (m, n))], axis=-1)
    i, j = np.meshgrid(np.arange(m), np.arange(n), indexing="ij")
    a, b = i * n + j, ((i + 1) % m) * n + j
    c, d = ((i + 1) % m) * n + (j + 1) % n, i * n + (j + 1) % n
    faces = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])
    return vertices.reshape(-1, 3), faces


def face_normals_areas(vertices, faces):
    cross = np.cross(vertices[faces[:, 1]] - vertices[faces[:, 0]], vertices[faces[:, 2]] - vertices[faces[:, 0]])
    twice = np.linalg.norm(cross, axis=1)
    return cross / twice[:, None], twice / 2


RADIUS = 0.04
SPHERE = tessellate(primitive("sphere", RADIUS), segments=32)  # 16 bands of latitude: thin triangles at the poles


def sphere_against_mesh(vertices, faces, rng):
    pose = rigid_pose(rng)
    mesh = mesh_object(vertices, faces, pose)
    sphere = primitive("sphere", RADIUS, pose=pose)
    q = pose[:3, 3] + rng.uniform(-0.08, 0.08, (2000, 3))
    got, want = project_to_surface(mesh, q), project_to_surface(sphere, q)
    normals, _ = face_normals_areas(vertices, faces)
    gap = RADIUS - np.min(np.einsum("ij,ij->i", normals, vertices[faces[:, 0]]))  # the faces' planes' depth
    assert 0 < gap < 0.01 * RADIUS
    assert np.abs(got.distance - want.distance).max() <= gap
    # outside the faces' planes, the radial direction of q lies within the cone of the vertices about the normal
    # of its nearest face (or about the faces' normals at its nearest edge or vertex)
    cone = angle(vertices[faces], normals[:, None, :]).max()
    out = np.linalg.norm(q - pose[:3, 3], axis=1) >= RADIUS - gap
    assert out.mean() > 0.9
    assert angle(got.normals, want.normals)[out].max() <= cone
    assert np.linalg.norm(got.points - want.points, axis=1)[out].max() < RADIUS * math.radians(cone)
    # coordinates about 1 (the pose's shift): a few units of 2.2e-16
    np.testing.assert_allclose(np.linalg.norm(q - got.points, axis=1), np.abs(got.distance), rtol=0, atol=1e-15)
    return cone


def test_a_sphere_mesh_projects_as_its_sphere_within_the_chord_error():
    cone = sphere_against_mesh(*SPHERE, np.random.default_rng(0))
    assert 7 < cone < 8  # 360 / 32 / 2 = 5.6 degrees around, more towards the poles


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_an_icosphere_projects_as_its_sphere_within_the_chord_error():
    trimesh = pytest.importorskip("trimesh")
    ico = trimesh.creation.icosphere(subdivisions=3, radius=RADIUS)  # 1280 faces
    cone = sphere_against_mesh(np.asarray(ico.vertices), np.asarray(ico.faces), np.random.default_rng(0))
    assert 5 < cone < 6


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_mesh_mass_properties_agree_with_trimesh():
    trimesh = pytest.importorskip("trimesh")
    m = trimesh.creation.torus(0.05, 0.015, major_sections=24, minor_sections=12)
    m.apply_translation([0.3, -0.2, 0.1])
    m = trimesh.util.concatenate([m, trimesh.creation.box([0.02, 0.03, 0.04])])  # two bodies, one off-centre
    pose = rigid_pose(np.random.default_rng(1))
    props = mass_properties(mesh_object(m.vertices, m.faces, pose, density=800.0))
    assert props.volume == pytest.approx(m.volume, rel=1e-12)
    assert props.mass == pytest.approx(800.0 * m.volume, rel=1e-12)
    np.testing.assert_allclose(props.center_of_mass, pose[:3, :3] @ m.center_mass + pose[:3, 3], rtol=0, atol=1e-13)


def test_mesh_mass_properties_closed_forms():
    pose = rigid_pose(np.random.default_rng(1))
    box = tessellate(primitive("box", 0.02, 0.03, 0.04))
    torus = torus_mesh(0.05, 0.015, 24, 12)
    # two bodies: the box (volume 2.4e-5) at the origin, the torus shifted by (0.3, -0.2, 0.1)
    vertices = np.concatenate([box[0], torus[0] + [0.3, -0.2, 0.1]])
    faces = np.concatenate([box[1], torus[1] + len(box[0])])
    props = mass_properties(mesh_object(vertices, faces, pose, density=800.0))
    # the polygonal torus: each of its 24 slices is a prism-like ring piece; its volume by the divergence theorem
    # is the polygon's area (12-gon of radius 0.015) times the path of its centroid (Pappus) times the chord
    # factor of the 24-gon, sin(2 pi / 24) / (2 pi / 24)
    polygon = 0.5 * 12 * 0.015**2 * math.sin(2 * math.pi / 12)
    ring = polygon * 2 * math.pi * 0.05 * math.sin(2 * math.pi / 24) / (2 * math.pi / 24)
    assert props.volume == pytest.approx(2.4e-5 + ring, rel=1e-12)
    assert props.mass == pytest.approx(800.0 * (2.4e-5 + ring), rel=1e-12)
    centre = ring / (2.4e-5 + ring) * np.array([0.3, -0.2, 0.1])  # each body's centroid at its own centre
    np.testing.assert_allclose(props.center_of_mass, pose[:3, :3] @ centre + pose[:3, 3], rtol=0, atol=1e-15)


def test_a_box_mesh_answers_as_the_box_off_its_edges():
    box = primitive("box", 0.02, 0.04, 0.06, pose=rigid_pose(np.random.default_rng(2)))
    mesh = mesh_object(*tessellate(box))
    rng = np.random.default_rng(3)
    q = rng.uniform(-1.5, 1.5, (3000, 3)) * np.array([0.01, 0.02, 0.03])
    q = q @ box.pose[:3, :3].T + box.pose[:3, 3]
    got, want = project_to_surface(mesh, q), project_to_surface(box, q)
    # coordinates about 1 (the pose's shift): a few units of 2.2e-16
    np.testing.assert_allclose(got.distance, want.distance, rtol=0, atol=1e-15)
    np.testing.assert_allclose(got.points, want.points, rtol=0, atol=1e-15)
    on_a_face = (np.abs(np.abs(want.normals @ box.pose[:3, :3]) - 1) < 1e-12).any(axis=1)
    assert on_a_face.mean() > 0.5
    np.testing.assert_allclose(got.normals[on_a_face], want.normals[on_a_face], rtol=0, atol=1e-12)


def test_inside_and_outside_of_a_torus_as_its_closed_form():
    big, small = 0.05, 0.015
    mesh = mesh_object(*torus_mesh(big, small, 48, 24))
    q = np.random.default_rng(4).uniform([-0.07, -0.07, -0.02], [0.07, 0.07, 0.02], (4000, 3))
    exact = np.hypot(np.hypot(q[:, 0], q[:, 1]) - big, q[:, 2]) - small
    got = project_to_surface(mesh, q).distance
    clear = np.abs(exact) > 1e-3  # beyond the chord error (0.3 mm here)
    assert clear.sum() > 3000
    np.testing.assert_array_equal(np.sign(got[clear]), np.sign(exact[clear]))
    assert np.abs(got - exact).max() < 1e-3


def winding_number(vertices, faces, q):
    """The generalized winding number of each point (Van Oosterom and Strackee's solid angles): 1 inside, 0 outside."""
    a, b, c = (vertices[faces[:, i]][None] - q[:, None] for i in range(3))
    la, lb, lc = (np.linalg.norm(x, axis=-1) for x in (a, b, c))
    det = np.einsum("pfi,pfi->pf", a, np.cross(b, c))
    dots = (
        np.einsum("pfi,pfi->pf", a, b) * lc + np.einsum("pfi,pfi->pf", b, c) * la + np.einsum("pfi,pfi->pf", c, a) * lb
    )
    return (2 * np.arctan2(det, la * lb * lc + dots)).sum(axis=1) / (4 * np.pi)


def test_points_a_hair_from_a_torus_mesh_are_inside_or_outside_as_its_winding_number_says():
    vertices, faces = torus_mesh(0.05, 0.015, 16, 8)  # concave inside the hole, convex outside
    mesh = mesh_object(vertices, faces)
    rng = np.random.default_rng(10)
    near = np.concatenate(
        [vertices, 0.5 * (vertices[faces[:, 0]] + vertices[faces[:, 1]]), sample_surface(mesh, 100, rng)[0]]
    )
    step = rng.normal(size=near.shape)
    q = near + step / np.linalg.norm(step, axis=1, keepdims=True) * 10 ** rng.uniform(
        -7, -4, (len(near), 1)
    ) * object_size(mesh)
    inside = winding_number(vertices, faces, q) > 0.5
    assert 0.3 < inside.mean() < 0.7
    np.testing.assert_array_equal(project_to_surface(mesh, q).distance < 0, inside)


TORUS = mesh_object(*torus_mesh(0.05, 0.015, 16, 8))
coordinate = st.floats(-0.08, 0.08, allow_nan=False)


@settings(max_examples=20, deadline=None)
@given(point=st.tuples(coordinate, coordinate, coordinate))
def test_a_mesh_point_is_its_distance_away_on_the_surface(point):
    s = project_to_surface(TORUS, point)
    assert np.linalg.norm(np.asarray(point) - s.points) == pytest.approx(abs(s.distance), rel=0, abs=1e-16)
    np.testing.assert_allclose(np.linalg.norm(s.normals), 1.0, rtol=0, atol=1e-15)
    again = project_to_surface(TORUS, s.points)
    assert abs(again.distance) <= 1e-16  # sizes about 0.1: round-off
    np.testing.assert_allclose(again.points, s.points, rtol=0, atol=1e-16)


def test_edges_and_vertices_take_the_area_weighted_normal_of_their_faces():
    v, f = SPHERE
    mesh = mesh_object(v, f)
    normals, areas = face_normals_areas(v, f)
    k = f[40, 0]  # a vertex of a band between two rings
    around = (f == k).any(axis=1)
    vertex_normal = (areas[around, None] * normals[around]).sum(axis=0)
    vertex_normal /= np.linalg.norm(vertex_normal)
    # from outside along a positive mix of its faces' normals (the mesh is convex), the vertex is nearest
    s = project_to_surface(mesh, v[k] + 1e-3 * vertex_normal)
    np.testing.assert_allclose(s.points, v[k], rtol=0, atol=1e-17)
    np.testing.assert_allclose(s.normals, -vertex_normal, rtol=0, atol=1e-15)
    a, b = f[40, 0], f[40, 1]  # an edge of face 40, and the face across it
    pair = np.flatnonzero((f == a).any(axis=1) & (f == b).any(axis=1))
    assert len(pair) == 2 and 40 in pair
    edge_normal = (areas[pair, None] * normals[pair]).sum(axis=0)
    edge_normal /= np.linalg.norm(edge_normal)
    middle = 0.5 * (v[a] + v[b])
    s = project_to_surface(mesh, middle + 1e-3 * edge_normal)
    np.testing.assert_allclose(s.points, middle, rtol=0, atol=1e-17)
    np.testing.assert_allclose(s.normals, -edge_normal, rtol=0, atol=1e-15)
    # off the edge by twice the tolerance, inside face 40: its own normal
    centre = v[f[40]].mean(axis=0)
    near = middle + 2 * MESH_EDGE_TOL * object_size(mesh) * (centre - middle) / np.linalg.norm(centre - middle)
    np.testing.assert_allclose(project_to_surface(mesh, near).normals, -normals[40], rtol=0, atol=1e-15)
    assert angle(edge_normal, normals[40]) > 1  # so the test tells them apart


def test_mesh_samples_lie_on_their_faces_and_are_reproducible():
    mesh = mesh_object(*torus_mesh(0.05, 0.015, 16, 8), rigid_pose(np.random.default_rng(5)))
    p, n = sample_surface(mesh, 400, np.random.default_rng(6))
    s = project_to_surface(mesh, p)
    assert np.abs(s.distance).max() < 1e-15  # coordinates about 1: round-off
    inner = angle(s.normals, n) < 1e-6  # all but the samples within the edge tolerance
    assert inner.mean() > 0.99
    np.testing.assert_array_equal(sample_surface(mesh, 400, np.random.default_rng(6))[0], p)


def test_mesh_samples_spread_by_area():
    box = tessellate(primitive("box", 1.0, 2.0, 3.0))  # faces' areas 6, 3, 2 (x, y, z normals)
    p, n = sample_surface(mesh_object(*box), 20000, np.random.default_rng(7))
    counts = np.bincount(np.argmax(np.abs(n), axis=1), minlength=3) / 20000
    np.testing.assert_allclose(counts, [6 / 11, 3 / 11, 2 / 11], rtol=0, atol=0.015)  # 4 binomial sigma


def test_a_mesh_tessellates_as_itself_in_the_grasp_frame():
    pose = rigid_pose(np.random.default_rng(8))
    v, f = tessellate(mesh_object(*SPHERE, pose))
    np.testing.assert_allclose(v, SPHERE[0] @ pose[:3, :3].T + pose[:3, 3], rtol=0, atol=1e-15)
    np.testing.assert_array_equal(f, SPHERE[1])


def test_moving_a_mesh_moves_its_projections():
    mesh = mesh_object(*torus_mesh(0.05, 0.015, 16, 8))
    rng = np.random.default_rng(9)
    q, pose = rng.uniform(-0.07, 0.07, (300, 3)), rigid_pose(rng)
    here = project_to_surface(mesh, q)
    there = project_to_surface(moved(mesh, pose), q @ pose[:3, :3].T + pose[:3, 3])
    np.testing.assert_allclose(there.points, here.points @ pose[:3, :3].T + pose[:3, 3], rtol=0, atol=1e-14)
    np.testing.assert_allclose(there.distance, here.distance, rtol=0, atol=1e-14)
    np.testing.assert_allclose(there.normals, here.normals @ pose[:3, :3].T, rtol=0, atol=1e-14)


CUBE_VERTICES, CUBE_FACES = tessellate(primitive("box", 1.0, 1.0, 1.0))


def test_a_point_that_is_not_finite_gets_nan_and_the_others_their_answer():
    s = project_to_surface(mesh_object(CUBE_VERTICES, CUBE_FACES), [[np.nan, 0, 0], [0, -np.inf, 0], [0, 0, 2]])
    assert np.isnan(s.points[:2]).all() and np.isnan(s.normals[:2]).all() and np.isnan(s.distance[:2]).all()
    assert (
        s.points[2].tolist() == [0.0, 0.0, 0.5] and s.normals[2].tolist() == [0.0, 0.0, -1.0] and s.distance[2] == 1.5
    )


def test_a_missing_libigl_is_one_line_naming_the_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "igl", None)  # import igl now raises ImportError
    mesh = mesh_object(CUBE_VERTICES, CUBE_FACES)
    with pytest.raises(MissingExtra, match=r"needs igl: pip install libigl .*pip install -e '\.\[mesh\]'"):
        project_to_surface(mesh, [0.0, 0.0, 2.0])
    assert mass_properties(mesh).volume == pytest.approx(1.0, rel=1e-15)  # what needs no libigl works without it
    assert sample_surface(mesh, 3, np.random.default_rng(0))[0].shape == (3, 3)


@pytest.mark.parametrize(
    "vertices, faces, match",
    [
        (None, CUBE_FACES, "mesh needs vertices and faces"),
        (CUBE_VERTICES[:, :2], CUBE_FACES, r"mesh vertices must have shape \(V, 3\) with V >= 4, got \(8, 2\)"),
        (
            np.where(np.arange(8)[:, None] == 5, np.nan, CUBE_VERTICES),
            CUBE_FACES,
            r"mesh vertex 5 is not finite: \[nan, nan, nan\]",
        ),
        (CUBE_VERTICES, CUBE_FACES[:, :2], r"mesh faces must have shape \(F, 3\) with F >= 1, got \(12, 2\)"),
        (CUBE_VERTICES, CUBE_FACES + 1, "mesh faces must be whole vertex indices from 0 to 7"),
        (CUBE_VERTICES, CUBE_FACES + 0.5, "mesh faces must be whole vertex indices from 0 to 7"),
        (CUBE_VERTICES, CUBE_FACES[:, ::-1], "mesh bounds no solid: its winding number is nowhere above 1/2"),
        (CUBE_VERTICES, np.array([[0, 0, 1]] * 4), "mesh bounds no solid: every face has zero area"),
        ([["a", "b", "c"]] * 8, CUBE_FACES, "mesh vertices must hold real numbers"),
    ],
)
def test_check_shape_refuses_a_bad_mesh(vertices, faces, match):
    with pytest.raises(ValueError, match=match):
        check_shape(Shape("mesh", np.zeros(0), vertices, faces))


def split_cube():
    """The unit cube with its edge 0-3 split at its midpoint 8 by the zero-area face (3, 8, 0)."""
    v = np.vstack([CUBE_VERTICES, 0.5 * (CUBE_VERTICES[0] + CUBE_VERTICES[3])])
    f = CUBE_FACES.tolist()
    f.remove([0, 3, 2])
    return v, np.array([*f, [0, 8, 2], [8, 3, 2], [3, 8, 0]])


def test_check_shape_drops_a_degenerate_face_and_keeps_the_cube():
    # paired with the cube's edge 0-3 it would give that edge one face's normal, not the bisector
    s = check_shape(Shape("mesh", np.zeros(0), *split_cube()))
    assert len(s.faces) == 13 and [3, 8, 0] not in s.faces.tolist()
    assert mass_properties(GraspObject(s, np.eye(4))).volume == pytest.approx(1.0, rel=1e-12)
    e = project_to_surface(GraspObject(s, np.eye(4)), [[-0.6, -0.6, -0.6]])  # corner 0: the faces' average normal
    assert e.distance[0] == pytest.approx(0.1 * 3**0.5, rel=1e-12) and (e.normals[0] > 0.4).all() and e.on_edge[0]


@pytest.mark.parametrize(
    "faces",
    [CUBE_FACES[1:], np.vstack([CUBE_FACES[:1, ::-1], CUBE_FACES[1:]]), np.vstack([[[0, 0, 1]], CUBE_FACES])],
    ids=["open", "one-face-flipped", "repeated-corner"],
)
def test_check_shape_takes_an_open_or_miswound_cube_as_the_cube(faces):
    o = mesh_object(CUBE_VERTICES, faces)
    assert mass_properties(o).volume == pytest.approx(1.0, rel=1e-2)
    s = project_to_surface(o, [[0.1, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]])
    np.testing.assert_allclose(s.distance, [-0.4, 0.5, 0.5], atol=1e-12)


@pytest.mark.parametrize("scale", [1e76, 1e100, 1e-76, 1e-160])
def test_check_shape_refuses_a_mesh_whose_size_is_beyond_double_precision_areas(scale):
    with pytest.raises(
        ValueError, match=r"^mesh size \(the diagonal of its bounding box\) is .*, outside 1e-75 to 1e\+75"
    ):
        check_shape(Shape("mesh", np.zeros(0), CUBE_VERTICES * scale, CUBE_FACES))


@pytest.mark.parametrize("scale", [1e74, 1e-74])
def test_a_mesh_at_the_ends_of_the_size_range_samples_and_projects(scale):
    mesh = mesh_object(CUBE_VERTICES * scale, CUBE_FACES)
    p, n = sample_surface(mesh, 50, np.random.default_rng(0))
    assert np.isfinite(p).all() and np.isfinite(n).all()
    s = project_to_surface(mesh, [[0.5 * scale, 0.1 * scale, 0.2 * scale], [2 * scale, 0, 0]])
    np.testing.assert_allclose(s.distance / scale, [0.0, 1.5], rtol=0, atol=1e-15)
    np.testing.assert_allclose(s.normals, [[-1, 0, 0], [-1, 0, 0]], rtol=0, atol=1e-15)


def test_check_shape_keeps_a_mesh_read_only():
    s = check_shape(Shape("mesh", np.zeros(0), CUBE_VERTICES.tolist(), CUBE_FACES.tolist(), source="cube.stl"))
    assert s.vertices.dtype == np.float64 and s.faces.dtype == np.int64 and s.source == "cube.stl"
    assert not (s.vertices.flags.writeable or s.faces.flags.writeable)


def test_on_edge_is_true_within_the_mesh_edge_tolerance_of_an_edge_or_vertex():
    mesh = mesh_object(CUBE_VERTICES, CUBE_FACES)  # the unit cube, faces halved by a diagonal
    tol = MESH_EDGE_TOL * object_size(mesh)
    q = [
        [1.0, 1.0, 0.1],  # outside the edge x = y = 0.5
        [1.0, 1.0, 1.0],  # outside a corner
        [0.6, 0.3, -0.1],  # over the +x face, off its diagonal
        [0.6, 0.0, 0.0],  # over the middle of the +x face: its diagonal, an edge between coplanar faces
        [0.6, 0.5 - 2 * tol, 0.1],  # over the +x face, twice the tolerance from its edge
        [0.6, 0.5 - 0.5 * tol, 0.1],  # half the tolerance from it
    ]
    assert project_to_surface(mesh, q).on_edge.tolist() == [True, True, False, True, False, True]
