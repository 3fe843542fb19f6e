"""The grasps bundled in grasps/: they load, match the JSON Schema, and hold the pinned arrays.

The engine tests pin what these grasps resolve to; here we pin what the
loader hands the engine, so that a change in either file or loader shows.
"""

import jsonschema
import numpy as np
import pytest
import yaml

from grasptwist.engine.decompose import decompose_off_tangent, decompose_tangent
from grasptwist.engine.degeneracy import Status
from grasptwist.io.grasp import grasp_schema, load_grasps
from places import GRASPS

BUNDLED = sorted(GRASPS.glob("*.yaml"))
S3 = 0.5773502691896258  # 1/sqrt(3) as written in polyhedron.yaml


def unit(*v):
    v = np.array(v, dtype=float)
    return v / np.linalg.norm(v)


# file -> one dict per document: name, contact names, points, normals (unit), wrist, {twist: screw}
EXPECTED = {
    "cylinder.yaml": [
        dict(
            name="cylinder",
            units=None,
            contacts=("1", "2", "3"),
            points=[[1, 0, 0], [-0.5, 0.866, 0], [-0.5, -0.866, 0]],
            normals=[unit(-1, 0, 0), unit(0.5, -0.866, 0), unit(0.5, 0.866, 0)],
            wrist=[0, 0, 1],
            twists={
                "sigma-1": [0, -1, 0, 0, 0, 0.5],
                "spin-z": [0, 0, 1, 0, 0, 0],
                "lift-z": [0, 0, 0, 0, 0, 1],
            },
        )
    ],
    "polyhedron.yaml": [
        dict(
            name="polyhedron",
            units=None,
            contacts=("1", "2", "3"),
            points=[[0, 2, 2], [2, 0, 2], [2, 2, 0]],
            normals=np.eye(3),
            wrist=[0, 0, 0],
            twists={"diagonal-spin": [S3, S3, S3, 0, 0, 0]},
        )
    ],
    "sphere.yaml": [
        dict(
            name="sphere-tripod",
            units="m",
            contacts=("thumb", "index", "middle"),
            points=[[0.0, 0.031721, -0.014792], [-0.027471, -0.01586, -0.014792], [0.027471, -0.01586, -0.014792]],
            normals=[
                unit(0.0, -0.031721, 0.014792),
                unit(0.027471, 0.01586, 0.014792),
                unit(-0.027471, 0.01586, 0.014792),
            ],
            wrist=[0, 0, 0.11],
            twists={"roll-x": [1, 0, 0, 0, 0, 0], "spin-z": [0, 0, 1, 0, 0, 0], "lift-z": [0, 0, 0, 0, 0, 0.05]},
        ),
        dict(
            name="sphere-equator",
            units="m",
            contacts=("thumb", "index", "middle"),
            points=[[0.0, 0.035, 0.0], [-0.030311, -0.0175, 0.0], [0.030311, -0.0175, 0.0]],
            normals=[unit(0, -1, 0), unit(0.866025, 0.5, 0), unit(-0.866025, 0.5, 0)],
            wrist=[0, 0, 0.11],
            twists={"roll-x": [1, 0, 0, 0, 0, 0], "lift-z": [0, 0, 0, 0, 0, 0.05]},
        ),
    ],
    "three-finger-hand.yaml": [
        dict(
            name="three-finger-hand",
            units=None,
            contacts=("1", "2", "3"),
            points=[[1.0, 0.3, 0.4], [-1.0, -0.2, -0.1], [0.2, -1.0, -0.5]],
            normals=[[-1, 0, 0], [1, 0, 0], [0, 1, 0]],
            wrist=[0, 0, 3],
            twists={"roll-push": [0.4, 0, 0.1, 0, 0.2, 0]},
        )
    ],
    "trifinger-cube.yaml": [
        dict(
            name="trifinger-cube",
            units="m",
            contacts=("1", "2", "3"),
            points=[[0.0325, 0.015, 0.045], [0.005, -0.0325, 0.025], [-0.0325, 0.0, 0.015]],
            normals=[[-1, 0, 0], [0, 1, 0], [1, 0, 0]],
            wrist=[0, 0, 0.29],
            twists={"spin": [0, 0, 0.5, 0, 0, 0], "lift-tilt": [0.3, 0, 0, 0, 0.3 * 0.0325, 0.02]},
        )
    ],
    "box-edge.yaml": [
        dict(
            name="box-edge",
            units="m",
            contacts=("thumb", "index", "middle"),
            points=[[0.10, 0.0, 0.025], [0.07, 0.1, 0.04], [0.13, 0.1, 0.015]],
            normals=[[0, 1, 0], [0, -1, 0], [0, -1, 0]],
            wrist=[0.1, 0.05, 0.15],
            twists={
                # v = -omega x at
                "tip-over-edge": [-1, 0, 0, 0, 0, 0.1],
                "slide-x": [0, 0, 0, 0.1, 0, 0],
                "turn-y": [0, 1, 0, -0.025, 0, 0.1],
            },
        )
    ],
    "bottle.yaml": [
        dict(
            name="bottle",
            units="m",
            contacts=("thumb", "index", "middle"),
            points=[[0.023, 0, 0.1805], [-0.0175, 0.030311, 0.08], [-0.0175, -0.030311, 0.08]],
            # the mesh's: on the body its column edges' bisectors (radial to 1e-4: the 6-decimal file),
            # on the shoulder the area-weighted normal of the two triangles at the thumb's edge
            normals=[[-0.808702, 0.009159, -0.588147], [0.5, -0.866025, 0], [0.5, 0.866025, 0]],
            wrist=[0.12, 0, 0.16],
            twists={"lift-z": [0, 0, 0, 0, 0, 0.05], "pour": [0, 1, 0, -0.1, 0, 0]},
            atol=1e-4,
        )
    ],
    "handle.yaml": [
        dict(
            name="mug-handle",
            units="m",
            contacts=("thumb", "index", "middle"),
            points=[[0.056, 0.0, 0.087], [0.062, 0.0, 0.073], [0.083, 0.0, 0.045]],
            normals=[[0, 0, -1], [0, 0, 1], [-1, 0, 0]],
            wrist=[0.14, -0.06, 0.07],
            twists={"lift-z": [0, 0, 0, 0, 0, 0.1], "pour": [1, 0, 0, 0, 0.06, 0], "turn-z": [0, 0, 1, 0, 0, 0]},
        )
    ],
}


