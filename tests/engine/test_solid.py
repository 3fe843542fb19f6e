"""The solid a mesh bounds (issue 35): the meshes of tests/meshes/make_meshes.py, each against its exact solid
and an independent count of winding numbers; closed meshes against trimesh (the divergence theorem)."""

import functools
import sys
from pathlib import Path

import numpy as np
import pytest

MESHES_DIR = Path(__file__).parents[1] / "meshes"
sys.path.insert(0, str(MESHES_DIR))
pytest.importorskip("igl")
trimesh = pytest.importorskip("trimesh")

from make_meshes import MESHES  # noqa: E402

import grasptwist as gt  # noqa: E402
from grasptwist.engine.objects import mass_properties, project_to_surface, sample_surface  # noqa: E402
from grasptwist.engine.objects.creases import edge_distance  # noqa: E402
from grasptwist.engine.objects.geometry import body_of  # noqa: E402
from grasptwist.engine.objects.mesh import solid_of  # noqa: E402
from grasptwist.engine.objects.primitives import second_moment  # noqa: E402
from grasptwist.engine.objects.solid import winding_number  # noqa: E402
from grasptwist.io.grasp import load_grasps, read_grasps  # noqa: E402
from grasptwist.io.mesh_file import read_mesh  # noqa: E402
from grasptwist.model import GraspObject, Shape  # noqa: E402
from grasptwist.objects import check_object  # noqa: E402


@functools.cache
def checked_shape(name):
    """The mesh file's shape, checked once for every test (its solid and mass kept with it)."""
    v, f = read_mesh(name, MESHES_DIR)
    return check_object(GraspObject(Shape("mesh", np.zeros(0), v, f, name), np.eye(4))).shape


def mesh_object(name, **kw):
    return GraspObject(checked_shape(name), np.eye(4), **kw)


def test_the_meshes_on_disk_are_the_scripts():
    for name, ((v, f), _, _) in MESHES.items():
        read_v, read_f = read_mesh(name, MESHES_DIR)
        used = v[np.unique(f)]  # the open cylinder's lid centre is no face's
        np.testing.assert_allclose(np.sort(read_v, axis=0), np.sort(used, axis=0), rtol=0, atol=1e-15)
        assert len(read_f) == len(f)


@pytest.mark.parametrize("name", list(MESHES))
def test_each_mesh_bounds_its_exact_solid(name):
    _, volume, centre = MESHES[name]
    m = mass_properties(mesh_object(name, density=1.0))
    assert m.volume == pytest.approx(volume, rel=3e-3)
    np.testing.assert_allclose(m.center_of_mass, centre, rtol=0, atol=1e-4)  # 0.1 mm of 60-100 mm


@pytest.mark.parametrize("name", ["open_cylinder.obj", "overlapping_boxes.obj", "pieces.obj"])
def test_volume_and_centre_agree_with_a_monte_carlo_count_of_winding_numbers(name):
    o = mesh_object(name, density=1.0)
    v, f = o.shape.vertices, o.shape.faces
    lo, hi = v.min(axis=0), v.max(axis=0)
    q = np.random.default_rng(7).uniform(lo, hi, (20000, 3))  # a volume to some 0.4 %
    inside = winding_number(v, f, q) > 0.5
    volume = inside.mean() * np.prod(hi - lo)
    m = mass_properties(o)
    assert m.volume == pytest.approx(volume, rel=1e-2)
    np.testing.assert_allclose(m.center_of_mass, q[inside].mean(axis=0), rtol=0, atol=1e-2 * np.linalg.norm(hi - lo))


@pytest.mark.parametrize("make", [lambda: trimesh.creation.torus(0.05, 0.015), lambda: trimesh.creation.icosphere(3)])
def test_a_closed_mesh_has_the_divergence_theorems_mass_properties(make):
    m = make()
    m.apply_translation([0.3, -0.2, 0.1])
    o = check_object(GraspObject(Shape("mesh", np.zeros(0), m.vertices, m.faces), np.eye(4), density=1.0))
    p = mass_properties(o)
    scale = m.volume * np.ptp(m.vertices, axis=0).max() ** 2
    assert p.volume == pytest.approx(m.volume, rel=1e-9)
    np.testing.assert_allclose(p.center_of_mass, m.center_mass, rtol=0, atol=1e-12)
    np.testing.assert_allclose(p.inertia, m.moment_inertia, rtol=0, atol=1e-9 * scale)


