"""The engine's ways to the same numbers.

* The small-batch path (a row at a time in plain floats) against the chunked
  path (numpy arrays over rows): the same statuses, culprits and bits, on
  random grasps and on grasps with every degenerate condition.
* ``resolve`` (both methods at once) against the separate calls.
* A prepared grasp against fresh calls, for single twists and batches.
"""

from dataclasses import fields

import numpy as np
import pytest

import grasptwist as gt
from grasp_gen import grasps, in_plane
from grasptwist.engine.decompose import CHUNK, SMALL_BATCH

S = gt.Status
EX1 = np.array([[1, 0, 0], [-0.5, 0.866, 0], [-0.5, -0.866, 0]], float)
EX2 = np.array([[0, 2, 2], [2, 0, 2], [2, 2, 0]], float)
RIGHT = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float)
N = np.array([[1, 0.3, 0.5], [-1, 0.2, 0.6], [0.1, -1, 0.4]])  # clear of every tangent degeneracy
UP = np.array([0.1, 0.2, 1.0])
TWIST = np.array([0.3, -0.2, 1.0, 0.1, 0.5, -0.4])
nan, inf = np.nan, np.inf

# (points, normals, wrist, twist): each degenerate condition, several of them exact
# (a division by an exact zero, which the float path hands to numpy scalars)
DEGENERATE = [
    (EX1, N, [0, 0, 0], TWIST),  # wrist-coplanar, exactly
    (EX1, N, [0.3, 0.2, 1e-12], TWIST),  # wrist-coplanar within tolerance
    ([[0, 0, 0], [1, 0, 0], [1, 0, 0]], N, UP, TWIST),  # coincident contacts
    ([[2, 2, 2]] * 3, N, UP, TWIST),  # all three coincide
    ([[0, 0, 0], [1, 0, 0], [3, 0, 0]], N, UP, TWIST),  # collinear
    ([[0, 0, 0], [1, 0, 0], [0.5, 1e-12, 0]], N, UP, TWIST),  # collinear within tolerance
    (EX1, N, [0, nan, 1], TWIST),  # non-finite wrist
    ([[1, 0, inf], [-0.5, 0.866, 0], [-0.5, -0.866, 0]], N, UP, TWIST),  # non-finite point
    (EX1, N, UP, [0, 0, nan, 0, 0, 0]),  # non-finite twist
    (EX1, [[nan, 0, 0], [0, 1, 0], [0, 0, 1]], UP, TWIST),  # non-finite normal
    (EX1 * 1e200, N, UP * 1e200, [1e200, 0, 0, 0, 0, 0]),  # overflow
    (EX2 * 1e100, np.eye(3), [0, 0, 1e300], [0, 0, 1e300, 0, 0, 0]),  # overflow of the amplitudes alone
    (EX2, [[1, 0, 0], [0, 0, 0], [0, 0, 1]], UP, TWIST),  # zero normal
    (EX1, -EX1, UP, TWIST),  # normal lines of rank 2
    ([[-1, 0, 0], [1, 0, 0], [0, 1, 0.5]], [[1, 0, 0], [-1, 0, 0], [0, -1, 0]], UP, TWIST),  # antipodal pinch
    (RIGHT, [[0, 0, 1], [0, 1, 0], [1, 0, 0]], UP, TWIST),  # Theta_1 not unique
    (RIGHT, [[0, 0, 1], [0, 1, 1.5e-9], [1, 0, 1]], UP, TWIST),  # [Theta_1|Sigma_1] = 0
    (RIGHT, [[0, 0, 1], [0, 0, 1], [1, 0.3, 0]], UP, TWIST),  # a normal exactly in the contacts' plane
]


@pytest.fixture(scope="module")
def batch():
    """Random grasps at several scales, nearly degenerate ones, and every degenerate condition."""
    rng = np.random.default_rng(5)
    parts = [grasps(rng, 40, scale=s) for s in (1e-3, 1.0, 1e3)]
    p, n, c, t = (np.concatenate(a) for a in zip(*parts))
    near = grasps(rng, 400)
    which = rng.integers(0, 3, 400)
    near_n = in_plane(near[0], near[1], which, rng.choice([0.0, 1e-12, 1e-9, 1e-6, 1e-4], 400))
    degenerate = [np.array([np.broadcast_to(np.asarray(row[k], float), shape) for row in DEGENERATE])
                  for k, shape in enumerate([(3, 3), (3, 3), (3,), (6,)])]  # fmt: skip
    return tuple(np.concatenate(a) for a in zip((p, n, c, t), (near[0], near_n, near[2], near[3]), degenerate))


