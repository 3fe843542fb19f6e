"""A file of several grasps of one object, as ``synthesize -o`` writes it: ``plot`` draws the
object once with every grasp's contacts and normals, each grasp in its own colour and named in
the legend, as a PNG and as an HTML page (issue 31)."""

import numpy as np
import pytest
from typer.testing import CliRunner

from grasptwist.cli import app
from grasptwist.io.grasp import load_grasps
from grasptwist.plot import grasps_figure, grasps_scene, read_figures
from grasptwist.plot.scene import GRASP_COLOURS, Arrow, Marker
from grasptwist.run.pictures import drawn_together
from places import GRASPS

BALL = 0.035
# each grasp's contacts by (latitude, longitude) in degrees, on the ball centred at the origin
ANGLES = ((-30, 0, 120, -30, 240, -30), (-40, 30, 150, 20, 270, -40), (0, 90, 210, -50, 330, -50))


def found_text(radius=BALL, last_radius=BALL) -> str:
    """Three documents on one ball (the last's radius may differ), no twists, as synthesize writes them."""
    documents = []
    for k, (la1, lo1, lo2, la2, lo3, la3) in enumerate(ANGLES):
        r = radius if k < 2 else last_radius
        contacts = []
        for name, lat, lon in (("thumb", la1, lo1), ("index", la2, lo2), ("middle", la3, lo3)):
            lat, lon = np.radians(lat), np.radians(lon)
            u = np.array([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)])
            contacts.append(f"- name: {name}\n  point: {(r * u).tolist()}\n  normal: {(-u).tolist()}")
        documents.append(
            f"name: ball-{k + 1}\nunits: m\nwrist: [0.0, 0.0, 0.11]\nobject: {{sphere: {r}}}\n"
            "contacts:\n" + "\n".join(contacts) + "\nfriction: 0.5\nmass: 1.0\ncenter_of_mass: [0, 0, 0]\n"
        )
    return "---\n".join(documents)


@pytest.fixture
def found(tmp_path):
    path = tmp_path / "found.yaml"
    path.write_text(found_text())
    return path


def test_the_scene_holds_each_grasps_contacts_and_one_object(found):
    grasps = load_grasps(found)
    scene = grasps_scene(grasps)
    assert len(scene.meshes) == 1 and scene.meshes[0].label == "sphere"
    assert scene.groups == ("1: ball-1", "2: ball-2", "3: ball-3")
    for k, grasp in enumerate(grasps):
        own = scene.of_group(k)
        markers = [e for e in own if isinstance(e, Marker)]
        arrows = [e for e in own if isinstance(e, Arrow)]
        assert [m.label for m in markers] == [f"{k + 1} thumb", f"{k + 1} index", f"{k + 1} middle"]
        assert np.allclose([m.position for m in markers], grasp.points, rtol=0, atol=1e-15)
        assert [a.kind for a in arrows] == ["normal"] * 3
        assert np.allclose([a.vector for a in arrows], grasp.normals, rtol=0, atol=1e-12)
        # each normal drawn into the ball from its contact, its tip still inside
        assert all(np.linalg.norm(a.tip) < BALL for a in arrows)
    assert len(scene.of_kind("contact")) == 9 and scene.kinds() == ["object"]  # the legend names the grasps
    # framed by the existing rule: everything lies inside the ball, so the cube is the ball's
    centre, half = scene.bounds()
    assert np.allclose(centre, 0, atol=1e-12) and half == pytest.approx(BALL, rel=1e-12)
    assert scene.title == "3 grasps of one sphere: ball-1 to ball-3"


def test_which_files_documents_go_together(tmp_path, found):
    grasps = load_grasps(found)
    assert drawn_together(str(found), grasps, asked=False)
    assert not drawn_together(str(found), grasps, asked=True)  # a twist, method or path asked: the first
    assert not drawn_together(str(found), grasps[:1], asked=False)
    assert not drawn_together(str(tmp_path), grasps, asked=False)  # a folder: one picture per grasp
    sphere = GRASPS / "sphere.yaml"  # one ball, but grasps with twists to draw: the first, as before
    assert not drawn_together(str(sphere), load_grasps(sphere), asked=False)
    other = tmp_path / "other.yaml"
    other.write_text(found_text(last_radius=0.04))  # the last document's ball is another
    assert not drawn_together(str(other), load_grasps(other), asked=False)


def test_the_html_figure_has_one_legend_entry_per_grasp_in_its_colour(found):
    grasps = load_grasps(found)
    figure = grasps_figure(grasps)
    legend = [(t["name"], t["type"]) for t in figure["data"] if t.get("showlegend")]
    assert legend == [
        ("object", "mesh3d"),
        ("1: ball-1", "scatter3d"),
        ("2: ball-2", "scatter3d"),
        ("3: ball-3", "scatter3d"),
    ]
    for k, grasp in enumerate(grasps):
        markers, shafts = [
            t for t in figure["data"] if t["name"] == f"{k + 1}: ball-{k + 1}" and t["type"] == "scatter3d"
        ]
        assert markers["marker"]["color"] == shafts["line"]["color"] == GRASP_COLOURS[k]
        assert np.allclose(np.transpose([markers["x"], markers["y"], markers["z"]]), grasp.points, atol=1e-15)
        assert markers["text"] == [f"{k + 1} thumb", f"{k + 1} index", f"{k + 1} middle"]
    assert len(set(GRASP_COLOURS[:3])) == 3
    axis = figure["layout"]["scene"]["xaxis"]["range"]
    assert axis == pytest.approx([-BALL, BALL], rel=1e-12)


def test_plot_writes_one_page_of_them_all_without_a_warning(tmp_path, found):
    pytest.importorskip("plotly")
    out = tmp_path / "found.html"
    r = CliRunner().invoke(app, ["plot", str(found), "-o", str(out), "--js-beside"])
    assert r.exit_code == 0, r.output
    assert r.stdout == f"{out}\n" and r.stderr == ""
    (figure,) = read_figures(out.read_text("utf-8"))
    names = [t["name"] for t in figure["data"] if t.get("showlegend")]
    assert names == ["object", "1: ball-1", "2: ball-2", "3: ball-3"]


def test_the_pngs_legend_names_each_grasp_in_its_colour(found):
    pytest.importorskip("matplotlib")
    from matplotlib.colors import to_hex

    from grasptwist.plot.render import figure

    fig = figure(grasps_scene(load_grasps(found)))
    legend = fig.legends[0]
    assert [t.get_text() for t in legend.get_texts()] == ["object", "1: ball-1", "2: ball-2", "3: ball-3"]
    assert [to_hex(h.get_color()) for h in legend.legend_handles[1:]] == list(GRASP_COLOURS[:3])


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_plot_writes_one_png_of_them_all_without_a_warning(tmp_path, found):
    pytest.importorskip("matplotlib")
    image = pytest.importorskip("PIL.Image")
    out = tmp_path / "found.png"
    r = CliRunner().invoke(app, ["plot", str(found), "-o", str(out)])
    assert r.exit_code == 0, r.output
    assert r.stdout == f"{out}\n" and r.stderr == ""  # 0.5.0: "drawing the first of its 3 grasps"
    with image.open(out) as png:
        assert png.size == (1400, 700)
        rgb = np.asarray(png.convert("RGB"), dtype=int)
    for colour in GRASP_COLOURS[:3]:  # each grasp's dots, arrows and labels in its own colour
        want = np.array([int(colour[i : i + 2], 16) for i in (1, 3, 5)])
        assert np.sum(np.abs(rgb - want).max(axis=2) < 8) > 50
