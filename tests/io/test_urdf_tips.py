"""A URDF finger's tip radius: its tip link's spherical collision geometry about the link's origin
(io/urdf.py ``_tip_radius``), and no radius, rather than an error, when there is none to read."""

import numpy as np
import pytest

from grasptwist.hand import load_urdf_hand

trimesh = pytest.importorskip("trimesh")
pytest.importorskip("yourdfpy")


def urdf(collision):
    """Three one-joint fingers on a palm, each tip link with ``collision`` (XML inside <collision>)."""
    links, joints = ['<link name="palm"/>'], []
    for f in range(3):
        links.append(f'<link name="l{f}"/><link name="tip{f}"><collision>{collision}</collision></link>')
        joints.append(
            f'<joint name="j{f}" type="revolute"><parent link="palm"/><child link="l{f}"/>'
            f'<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
            f'<joint name="t{f}" type="fixed"><parent link="l{f}"/><child link="tip{f}"/>'
            f'<origin xyz="{f + 1} 0 0"/></joint>'
        )
    return f'<robot name="r">{"".join(links)}{"".join(joints)}</robot>'


def radii(tmp_path, collision):
    (tmp_path / "hand.urdf").write_text(urdf(collision), "utf-8")
    hand = load_urdf_hand("hand.urdf", ["tip0", "tip1", "tip2"], folder=tmp_path)
    return [f.tip_radius for f in hand.fingers]


def test_a_sphere_centred_on_the_tip_gives_its_radius(tmp_path):
    assert radii(tmp_path, '<geometry><sphere radius="0.012"/></geometry>') == [0.012] * 3


def test_a_sphere_elsewhere_is_no_fingertip(tmp_path):
    assert radii(tmp_path, '<origin xyz="0 0 0.01"/><geometry><sphere radius="0.012"/></geometry>') == [0.0] * 3


@pytest.mark.parametrize("kind", ["stl", "obj", "ply", "glb"])  # grasptwist's readers; glb: trimesh's, imported for it
def test_a_hemisphere_mesh_gives_its_radius_scaled(tmp_path, kind):
    cap = trimesh.creation.icosphere(subdivisions=3, radius=1.0)
    cap = cap.slice_plane([0, 0, 0], [0, 0, -1], cap=True)  # the lower half, closed
    data = cap.export(file_type=kind)
    (tmp_path / f"cap.{kind}").write_bytes(data.encode() if isinstance(data, str) else data)
    got = radii(tmp_path, f'<geometry><mesh filename="cap.{kind}" scale="0.008 0.008 0.008"/></geometry>')
    assert got == pytest.approx([0.008] * 3, rel=1e-6)


@pytest.mark.parametrize(
    "filename",
    ["package://no_such_package_here/tip.stl", "../outside.stl", "missing.stl", "file:///etc/passwd"],
    ids=["no-package", "outside", "missing", "url"],
)
def test_a_mesh_that_cannot_be_read_gives_no_radius_and_no_error(tmp_path, filename):
    (tmp_path.parent / "outside.stl").write_bytes(trimesh.creation.icosphere().export(file_type="stl"))
    assert radii(tmp_path, f'<geometry><mesh filename="{filename}"/></geometry>') == [0.0] * 3


def test_a_box_mesh_is_no_fingertip(tmp_path):
    (tmp_path / "box.stl").write_bytes(trimesh.creation.box([0.02] * 3).export(file_type="stl"))
    assert radii(tmp_path, '<geometry><mesh filename="box.stl"/></geometry>') == [0.0] * 3
    assert np.isfinite(radii(tmp_path, '<geometry><box size="1 1 1"/></geometry>')).all()
