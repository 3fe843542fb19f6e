"""The URDF model read without yourdfpy (io/urdf_model.py) against yourdfpy's own reading: every joint
and shape of the TriFinger URDFs (read from robot_properties_fingers) and of the test URDFs, and the
finger links' collision geometry (io/urdf_meshes.py ``link_geometry``) against the scene yourdfpy and
trimesh build of it (meshes, primitives, scales, mirrors, origins, the visual fallback)."""

import os
import warnings
from importlib.util import find_spec

import numpy as np
import pytest

from grasptwist import hand
from grasptwist.engine.objects.checks import merge_vertices
from grasptwist.io.urdf import _parse, _read, resolve_urdf
from grasptwist.io.urdf_meshes import link_geometry, mesh_file
from grasptwist.io.urdf_model import merged, read_model
from grasptwist.model import InputError
from places import TESTS

yourdfpy = pytest.importorskip("yourdfpy")
trimesh = pytest.importorskip("trimesh")

FINGERS = find_spec("robot_properties_fingers") is not None
TIPS = ["finger_tip_link_0", "finger_tip_link_120", "finger_tip_link_240"]
PRO = "package://robot_properties_fingers/urdf/pro/trifingerpro.urdf"
EDU = "package://robot_properties_fingers/urdf/edu/trifingeredu.urdf"
CORPUS = TESTS / "corpus" / "urdf"


def _bundled():
    """Every URDF of robot_properties_fingers that yourdfpy reads (its macro file is xacro, not URDF)."""
    if not FINGERS:
        return []
    folder = resolve_urdf("package://robot_properties_fingers/urdf")
    return [p for p in sorted(folder.rglob("*.urdf")) if p.name != "finger_macro.urdf"]


#: The test URDFs both readers take (the others are refused by both, for what corpus/urdf/expected.tsv says).
_TOYS = [CORPUS / f"{n}.urdf" for n in ("hand", "cycle", "floating-joint", "mimic-joint", "planar-joint", "two-roots")]


def _ours(path):
    return read_model(_parse(_read(path, 1 << 20, str(path)), str(path)), str(path))


def _theirs(path):
    return yourdfpy.URDF.load(str(path), build_scene_graph=False, load_meshes=False)


@pytest.mark.parametrize("path", _bundled() + _TOYS, ids=lambda p: p.name)
def test_joints_and_shapes_are_yourdfpys(path):
    ours, theirs = _ours(path), _theirs(path)
    assert [j.name for j in ours.joints] == [j.name for j in theirs.robot.joints]
    for a, b in zip(ours.joints, theirs.robot.joints):
        assert (a.type, a.parent, a.child, a.mimic) == (b.type, b.parent, b.child, b.mimic is not None)
        np.testing.assert_allclose(a.origin, np.eye(4) if b.origin is None else b.origin, rtol=0, atol=1e-12)
        np.testing.assert_allclose(a.axis, b.axis, rtol=0, atol=1e-12)
        assert a.limit == (None if b.limit is None else tuple(vars(b.limit).values()))
    assert list(ours.links) == [link.name for link in theirs.robot.links]
    for link in theirs.robot.links:
        for mine, yours in (
            (ours.links[link.name].collisions, link.collisions),
            (ours.links[link.name].visuals, link.visuals),
        ):
            assert len(mine) == len(yours)
            for a, b in zip(mine, yours):
                np.testing.assert_allclose(a.origin, np.eye(4) if b.origin is None else b.origin, rtol=0, atol=1e-12)
                _same_geometry(a, b.geometry)


def _same_geometry(a, g):
    if g.mesh is not None:
        assert (a.kind, a.filename) == ("mesh", g.mesh.filename)
        want = None if g.mesh.scale is None else np.broadcast_to(g.mesh.scale, 3)
        assert (a.scale is None) == (want is None) and (want is None or np.array_equal(a.scale, want))
    elif g.box is not None:
        assert (a.kind, a.size) == ("box", tuple(g.box.size))
    elif g.sphere is not None:
        assert (a.kind, a.size) == ("sphere", (g.sphere.radius,))
    else:
        assert (a.kind, a.size) == ("cylinder", (g.cylinder.radius, g.cylinder.length))


