"""The interior-point method written once (issue 39, item 1): engine/forces/ipm.py's lane form, run as it is
(numba compiles this source) and through its numpy twin (engine/forces/_twin.py, the numpy path)."""

import ast
import inspect

import numpy as np
import pytest

from grasptwist.engine.forces import _twin, ipm, socp


def _lanes(x, y, out, K, width):
    """A lane-form function with each rewrite the twin makes: an independent loop over the cones, a sum over
    them, an augmented scalar read from an array, a choice."""
    for ln in range(width):
        for m in ipm.every(K):
            t = x[m, ln]
            t *= 2
            y[m, ln] = t if t > 1 else -t
        s = 0.0
        for m in range(K):
            s += y[m, ln]
        out[ln] = s


def test_the_twin_runs_each_lane_loop_over_every_row_at_once_with_a_scalars_meaning():
    rng = np.random.default_rng(0)
    x = rng.uniform(-1, 2, (3, 7))
    kept = x.copy()
    y, out = np.empty((3, 7)), np.empty(7)
    twin = _twin.twins([_lanes])["_lanes"]
    twin(x, y, out, 3, None)  # no lane loop left: the width is never read
    expected = np.where(2 * kept > 1, 2 * kept, -2 * kept)
    np.testing.assert_array_equal(y, expected)
    np.testing.assert_array_equal(out, expected[0] + expected[1] + expected[2])
    np.testing.assert_array_equal(x, kept)  # t *= 2 rebinds t, never writes through to x
    code = ast.unparse(_twin._Twin().visit(ast.parse(inspect.getsource(_lanes))))
    assert "every" not in code and "for ln" not in code and "for m in range(K)" in code  # the sum stays a loop
    assert "y[:, :] = np.where(t > 1, t, -t)".replace("np", "_np") in code


def _branchy(x, width):
    for ln in range(width):
        if x[ln] > 0:
            x[ln] = 0.0


def _part(x, K, width):
    for m in ipm.every(1, K):
        for ln in range(width):
            x[m, ln] = 0.0


def test_the_twin_refuses_a_branch_and_a_part_of_an_axis_in_lane_form():
    with pytest.raises(ValueError, match="lane form has no If"):
        _twin.twins([_branchy])
    with pytest.raises(ValueError, match="every"):  # m a full slice would run over the whole axis
        _twin.twins([_part])


def _problem(rng, K, k, d, n):
    """Random strictly feasible rows ``(a, b, c, x, z)`` in lane form: ``b`` deep inside the cones at ``x = 0``,
    the dual start ``z_m = e`` and ``c = sum_m A_m^T e`` (phase II's start)."""
    a = rng.normal(size=(K, k, d, n))
    b = rng.normal(size=(K, k, n))
    b[:, 0] = np.sqrt((b[:, 1:] ** 2).sum(axis=1)) + rng.uniform(0.5, 2, (K, n))
    z = np.zeros((K, k, n))
    z[:, 0] = 1.0
    return a, b, a[:, 0].sum(axis=0), np.zeros((d, n)), z


@pytest.mark.parametrize(("K", "k", "d"), [(3, 3, 3), (4, 4, 7), (5, 1, 2)])  # Q3 grips, soft Q4 phase I, rays
def test_the_numpy_twin_steps_as_the_lane_source_run_by_python(K, k, d):
    """Five Mehrotra steps on six random rows of each cone size: the twin (numpy, all rows at once) and the
    lane-form source run by Python element by element (as numba runs it, lane by lane) move ``x`` and ``z``
    alike to round-off and stop the same rows."""
    n = 6
    a, b, c, x, z = _problem(np.random.default_rng(K * k * d), K, k, d, n)
    P = np.empty((K, d, d, n))
    ipm.newton_part(a, P, d, K, k, n)
    twin = socp._twins()
    P2 = np.empty_like(P)
    twin["newton_part"](a, P2, d, K, k, n)
    np.testing.assert_allclose(P2, P, rtol=1e-14, atol=1e-14)
    x2, z2 = x.copy(), z.copy()
    done, done2 = np.zeros(n, bool), np.zeros(n, bool)
    with np.errstate(all="ignore"):
        for _ in range(5):
            ipm.step(a, b, c, x, z, P, False, ipm.workspace(d, K, k, n), done, d, K, k, n)
            twin["step"](a, b, c, x2, z2, P, False, ipm.workspace(d, K, k, n), done2, d, K, k, n)
            np.testing.assert_allclose(x2, x, rtol=1e-12, atol=1e-12)
            np.testing.assert_allclose(z2, z, rtol=1e-12, atol=1e-12)
            assert (done2 == done).all()
    assert np.isfinite(x).all() and (c * x).sum(axis=0).min() < 0  # the steps went somewhere: the objective fell


def test_the_lane_source_solves_what_socp_solves():
    """socp.minimise (the twin, with its driver) reaches the optimum the lane source reaches run to the end."""
    K, k, d, n = 3, 4, 3, 4
    a, b, c, x, z = _problem(np.random.default_rng(5), K, k, d, n)
    P = np.empty((K, d, d, n))
    ipm.newton_part(a, P, d, K, k, n)
    done = np.zeros(n, bool)
    ended = np.zeros(n, bool)
    with np.errstate(all="ignore"):
        for _ in range(ipm.ITERATIONS):
            xs, zs = x.copy(), z.copy()
            ipm.step(a, b, c, x, z, P, False, ipm.workspace(d, K, k, n), done, d, K, k, n)
            x[:, ended], z[..., ended] = xs[:, ended], zs[..., ended]  # a row that is done stays
            ended |= done
            if ended.all():
                break
    assert ended.all()
    A, bb = a.transpose(3, 0, 1, 2), b.transpose(2, 0, 1)
    s, _ = socp.minimise(A, bb, c.T, np.zeros((n, d)))
    np.testing.assert_allclose(s, x.T, rtol=1e-12, atol=1e-12)