def test_a_primitives_inertia_is_its_closed_form_and_its_tessellations():
    box = mass_properties(GraspObject(Shape("box", np.array([1.0, 2.0, 3.0])), np.eye(4), mass=6.0))
    np.testing.assert_allclose(box.inertia, trimesh.creation.box((1, 2, 3)).moment_inertia, atol=1e-12)
    for kind, size in (("sphere", [0.5]), ("cylinder", [0.3, 1.0]), ("capsule", [0.3, 1.0])):
        fine = gt.objects.tessellate(GraspObject(Shape(kind, np.array(size)), np.eye(4)), segments=128)
        o = check_object(GraspObject(Shape("mesh", np.zeros(0), *fine), np.eye(4), density=1.0))
        ours = mass_properties(GraspObject(Shape(kind, np.array(size)), np.eye(4), density=1.0))
        np.testing.assert_allclose(ours.inertia, mass_properties(o).inertia, rtol=2e-3, atol=1e-12)
    assert np.diag(second_moment("capsule", [1.0, 0.0])).tolist() == pytest.approx([4 / 3 * np.pi / 5] * 3)


def test_a_pose_turns_the_inertia_and_a_given_mass_scales_it():
    pose = np.eye(4)
    pose[:3, :3] = [[0, -1, 0], [1, 0, 0], [0, 0, 1]]
    box = mass_properties(GraspObject(Shape("box", np.array([1.0, 2.0, 3.0])), pose, mass=12.0))
    # about x now the box's 2 m side's axis: 12 / 12 * (1 + 9); about y its 1 m side's: 4 + 9; about z 4 + 1
    np.testing.assert_allclose(box.inertia, np.diag([10.0, 13.0, 5.0]), atol=1e-12)
    assert mass_properties(GraspObject(Shape("sphere", np.ones(1)), np.eye(4))).inertia is None


def crossing_shape(name):
    """Pieces that cross the tests/meshes files do not: two 40 mm thick boxes whose tops and bottoms
    share their planes (a new user's), and a box a 32-sided cylinder passes through."""
    box = trimesh.creation.box
    parts = {
        "shared_planes": [box([0.1, 0.04, 0.04]), box([0.04, 0.1, 0.04]).apply_translation([0.03, 0.03, 0])],
        "box_and_cylinder": [box([0.1, 0.04, 0.04]), trimesh.creation.cylinder(0.01, 0.1, sections=32)],
    }[name]
    m = trimesh.util.concatenate(parts)
    # as an OBJ file writes them: the boxes' equal corners (0.05, -0.02, +-0.02) merged, which joined the two
    # boxes into one piece whose faces were never split (387 of 20,000 samples inside, up to 47 mm deep)
    v = np.round(m.vertices, 9)
    return check_object(GraspObject(Shape("mesh", np.zeros(0), v, m.faces, name), np.eye(4))).shape


def any_object(name, **kw):
    shape = checked_shape(name) if name.endswith(".obj") else crossing_shape(name)
    return GraspObject(shape, np.eye(4), **kw)


def on_the_outer_surface(o, p, n_in):
    """Whether each point ``p`` is on the solid's outer boundary, by its inward normal: just outside it the
    winding number is below 1/2, just inside above."""
    eps = 1e-4 * np.linalg.norm(np.ptp(o.shape.vertices, axis=0))
    v, f = o.shape.vertices, o.shape.faces
    return (winding_number(v, f, p - eps * n_in) < 0.5) & (winding_number(v, f, p + eps * n_in) > 0.5)


ALL = ["overlapping_boxes.obj", "pieces.obj", "box_with_cavity.obj", "open_cylinder.obj", "two_bodies.obj"]
ALL += ["shared_planes", pytest.param("box_and_cylinder", marks=pytest.mark.slow)]  # 1-2 s each
#: The meshes whose projections and searches take well under a second (the others' over one: slow).
QUICK = ["overlapping_boxes.obj", "box_with_cavity.obj", "shared_planes"]
SLOW = [pytest.param(name, marks=pytest.mark.slow) for name in ("pieces.obj", "open_cylinder.obj", "two_bodies.obj")]