def test_every_bundled_file_is_pinned():
    assert sorted(p.name for p in BUNDLED) == sorted(EXPECTED)


@pytest.mark.parametrize("path", BUNDLED, ids=lambda p: p.stem)
def test_bundled_file_loads_as_pinned(path):
    grasps = load_grasps(path)
    expected = EXPECTED[path.name]
    assert len(grasps) == len(expected)
    for document, (grasp, want) in enumerate(zip(grasps, expected)):
        assert (grasp.name, grasp.units, grasp.document, grasp.contact_names) == (
            want["name"], want["units"], document, want["contacts"],
        )  # fmt: skip
        # a contact that gives only its point is put on the object's surface (the bottle's: within round-off)
        np.testing.assert_allclose(grasp.points, want["points"], rtol=0, atol=1e-15)
        np.testing.assert_allclose(grasp.normals, want["normals"], rtol=0, atol=want.get("atol", 1e-15))
        np.testing.assert_array_equal(grasp.wrist, want["wrist"])
        assert [t.name for t in grasp.twists] == list(want["twists"])
        for twist in grasp.twists:
            np.testing.assert_allclose(twist.screw, want["twists"][twist.name], rtol=0, atol=1e-15)


@pytest.mark.parametrize("path", BUNDLED, ids=lambda p: p.stem)
def test_bundled_file_matches_the_json_schema(path):
    validator = jsonschema.Draft202012Validator(grasp_schema())
    for document in yaml.safe_load_all(path.read_text("utf-8")):
        validator.validate(document)


