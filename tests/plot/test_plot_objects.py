"""Pictures of the object (issue 30, item 6): the object's triangles and the fingertip spheres in the
scene, the picture framed on them and the contacts (a far wrist an arrow at the edge), the object
carried along a path's animation, and both drawings (PNG, HTML) of them."""

from dataclasses import replace

import numpy as np
import pytest

from grasptwist import plot
from grasptwist.engine.objects import tessellate
from grasptwist.io.grasp import load_grasps
from grasptwist.model import GraspObject, Shape
from grasptwist.plot.scene import REACH, clip_segment, cube_of, edge_arrow, framed, reach_box
from places import GRASPS

BALL = 0.035  # sphere.yaml's ball, centred at the origin


def with_object(grasp, kind, size, position=(0, 0, 0), rotation=None):
    pose = np.eye(4)
    pose[:3, 3] = position
    if rotation is not None:
        pose[:3, :3] = rotation
    return replace(grasp, object=GraspObject(Shape(kind, np.array(size, dtype=float)), pose))


def sphere_tripod(wrist=None):
    grasp = with_object(load_grasps(GRASPS / "sphere.yaml")[0], "sphere", [BALL])
    return grasp if wrist is None else replace(grasp, wrist=np.array(wrist, dtype=float))


def three_finger_hand(radii=(0.1, 0.0, 0.2)):
    grasp = load_grasps(GRASPS / "three-finger-hand.yaml")[0]
    fingers = tuple(replace(f, tip_radius=r) for f, r in zip(grasp.hand.fingers, radii))
    # without its box: the framing below is the contacts' and the tips' alone
    return replace(grasp, object=None, hand=replace(grasp.hand, fingers=fingers))


def fill(picture, subject_half):
    """How much of the picture's width the subject spans (1: all of it)."""
    return subject_half / picture.bounds()[1]


def test_the_scene_holds_the_objects_triangles_in_the_grasp_frame():
    turn = np.array([[0, -1, 0], [1, 0, 0], [0, 0, 1.0]])  # a quarter turn about z
    grasp = with_object(load_grasps(GRASPS / "box-edge.yaml")[0], "box", [0.1, 0.06, 0.04], (0.2, 0, 0.02), turn)
    (mesh,) = plot.grasp_scene(grasp).meshes
    assert mesh.kind == "object" and mesh.faces.shape == (12, 3) and len(mesh.vertices) == 8
    # the 0.1 edge along x turned onto y, centred at the pose's position
    np.testing.assert_allclose(mesh.vertices.min(axis=0), [0.17, -0.05, 0.0], atol=1e-15)
    np.testing.assert_allclose(mesh.vertices.max(axis=0), [0.23, 0.05, 0.04], atol=1e-15)
    (ball,) = plot.grasp_scene(sphere_tripod()).meshes
    vertices, faces = tessellate(sphere_tripod().object)
    assert np.array_equal(ball.vertices, vertices) and np.array_equal(ball.faces, faces)
    assert np.linalg.norm(ball.vertices, axis=1) == pytest.approx(BALL, rel=1e-12)  # on the exact sphere
    assert "object" in plot.grasp_scene(sphere_tripod()).kinds() and not plot.grasp_scene(grasp).spheres


def test_fingertip_spheres_touch_the_contacts_from_outside():
    grasp = three_finger_hand()
    picture = plot.grasp_scene(grasp)
    tips = picture.spheres
    assert [t.label for t in tips] == ["tip 1", "tip 3"]  # the finger without a radius has none
    assert [t.radius for t in tips] == [0.1, 0.2]
    unit = grasp.normals / np.linalg.norm(grasp.normals, axis=1, keepdims=True)
    for tip, i, r in zip(tips, (0, 2), (0.1, 0.2)):
        np.testing.assert_allclose(tip.centre, grasp.points[i] - r * unit[i], atol=1e-15)
    vertices, _ = tips[1].triangles()
    assert np.linalg.norm(vertices - tips[1].centre, axis=1) == pytest.approx(0.2, rel=1e-12)
    # the west and south fingers start within the picture; the east finger's knuckle, 2 above
    # its contact, and the wrist 3 up are beyond it: arrows at its edge
    assert [m.label for m in picture.of_kind("hand-base")] == ["base 2", "base 3"]
    np.testing.assert_allclose(picture.of_kind("hand-base")[0].position, [-2.0, -0.2, 1.9])
    assert [a.label.split(" (")[0] for a in picture.of_kind("beyond")] == ["c", "base 1"]
    assert not plot.grasp_scene(three_finger_hand((0, 0, 0))).spheres


