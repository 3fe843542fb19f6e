"""An object's primitives against their closed forms: nearest points and normals (faces, edges, corners, axes),
volumes, area-weighted samples, triangles; invariance under a rigid pose; the validators' every branch."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from grasp_gen import rigid_pose
from grasptwist.engine.objects import (
    check_object,
    check_pose,
    check_shape,
    check_size,
    mass_properties,
    moved,
    object_size,
    primitives,
    project_to_surface,
    sample_surface,
    tessellate,
)
from grasptwist.model import GraspObject, Shape

S3 = 1 / math.sqrt(3)
S2 = 1 / math.sqrt(2)


def obj(kind, *size, pose=None, **kw):
    return check_object(
        GraspObject(Shape(kind, np.array(size, dtype=float)), np.eye(4) if pose is None else pose, **kw)
    )


def assert_projects(o, point, surface, normal, distance):
    s = project_to_surface(o, point)
    np.testing.assert_allclose(s.points, surface, rtol=0, atol=1e-15)
    np.testing.assert_allclose(s.normals, normal, rtol=0, atol=1e-15)
    np.testing.assert_allclose(s.distance, distance, rtol=0, atol=1e-15)


BOX = obj("box", 2.0, 4.0, 6.0)  # half edges 1, 2, 3


@pytest.mark.parametrize(
    "point, surface, normal, distance",
    [
        ([3, 0, 0], [1, 0, 0], [-1, 0, 0], 2.0),  # in front of a face
        ([0, -2.5, 1], [0, -2, 1], [0, 1, 0], 0.5),
        ([0.5, 0, 0], [1, 0, 0], [-1, 0, 0], -0.5),  # inside, nearest the +x face
        ([0, 0, -2.5], [0, 0, -3], [0, 0, 1], -0.5),  # inside, nearest the -z face (0.5 < 1 and 2)
        ([2, 3, 0], [1, 2, 0], [-S2, -S2, 0], math.sqrt(2)),  # beside an edge: towards the edge
        ([2, -3, 4], [1, -2, 3], [-S3, S3, -S3], math.sqrt(3)),  # beside a corner
        ([1, 2, 0], [1, 2, 0], [-S2, -S2, 0], 0.0),  # on an edge: the faces' bisector
        ([-1, 2, 3], [-1, 2, 3], [S3, -S3, -S3], 0.0),  # on a corner
        ([1, 0.5, 0.5], [1, 0.5, 0.5], [-1, 0, 0], 0.0),  # on a face
        ([0, 0, 0], [1, 0, 0], [-1, 0, 0], -1.0),  # the centre: nearest +x face (1 < 2 < 3)
    ],
)
def test_box_closed_forms(point, surface, normal, distance):
    assert_projects(BOX, point, surface, normal, distance)


def test_a_cube_centre_goes_to_the_first_positive_face():
    assert_projects(obj("box", 2.0, 2.0, 2.0), [0, 0, 0], [1, 0, 0], [-1, 0, 0], -1.0)


@pytest.mark.parametrize(
    "point, surface, normal, distance",
    [
        ([0, 0, 3], [0, 0, 2], [0, 0, -1], 1.0),
        ([1, 1, 0], [S2 * 2, S2 * 2, 0], [-S2, -S2, 0], math.sqrt(2) - 2),
        ([0, 0, 0], [2, 0, 0], [-1, 0, 0], -2.0),  # the centre: the +x side
    ],
)
def test_sphere_closed_forms(point, surface, normal, distance):
    assert_projects(obj("sphere", 2.0), point, surface, normal, distance)


CYLINDER = obj("cylinder", 1.0, 4.0)  # radius 1, z in [-2, 2]


@pytest.mark.parametrize(
    "point, surface, normal, distance",
    [
        ([0, 3, 1], [0, 1, 1], [0, -1, 0], 2.0),  # side
        ([0.6, 0.8, 0.5], [0.6, 0.8, 0.5], [-0.6, -0.8, 0], 0.0),  # on the side
        ([0.3, 0, 3], [0.3, 0, 2], [0, 0, -1], 1.0),  # above the top cap
        ([0.3, 0, -1.5], [0.3, 0, -2], [0, 0, 1], -0.5),  # inside, nearest the bottom cap
        ([0.5, 0, 0], [1, 0, 0], [-1, 0, 0], -0.5),  # inside, nearest the side
        ([0, 0, 0], [1, 0, 0], [-1, 0, 0], -1.0),  # on the axis: the +x side
        ([0, 0, 5], [0, 0, 2], [0, 0, -1], 3.0),  # on the axis above the cap
        ([0, 4, 6], [0, 1, 2], [0, -0.6, -0.8], 5.0),  # beside the rim: towards it (3, 4, 5)
        ([0, -1, 2], [0, -1, 2], [0, S2, -S2], 0.0),  # on the rim: bisector of side and cap
    ],
)
def test_cylinder_closed_forms(point, surface, normal, distance):
    assert_projects(CYLINDER, point, surface, normal, distance)


CAPSULE = obj("capsule", 1.0, 2.0)  # radius 1, cap centres at z = +-1


@pytest.mark.parametrize(
    "point, surface, normal, distance",
    [
        ([0, 2, 0.5], [0, 1, 0.5], [0, -1, 0], 1.0),  # beside the tube
        ([0, 0, 3], [0, 0, 2], [0, 0, -1], 1.0),  # above the top cap
        ([0, 3, -5], [0, 0.6, -1.8], [0, -0.6, 0.8], 4.0),  # below and beside the bottom cap (3, 4, 5)
        ([0, 0, 0.5], [1, 0, 0.5], [-1, 0, 0], -1.0),  # on the axis segment: the +x side
        ([0, 0, 1.5], [0, 0, 2], [0, 0, -1], -0.5),  # inside the top cap, on the axis
    ],
)
def test_capsule_closed_forms(point, surface, normal, distance):
    assert_projects(CAPSULE, point, surface, normal, distance)


@pytest.mark.parametrize(
    "kind, size", [("box", (2.0, 4.0, 6.0)), ("sphere", (2.0,)), ("cylinder", (1.0, 4.0)), ("capsule", (1.0, 2.0))]
)
def test_the_vectorised_primitives_agree_with_their_per_point_twin(kind, size):
    q = np.random.default_rng(13).uniform(-5, 5, (300, 3))
    c, n, d, _ = primitives.nearest(kind, np.array(size), q, 0.0)
    point, normal, distance = (np.array(a) for a in zip(*(primitives.nearest_one(kind, size, p) for p in q.tolist())))
    np.testing.assert_allclose(c, point, rtol=0, atol=4e-15)
    np.testing.assert_allclose(n, normal, rtol=0, atol=4e-16)
    np.testing.assert_allclose(d, distance, rtol=0, atol=4e-15)


def test_projection_keeps_batch_shape_and_takes_no_points():
    s = project_to_surface(BOX, np.zeros((2, 5, 3)))
    assert s.points.shape == (2, 5, 3) and s.normals.shape == (2, 5, 3) and s.distance.shape == (2, 5)
    assert project_to_surface(BOX, np.zeros((0, 3))).distance.shape == (0,)


KINDS = [obj("box", 0.03, 0.05, 0.08), obj("sphere", 0.04), obj("cylinder", 0.03, 0.1), obj("capsule", 0.02, 0.06)]


@pytest.mark.parametrize("o", KINDS, ids=lambda o: o.shape.kind)
def test_projecting_the_moved_object_moves_the_projections(o):
    rng = np.random.default_rng(3)
    q = rng.uniform(-0.1, 0.1, (200, 3))
    pose = rigid_pose(rng)
    here = project_to_surface(o, q)
    there = project_to_surface(moved(o, pose), q @ pose[:3, :3].T + pose[:3, 3])
    np.testing.assert_allclose(there.points, here.points @ pose[:3, :3].T + pose[:3, 3], rtol=0, atol=1e-15)
    np.testing.assert_allclose(there.normals, here.normals @ pose[:3, :3].T, rtol=0, atol=1e-14)
    np.testing.assert_allclose(there.distance, here.distance, rtol=0, atol=1e-15)


coordinate = st.floats(-0.2, 0.2, allow_nan=False)


@settings(max_examples=20, deadline=None)
@given(
    kind=st.sampled_from(range(len(KINDS))),
    point=st.tuples(coordinate, coordinate, coordinate),
    seed=st.integers(0, 2**32 - 1),
)
def test_the_surface_point_is_on_the_surface_along_the_normal(kind, point, seed):
    o = moved(KINDS[kind], rigid_pose(np.random.default_rng(seed)))
    s = project_to_surface(o, point)
    np.testing.assert_allclose(np.linalg.norm(s.normals), 1.0, rtol=0, atol=1e-15)
    # coordinates up to 1.4 (the pose's shift): a few units of 2.2e-16 each
    np.testing.assert_allclose(s.points, np.asarray(point) + s.distance * s.normals, rtol=0, atol=1e-14)
    again = project_to_surface(o, s.points)
    assert abs(again.distance) <= 1e-14
    np.testing.assert_allclose(again.points, s.points, rtol=0, atol=1e-14)


@pytest.mark.parametrize(
    "o, volume",
    [
        (obj("box", 1.0, 2.0, 3.0), 6.0),
        (obj("sphere", 2.0), 32 / 3 * math.pi),
        (obj("cylinder", 2.0, 3.0), 12 * math.pi),
        (obj("capsule", 1.0, 2.0), 2 * math.pi + 4 / 3 * math.pi),
    ],
    ids=lambda x: getattr(getattr(x, "shape", None), "kind", ""),
)
def test_mass_properties_closed_forms(o, volume):
    pose = rigid_pose(np.random.default_rng(4))
    m = mass_properties(check_object(GraspObject(o.shape, pose, density=500.0)))
    assert m.volume == pytest.approx(volume, rel=1e-15)
    assert m.mass == pytest.approx(500.0 * volume, rel=1e-15)
    np.testing.assert_allclose(m.center_of_mass, pose[:3, 3], rtol=0, atol=0)
    assert mass_properties(GraspObject(o.shape, pose, mass=2.0, density=500.0)).mass == 2.0  # a given mass wins
    assert mass_properties(o).mass is None


def test_object_size_is_the_bounding_box_diagonal():
    assert object_size(obj("box", 3.0, 4.0, 12.0)) == 13.0
    assert object_size(obj("sphere", 1.0)) == pytest.approx(2 * math.sqrt(3), rel=1e-15)
    assert object_size(obj("cylinder", 1.0, 1.0)) == pytest.approx(3.0, rel=1e-15)  # 2, 2, 1
    assert object_size(obj("capsule", 1.0, 2.0)) == pytest.approx(math.sqrt(24), rel=1e-15)  # 2, 2, 4
    assert object_size(moved(obj("box", 3.0, 4.0, 12.0), rigid_pose(np.random.default_rng(0)))) == 13.0


def test_box_samples_fall_on_its_faces_in_proportion_to_their_areas():
    o = obj("box", 1.0, 2.0, 3.0)  # face areas 6, 3, 2 (x, y, z): 6/11, 3/11, 2/11 of the samples
    pose = rigid_pose(np.random.default_rng(5))
    n = 20000
    p, normals = sample_surface(moved(o, pose), n, np.random.default_rng(6))
    local, inward = (p - pose[:3, 3]) @ pose[:3, :3], normals @ pose[:3, :3]
    axis = np.argmax(np.abs(inward), axis=1)
    # binomial standard deviation sqrt(p (1 - p) / n) <= 0.0036: 4 sigma
    np.testing.assert_allclose(np.bincount(axis, minlength=3) / n, [6 / 11, 3 / 11, 2 / 11], rtol=0, atol=0.015)
    np.testing.assert_allclose(np.abs(local[np.arange(n), axis]), np.array([0.5, 1.0, 1.5])[axis], rtol=0, atol=1e-14)
    assert (local * inward).sum(axis=1).max() < 0  # inward: towards the centre


@pytest.mark.parametrize("o", KINDS, ids=lambda o: o.shape.kind)
def test_samples_lie_on_the_surface_with_its_normal_and_are_reproducible(o):
    o = moved(o, rigid_pose(np.random.default_rng(7)))
    p, n = sample_surface(o, 500, np.random.default_rng(8))
    s = project_to_surface(o, p)
    np.testing.assert_allclose(s.distance, 0.0, rtol=0, atol=1e-15)
    on_edge = np.abs(np.abs(s.normals @ n.T).diagonal() - 1) > 1e-12  # a sample on a rim is measure zero
    assert not on_edge.any()
    np.testing.assert_allclose(s.normals, n, rtol=0, atol=1e-13)
    again, _ = sample_surface(o, 500, np.random.default_rng(8))
    np.testing.assert_array_equal(again, p)


def test_capsule_samples_split_tube_and_caps_by_area():
    o = obj("capsule", 1.0, 2.0)  # tube 4 pi, caps 4 pi: half each
    p, _ = sample_surface(o, 20000, np.random.default_rng(9))
    assert np.mean(np.abs(p[:, 2]) <= 1.0) == pytest.approx(0.5, abs=0.015)  # 4 sigma


def volume_of(vertices, faces):
    a, b, c = (vertices[faces[:, i]] for i in range(3))
    return np.einsum("ij,ij->", a, np.cross(b, c)) / 6


def assert_closed(faces):
    """Every directed edge once and its reverse once: watertight and consistently oriented."""
    edges = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    n = faces.max() + 1
    directed = np.unique(edges[:, 0] * n + edges[:, 1])
    assert len(directed) == len(edges)
    np.testing.assert_array_equal(np.unique(edges[:, 1] * n + edges[:, 0]), directed)


@pytest.mark.parametrize(
    "o, volume",
    [
        (obj("box", 1.0, 2.0, 3.0), 6.0),
        # 16 segments: a cylinder's polygon is (n / 2) sin(2 pi / n) r^2 of the circle's pi r^2
        (obj("cylinder", 1.0, 2.0), 2 * 8 * math.sin(2 * math.pi / 16)),
    ],
    ids=["box", "cylinder"],
)
def test_tessellation_is_watertight_with_the_closed_form_volume(o, volume):
    pose = rigid_pose(np.random.default_rng(10))
    v, f = tessellate(moved(o, pose), segments=16)
    assert_closed(f)
    assert volume_of(v, f) == pytest.approx(volume, rel=1e-13)
    assert abs(project_to_surface(moved(o, pose), v).distance).max() <= 1e-15


@pytest.mark.parametrize("o", KINDS[1:], ids=lambda o: o.shape.kind)
def test_round_tessellations_lie_on_the_surface_and_approach_its_volume(o):
    coarse, fine = (tessellate(o, segments=k) for k in (16, 64))
    for v, f in (coarse, fine):
        assert_closed(f)
        assert abs(project_to_surface(o, v).distance).max() <= 1e-16  # sizes 0.02-0.1: a unit of round-off
    exact = mass_properties(o).volume
    below = [exact - volume_of(*t) for t in (coarse, fine)]
    assert 0 < below[1] < below[0] / 10  # inscribed, and the error falls as 1 / segments^2 (16 times)
    assert below[1] < 5e-3 * exact  # about (2 pi / 64)^2 / 6 per direction of the rings


@pytest.mark.parametrize(
    "shape, match",
    [
        (Shape("box", np.full(3, 1e100)), r"^box size \(the diagonal of its bounding box\) is 1.73e\+100, outside"),
        (Shape("sphere", [1e-80]), r"^sphere size \(the diagonal of its bounding box\) is 3.46e-80, outside"),
        (Shape("box", np.full(3, 1e200)), "^box size overflows double precision: rescale it"),
    ],
)
def test_check_shape_refuses_a_size_beyond_double_precision_areas(shape, match):
    with pytest.raises(ValueError, match=match):
        check_shape(shape)


def test_the_sphere_tessellation_has_the_promised_rings():
    v, f = tessellate(obj("sphere", 1.0), segments=8)  # 4 bands: 3 rings of 8 and 2 poles
    assert v.shape == (26, 3) and f.shape == (48, 3)


@pytest.mark.parametrize(
    "shape, match",
    [
        (Shape("cone", np.ones(2)), "shape kind must be one of box, sphere, cylinder, capsule, mesh, got 'cone'"),
        (Shape("box", np.ones(2)), r"box size must hold 3 number\(s\) \(a, b, c\), got 2"),
        (Shape("box", np.array([1.0, -1.0, 1.0])), "box b must be a finite number > 0, got -1.0"),
        (Shape("sphere", np.zeros(1)), "sphere radius must be a finite number > 0, got 0.0"),
        (Shape("cylinder", np.array([1.0, np.nan])), "cylinder height must be a finite number > 0, got nan"),
        (Shape("capsule", np.array([np.inf, 1.0])), "capsule radius must be a finite number > 0, got inf"),
        (Shape("box", ["a", 1, 1]), "box size must hold real numbers"),
        ("box", "shape must be a Shape, got str"),
    ],
)
def test_check_shape_refuses(shape, match):
    with pytest.raises(ValueError, match=match):
        check_shape(shape)


def test_a_scalar_radius_is_a_sphere_everywhere():
    """A sphere's one size as a number alone, in a Shape built by hand and never checked."""
    ball = GraspObject(Shape("sphere", 0.035), np.eye(4), mass=1.0)  # 0.5.0: TypeError in mass_properties
    assert check_size("sphere", 0.035).tolist() == check_shape(ball.shape).size.tolist() == [0.035]
    assert mass_properties(ball).volume == pytest.approx(4 / 3 * math.pi * 0.035**3, rel=1e-12)
    assert float(project_to_surface(ball, [0.0, 0.0, 0.05]).distance) == pytest.approx(0.015, rel=1e-12)
    assert tessellate(ball, segments=8)[0].shape == (26, 3) and object_size(ball) == pytest.approx(0.07 * math.sqrt(3))


