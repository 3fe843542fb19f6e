"""One synthesis problem (issue 39, item 4): the library, the command line and Dask build it in one
place (``run/grasp_search.py``'s ``grasp_problem`` over the engine's ``synthesis_problem``), so the
same document and options give the same grasps, bit for bit, through all three."""

import importlib.util
import json
from dataclasses import replace

import numpy as np
import pytest
from typer.testing import CliRunner

import grasptwist as gt
from grasptwist.cli import app
from grasptwist.engine.synthesis.problem import Problem
from grasptwist.run.grasp_search import grasp_problem
from grasptwist.run.options import SynthesisOptions
from places import GRASPS

SPHERE = GRASPS / "sphere.yaml"  # 'sphere-equator': friction, a mass and a second wrench of its own
OPTIONS = {"count": 2, "candidates": 300, "seed": 5, "seconds": 60.0}  # the command line's default seconds


def equator():
    return next(g for g in gt.read_grasps(SPHERE) if g.name == "sphere-equator")


def points_of(records):
    return np.array([[c["point"] for c in r["contacts"]] for r in records if r["ok"]])


def cli_records(*options):
    r = CliRunner().invoke(app, ["synthesize", str(SPHERE), *options, "-f", "jsonl", "-q"])
    assert r.exit_code == 1, r.output  # 'sphere-tripod' has nothing to hold: its error record
    return [x for x in map(json.loads, r.stdout.splitlines()) if x.get("grasp") == "sphere-equator"]


def same_problem(a: Problem, b: Problem):
    """Two problems alike in everything a search reads: numbers, options, the hand, and the surface
    (the same points sampled from the same seed)."""
    for name in ("friction", "count", "safety", "objective", "methods", "min_conditioning", "quality", "seed"):
        assert getattr(a, name) == getattr(b, name), name
    assert (a.budget.candidates, a.budget.seconds, a.spacing, a.tol) == (
        b.budget.candidates,
        b.budget.seconds,
        b.spacing,
        b.tol,
    )
    assert a.perturbation == b.perturbation and len(a.constraints) == len(b.constraints)
    np.testing.assert_array_equal(a.wrenches, b.wrenches)
    np.testing.assert_array_equal(a.wrist, b.wrist)
    np.testing.assert_array_equal(
        a.surface.sample(50, np.random.default_rng(1)), b.surface.sample(50, np.random.default_rng(1))
    )
    assert a.weight.mass == b.weight.mass and a.surface.size == b.surface.size
    np.testing.assert_array_equal(a.weight.center_of_mass, b.weight.center_of_mass)


def test_the_library_the_command_line_and_dask_s_task_build_the_same_problem(monkeypatch):
    from grasptwist.dask import _synthesized  # the unit of work of synthesize_bag: one object's records
    from grasptwist.engine.synthesis import search
    from grasptwist.run import grasp_search
    from grasptwist.run import synthesize as run_synthesize

    built = []

    def record(problem):  # what each door asks, then a search of one candidate: no time spent
        built.append(problem)
        return search.solve_steps(replace(problem, budget=replace(problem.budget, candidates=1)))

    monkeypatch.setattr(run_synthesize, "solve_steps", record)
    monkeypatch.setattr(grasp_search, "solve", lambda problem: built.append(problem))
    gt.synthesize(equator(), **OPTIONS)  # the file's friction, weight and wrench 'turn-z', as the CLI's
    cli_records("-n", "2", "--candidates", "300", "--seed", "5")
    _synthesized(str(SPHERE), OPTIONS, None)
    api, cli, bag = built
    same_problem(api, cli)
    same_problem(api, bag)


@pytest.mark.slow  # three searches, about a second each
def test_the_library_the_command_line_and_dask_s_task_give_the_same_grasps():
    from grasptwist.dask import _synthesized

    api = gt.synthesize(equator(), **OPTIONS)
    cli = cli_records("-n", "2", "--candidates", "300", "--seed", "5")
    bag = [x for x in _synthesized(str(SPHERE), OPTIONS, None) if x.get("grasp") == "sphere-equator"]
    assert api.stopped_by == "candidates" and api.points.shape == (2, 3, 3)
    assert [x["scores"]["total_normal_force"]["turn-z"] for x in cli] == api.total_normal_force[:, 1].tolist()
    np.testing.assert_array_equal(points_of(cli), api.points)
    np.testing.assert_array_equal(points_of(bag), api.points)


LOADS = ("load +x", "load -x", "load +y", "load -y", "load +z")  # the weight's size; -z is the weight