def test_the_picture_frames_the_ball_and_points_at_the_far_wrist():
    near, far = plot.grasp_scene(sphere_tripod()), plot.grasp_scene(sphere_tripod([0, 0.05, 10.0]))
    # sphere.yaml's wrist 0.11 above the ball's centre, and one 10 away
    for picture, wrist in ((near, np.array([0, 0, 0.11])), (far, np.array([0, 0.05, 10.0]))):
        assert not picture.of_kind("wrist")
        (arrow,) = picture.of_kind("beyond")
        centre, half = picture.bounds()
        assert fill(picture, BALL) >= 1 / REACH
        # the arrow points from the picture's centre at the wrist, its tip just inside the edge
        np.testing.assert_allclose(arrow.vector, (wrist - centre) / np.linalg.norm(wrist - centre), atol=1e-15)
        assert 0.97 * half <= np.max(np.abs(arrow.tip - centre)) < half
        assert arrow.label == f"c ({np.linalg.norm(wrist - centre):.3g} away)"
    assert far.of_kind("beyond")[0].label == "c (10 away)"
    # every drawn point inside the picture, which is as wide as the ball and its arrows need
    for picture in (near, far):
        centre, half = picture.bounds()
        assert np.all(np.abs(picture.points() - centre) <= half * (1 + 1e-12))
    # a wrist 10 away frames the ball as one 0.11 away does (a cube reaching it would be 100 times wider)
    assert near.bounds()[1] == pytest.approx(far.bounds()[1], rel=0.05)


def test_far_points_at_one_place_share_an_arrow():
    # the TriFinger's three fingers start where its wrist is, 0.29 above the table (one 1 mm off)
    contacts = [plot.Marker(np.array(p), n, "contact") for p, n in (([0.03, 0, 0], "1"), ([-0.03, 0, 0], "2"))]
    far = [plot.Marker(np.array([0, 0, 0.29]), n, k) for n, k in (("c", "wrist"), ("base 1", "hand-base"))]
    far += [plot.Marker(np.array([0, 0.001, 0.29]), "base 2", "hand-base")]
    picture = framed(plot.Scene("t", "tangent", 0, markers=(*contacts, *far)))
    (arrow,) = picture.of_kind("beyond")
    assert arrow.label == "c, base 1, base 2 (0.29 away)"
    np.testing.assert_allclose(arrow.vector, [0, 0, 1])


def test_a_near_wrist_stays_a_point_of_the_picture():
    grasp = sphere_tripod([0, 0, 0.05])  # within REACH ball radii of the centre
    picture = plot.grasp_scene(grasp)
    assert [m.label for m in picture.of_kind("wrist")] == ["c"] and not picture.of_kind("beyond")
    assert fill(picture, BALL) >= 1 / REACH


def test_reach_box_clip_and_edge_arrow_on_numbers():
    centre, half = reach_box([[0, 0, 0], [0.06, 0.02, 0.0], [0.03, 0.01, 0.01]])
    np.testing.assert_allclose(centre, [0.03, 0.01, 0.005])
    assert half == pytest.approx(REACH * 0.03)
    assert cube_of([[1.0, 2.0, 3.0]])[1] == 1.0  # a point: a unit cube about it
    c, h = np.zeros(3), 1.0
    a, b = clip_segment([0.5, 0, 0], [0.5, 0, 5.0], c, h)  # from inside out through the top face
    np.testing.assert_allclose([a, b], [[0.5, 0, 0], [0.5, 0, 1.0]])
    a, b = clip_segment([-3, -3, 0.2], [3, 3, 0.2], c, h)  # through the cube, both ends outside
    np.testing.assert_allclose([a, b], [[-1, -1, 0.2], [1, 1, 0.2]])
    a, b = clip_segment([0.1, 0.2, 0.3], [0.2, 0.1, 0.0], c, h)  # wholly inside: itself
    np.testing.assert_allclose([a, b], [[0.1, 0.2, 0.3], [0.2, 0.1, 0.0]])
    assert clip_segment([2, 0, 0], [2, 0, 5], c, h) is None  # beside it, parallel to a face
    assert clip_segment([1.5, 0.8, 0], [0.8, 1.5, 0], c, h) is None  # past a corner
    origin, d, length = edge_arrow(np.array([1.0, 1, 1]), 2.0, [1.0, 1 + 30, 1 + 40])
    np.testing.assert_allclose(d, [0, 0.6, 0.8])
    # the ray leaves the cube through z = 3 at t = 2 / 0.8; the tip sits 0.04 before
    np.testing.assert_allclose(origin + length * d, np.array([1.0, 1, 1]) + (2.5 - 0.04) * d)
    assert length == 0.5


