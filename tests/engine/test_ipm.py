"""The interior-point method written once (issue 39, item 1): engine/forces/ipm.py's lane form, run as it is
(numba compiles this source) and through its numpy twin (engine/forces/_twin.py, the numpy path)."""

import ast
import inspect

import numpy as np
import pytest

from grasptwist.engine.forces import _twin, ipm, one, socp


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


def test_the_float_twin_refuses_what_one_number_in_python_floats_cannot_mean():
    def branchy(x, width):
        for ln in range(width):
            if x[ln] > 0:
                x[ln] = 0.0

    def sliced(x, out, width):
        for ln in range(width):
            out[0, ln] = x[:, 0, ln]

    def batched(x, width):
        for ln in range(width):
            x[0, ln] = np.einsum("i,i", x, x)

    def bare(x, width):
        for ln in range(width):
            x[0, ln] = np.pi

    with pytest.raises(ValueError, match="lane form has no If"):
        _twin.floats([branchy])
    with pytest.raises(ValueError, match="no slice"):
        _twin.floats([sliced])
    with pytest.raises(ValueError, match=r"no np\.einsum"):
        _twin.floats([batched])
    with pytest.raises(ValueError, match=r"no np\.pi"):
        _twin.floats([bare])


def test_the_float_twin_is_the_lane_source_on_one_row_of_nested_lists():
    """The float twin's source: no lane loop, ``X[i, j, ln]`` as ``X[i][j]``, a lone lane index and a helper's
    lane argument as ``0``, ``every`` as ``range``, numpy's scalar calls as math's and the builtins."""
    made = one._twin()
    update, column = made["_update"].__source__, made["_column"].__source__
    assert "for ln" not in update and "np." not in update and "every" not in update
    assert "good = good & _isfinite(dz[m][i])" in update
    assert "done[0] = (not good) | closed | phase_one & found" in update
    assert "size += abs(x[j])" in update and "big = max(big, abs(res[j]))" in update
    assert "t = a[m][0][j] * u[m][0]" in column
    assert "each[m] = _column(a, z, m, j, k, 0)" in made["_residual"].__source__


@pytest.mark.parametrize(("K", "k", "d"), [(3, 3, 3), (4, 4, 7), (5, 1, 2)])  # Q3 grips, soft Q4 phase I, rays
def test_the_float_twin_steps_as_the_numpy_twin_row_by_row(K, k, d):
    """Five Mehrotra steps on three random rows of each cone size, phase II and phase I's rules: the float twin
    (one row in nested lists, what one.py runs) moves ``x`` and ``z`` as the numpy twin does to 1e-12."""
    n = 3
    a, b, c, x, z = _problem(np.random.default_rng(K + k + d), K, k, d, n)
    P = np.empty((K, d, d, n))
    numpy_twin, float_twin = socp._twins(), one._twin()
    numpy_twin["newton_part"](a, P, d, K, k, n)
    for phase_one in (False, True):
        xs, zs, done = x.copy(), z.copy(), np.zeros(n, bool)
        rows = [
            [a[..., r].tolist(), b[..., r].tolist(), c[:, r].tolist(), x[:, r].tolist(), z[..., r].tolist()]
            for r in range(n)
        ]
        with np.errstate(all="ignore"):
            for _ in range(5):
                numpy_twin["step"](a, b, c, xs, zs, P, phase_one, ipm.workspace(d, K, k, n), done, d, K, k, n)
                for r, (ar, br, cr, xr, zr) in enumerate(rows):
                    work, ended = _twin.float_workspace(ipm.workspace(d, K, k, 1)), [None]
                    float_twin["step"](ar, br, cr, xr, zr, one.newton_matrices(ar), phase_one, work, ended, d, K, k, 1)
                    np.testing.assert_allclose(xr, xs[:, r], rtol=1e-12, atol=1e-12)
                    np.testing.assert_allclose(zr, zs[..., r], rtol=1e-12, atol=1e-12)
                    assert ended[0] == done[r]
        assert (c * xs).sum(axis=0).min() < (c * x).sum(axis=0).min()  # the steps went somewhere


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