def assert_same(a, b, where=""):
    """Two results (or two Resolutions) hold the same fields, bit for bit (NaN equal to NaN)."""
    if isinstance(a, np.ndarray) or a is None:
        np.testing.assert_array_equal(a, b, err_msg=where)
        return
    if isinstance(a, gt.Resolution):
        for name in a._fields:
            assert_same(getattr(a, name), getattr(b, name), f"{where} {name}")
        return
    assert type(a) is type(b)
    for f in fields(a):
        np.testing.assert_array_equal(getattr(a, f.name), getattr(b, f.name), err_msg=f"{where} {f.name}")
    np.testing.assert_array_equal(a.residual, b.residual, err_msg=f"{where} residual")


def test_the_batch_holds_every_status_of_each_method(batch):
    p, n, c, t = batch
    r = gt.resolve(p, n, c, t)
    assert set(np.unique(r.off_tangent.status)) == {
        S.OK, S.NONFINITE_INPUT, S.COINCIDENT_CONTACTS, S.COLLINEAR_CONTACTS, S.WRIST_COPLANAR, S.OVERFLOW
    }  # fmt: skip
    # no-wrist marks the rows of grasps without a wrist in a batch of records; the last four are a hand's
    hands = {S.FINGER_CANNOT_FOLLOW, S.CONTACT_OFF_FINGER, S.UNREACHABLE, S.OUTSIDE_LIMITS}
    assert set(np.unique(r.tangent.status)) == set(S) - {S.WRIST_COPLANAR, S.NO_WRIST, S.NONFINITE_POSE} - hands
    assert len(p) > SMALL_BATCH


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_one_row_at_a_time_gives_the_chunked_paths_bits(batch):
    p, n, c, t = batch
    chunked = gt.resolve(p, n, c, t)
    for i in range(len(p)):
        one = gt.resolve(p[i], n[i], c[i], t[i])  # no batch axis: the small-batch path
        assert_same(one.off_tangent, chunked.off_tangent.row(i), f"row {i}")
        assert_same(one.tangent, chunked.tangent.row(i), f"row {i}")
        np.testing.assert_array_equal(one.velocity, chunked.velocity[i])


def test_a_handful_of_rows_gives_the_chunked_paths_bits(batch):
    p, n, c, t = batch
    chunked = gt.resolve(p, n, c, t)
    for start in range(0, len(p), SMALL_BATCH):
        rows = slice(start, start + SMALL_BATCH)
        small = gt.resolve(p[rows], n[rows], c[rows], t[rows])
        for name in ("off_tangent", "tangent"):
            got, want = getattr(small, name), getattr(chunked, name)
            for field in [f.name for f in fields(want)] + ["residual"]:
                np.testing.assert_array_equal(getattr(got, field), getattr(want, field)[rows], err_msg=field)


def test_resolve_gives_the_separate_calls_bits_on_both_paths(batch):
    p, n, c, t = batch
    for rows in (slice(None), slice(0, 3), 5):
        r = gt.resolve(p[rows], n[rows], c[rows], t[rows])
        assert_same(r.off_tangent, gt.decompose_off_tangent(p[rows], c[rows], t[rows]))
        assert_same(r.tangent, gt.decompose_tangent(p[rows], n[rows], t[rows]))
        np.testing.assert_array_equal(r.velocity, gt.contact_velocities(p[rows], t[rows]))
    lean = gt.resolve(p, n, None, t, bases=False)
    assert lean.off_tangent is None and lean.tangent.theta is None
    np.testing.assert_array_equal(lean.tangent.alpha, gt.decompose_tangent(p, n, t).alpha)


def test_broadcasting_and_chunks_do_not_change_a_rows_bits():
    rng = np.random.default_rng(2)
    p, n, c, t = grasps(rng, 1, scale=10.0)
    twists = rng.normal(size=(CHUNK + 5, 6))  # one grasp, more twists than a chunk
    many = gt.resolve(p[0], n[0], c[0], twists)
    for i in (0, CHUNK - 1, CHUNK, CHUNK + 4):
        assert_same(many.tangent.row(i), gt.decompose_tangent(p[0], n[0], twists[i]), f"twist {i}")
        assert_same(many.off_tangent.row(i), gt.decompose_off_tangent(p[0], c[0], twists[i]), f"twist {i}")
    empty = gt.resolve(np.zeros((0, 3, 3)), np.zeros((0, 3, 3)), np.zeros((0, 3)), np.zeros(6))
    assert empty.tangent.alpha.shape == (0, 3) and empty.off_tangent.sigma.shape == (0, 3, 6)


# --- prepared grasps ---------------------------------------------------------------