def test_a_given_extent_cuts_the_same_picture_to_it():
    picture = plot.grasp_scene(three_finger_hand(), links=True)
    centre, half = picture.bounds()
    small = framed(replace(picture, extent=None), extent=(centre, 0.5 * half))
    assert small.bounds() == (centre, 0.5 * half)
    inside = np.abs(np.array([p for s in small.segments for p in (s.start, s.end)]) - centre)
    assert np.all(inside <= 0.5 * half * (1 + 1e-12))


def test_the_animation_carries_the_object_with_the_path():
    from grasptwist.plot.animation import path_figure
    from grasptwist.run.follow import Samples, Summary, follow_grasp
    from grasptwist.run.options import FollowOptions

    # the paper's cylinder (contacts on the unit circle z = 0) half-turned about x
    grasp = with_object(load_grasps(GRASPS / "cylinder.yaml")[0], "cylinder", [1.0, 0.5])
    out = list(follow_grasp(FollowOptions(path="turn-x", samples=5, bases=False), grasp))
    chunks = [c for c in out if isinstance(c, Samples)]
    (summary,) = [s for s in out if isinstance(s, Summary)]
    figure = path_figure(grasp, chunks, summary)
    slot = next(n for n, t in enumerate(figure["data"]) if t["name"] == "object")
    vertices, _ = tessellate(grasp.object)
    half = figure["layout"]["scene"]["xaxis"]["range"][1] - figure["layout"]["scene"]["xaxis"]["range"][0]
    poses = chunks[0].poses
    assert len(figure["frames"]) == 5
    for k, frame in enumerate(figure["frames"]):
        trace = frame["data"][slot]
        shown = np.array([trace[c] for c in "xyz"]).T
        carried = vertices @ poses.rotation[k].T + poses.position[k]  # pose @ vertex
        np.testing.assert_allclose(shown, carried, atol=1e-6 * half)
        assert trace["i"] == figure["data"][slot]["i"]
    # at t = pi/2 the cylinder's axis lies along -y
    np.testing.assert_allclose(poses.rotation[2] @ [0, 0, 1], [0, -1, 0], atol=1e-12)


def test_the_html_figure_holds_the_object_and_tips_and_frames_them():
    pytest.importorskip("plotly")
    grasp = replace(three_finger_hand(), object=sphere_tripod().object)
    figure = plot.twist_figure(grasp)
    (obj,) = [t for t in figure["data"] if t["name"] == "object" and t.get("visible", True) is True]
    assert obj["type"] == "mesh3d" and obj["opacity"] < 1  # translucent
    vertices, faces = tessellate(grasp.object)
    assert len(obj["i"]) == len(faces)
    np.testing.assert_allclose(np.array([obj[c] for c in "xyz"]).T, vertices, atol=1e-5)  # rounded to 1e-6 of 3
    (tips,) = [t for t in figure["data"] if t["name"] == "fingertip sphere" and t.get("visible", True) is True]
    assert len(tips["x"]) == 2 * len(plot.grasp_scene(grasp).spheres[0].triangles()[0])
    ranges = np.array([figure["layout"]["scene"][f"{c}axis"]["range"] for c in "xyz"])
    assert figure["layout"]["scene"]["aspectmode"] == "cube"
    assert np.all(ranges[:, 0] <= vertices.min(axis=0)) and np.all(ranges[:, 1] >= vertices.max(axis=0))
    # the same object with every twist: one trace, shown by every twist's button
    figure = plot.twist_figure(sphere_tripod())
    (slot,) = [n for n, t in enumerate(figure["data"]) if t["name"] == "object"]
    buttons = figure["layout"]["updatemenus"][0]["buttons"]
    assert len(buttons) == 3 and all(b["args"][0]["visible"][slot] is True for b in buttons)


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_a_png_of_the_object_and_tips_is_written(tmp_path):
    pytest.importorskip("matplotlib")
    image = pytest.importorskip("PIL.Image")
    grasp = replace(three_finger_hand(), object=GraspObject(Shape("box", np.array([2.0, 2.0, 1.0])), np.eye(4)))
    out = plot.plot_grasp(grasp, tmp_path / "hand.png", size=(500, 250))
    with image.open(out) as png:
        assert png.size == (500, 250)
        rgb = np.asarray(png.convert("RGB"), dtype=int)
    # matplotlib's "tan" object, shaded and translucent: pixels with red well over blue
    assert np.sum((rgb[..., 0] - rgb[..., 2] > 40) & (rgb[..., 0] > 150)) > 500