@pytest.mark.parametrize(
    "use", [mass_properties, object_size, tessellate, lambda o: project_to_surface(o, [0.0, 0.0, 1.0])]
)
@pytest.mark.parametrize(
    "shape, match",
    [
        (Shape("cylinder", 0.035), r"^cylinder size must hold 2 number\(s\) \(radius, height\), got 1$"),
        (Shape("box", [0.1, 0.1]), r"^box size must hold 3 number\(s\) \(a, b, c\), got 2$"),
        (Shape("sphere", "big"), "^sphere size must hold real numbers$"),
        (Shape("sphere", -1.0), r"^sphere radius must be a finite number > 0, got -1.0$"),
    ],
)
def test_a_hand_built_shape_with_a_wrong_size_is_one_line_naming_the_field(use, shape, match):
    with pytest.raises(ValueError, match=match):
        use(GraspObject(shape, np.eye(4)))


def test_sample_surface_checks_the_size_too():
    with pytest.raises(ValueError, match=r"^capsule size must hold 2 number\(s\)"):
        sample_surface(GraspObject(Shape("capsule", 0.01), np.eye(4)), 3, np.random.default_rng(0))


def test_check_shape_returns_read_only_floats():
    s = check_shape(Shape("box", [1, 2, 3]))
    assert s.size.dtype == np.float64 and not s.size.flags.writeable