@pytest.mark.parametrize("phase", ["phase I", "phase II"])
def test_a_row_is_the_same_to_the_bit_alone_in_floats_and_in_a_batch_through_numpy(phase):
    """socp iterates up to ALONE rows through the float twin, more through the numpy twin: the same operations
    in the same order on the same doubles, so a row's answer does not depend on its company (a power ``** 3``
    had differed in the last bit between the two, 4e-11 after the iterations)."""
    K, k, d = 4, 4, 7
    a, b, c, x, z = _problem(np.random.default_rng(11), K, k, d, socp.ALONE + 1)
    A, bb = a.transpose(3, 0, 1, 2), b.transpose(2, 0, 1)
    if phase == "phase I":
        bb = bb - 3.0  # most rows start outside their cones
        few, many = socp.phase_one(A[: socp.ALONE], bb[: socp.ALONE]), socp.phase_one(A, bb)
    else:
        few = socp.minimise(A[: socp.ALONE], bb[: socp.ALONE], c.T[: socp.ALONE], x.T[: socp.ALONE])
        many = socp.minimise(A, bb, c.T, x.T)
    for alone, batched in zip(few, many, strict=True):
        np.testing.assert_array_equal(alone, batched[: socp.ALONE])


@pytest.mark.parametrize("n", [socp.ALONE, socp.ALONE + 4], ids=["floats", "numpy"])
def test_the_lane_source_solves_what_socp_solves(n):
    """socp.minimise (its driver, and the float twin row by row up to ALONE rows, else the numpy twin) reaches
    the optimum the lane source reaches run to the end."""
    K, k, d = 3, 4, 3
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


@pytest.mark.parametrize(("K", "k", "d"), [(3, 3, 3), (4, 4, 7), (5, 1, 2)])
def test_phase_ones_problem_is_written_once(K, k, d):
    """ipm.widened, phase I's problem, which socp (numpy twin), one.py (float twin) and the kernel (compiled) all
    make: its definition (each cone widened by the margin r, the cone r + 1 >= 0, the objective r, the start
    clearing every cone by 1) on random rows, and the float twin's the numpy twin's to the bit."""
    n = 4
    a, b, _, _, _ = _problem(np.random.default_rng(K * k * d), K, k, d, n)
    b[:, 0] -= 3.0  # some cones not holding at x = 0: the start's margin positive
    wide, bw, c = np.empty((K + 1, k, d + 1, n)), np.empty((K + 1, k, n)), np.empty((d + 1, n))
    x, z = np.empty((d + 1, n)), np.empty((K + 1, k, n))
    socp._twins()["widened"](a, b, wide, bw, c, x, z, d, K, k, n)
    np.testing.assert_array_equal(wide[:K, :, :d], a)
    np.testing.assert_array_equal(wide[:, 0, d], 1.0)
    assert (wide[:, 1:, d] == 0).all() and (wide[K, :, :d] == 0).all() and (wide[K, 1:] == 0).all()
    np.testing.assert_array_equal(bw[:K], b)
    assert bw[K, 0].tolist() == [1.0] * n and (bw[K, 1:] == 0).all()
    assert (c[:d] == 0).all() and (c[d] == 1).all() and (x[:d] == 0).all()
    over = (np.sqrt((b[:, 1:] ** 2).sum(axis=1)) - b[:, 0]).max(axis=0)
    np.testing.assert_allclose(x[d], np.maximum(over + 1, 0), rtol=1e-15)
    assert (x[d] > 0).any()
    assert (z[:, 0] == 0.25).all() and (z[:, 1:] == 0).all()
    for r in range(n):
        rows = [[[0.0] * (d + 1) for _ in range(k)] for _ in range(K + 1)], [[0.0] * k for _ in range(K + 1)]
        cr, xr, zr = [0.0] * (d + 1), [0.0] * (d + 1), [[0.0] * k for _ in range(K + 1)]
        one._twin()["widened"](a[..., r].tolist(), b[..., r].tolist(), *rows, cr, xr, zr, d, K, k, 1)
        assert rows[0] == wide[..., r].tolist() and rows[1] == bw[..., r].tolist()
        assert (cr, xr, zr) == (c[:, r].tolist(), x[:, r].tolist(), z[..., r].tolist())