def _layout(fig):
    """The drawn figure's text boxes (display pixels) by what they are: the legend, each panel's
    title, and per panel and axis its axis name and the tick labels within its limits."""
    renderer = fig.canvas.get_renderer()
    fig.draw_without_rendering()
    out = {"legend": [fig.legends[0].get_window_extent(renderer)]}
    for k, ax in enumerate(fig.axes):
        out[f"title {k}"] = [ax.title.get_window_extent(renderer)]
        for name, axis in zip("xyz", (ax.xaxis, ax.yaxis, ax.zaxis)):
            lo, hi = sorted(getattr(ax, f"get_{name}lim")())
            labels = zip(axis.get_ticklabels(), axis.get_majorticklocs())
            out[f"{name} ticks {k}"] = [
                t.get_window_extent(renderer) for t, v in labels if t.get_text() and lo <= v <= hi
            ]
            if axis.label.get_text():
                out[f"{name} name {k}"] = [axis.label.get_window_extent(renderer)]
    return out


def _overprinted(layout):
    """Pairs of boxes that overlap: the legend or a title with anything, an axis's tick labels
    with each other or with its name (tick labels of two axes meeting at a corner of the
    cube are matplotlib's 3D layout, not counted)."""
    found = set()
    keys = list(layout)
    for i, a in enumerate(keys):
        for b in keys[i:]:
            same_axis = a.split()[0] == b.split()[0] and a.split()[-1] == b.split()[-1]
            if not ({"legend", "title"} & {a.split()[0], b.split()[0]} or same_axis):
                continue
            for m, x in enumerate(layout[a]):
                for n, y in enumerate(layout[b]):
                    if (a != b or n > m) and x.overlaps(y):
                        found.add((a, b))
    return found


def test_the_pngs_axes_have_few_ticks_and_its_legend_one_object():
    """Without drawing (fast): at most TICKS + 1 ticks on each axis within its limits (the bottle's
    x ticks ran together), one legend entry per kind, the object's among them."""
    pytest.importorskip("matplotlib")
    from grasptwist.plot.render import TICKS, figure
    from grasptwist.plot.scene import grasp_scene

    (g,) = load_grasps(GRASPS / "box-edge.yaml")
    fig = figure(grasp_scene(g, g.twists[0]))
    for ax in fig.axes:
        for name, axis in zip("xyz", (ax.xaxis, ax.yaxis, ax.zaxis)):
            lo, hi = sorted(getattr(ax, f"get_{name}lim")())
            assert 2 <= sum(lo <= v <= hi for v in axis.get_majorticklocs()) <= TICKS + 1
    legend = [t.get_text() for t in fig.legends[0].get_texts()]
    assert legend.count("object") == 1 and len(set(legend)) == len(legend) == 12


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
@pytest.mark.parametrize("name", ["box-edge.yaml", "bottle.yaml", "handle.yaml", "trifinger-cube.yaml"])
def test_the_pngs_text_does_not_overprint(name):
    """Issue 30's user: down the contact-plane normal the bottle's x tick labels ran together and
    the y name sat on the panel's title; with a box the legend was printed over tick labels."""
    pytest.importorskip("matplotlib")
    from grasptwist.plot.render import figure
    from grasptwist.plot.scene import grasp_scene

    (g,) = load_grasps(GRASPS / name)
    assert _overprinted(_layout(figure(grasp_scene(g, g.twists[0])))) == set()