@pytest.mark.parametrize("path", BUNDLED, ids=lambda p: p.stem)
def test_bundled_file_states_its_findings(path):
    """Each header says what the grasp shows: a "Finding:" naming the engine's status code
    for exactly the methods the engine finds degenerate, and no finding otherwise."""
    header = path.read_text("utf-8").split("\nname:")[0]
    assert header.startswith("# ")
    found = set()
    for grasp in load_grasps(path):
        if grasp.wrist is not None:
            found.add(Status(int(decompose_off_tangent(grasp.points, grasp.wrist, np.zeros(6)).status)))
        found.add(Status(int(decompose_tangent(grasp.points, grasp.normals, np.zeros(6)).status)))
    found.discard(Status.OK)
    named = {s for s in Status if s != Status.OK and s.code in header}
    assert named == found
    assert ("Finding:" in header) == bool(found)


# file -> the kind of each document's object (None: the file gives none)
OBJECTS = {
    "bottle.yaml": ["mesh"],
    "box-edge.yaml": ["box"],
    "cylinder.yaml": ["cylinder"],
    "handle.yaml": [None],  # a mug's handle: no primitive, and no mesh of it (yet)
    "polyhedron.yaml": ["box"],
    "sphere.yaml": ["sphere", "sphere"],
    "three-finger-hand.yaml": ["box"],
    "trifinger-cube.yaml": ["box"],
}


@pytest.mark.parametrize("path", BUNDLED, ids=lambda p: p.stem)
def test_bundled_contacts_lie_on_their_objects(path):
    """Each contact as typed is on its object's surface, far within the tolerance (1e-5 of the
    object's size: the points are written to 6 digits), its normal within a degree of the surface's."""
    from grasptwist.engine.objects import object_size, project_to_surface

    grasps = load_grasps(path)
    assert [g.object.shape.kind if g.object else None for g in grasps] == OBJECTS[path.name]
    for grasp in grasps:
        if grasp.object is None:
            assert grasp.surface_distance is None
            continue
        size = object_size(grasp.object)
        surface = project_to_surface(grasp.object, grasp.points)
        assert np.abs(grasp.surface_distance).max() <= 1e-5 * size
        np.testing.assert_allclose(surface.distance, 0, atol=1e-5 * size)
        cosines = np.sum(surface.normals * grasp.normals, axis=1)
        assert cosines.min() >= np.cos(np.radians(1)), cosines


def test_every_bundled_file_says_what_its_object_is():
    assert sorted(OBJECTS) == sorted(p.name for p in BUNDLED)


def obj_geometry(text):
    """``(vertices, faces)`` of a Wavefront OBJ text of ``v`` and ``f`` lines."""
    rows = [line.split() for line in text.splitlines()]
    vertices = np.array([r[1:] for r in rows if r and r[0] == "v"], dtype=float)
    faces = np.array([r[1:] for r in rows if r and r[0] == "f"], dtype=int)
    return vertices, faces


def test_the_bottle_script_makes_the_committed_mesh(tmp_path):
    """grasps/meshes/make_bottle.py writes bottle.obj again: the same faces, vertices within the
    file's 6 decimals (1e-6 m), on any machine."""
    import subprocess
    import sys

    target = tmp_path / "bottle.obj"
    subprocess.run([sys.executable, GRASPS / "meshes" / "make_bottle.py", target], check=True)
    made, committed = (obj_geometry(p.read_text()) for p in (target, GRASPS / "meshes" / "bottle.obj"))
    np.testing.assert_array_equal(made[1], committed[1])
    np.testing.assert_allclose(made[0], committed[0], rtol=0, atol=1e-6)
    assert committed[1].shape == (1152, 3) and committed[0].shape == (578, 3)


def test_the_bottles_density_gives_its_weight():
    """1000 kg/m^3 over the mesh's 693.8 cm^3 is 0.6938 kg, held at its centre of mass on the axis
    (the volume and centre as test_mesh_file.py's signed volume and trimesh give them)."""
    (g,) = load_grasps(GRASPS / "bottle.yaml")
    assert g.object.density == 1000 and g.object.mass == pytest.approx(0.69382, rel=1e-4)
    (hold,) = g.wrenches
    np.testing.assert_allclose(hold.wrench[:3], [0, 0, g.object.mass * 9.81], rtol=1e-12)
    np.testing.assert_allclose(hold.wrench[3:], 0, atol=1e-15)  # the centre is on the vertical axis
    np.testing.assert_allclose(g.center_of_mass, [0, 0, 0.09183], atol=1e-5)
