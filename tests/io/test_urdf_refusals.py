"""URDF hands a new user's trial broke on: fingers that cannot be placed (no joint, a shared joint),
repeated names, shapes of no size, link meshes reported where the file names the URDF; each a
located error, the batch's other files keeping their records."""

import json
import os

import numpy as np
import pytest
from typer.testing import CliRunner

from grasptwist import hand
from grasptwist.cli import app
from grasptwist.engine.collision import LinkGeometry, convex_planes, hull_depth, link_hulls
from grasptwist.io.grasp import load_hand_file
from grasptwist.model import InputError
from grasptwist.run.placement import read_grasps
from places import ROOT

pytest.importorskip("yourdfpy")

GOOD = ROOT / "grasps" / "polyhedron.yaml"
SPHERE = '<sphere radius="0.01"/>'


def toy_urdf(tip0=SPHERE, link0='<cylinder radius="0.008" length="0.05"/>', extra=""):
    """Three one-joint fingers about a base (tips 0.15 from its z axis at 0, 120 and 240 degrees),
    and a link ``stub`` fixed to the base; one element a line."""
    rows = ['<robot name="toy">', '<link name="base"/>', '<link name="stub"/>']
    rows.append('<joint name="stub_fix" type="fixed"><parent link="base"/><child link="stub"/></joint>')
    for i in range(3):
        a = 2 * np.pi * i / 3
        shape = link0 if i == 0 else '<cylinder radius="0.008" length="0.05"/>'
        rows.append(f'<link name="l{i}"><collision><geometry>{shape}</geometry></collision></link>')
        rows.append(
            f'<joint name="j{i}" type="revolute"><parent link="base"/><child link="l{i}"/>'
            f'<origin xyz="{0.1 * np.cos(a):.17g} {0.1 * np.sin(a):.17g} 0" rpy="0 0 {a:.17g}"/><axis xyz="0 0 1"/>'
            '<limit lower="-3" upper="3" effort="1" velocity="5"/></joint>'
        )
        rows.append(
            f'<link name="t{i}"><collision><geometry>{tip0 if i == 0 else SPHERE}</geometry></collision></link>'
        )
        rows.append(
            f'<joint name="t{i}_fix" type="fixed"><parent link="l{i}"/><child link="t{i}"/>'
            '<origin xyz="0.05 0 0"/></joint>'
        )
    return "\n".join([*rows, extra, "</robot>", ""])


def grasp_text(tips=("t0", "t1", "t2"), urdf="hand.urdf"):
    """The toy's fingers on contacts at their tips at home (joints at 0)."""
    contacts = "".join(
        f"  - {{point: [{0.15 * np.cos(a):.17g}, {0.15 * np.sin(a):.17g}, 0], normal: [{-np.cos(a):.17g}, {-np.sin(a):.17g}, 0]}}\n"
        for a in 2 * np.pi * np.arange(3) / 3
    )
    fingers = "".join(f"    - {{tip: {t}}}\n" for t in tips)
    return (
        "name: toy\nwrist: [0, 0, 0.1]\ncontacts:\n" + contacts + "twists:\n  - {name: spin, angular: [0, 0, 1]}\n"
        f"hand:\n  urdf: {urdf}\n  joint_positions: {{j0: 0}}\n  fingers:\n{fingers}"
    )


def folder_with(tmp_path, urdf, text):
    """A folder of the toy grasp file ``g.yaml`` on ``urdf`` and a good grasp file without a hand."""
    (tmp_path / "hand.urdf").write_text(urdf, "utf-8")
    (tmp_path / "g.yaml").write_text(text, "utf-8")
    (tmp_path / "good.yaml").write_bytes(GOOD.read_bytes())
    return tmp_path


def check_folder(folder):
    """``grasptwist check FOLDER -f jsonl``: the bad file's one error record (with its stderr line), and
    the good file's record, which must be whole."""
    result = CliRunner().invoke(app, ["check", str(folder), "-f", "jsonl"])
    assert result.exit_code == 1, result.output
    records = [json.loads(line) for line in result.stdout.splitlines()]
    (bad,) = [r for r in records if "error" in r]
    (good,) = [r for r in records if "error" not in r]
    assert good["grasp"] == "polyhedron" and good["ok"] and good["closure_friction"] == pytest.approx(0.5**0.5)
    (line,) = [line for line in result.stderr.splitlines() if ": error: " in line]
    return bad, line


