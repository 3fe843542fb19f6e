"""One validation (issue 35, item 6): an object built in Python goes through the checks a grasp file's
object gets, at the one gate every geometry function (and so the search) takes it through, with the
file reader's codes."""

from dataclasses import replace

import numpy as np
import pytest

import grasptwist as gt
from grasptwist.engine.objects.checks import ObjectError, checked
from grasptwist.io.grasp import READING, read_grasps
from grasptwist.objects import GraspObject, Shape, mass_properties, moved, project_to_surface
from small_meshes import CORNERS, TRIANGLES

# the tetrahedron of objects.md, its right angle at the origin, faces counter-clockwise from outside
VERTICES = np.array([[0, 0, 0], [0.1, 0, 0], [0, 0.1, 0], [0, 0, 0.1]])
FACES = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])


NO_CONTACTS = replace(READING, contacts=False)  # as synthesize reads: an object alone


def tetra(vertices=VERTICES, faces=FACES, **kw):
    return GraspObject(Shape("mesh", np.zeros(0), vertices, faces), np.eye(4), **kw)


def refused(obj):
    """The code of what the search says of ``obj``, before it searches."""
    with pytest.raises(ObjectError) as err:
        gt.synthesize(obj, 0.8, count=1, candidates=100)
    return err.value.code


def test_a_mesh_built_inside_out_is_refused_before_any_search():
    assert refused(tetra(faces=FACES[:, ::-1], mass=0.1)) == "mesh-not-solid"
    with pytest.raises(ObjectError, match="bounds no solid"):
        project_to_surface(tetra(faces=FACES[:, ::-1]), [0.02, 0.02, -0.01])


def test_a_mesh_flattened_by_a_scale_of_1e_13_along_one_axis_is_refused():
    flat = VERTICES * [1, 1, 1e-13]
    assert refused(tetra(flat, mass=0.1)) == "mesh-not-solid"  # its three flat faces dropped: a sheet is left
    with pytest.raises(ObjectError, match="bounds no solid"):
        mass_properties(tetra(flat, mass=0.1))


def test_python_and_the_file_reader_give_the_same_codes(tmp_path):
    # an open mesh (a cube with a triangle missing): the same solid either way, the cube's
    corners, open_faces = CORNERS * 0.05, TRIANGLES[1:]
    np.testing.assert_allclose(mass_properties(tetra(corners, open_faces, mass=0.1)).volume, 0.1**3, rtol=0.01)
    lines = [f"v {x} {y} {z}" for x, y, z in corners] + [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in open_faces]
    (tmp_path / "open.obj").write_text("\n".join(lines) + "\n")
    (tmp_path / "g.yaml").write_text("object:\n  mesh: open.obj\n  mass: 0.1\nfriction: 0.8\n")
    (read,) = read_grasps(tmp_path / "g.yaml", reading=NO_CONTACTS)
    assert [w.partition(":")[0] for w in read.warnings] == ["mesh-open"]
    # a density that is not above 0, a size that overflows: the same codes as a file's
    assert refused(GraspObject(Shape("box", [1.0, 1, 1]), np.eye(4), density=-700.0)) == "invalid-density"
    assert refused(GraspObject(Shape("box", [1e308, 1e308, 1e308]), np.eye(4), mass=1.0)) == "non-finite"
    (err,) = read_grasps("object:\n  box: [1e308, 1e308, 1e308]\n  mass: 1\n", file="b.yaml", reading=NO_CONTACTS)
    assert err.code == "non-finite"
    pose = np.diag([1.0, 1, -1, 1])  # a mirror is no rigid motion
    assert refused(GraspObject(Shape("sphere", 0.03), pose, mass=0.1)) == "invalid-pose"


def test_the_gate_checks_an_object_once_and_passes_what_it_accepted():
    obj = tetra(mass=0.1)
    first = checked(obj)
    assert checked(obj) is first and checked(first) is first
    step = np.eye(4)
    step[2, 3] = 1.0
    carried = moved(obj, step)
    assert checked(carried) is carried  # a checked pose on an accepted shape: not checked again
    np.testing.assert_allclose(mass_properties(carried).center_of_mass, [0.025, 0.025, 1.025], rtol=1e-12)


def test_an_accepted_object_searches_as_before():
    cube = GraspObject(Shape("box", np.full(3, 0.065)), np.eye(4), mass=0.1)
    found = gt.synthesize(cube, 0.8, count=1, candidates=1000, loads="weight")  # the weight alone: its bound
    assert found.failure is None and 0.981 <= found.total_normal_force[0, 0] < 1.1
