"""io/mesh_file.py: a mesh read within its limits, every refusal one coded error."""

import sys

import numpy as np
import pytest

from grasptwist.io.limits import MAX_TRIANGLES
from grasptwist.io.mesh_file import check_mesh, read_mesh
from grasptwist.model import InputError
from places import GRASPS


@pytest.fixture
def trimesh():
    """trimesh, for the PLY it parses and the meshes it writes: its import takes a second, so these tests are slow."""
    return pytest.importorskip("trimesh")


def volume(vertices, faces):
    """The signed volume of a closed triangle mesh (> 0 wound outwards)."""
    a, b, c = vertices[faces].transpose(1, 0, 2)
    return float(np.einsum("ij,ij->", a, np.cross(b, c)) / 6)


# The tetrahedron (0, 0, 0), e_x, e_y, e_z, wound counter-clockwise seen from outside.
TETRA_V = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
TETRA_F = ["f 1 3 2", "f 1 2 4", "f 1 4 3", "f 2 3 4"]


def obj(tmp_path, text, name="m.obj"):
    (tmp_path / name).write_text(text)
    return name


def tetra(faces=TETRA_F, vertices=TETRA_V):
    return vertices + "\n".join(faces) + "\n"


def test_a_closed_mesh_is_read_with_its_volume_outwards(tmp_path):
    vertices, faces = read_mesh(obj(tmp_path, tetra()), tmp_path)
    assert vertices.shape == (4, 3) and faces.shape == (4, 3)
    assert volume(vertices, faces) == pytest.approx(1 / 6)
    assert not vertices.flags.writeable and not faces.flags.writeable


def test_a_mesh_wound_inwards_is_turned_outwards_and_said(tmp_path):
    inward = [f"f {a} {c} {b}" for _, a, b, c in (f.split() for f in TETRA_F)]
    said = []
    vertices, faces = read_mesh(obj(tmp_path, tetra(inward)), tmp_path, warnings=said)
    assert volume(vertices, faces) == pytest.approx(1 / 6)
    assert said == ["mesh-repaired: faces re-wound outwards (the geometry is unchanged)"]  # 0.5.0: silent
    said = []
    read_mesh(obj(tmp_path, tetra()), tmp_path, warnings=said)
    assert said == []  # wound outwards already
    # an STL wound inwards, as a binary STL gives it (its vertices repeated: their merging not said)
    a, b, c = vertices[faces[:, ::-1]].transpose(1, 0, 2)
    n = np.cross(b - a, c - a)
    records = np.zeros(len(a), dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])
    records["n"], records["v"] = n, np.stack([a, b, c], axis=1)
    (tmp_path / "in.stl").write_bytes(bytes(80) + np.uint32(len(a)).tobytes() + records.tobytes())
    said = []
    vertices, faces = read_mesh("in.stl", tmp_path, warnings=said)
    assert volume(vertices, faces) == pytest.approx(1 / 6, rel=1e-6)
    assert said == ["mesh-repaired: faces re-wound outwards (the geometry is unchanged)"]


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_an_stl_repeats_its_vertices_and_is_merged(tmp_path, trimesh):
    trimesh.creation.box((1, 2, 3)).export(tmp_path / "box.stl")
    vertices, faces = read_mesh("box.stl", tmp_path)
    assert (len(vertices), len(faces)) == (8, 12)
    assert np.ptp(vertices, axis=0).tolist() == [1, 2, 3]


def test_the_bundled_bottle():
    vertices, faces = read_mesh("meshes/bottle.obj", GRASPS)
    assert len(faces) == 1152
    assert volume(vertices, faces) == pytest.approx(6.938e-4, rel=1e-3)


@pytest.mark.parametrize(
    ("text", "name", "code", "match"),
    [
        (tetra(), "m.step", "unsupported-mesh", r"^m.step: expected a mesh file ending in \.stl, \.obj or \.ply$"),
        ("", "m.obj", "empty-mesh", "no triangles in the mesh$"),
        ("solid x\nendsolid x\n", "m.stl", "empty-mesh", "no triangles"),
        (tetra(["f 1 2 9"]), "m.obj", "invalid-mesh", "^m.obj: a face names a vertex the file does not have$"),
        (tetra(["f 1 2 x"]), "m.obj", "invalid-mesh", "^m.obj:5: a face's corners are not vertex numbers$"),
        (tetra(["f 1 2"]), "m.obj", "invalid-mesh", "^m.obj:5: a face needs three corners$"),
        (b"solid x\n\xff\xfe garbage", "m.stl", "empty-mesh", "no triangles"),
        # a text file named .stl (issue 30's user): no STL of either kind, refused unparsed
        (b"not a mesh", "m.stl", "invalid-mesh", r"^m.stl: not a readable STL file \(neither a binary STL "),
        (bytes(80) + (3).to_bytes(4, "little") + bytes(149), "m.stl", "invalid-mesh", "not a readable STL"),
        (tetra(vertices="v nan 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"), "m.obj", "non-finite", "NaN or infinite$"),
        (
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nelement face 9999999\nend_header\n",
            "m.ply",
            "invalid-mesh",
            "^m.ply:3: the header declares 3 vertex elements, one a line, but the body holds 0 lines$",
        ),
    ],
    ids=[
        "suffix",
        "empty",
        "empty-stl",
        "bad-index",
        "bad-word",
        "two-corners",
        "junk-stl",
        "text-stl",
        "truncated-stl",
        "nan",
        "ply-header",
    ],
)
def test_each_refusal_is_one_coded_error(tmp_path, text, name, code, match):
    (tmp_path / name).write_bytes(text if isinstance(text, bytes) else text.encode())
    with pytest.raises(InputError, match=match) as caught:
        read_mesh(name, tmp_path)
    assert caught.value.code == code and caught.value.file == name


