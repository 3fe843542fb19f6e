"""The picture's geometry (plain data from plot.scene) and headless rendering."""

import itertools
import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import grasptwist as gt
from grasp_gen import grasps
from grasptwist import plot
from grasptwist.engine import screws
from grasptwist.engine.degeneracy import Status
from grasptwist.io.grasp_file import load_grasps

BUNDLED = sorted((Path(__file__).parent.parent / "grasps").glob("*.yaml"))
EX1 = np.array([[1, 0, 0], [-0.5, 0.866, 0], [-0.5, -0.866, 0]], float)
EX1_WRIST = np.array([0, 0, 1.0])
EX2 = np.array([[0, 2, 2], [2, 0, 2], [2, 2, 0]], float)
SPIN_Z = np.array([0, 0, 1.0, 0, 0, 0])
J, K = [1, 2, 0], [2, 0, 1]


def random_grasp(seed=7):
    points, normals, wrist, twist = grasps(np.random.default_rng(seed), 1)
    return points[0], normals[0], wrist[0], twist[0]


# Fixtures: (points, normals, wrist, twist, method) for both paper examples and a random grasp.
CASES = {
    "ex1-off-tangent": (EX1, -EX1, EX1_WRIST, SPIN_Z, "off-tangent"),
    "ex1-tangent": (EX1, -EX1 + [0, 0, 0.5], EX1_WRIST, np.array([0.3, -0.2, 1, 0.1, 0.4, 0.2]), "tangent"),
    "ex2-tangent": (EX2, np.eye(3), None, np.array([0.57735, 0.57735, 0.57735, 0, 0, 0]), "tangent"),
    "random-off-tangent": random_grasp() + ("off-tangent",),
    "random-tangent": random_grasp() + ("tangent",),
}


def make_scene(case, **kw):
    points, normals, wrist, twist, method = CASES[case]
    return plot.scene(points, normals, wrist, twist, method, **kw)


def distance_to_line(point, segment):
    """Distance from ``point`` to the infinite line carrying ``segment``."""
    d = screws.unit(segment.direction)
    return float(screws.norm(screws.cross(np.asarray(point) - segment.start, d)))


def axes(scene, kind):
    return {s.label: s for s in scene.of_kind(kind)}


def test_sigma_axes_pass_through_the_other_two_contacts_and_psi_through_contact_and_wrist():
    points, _, wrist, _, _ = CASES["random-off-tangent"]
    sc = make_scene("random-off-tangent")
    sigma, psi = axes(sc, "sigma-axis"), axes(sc, "psi-axis")
    assert sorted(sigma) == ["Σ1", "Σ2", "Σ3"] and sorted(psi) == ["Ψ1", "Ψ2", "Ψ3"]
    for i in range(3):
        for p in (points[J[i]], points[K[i]]):
            assert distance_to_line(p, sigma[f"Σ{i + 1}"]) < 1e-9
        for p in (points[i], wrist):
            assert distance_to_line(p, psi[f"Ψ{i + 1}"]) < 1e-9


def test_theta_axes_pass_through_their_contact_along_eq22():
    sc = make_scene("ex2-tangent")
    theta = axes(sc, "theta-axis")
    for i in range(3):
        seg = theta[f"Θ{i + 1}"]
        assert distance_to_line(EX2[i], seg) < 1e-9
        # Example 2: w_i is the i-th coordinate axis (NOTES.md).
        np.testing.assert_allclose(np.abs(screws.unit(seg.direction)), np.eye(3)[i], atol=1e-12)


def test_axis_segments_are_centred_near_the_centroid_and_scaled_to_the_grasp():
    sc = make_scene("ex1-off-tangent")
    centroid, size = EX1.mean(axis=0), np.max(np.linalg.norm(EX1 - EX1[J], axis=1))
    for seg in sc.segments:
        mid = (seg.start + seg.end) / 2
        # the midpoint is the foot of the perpendicular from the centroid
        assert abs(screws.dot(centroid - mid, seg.direction)) < 1e-9
        assert 0.5 * size < screws.norm(seg.direction) < 3 * size


