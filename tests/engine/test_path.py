"""Paths: exact poses, the grasp moving along, and degeneracies located between samples.

Expected crossing times are derived by hand from the geometry (comments), never
taken from the program's output.
"""

import numpy as np
import pytest

import grasptwist as gt
from grasp_gen import rotation
from grasptwist.engine import se3
from grasptwist.path import Segment, check_segments, degeneracies, follow, integrate

# The paper's Example 1: contacts on the unit circle in z = 0, radial normals, wrist above.
CYLINDER = np.array([[1, 0, 0], [-0.5, 0.866, 0], [-0.5, -0.866, 0.0]])
CYLINDER_NORMALS = -CYLINDER
CYLINDER_WRIST = np.array([0, 0, 1.0])
# The paper's Example 2: contacts on the faces x = 0, y = 0, z = 0; their plane is x + y + z = 4.
POLYHEDRON = np.array([[0, 2, 2], [2, 0, 2], [2, 2, 0.0]])
POLYHEDRON_NORMALS = np.eye(3)
POLYHEDRON_WRIST = np.zeros(3)

TURN_X = [1.0, 0, 0, 0, 0, 0]  # unit rate about the x axis through the origin


def off_tangent_at(points, wrist, segments, t):
    """The engine's off-tangent conditioning on the grasp moved to time t, with numpy's own matmul."""
    pose = integrate(segments, t)
    moved = points @ pose.rotation.T + pose.position
    return float(gt.decompose_off_tangent(moved, wrist, np.zeros(6)).conditioning)


def wrist_crossings(d):
    return [c for c in d.crossings if c.method == "off-tangent"]


# --- poses -------------------------------------------------------------------------


@pytest.mark.parametrize("frame", ["space", "body"])
def test_a_constant_twist_ends_at_the_closed_form_screw_motion(frame):
    # screw axis through q along unit w, pitch h, rate 0.8, for 3.9 s: a point p ends at
    # q + Rot(w, theta)(p - q) + h theta w with theta = 0.8 * 3.9 (from the start pose, space = body)
    rng = np.random.default_rng(0)
    w = rng.normal(size=3)
    w /= np.linalg.norm(w)
    q, h, rate, duration = rng.normal(size=3), 0.3, 0.8, 3.9
    omega = rate * w
    twist = np.concatenate((omega, -np.cross(omega, q) + h * omega))
    theta = rate * duration
    k = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])
    rot = np.eye(3) + np.sin(theta) * k + (1 - np.cos(theta)) * k @ k
    pose = integrate([Segment(duration, twist=twist, frame=frame)], duration)
    np.testing.assert_allclose(pose.rotation, rot, rtol=0, atol=1e-14)
    np.testing.assert_allclose(pose.position, q - rot @ q + h * theta * w, rtol=0, atol=1e-14)
    np.testing.assert_allclose(pose.twist, twist, atol=1e-15)


def test_body_and_space_paths_describing_the_same_motion_agree():
    rng = np.random.default_rng(1)
    v1, v2 = rng.normal(size=(2, 6))
    d1, d2 = 1.3, 0.8
    # after segment 1 the pose is H1 = exp(V1 d1) (body = space from the identity);
    # the space twist V2 is the body twist Ad_{H1^-1} V2 from there
    h1 = se3.exp(v1, d1)
    v2_body = se3.adjoint(*se3.inverse(*h1)) @ v2
    space = [Segment(d1, twist=v1), Segment(d2, twist=v2)]
    body = [Segment(d1, twist=v1, frame="body"), Segment(d2, twist=v2_body, frame="body")]
    t = np.linspace(0, d1 + d2, 41)
    a, b = integrate(space, t), integrate(body, t)
    np.testing.assert_allclose(a.rotation, b.rotation, atol=1e-14)
    np.testing.assert_allclose(a.position, b.position, atol=1e-14)
    np.testing.assert_allclose(a.twist, b.twist, atol=1e-14)
    # and a constant space twist moves the pose as exp(V_s tau) H1
    tau = t[t > d1] - d1
    r, x = se3.compose(*se3.exp(v2, tau), *h1)
    np.testing.assert_allclose(a.rotation[t > d1], r, atol=1e-14)
    np.testing.assert_allclose(a.position[t > d1], x, atol=1e-14)