def bad_pose(change):
    p = np.eye(4)
    change(p)
    return p


@pytest.mark.parametrize(
    "pose, match",
    [
        (np.eye(3), r"pose must have shape \(4, 4\), got \(3, 3\)"),
        (bad_pose(lambda p: p.__setitem__((0, 3), np.nan)), "pose must be finite"),
        (bad_pose(lambda p: p.__setitem__((1, 3), np.inf)), "pose must be finite"),
        (
            bad_pose(lambda p: p.__setitem__((3, 0), 1.0)),
            r"its last row must be \(0, 0, 0, 1\), got \(1.0, 0.0, 0.0, 1.0\)",
        ),
        (bad_pose(lambda p: p.__setitem__((0, 0), 2.0)), "its rotation block is not a rotation"),  # a scale
        (bad_pose(lambda p: p.__setitem__((0, 1), 1e-6)), "its rotation block is not a rotation"),  # a shear
        (np.diag([-1.0, 1, 1, 1]), "its rotation block is not a rotation"),  # a mirror
        ([["x"] * 4] * 4, "pose must hold real numbers"),
    ],
)
def test_check_pose_refuses(pose, match):
    with pytest.raises(ValueError, match=match):
        check_pose(pose)


def test_check_pose_takes_a_rotation_to_round_off():
    p = rigid_pose(np.random.default_rng(11))
    assert not check_pose(p).flags.writeable


