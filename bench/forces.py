"""Force-side speed: the engine against Clarabel called directly, on the same grasps, in one run.

Run: ``python bench/forces.py [--n 100000] [--loop 1000] [--closure-loop 100] [--single 300] [--epsilon 200]
[--soft 20000]``.

Grasps: three contacts near a unit ball's equator, normals towards its centre tilted at
random, one friction per grasp (0.4..1), the wrench that holds a 0.2..2 kg weight plus a
disturbing moment; safety 1.5.  Baselines are Clarabel through its own Python API
(tests/conic.py: the nine contact-force numbers, no modelling layer), one grasp a call:

- **single calls** (medians of wall time): ``gt.grip`` on one grasp, a prepared grasp's
  ``.grip(wrench)`` for new wrenches, and one Clarabel solve with its set-up;
- **batched** (CPU time a grasp, the median of three calls): ``gt.grip`` on ``n`` grasps at once against a loop of
  Clarabel solves over the first ``--loop`` grasps, scaled; ``gt.forces.force_closure``'s closure
  friction against a bisection of Clarabel closure-margin solves (``--closure-loop``);
  Ferrari-Canny epsilon against the bare ``scipy.spatial.ConvexHull`` calls it makes;
- **agreement** on the loop's grasps: verdicts, total normal force, closure friction;
  on all: the wrench reproduced, the largest friction used over the cone's, and the
  certificates (dual gap, Farkas ``y . w > 0``).

**Soft fingers** (``torsion`` 1 cm, the first ``--soft`` grasps): batched and single calls on each path,
the batch's CPU split into the set-up in numpy (``B = [G'; E]`` and its SVD) and the interior-point
iterations (compiled where numba is on), and the compiled path held to the numpy one.

**The edge** (single calls, medians): a 1 kg tray held from below by three fingers (5 cm, normals
up, mu 0.5) whose centre of mass lies on the line of two of them, so the third carries exactly
nothing (no grip strictly inside the cones: facial reduction), against the same with 1 mN m more.

The grip's figures come twice where numba is installed (the ``fast`` extra): compiled, then on
the numpy path (``GRASPTWIST_NUMBA=0``'s), with the two held to each other.  The compiled
kernel is loaded (or compiled, on a fresh install) before any timing; that first call is printed.
"""

import argparse
import contextlib
import pathlib
import statistics
import sys
import time

import numpy as np

import grasptwist as gt
from grasptwist.engine.forces import compiled

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "tests"))
from conic import closure_friction, least_grip  # noqa: E402

SAFETY = 1.5


def grasps(n, seed=0):
    rng = np.random.default_rng(seed)
    angle = rng.uniform(0, 2 * np.pi, (n, 1)) + np.array([0, 2.1, 4.2]) + rng.normal(0, 0.3, (n, 3))
    p = np.stack((np.cos(angle), np.sin(angle), rng.normal(0, 0.3, (n, 3))), axis=-1)
    normals = -p + rng.normal(0, 0.3, (n, 3, 3))
    mass = rng.uniform(0.2, 2.0, n)
    wrench = np.concatenate((np.zeros((n, 2)), 9.81 * mass[:, None], rng.normal(0, 0.5, (n, 3))), axis=1)
    friction = rng.uniform(0.4, 1.0, (n, 1))
    return p, normals, wrench, friction


def agreement(a, b):
    """How two grips of the same grasps agree: statuses and culprits, and totals where ``b`` holds."""
    same = ((a.status == b.status) & (a.culprit == b.culprit)).mean()
    diff = np.abs(a.total_normal_force[b.ok] / b.total_normal_force[b.ok] - 1).max()
    return f"same status and culprit {same:.3%}, total normal force max rel diff {diff:.1e}"


def median_us(call, count):
    """Median wall time of ``call(i)`` for ``i < count``, in microseconds."""
    times = []
    for i in range(count):
        t = time.perf_counter()
        call(i)
        times.append(time.perf_counter() - t)
    return 1e6 * statistics.median(times)


def cpu(call):
    """``(result, CPU seconds)`` of ``call()``."""
    t = time.process_time()
    out = call()
    return out, time.process_time() - t


def paths():
    """``(name, context)`` of the grip's paths: compiled first where numba is installed, then numpy."""
    out = [("numpy", compiled.numpy_path)]
    if compiled.kernel() is not None:
        out.insert(0, ("compiled", contextlib.nullcontext))
    return out


