import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from grasp_gen import rotation
from grasptwist.engine import screws

seeds = st.integers(0, 2**32 - 1)


def test_klein_is_the_papers_eq4_on_a_known_pair():
    # [W|T] = u.f + omega.g  (paper, after eq. 4)
    w = np.array([1.0, 2, 3, 4, 5, 6])
    t = np.array([-1.0, 0.5, 2, 3, -2, 1])
    assert screws.klein(w, t) == pytest.approx(1 * 3 + 2 * -2 + 3 * 1 + -1 * 4 + 0.5 * 5 + 2 * 6)


@given(seeds)
def test_klein_is_independent_of_the_origin(seed):
    rng = np.random.default_rng(seed)
    x, y = rng.normal(size=(2, 6))
    shift = rng.normal(size=3) * 10
    moved = [screws.screw(s[:3], screws.field_at(s, shift)) for s in (x, y)]
    assert screws.klein(*moved) == pytest.approx(screws.klein(x, y), rel=1e-9, abs=1e-9)


@given(seeds)
def test_unit_line_properties(seed):
    rng = np.random.default_rng(seed)
    p, d = rng.normal(size=(2, 3))
    line = screws.line_through(p, 5 * d)
    assert np.linalg.norm(line[:3]) == pytest.approx(1.0)
    assert screws.klein(line, line) == pytest.approx(0.0, abs=1e-12)  # zero pitch
    assert screws.klein(line, screws.constant_field(line)) == pytest.approx(1.0)  # eq. 6
    np.testing.assert_allclose(screws.field_at(line, p), 0, atol=1e-12)
    np.testing.assert_allclose(screws.field_at(line, p + 3.7 * d), 0, atol=1e-12)
    assert screws.pitch(line) == pytest.approx(0.0, abs=1e-12)


def test_line_between_matches_plucker_eq15_for_example_1():
    # Sigma_1 of Example 1: the line p2 -> p3 is (0,-1,0; 0,0,0.5)
    line = screws.line_between([-0.5, 0.866, 0], [-0.5, -0.866, 0])
    np.testing.assert_allclose(line, [0, -1, 0, 0, 0, 0.5], atol=1e-12)


def test_constant_field_squares_to_zero():
    s = np.array([1.0, 2, 3, 4, 5, 6])
    np.testing.assert_array_equal(screws.constant_field(screws.constant_field(s)), 0)


def test_meeting_lines_are_reciprocal_and_skew_ones_give_minus_d_sin():
    a = screws.line_through([0, 0, 0], [1, 0, 0])
    b = screws.line_through([0, 0, 0], [0, 1, 0])
    assert screws.klein(a, b) == 0
    # the x axis and the line (0, t, 2 + t): common normal (0,-1,1)/sqrt2, distance sqrt2, at 90 degrees
    c = screws.line_through([0, 0, 2.0], [0, 1, 1])
    assert abs(screws.klein(a, c)) == pytest.approx(np.sqrt(2) * 1.0)
    # at 45 degrees and distance 3: |[L1|L2]| = 3 sin 45
    e = screws.line_through([0, 0, 3.0], [1, 1, 0])
    assert abs(screws.klein(a, e)) == pytest.approx(3 * np.sin(np.pi / 4))


@given(seeds)
def test_twist_at_gives_the_requested_point_velocity(seed):
    rng = np.random.default_rng(seed)
    w, vel, at = rng.normal(size=(3, 3))
    t = screws.twist_at(w, vel, at)
    np.testing.assert_allclose(screws.field_at(t, at), vel, atol=1e-12)
    np.testing.assert_allclose(t[:3], w)


@given(seeds)
@settings(max_examples=50)
def test_rigid_motion_carries_fields_along(seed):
    rng = np.random.default_rng(seed)
    s = rng.normal(size=6)
    r = rotation(rng)
    t = rng.normal(size=3)
    p = rng.normal(size=3)
    moved = screws.rigid_motion(s, r, t)
    np.testing.assert_allclose(screws.field_at(moved, r @ p + t), r @ screws.field_at(s, p), atol=1e-12)


