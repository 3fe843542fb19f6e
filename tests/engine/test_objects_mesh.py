"""A mesh object against the primitives it approximates, against trimesh's mass properties and against a torus's
closed form (inside or outside), its normals at faces, edges and vertices, and the validators' mesh branches."""

import math
import sys

import numpy as np
import pytest

trimesh = pytest.importorskip("trimesh")
pytest.importorskip("igl")

from grasp_gen import rotation  # noqa: E402
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


def mesh_object(m, pose=None, **kw):
    shape = Shape("mesh", np.zeros(0), np.array(m.vertices, dtype=float), np.array(m.faces), source="test.stl")
    return check_object(GraspObject(shape, np.eye(4) if pose is None else pose, **kw))


def pose_of(rng):
    p = np.eye(4)
    p[:3, :3] = rotation(rng)
    p[:3, 3] = rng.uniform(-1, 1, 3)
    return p


def angle(a, b):
    return np.degrees(np.arctan2(np.linalg.norm(np.cross(a, b), axis=-1), np.einsum("...i,...i->...", a, b)))


RADIUS = 0.04
ICO = trimesh.creation.icosphere(subdivisions=3, radius=RADIUS)  # 1280 faces


def chord_gap(m):
    """How far inside the sphere the flat faces get (each face's plane distance from the centre)."""
    a = m.vertices[m.faces[:, 0]]
    return RADIUS - np.min(np.einsum("ij,ij->i", m.face_normals, a))


def test_an_icosphere_projects_as_its_sphere_within_the_chord_error():
    rng = np.random.default_rng(0)
    pose = pose_of(rng)
    mesh = mesh_object(ICO, pose)
    sphere = check_object(GraspObject(Shape("sphere", np.array([RADIUS])), pose))
    q = pose[:3, 3] + rng.uniform(-0.08, 0.08, (2000, 3))
    got, want = project_to_surface(mesh, q), project_to_surface(sphere, q)
    gap = chord_gap(ICO)  # 0.45 % of the radius
    assert 0 < gap < 5e-3 * RADIUS
    assert np.abs(got.distance - want.distance).max() <= gap
    # outside the faces' planes, the radial direction of q lies within the cone of the vertices about the normal
    # of its nearest face (or about the faces' normals at its nearest edge or vertex)
    cone = angle(ICO.vertices[ICO.faces], ICO.face_normals[:, None, :]).max()
    assert 5 < cone < 6
    out = np.linalg.norm(q - pose[:3, 3], axis=1) >= RADIUS - gap
    assert out.mean() > 0.9
    assert angle(got.normals, want.normals)[out].max() <= cone
    assert np.linalg.norm(got.points - want.points, axis=1)[out].max() < RADIUS * math.radians(cone)
    np.testing.assert_allclose(np.linalg.norm(q - got.points, axis=1), np.abs(got.distance), rtol=0, atol=1e-15)


def test_mesh_mass_properties_agree_with_trimesh():
    m = trimesh.creation.torus(0.05, 0.015, major_sections=24, minor_sections=12)
    m.apply_translation([0.3, -0.2, 0.1])
    m = trimesh.util.concatenate([m, trimesh.creation.box([0.02, 0.03, 0.04])])  # two bodies, one off-centre
    pose = pose_of(np.random.default_rng(1))
    props = mass_properties(mesh_object(m, pose, density=800.0))
    assert props.volume == pytest.approx(m.volume, rel=1e-12)
    assert props.mass == pytest.approx(800.0 * m.volume, rel=1e-12)
    np.testing.assert_allclose(props.center_of_mass, pose[:3, :3] @ m.center_mass + pose[:3, 3], rtol=0, atol=1e-13)