def test_origins_are_rz_ry_rx_of_rpy_after_the_translation(tmp_path):
    (tmp_path / "r.urdf").write_text(
        '<robot name="r"><link name="a"/><link name="b"/><joint name="j" type="fixed"><parent link="a"/>'
        '<child link="b"/><origin xyz="1 2 3" rpy="0.3 -0.4 2.5"/></joint></robot>'
    )
    (joint,) = _ours(tmp_path / "r.urdf").joints
    r, p, y = 0.3, -0.4, 2.5
    rz = np.array([[np.cos(y), -np.sin(y), 0], [np.sin(y), np.cos(y), 0], [0, 0, 1]])
    ry = np.array([[np.cos(p), 0, np.sin(p)], [0, 1, 0], [-np.sin(p), 0, np.cos(p)]])
    rx = np.array([[1, 0, 0], [0, np.cos(r), -np.sin(r)], [0, np.sin(r), np.cos(r)]])
    np.testing.assert_allclose(joint.origin[:3, :3], rz @ ry @ rx, rtol=0, atol=1e-15)
    assert joint.origin[:3, 3].tolist() == [1, 2, 3] and joint.origin[3].tolist() == [0, 0, 0, 1]


@pytest.mark.parametrize(
    ("shape", "line", "match"),
    [
        ("<collision/>", 3, "link 'b': <collision> without a <geometry> element"),
        ("<visual><geometry/></visual>", 3, "link 'b': <visual> without a <geometry> element"),
        ("<collision><geometry>\n<cone/></geometry></collision>", 4, "unknown geometry <cone>"),
        ('<collision><geometry>\n<box size="1 2"/></geometry></collision>', 4, r"<box size>: expected 3"),
        ("<collision><geometry>\n<sphere/></geometry></collision>", 4, "<sphere> without radius"),
        ('<collision><geometry>\n<cylinder radius="1" length="x"/></geometry></collision>', 4, "<cylinder length>"),
        ('<collision><geometry>\n<mesh filename="m.stl" scale="1 2"/></geometry></collision>', 4, "<mesh scale>"),
        ("<collision><geometry>\n<mesh/></geometry></collision>", 4, "<mesh> without a filename"),
        (
            '<collision>\n<origin rpy="0 0 nan"/><geometry><sphere radius="1"/></geometry></collision>',
            4,
            "<origin rpy>",
        ),
    ],
)
def test_a_bad_shape_is_invalid_urdf_at_its_line(tmp_path, shape, line, match):
    (tmp_path / "r.urdf").write_text(f'<robot name="r">\n<link name="a"/>\n<link name="b">{shape}</link></robot>')
    with pytest.raises(InputError, match=match) as caught:
        _ours(tmp_path / "r.urdf")
    assert (caught.value.code, caught.value.line) == ("invalid-urdf", line)


def test_a_scale_of_one_number_or_commas_is_read_as_yourdfpy_reads_it(tmp_path):
    meshes = '<mesh filename="m.stl" scale="0.5"/>', '<mesh filename="m.stl" scale="1,2,3"/>', '<box size="1,2,3"/>'
    links = "".join(
        f'<link name="l{i}"><collision><geometry>{m}</geometry></collision></link>' for i, m in enumerate(meshes)
    )
    (tmp_path / "r.urdf").write_text(f'<robot name="r">{links}</robot>')
    shapes = [link.collisions[0] for link in _ours(tmp_path / "r.urdf").links.values()]
    assert [s.scale.tolist() for s in shapes[:2]] == [[0.5] * 3, [1.0, 2.0, 3.0]] and shapes[2].size == (1, 2, 3)
    for link in _theirs(tmp_path / "r.urdf").robot.links:
        _same_geometry(_ours(tmp_path / "r.urdf").links[link.name].collisions[0], link.collisions[0].geometry)