CUBE_V = "".join(f"v {x} {y} {z}\n" for z in (-1, 1) for y in (-1, 1) for x in (-1, 1))
CUBE_F = ["f 1 3 4 2", "f 5 6 8 7", "f 1 2 6 5", "f 3 7 8 4", "f 1 5 7 3", "f 2 4 8 6"]


@pytest.mark.parametrize("scale", ["1e100", "1e-160"])
def test_a_mesh_beyond_double_precision_areas_is_refused(tmp_path, scale):
    (tmp_path / "m.obj").write_text(tetra(CUBE_F, CUBE_V.replace("1", scale)))
    with pytest.raises(InputError, match=r"^m.obj: the mesh's size .* is .*, outside 1e-75 to 1e\+75") as caught:
        read_mesh("m.obj", tmp_path)
    assert caught.value.code == "invalid-size"


def test_a_degenerate_triangle_is_dropped_with_a_warning(tmp_path):
    # the cube's edge 1-3 split at its middle 9 by the zero-area triangle (3, 9, 1)
    faces = ["f 1 9 4 2", "f 9 3 4", "f 3 9 1", *CUBE_F[1:]]
    (tmp_path / "m.obj").write_text(tetra(faces, CUBE_V + "v -1 0 -1\n"))
    said = []
    vertices, kept = read_mesh("m.obj", tmp_path, warnings=said)
    assert len(kept) == 13 and volume(vertices, kept) == pytest.approx(8.0, rel=1e-12)
    assert said == ["mesh-repaired: 1 zero-area face dropped (the geometry is unchanged)"]


def test_a_missing_file_is_a_read_error(tmp_path):
    with pytest.raises(InputError, match="^none.obj: cannot read: ") as caught:
        read_mesh("none.obj", tmp_path)
    assert caught.value.code == "read-error"


def test_the_size_cap_is_checked_before_parsing(tmp_path, monkeypatch):
    from grasptwist.io import mesh_formats

    name = obj(tmp_path, tetra())
    monkeypatch.setitem(mesh_formats._READERS, ".obj", lambda *a, **k: pytest.fail("parsed"))
    with pytest.raises(InputError, match="larger than the size limit of 20 bytes$") as caught:
        read_mesh(name, tmp_path, max_bytes=20)
    assert caught.value.code == "too-large"


def test_the_triangle_limit(tmp_path, monkeypatch):
    from grasptwist.io import mesh_formats

    name = obj(tmp_path, tetra())
    assert len(read_mesh(name, tmp_path, max_triangles=4)[1]) == 4
    # the four f lines say it before the file is parsed
    monkeypatch.setitem(mesh_formats._READERS, ".obj", lambda *a, **k: pytest.fail("parsed"))
    with pytest.raises(
        InputError, match="^m.obj: the file declares 4 faces, more than the limit of 3 triangles$"
    ) as caught:
        read_mesh(name, tmp_path, max_triangles=3)
    assert caught.value.code == "too-many-triangles"
    monkeypatch.undo()
    # two quadrilaterals and two triangles: 4 faces, 6 triangles, counted once parsed
    quads = tetra(["f 1 3 2", "f 1 2 4", "f 1 4 3 3", "f 2 3 4 4"])
    with pytest.raises(
        InputError, match="^m.obj:8: a polygon of more than 3 corners takes the mesh past the limit of 5"
    ):
        read_mesh(obj(tmp_path, quads), tmp_path, max_triangles=5)


@pytest.mark.parametrize(
    ("data", "declared"),
    [
        (b"Solid box\n" + b"facet normal 0 0 1\n outer loop\n endloop\nendfacet\n" * 5 + b"endsolid\n", 5),
        (b"solid" + bytes(75) + (5).to_bytes(4, "little") + bytes(250), 5),  # binary, though its header says solid
        (bytes(80) + (200_000).to_bytes(4, "little") + bytes(10_000_000), 200_000),
    ],
    ids=["ascii", "binary-solid", "binary-10MB"],
)
def test_an_stl_over_the_limit_is_refused_before_it_is_parsed(tmp_path, monkeypatch, data, declared):
    """A binary STL's header gives its count (a 100 MB one once took trimesh 2.7 s and 420 MB to refuse),
    an ASCII one its endfacet words."""
    from grasptwist.io import mesh_formats

    (tmp_path / "m.stl").write_bytes(data)
    monkeypatch.setitem(mesh_formats._READERS, ".stl", lambda *a, **k: pytest.fail("parsed"))
    with pytest.raises(
        InputError, match=f"^m.stl: the file declares {declared:,} faces, more than the limit of 4 "
    ) as caught:
        read_mesh("m.stl", tmp_path, max_triangles=4, max_bytes=len(data))
    assert caught.value.code == "too-many-triangles"


