"""The world around the object and the fingers against each other (issue 37, items 1-2): signed distances
of the table and of boxes in closed form, a fingertip sphere's clearance exact, two overlapping fingertip
spheres' depth exact, a link through a box reported with its depth, hulls of links into each other, and
the search's hand and contacts kept clear of a table."""

import numpy as np
import pytest

from grasptwist.engine.collision import (
    LinkGeometry,
    clusters,
    convex_planes,
    finger_overlaps,
    hull_depth,
    link_hulls,
)
from grasptwist.engine.environment import (
    CLEARANCE,
    TABLE,
    box_distance,
    clearance_of,
    environment_distance,
    parts_distance,
    sphere_distance,
)
from grasptwist.engine.synthesis.clearance import clear_contacts, grasp_clearance
from grasptwist.engine.synthesis.search import synthesize
from grasptwist.model import Environment, GraspObject, Obstacle, Shape

NO_FACES = np.zeros((0, 3), int)


def pose(position, angle=0.0):
    """A pose turned by ``angle`` about z, at ``position``."""
    c, s = np.cos(angle), np.sin(angle)
    out = np.eye(4)
    out[:3, :3] = [[c, -s, 0], [s, c, 0], [0, 0, 1]]
    out[:3, 3] = position
    return out


def cube_link(finger, name, centre, half):
    """A link that is an axis-aligned cube of half size ``half`` about ``centre`` (its 8 corners)."""
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float) * half + centre
    return LinkGeometry(finger, name, 1, corners, NO_FACES)


def test_box_distance_is_the_closed_form_inside_at_a_face_edge_and_corner_and_turns_with_the_box():
    size = [2.0, 4.0, 6.0]  # half sizes 1, 2, 3
    p = [[0, 0, 0], [0.5, 0, 0], [3, 0, 0], [2, 3, 0], [2, 3, 5]]
    assert box_distance(p, size, np.eye(4)) == pytest.approx([-1, -0.5, 2, np.sqrt(2), np.sqrt(1 + 1 + 4)])
    # the box turned a quarter about z and moved: its 4-long side along x
    turned = pose([10.0, 0, 0], np.pi / 2)
    assert box_distance([[13.0, 0, 0], [10, 2, 0]], size, turned) == pytest.approx([1.0, 1.0])


def test_the_environment_is_its_nearest_obstacle_and_nothing_is_infinitely_far():
    env = Environment(0.0, (Obstacle(np.full(3, 0.1), pose([0.5, 0, 0.05])), Obstacle(np.ones(3), pose([0, 5.0, 0]))))
    d, k = environment_distance([[0.5, 0, 0.12], [0, 0, 0.3], [0, 4.4, 2.0]], env)
    assert d == pytest.approx([0.02, 0.3, 0.1 * np.sqrt(1 + 15**2)]) and k.tolist() == [0, TABLE, 1]
    assert environment_distance([[0, 0, -5.0]], None)[0].tolist() == [np.inf]
    assert clearance_of(env) == CLEARANCE == 0.001


def test_a_fingertip_sphere_at_a_known_height_has_that_clearance_exactly():
    # a 10 mm sphere whose centre is 12.5 mm above a table at z = 0.02: 2.5 mm of clearance
    d, k = sphere_distance([[0.3, -0.1, 0.0325]], [0.01], Environment(0.02))
    assert d.tolist() == [pytest.approx(0.0025, abs=1e-15)] and k.tolist() == [TABLE]
    # as a hand's part, beside a link 40 mm above the table
    link = clusters([cube_link(0, "a", [0, 0, 0.07], 0.01).vertices])
    d, _ = parts_distance(link, 1, np.eye(4)[None, None], [[[0.3, -0.1, 0.0325]]], [0.01], Environment(0.02))
    assert d[0] == pytest.approx([0.04, 0.0025], abs=1e-15)


def test_two_overlapping_fingertip_spheres_overlap_by_the_sum_of_radii_less_their_distance():
    centers = np.array([[[0, 0, 0], [0.012, 0.005, 0], [1.0, 0, 0]]])  # 13 mm apart, a third far away
    depth = finger_overlaps(link_hulls([]), np.zeros((1, 0, 4, 4)), centers, [0.01, 0.008, 0.01])
    assert depth[0, 0, 1] == depth[0, 1, 0] == pytest.approx(0.018 - 0.013, abs=1e-15)
    assert depth[0, 0, 2] == depth[0, 1, 2] == 0.0