@pytest.mark.parametrize("name", ALL)
def test_samples_lie_on_the_outer_surface_only(name):
    o = any_object(name)
    p, n = sample_surface(o, 20000, np.random.default_rng(0))  # n inward
    keep = np.ones(len(p), dtype=bool)
    if name == "open_cylinder.obj":  # the rim's wall is thinner than eps from the opening
        keep = p[:, 2] < 0.1 - 2e-4 * np.linalg.norm(np.ptp(o.shape.vertices, axis=0))
    # none inside (before: the last split's parts that straddle where pieces cross, kept whole by their
    # centres: 7 of pieces.obj's, 11 of shared_planes', 46 of box_and_cylinder's, up to 0.9 mm deep)
    assert on_the_outer_surface(o, p[keep], n[keep]).all()


@pytest.mark.parametrize("name", QUICK + SLOW + ALL[-1:])
def test_no_nearest_point_is_inside_the_solid(name):
    """A point projected lies on the boundary: some point within eps of it (along its normal or an axis) is
    outside, or on the surface (a concave crease: 1/2) (before: 377 of shared_planes' 20,000 projected up to
    0.9 mm inside; 5,000 here)."""
    o = any_object(name)
    v = o.shape.vertices
    q = np.random.default_rng(1).uniform(v.min(axis=0), v.max(axis=0), (5000, 3))
    s = project_to_surface(o, q)
    eps = 1e-5 * np.linalg.norm(np.ptp(v, axis=0))
    away = np.concatenate(
        [-s.normals[None], np.eye(3)[:, None].repeat(len(q), 1), -np.eye(3)[:, None].repeat(len(q), 1)]
    )
    w = winding_number(v, o.shape.faces, (s.points + eps * away).reshape(-1, 3)).reshape(7, -1)
    assert (w.min(axis=0) < 0.5 + 1e-3).all()
    np.testing.assert_allclose(np.abs(s.distance), np.linalg.norm(q - s.points, axis=1), rtol=1e-12, atol=1e-15)


@pytest.mark.parametrize("name", QUICK + SLOW + ALL[-1:])
def test_synthesized_grasps_are_verified_on_the_outer_surface_of_every_mesh(name):
    """0.5.0: IndexError in mesh_creases (the given faces against the outer surface's) on every mesh with
    faces inside its solid, a broadcast ValueError on crossing pieces."""
    o = any_object(name, density=700.0)
    s = gt.synthesize(o, 0.8, count=2, candidates=300, perturbations=8, loads="weight")  # the surface's test
    assert len(s.points) == 2 and s.unverified == 0
    assert on_the_outer_surface(o, s.points.reshape(-1, 3), s.normals.reshape(-1, 3)).all()
    assert np.isfinite(s.edge_distance).all() and (s.edge_distance >= 0).all()  # every mesh here has creases


def test_the_creases_are_the_outer_surface_s():
    o = any_object("shared_planes")
    # box A's top face: its nearest creases are its rim, 20 mm off (the face B shares with it is no crease)
    np.testing.assert_allclose(edge_distance(o, [[-0.03, 0.0, 0.02], [0.03, 0.05, 0.02]]), [0.02, 0.02], atol=1e-15)
    assert internal_counts(o) == (0, 4)
    # the new user's point inside both boxes: to the walls 20 mm off (before: onto B's face x = 0.01, -0.0113)
    np.testing.assert_allclose(
        project_to_surface(o, [[0.012, 0.0, 0.0]]).distance, [-0.02], atol=1e-15
    )  # B's face x = 0.01 and A's y = 0.02, two triangles each, partly inside


def internal_counts(o):
    s = solid_of(o.shape)
    return s.internal, s.partly


def test_nearest_points_are_on_the_outer_surface():
    boxes = mesh_object("overlapping_boxes.obj")
    # the middle of the overlap: the internal faces x = 0.03 and 0.06 are 0.015 away, the outer walls 0.02
    s = project_to_surface(boxes, [[0.045, 0.02, 0.02], [0.045, 0.02, 0.05]])
    np.testing.assert_allclose(s.distance, [-0.02, 0.01], atol=1e-15)
    hollow = mesh_object("box_with_cavity.obj")
    s = project_to_surface(hollow, [[0, 0, 0.015], [0, 0, 0.04]])  # the cavity's ceiling; above the box
    np.testing.assert_allclose(s.distance, [-0.015, 0.01], atol=1e-15)
    np.testing.assert_allclose(s.points, [[0, 0, 0.03], [0, 0, 0.03]], atol=1e-15)