def test_a_path_outside_the_folder_is_refused_unless_allowed(tmp_path):
    inner = tmp_path / "grasps"
    inner.mkdir()
    obj(tmp_path, tetra())
    with pytest.raises(InputError, match=r"^\.\./m\.obj: '\.\./m\.obj' resolves outside ") as caught:
        read_mesh("../m.obj", inner)
    assert caught.value.code == "path-outside"
    assert len(read_mesh("../m.obj", inner, allow_outside=True)[1]) == 4


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_without_trimesh_a_ply_says_which_extra_and_an_stl_and_an_obj_are_read(tmp_path, monkeypatch, trimesh):
    box = trimesh.creation.box((1, 2, 3))
    box.export(tmp_path / "box.ply")
    box.export(tmp_path / "box.stl")
    (tmp_path / "ascii.stl").write_bytes(trimesh.exchange.stl.export_stl_ascii(box).encode())
    monkeypatch.setitem(sys.modules, "trimesh", None)
    with pytest.raises(InputError, match=r"needs trimesh: pip install trimesh .*'\.\[mesh\]'") as caught:
        read_mesh("box.ply", tmp_path)
    assert caught.value.code == "mesh-unavailable"
    assert len(read_mesh(obj(tmp_path, tetra()), tmp_path)[1]) == 4
    for name in ("box.stl", "ascii.stl"):  # read by grasptwist, each triangle's corners merged
        vertices, faces = read_mesh(name, tmp_path)
        assert (len(vertices), len(faces)) == (8, 12)
        assert volume(vertices, faces) == pytest.approx(6)


def test_an_obj_reads_polygons_negative_indices_and_skips_the_rest(tmp_path):
    """A square pyramid: its base a quad, its sides by negative indices, with normals and a group."""
    text = "o pyramid\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 0.5 1\nvn 0 0 -1\ng sides\n"
    text += "f 1//1 4//1 3//1 2//1\nf -5 -4 -1\nf -4 -3 -1\nf 3/1/1 4/1/1 5/1/1\nf 4 1 5\n"
    vertices, faces = read_mesh(obj(tmp_path, text), tmp_path)
    assert (len(vertices), len(faces)) == (5, 6)
    assert volume(vertices, faces) == pytest.approx(1 / 3)


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_the_obj_reader_and_trimesh_agree_on_the_bottle(trimesh):
    """Our OBJ lines and trimesh's parse of the same file: the same closed mesh."""
    ours = read_mesh("meshes/bottle.obj", GRASPS)
    mesh = trimesh.load(GRASPS / "meshes" / "bottle.obj", process=False, force="mesh")
    theirs = check_mesh(np.asarray(mesh.vertices), np.asarray(mesh.faces), MAX_TRIANGLES, "bottle.obj")
    for a, b in zip(ours, theirs):
        np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("end", ["\r\n", "\r"])
def test_an_obj_reads_the_same_whatever_its_line_ends(tmp_path, end):
    expected = read_mesh(obj(tmp_path, tetra()), tmp_path)
    (tmp_path / "other.obj").write_bytes(tetra().replace("\n", end).encode())
    for a, b in zip(read_mesh("other.obj", tmp_path), expected):
        np.testing.assert_array_equal(a, b)


def test_a_binary_ply_s_polygons_count_as_their_fans_before_trimesh_reads_them(tmp_path, monkeypatch):
    import struct

    from grasptwist.io import mesh_formats

    header = "ply\nformat binary_big_endian 1.0\nelement vertex 6\nproperty double x\nproperty double y\n"
    header += "property double z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
    body = struct.pack(">18d", *range(18)) + bytes([6]) + struct.pack(">6i", *range(6))
    (tmp_path / "m.ply").write_bytes(header.encode() + body)
    monkeypatch.setattr(mesh_formats, "_parsed", lambda *a, **k: pytest.fail("parsed"))
    with pytest.raises(InputError, match=r"^m.ply:7: the faces hold 4 triangles, more than the limit of 3$") as caught:
        read_mesh("m.ply", tmp_path, max_triangles=3)
    assert caught.value.code == "too-many-triangles"
    (tmp_path / "m.ply").write_bytes(header.encode() + body[:-4])  # the last corner cut off
    with pytest.raises(InputError, match=r"^m.ply:7: the body ends inside a face row$"):
        read_mesh("m.ply", tmp_path)
