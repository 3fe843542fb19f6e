"""plot draws the friction cones and the grip forces (issue 19): geometry, not pixels."""

import numpy as np
import pytest

import grasptwist as gt
from grasptwist.io.grasp import load_grasps
from grasptwist.plot.scene import force_parts, grasp_scene
from grasptwist.plot.traces import force_traces, scene_traces
from grasptwist.run.pictures import grip_forces as _grip_forces

P = np.array([[1.0, 0, 0], [-0.5, 0.75**0.5, 0], [-0.5, -(0.75**0.5), 0]])


def equator():
    (g,) = [g for g in load_grasps("grasps/sphere.yaml") if g.name == "sphere-equator"]
    return g


@pytest.mark.parametrize("mu", [[0.5, 0.5, 0.5], [0.2, 1.0, 3.0]])
def test_each_cone_has_its_apex_at_the_contact_its_axis_along_the_normal_and_half_angle_atan_mu(mu):
    normals = np.array([[-1.0, 0.2, 0.3], [0.4, -0.9, 0.1], [0.5, 0.8, -0.2]])  # any lengths
    cones, _ = force_parts(P, 2 * normals, mu)
    assert [c.kind for c in cones] == ["friction-cone"] * 3
    for i, c in enumerate(cones):
        apex, rim = c.corners[0], c.corners[1:]
        np.testing.assert_allclose(apex, P[i], atol=1e-15)
        side = rim - apex
        n = normals[i] / np.linalg.norm(normals[i])
        along = side @ n
        across = np.linalg.norm(side - along[:, None] * n, axis=1)
        assert (along > 0).all()  # opens into the object, where the finger's force points
        np.testing.assert_allclose(np.arctan2(across, along), np.arctan(mu[i]), atol=1e-12)
        np.testing.assert_allclose(
            (rim[:-1] - apex).mean(axis=0) / np.linalg.norm((rim[:-1] - apex).mean(axis=0)), n, atol=1e-12
        )


def test_no_cone_for_a_frictionless_or_unlimited_contact():
    cones, arrows = force_parts(P, -P, [0.0, np.inf, 0.5])
    assert len(cones) == 1 and cones[0].label.startswith("cone") and arrows == ()


def test_the_force_arrows_are_the_engines_grip_forces():
    g = equator()
    forces = _grip_forces(g)
    hold = {w.name: w.wrench for w in g.wrenches}["hold"]
    expected = gt.forces.grip(g.points, g.normals, hold, g.friction).force
    picture = grasp_scene(g, forces=forces)
    arrows = picture.of_kind("grip-force")
    assert [a.origin.tolist() for a in arrows] == g.points.tolist()
    np.testing.assert_allclose([a.vector for a in arrows], expected, rtol=1e-12)
    # the ball's weight, m g / 3 by friction at each finger, pressed with m g / (3 mu)
    np.testing.assert_allclose([a.vector[2] for a in arrows], 9.81 / 3, rtol=1e-9)
    np.testing.assert_allclose(gt.forces.grip(g.points, g.normals, hold, 0.5).normal_force, 9.81 / 1.5, rtol=1e-9)


def test_force_traces_draw_the_cones_and_forces_and_scene_traces_leave_them_out():
    g = equator()
    picture = grasp_scene(g, forces=_grip_forces(g))
    traces = force_traces(picture, "m")
    assert list(traces) == ["friction cone (half-angle atan μ_i)", "grip force f_i"]
    (mesh,) = traces["friction cone (half-angle atan μ_i)"]
    assert mesh["type"] == "mesh3d" and len(mesh["i"]) == 3 * 24  # a fan of 24 triangles per cone
    shafts, heads = traces["grip force f_i"]
    assert shafts["x"][0] == pytest.approx(g.points[0, 0]) and heads["type"] == "cone"
    assert not any("friction" in k or "grip" in k for k in scene_traces(picture, "m"))
    bare = grasp_scene(load_grasps("grasps/sphere.yaml")[0])  # the tripod: no friction given
    assert force_traces(bare, "m") == {} and not bare.of_kind("friction-cone")


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_plot_draws_a_grasp_with_friction(tmp_path):
    pytest.importorskip("matplotlib")
    from grasptwist.plot.render import plot_grasp

    g = equator()
    out = plot_grasp(g, tmp_path / "equator.png", forces=_grip_forces(g), size=(600, 300))
    assert out.stat().st_size > 0


BOX = """\
name: box-on-fingertips
units: m
contacts:
  - {name: a, point: [0.1, 0, 0], normal: [0, 0, 1]}
  - {name: b, point: [-0.05, 0.0866025, 0], normal: [0, 0, 1]}
  - {name: c, point: [-0.05, -0.0866025, 0], normal: [0, 0, 1]}
friction: 0.8
mass: 0.5
center_of_mass: [0, 0, 0.2]
paths:
  - name: tilt
    segments:
      - angular: [0, 1, 0]
        duration: 6.283185307179586
"""


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_the_animation_draws_each_samples_grip_and_marks_where_the_weight_cannot_be_held():
    from grasptwist.plot.animation import path_figure
    from grasptwist.run.pictures import page_extras as _page_extras

    (g,) = load_grasps(BOX, file="box.yaml")
    _, followed, _ = _page_extras(None)(g)
    ((chunks, summary),) = followed
    figure = path_figure(g, chunks, summary)
    times = np.concatenate([c.poses.time for c in chunks])
    force = np.concatenate([c.grip.force for c in chunks])
    points = np.concatenate([c.block.points for c in chunks])  # moved with the box
    held = ~((times >= np.arctan(0.5)) & (times <= 2 * np.pi - np.arctan(0.25)))
    assert held.any() and not held.all()
    labels = [s["label"] for s in figure["layout"]["sliders"][0]["steps"]]
    assert [label.startswith("✗") for label in labels] == (~held).tolist()
    assert "cannot hold the weight: t in [0.4636, 6.038]" in figure["layout"]["annotations"][0]["text"]
    for k, frame in enumerate(figure["frames"]):
        shafts = [t for t in frame["data"] if t.get("name") == "grip force f_i" and t["type"] == "scatter3d"]
        (shaft,) = shafts
        if not held[k]:
            assert shaft["x"] == [] and "cannot hold the weight" in frame["layout"]["title"]["text"]
            continue
        # each shaft runs from the contact along the engine's force (drawn to a common length)
        starts = np.array([shaft[c][0::3] for c in "xyz"]).T
        ends = np.array([shaft[c][1::3] for c in "xyz"]).T
        np.testing.assert_allclose(starts, points[k])
        drawn = ends - starts
        np.testing.assert_allclose(np.cross(drawn, force[k]), 0, atol=1e-12)
        assert (np.einsum("ij,ij->i", drawn, force[k]) > 0).all()