@pytest.mark.parametrize(
    "o, match",
    [
        (
            GraspObject(Shape("sphere", np.ones(1)), np.eye(4), mass=-1.0),
            "object mass must be a finite number > 0, got -1.0",
        ),
        (
            GraspObject(Shape("sphere", np.ones(1)), np.eye(4), density=math.nan),
            "object density must be a finite number > 0, got nan",
        ),
        (
            GraspObject(Shape("sphere", np.ones(1)), np.eye(4), density="heavy"),
            "object density must be a finite number > 0, got 'heavy'",
        ),
        (GraspObject(Shape("sphere", -np.ones(1)), np.eye(4)), "sphere radius must be a finite number > 0"),
        (GraspObject(Shape("sphere", np.ones(1)), np.zeros((4, 4))), "pose must be rigid"),
        (Shape("sphere", np.ones(1)), "object must be a GraspObject, got Shape"),
    ],
)
def test_check_object_refuses(o, match):
    with pytest.raises(ValueError, match=match):
        check_object(o)


def test_moved_refuses_a_pose_that_is_not_rigid():
    with pytest.raises(ValueError, match="pose must be rigid"):
        moved(BOX, np.diag([1.0, 1, 2, 1]))


@pytest.mark.parametrize(
    "points, match",
    [([1, 2], r"points must have shape \(..., 3\), got \(2,\)"), (["a", "b", "c"], "points must be real numbers")],
)
def test_project_refuses_points_of_the_wrong_shape(points, match):
    with pytest.raises(ValueError, match=match):
        project_to_surface(BOX, points)