def test_a_pose_target_is_reached_to_1e_12():
    rng = np.random.default_rng(2)
    targets = [(rotation(rng), rng.normal(size=3) * 3), (se3.rotvec_to_matrix([0, 0, np.pi - 1e-9]), [1.0, 2, 3])]
    for r, x in targets:
        path = [Segment(0.7, twist=rng.normal(size=6)), Segment(2.0, position=x, rotation=r)]
        end = integrate(path, 2.7)
        np.testing.assert_allclose(end.rotation, r, rtol=0, atol=1e-12)
        np.testing.assert_allclose(end.position, x, rtol=0, atol=1e-12)
        assert end.segment == 1


def test_pose_target_of_the_polyhedron_is_the_screw_along_the_diagonal():
    # 120 degrees about (1,1,1)/sqrt3 (quaternion (1/2, 1/2, 1/2, 1/2)) and 8/sqrt3 back along the
    # diagonal: a screw motion about the diagonal, so its space twist is (omega; v) with
    # omega = (2 pi / 3) e / 2 s and v = -(8/sqrt3) e / 2 s (axis through the origin), constant.
    e = np.ones(3) / np.sqrt(3)
    target = Segment(2.0, position=-8 / 3 * np.ones(3), rotation=se3.quaternion_to_matrix([0.5, 0.5, 0.5, 0.5]))
    pose = integrate([target], np.linspace(0, 2, 5))
    np.testing.assert_allclose(
        pose.twist, np.tile(np.concatenate((np.pi / 3 * e, -4 / np.sqrt(3) * e)), (5, 1)), atol=1e-15
    )
    # at the end each contact is where the next one was (x -> y -> z), moved back by 8/3
    moved = se3.transform(pose.rotation[-1], pose.position[-1], POLYHEDRON)
    np.testing.assert_allclose(moved, POLYHEDRON[[1, 2, 0]] - 8 / 3, atol=1e-14)


# --- following ---------------------------------------------------------------------


def test_contact_velocities_along_the_path_are_the_derivative_of_the_contact_positions():
    rng = np.random.default_rng(3)
    path = [
        Segment(1.0, twist=rng.normal(size=6)),
        Segment(0.5, twist=rng.normal(size=6), frame="body"),
        Segment(1.5, position=rng.normal(size=3), rotation=rotation(rng)),
    ]
    t = np.array([0.3, 0.77, 1.2, 1.4, 1.9, 2.95])  # away from the segments' ends
    h = 1e-5
    f = follow(POLYHEDRON, POLYHEDRON_NORMALS, POLYHEDRON_WRIST, path, t)
    ahead = follow(POLYHEDRON, POLYHEDRON_NORMALS, POLYHEDRON_WRIST, path, t + h).points
    behind = follow(POLYHEDRON, POLYHEDRON_NORMALS, POLYHEDRON_WRIST, path, t - h).points
    np.testing.assert_allclose(f.velocities, (ahead - behind) / (2 * h), rtol=0, atol=1e-8)
    np.testing.assert_allclose(f.velocities, gt.contact_velocities(f.points, f.poses.twist), atol=1e-15)


