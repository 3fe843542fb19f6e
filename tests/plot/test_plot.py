"""The picture's geometry (plain data from plot.scene), its file names, and one headless render per format."""

import itertools
import subprocess
import sys
from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest

import grasptwist as gt
from grasp_gen import grasps
from grasptwist import plot
from grasptwist.engine import screws
from grasptwist.engine.degeneracy import Status
from grasptwist.engine.screws import J, K
from grasptwist.model import Twist
from places import GRASPS

EX1 = np.array([[1, 0, 0], [-0.5, 0.866, 0], [-0.5, -0.866, 0]], float)
EX1_WRIST = np.array([0, 0, 1.0])
EX2 = np.array([[0, 2, 2], [2, 0, 2], [2, 2, 0]], float)
SPIN_Z = np.array([0, 0, 1.0, 0, 0, 0])


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
    return plot.scene(points, normals, wrist, twist, method=method, **kw)


def grasp_size(points):
    """Longest side of the contact triangle: the unit of the scene's drawn lengths."""
    return float(np.max(screws.norm(points - points[list(J)])))


def distance_to_line(point, segment):
    """Distance from ``point`` to the infinite line carrying ``segment``."""
    d = screws.unit(segment.direction)
    return float(screws.norm(screws.cross(np.asarray(point) - segment.start, d)))


def axes(scene, kind):
    return {s.label: s for s in scene.of_kind(kind)}


# --- geometry ----------------------------------------------------------------


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
        # Example 2: w_i is the i-th coordinate axis (README, "Conventions").
        np.testing.assert_allclose(np.abs(screws.unit(seg.direction)), np.eye(3)[i], atol=1e-12)


def test_axis_segments_are_centred_on_the_foot_from_the_centroid_and_all_as_long():
    sc = make_scene("ex1-off-tangent")
    centroid, size = EX1.mean(axis=0), grasp_size(EX1)
    lengths = []
    for seg in sc.segments:
        mid = (seg.start + seg.end) / 2
        # the midpoint is the foot of the perpendicular from the centroid
        assert abs(screws.dot(centroid - mid, seg.direction)) < 1e-9
        lengths.append(float(screws.norm(seg.direction)))
    assert len(lengths) == 7  # Sigma_i, Psi_i and the twist's axis
    # one length for every axis, "about as long as the grasp" (README), reaching every contact
    np.testing.assert_allclose(lengths, lengths[0], rtol=1e-12)
    assert size < lengths[0] < 2 * size


@pytest.mark.parametrize("case", sorted(CASES))
def test_contact_velocity_arrows_equal_the_engine_and_their_parts_chain_to_them(case):
    points, _, _, twist, _ = CASES[case]
    sc = make_scene(case, names=("a", "b", "c"))
    velocity = sc.of_kind("contact-velocity")
    np.testing.assert_allclose([a.vector for a in velocity], gt.contact_velocities(points, twist), atol=1e-12)
    parts = [a for a in sc.arrows if a.kind.endswith("-part")]
    assert len(parts) == 9  # three per contact
    scale = {a.scale for a in velocity + parts}
    assert len(scale) == 1  # one drawing length per unit velocity for all of them
    # fitted so that the longest chain (or velocity) is 0.45 of the grasp's size
    longest = max(
        max(float(screws.norm(v.vector)) for v in velocity),
        max(sum(float(screws.norm(a.vector)) for a in parts[3 * i : 3 * i + 3]) for i in range(3)),
    )
    assert scale.pop() * longest == pytest.approx(0.45 * grasp_size(points), rel=1e-12)
    for i, v in enumerate(velocity):
        np.testing.assert_array_equal(v.origin, points[i])
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
    assert sc.title.splitlines() == [
        "grasp: T = (0, 0, 1; 0, 0, 0)",
        "off-tangent: x = (0, 0, 0)   y = (-0.471, -0.471, -0.471)",
    ]


def test_tangent_parts_come_from_contact_split():
    points, normals, _, twist, _ = CASES["ex1-tangent"]
    theta_velocity, sigma_velocity = gt.decompose_tangent(points, normals, twist).contact_split()
    sc = make_scene("ex1-tangent")
    parts = {a.label: a.vector for a in sc.arrows if a.kind.endswith("-part")}
    assert len(parts) == 9
    for i in range(3):
        at = f"(p{i + 1})"
        np.testing.assert_allclose(parts[f"β{i + 1} Σ{i + 1}{at}"], sigma_velocity[i])
        for j in (J[i], K[i]):
            np.testing.assert_allclose(parts[f"α{j + 1} Θ{j + 1}{at}"], theta_velocity[i, j])