def line_of(text, needle):
    """1-based (line, column) of ``needle``'s first occurrence in ``text``."""
    for i, row in enumerate(text.splitlines(), 1):
        if needle in row:
            return i, row.index(needle) + 1
    raise AssertionError(needle)


# ----------------------------------------------------------------------------------------------
# Fingers inverse kinematics cannot place: refused when the hand is read, at the finger's tip.


@pytest.mark.parametrize("tip", ["base", "stub"])  # the root link; a link fixed to it
def test_a_finger_no_joint_moves_is_refused_at_its_tip(tmp_path, tip):
    text = grasp_text(("t0", "t1", tip))
    bad, said = check_folder(folder_with(tmp_path, toy_urdf(), text))
    line, column = line_of(text, f"tip: {tip}}}")
    column += len("tip: ")
    assert bad["error"]["code"] == "fixed-finger"
    assert said.startswith(f"{tmp_path / 'g.yaml'}:{line}:{column}: error: fixed-finger: hand.fingers[2].tip: ")
    assert f"no movable joint moves its tip link {tip!r}" in said
    with pytest.raises(InputError) as caught:  # in Python too
        hand.load_urdf_hand(tmp_path / "hand.urdf", ["t0", "t1", tip])
    assert caught.value.code == "fixed-finger" and "finger '3'" in caught.value.message


@pytest.mark.parametrize(
    ("tips", "named"),
    [(("t0", "t1", "t1"), "has the same tip link 't1' as finger '2'"), (("t0", "t1", "l1"), "shares joint 'j1'")],
)
def test_fingers_sharing_a_joint_are_refused_at_the_second_ones_tip(tmp_path, tips, named):
    text = grasp_text(tips)
    bad, said = check_folder(folder_with(tmp_path, toy_urdf(), text))
    line = [i for i, row in enumerate(text.splitlines(), 1) if row.startswith("    - {tip:")][2]
    assert bad["error"]["code"] == "shared-joint"
    assert said.startswith(f"{tmp_path / 'g.yaml'}:{line}:13: error: shared-joint: hand.fingers[2].tip: finger '3' ")
    assert named in said
    with pytest.raises(InputError) as caught:  # in Python, at the shared joint's line of the URDF
        hand.load_urdf_hand(tmp_path / "hand.urdf", list(tips))
    assert (caught.value.code, caught.value.line) == ("shared-joint", line_of(toy_urdf(), '<joint name="j1"')[0])


# ----------------------------------------------------------------------------------------------
# The URDF's own numbers and names.


@pytest.mark.parametrize(
    ("shape", "where"),
    [
        ('<sphere radius="0"/>', "tip0"),
        ('<sphere radius="-0.01"/>', "tip0"),
        ('<cylinder radius="0" length="0.05"/>', "link0"),
        ('<cylinder radius="0.01" length="-0.05"/>', "link0"),
        ('<box size="0 0 0"/>', "tip0"),
        ('<box size="-0.1 0.016 0.016"/>', "link0"),
    ],
)
def test_a_shape_of_no_size_is_invalid_urdf_at_its_line(tmp_path, shape, where):
    urdf = toy_urdf(**{where: shape})
    (tmp_path / "hand.urdf").write_text(urdf, "utf-8")
    with pytest.raises(InputError) as caught:
        hand.load_urdf_hand(tmp_path / "hand.urdf", ["t0", "t1", "t2"])
    error = caught.value
    assert (error.code, error.line) == ("invalid-urdf", line_of(urdf, shape)[0])
    assert "must be above 0" in error.message and f"<{shape[1:].split()[0]}" in error.message