def test_follow_is_the_engine_on_each_moved_grasp():
    rng = np.random.default_rng(4)
    points = rng.normal(size=(5, 3, 3))
    normals = rng.normal(size=(5, 3, 3))
    wrist = rng.normal(size=(5, 3)) + [0, 0, 3]
    path = [Segment(1.0, twist=rng.normal(size=6)), Segment(1.0, position=[0, 0, 1.0], rotation=rotation(rng))]
    t = np.linspace(0, 2, 7)
    f = follow(points, normals, wrist, path, t, bases=True)
    assert f.points.shape == (7, 5, 3, 3) and f.off_tangent.x.shape == (7, 5, 3) and f.tangent.alpha.shape == (7, 5, 3)
    for i in (0, 3, 6):
        pose = integrate(path, t[i])
        moved = points @ pose.rotation.T + pose.position
        turned = normals @ pose.rotation.T
        np.testing.assert_allclose(f.points[i], moved, atol=1e-14)
        off = gt.decompose_off_tangent(moved, wrist, pose.twist)
        tan = gt.decompose_tangent(moved, turned, pose.twist)
        np.testing.assert_allclose(f.off_tangent.x[i], off.x, rtol=1e-12, atol=1e-13)
        np.testing.assert_allclose(f.off_tangent.y[i], off.y, rtol=1e-12, atol=1e-13)
        np.testing.assert_allclose(f.off_tangent.psi[i], off.psi, atol=1e-13)
        np.testing.assert_allclose(f.tangent.alpha[i], tan.alpha, rtol=1e-12, atol=1e-13)
        np.testing.assert_allclose(f.tangent.beta[i], tan.beta, rtol=1e-12, atol=1e-13)
        np.testing.assert_array_equal(f.tangent.status[i], tan.status)
        # the tangent method is solved once per segment at rest and carried to the moved grasp
        np.testing.assert_allclose(f.tangent.theta[i], tan.theta, atol=1e-13)
        np.testing.assert_allclose(f.tangent.sigma[i], tan.sigma, atol=1e-13)
        np.testing.assert_allclose(f.tangent.normal_velocity[i], tan.normal_velocity, rtol=1e-12, atol=1e-13)
        np.testing.assert_allclose(f.tangent.conditioning[i], tan.conditioning, rtol=1e-12)
        np.testing.assert_allclose(f.velocities[i], gt.contact_velocities(moved, pose.twist), atol=1e-13)
        assert np.array_equal(f.tangent.points[i], f.points[i]) and np.array_equal(f.tangent.twist[i, 0], pose.twist)
    assert f.off_tangent.residual.max() < 1e-12 and f.tangent.residual.max() < 1e-12


def test_the_tangent_method_does_not_change_along_a_path_but_the_off_tangent_one_does():
    # the module's claim: contacts and normals move together, so only the wrist's relation changes
    rng = np.random.default_rng(5)
    path = [Segment(3.0, twist=rng.normal(size=6)), Segment(1.0, position=[1.0, 2, 0], rotation=rotation(rng))]
    f = follow(POLYHEDRON, POLYHEDRON_NORMALS, POLYHEDRON_WRIST, path, np.linspace(0, 4, 50))
    np.testing.assert_allclose(f.tangent.conditioning, f.tangent.conditioning[0], rtol=1e-12)
    np.testing.assert_allclose(f.tangent.theta_sigma, np.broadcast_to(f.tangent.theta_sigma[0], (50, 3)), rtol=1e-12)
    assert np.ptp(f.off_tangent.conditioning) > 0.1


def test_follow_options():
    path = [Segment(1.0, twist=TURN_X)]
    f = follow(CYLINDER, CYLINDER_NORMALS, None, path, [0.0, 1.0])
    assert f.off_tangent is None and f.tangent.alpha.shape == (2, 3)
    f = follow(CYLINDER, CYLINDER_NORMALS, CYLINDER_WRIST, path, [0.0, 1.0], method="off-tangent")
    assert f.tangent is None and f.off_tangent.sigma is None
    with pytest.raises(ValueError, match="^method must be"):
        follow(CYLINDER, CYLINDER_NORMALS, CYLINDER_WRIST, path, [0.0], method="both-ish")
    with pytest.raises(ValueError, match="^times must be finite and within the path"):
        follow(CYLINDER, CYLINDER_NORMALS, CYLINDER_WRIST, path, [1.5])
    with pytest.raises(ValueError, match=r"^wrist must have shape \(\.\.\., 3\)"):
        follow(CYLINDER, CYLINDER_NORMALS, [0, 1], path, [0.0])