@pytest.mark.parametrize("case", sorted(CASES))
def test_contact_velocity_arrows_equal_the_engine_and_their_parts_sum_to_them(case):
    points, _, _, twist, _ = CASES[case]
    sc = make_scene(case, names=("a", "b", "c"))
    velocity = [a for a in sc.arrows if a.kind == "contact-velocity"]
    np.testing.assert_allclose([a.vector for a in velocity], gt.contact_velocities(points, twist), atol=1e-12)
    parts = [a for a in sc.arrows if a.kind.endswith("-part")]
    assert len(parts) == 9  # three per contact
    scale = {a.scale for a in sc.arrows if a.kind == "contact-velocity" or a.kind.endswith("-part")}
    assert len(scale) == 1  # one drawing length per unit velocity for all of them
    for i, v in enumerate(velocity):
        chain = parts[3 * i : 3 * i + 3]  # the scene lists each contact's parts together
        np.testing.assert_array_equal(chain[0].origin, points[i])
        np.testing.assert_allclose(sum(a.vector for a in chain), v.vector, atol=1e-9 * (1 + screws.norm(v.vector)))
        # chained tip to tail, ending at the contact velocity's tip
        for a, b in itertools.pairwise(chain):
            np.testing.assert_allclose(a.tip, b.origin, atol=1e-12)
        np.testing.assert_allclose(chain[-1].tip, v.tip, atol=1e-9)


def test_off_tangent_parts_are_x_i_sigma_i_and_y_j_psi_j_of_the_engine():
    r = gt.decompose_off_tangent(EX1, EX1_WRIST, SPIN_Z)
    sc = make_scene("ex1-off-tangent")
    parts = {a.label: a.vector for a in sc.arrows if a.kind.endswith("-part")}
    for i in range(3):
        at = f"(p{i + 1})"
        np.testing.assert_allclose(parts[f"x{i + 1} Σ{i + 1}{at}"], r.x[i] * screws.field_at(r.sigma[i], EX1[i]))
        for j in (J[i], K[i]):
            np.testing.assert_allclose(parts[f"y{j + 1} Ψ{j + 1}{at}"], r.y[j] * screws.field_at(r.psi[j], EX1[i]))
    # Example 1b: x = 0, so every contact moves by the Psi parts alone.
    assert all(np.allclose(v, 0) for label, v in parts.items() if label.startswith("x"))
    assert "y = (-0.471, -0.471, -0.471)" in sc.title


def test_tangent_parts_come_from_contact_split():
    points, normals, _, twist, _ = CASES["ex1-tangent"]
    theta_velocity, sigma_velocity = gt.decompose_tangent(points, normals, twist).contact_split()
    sc = make_scene("ex1-tangent")
    parts = {a.label: a.vector for a in sc.arrows if a.kind.endswith("-part")}
    for i in range(3):
        at = f"(p{i + 1})"
        np.testing.assert_allclose(parts[f"β{i + 1} Σ{i + 1}{at}"], sigma_velocity[i])
        for j in (J[i], K[i]):
            np.testing.assert_allclose(parts[f"α{j + 1} Θ{j + 1}{at}"], theta_velocity[i, j])


def test_twist_axis_and_pitch():
    twist = screws.screw([0, 0, 2.0], [0.4, -2.0, 1.0])  # axis through (1, 0.2, *) along z, pitch 0.5
    sc = plot.scene(EX1, -EX1, EX1_WRIST, twist)
    (seg,) = sc.of_kind("twist-axis")
    assert distance_to_line([1, 0.2, 5], seg) < 1e-12
    assert "pitch 0.5" in seg.label


def test_pure_translation_draws_an_arrow_and_a_far_axis_a_note():
    sc = plot.scene(EX1, -EX1, EX1_WRIST, [0, 0, 0, 0, 0, 3.0])
    (arrow,) = sc.of_kind("twist-translation")
    np.testing.assert_allclose(screws.unit(arrow.vector), [0, 0, 1])
    assert not sc.of_kind("twist-axis")
    far = plot.scene(EX1, -EX1, EX1_WRIST, [0, 0, 0.001, 10, 0, 0])
    assert not far.of_kind("twist-axis") and "not drawn" in far.title


def test_degenerate_grasp_keeps_the_grasp_and_says_why_in_the_title():
    sc = plot.scene(EX1, -EX1, [0.2, 0.1, 0], SPIN_Z, "off-tangent", names=("thumb", "index", "middle"))
    assert sc.status == Status.WRIST_COPLANAR
    assert "wrist lies in the plane of the contacts" in sc.title
    assert not sc.segments or {s.kind for s in sc.segments} == {"twist-axis"}
    assert not [a for a in sc.arrows if a.kind.endswith("-part")]
    assert [m.label for m in sc.of_kind("contact")] == ["thumb", "index", "middle"]
    assert len(sc.of_kind("contact-velocity")) == 3
    collinear = plot.scene([[0, 0, 0], [1, 0, 0], [2, 0, 0]], np.eye(3), None, None, "tangent")
    assert collinear.status == Status.COLLINEAR_CONTACTS and "collinear" in collinear.title
    assert not collinear.segments


