"""Finger links against an object (engine/collision.py): depths equal to known overlaps, the culled search
equal to every vertex's, clusters that hold their vertices, links posed by the product of exponentials,
the fingertip sphere's vertices."""

import numpy as np
import pytest

from grasp_gen import rotation
from grasptwist.engine.collision import (
    COLLISION_TOL,
    LinkGeometry,
    clusters,
    collision_tolerance,
    link_poses,
    penetration_depths,
    tip_sphere,
)
from grasptwist.engine.hands import finger_states
from grasptwist.engine.objects import check_object, project_to_surface
from grasptwist.model import GraspObject, Shape


def obj(kind, *size, pose=None, vertices=None, faces=None):
    shape = Shape(kind, np.array(size, dtype=float), vertices, faces)
    return check_object(GraspObject(shape, np.eye(4) if pose is None else pose))


def pose(r=None, t=(0.0, 0.0, 0.0)):
    p = np.eye(4)
    p[:3, :3] = np.eye(3) if r is None else r
    p[:3, 3] = t
    return p


def grid_box(low, high, n=5):
    """The vertices of a box's surface on an ``n``-grid (a link's mesh: flat faces, vertices on them)."""
    axes = [np.linspace(a, b, n) for a, b in zip(low, high)]
    g = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    on_face = np.isclose(g, low).any(axis=1) | np.isclose(g, high).any(axis=1)
    return g[on_face]


def naive(o, vertices, poses):
    """Every vertex through the signed distance: ``(N, L)``."""
    out = np.zeros(poses.shape[:2])
    for k in range(poses.shape[0]):
        for i, v in enumerate(vertices):
            moved = v @ poses[k, i, :3, :3].T + poses[k, i, :3, 3]
            out[k, i] = max(0.0, -project_to_surface(o, moved).distance.min())
    return out


@pytest.mark.parametrize("overlap", [0.0, 0.004, 0.03])
def test_a_flat_link_pushed_into_a_box_is_as_deep_as_it_went(overlap):
    # a 2 x 2 x 1 box; a link's flat bottom face lowered ``overlap`` below its top face z = 0.5
    box = obj("box", 2.0, 2.0, 1.0)
    link = grid_box([-0.2, -0.2, 0.5 - overlap], [0.2, 0.2, 0.9])
    depth = penetration_depths(box, clusters([link], 8), pose()[None, None])
    assert depth[0, 0] == pytest.approx(overlap, abs=1e-15)


def test_the_depth_does_not_depend_on_where_object_and_link_are_put():
    box = obj("box", 2.0, 2.0, 1.0)
    link = grid_box([-0.2, -0.2, 0.496], [0.2, 0.2, 0.9])
    r, t = rotation(np.random.default_rng(3)), np.array([0.3, -1.0, 2.0])
    moved = obj("box", 2.0, 2.0, 1.0, pose=pose(r, t))
    assert penetration_depths(moved, clusters([link], 8), pose(r, t)[None, None])[0, 0] == pytest.approx(
        penetration_depths(box, clusters([link], 8), pose()[None, None])[0, 0], abs=1e-14
    )


def test_a_link_apart_from_the_object_is_zero_deep():
    box = obj("box", 2.0, 2.0, 1.0)
    link = grid_box([-0.2, -0.2, 0.501], [0.2, 0.2, 0.9])
    assert penetration_depths(box, clusters([link], 8), pose()[None, None]).tolist() == [[0.0]]
    assert penetration_depths(box, clusters([]), np.zeros((1, 0, 4, 4))).shape == (1, 0)