# --------------------------------------------------------------------------
# The finger links' geometry against yourdfpy's collision scene (the reading link_geometry replaced).


def _yourdfpy_geometry(toy, folder=None):
    """Each link's ``(vertices, faces)`` at home in the root frame, as yourdfpy's collision scene (its
    visual one without collision geometry) gives them, every mesh loaded by trimesh."""
    urdf = resolve_urdf(toy.source, folder)
    options = {"filename_handler": lambda fname: str(resolve_urdf(fname, urdf.parent))}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)  # yourdfpy's own use of Scene.dump
        model = yourdfpy.URDF.load(
            str(urdf), build_scene_graph=False, build_collision_scene_graph=True, load_collision_meshes=True, **options
        )
        scene = model.collision_scene
        if not scene.graph.nodes_geometry:
            model = yourdfpy.URDF.load(str(urdf), **options)
            scene = model.scene
    parts = {}
    for node in scene.graph.nodes_geometry:
        pose, name = scene.graph[node]
        mesh = scene.geometry[name]
        v = np.asarray(mesh.vertices) @ pose[:3, :3].T + pose[:3, 3]
        parts.setdefault(scene.graph.transforms.parents[node], []).append((v, np.asarray(mesh.faces)))
    out = {}
    for link, found in parts.items():
        offsets = np.cumsum([0] + [len(v) for v, _ in found[:-1]])
        out[link] = np.concatenate([v for v, _ in found]), np.concatenate([f + o for (_, f), o in zip(found, offsets)])
    return out


def _same_as_yourdfpy(toy, folder=None):
    ours, theirs = link_geometry(toy, folder=folder), _yourdfpy_geometry(toy, folder)
    assert ours
    for g in ours:
        vertices, faces = theirs[g.link]
        assert np.array_equal(g.faces, faces), g.link
        np.testing.assert_allclose(g.vertices, vertices, rtol=0, atol=1e-12)
    return ours


@pytest.mark.skipif(not FINGERS, reason="needs robot_properties_fingers")
@pytest.mark.parametrize("urdf", [PRO, EDU], ids=["pro", "edu"])
def test_the_trifingers_link_geometry_is_yourdfpys(urdf):
    ours = _same_as_yourdfpy(hand.load_urdf_hand(urdf, TIPS))
    assert len(ours) == (12 if urdf == PRO else 9)
    # an STL repeats each corner in every triangle: merged, a closed mesh has about half as many vertices as faces
    assert all(len(g.vertices) < len(g.faces) for g in ours)


def _toy(tmp_path, a3, b3, extra=""):
    """The corpus's toy hand with links a3 and b3 given shapes, and a mesh file m.stl beside it."""
    mesh = trimesh.creation.annulus(r_min=0.004, r_max=0.01, height=0.02, sections=12)
    mesh.apply_translation([0.001, 0.002, 0.003])
    (tmp_path / "m.stl").write_bytes(mesh.export(file_type="stl"))
    text = (CORPUS / "hand.urdf").read_text().replace('<link name="a3"/>', f'<link name="a3">{a3}</link>')
    (tmp_path / "h.urdf").write_text(text.replace('<link name="b3"/>', f'<link name="b3">{b3}</link>{extra}'))
    return hand.load_urdf_hand("h.urdf", ["a_tip", "b_tip"], folder=tmp_path)


def _shape(kind, geometry, origin='xyz="0.01 -0.02 0.03" rpy="0.3 -0.2 1.1"'):
    return f"<{kind}><origin {origin}/><geometry>{geometry}</geometry></{kind}>"


