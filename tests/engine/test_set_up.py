"""The grip's set-up written once (issue 39, item 1): engine/forces/set_up.py's lane form, run as it is (numba
compiles this source, each kernel row a lane of width 1) and through its numpy twins (the numpy path's
geometry, G^+ w, cones, dual twist and closure test)."""

import numpy as np
import pytest

from grasptwist.engine.forces import closure, set_up
from grasptwist.engine.forces.closure import force_closure
from grasptwist.engine.forces.grasp_map import (
    contact_matrices,
    geometry,
    grasp_map,
    manipulating_reference,
    unit_normals,
)
from grasptwist.engine.forces.ipm import START_MARGIN

WIDTH = 12


def _rows(seed=0):
    """``WIDTH`` lanes of grasps near a unit ball's equator, with the odd rows real data holds: coincident
    contacts (NaN geometry), a normal of 1e200, one of 1e-200, a zero normal, an infinite friction limit."""
    rng = np.random.default_rng(seed)
    angle = rng.uniform(0, 2 * np.pi, (WIDTH, 1)) + np.array([0, 2.1, 4.2]) + rng.normal(0, 0.3, (WIDTH, 3))
    p = np.stack((np.cos(angle), np.sin(angle), rng.normal(0, 0.3, (WIDTH, 3))), axis=-1)
    n = -p + rng.normal(0, 0.3, (WIDTH, 3, 3))
    p[1, 2] = p[1, 1]
    n[2, 0] *= 1e200
    n[3, 1] *= 1e-200
    n[4, 2] = 0.0
    limit = rng.uniform(0.3, 1.0, (WIDTH, 3))
    limit[5, 0] = np.inf
    w = np.concatenate((rng.normal(0, 1, (WIDTH, 3)), rng.normal(0, 0.5, (WIDTH, 3))), axis=1)
    return p, n, limit, w


def _lanes(a):
    return np.ascontiguousarray(np.moveaxis(a, 0, -1))


def _set_up(functions):
    """The whole set-up of :func:`_rows` through ``functions`` (the lane source or its twins): every array."""
    p, n, limit, w = (_lanes(a) for a in _rows())
    g, q, mv, sizes = np.empty((3, WIDTH)), np.empty((3, 3, WIDTH)), np.empty((3, WIDTH)), np.empty((3, WIDTH))
    e, side, unit = np.empty((3, 3, WIDTH)), np.empty((3, WIDTH)), np.empty((3, 3, WIDTH))
    fm, omega, frame, M = (
        np.empty((3, 3, WIDTH)),
        np.empty((3, WIDTH)),
        np.empty((3, 3, 3, WIDTH)),
        np.empty((3, 3, 3, WIDTH)),
    )
    A, b, twist, inside = (
        np.empty((3, 3, 3, WIDTH)),
        np.empty((3, 3, WIDTH)),
        np.empty((6, WIDTH)),
        np.empty((3, WIDTH)),
    )
    scale = np.abs(w).max(axis=0)
    blame, pulling = np.empty(WIDTH, np.int64), np.empty(WIDTH, bool)
    work = set_up.inside_workspace(WIDTH)
    with np.errstate(all="ignore"):
        functions["contact_geometry"](p, g, q, mv, sizes, WIDTH)
        functions["squeeze_directions"](p, e, side, WIDTH)
        functions["unit_normals"](n, unit, WIDTH)
        functions["manipulating"](g, q, mv, sizes, w, fm, omega, WIDTH)
        functions["twist_through"](g, q, mv, sizes, unit, twist, WIDTH)
        functions["cone_frames"](unit, limit, frame, WIDTH)
        functions["squeeze_map"](e, M, WIDTH)
        functions["cone_rows"](frame, M, fm, scale, A, b, 3, WIDTH)
        functions["internal_inside"](p, unit, mv, M, limit, inside, work, WIDTH)
        start = np.where(np.isnan(inside), 0.0, inside)  # a start from each row's squeeze, or from none
        functions["start"](A, b, start, start, 3, WIDTH)
        functions["culprit"](A, b, np.sin(np.arange(3 * WIDTH)).reshape(3, WIDTH), blame, pulling, 3, WIDTH)
    return {
        "g": g, "q": q, "m": mv, "sizes": sizes, "e": e, "side": side, "unit": unit, "fm": fm, "twist": twist,
        "frame": frame, "M": M, "A": A, "b": b, "inside": inside,
        "rows": work[7], "rays": work[8], "tilt": work[1], "start": start, "blame": blame, "pulling": pulling,
    }  # fmt: skip


