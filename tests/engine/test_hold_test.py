"""The hold test's squeeze (engine/hold_test.py ``squeezed``): the same wrench, every finger pressing at
least the floor, inside the cones; unchanged where no squeeze is inside them."""

import numpy as np

from grasptwist.engine.forces.grasp_map import grasp_map
from grasptwist.engine.forces.grip import grip
from grasptwist.engine.hold_test import direction_wrenches, squeezed

P = np.array([[0.03, 0.0, -0.01], [-0.02, 0.025, -0.01], [-0.01, -0.03, 0.005]])
N = -P / np.linalg.norm(P, axis=1, keepdims=True)
MU = 0.8


def _normal(f):
    return (f * N).sum(axis=-1)


def test_a_squeeze_lifts_every_finger_to_the_floor_with_the_same_wrench_inside_the_cones():
    least = grip(P, N, direction_wrenches(0.1, [0, 0, 0], 0.981), MU).force  # (6, 3, 3)
    assert _normal(least).min() < 0.1  # the least grip leaves some finger nearly idle
    out = squeezed(P, N, least, MU, 0.5)
    np.testing.assert_allclose(out.reshape(6, 9) @ grasp_map(P).T, least.reshape(6, 9) @ grasp_map(P).T, atol=1e-12)
    pressed = _normal(out)
    assert (pressed >= 0.5 - 1e-12).all()
    # the least squeeze: a finger at the floor (a grip already above it unchanged)
    np.testing.assert_allclose(pressed.min(axis=1), np.maximum(0.5, _normal(least).min(axis=1)), rtol=1e-12)
    tangential = np.linalg.norm(out - pressed[..., None] * N, axis=-1)
    assert (tangential <= MU * pressed + 1e-12).all()


def test_a_grip_already_above_the_floor_is_unchanged():
    least = grip(P, N, direction_wrenches(0.1, [0, 0, 0], 0.981), MU).force
    assert np.array_equal(squeezed(P, N, least, MU, 0.0), least)


def test_without_a_squeeze_inside_the_cones_the_forces_are_unchanged_and_nan_stays_nan():
    # a tray: three contacts on its underside, normals up, no internal force pushes at all three
    tray = np.array([[1.0, 0, 0], [-0.5, 0.75**0.5, 0], [-0.5, -(0.75**0.5), 0]])
    up = np.tile([0.0, 0, 1], (3, 1))
    f = np.tile([0.0, 0, 1 / 3], (3, 1))
    np.testing.assert_array_equal(squeezed(tray, up, f, 0.5, 1.0), f)
    assert np.isnan(squeezed(P, N, np.full((3, 3), np.nan), MU, 1.0)).all()
