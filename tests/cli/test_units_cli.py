"""Units and ``-o`` on the command line (issue 35, items 5 and 7): ``synthesize MESH --units``, records
that say their units, a grasp file written with ``-o`` that reads back from anywhere, and ``-o``
that never replaces a mesh a grasp file names."""

import numpy as np
import pytest

from hostile import jsonl, run
from small_meshes import cube_obj

#: The weight alone: the hold test's loads (tests/cli/test_synthesize_cli.py) would cost numpy's grip five more grips a grasp.
SEARCH = ("--friction", "0.8", "--mass", "0.19", "-n", "2", "--candidates", "200", "--loads", "weight")
#: One grasp where the point is a warning, a path or a refusal, not how grasps compare: each grasp found is
#: verified (its hold friction bisected), most of a search's time.
ONE = (*SEARCH[:4], "-n", "1", *SEARCH[6:])


@pytest.fixture
def objects(tmp_path):
    """A folder with the same 65 mm cube in millimetres and in metres, and a grasp file in mm."""
    folder = tmp_path / "objects"
    folder.mkdir()
    cube_obj(folder / "cube_mm.obj", 65.0)
    cube_obj(folder / "cube_m.obj", 0.065)
    (folder / "cube.yaml").write_text("units: mm\nobject:\n  mesh: cube_mm.obj\n  density: 700\nfriction: 0.8\n")
    return folder


@pytest.mark.slow  # the default run's 40 s: development.md, Test time
def test_a_mesh_in_millimetres_and_one_in_metres_give_the_same_grasps_up_to_scale(objects):
    mm, _ = run("synthesize", objects / "cube_mm.obj", "--units", "mm", *SEARCH, "-f", "jsonl")
    m, _ = run("synthesize", objects / "cube_m.obj", *SEARCH, "-f", "jsonl")
    assert mm.exit_code == m.exit_code == 0, mm.stderr + m.stderr
    in_mm, in_m = jsonl(mm.stdout), jsonl(m.stdout)
    assert [r["units"] for r in in_mm] == ["mm"] * 2 and [r["units"] for r in in_m] == ["m"] * 2
    points_mm = np.array([[c["point"] for c in r["contacts"]] for r in in_mm])
    points_m = np.array([[c["point"] for c in r["contacts"]] for r in in_m])
    np.testing.assert_allclose(points_mm / 1000, points_m, rtol=0, atol=1e-12)
    forces = [[r["scores"]["total_normal_force"]["hold"] for r in recs] for recs in (in_mm, in_m)]
    np.testing.assert_allclose(forces[0], forces[1], rtol=1e-9)  # N either way
    assert "mesh-size-unlikely" not in mm.stderr + m.stderr


def test_a_mesh_in_millimetres_read_in_metres_warns_in_the_records_and_on_stderr(objects):
    r, _ = run("synthesize", objects / "cube_mm.obj", *ONE, "-f", "jsonl")
    assert r.exit_code == 0, r.stderr
    (said,) = {w for rec in jsonl(r.stdout) for w in rec["warnings"]}
    assert said.startswith("mesh-size-unlikely: the mesh spans 65 m: is it in millimetres?")
    assert "warning: mesh-size-unlikely" in r.stderr
    bad, _ = run("synthesize", objects / "cube_mm.obj", "--units", "px", *ONE)
    assert bad.exit_code == 2 and "--units" in bad.stderr


def test_a_grasp_file_written_from_another_folder_reads_back_from_anywhere(objects, tmp_path, monkeypatch):
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    r, _ = run("synthesize", "../objects/cube.yaml", *ONE, "-o", "../objects/found.yaml", "-f", "jsonl")
    assert r.exit_code == 0, r.stderr
    found = (objects / "found.yaml").read_text()
    assert "units: mm" in found and "mesh: cube_mm.obj" in found  # from the new file's folder
    monkeypatch.chdir(tmp_path)  # a third folder
    back, _ = run("resolve", "objects/found.yaml", "--twist", "0,0,1,0,0,0", "-f", "jsonl")
    assert back.exit_code == 0, back.stderr
    recs = jsonl(back.stdout)
    assert [x["units"] for x in recs] == ["mm"]
    np.testing.assert_allclose(
        [[c["point"] for c in x["contacts"]] for x in recs],
        [[c["point"] for c in x["contacts"]] for x in jsonl(r.stdout)],
        rtol=1e-15,
    )


@pytest.mark.slow  # the default run's 40 s: development.md, Test time
def test_a_scaled_mesh_is_written_with_its_scale(objects, tmp_path):
    (objects / "scaled.yaml").write_text(
        "units: m\nobject:\n  mesh: {file: cube_mm.obj, units: mm, scale: [1, 1, 2]}\n  mass: 0.2\nfriction: 0.8\n"
    )
    r, _ = run("synthesize", objects / "scaled.yaml", *SEARCH, "-o", tmp_path / "found.yaml", "-f", "jsonl")
    assert r.exit_code == 0, r.stderr
    assert "scale: [0.001, 0.001, 0.002]" in (tmp_path / "found.yaml").read_text()
    back, _ = run("forces", tmp_path / "found.yaml", "--allow-outside", "-f", "jsonl")
    assert back.exit_code == 0, back.stderr
    assert max(abs(c["point"][2]) for x in jsonl(back.stdout) for c in x["contacts"]) <= 0.065 + 1e-12


