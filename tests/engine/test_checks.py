"""The public validators: every branch, and the engine's functions using them at the boundary."""

import numpy as np
import pytest

import grasptwist as gt

EX1 = np.array([[1, 0, 0], [-0.5, 0.866, 0], [-0.5, -0.866, 0]], float)

CHECKS = [
    (gt.check_points, "points", (3, 3), r"\(\.\.\., 3, 3\)"),
    (gt.check_normals, "normals", (3, 3), r"\(\.\.\., 3, 3\)"),
    (gt.check_wrist, "wrist", (3,), r"\(\.\.\., 3\)"),
    (gt.check_twist, "twist", (6,), r"\(\.\.\., 6\)"),
]
ids = [c[1] for c in CHECKS]


@pytest.mark.parametrize("check, name, shape, want", CHECKS, ids=ids)
def test_a_wrong_trailing_shape_names_the_argument_and_both_shapes(check, name, shape, want):
    wrong = shape[:-1] + (shape[-1] + 1,)
    with pytest.raises(ValueError, match=rf"^{name} must have shape {want}, got \(2, {', '.join(map(str, wrong))}\)$"):
        check(np.zeros((2, *wrong)))


@pytest.mark.parametrize("check, name, shape, want", CHECKS, ids=ids)
def test_too_few_axes_are_a_wrong_shape(check, name, shape, want):
    with pytest.raises(ValueError, match=rf"^{name} must have shape {want}, got \(\)$"):
        check(1.0)
    if len(shape) == 2:
        with pytest.raises(ValueError, match=rf"^{name} must have shape {want}, got \(3,\)$"):
            check([1.0, 2.0, 3.0])


@pytest.mark.parametrize("check, name, shape, want", CHECKS, ids=ids)
def test_ragged_nesting_is_a_shape_error(check, name, shape, want):
    with pytest.raises(ValueError, match=rf"^{name} must have shape {want}, got a ragged nested sequence$"):
        check([[1.0, 2.0, 3.0], [1.0, 2.0]])


@pytest.mark.parametrize(
    "value, what",
    [
        (["a", "b", "c"], "dtype <U1"),
        ([None, 1.0, 2.0], "dtype object"),
        ([1j, 0, 0], "complex numbers"),
        ([True, False, True], "booleans"),
    ],
    ids=["strings", "none", "complex", "booleans"],
)
@pytest.mark.parametrize("check, name, shape, want", CHECKS, ids=ids)
def test_values_that_are_not_real_numbers_are_named(check, name, shape, want, value, what):
    with pytest.raises(ValueError, match=rf"^{name} must hold real numbers, got {what}$"):
        check(np.broadcast_to(np.array(value[:1]), shape))


@pytest.mark.parametrize("check, name, shape, want", CHECKS, ids=ids)
def test_good_input_comes_back_as_float64_with_its_batch_axes(check, name, shape, want):
    ints = np.arange(np.prod((4, 5, *shape))).reshape((4, 5, *shape))
    out = check(ints)
    assert out.dtype == np.float64 and out.shape == ints.shape
    np.testing.assert_array_equal(out, ints)
    assert check(ints.astype(np.float32)).dtype == np.float64
    floats = ints.astype(float)
    assert check(floats) is floats  # no copy of an array that is already right
    assert check(floats.tolist()).shape == floats.shape


def test_nan_and_infinity_are_not_rejected_here_they_are_row_statuses():
    p = EX1.copy()
    p[0, 0] = np.nan
    np.testing.assert_array_equal(gt.check_points(p), p)
    assert gt.decompose_off_tangent(p, [0, 0, 1], np.zeros(6)).status == gt.Status.NONFINITE_INPUT


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda: gt.decompose_off_tangent(np.zeros((3, 2)), [0, 0, 1], np.zeros(6)), r"^points must have shape"),
        (
            lambda: gt.decompose_off_tangent(EX1, [0, 1], np.zeros(6)),
            r"^wrist must have shape \(\.\.\., 3\), got \(2,\)$",
        ),
        (lambda: gt.decompose_off_tangent(EX1, [0, 0, 1], np.zeros(5)), r"^twist must have shape \(\.\.\., 6\)"),
        (
            lambda: gt.decompose_tangent(EX1, np.eye(2), np.zeros(6)),
            r"^normals must have shape \(\.\.\., 3, 3\), got \(2, 2\)$",
        ),
        (lambda: gt.decompose_tangent(EX1, "up", np.zeros(6)), r"^normals must hold real numbers, got dtype <U2$"),
        (lambda: gt.contact_velocities(EX1, [0, 0, "1", 0, 0, 0]), r"^twist must hold real numbers"),
        (lambda: gt.contact_velocities([[0, 0, 0], [1, 0]], np.zeros(6)), r"^points must have shape .*ragged"),
    ],
    ids=["points", "wrist", "twist", "normals", "normals-text", "velocity-twist", "velocity-points"],
)
def test_the_engine_functions_check_their_arguments_at_the_boundary(call, message):
    with pytest.raises(ValueError, match=message):
        call()
