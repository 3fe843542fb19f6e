"""A grasp's margins (engine/synthesis/robustness.py, engine/objects/creases.py): the hold friction against
its closed form on a ball and Clarabel, edge distances against the edges sampled, robustness against
theory (the cone's edge on a ball, a box's edge crossed by a disc of perturbations)."""

import numpy as np
import pytest

from conic import least_grip
from grasptwist.engine.forces.closure import force_closure
from grasptwist.engine.objects.creases import CREASE_ANGLE_DEG, edge_distance, mesh_creases
from grasptwist.engine.objects.primitives import triangles
from grasptwist.engine.synthesis.problem import surface_of
from grasptwist.engine.synthesis.robustness import (
    check_friction_error,
    check_perturbations,
    check_position_error,
    default_position_error,
    hold_friction,
    margins,
    perturbation_draws,
    robustness,
)
from grasptwist.engine.synthesis.search import synthesize
from grasptwist.objects import GraspObject, Shape

LIFT = [[0, 0, 9.81, 0, 0, 0]]
CUBE = GraspObject(Shape("box", np.full(3, 0.065)), np.eye(4), mass=0.1)
BALL = GraspObject(Shape("sphere", np.array([0.035])), np.eye(4), mass=0.1)


def tripod(phi, radius=1.0):
    """Three contacts at latitude ``phi`` of a ball (inward normals): they need friction ``tan phi``."""
    a = np.radians([90, 210, 330])
    p = radius * np.stack([np.cos(phi) * np.cos(a), np.cos(phi) * np.sin(a), np.full(3, np.sin(phi))], axis=1)
    return p, -p / radius


def test_the_hold_friction_of_a_tripod_is_tan_phi_and_clarabel_agrees_on_either_side():
    phis = np.radians([5, 15, 25, 35])
    p, n = map(np.array, zip(*(tripod(phi) for phi in phis)))
    h = hold_friction(p, n, LIFT, 1.0)
    # within 2^-30 of the bracket [0, 1] above the least: all thirty halvings done, four a round
    assert (h >= np.tan(phis) - 1e-15).all() and (h - np.tan(phis) <= 2.0**-30).all()
    for pk, nk, hk in zip(p, n, h):
        assert least_grip(pk, nk, LIFT[0], 1.001 * hk)[0] is not None
        assert least_grip(pk, nk, LIFT[0], 0.99 * hk)[0] is None
    # closure holds every wrench: it needs at least the hold friction
    assert (force_closure(p, n).closure_friction >= h - 1e-9).all()


def test_without_a_friction_limit_the_hold_friction_is_bracketed_first():
    phis = np.radians([20, 60, 80])
    p, n = map(np.array, zip(*(tripod(phi) for phi in phis)))
    assert hold_friction(p, n, LIFT, np.inf) == pytest.approx(np.tan(phis), rel=1e-6)


def test_the_hold_friction_is_zero_when_a_finger_carries_the_weight_and_nan_when_not_held_at_the_start():
    h = 0.0325
    under = np.array([[[h, 0, 0], [-h, 0, 0], [0, 0, -h]]])  # two squeeze, one under: no friction needed
    inward = -under / h
    assert hold_friction(under, inward, LIFT, 0.8).tolist() == [0.0]
    p, n = tripod(np.radians(30))
    assert np.isnan(hold_friction(p[None], n[None], LIFT, 0.5)).all()  # tan 30 = 0.577 > 0.5


def test_edge_distance_of_a_box_and_a_cylinder_is_the_distance_to_their_edges_sampled():
    rng = np.random.default_rng(4)
    box = GraspObject(Shape("box", np.array([0.04, 0.06, 0.1])), np.eye(4))
    can = GraspObject(Shape("cylinder", np.array([0.03, 0.08])), np.eye(4))
    t = np.linspace(-1, 1, 2001)
    half = np.array([0.02, 0.03, 0.05])
    edges = []
    for k in range(3):
        for si in (-1, 1):
            for sj in (-1, 1):
                e = np.zeros((len(t), 3))
                i, j = [a for a in range(3) if a != k]
                e[:, k], e[:, i], e[:, j] = t * half[k], si * half[i], sj * half[j]
                edges.append(e)
    a = np.linspace(0, 2 * np.pi, 10001)
    rims = [np.stack([0.03 * np.cos(a), 0.03 * np.sin(a), np.full_like(a, z)], axis=1) for z in (-0.04, 0.04)]
    for obj, sampled in ((box, np.concatenate(edges)), (can, np.concatenate(rims))):
        q = surface_of(obj).sample(50, rng)[0]
        brute = np.linalg.norm(q[:, None] - sampled[None], axis=-1).min(axis=1)
        assert edge_distance(obj, q) == pytest.approx(brute, abs=3e-5)  # the samples' spacing
    assert np.isinf(edge_distance(BALL, [[0.035, 0, 0]])).all()


def test_a_mesh_creases_where_its_faces_turn_past_the_angle_and_measures_as_the_primitive():
    v, f = triangles("box", [0.04, 0.06, 0.1], 0)
    mesh = GraspObject(Shape("mesh", np.zeros(0), v, f), np.eye(4))
    box = GraspObject(Shape("box", np.array([0.04, 0.06, 0.1])), np.eye(4))
    q = surface_of(box).sample(40, np.random.default_rng(5))[0]
    assert len(mesh_creases(mesh.shape)) == 12  # not the faces' diagonals
    assert edge_distance(mesh, q) == pytest.approx(edge_distance(box, q), abs=1e-12)
    # a 32-sided cylinder turns 11.25 degrees between sides: only its rims are creases
    v, f = triangles("cylinder", [0.03, 0.08], 32)
    assert CREASE_ANGLE_DEG > 11.25 and len(mesh_creases(Shape("mesh", np.zeros(0), v, f))) == 64


