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