def test_a_link_through_a_box_obstacle_is_reported_with_its_depth():
    # a 20 mm cube link pushed 3 mm into a box whose top face is z = 0.05: its lowest corners 3 mm deep
    link = link_hulls([cube_link(0, "lower", [0, 0, 0], 0.01)])
    env = Environment(None, (Obstacle(np.array([0.2, 0.2, 0.1]), pose([0, 0, 0.0])),))
    moved = pose([0.02, 0.03, 0.057])[None, None]
    d, k = parts_distance(link.parts, 1, moved, np.zeros((1, 0, 3)), np.zeros(0), env)
    assert d.tolist() == [[pytest.approx(-0.003, abs=1e-15)]] and k.tolist() == [[0]]


def test_a_merged_link_hull_is_the_exact_one_to_about_its_merge_width():
    from scipy.spatial import ConvexHull

    rng = np.random.default_rng(3)
    p = rng.normal(size=(400, 3))
    p /= np.linalg.norm(p, axis=1, keepdims=True)  # points of a unit sphere: Qhull merges their many facets
    v, planes = convex_planes(p)
    exact = ConvexHull(p).equations
    assert len(v) < 400 and np.allclose(np.linalg.norm(planes[:, :3], axis=1), 1)
    inside = rng.uniform(-0.5, 0.5, size=(200, 3))
    merged, full = hull_depth(inside, planes), hull_depth(inside, exact)
    assert np.abs(full - merged).max() < 2.5 * 2e-3 * 2  # extent 2


def test_links_of_different_fingers_overlap_by_their_deepest_vertex_and_a_finger_never_with_itself():
    a = cube_link(0, "a", [0, 0, 0], 0.01)
    # b overlaps a by (3, 16, 18) mm along x, y, z: its corner (7, -6, -8) mm is 3, 4 and 2 mm inside a's
    # faces, so 2 mm deep (the vertex depth: a lower bound of the 3 mm that would part them)
    b = cube_link(1, "b", [0.017, 0.004, 0.002], 0.01)
    c = cube_link(0, "c", [0.0, 0.0, 0.005], 0.01)  # finger 0's own: overlaps a, but is the same finger
    hulls = link_hulls([a, b, c])
    poses = np.broadcast_to(np.eye(4), (1, 3, 4, 4))
    depth = finger_overlaps(hulls, poses, np.full((1, 2, 3), 5.0) + [[[0, 0, 0], [0, 0, 1]]], [0.0, 0.0])
    assert depth[0, 0, 1] == pytest.approx(0.002, abs=1e-15) and depth[0, 0, 2] == 0.0
    assert depth[0, 1, 2] == pytest.approx(0.003, abs=1e-15)  # b's corner (7, -6, 12) mm is 3, 4, 3 mm into c


def test_a_fingertip_sphere_into_another_fingers_link_by_a_face_is_exact():
    hulls = link_hulls([cube_link(0, "a", [0, 0, 0], 0.01)])
    centers = np.array([[[9.0, 9, 9], [0.018, 0.002, 0.0]]])  # finger 1's 10 mm sphere, 8 mm from the face
    depth = finger_overlaps(hulls, np.eye(4)[None, None], centers, [0.0, 0.01])
    assert depth[0, 0, 2] == pytest.approx(0.002, abs=1e-15)


def test_a_contact_on_the_face_the_object_rests_on_or_too_near_the_table_is_not_clear():
    p = np.array([[0.0325, 0, 0.0], [0.0325, 0, 0.0115], [0.0325, 0, 0.0105], [0, 0, 0.0]])
    n = np.array([[-1.0, 0, 0], [-1.0, 0, 0], [-1.0, 0, 0], [0, 0, 1.0]])
    # a 10 mm sphere beside the cube: its bottom at z - 0.01, clear from 1 mm above the table
    assert clear_contacts(p, n, Environment(0.0), 0.01, 0.001).tolist() == [False, True, False, False]


def test_a_search_on_a_table_never_touches_within_the_clearance_and_reports_each_grasps_clearance():
    cube = GraspObject(Shape("box", np.full(3, 0.065)), pose([0, 0, 0.0325]), mass=0.094)
    env = Environment(0.0, clearance=0.002)
    s = synthesize(cube, 0.8, environment=env, count=2, candidates=1500)
    assert len(s.points) == 2
    low = grasp_clearance(s.points, env)
    assert (low >= 0.002).all() and low == pytest.approx(s.points[..., 2].min(axis=1), abs=1e-15)