def test_the_checks_of_the_perturbation_options():
    assert check_position_error(None) is None and check_position_error(0) == 0.0
    assert check_friction_error(0) == 0.0 and check_perturbations(np.int64(3)) == 3
    for check, bad in (
        (check_position_error, np.inf),
        (check_position_error, True),
        (check_friction_error, -0.1),
        (check_friction_error, "0.2"),
        (check_perturbations, 2.0),
        (check_perturbations, True),
    ):
        with pytest.raises(ValueError):
            check(bad)
    assert default_position_error(0.1, np.zeros(3)) == pytest.approx(0.002)  # no tips: 2% of the size


def test_on_a_ball_robustness_falls_as_the_contacts_approach_the_cone_edge():
    mu = 0.5
    phis = np.arctan(np.array([0.2, 0.3, 0.38, 0.42, 0.46, 0.55]))  # tan phi against mu (1 - 0.2 v)
    p, n = map(np.array, zip(*(tripod(phi, 0.035) for phi in phis)))
    r = robustness(surface_of(BALL), p, n, LIFT, mu, position_error=0.002, perturbations=256)
    assert (np.diff(r) <= 0).all() and r[0] == 1.0 and r[-1] == 0.0
    assert 0 < r[3] < 1  # between: the draws decide
    # no wrench to hold: every perturbation holds it (a division by the wrenches' count had raised)
    assert robustness(surface_of(BALL), p, n, np.empty((0, 6)), mu, perturbations=8).tolist() == [1.0] * len(p)


def test_a_disc_of_perturbations_crosses_a_box_edge_as_often_as_the_circular_segment_says():
    """Two fingers squeeze the cube's side faces at their centres, the third is under it, ``d`` from
    an edge: a perturbation fails exactly when it carries that contact over the edge (a disc of
    radius ``e`` crosses a line at ``d`` with the probability ``(theta - sin theta) / (2 pi)``,
    ``theta = 2 acos(d / e)``)."""
    h, e, count = 0.0325, 0.004, 4096
    d = np.array([0.0, 0.001, 0.002, 0.003, 0.005])
    p = np.zeros((len(d), 3, 3))
    p[:, 0], p[:, 1] = [h, 0, 0], [-h, 0, 0]
    p[:, 2] = np.stack([h - d, np.zeros_like(d), np.full_like(d, -h)], axis=1)
    n = np.tile([[-1.0, 0, 0], [1, 0, 0], [0, 0, 1]], (len(d), 1, 1))
    r = robustness(surface_of(CUBE), p, n, LIFT, 0.8, position_error=e, perturbations=count)
    theta = 2 * np.arccos(np.minimum(d / e, 1))
    crossing = (theta - np.sin(theta)) / (2 * np.pi)
    assert r == pytest.approx(1 - crossing, abs=4 * 0.5 / np.sqrt(count))
    assert r[-1] == 1.0 and (np.diff(r) >= 0).all()


def test_the_draws_are_seeded_and_the_margins_of_no_grasp_are_empty():
    a, b = perturbation_draws(8, 0.2, 3), perturbation_draws(8, 0.2, 3)
    assert np.array_equal(a[0], b[0]) and not np.array_equal(a[0], perturbation_draws(8, 0.2, 4)[0])
    m = margins(surface_of(CUBE), np.empty((0, 3, 3)), np.empty((0, 3, 3)), LIFT, 0.8, position_error=0.002)
    assert m.hold_friction.shape == (0,) and m.edge_distance.shape == (0, 3) and m.robustness.shape == (0,)


@pytest.mark.slow  # the default run's 40 s: development.md, Test time
def test_the_robust_objective_ranks_the_most_robust_first_and_keeps_a_margin_of_friction():
    robust = synthesize(CUBE, 0.8, count=3, candidates=2000, position_error=0.006)
    plain = synthesize(CUBE, 0.8, count=3, candidates=2000, position_error=0.006, objective="total_normal_force")
    assert (np.diff(robust.robustness) <= 0).all()
    assert (np.sort(robust.robustness) >= np.sort(plain.robustness)).all()
    assert robust.robustness.mean() > plain.robustness.mean()  # the plain ranking keeps grasps near edges
    assert robust.edge_distance.min(axis=1).mean() > plain.edge_distance.min(axis=1).mean()
    # the margins are the returned grasps': hold friction within the cone the grip used
    assert (robust.hold_friction <= robust.closure_friction + 1e-9).all()


def test_the_goal_on_the_cube_in_a_short_search():
    found = synthesize(CUBE, 0.5, count=3, candidates=2000)
    assert len(found.points) == 3 and (found.hold_friction <= 0.7 * 0.5).all()


@pytest.mark.slow
@pytest.mark.parametrize(
    "obj",
    [
        CUBE,
        BALL,
        GraspObject(Shape("cylinder", np.array([0.03, 0.1])), np.eye(4), mass=0.2),
    ],
    ids=["cube", "ball", "cylinder"],
)
def test_with_default_options_every_grasp_holds_its_weight_with_30_percent_less_friction(obj):
    mu = 0.5
    found = synthesize(obj, mu, count=5)
    assert len(found.points) == 5 and (found.hold_friction <= 0.7 * mu).all()
    for p, n in zip(found.points, found.normals):  # and Clarabel holds it there
        assert least_grip(p, n, _weight(obj), 0.7 * mu)[0] is not None


def _weight(obj):
    return np.array([0, 0, 9.81 * obj.mass, 0, 0, 0])