def test_a_box_mesh_answers_as_the_box_off_its_edges():
    box = check_object(GraspObject(Shape("box", np.array([0.02, 0.04, 0.06])), pose_of(np.random.default_rng(2))))
    mesh = mesh_object(trimesh.Trimesh(*tessellate(box), process=False))
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
    m = trimesh.creation.torus(big, small, major_sections=48, minor_sections=24)
    mesh = mesh_object(m)
    q = np.random.default_rng(4).uniform([-0.07, -0.07, -0.02], [0.07, 0.07, 0.02], (4000, 3))
    exact = np.hypot(np.hypot(q[:, 0], q[:, 1]) - big, q[:, 2]) - small
    got = project_to_surface(mesh, q).distance
    clear = np.abs(exact) > 1e-3  # beyond the chord error (0.3 mm here)
    assert clear.sum() > 3000
    np.testing.assert_array_equal(np.sign(got[clear]), np.sign(exact[clear]))
    assert np.abs(got - exact).max() < 1e-3


def test_edges_and_vertices_take_the_area_weighted_normal_of_their_faces():
    mesh = mesh_object(ICO)
    v, f = ICO.vertices, ICO.faces
    faces_at_0 = np.flatnonzero((f == 0).any(axis=1))
    area_normal = (ICO.area_faces[faces_at_0, None] * ICO.face_normals[faces_at_0]).sum(axis=0)
    area_normal /= np.linalg.norm(area_normal)
    s = project_to_surface(mesh, 1.5 * v[0])  # straight out from vertex 0: nearest is the vertex
    np.testing.assert_allclose(s.points, v[0], rtol=0, atol=1e-17)
    np.testing.assert_allclose(s.normals, -area_normal, rtol=0, atol=1e-15)
    a, b = f[0, 0], f[0, 1]  # an edge of face 0, and the face across it
    other = [i for i in np.flatnonzero((f == a).any(axis=1) & (f == b).any(axis=1)) if i != 0][0]
    two = ICO.area_faces[[0, other], None] * ICO.face_normals[[0, other]]
    edge_normal = two.sum(axis=0) / np.linalg.norm(two.sum(axis=0))
    middle = 0.5 * (v[a] + v[b])
    s = project_to_surface(mesh, middle * 1.2)
    np.testing.assert_allclose(s.points, middle, rtol=0, atol=1e-16)
    np.testing.assert_allclose(s.normals, -edge_normal, rtol=0, atol=1e-15)
    # off the edge by twice the tolerance, inside face 0: its own normal
    centre = v[f[0]].mean(axis=0)
    near = middle + 2 * MESH_EDGE_TOL * object_size(mesh) * (centre - middle) / np.linalg.norm(centre - middle)
    np.testing.assert_allclose(project_to_surface(mesh, near).normals, -ICO.face_normals[0], rtol=0, atol=1e-15)


def test_mesh_samples_lie_on_their_faces_and_are_reproducible():
    m = trimesh.creation.torus(0.05, 0.015, major_sections=16, minor_sections=8)
    mesh = mesh_object(m, pose_of(np.random.default_rng(5)))
    p, n = sample_surface(mesh, 400, np.random.default_rng(6))
    s = project_to_surface(mesh, p)
    assert np.abs(s.distance).max() < 1e-15  # coordinates about 1: round-off
    inner = angle(s.normals, n) < 1e-6  # all but the samples within the edge tolerance
    assert inner.mean() > 0.99
    np.testing.assert_array_equal(sample_surface(mesh, 400, np.random.default_rng(6))[0], p)


def test_mesh_samples_spread_by_area():
    box = trimesh.creation.box([1.0, 2.0, 3.0])  # faces' areas 6, 3, 2 (x, y, z normals)
    p, n = sample_surface(mesh_object(box), 20000, np.random.default_rng(7))
    counts = np.bincount(np.argmax(np.abs(n), axis=1), minlength=3) / 20000
    np.testing.assert_allclose(counts, [6 / 11, 3 / 11, 2 / 11], rtol=0, atol=0.015)  # 4 binomial sigma