@pytest.mark.parametrize(
    ("segment", "message"),
    [
        (Segment(-1.0, twist=TURN_X), r"segments\[0\]\.duration must be a finite number > 0"),
        (Segment(float("nan"), twist=TURN_X), r"segments\[0\]\.duration must be a finite number > 0"),
        (Segment(1.0, twist=[1, 0, 0]), r"segments\[0\]\.twist must have shape \(6,\)"),
        (Segment(1.0, twist=TURN_X, frame="world"), r"segments\[0\]\.frame must be 'space' or 'body'"),
        (Segment(1.0, twist=TURN_X, position=[0, 0, 0]), r"segments\[0\] has both a twist and a pose target"),
        (Segment(1.0, position=[0, 0, 0]), r"segments\[0\] needs a twist or a pose target"),
        (Segment(1.0, position=[0, 0, 0], rotation=2 * np.eye(3)), r"segments\[0\]\.rotation must be a rotation"),
        (Segment(1.0, position=[0, 0, 0], rotation=-np.eye(3)), r"segments\[0\]\.rotation must be a rotation"),
        (Segment(1.0, position=[0, np.inf, 0], rotation=np.eye(3)), r"segments\[0\]\.position must be finite"),
    ],
)
def test_bad_segments_raise_value_errors_naming_the_field(segment, message):
    with pytest.raises(ValueError, match=message):
        check_segments([segment])


def test_an_empty_path_or_not_a_list_is_refused():
    with pytest.raises(ValueError, match="^segments must hold at least one segment"):
        integrate([], [0.0])
    with pytest.raises(ValueError, match="^segments must be a sequence of Segment"):
        integrate(Segment(1.0, twist=TURN_X), [0.0])


# --- degeneracies ------------------------------------------------------------------

# Example 1 turning about the x axis at unit rate.  By hand: the contacts' plane z = 0 contains
# the x axis (p1 lies on it and the contacts' centroid is the origin), so turning by phi about x
# carries it to the plane through the x axis with normal (0, -sin phi, cos phi).  The wrist
# (0, 0, 1) lies in it when cos phi = 0: at phi = pi/2 and 3 pi/2, crossing transversally
# (D = m . (p1 - c) = -|m| cos phi changes sign).
CYLINDER_CROSSINGS = (np.pi / 2, 3 * np.pi / 2)


@pytest.mark.parametrize(
    "times",
    [
        None,
        np.linspace(0, 2 * np.pi, 3),  # 0, pi, 2 pi: each crossing straddled
        [0.0, np.pi / 2, 2 * np.pi],  # a sample exactly on the first crossing
        [0.0, 0.1, 2 * np.pi],  # both crossings inside one interval: no sign change between samples
    ],
)
def test_the_cylinder_turning_about_x_meets_its_wrist_at_a_quarter_turn(times):
    d = degeneracies(CYLINDER, CYLINDER_NORMALS, CYLINDER_WRIST, [Segment(2 * np.pi, twist=TURN_X)], times)
    found = wrist_crossings(d)
    assert len(found) == 2
    for c, expected in zip(found, CYLINDER_CROSSINGS):
        assert (c.code, c.culprit) == ("wrist-coplanar", -1)
        assert c.t_start == c.t_end
        assert abs(c.t_start - expected) <= 1e-9
    # the tangent method fails for the whole path: the radial normals lie in the contacts' plane
    assert d.crossings[0] == ("tangent", "normals-rank-deficient", 0.0, 2 * np.pi, -1)
    value, at = d.min_conditioning["off-tangent"]
    assert value <= gt.DEGENERACY_TOL and abs(at - np.pi / 2) <= 1e-9
    assert d.first_warning == ("tangent", 0.0)


