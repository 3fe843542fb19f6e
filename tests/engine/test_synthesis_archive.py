"""The search's archive (engine/synthesis/archive.py): the grasps it keeps are those of the rule it states,
applied by brute force, and keeping one costs a look at its neighbours, not at every grasp kept."""

import numpy as np
import pytest

from grasptwist.engine.synthesis import archive as archive_module
from grasptwist.engine.synthesis.archive import Archive
from grasptwist.engine.synthesis.candidates import triple_distance
from grasptwist.engine.synthesis.scores import CONSTRAINTS, Scores


def scores(value, failed=None):
    n = len(value)
    failed = np.full(n, -1, np.int8) if failed is None else failed
    return Scores(np.asarray(value, float), np.zeros((n, 1)), np.ones((n, 2)), failed)


def brute_force(chunks, size, spacing):
    """The rule in the archive's docstring, on lists: offered best first within a chunk."""
    kept = []  # (value, arrival, points)
    arrival = 0
    for p, value in chunks:
        for i in np.argsort(value, kind="stable"):
            if len(kept) >= size and value[i] >= max(k[0] for k in kept):
                break
            near = [k for k in kept if triple_distance(p[i], k[2]) < spacing]
            if any(k[0] <= value[i] for k in near):
                continue
            kept = [k for k in kept if all(k is not m for m in near)] + [(value[i], arrival, p[i])]
            arrival += 1
            if len(kept) > size:
                kept.remove(max(kept, key=lambda k: (k[0], k[1])))
    kept.sort(key=lambda k: (k[0], k[1]))
    return np.array([k[0] for k in kept]), np.array([k[2] for k in kept])


@pytest.mark.parametrize(("size", "spacing"), [(8, 0.3), (40, 0.15), (5, 0.0), (3, 10.0)])
def test_the_archive_keeps_what_its_rule_keeps_by_brute_force(size, spacing):
    rng = np.random.default_rng(size)
    chunks = [(rng.uniform(-1, 1, (60, 3, 3)), rng.integers(0, 30, 60).astype(float)) for _ in range(4)]
    a = Archive(size, spacing)
    for p, value in chunks:
        a.add(p, -p, scores(value))
    value, points = brute_force(chunks, size, spacing)
    np.testing.assert_array_equal(a.objective, value)  # ties included: the earlier stays
    np.testing.assert_array_equal(a.points, points)
    assert len(value) == a.count <= size
    if len(points) > 1:  # every pair kept is spacing apart
        d = triple_distance(points[:, None], points[None])
        assert d[~np.eye(len(points), dtype=bool)].min() >= spacing
    assert a.bound == (value[-1] if len(value) == size else np.inf)


def test_infeasible_rows_are_never_kept_and_a_full_archive_turns_the_worse_away():
    a = Archive(2, 0.0)
    p = np.arange(27.0).reshape(3, 3, 3)
    a.add(p, -p, scores([1.0, 2.0, 0.5], np.array([-1, -1, 2], np.int8)))
    assert a.objective.tolist() == [1.0, 2.0] and a.furthest == len(CONSTRAINTS)  # feasible rows got furthest
    a.add(p[:1] + 100, -p[:1], scores([3.0]))
    assert a.objective.tolist() == [1.0, 2.0] and a.bound == 2.0


def test_keeping_a_grasp_looks_at_its_neighbours_not_at_every_grasp_kept(monkeypatch):
    # 4000 grasps kept, spread over a cube: each offer compares itself with the few kept in the cubes
    # around its first contact (the former archive compared every candidate with every grasp kept)
    compared = []

    def counted(a, b):
        compared.append(len(b))
        return triple_distance(a, b)

    monkeypatch.setattr(archive_module, "triple_distance", counted)
    rng = np.random.default_rng(0)
    a = Archive(4000, 0.05)
    for _ in range(2):
        p = rng.uniform(0, 1, (2048, 3, 3))
        a.add(p, -p, scores(rng.random(2048)))
    # about 27 cubes of 1.5 grasps each (4000 kept, three contacts each, 8000 cubes), whatever the count kept
    assert a.count > 1000 and len(compared) <= 2 * 2048
    assert np.mean(compared) < 60 < a.count / 20 and max(compared) < 200