@pytest.mark.parametrize("command", ["synthesize", "resolve"])
def test_o_onto_a_mesh_a_grasp_file_names_is_refused_located_and_the_mesh_kept(objects, command):
    mesh = objects / "cube_mm.obj"
    before = mesh.read_bytes()
    grasp = objects / "cube.yaml"
    if command == "resolve":  # a grasp with contacts, the same mesh
        grasp.write_text(grasp.read_text() + "contacts:\n  - {point: [32.5, 0, 0]}\n  - {point: [-32.5, 0, 0]}\n"
                         "  - {point: [0, 32.5, 0]}\n")  # fmt: skip
        args = ("resolve", grasp, "--twist", "0,0,1,0,0,0")
    else:
        args = ("synthesize", grasp, *SEARCH)
    r, _ = run(*args, "-o", mesh, "-f", "jsonl")
    assert r.exit_code == 2
    assert f"{grasp}:3:9: error: output-is-input: object.mesh: cube_mm.obj: is the file -o writes" in r.stderr
    assert "grasptwist: error: -o: not written" in r.stderr
    assert mesh.read_bytes() == before


def test_o_file_yaml_that_a_grasp_file_names_as_its_mesh_is_not_written(objects, tmp_path):
    # a mesh that is a link to the output: the same file, found by its device and inode
    out = tmp_path / "found.yaml"
    out.write_text("kept\n")
    (objects / "link.obj").symlink_to(out)
    (objects / "linked.yaml").write_text("object:\n  mesh: link.obj\n  mass: 0.2\nfriction: 0.8\n")
    r, _ = run("synthesize", objects / "cube.yaml", objects / "linked.yaml", *ONE, "-o", out, "-f", "jsonl")
    assert r.exit_code == 2 and "linked.yaml:2:9: error: output-is-input" in r.stderr
    assert out.read_text() == "kept\n"


@pytest.mark.slow  # a URDF hand is read: 1 s; the reader's own refusal is tested fast below
def test_o_onto_the_urdf_a_grasp_file_names_is_refused_and_the_urdf_kept(tmp_path):
    pytest.importorskip("yourdfpy")
    from grasptwist.io.urdf import resolve_urdf
    from places import GRASPS

    try:
        urdf = resolve_urdf("package://robot_properties_fingers/urdf/pro/trifingerpro.urdf")
    except Exception:  # noqa: BLE001 - the package that ships it is not installed
        pytest.skip("robot_properties_fingers is not installed")
    (tmp_path / "hand.urdf").write_bytes(urdf.read_bytes())
    text = (GRASPS / "trifinger-cube.yaml").read_text()
    text = text.replace("package://robot_properties_fingers/urdf/pro/trifingerpro.urdf", "hand.urdf")
    (tmp_path / "g.yaml").write_text(text)
    before = (tmp_path / "hand.urdf").read_bytes()
    r, _ = run("resolve", tmp_path / "g.yaml", "-o", tmp_path / "hand.urdf", "-f", "jsonl")
    assert r.exit_code == 2 and "error: output-is-input: hand.urdf:" in r.stderr
    assert (tmp_path / "hand.urdf").read_bytes() == before


def test_a_search_judges_its_object_against_the_hand_it_is_given():
    from grasptwist.model import CONTACT_NAMES, Finger, Grasp, GraspObject, Hand, Shape
    from grasptwist.run.synthesize import _object_warnings

    def finger(length):
        return Finger("f", None, (), np.zeros((0, 6)), np.zeros((0, 3)), None, length, ())

    cube = GraspObject(Shape("box", np.full(3, 65.0)), np.eye(4))
    nan = np.full((3, 3), np.nan)
    entry = Grasp("cube", "mm", "cube.yaml", 0, CONTACT_NAMES, nan, nan, None, (), 1, object=cube)
    urdf_sized = Hand((finger(0.382),) * 3, (), "trifinger.urdf", None)  # a TriFinger's reach, in metres
    (said,) = _object_warnings(entry, cube, urdf_sized)
    assert said == (  # the reach in the URDF's metres and the object's unit (0.5.0: "(0.382 mm)")
        "hand-size-mismatch: the object's largest extent (65 mm) is 170 times the fingers' reach (the URDF's "
        "0.382 m, 382 mm, taken as 0.382 mm: lengths are never converted): is the object in another unit than "
        "the hand (a URDF is in metres)?"
    )
    assert _object_warnings(entry, cube, Hand((finger(382.0),) * 3, (), None, None)) == ()
    assert _object_warnings(entry, cube, None) == ()  # a primitive without a hand: no unit to judge by


def test_the_readers_refuse_the_output_before_they_parse_it(tmp_path):
    import os

    from grasptwist.io.mesh_file import read_mesh
    from grasptwist.io.urdf import resolve_urdf
    from grasptwist.model import InputError

    mesh = cube_obj(tmp_path / "cube.obj", 0.065)
    info = os.stat(mesh)
    output = (info.st_dev, info.st_ino)
    with pytest.raises(InputError) as err:  # the reader of meshes and URDFs alike (io/urdf.py's _read)
        read_mesh("cube.obj", tmp_path, output=output)
    assert err.value.code == "output-is-input" and err.value.file == "cube.obj"
    assert len(read_mesh("cube.obj", tmp_path)[1]) == 12  # not the output: read
    # a path that leaves the folder and is the output: said as such, not as path-outside
    (tmp_path / "inner").mkdir()
    with pytest.raises(InputError) as err:
        resolve_urdf("../cube.obj", tmp_path / "inner", output=output)
    assert err.value.code == "output-is-input"
    with pytest.raises(InputError) as err:
        resolve_urdf("../cube.obj", tmp_path / "inner")
    assert err.value.code == "path-outside"