def test_normals_are_unit_arrows_and_tangent_squares_lie_in_the_tangent_planes():
    points, normals, _, _, _ = CASES["random-tangent"]
    sc = make_scene("random-tangent")
    size = grasp_size(points)
    shown = sc.of_kind("normal")
    np.testing.assert_allclose([a.vector for a in shown], screws.unit(normals), rtol=1e-15)
    assert [a.scale for a in shown] == [pytest.approx(0.25 * size)] * 3
    squares = sc.of_kind("tangent-plane")
    for i, square in enumerate(squares):
        n = screws.unit(normals[i])
        np.testing.assert_allclose(square.corners.mean(axis=0), points[i], atol=1e-12)
        np.testing.assert_allclose(screws.dot(square.corners - points[i], n), 0, atol=1e-12)
        sides = screws.norm(square.corners - square.corners[[1, 2, 3, 0]])
        np.testing.assert_allclose(sides, 0.3 * size, rtol=1e-12)  # a square, half-side 0.15 of the grasp
    (triangle,) = sc.of_kind("contact-plane")
    np.testing.assert_array_equal(triangle.corners, points)


def test_twist_axis_and_pitch():
    twist = screws.screw([0, 0, 2.0], [0.4, -2.0, 1.0])  # axis through (1, 0.2, *) along z, pitch 0.5
    sc = plot.scene(EX1, -EX1, EX1_WRIST, twist)
    (seg,) = sc.of_kind("twist-axis")
    assert distance_to_line([1, 0.2, 5], seg) < 1e-12
    np.testing.assert_allclose(screws.unit(seg.direction), [0, 0, 1], atol=1e-15)
    assert seg.label == "T axis, pitch 0.5"
    (spin,) = plot.scene(EX1, -EX1, EX1_WRIST, SPIN_Z).of_kind("twist-axis")
    assert spin.label == "T axis, pitch 0" and distance_to_line([0, 0, 0], spin) < 1e-15


def test_pure_translation_draws_an_arrow_and_a_far_axis_a_note():
    sc = plot.scene(EX1, -EX1, EX1_WRIST, [0, 0, 0, 0, 0, 3.0])
    (arrow,) = sc.of_kind("twist-translation")
    np.testing.assert_allclose(arrow.vector, [0, 0, 1])
    np.testing.assert_allclose(arrow.origin, EX1.mean(axis=0))
    assert not sc.of_kind("twist-axis")
    far = plot.scene(EX1, -EX1, EX1_WRIST, [0, 0, 0.001, 10, 0, 0])  # axis 10^4 away, through (0, 10^4, *)
    assert not far.of_kind("twist-axis")
    assert "twist axis (pitch 0) passes 1e+04 from the contacts' centroid: not drawn" in far.title.splitlines()


def test_degenerate_grasp_keeps_the_grasp_and_says_why_in_the_title():
    sc = plot.scene(EX1, -EX1, [0.2, 0.1, 0], SPIN_Z, method="off-tangent", names=("thumb", "index", "middle"))
    assert sc.status == Status.WRIST_COPLANAR
    assert sc.title.splitlines()[1] == (
        "off-tangent: degenerate — " + gt.status_message(Status.WRIST_COPLANAR, -1, ("thumb", "index", "middle"))
    )
    assert [s.kind for s in sc.segments] == ["twist-axis"]
    assert not [a for a in sc.arrows if a.kind.endswith("-part")]
    assert [m.label for m in sc.of_kind("contact")] == ["thumb", "index", "middle"]
    assert len(sc.of_kind("contact-velocity")) == 3
    collinear = plot.scene([[0, 0, 0], [1, 0, 0], [2, 0, 0]], np.eye(3), None, None, method="tangent")
    assert collinear.status == Status.COLLINEAR_CONTACTS and "collinear" in collinear.title
    assert not collinear.segments


def test_no_twist_draws_grasp_and_basis_only():
    sc = plot.scene(EX2, np.eye(3), None, None)
    assert sc.method == "tangent"  # the default without a wrist
    assert len(sc.of_kind("theta-axis")) == 3
    assert not [a for a in sc.arrows if a.kind != "normal"]
    assert sc.title == "grasp\ntangent: basis only"


def test_legend_lists_the_drawn_kinds_in_order_and_names_the_methods_amplitudes():
    sc = make_scene("ex1-off-tangent")
    # Example 1b has x = 0: the zero Sigma parts are not drawn, so not in the legend
    assert sc.kinds() == [
        "contact", "wrist", "normal", "tangent-plane", "contact-plane", "sigma-axis", "psi-axis",
        "twist-axis", "contact-velocity", "psi-part",
    ]  # fmt: skip
    assert "sigma-part" in make_scene("ex1-tangent").kinds()
    assert plot.legend_text("sigma-part", "off-tangent") == "part x_i Σ_i(p_i)"
    assert plot.legend_text("sigma-part", "tangent") == "part β_i Σ_i(p_i)"