SOURCE = {f.__name__: f for f in set_up.LANE_FORM}


def test_the_twins_are_the_lane_source_to_the_bit():
    """Each rewrite keeps the source's meaning on every row: an independent loop over the contacts, the pairs
    or a component runs over its whole axis at once, and no operand broadcasts along the wrong one (which
    the source run lane by lane by Python cannot do)."""
    twin, source = _set_up(set_up.twins()), _set_up(SOURCE)
    for name, value in source.items():
        np.testing.assert_array_equal(twin[name], value, err_msg=name)
    # the odd rows are there: NaN geometry of coincident contacts, a zero normal's NaN, an infinite limit's flat
    # frame, and a start inside the cones where the grasp closes
    assert np.isnan(source["sizes"][2, 1]) or source["sizes"][2, 1] == 0
    assert np.isnan(source["unit"][2, :, 4]).all() and not np.isnan(source["unit"][:, :, [2, 3]]).any()
    assert (source["frame"][0, 1:, :, 5] == 0).all()
    assert 0 < np.isfinite(source["inside"][0]).sum() < WIDTH
    assert len(set(source["blame"][np.array([r not in (1, 4) for r in range(WIDTH)])])) > 1


def test_the_set_up_meets_its_definitions():
    """Independent of its formulas: the conditioning from the eigenvalues of ``sum q q^T``, G^+ w from
    LAPACK's pseudo-inverse, the dual twist from least squares, the unit normals' directions, each cone's
    frame (``F f`` in ``Q^3`` exactly when ``|f_t| <= limit f_n``) and the start strictly inside every cone."""
    p, n, limit, w = _rows()
    out = _set_up(set_up.twins())
    good = np.array([r not in (1, 4) for r in range(WIDTH)])  # no coincident contacts, no zero normal
    q = np.moveaxis(out["q"], -1, 0)
    second = np.linalg.eigvalsh(np.einsum("nik,nil->nkl", q, q))
    t = second.sum(axis=1)
    np.testing.assert_allclose(out["sizes"][0][good], t[good], rtol=1e-12)
    np.testing.assert_allclose(out["sizes"][1][good], (q**2).sum(axis=2).max(axis=1)[good], rtol=1e-12)
    sides = np.linalg.norm(p[:, [2, 0, 1]] - p[:, [1, 2, 0]], axis=2)  # side i joins contacts j = i + 1 and k = i + 2
    np.testing.assert_allclose(out["side"].T, sides, rtol=1e-12)
    np.testing.assert_allclose(out["sizes"][2][good], np.sqrt(2 * second[good, 1] / t[good]), rtol=1e-9)
    fm = np.moveaxis(out["fm"], -1, 0)
    np.testing.assert_allclose(fm[good], manipulating_reference(p, w)[good], rtol=1e-9, atol=1e-12)
    unit = np.moveaxis(out["unit"], -1, 0)
    for r in np.flatnonzero(good):
        direction = n[r] / np.abs(n[r]).max(axis=-1, keepdims=True)
        np.testing.assert_allclose(unit[r], direction / np.linalg.norm(direction, axis=-1, keepdims=True), rtol=1e-15)
        # the twist whose field is nearest the unit normals, by least squares on G^T
        twist = np.linalg.lstsq(grasp_map(p[r]).T, unit[r].reshape(9), rcond=None)[0]
        np.testing.assert_allclose(out["twist"][:, r], twist, rtol=1e-9, atol=1e-12)
    rng = np.random.default_rng(1)
    frame = np.moveaxis(out["frame"], -1, 0)
    for r in np.flatnonzero(good):
        for i in range(3):
            f = rng.normal(size=(200, 3))
            fn = f @ unit[r, i]
            ft = np.linalg.norm(f - fn[:, None] * unit[r, i], axis=1)
            y = f @ frame[r, i].T
            inside_cone = y[:, 0] >= np.hypot(y[:, 1], y[:, 2])
            clear = np.abs(ft - limit[r, i] * fn) > 1e-9
            np.testing.assert_array_equal(inside_cone[clear], (ft <= limit[r, i] * fn)[clear])
    inside = np.moveaxis(out["inside"], -1, 0)
    M = contact_matrices(np.moveaxis(out["e"], -1, 0))
    for r in np.flatnonzero(good & np.isfinite(inside).all(axis=1)):
        f = M[r] @ inside[r]  # (3 contacts, xyz): the squeeze's forces
        fn = np.einsum("ik,ik->i", f, unit[r])
        ft = np.linalg.norm(f - fn[:, None] * unit[r], axis=1)
        assert (ft < limit[r] * fn).all()
    # the start clears every cone by START_MARGIN, the culprit is the cone left furthest, and pulling is
    # possible exactly where the normal rows are singular (LAPACK's determinant)
    A, b = np.moveaxis(out["A"], -1, 0), np.moveaxis(out["b"], -1, 0)
    start = np.moveaxis(out["start"], -1, 0)
    x = np.sin(np.arange(3 * WIDTH)).reshape(3, WIDTH).T
    for r in np.flatnonzero(good):
        if np.isfinite(inside[r]).all():
            y = A[r] @ start[r] + b[r]
            assert (y[:, 0] - np.hypot(y[:, 1], y[:, 2]) >= START_MARGIN * (1 - 1e-12)).all()
        y = A[r] @ x[r] + b[r]
        assert out["blame"][r] == np.argmax(np.hypot(y[:, 1], y[:, 2]) - y[:, 0])
        normal = A[r, :, 0, :]
        singular = not abs(np.linalg.det(normal)) > 1e-9 * np.prod(np.linalg.norm(normal, axis=1))
        assert out["pulling"][r] == singular