@pytest.mark.parametrize(
    "o",
    [
        obj("box", 0.3, 0.2, 0.1),
        obj("sphere", 0.15),
        obj("cylinder", 0.1, 0.3, pose=pose(rotation(np.random.default_rng(1)), (0.02, 0.0, 0.01))),
        obj("capsule", 0.08, 0.2),
        obj(
            "mesh",
            vertices=np.array(
                [[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1], [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]]
            )
            * 0.1,
            faces=np.array(
                [
                    [0, 2, 1],
                    [0, 3, 2],
                    [4, 5, 6],
                    [4, 6, 7],
                    [0, 1, 5],
                    [0, 5, 4],
                    [1, 2, 6],
                    [1, 6, 5],
                    [2, 3, 7],
                    [2, 7, 6],
                    [3, 0, 4],
                    [3, 4, 7],
                ]
            ),  # fmt: skip
        ),
    ],
    ids=["box", "sphere", "cylinder", "capsule", "mesh"],
)
def test_the_culled_search_finds_the_deepest_vertex_of_every_link_exactly(o):
    # clouds of links at random poses about the object: what the culling skips could not be deepest
    if o.shape.kind == "mesh":
        pytest.importorskip("igl")
    rng = np.random.default_rng(7)
    links = [rng.normal(0.0, 0.05, (n, 3)) + rng.uniform(-0.1, 0.1, 3) for n in (50, 200, 9)]
    poses = np.stack([[pose(rotation(rng), rng.uniform(-0.15, 0.15, 3)) for _ in links] for _ in range(12)])
    got = penetration_depths(o, clusters(links, 16), poses)
    # the same vertex's depth, to round-off (the vertices are posed by a composed transform here)
    np.testing.assert_allclose(got, naive(o, links, poses), rtol=0, atol=1e-15)
    assert 0.2 < np.mean(got > 0) < 1.0  # some inside, some apart: both ways are tried


def test_clusters_hold_each_links_vertices_in_their_balls():
    rng = np.random.default_rng(0)
    links = [rng.normal(size=(100, 3)), rng.normal(size=(7, 3)), np.zeros((0, 3))]
    c = clusters(links, 16)
    for i, v in enumerate(links):
        mine = c.link == i
        held = c.vertices[mine].reshape(-1, 3)
        assert {tuple(p) for p in held} == {tuple(p) for p in v}  # each vertex, nothing else (padding repeats)
        distance = np.linalg.norm(c.vertices[mine] - c.center[mine, None], axis=-1)
        assert (distance <= c.radius[mine, None] + 1e-15).all()
    assert np.bincount(c.link).tolist() == [8, 1]  # 100 vertices halved three times: 8 of 12 or 13


def test_links_move_with_the_first_joints_of_their_finger(trifinger):
    hand, q = trifinger
    # a link moved by all of finger 2's joints is where the tip pose goes, one moved by its first by that joint only
    geometry = [LinkGeometry(1, "tip", 3, np.zeros((1, 3)), np.zeros((0, 3), int))]
    geometry.append(LinkGeometry(1, "upper", 1, np.zeros((1, 3)), np.zeros((0, 3), int)))
    poses = link_poses(hand, geometry, q[None])
    finger = hand.fingers[1]
    assert poses[0, 0] @ finger.tip_pose == pytest.approx(finger_states(hand, q)[1].tip, abs=1e-15)
    first = q[finger.joint_index[0]]
    one = np.where(np.arange(len(q)) == finger.joint_index[0], first, 0.0)
    assert poses[0, 1] @ finger.tip_pose == pytest.approx(finger_states(hand, one)[1].tip, abs=1e-15)
    # seen from an object moved by P, the link is where P^-1 puts it
    p = pose(rotation(np.random.default_rng(2)), (0.1, 0.2, 0.3))
    seen = link_poses(hand, geometry, q[None], p[None])
    assert seen[0] == pytest.approx(np.linalg.inv(p) @ poses[0], abs=1e-14)


def test_the_fingertip_sphere_is_its_vertices_within_its_radius_and_the_tolerance():
    v = np.array([[0, 0, 0.01], [0, 0.0101, 0], [0, 0, 0.0102], [0, 0, 0.02]])
    assert tip_sphere(v, [0, 0, 0], 0.01, 1.5e-4).tolist() == [True, True, False, False]
    assert tip_sphere(v, [0, 0, 0], 0.0, 1.5e-4).tolist() == [False] * 4  # a point tip has no sphere
    assert collision_tolerance(obj("box", 0.065, 0.065, 0.065)) == pytest.approx(COLLISION_TOL * 0.065 * 3**0.5)


@pytest.fixture
def trifinger():
    pytest.importorskip("yourdfpy")
    pytest.importorskip("robot_properties_fingers")
    import grasptwist as gt

    (g,) = gt.read_grasps("grasps/trifinger-cube.yaml")
    return g.hand, np.asarray(g.joint_positions)