def test_what_the_solid_found():
    found = {name: solid_of(mesh_object(name).shape) for name in MESHES}
    assert (found["open_cylinder.obj"].open_edges, found["open_cylinder.obj"].largest_hole) == (
        64,
        pytest.approx(0.06, rel=2e-3),
    )
    assert found["box_with_cavity.obj"].cavities == 1 and found["box_with_cavity.obj"].closed
    assert found["overlapping_boxes.obj"].bodies == 1 and found["overlapping_boxes.obj"].internal == 4
    assert found["pieces.obj"].bodies == 1 and not found["pieces.obj"].closed
    assert (found["two_bodies.obj"].bodies, found["two_bodies.obj"].gap) == (2, pytest.approx(0.02))


GRASP = """\
object:
  mesh: {mesh}
  density: 700
contacts:
  - {{point: {p0}}}
  - {{point: [0.02, 0.0, 0.02]}}
  - {{point: [0.02, 0.04, 0.02]}}
"""


def test_a_contact_on_an_internal_face_is_a_located_error():
    text = GRASP.format(mesh=MESHES_DIR / "overlapping_boxes.obj", p0="[0.06, 0.02, 0.02]")  # box A's face inside B
    (e,) = read_grasps(text, file=str(MESHES_DIR / "g.yaml"))
    assert (e.code, e.line, e.column) == ("contact-inside-object", 5, 13)
    assert "contacts[0].point: on a face of the mesh inside its solid" in e.message
    text = GRASP.format(mesh=MESHES_DIR / "box_with_cavity.obj", p0="[0.0, 0.0, 0.015]")  # the cavity's ceiling
    assert read_grasps(text, file=str(MESHES_DIR / "g.yaml"))[0].code == "contact-inside-object"


def test_a_mesh_file_warns_what_it_is():
    def said(name):
        text = GRASP.format(mesh=name, p0="[0.0, 0.02, 0.02]")
        return load_grasps(text, file=str(MESHES_DIR / "g.yaml"))[0].warnings

    assert said("two_bodies.obj") == (
        "mesh-bodies: two_bodies.obj: the mesh is 2 bodies, 0.02 apart at the least: "
        "a synthesized grasp keeps to one (--span-bodies, span_bodies=True: across them)",
    )
    assert said("overlapping_boxes.obj") == (
        "mesh-internal: overlapping_boxes.obj: 4 faces inside the solid, 0 partly, and 0 cavities: out of a finger's reach",
    )


def test_a_sheet_is_not_solid(tmp_path):
    (tmp_path / "sheet.obj").write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n")
    text = GRASP.format(mesh="sheet.obj", p0="[0.0, 0.5, 0.0]")
    (e,) = read_grasps(text, file=str(tmp_path / "g.yaml"))
    assert (e.code, e.line) == ("mesh-not-solid", 2) and "repair it" in e.message


def test_an_open_mesh_warns_its_hole(tmp_path):
    text = GRASP.format(mesh="open_cylinder.obj", p0="[0.03, 0.0, 0.05]").replace(
        "[0.02, 0.0, 0.02]", "[0.0, 0.0, 0.0]"
    )
    text = text.replace("[0.02, 0.04, 0.02]", "[0.0, 0.03, 0.05]")
    (g,) = load_grasps(text, file=str(MESHES_DIR / "g.yaml"))
    assert g.warnings[0].startswith("mesh-open: open_cylinder.obj: 64 open edges (the largest hole 0.06 across)")


@pytest.mark.slow  # the default run's 40 s: development.md, Test time
def test_a_synthesized_grasp_keeps_to_one_body_unless_told():
    o = mesh_object("two_bodies.obj", density=700.0)
    s = gt.synthesize(o, 0.8, count=2, candidates=1500, loads="weight")  # the bodies' test: the weight is enough
    bodies = body_of(o, s.points)
    assert len(s.points) and (bodies == bodies[:, :1]).all()


def test_span_bodies_draws_from_every_body_and_one_body_from_one():
    from grasptwist.engine.synthesis.problem import surface_of

    o = mesh_object("two_bodies.obj")
    rng = np.random.default_rng(3)
    spanning = surface_of(o, span_bodies=True)
    assert spanning.body is None and set(body_of(o, spanning.sample(200, rng)[0]).tolist()) == {0, 1}
    one = surface_of(o)
    for _ in range(5):  # each call's points on one body
        assert len(set(one.body(one.sample(50, rng)[0]).tolist())) == 1