def test_a_point_that_is_not_finite_gets_nan_and_the_others_their_answer():
    with np.errstate(all="raise"):  # and no warning on the way
        s = project_to_surface(BOX, [[np.nan, 0, 0], [np.inf, 0, 0], [0, 0, 0]])
    assert np.isnan(s.points[:2]).all() and np.isnan(s.normals[:2]).all() and np.isnan(s.distance[:2]).all()
    assert (
        s.points[2].tolist() == [1.0, 0.0, 0.0] and s.normals[2].tolist() == [-1.0, 0.0, 0.0] and s.distance[2] == -1.0
    )


def test_on_edge_is_true_on_edges_corners_and_rims_only():
    box, cylinder, sphere = obj("box", 2.0, 2.0, 2.0), obj("cylinder", 1.0, 2.0), obj("capsule", 1.0, 2.0)
    # outside an edge, outside a corner, inside a face, a hair inside an edge (2e-9 of the size off it)
    q = [[2.0, 2.0, 0.0], [3.0, 3.0, 3.0], [0.5, 0.2, 0.1], [1.0, 1.0 - 4e-9, 0.0]]
    assert project_to_surface(box, q).on_edge.tolist() == [True, True, False, False]
    # outside the top rim, over the top's middle, beside the side
    q = [[2.0, 0.0, 2.0], [0.3, 0.0, 2.0], [2.0, 0.0, 0.0]]
    assert project_to_surface(cylinder, q).on_edge.tolist() == [True, False, False]
    assert not project_to_surface(sphere, [[2.0, 0.0, 1.0], [0.0, 0.0, 3.0]]).on_edge.any()
    assert project_to_surface(box, [[np.nan, 0, 0], [2.0, 2.0, 2.0]]).on_edge.tolist() == [False, True]


@pytest.mark.parametrize(
    "shape",
    [
        Shape("box", np.array([0.04, 0.06, 0.1])),
        Shape("cylinder", np.array([0.03, 0.08])),
        Shape("sphere", np.array([0.035])),
        Shape("capsule", np.array([0.02, 0.05])),
    ],
    ids=lambda s: s.kind,
)
def test_the_signed_distance_alone_is_the_projection_s_bit_for_bit(shape):
    from grasptwist.engine.objects.geometry import signed_distance

    pose = np.eye(4)
    pose[:3, :3] = np.linalg.qr(np.random.default_rng(1).normal(size=(3, 3)))[0]
    pose[:3, 3] = [0.1, -0.2, 0.3]
    obj = GraspObject(shape, pose)
    q = pose[:3, 3] + np.random.default_rng(2).normal(scale=0.05, size=(500, 3))
    q[:3] = [np.nan, 0, 0], [np.inf, 0, 0], pose[:3, 3]  # not finite; the centre (on the axis)
    expected = project_to_surface(obj, q).distance
    np.testing.assert_array_equal(signed_distance(obj, q), expected)
    assert signed_distance(obj, q.reshape(10, 50, 3)).shape == (10, 50)