def single(p, n, w, mu, count):
    clarabel = median_us(lambda i: least_grip(p[i], n[i], w[i], mu[i], SAFETY), count)
    for name, path in paths():
        with path():
            one = median_us(lambda i: gt.grip(p[i], n[i], w[i], mu[i], safety=SAFETY), count)
            hand = gt.prepare_grip(p[0], n[0], mu[0], safety=SAFETY)
            prepared = median_us(lambda i, hand=hand: hand.grip(w[i]), count)
        print(
            f"single calls, {name} (median of {count}): gt.grip {one:.0f} us, prepared .grip(wrench) {prepared:.0f} us, "
            f"Clarabel direct {clarabel:.0f} us; gt.grip is {clarabel / one:.2f}x Clarabel, prepared {clarabel / prepared:.2f}x"
        )


def edge(count):
    """The grip's cliff (issue 39): a weight whose grip exists only on the cones' edge, against a clean row."""
    p = 0.05 * np.array([[1, 0, 0], [-0.5, 0.75**0.5, 0], [-0.5, -(0.75**0.5), 0]])
    up = np.array([[0, 0, 1.0]] * 3)
    w = np.concatenate(([0, 0, 9.81], np.cross([-0.025, 0, 0], [0, 0, 9.81])))
    for name, path in paths():
        with path():
            times = [median_us(lambda i, v=v: gt.grip(p, up, v, 0.5), count) for v in (w, w + [0, 0, 0, 0, -1e-3, 0])]
        print(
            f"the edge, {name}: a weight held on the cones' edge {times[0]:.0f} us, with 1 mN m about y more (its centre of mass 0.1 mm inside: a clean row) {times[1]:.0f} us"
        )


def batched(p, n, w, mu, k, kc):
    size = len(p)
    refs, t_loop = cpu(lambda: [least_grip(p[i], n[i], w[i], mu[i], SAFETY)[0] for i in range(k)])
    ref_closure, t_bisect = cpu(lambda: np.array([closure_friction(p[i], n[i]) for i in range(kc)]))
    per = (t_loop / k, t_bisect / kc)
    grips = {}
    for name, path in paths():
        with path():  # three calls, each result let go: the first also pays the page faults of new memory
            runs = [cpu(lambda: gt.grip(p, n, w, mu, safety=SAFETY))[1] for _ in range(3)]
            grips[name] = gt.grip(p, n, w, mu, safety=SAFETY)
        t_first, t_grip = runs[0], statistics.median(runs)
        print(
            f"grip, {size} grasps, {name}: {1e6 * t_grip / size:.1f} us a grasp (CPU, median of 3 calls; the first "
            f"{1e6 * t_first / size:.1f}), Clarabel loop ({k} grasps) {1e6 * per[0]:.0f} us a grasp: "
            f"{per[0] * size / t_grip:.0f}x; held {grips[name].ok.mean():.1%}"
        )
    if len(grips) == 2:
        print(f"compiled against numpy, all {size}: {agreement(grips['compiled'], grips['numpy'])}")
    c, t_closure = cpu(lambda: gt.forces.force_closure(p, n, mu))
    print(
        f"closure friction, {size} grasps: engine {1e6 * t_closure / size:.1f} us a grasp (CPU), Clarabel bisection "
        f"({kc} grasps, 46 solves each) {1e3 * per[1]:.1f} ms a grasp: {per[1] * size / t_closure:.0f}x; "
        f"force closure {c.force_closure.mean():.1%}"
    )
    solved = np.array([r is not None for r in refs])
    ref = np.array([r for r in refs if r is not None])
    finite = np.isfinite(ref_closure)
    crel = np.abs(c.closure_friction[:kc][finite] / ref_closure[finite] - 1).max()
    print(
        f"closure friction against Clarabel's on the loop's grasps: max rel diff {crel:.1e}, none-ness "
        f"{(np.isnan(c.closure_friction[:kc]) == ~finite).mean():.2%}"
    )
    for name, g in grips.items():
        rel = np.abs(g.total_normal_force[:k][solved] / ref - 1).max()
        ok, bad = g.ok, g.status == gt.forces.Status.CANNOT_HOLD
        made = np.concatenate((g.force[ok].sum(axis=1), np.cross(p[ok], g.force[ok]).sum(axis=1)), axis=1)
        gap = np.abs(g.gap[ok]) / g.total_normal_force[ok]
        yw = np.einsum("ni,ni->n", g.certificate[bad], w[bad])
        print(
            f"{name}: against Clarabel on the loop's grasps held/cannot-hold {(g.ok[:k] == solved).mean():.2%}, total "
            f"normal force max rel diff {rel:.1e}; all {size}: wrench reproduced to "
            f"{np.abs(made - w[ok]).max() / np.abs(w).max():.1e} (relative), largest friction_used / (mu / safety) "
            f"{(g.friction_used[ok] / (mu[ok] / SAFETY)).max():.12f}; dual gap / total: median {np.median(gap):.1e}, "
            f"largest {gap.max():.1e}; Farkas y . w > 0 on {(yw > 0).mean():.2%} of {bad.sum()} cannot-hold"
        )