def test_a_zero_sphere_is_one_located_error_in_a_batch(tmp_path):
    urdf = toy_urdf(tip0='<sphere radius="0"/>')
    bad, said = check_folder(folder_with(tmp_path, urdf, grasp_text()))
    line = line_of(urdf, '<sphere radius="0"/>')[0]
    at, column = line_of(grasp_text(), "urdf: ")
    assert bad["error"]["code"] == "invalid-urdf"
    assert said == (
        f"{tmp_path / 'g.yaml'}:{at}:{column + len('urdf: ')}: error: invalid-urdf: "
        f"hand.urdf: {tmp_path / 'hand.urdf'}:{line}: "
        "link 't0': <collision>: <sphere radius> must be above 0, got '0'"
    )


@pytest.mark.parametrize("tag", ["joint", "link"])
def test_a_name_given_twice_is_invalid_urdf_at_the_second(tmp_path, tag):
    name = "j1" if tag == "joint" else "l1"
    first = f'<{tag} name="{name}"'
    # the third finger's named as the second's: j2 -> j1, or l2 -> l1 (and the joints naming it)
    urdf = toy_urdf().replace('name="j2"', 'name="j1"') if tag == "joint" else toy_urdf().replace('"l2"', '"l1"')
    (tmp_path / "hand.urdf").write_text(urdf, "utf-8")
    with pytest.raises(InputError) as caught:
        hand.load_urdf_hand(tmp_path / "hand.urdf", ["t0", "t1"])
    lines = [i for i, row in enumerate(urdf.splitlines(), 1) if row.startswith(first)]
    assert (caught.value.code, caught.value.line) == ("invalid-urdf", lines[1])
    assert caught.value.message == f"a second <{tag}> named {name!r} (the first at line {lines[0]})"


# ----------------------------------------------------------------------------------------------
# Link geometry that bounds no solid.


@pytest.mark.parametrize(
    "points",
    [
        [[0.3, 0.2, 0.1]],  # a point
        [[0.3, 0.2, 0.1]] * 5,  # the same point again
        [[0, 0, 0], [1, 0, 0]],  # a segment
        [[0, 0, 0], [1, 1, 1], [2, 2, 2], [3, 3, 3]],  # points on a line
        [[0, 0, 0], [1, 0, 0], [0, 1, 0]],  # a triangle
        [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0], [0.5, 0.5, 0]],  # a flat square
    ],
)
def test_a_hull_of_no_volume_is_a_thin_solid_about_it(points):
    v, planes = convex_planes(points)
    points = np.asarray(points, dtype=float)
    extent = np.ptp(points, axis=0).max()
    half = 2e-3 * extent or 1e-9  # HULL_MERGE times the extent; a point's: 1e-9 (|p| < 1)
    assert np.isfinite(planes).all() and np.allclose(np.linalg.norm(planes[:, :3], axis=1), 1)
    depth = hull_depth(points, planes)  # each point the centre of a cube of the solid: half deep at least
    assert depth.min() >= half * (1 - 1e-6) and depth.max() <= half * np.sqrt(3) * (1 + 1e-6)
    assert np.abs(v - points.mean(axis=0)).max() <= extent * np.sqrt(3) + 2 * half  # no farther than grown
    assert hull_depth(points.mean(axis=0) + [0, 0, 3 * half], planes) < 0  # thin: 3 half-widths off is out
    hulls = link_hulls([LinkGeometry(0, "flat", 1, points, np.zeros((0, 3), int))])
    assert hulls.vertices.shape[0] == 1


# ----------------------------------------------------------------------------------------------
# Link meshes: at the urdf key of the file that names the URDF, the URDF's file and <mesh> line.