def test_a_mesh_tessellates_as_itself_in_the_grasp_frame():
    pose = pose_of(np.random.default_rng(8))
    v, f = tessellate(mesh_object(ICO, pose))
    np.testing.assert_allclose(v, ICO.vertices @ pose[:3, :3].T + pose[:3, 3], rtol=0, atol=1e-15)
    np.testing.assert_array_equal(f, ICO.faces)


def test_moving_a_mesh_moves_its_projections():
    mesh = mesh_object(trimesh.creation.torus(0.05, 0.015, major_sections=16, minor_sections=8))
    rng = np.random.default_rng(9)
    q, pose = rng.uniform(-0.07, 0.07, (300, 3)), pose_of(rng)
    here = project_to_surface(mesh, q)
    there = project_to_surface(moved(mesh, pose), q @ pose[:3, :3].T + pose[:3, 3])
    np.testing.assert_allclose(there.points, here.points @ pose[:3, :3].T + pose[:3, 3], rtol=0, atol=1e-14)
    np.testing.assert_allclose(there.distance, here.distance, rtol=0, atol=1e-14)
    np.testing.assert_allclose(there.normals, here.normals @ pose[:3, :3].T, rtol=0, atol=1e-14)


def test_a_missing_libigl_is_one_line_naming_the_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "igl", None)  # import igl now raises ImportError
    mesh = mesh_object(trimesh.creation.box([1.0, 1.0, 1.0]))
    with pytest.raises(MissingExtra, match=r"needs igl: pip install libigl .*pip install -e '\.\[mesh\]'"):
        project_to_surface(mesh, [0.0, 0.0, 2.0])


CUBE = trimesh.creation.box([1.0, 1.0, 1.0])


@pytest.mark.parametrize(
    "vertices, faces, match",
    [
        (None, CUBE.faces, "mesh needs vertices and faces"),
        (CUBE.vertices[:, :2], CUBE.faces, r"mesh vertices must have shape \(V, 3\) with V >= 4, got \(8, 2\)"),
        (
            np.where(np.arange(8)[:, None] == 5, np.nan, CUBE.vertices),
            CUBE.faces,
            r"mesh vertex 5 is not finite: \[nan, nan, nan\]",
        ),
        (CUBE.vertices, CUBE.faces[:, :2], r"mesh faces must have shape \(F, 3\) with F >= 4, got \(12, 2\)"),
        (CUBE.vertices, CUBE.faces + 1, "mesh faces must be whole vertex indices from 0 to 7"),
        (CUBE.vertices, CUBE.faces + 0.5, "mesh faces must be whole vertex indices from 0 to 7"),
        (CUBE.vertices, CUBE.faces[1:], "mesh is not closed: 3 edge"),
        (CUBE.vertices, np.vstack([CUBE.faces[:1, ::-1], CUBE.faces[1:]]), "not consistently oriented or not manifold"),
        (CUBE.vertices, CUBE.faces[:, ::-1], "mesh encloses no positive volume: its faces must be counter-clockwise"),
        (CUBE.vertices, np.vstack([[[0, 0, 1]], CUBE.faces]), "mesh has a face with a repeated vertex"),
        ([["a", "b", "c"]] * 8, CUBE.faces, "mesh vertices must hold real numbers"),
    ],
)
def test_check_shape_refuses_a_bad_mesh(vertices, faces, match):
    with pytest.raises(ValueError, match=match):
        check_shape(Shape("mesh", np.zeros(0), vertices, faces))


def test_check_shape_keeps_a_mesh_read_only():
    s = check_shape(Shape("mesh", np.zeros(0), CUBE.vertices.tolist(), CUBE.faces.tolist(), source="cube.stl"))
    assert s.vertices.dtype == np.float64 and s.faces.dtype == np.int64 and s.source == "cube.stl"
    assert not (s.vertices.flags.writeable or s.faces.flags.writeable)