def test_primitives_scales_mirrors_and_origins_are_yourdfpys(tmp_path):
    a3 = "".join(
        _shape("collision", g)
        for g in (
            '<box size="0.01 0.02 0.05"/>',
            '<sphere radius="0.01"/>',
            '<cylinder radius="0.01" length="0.04"/>',
            '<mesh filename="m.stl" scale="2 0.5 1"/>',
        )
    )
    b3 = _shape("collision", '<mesh filename="m.stl" scale="1 -1 1"/>') + _shape(
        "collision", '<mesh filename="m.stl"/>', ""
    )
    ours = _same_as_yourdfpy(_toy(tmp_path, a3, b3), tmp_path)
    assert [g.link for g in ours] == ["a3", "b3"]


@pytest.mark.parametrize("kind", ["obj", "ply", "glb"])  # grasptwist's OBJ and PLY readers; glb: trimesh's
def test_a_link_mesh_in_another_format_is_yourdfpys(tmp_path, kind):
    toy = _toy(tmp_path, _shape("collision", f'<mesh filename="m.{kind}" scale="1 2 1"/>'), "")
    data = trimesh.load(tmp_path / "m.stl").export(file_type=kind)
    (tmp_path / f"m.{kind}").write_bytes(data.encode() if isinstance(data, str) else data)
    assert [g.link for g in _same_as_yourdfpy(toy, tmp_path)] == ["a3"]


def test_without_collision_geometry_the_visual_meshes_are_yourdfpys(tmp_path):
    a3 = _shape("visual", '<mesh filename="m.stl" scale="0.5"/>') + _shape("visual", '<box size="0.01 0.02 0.05"/>')
    b3 = _shape("visual", '<mesh filename="m.stl"/>') + _shape("visual", '<sphere radius="0.01"/>')  # turned, here
    ours = _same_as_yourdfpy(_toy(tmp_path, a3, b3), tmp_path)
    assert [g.link for g in ours] == ["a3", "b3"]


def test_a_finger_links_mesh_outside_the_caps_is_the_urdfs_error_naming_it(tmp_path):
    toy = _toy(
        tmp_path, _shape("collision", '<mesh filename="m.stl"/>'), _shape("collision", '<mesh filename="bad.stl"/>')
    )
    (tmp_path / "bad.stl").write_bytes(b"not a mesh")
    with pytest.raises(InputError, match=r"mesh 'bad\.stl': not a readable STL file") as caught:
        link_geometry(toy, folder=tmp_path)
    text = (tmp_path / toy.source).read_text().splitlines()
    line = next(i for i, row in enumerate(text, 1) if 'filename="bad.stl"' in row)
    error = caught.value  # the URDF as its reading names it, at the <mesh>'s line
    assert (error.code, error.file, error.line) == ("invalid-mesh", os.path.join(tmp_path, toy.source), line)


def test_a_mesh_is_merged_as_trimesh_merges_what_it_loads(tmp_path):
    cap = trimesh.creation.icosphere(subdivisions=2, radius=0.01).slice_plane([0, 0, 0], [0, 0, -1], cap=True)
    (tmp_path / "cap.stl").write_bytes(cap.export(file_type="stl"))
    vertices, faces = mesh_file("cap.stl", tmp_path / "h.urdf", "h.urdf")
    loaded = trimesh.load(tmp_path / "cap.stl")  # processed: vertices merged to trimesh.tol.merge
    assert np.array_equal(faces, loaded.faces) and np.array_equal(vertices, loaded.vertices)
    # and the merge itself, where trimesh rounds to 8 decimals: 1e-9 apart is one vertex, 1e-7 two
    near = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [1e-9, 0, 0], [0, 1 + 1e-7, 0]])
    v, f = merged(near, [[0, 1, 2], [3, 1, 4]])
    assert (len(v), f.tolist()) == (4, [[0, 1, 2], [0, 1, 3]])
    assert [len(x) for x in merge_vertices(near, [[0, 1, 2], [3, 1, 4]])] == [5, 2]  # exact merging keeps them apart