def test_a_squeeze_is_inside_exactly_where_the_common_friction_closes():
    """Where every contact has the friction ``mu``, a squeeze strictly inside the cones exists exactly where the
    least common friction of force closure (the bisection on the sectors' angle, not the limits' sines of
    :func:`set_up.own_sectors`) is below ``mu``: on 400 random grasps, rows within 1e-6 of it aside."""
    rng = np.random.default_rng(3)
    angle = rng.uniform(0, 2 * np.pi, (400, 1)) + np.array([0, 2.1, 4.2]) + rng.normal(0, 0.4, (400, 3))
    p = np.stack((np.cos(angle), np.sin(angle), rng.normal(0, 0.3, (400, 3))), axis=-1)
    n = -p + rng.normal(0, 0.5, (400, 3, 3))
    mu = 0.6
    least = force_closure(p, n, mu).closure_friction
    geo = geometry(p)
    inside = closure.internal_inside(p, unit_normals(n)[0], geo, np.full((400, 3), mu))
    clear = ~(np.abs(least / mu - 1) < 1e-6)
    closes = least < mu  # NaN: never
    assert 50 < closes.sum() < 350
    np.testing.assert_array_equal(np.isfinite(inside).all(axis=1)[clear], closes[clear])


@pytest.mark.slow
def test_the_compiled_set_up_is_its_twin():
    """numba's compile of the lane source (the kernel's, each row a lane) against the numpy twins on the rows the
    kernel keeps (not the coincident contacts, not the zero normal: numpy's): to round-off, as numba contracts
    ``a * b - c * d`` into one rounding (so the coincident contacts' ``m`` is not exactly 0 there)."""
    pytest.importorskip("numba")
    from grasptwist.engine.forces import kernel

    compiled, twin = _set_up(kernel._set), _set_up(set_up.twins())
    kept = np.array([r not in (1, 4) for r in range(WIDTH)])
    for name, value in twin.items():
        np.testing.assert_allclose(compiled[name][..., kept], value[..., kept], rtol=1e-12, atol=1e-14, err_msg=name)