def test_where_the_wrist_warning_starts():
    d = degeneracies(CYLINDER, CYLINDER_NORMALS, CYLINDER_WRIST, [Segment(np.pi, twist=TURN_X)], [0, 1, 2, 3])
    start = d.warning_start["off-tangent"]
    assert 1.0 < start < np.pi / 2
    # the engine's conditioning crosses CONDITION_WARNING there (to the bisection's precision)
    path = [Segment(np.pi, twist=TURN_X)]
    assert off_tangent_at(CYLINDER, CYLINDER_WRIST, path, start - 1e-8) >= gt.CONDITION_WARNING
    assert off_tangent_at(CYLINDER, CYLINDER_WRIST, path, start + 1e-8) < gt.CONDITION_WARNING


@pytest.mark.parametrize(("frame", "expected"), [("space", 1 + np.pi / 3), ("body", 1 + np.pi / 2)])
def test_lift_then_turn_in_either_frame(frame, expected):
    # Lift by 0.5, then turn about x.  Space frame: about the fixed x axis, the lifted plane stays
    # at distance 0.5 from it with normal (0, -sin phi, cos phi); the wrist (0,0,1) is at distance
    # cos phi along that normal, so they meet at cos phi = 0.5, phi = pi/3.  Body frame: about the
    # object's x axis, now at height 0.5 and inside the plane; the wrist is 0.5 above it, in the
    # plane when cos phi = 0, phi = pi/2.
    path = [Segment(1.0, twist=[0, 0, 0, 0, 0, 0.5]), Segment(2.0, twist=TURN_X, frame=frame)]
    d = degeneracies(CYLINDER, CYLINDER_NORMALS, CYLINDER_WRIST, path, np.linspace(0, 3, 3))
    (c,) = wrist_crossings(d)
    assert c.t_start == c.t_end and abs(c.t_start - expected) <= 1e-9


def test_the_polyhedron_pose_target_crosses_the_wrist_halfway():
    # The screw along the diagonal (see above) keeps the contacts' plane normal to e = (1,1,1)/sqrt3
    # and moves it back by (8/sqrt3) t/2; it starts 4/sqrt3 from the wrist (the origin), so it
    # reaches it at t = 1.
    path = [Segment(2.0, position=-8 / 3 * np.ones(3), rotation=se3.quaternion_to_matrix([0.5, 0.5, 0.5, 0.5]))]
    for times in (None, np.linspace(0, 2, 3), [0.0, 1.7, 2.0]):
        d = degeneracies(POLYHEDRON, POLYHEDRON_NORMALS, POLYHEDRON_WRIST, path, times)
        (c,) = d.crossings
        assert (c.method, c.code) == ("off-tangent", "wrist-coplanar")
        assert c.t_start == c.t_end and abs(c.t_start - 1.0) <= 1e-9
        assert d.min_conditioning["tangent"] == (pytest.approx(0.5), 0.0)
        assert d.warning_start["tangent"] is None and 0.9 < d.first_warning[1] < 1.0
    # Spinning about the diagonal first changes nothing of that (the plane's normal is the axis): the
    # target, still a screw along the diagonal from there, is crossed halfway again, at t = 1 + 1.
    spin = Segment(1.0, twist=[*(0.5 * np.ones(3) / np.sqrt(3)), 0, 0, 0])
    d = degeneracies(POLYHEDRON, POLYHEDRON_NORMALS, POLYHEDRON_WRIST, [spin, *path], [0.0, 1.5, 3.0])
    (c,) = d.crossings
    assert c.t_start == c.t_end and abs(c.t_start - 2.0) <= 1e-9