def test_no_twist_draws_grasp_and_basis_only():
    sc = plot.scene(EX2, np.eye(3), None, None)
    assert sc.method == "tangent"  # the default without a wrist
    assert len(sc.of_kind("theta-axis")) == 3
    assert not [a for a in sc.arrows if a.kind != "normal"]


def test_bad_method_or_missing_wrist_is_an_error():
    with pytest.raises(ValueError, match="needs a wrist"):
        plot.scene(EX2, np.eye(3), None, SPIN_Z, "off-tangent")
    with pytest.raises(ValueError, match="unknown method"):
        plot.scene(EX2, np.eye(3), None, SPIN_Z, "sideways")


def test_views_look_down_the_contact_plane_normal_from_the_wrist_side():
    sc = make_scene("ex1-off-tangent")
    (_, oblique), (_, down) = sc.views
    np.testing.assert_allclose(down, [0, 0, 1], atol=1e-12)
    assert 0.1 < screws.dot(oblique, down) < 0.99


def test_import_needs_no_matplotlib_and_says_how_to_install_it():
    code = (
        "import sys; sys.modules['matplotlib'] = None\n"
        "import grasptwist.plot as p\n"
        "try:\n    p.require_matplotlib()\nexcept p.MissingMatplotlib as e:\n    print(e)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert "pip install 'grasptwist[plot]'" in out


def test_render_without_matplotlib_raises_missing_matplotlib(monkeypatch, tmp_path):
    monkeypatch.setitem(sys.modules, "matplotlib", None)  # makes `import matplotlib` fail
    with pytest.raises(plot.MissingMatplotlib, match="grasptwist\\[plot\\]"):
        plot.render(make_scene("ex2-tangent"), tmp_path / "x.png")
    assert not (tmp_path / "x.png").exists()


def test_safe_names_and_unsupported_format(tmp_path):
    from grasptwist.plot.scene import _safe_name  # no public name yet: the plot split gives one

    assert _safe_name("a b/c:d") == "a_b_c_d"
    with pytest.raises(ValueError, match=".png"):
        plot.render(make_scene("ex2-tangent"), tmp_path / "x.jpg")


# --- rendering ---------------------------------------------------------------


@pytest.mark.parametrize("case", ["ex1-off-tangent", "ex2-tangent", "random-off-tangent"])
def test_renders_png_of_the_requested_size_and_svg_headless(case, tmp_path):
    pytest.importorskip("matplotlib")
    import matplotlib.image

    sc = make_scene(case)
    png = plot.render(sc, tmp_path / "g.png", size=(640, 320), dpi=80)
    pixels = matplotlib.image.imread(png)
    assert pixels.shape[:2] == (320, 640)
    assert pixels[..., :3].var() > 0
    svg = plot.render(sc, tmp_path / "g.svg", size=(640, 320), dpi=80)
    assert "<svg" in svg.read_text()


def test_render_grasps_writes_one_image_per_grasp_and_twist(tmp_path):
    pytest.importorskip("matplotlib")
    twist = lambda name, s: SimpleNamespace(name=name, screw=np.asarray(s, float))
    cylinder = SimpleNamespace(
        name="cylinder",
        contact_names=("1", "2", "3"),
        points=EX1,
        normals=-EX1,
        wrist=EX1_WRIST,
        twists=(twist("spin z", SPIN_Z), twist("lift", [0, 0, 0, 0, 0, 1])),
    )
    polyhedron = SimpleNamespace(
        name="polyhedron", contact_names=("a", "b", "c"), points=EX2, normals=np.eye(3), wrist=None, twists=()
    )
    paths = plot.render_grasps([cylinder, polyhedron, cylinder], tmp_path / "out", suffix=".svg", size=(400, 200))
    names = [p.name for p in paths]
    assert names == [
        "cylinder-spin_z.svg",
        "cylinder-lift.svg",
        "polyhedron.svg",
        "cylinder-spin_z-2.svg",
        "cylinder-lift-2.svg",
    ]
    assert all(p.stat().st_size > 0 for p in paths)


@pytest.mark.parametrize("suffix", [".png", ".svg"])
def test_every_bundled_example_renders_headless(suffix, tmp_path):
    pytest.importorskip("matplotlib")
    import matplotlib.image

    assert BUNDLED
    loaded = [g for f in BUNDLED for g in load_grasps(f)]
    paths = plot.render_grasps(loaded, tmp_path, suffix=suffix, size=(480, 240), dpi=60)
    assert len(paths) == sum(max(1, len(g.twists)) for g in loaded)
    for path in paths:
        if suffix == ".png":
            pixels = matplotlib.image.imread(path)
            assert pixels.shape[:2] == (240, 480) and pixels[..., :3].var() > 0
        else:
            assert "<svg" in path.read_text()