def test_a_grasp_document_s_problem_holds_its_weight_first_and_its_own_wrenches_after():
    task = grasp_problem(equator(), count=2)
    p = task.problem
    assert isinstance(p, Problem) and task.names == ("hold", "turn-z", *LOADS) and p.wrenches.shape == (7, 6)
    g = equator()
    np.testing.assert_allclose(p.wrenches[0, :3], [0, 0, 9.81 * g.mass], rtol=1e-12)  # -m g, gravity -z
    assert p.friction == task.friction == float(np.min(g.friction)) and p.weight.mass == g.mass
    # --mass replaces the object's, --wrench the file's others, --friction its friction
    task = grasp_problem(g, mass=2.0, wrenches=[[1.0, 0, 0, 0, 0, 0]], friction=0.3, loads="weight")
    assert task.names == ("hold", "1") and task.problem.weight.mass == 2.0 and task.problem.friction == 0.3
    np.testing.assert_array_equal(task.problem.wrenches[1], [1.0, 0, 0, 0, 0, 0])


@pytest.mark.parametrize(
    ("change", "code"),
    [
        ({"object": None}, "no-object"),
        ({"friction": None}, "no-friction"),
        ({"mass": None, "wrenches": ()}, "nothing-to-hold"),
        ({"mass": 1e308, "gravity": np.array([0, 0, -1e308])}, "non-finite"),
    ],
)
def test_a_document_the_search_cannot_start_from_is_its_located_error(change, code):
    g = equator()
    if change.get("mass", 0) is None:  # no weight: neither the file's nor its object's
        change = {**change, "object": replace(g.object, mass=None, density=None)}
    error = grasp_problem(replace(g, **change))
    assert isinstance(error, gt.InputError) and error.code == code and error.line == g.line


def test_tip_radius_replaces_every_fingertip_s_radius_once_for_the_library_and_the_command_line():
    from grasptwist.engine.synthesis.problem import with_tip_radius

    (g,) = gt.read_grasps(GRASPS / "three-finger-hand.yaml")
    task = grasp_problem(g, friction=0.8, wrenches=[[0, 0, 1.0, 0, 0, 0]], tip_radius=0.004)
    assert [f.tip_radius for f in task.hand.fingers] == [0.004] * 3
    assert task.problem.hand.radii.tolist() == [0.004] * 3
    # the inline tips sit on the file's contacts, 4 mm behind them: as a hand given that radius in the file
    same = grasp_problem(replace_hand(g, with_tip_radius(g.hand, 0.004)), friction=0.8, wrenches=[[0, 0, 1.0, 0, 0, 0]])
    np.testing.assert_array_equal(task.problem.hand.tips, same.problem.hand.tips)


def replace_hand(grasp, hand):
    return replace(grasp, hand=hand)


@pytest.mark.slow  # imports dask (about a second)
@pytest.mark.skipif(importlib.util.find_spec("dask") is None, reason="needs the extra grasptwist[dask]")
def test_synthesize_bag_on_the_synchronous_scheduler_gives_the_library_s_grasps():
    api = gt.synthesize(equator(), **OPTIONS)
    recs = gt.dask.synthesize_bag([str(SPHERE)], **OPTIONS).compute(scheduler="synchronous")
    np.testing.assert_array_equal(points_of([r for r in recs if r.get("grasp") == "sphere-equator"]), api.points)


def test_the_hold_test_s_six_loads_are_held_beside_the_weight_unless_loads_is_weight():
    # the default (--loads six): the weight's size along +-x, +-y, +-z at the centre of mass, the one
    # equal to the weight left out, after the document's own wrenches
    g = equator()
    plain, six = (grasp_problem(g, loads=loads, **OPTIONS) for loads in ("weight", "six"))
    assert plain.names == ("hold", "turn-z") and six.names == (*plain.names, *LOADS)
    np.testing.assert_array_equal(six.problem.wrenches[: len(plain.names)], plain.problem.wrenches)
    weight = plain.problem.weight
    size = weight.mass * np.linalg.norm(weight.gravity)
    force = six.problem.wrenches[len(plain.names) :, :3]
    np.testing.assert_allclose(force, -size * np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1]]))
    moment = six.problem.wrenches[len(plain.names) :, 3:]
    np.testing.assert_allclose(moment, np.cross(weight.center_of_mass, force), atol=1e-15)


def test_without_a_weight_there_are_no_loads_and_an_unknown_loads_is_refused():
    g = equator()
    task = grasp_problem(g, hold=False, **OPTIONS)  # the file's wrench alone: nothing to turn
    assert task.names == ("turn-z",) and task.problem.wrenches.shape == (1, 6)
    with pytest.raises(ValueError, match="loads must be one of six, weight"):
        grasp_problem(g, loads="all", **OPTIONS)
    with pytest.raises(ValueError, match="loads must be one of six, weight"):
        SynthesisOptions(loads="all")