def test_a_tangential_zero_is_found_and_bracketed():
    # Turning about the axis x through a = (0, 0, -1), the contacts' plane (1 from that axis) stays
    # tangent to the cylinder of radius 1 about it, touching it at a + (0, -sin phi, cos phi).  A wrist
    # on that cylinder at phi0 = pi/3 is grazed there: its distance to the plane, cos(phi - phi0) - 1,
    # has a double zero, without a sign change.
    a, phi0 = np.array([0, 0, -1.0]), np.pi / 3
    wrist = a + [0, -np.sin(phi0), np.cos(phi0)]
    path = [Segment(np.pi, twist=[1.0, 0, 0, *-np.cross([1.0, 0, 0], a)])]
    d = degeneracies(CYLINDER, CYLINDER_NORMALS, wrist, path, np.linspace(0, np.pi, 3))
    (c,) = wrist_crossings(d)
    assert c.t_start < phi0 < c.t_end and c.t_end - c.t_start < 1e-3  # a zone ~ sqrt(tol) wide
    assert abs((c.t_start + c.t_end) / 2 - phi0) < 1e-8  # symmetric about the graze
    eps = 2e-9 * np.pi  # the zone's ends, to 1e-9 of the duration: the engine's own verdict flips there
    assert off_tangent_at(CYLINDER, wrist, path, c.t_start - eps) > gt.DEGENERACY_TOL
    assert off_tangent_at(CYLINDER, wrist, path, c.t_start + eps) <= gt.DEGENERACY_TOL
    assert off_tangent_at(CYLINDER, wrist, path, c.t_end - eps) <= gt.DEGENERACY_TOL
    assert off_tangent_at(CYLINDER, wrist, path, c.t_end + eps) > gt.DEGENERACY_TOL
    assert abs(d.min_conditioning["off-tangent"][1] - phi0) < 1e-6
    # a wrist just inside that cylinder is never in the plane: nothing reported, the minimum still found
    inside = a + 0.99 * (wrist - a)
    d = degeneracies(CYLINDER, CYLINDER_NORMALS, inside, path, np.linspace(0, np.pi, 3))
    assert wrist_crossings(d) == []
    value, at = d.min_conditioning["off-tangent"]
    assert value == off_tangent_at(CYLINDER, inside, path, at)
    # no lower value on a fine grid (near the graze the conditioning has two equal minima, off phi0
    # because it divides |D| by a length that varies too)
    t = np.linspace(0.9, 1.2, 3001)
    pose = integrate(path, t)
    grid = gt.decompose_off_tangent(
        CYLINDER @ pose.rotation.swapaxes(1, 2) + pose.position[:, None], inside, np.zeros(6)
    )
    assert value <= grid.conditioning.min() < value + 1e-6
    # and one just outside is crossed twice, where cos(phi - phi0) = 1 / 1.01
    d = degeneracies(CYLINDER, CYLINDER_NORMALS, a + 1.01 * (wrist - a), path, np.linspace(0, np.pi, 3))
    times = [c.t_start for c in wrist_crossings(d)]
    np.testing.assert_allclose(times, phi0 + np.array([-1, 1]) * np.arccos(1 / 1.01), rtol=0, atol=1e-9)


def test_a_stretch_with_the_wrist_kept_in_the_plane_is_reported_whole():
    # The wrist (0, 2, 0) starts in the plane z = 0; sliding the object along y keeps it there for
    # 1 s; then turning about x tilts the plane away from it at once.
    path = [Segment(1.0, twist=[0, 0, 0, 0, 1.0, 0]), Segment(1.0, twist=TURN_X)]
    d = degeneracies(CYLINDER, CYLINDER_NORMALS, [0, 2.0, 0], path, [0.0, 2.0])
    (c,) = wrist_crossings(d)
    assert c.t_start == 0.0 and 0 <= c.t_end - 1.0 < 1e-8
    assert d.warning_start["off-tangent"] == 0.0


def test_nothing_to_report_on_a_harmless_path():
    path = [Segment(1.0, twist=[0, 0, 1.0, 0, 0, 0])]  # spinning about z keeps the wrist 1 above the plane
    d = degeneracies(CYLINDER, CYLINDER_NORMALS, CYLINDER_WRIST, path)
    assert wrist_crossings(d) == [] and d.warning_start["off-tangent"] is None
    assert d.min_conditioning["off-tangent"][0] == pytest.approx(off_tangent_at(CYLINDER, CYLINDER_WRIST, path, 0.0))
    d = degeneracies(CYLINDER, CYLINDER_NORMALS, None, path)
    assert "off-tangent" not in d.min_conditioning