def _timing(module, name, spent):
    """``module.name`` wrapped to add its CPU time to ``spent[name]`` (a context)."""
    f = getattr(module, name)

    def timed(*args, **kwargs):
        t = time.process_time()
        try:
            return f(*args, **kwargs)
        finally:
            spent[name] = spent.get(name, 0.0) + time.process_time() - t

    @contextlib.contextmanager
    def context():
        setattr(module, name, timed)
        try:
            yield
        finally:
            setattr(module, name, f)

    return context()


def soft(p, n, w, mu, m, count):
    """Soft fingers (torsional radius 1 cm) on the first ``m`` grasps, batched and single, each path; the batch's
    CPU split into the set-up in numpy (``cones.cone_grasp``: B and its SVD) and the interior-point iterations
    (``socp``'s, compiled where numba is on)."""
    from grasptwist.engine.forces import cones, socp

    p, n, w, mu = p[:m], n[:m], w[:m], mu[:m]
    _, first = cpu(lambda: gt.grip(p[:2], n[:2], w[:2], mu[:2], safety=SAFETY, torsion=0.01))
    if compiled.iteration() is not None:
        print(
            f"first soft grip (numba loads its cached iterations, or compiles them on a fresh install): {first:.2f} s"
        )
    grips, times = {}, {}
    for name, path in paths():
        with path():
            runs = []
            for _ in range(3):
                spent = {}
                with _timing(cones, "cone_grasp", spent), _timing(socp, "_iterated", spent):
                    g, t = cpu(lambda: gt.grip(p, n, w, mu, safety=SAFETY, torsion=0.01))
                runs.append((t, spent))
            grips[name] = g
            t, spent = sorted(runs, key=lambda r: r[0])[1]
            one = median_us(lambda i: gt.grip(p[i], n[i], w[i], mu[i], safety=SAFETY, torsion=0.01), count)
        times[name] = (t, one)
        print(
            f"soft grip (torsion 1 cm), {m} grasps, {name}: {1e6 * t / m:.1f} us a grasp (CPU, median of 3 calls): "
            f"set-up (B, SVD) {1e6 * spent['cone_grasp'] / m:.1f}, iterations {1e6 * spent['_iterated'] / m:.1f}, "
            f"the rest {1e6 * (t - spent['cone_grasp'] - spent['_iterated']) / m:.1f}; single gt.grip {one:.0f} us "
            f"(median of {count}); held {g.ok.mean():.1%}"
        )
    if len(grips) == 2:
        print(
            f"soft, compiled against numpy: batched {times['numpy'][0] / times['compiled'][0]:.2f}x, single "
            f"{times['numpy'][1] / times['compiled'][1]:.1f}x; {agreement(grips['compiled'], grips['numpy'])}"
        )


def epsilon(p, n, mu, m):
    """The engine's epsilon against the bare ``ConvexHull`` calls it makes (timed inside the same run)."""
    import scipy.spatial

    hull = scipy.spatial.ConvexHull
    spent = []

    def timed(*args, **kwargs):
        t = time.process_time()
        try:
            return hull(*args, **kwargs)
        finally:
            spent.append(time.process_time() - t)

    scipy.spatial.ConvexHull = timed
    try:
        e, t_engine = cpu(lambda: gt.forces.force_closure(p[:m], n[:m], mu[:m], quality=True))
    finally:
        scipy.spatial.ConvexHull = hull
    hulls = len(spent)
    print(
        f"epsilon (8 edges), {m} grasps: engine {1e3 * t_engine / m:.2f} ms a grasp (CPU); its {hulls} ConvexHull calls "
        f"(one per grasp in closure, {1e3 * sum(spent) / max(hulls, 1):.2f} ms each) are {sum(spent) / t_engine:.0%} of it: "
        f"a per-grasp loop of ConvexHull costs {t_engine / sum(spent):.2f}x less at most, not 10x"
    )


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=100_000)
    ap.add_argument("--loop", type=int, default=1000)
    ap.add_argument("--closure-loop", type=int, default=100)
    ap.add_argument("--single", type=int, default=300)
    ap.add_argument("--epsilon", type=int, default=200)
    ap.add_argument("--soft", type=int, default=20_000)
    args = ap.parse_args()
    p, n, w, mu = grasps(args.n)
    _, first = cpu(lambda: gt.grip(p[:2], n[:2], w[:2], mu[:2], safety=SAFETY))
    if compiled.kernel() is not None:
        print(f"first grip (numba loads its cached kernel, or compiles it on a fresh install): {first:.2f} s (CPU)")
    single(p, n, w, mu, args.single)
    edge(args.single)
    batched(p, n, w, mu, args.loop, args.closure_loop)
    soft(p, n, w, mu, args.soft, args.single)
    epsilon(p, n, mu, args.epsilon)


if __name__ == "__main__":
    main()