def _close(got, want, scale):
    """``|got - want| <= 1e-12 * scale`` where ``want`` is finite, equal elsewhere (NaN, infinities)."""
    finite = np.isfinite(want)
    np.testing.assert_array_equal(got[~finite], want[~finite])
    assert np.all(np.abs(got[finite] - want[finite]) <= 1e-12 * np.broadcast_to(scale, want.shape)[finite])


def _compare_prepared(got, fresh):
    """A prepared grasp's Resolution against fresh calls': equal verdicts and bases, close numbers."""
    for name in ("off_tangent", "tangent"):
        g, f = getattr(got, name), getattr(fresh, name)
        if f is None:
            assert g is None
            continue
        exact = (
            "status",
            "culprit",
            "conditioning",
            "sigma",
            "psi",
            "sigma_psi",
            "theta",
            "theta_sigma",
            "in_tangent_planes",
        )
        for k in exact:
            if hasattr(f, k):
                np.testing.assert_array_equal(getattr(g, k), getattr(f, k), err_msg=f"{name}.{k}")
        amplitudes = ("x", "y") if name == "off_tangent" else ("alpha", "beta", "normal_velocity")
        scale = np.max(
            np.abs(np.concatenate([np.nan_to_num(getattr(f, a)) for a in amplitudes], -1)), -1, keepdims=True
        )
        for a in amplitudes:
            _close(getattr(g, a), getattr(f, a), scale)
    speed = np.max(np.abs(np.nan_to_num(fresh.velocity)), axis=(-1, -2), keepdims=True)
    _close(got.velocity, fresh.velocity, speed)


def test_a_prepared_grasp_resolves_single_twists_and_batches_as_fresh_calls_do():
    rng = np.random.default_rng(9)
    p, n, c, _ = grasps(rng, 12, scale=3.0)
    twists = rng.normal(size=(40, 6)) * [1, 1, 1, 3, 3, 3]
    for i in range(len(p)):
        g = gt.prepare(p[i], n[i], c[i])
        _compare_prepared(g.resolve(twists), gt.resolve(p[i], n[i], c[i], twists))
        for k in range(3):
            one = g.resolve(twists[k])
            _compare_prepared(one, gt.resolve(p[i], n[i], c[i], twists[k]))
        assert g.resolve(twists[:6].reshape(2, 3, 6)).tangent.alpha.shape == (2, 3, 3)


@pytest.mark.parametrize("row", range(len(DEGENERATE)))
def test_a_prepared_degenerate_grasp_carries_the_fresh_calls_statuses(row):
    p, n, c, t = (np.asarray(a, float) for a in DEGENERATE[row])
    twists = np.array([t, TWIST, np.zeros(6), [0, 0, inf, 0, 0, 0], [1e307, 0, 0, 0, 0, 0]])
    g = gt.prepare(p, n, c)
    _compare_prepared(g.resolve(twists), gt.resolve(p, n, c, twists))
    for tw in twists:
        _compare_prepared(g.resolve(tw), gt.resolve(p, n, c, tw))


def test_prepared_results_without_a_wrist_share_read_only_bases():
    g = gt.prepare(EX2, np.eye(3))
    a, b = g.resolve([1, 0, 0, 0, 0, 0]), g.resolve([0, 1, 0, 0, 0, 0])
    assert a.off_tangent is None and g.off_tangent is None and g.map.shape == (18, 6)
    assert a.tangent.theta is b.tangent.theta and not a.tangent.theta.flags.writeable
    np.testing.assert_array_equal(a.tangent.theta, gt.decompose_tangent(EX2, np.eye(3), np.zeros(6)).theta)
    with pytest.raises(ValueError, match="read-only"):
        a.tangent.theta[0, 0] = 1.0


def test_prepare_takes_one_grasp_and_checks_its_arguments():
    with pytest.raises(
        ValueError, match=r"^prepare takes one grasp: points must have no batch axis, got shape \(2, 3, 3\)$"
    ):
        gt.prepare(np.stack([EX1, EX1]), np.eye(3), UP)
    with pytest.raises(ValueError, match=r"^prepare takes one grasp: wrist must have no batch axis"):
        gt.prepare(EX1, np.eye(3), [UP, UP])
    with pytest.raises(ValueError, match=r"^normals must have shape \(\.\.\., 3, 3\), got \(3,\)$"):
        gt.prepare(EX1, [0, 0, 1], UP)
    with pytest.raises(ValueError, match=r"^twist must have shape \(\.\.\., 6\), got \(3,\)$"):
        gt.prepare(EX1, np.eye(3), UP).resolve([0, 0, 1])