@pytest.mark.parametrize(
    ("mesh", "code", "words"),
    [
        ("tip.stl", "invalid-mesh", "mesh 'tip.stl': not a readable STL file"),
        (
            "package://nosuchpkg_xyz/tip.stl",
            "package-not-found",
            "mesh 'package://nosuchpkg_xyz/tip.stl': no installed",
        ),
        ("../tip.stl", "path-outside", "mesh '../tip.stl' resolves outside"),
    ],
)
def test_a_link_mesh_s_error_is_at_the_urdf_key_naming_the_urdf_line(tmp_path, mesh, code, words):
    urdf = toy_urdf(tip0=f'<mesh filename="{mesh}"/>')
    text = grasp_text()
    (tmp_path / "f").mkdir()
    folder = folder_with(tmp_path / "f", urdf, text)
    for where in (folder, tmp_path):  # its own, and one outside its folder
        (where / "tip.stl").write_bytes(b"not a mesh")
    bad, said = check_folder(folder)
    line, column = line_of(text, "urdf: ")
    mesh_line = line_of(urdf, f'filename="{mesh}"')[0]
    assert bad["error"]["code"] == code
    assert said.startswith(
        f"{folder / 'g.yaml'}:{line}:{column + len('urdf: ')}: error: {code}: "
        f"hand.urdf: {os.path.join(folder, 'hand.urdf')}:{mesh_line}: {words}"
    )


def test_a_link_mesh_s_error_names_the_hand_file_that_names_the_urdf(tmp_path):
    from grasptwist.io.grasp import read_grasps as read_unplaced
    from grasptwist.run.grasp_search import grasp_problem

    urdf = toy_urdf(tip0='<mesh filename="tip.stl"/>')
    (tmp_path / "hand.urdf").write_text(urdf, "utf-8")
    (tmp_path / "tip.stl").write_bytes(b"not a mesh")
    hand_file = tmp_path / "h.yaml"
    hand_file.write_text("hand:\n  urdf: hand.urdf\n  fingers:\n    - {tip: t0}\n    - {tip: t1}\n    - {tip: t2}\n")
    held, _ = load_hand_file(hand_file)
    assert held.urdf_at == (str(hand_file), 2, 9)
    (grasp,) = read_unplaced(GOOD)  # a box, its contacts
    error = grasp_problem(grasp, friction=0.5, mass=1.0, hand=held, hand_file=str(hand_file))
    assert isinstance(error, InputError)
    assert (error.code, error.file, error.line, error.column) == ("invalid-mesh", str(hand_file), 2, 9)
    assert error.message.startswith(
        f"hand.urdf: {tmp_path / 'hand.urdf'}:{line_of(urdf, 'tip.stl')[0]}: mesh 'tip.stl': "
    )


def test_the_toy_hand_itself_is_read_and_checked(tmp_path):
    """The fixture is good: the refusals above are each its one change."""
    (tmp_path / "hand.urdf").write_text(toy_urdf(), "utf-8")
    (g,) = read_grasps(grasp_text(), file=str(tmp_path / "g.yaml"))
    assert [f.tip for f in g.hand.fingers] == ["t0", "t1", "t2"] and g.hand.joint_names == ("j0", "j1", "j2")


def test_a_link_mesh_of_one_flat_triangle_is_checked_without_a_fault(tmp_path):
    """A valid mesh that bounds no solid (Qhull refused it, and the grasp's whole run was lost)."""
    (tmp_path / "hand.urdf").write_text(toy_urdf(tip0='<mesh filename="tip.stl"/>'), "utf-8")
    corners = "".join(f"vertex {x} {y} 0\n" for x, y in [(0, 0), (0.01, 0), (0, 0.01)])
    (tmp_path / "tip.stl").write_text(
        f"solid t\nfacet normal 0 0 1\nouter loop\n{corners}endloop\nendfacet\nendsolid t\n"
    )
    (tmp_path / "g.yaml").write_text(grasp_text(), "utf-8")
    result = CliRunner().invoke(app, ["check", str(tmp_path / "g.yaml"), "-f", "jsonl"])
    record = json.loads(result.stdout)  # placed and checked: its numbers (the toy's normals are flat: no tangent)
    assert "error" not in record and record["off_tangent"]["conditioning"] > 0
    # the toy's contacts are its tips' centres: fingers 2 and 3, 10 mm spheres, are a radius off (tip-off-contact);
    # finger 1's flat triangle is no sphere (a point tip), on its contact
    assert [w.split(":")[0] for w in record["warnings"]] == ["tip-off-contact"] * 2
    assert all("finger 1" not in w for w in record["warnings"])
    assert "internal error" not in result.stderr