def test_bounds_hold_every_drawn_point():
    sc = make_scene("random-off-tangent")
    centre, half = sc.bounds()
    drawn = [m.position for m in sc.markers] + [p for s in sc.segments for p in (s.start, s.end)]
    drawn += [p for a in sc.arrows for p in (a.origin, a.tip)] + [c for p in sc.patches for c in p.corners]
    spread = np.abs(np.array(drawn) - centre)
    assert np.all(spread <= half * (1 + 1e-12))
    assert np.max(spread) == pytest.approx(half)  # tight along the widest axis


def test_check_method_picks_the_default_and_refuses_what_cannot_be_drawn():
    assert plot.check_method(None, None) == "tangent"
    assert plot.check_method(None, EX1_WRIST) == "off-tangent"
    assert plot.check_method("tangent", EX1_WRIST) == "tangent"
    with pytest.raises(ValueError, match="the off-tangent method needs a wrist point"):
        plot.scene(EX2, np.eye(3), None, SPIN_Z, method="off-tangent")
    with pytest.raises(ValueError, match="unknown method 'sideways': choose one of off-tangent, tangent"):
        plot.scene(EX2, np.eye(3), None, SPIN_Z, method="sideways")


def test_views_look_down_the_contact_plane_normal_from_the_wrist_side():
    (_, oblique), (_, down) = make_scene("ex1-off-tangent").views
    np.testing.assert_allclose(down, [0, 0, 1], atol=1e-12)
    # a horizontal plane: tilted 50 degrees from the normal, at matplotlib's default azimuth -60
    tilt, azim = np.radians(50), np.radians(-60)
    np.testing.assert_allclose(oblique, [np.sin(tilt) * np.cos(azim), np.sin(tilt) * np.sin(azim), np.cos(tilt)])
    (_, below) = plot.scene(EX1, -EX1, -EX1_WRIST, SPIN_Z).views[1]
    np.testing.assert_allclose(below, [0, 0, -1], atol=1e-12)
    # Example 2's plane x + y + z = 4 seen from the wrist at the origin
    (_, oblique), (_, tilted) = plot.scene(EX2, np.eye(3), [0, 0, 0], None, method="tangent").views
    np.testing.assert_allclose(tilted, -np.ones(3) / np.sqrt(3), atol=1e-12)
    assert screws.dot(oblique, tilted) == pytest.approx(np.cos(tilt))
    assert oblique[2] > 0  # the oblique view leans upwards


# --- file names --------------------------------------------------------------


def test_image_names_are_sanitised_and_a_name_met_twice_gets_a_number():
    assert plot.image_name("a b/c:d") == "a_b_c_d"
    assert plot.image_name("../.hidden", "spin z") == "hidden-spin_z"
    twist = lambda name: Twist(name, SPIN_Z, None)  # noqa: E731
    cylinder = SimpleNamespace(name="cylinder", twists=(twist("spin z"), twist("lift")))
    polyhedron = SimpleNamespace(name="polyhedron", twists=())
    shouting = SimpleNamespace(name="CYLINDER", twists=(twist("Spin z"),))
    plan = plot.image_paths([cylinder, polyhedron, cylinder, shouting], "out", suffix=".svg")
    assert [str(path) for path, _, _ in plan] == [
        "out/cylinder-spin_z.svg",
        "out/cylinder-lift.svg",
        "out/polyhedron.svg",
        "out/cylinder-spin_z-2.svg",
        "out/cylinder-lift-2.svg",
        "out/CYLINDER-Spin_z-3.svg",  # case-insensitive file systems
    ]
    assert [(g.name, t and t.name) for _, g, t in plan][2:4] == [("polyhedron", None), ("cylinder", "spin z")]
    with pytest.raises(ValueError, match="cannot write '.jpg': use one of .png, .svg, .pdf"):
        plot.image_paths([cylinder], "out", suffix=".jpg")


def test_chosen_twist_names_the_twists_there_are():
    grasp = SimpleNamespace(name="g", twists=(Twist("spin", SPIN_Z, 3), Twist("lift", SPIN_Z, 4)))
    assert plot.chosen_twist(grasp).name == "spin" and plot.chosen_twist(grasp, "lift").name == "lift"
    assert plot.chosen_twist(SimpleNamespace(name="g", twists=())) is None
    with pytest.raises(plot.TwistNotFound, match=r"grasp 'g' has no twist 'nope' \(it has: spin, lift\)"):
        plot.chosen_twist(grasp, "nope")


# --- rendering ---------------------------------------------------------------