def test_axis_point_and_pitch_of_a_screw_motion():
    # rotation about the axis through (1, 2, 0) along z, with pitch 0.5
    t = screws.twist_at([0, 0, 2.0], [0, 0, 1.0], [1, 2, 0])
    assert screws.pitch(t) == pytest.approx(0.5)
    np.testing.assert_allclose(screws.axis_point(t), [1, 2, 0], atol=1e-12)
    assert screws.pitch([0, 0, 0, 1.0, 0, 0]) == np.inf


def test_batch_shapes_broadcast():
    p = np.zeros((4, 1, 3))
    d = np.ones((5, 3))
    assert screws.line_through(p, d).shape == (4, 5, 6)
    assert screws.klein(np.ones((2, 1, 6)), np.ones((3, 6))).shape == (2, 3)


def _extreme_vectors(rng, n):
    """Random vectors over 600 orders of magnitude, with exact zeros mixed in."""
    v = rng.normal(size=(n, 3)) * 10.0 ** rng.uniform(-300, 300, size=(n, 1))
    v[rng.random((n, 3)) < 0.1] = 0.0
    return v


@given(seeds)
@settings(max_examples=20)
def test_three_component_forms_give_the_array_forms_bits(seed):
    rng = np.random.default_rng(seed)
    a, b, c = (rng.normal(size=(50, 3)) * 10.0 ** rng.uniform(-5, 5, size=(50, 1)) for _ in range(3))
    s = rng.normal(size=50)
    comp = lambda v: tuple(v.T)  # noqa: E731  (x, y, z), each an array over rows
    np.testing.assert_array_equal(screws.dot3(comp(a), comp(b)), screws.dot(a, b))
    np.testing.assert_array_equal(np.stack(screws.cross3(comp(a), comp(b)), -1), screws.cross(a, b))
    np.testing.assert_array_equal(np.stack(screws.add3(comp(a), comp(b)), -1), a + b)
    np.testing.assert_array_equal(np.stack(screws.sub3(comp(a), comp(b)), -1), a - b)
    np.testing.assert_array_equal(np.stack(screws.mul3(comp(a), s), -1), a * s[:, None])
    np.testing.assert_array_equal(np.stack(screws.div3(comp(a), s), -1), a / s[:, None])
    twist = screws.twist_at(a, b, c)
    np.testing.assert_array_equal(np.stack(screws.twist_at3(comp(a), comp(b), comp(c)), -1), twist[:, 3:])
    # ... and in plain floats, one row at a time
    for i in range(5):
        assert screws.dot3(a[i].tolist(), b[i].tolist()) == screws.dot(a[i], b[i])
        assert screws.cross3(a[i].tolist(), b[i].tolist()) == tuple(screws.cross(a[i], b[i]).tolist())
        assert screws.twist_at3(a[i].tolist(), b[i].tolist(), c[i].tolist()) == tuple(twist[i, 3:].tolist())


@given(seeds)
@settings(max_examples=20)
def test_direction3_gives_directions_bits_at_any_size(seed):
    v = _extreme_vectors(np.random.default_rng(seed), 200)
    v = v[np.any(v != 0, axis=1)]
    want = screws.direction(v)
    got = np.array([screws.direction3(*row) for row in v.tolist()])
    np.testing.assert_array_equal(got, want)
    np.testing.assert_allclose(np.linalg.norm(got, axis=1), 1.0, rtol=1e-15)


def test_direction3_of_a_zero_vector_raises_where_direction_keeps_zero():
    np.testing.assert_array_equal(screws.direction([0.0, 0.0, 0.0]), 0.0)
    with pytest.raises(ZeroDivisionError, match="division by zero"):
        screws.direction3(0.0, 0.0, 0.0)


def test_the_cyclic_indices_are_the_papers():
    assert [(i, screws.J[i], screws.K[i]) for i in range(3)] == [(0, 1, 2), (1, 2, 0), (2, 0, 1)]
