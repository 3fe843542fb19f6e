"""Two convex hulls crossing edge through edge (engine/collision.py hull_penetration): the separating
axis depth against the Minkowski difference's hull (scipy), and the TriFinger grasp a trial found."""

import numpy as np
import pytest
from scipy.spatial import ConvexHull

import grasptwist as gt
from grasptwist.engine.collision import (
    collision_tolerance,
    convex_edges,
    finger_overlaps,
    hull_depth,
    hull_penetration,
    link_poses,
    tip_centers_at,
)
from grasptwist.engine.ik import home_tips
from grasptwist.engine.se3 import rotvec_to_matrix
from grasptwist.run.collisions import _hulls

CUBE = np.array([[x, y, z] for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)])


def hull(points):
    h = ConvexHull(points)
    edges = convex_edges(h.points, h.simplices, h.neighbors, h.equations[:, :3])
    return points[None], h.equations[None, :, :3], edges[None]


def minkowski_depth(a, b):
    """The origin's distance inside the hull of ``a - b`` (every difference of their points), 0 outside."""
    d = ConvexHull((a[:, None] - b[None]).reshape(-1, 3))
    return max(0.0, float((-d.equations[:, 3]).min()))


@pytest.mark.parametrize("z", [1.0, 1.2, 1.3, 1.5])
def test_two_cubes_whose_edges_cross_overlap_by_the_depth_of_their_minkowski_difference(z):
    # the second cube turned 45 degrees about x and about y: its lowest edge crosses the first's top edges
    turned = CUBE @ (rotvec_to_matrix([0, np.pi / 4, 0]) @ rotvec_to_matrix([np.pi / 4, 0, 0])).T + [0, 0, z]
    got = hull_penetration(*hull(CUBE), *hull(turned))[0]
    assert got == pytest.approx(minkowski_depth(CUBE, turned), abs=1e-12)
    assert (got > 0) == (z < 1.5)


def test_random_polytopes_overlap_by_the_depth_of_their_minkowski_difference():
    rng = np.random.default_rng(7)
    got, want = [], []
    for _ in range(60):
        a = rng.normal(size=(rng.integers(4, 12), 3)) * rng.uniform(0.2, 1, 3)
        b = rng.normal(size=(rng.integers(4, 12), 3)) * rng.uniform(0.2, 1, 3) + rng.normal(size=3)
        got.append(hull_penetration(*hull(a), *hull(b))[0])
        want.append(minkowski_depth(a, b))
    assert np.array(got) == pytest.approx(want, abs=1e-12)
    assert 10 < np.count_nonzero(want) < 60  # apart and overlapping pairs both


#: The trial's grasp (synthesize grasps/trifinger-cube.yaml --friction 0.8 --mass 0.1 -n 20, seed 0,
#: rank 5): finger 1's tip link's stem crosses finger 2's lower link, no hull vertex in the other.
CROSSED = [0.188681879921344, 0.4029170990653637, -1.474514545969438, 0.4352969697630192, 0.6130922207973979]
CROSSED += [-1.3614590036277632, 0.27169044000636794, 0.6455464201920984, -1.3808608328417304]


def test_the_trifinger_grasp_whose_tip_stem_crosses_another_fingers_lower_link_collides():
    grasp = gt.read_grasps("grasps/trifinger-cube.yaml")[0]
    hand = grasp.hand
    hulls = _hulls(hand, "grasps", 1 << 20)
    q = np.array([CROSSED])
    poses, centers = link_poses(hand, hulls.links, q), tip_centers_at(hand, home_tips(hand), q)
    radii = [f.tip_radius for f in hand.fingers]
    names = [g.link for g in hulls.links]
    i, j = names.index("finger_tip_link_0"), names.index("finger_lower_link_120")
    depth = finger_overlaps(hulls, poses, centers, radii)
    # the least translation that parts the two hulls: the Minkowski difference's, 2.44 mm
    a = np.unique(hulls.vertices[i], axis=0) @ poses[0, i, :3, :3].T + poses[0, i, :3, 3]
    b = np.unique(hulls.vertices[j], axis=0) @ poses[0, j, :3, :3].T + poses[0, j, :3, 3]
    assert depth[0, i, j] == pytest.approx(minkowski_depth(a, b), abs=1e-12)
    assert depth[0, i, j] == pytest.approx(0.00244, abs=1e-5)
    assert depth[0, i, j] > collision_tolerance(grasp.object)
    # no hull vertex of either is inside the other: the vertices alone see nothing (2.7 mm outside)
    home_b = b @ poses[0, i, :3, :3] - poses[0, i, :3, 3] @ poses[0, i, :3, :3]
    home_a = a @ poses[0, j, :3, :3] - poses[0, j, :3, 3] @ poses[0, j, :3, :3]
    assert hull_depth(home_b, hulls.planes[i]).max() < -0.002 and hull_depth(home_a, hulls.planes[j]).max() < -0.002