def test_import_needs_no_matplotlib_and_says_how_to_install_it():
    code = (
        "import sys; sys.modules['matplotlib'] = None\n"
        "import grasptwist.plot as p\n"
        "try:\n    p.require_matplotlib()\nexcept p.MissingMatplotlib as e:\n    print(e)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert (
        out
        == "grasptwist plot needs matplotlib: pip install matplotlib (from a clone of grasptwist: pip install -e '.[plot]')\n"
    )


def test_render_without_matplotlib_raises_missing_matplotlib(monkeypatch, tmp_path):
    monkeypatch.setitem(sys.modules, "matplotlib", None)  # makes `import matplotlib` fail
    with pytest.raises(plot.MissingMatplotlib, match=r"pip install -e '\.\[plot\]'"):
        plot.render(make_scene("ex2-tangent"), tmp_path / "x.png")
    assert not (tmp_path / "x.png").exists()


def test_an_unsupported_format_is_refused_before_drawing(tmp_path):
    with pytest.raises(ValueError, match="cannot write '.jpg': use one of .png, .svg, .pdf"):
        plot.render(make_scene("ex2-tangent"), tmp_path / "x.jpg")
    assert not list(tmp_path.iterdir())


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_one_png_of_the_requested_size_and_one_svg_headless(tmp_path):
    """The smoke test of drawing; what is drawn is checked on the scene above."""
    pytest.importorskip("matplotlib")
    import matplotlib.image

    sc = make_scene("ex1-off-tangent")
    png = plot.render(sc, tmp_path / "g.png", size=(480, 240), dpi=60)
    pixels = matplotlib.image.imread(png)
    assert pixels.shape[:2] == (240, 480)
    assert pixels[..., :3].var() > 0
    svg = plot.render(make_scene("ex2-tangent"), tmp_path / "g.svg", size=(480, 240), dpi=60)
    assert svg.read_text().lstrip().startswith("<?xml") and "<svg" in svg.read_text()


# --- render_loaded: what `grasptwist plot` draws of the grasps it read --------------

GRASP = """\
name: {name}
{wrist}contacts:
  - {{point: [1, 0, 0], normal: [-1, 0, 0]}}
  - {{point: [-0.5, 0.866, 0], normal: [0.5, -0.866, 0]}}
  - {{point: [-0.5, -0.866, 0], normal: [0.5, 0.866, 0.2]}}
"""


def loaded(*paths):
    """The grasps of grasp files, read as the command line reads them."""
    from grasptwist.io.inputs import read

    return [g for p in paths for g in read(str(p))]


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_render_loaded_of_a_folder_reports_what_it_cannot_draw(tmp_path):
    pytest.importorskip("matplotlib")
    folder = tmp_path / "in"
    folder.mkdir()
    (folder / "a.yaml").write_text(GRASP.format(name="good/one", wrist="wrist: [0, 0, 1]\n"))
    (folder / "b.yaml").write_text(GRASP.format(name="no-wrist", wrist=""))
    spin = Twist("spin", SPIN_Z, None)
    grasps = [replace(g, twists=(spin,)) for g in loaded(folder / "a.yaml", folder / "b.yaml")]
    events = list(plot.render_loaded(str(folder), tmp_path / "out", grasps, method="off-tangent"))
    notes = [e for e in events if isinstance(e, plot.Note)]
    assert [n.line.split(": error: ")[0] for n in notes] == [f"{folder / 'b.yaml'}: grasp 'no-wrist'"]
    assert all(n.error for n in notes)
    assert notes[0].line.endswith(
        "error: the off-tangent method needs a wrist point; use --method tangent or add a wrist"
    )
    assert [e for e in events if not isinstance(e, plot.Note)] == [tmp_path / "out" / "good_one-spin.png"]
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["good_one-spin.png"]


def test_render_loaded_of_a_file_warns_of_more_grasps_and_refuses_an_unknown_twist_before_drawing(tmp_path):
    pytest.importorskip("matplotlib")
    sphere = GRASPS / "sphere.yaml"
    events = plot.render_loaded(str(sphere), tmp_path / "s.png", loaded(sphere), twist_name="nope")
    note = next(events)
    assert note == plot.Note(
        f"{GRASPS / 'sphere.yaml'}: warning: drawing the first of its 2 grasps, 'sphere-tripod'", False
    )
    with pytest.raises(plot.TwistNotFound, match="has no twist 'nope' \\(it has: roll-x, spin-z, lift-z\\)"):
        next(events)
    (tmp_path / "w.yaml").write_text(GRASP.format(name="g", wrist=""))
    with pytest.raises(ValueError, match="needs a wrist"):
        w = tmp_path / "w.yaml"
        list(plot.render_loaded(str(w), tmp_path / "w.png", loaded(w), method="off-tangent"))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["w.yaml"]
