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


def test_the_command_line_s_default_seconds_and_the_library_s_none_give_the_same_grasps():
    """``synthesize`` limits a search to 60 s by default, ``gt.synthesize`` to none: a limit not reached
    draws the same candidates (the first take a probe either way), so the same options give the same
    grasps (before: 1.5332 N on the command line, 1.1626 N in Python, on this box)."""
    box = GRASPS / "box-edge.yaml"
    # the weight alone, as the trial that found it asked (the six loads draw the same way)
    api = gt.synthesize(gt.read_grasps(box)[0], 0.5, mass=0.1, count=1, candidates=300, loads="weight")
    args = ["synthesize", str(box), "-n", "1", "--friction", "0.5", "--mass", "0.1", "--candidates", "300"]
    args += ["--loads", "weight"]
    r = CliRunner().invoke(app, [*args, "-f", "jsonl", "-q"])
    (rec,) = map(json.loads, r.stdout.splitlines())
    assert r.exit_code == 0 and api.stopped_by == rec["search"]["stopped_by"] == "candidates"
    np.testing.assert_array_equal(points_of([rec]), api.points)
    assert (
        rec["scores"]["total_normal_force"]["hold"] == api.total_normal_force[0, 0] == pytest.approx(1.5332, abs=1e-4)
    )


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


def test_a_soft_document_is_searched_soft_unless_contact_point_makes_every_contact_a_point():
    from grasptwist.run.options import POINT_CONTACTS

    contacts = "".join(
        f"  - {{point: {p}, normal: {n}, model: soft, torsion: {e}}}\n"
        for p, n, e in (("[0.035, 0, 0]", "[-1, 0, 0]", 0.005), ("[-0.035, 0, 0]", "[1, 0, 0]", 0.004))
    )
    text = "object: {sphere: 0.035, mass: 0.1}\nfriction: 0.8\ncontacts:\n" + contacts
    text += "  - {point: [0, 0.035, 0], normal: [0, -1, 0], model: soft, torsion: 0.006}\n"
    (g,) = gt.read_grasps(text.encode())
    assert grasp_problem(g).problem.torsion == 0.004  # the file's: the least radius
    assert grasp_problem(g, torsion=0.01).problem.torsion == 0.01  # --contact soft --torsion 0.01
    assert grasp_problem(g, torsion=POINT_CONTACTS).problem.torsion is None  # --contact point


def test_the_builder_s_errors_name_the_keyword_and_the_option_that_mend_them():
    """One builder, two callers: gt.synthesize's error says ``friction=`` where the command line's says
    ``--friction`` (both, one message); the codes are the same."""
    g = equator()
    with pytest.raises(gt.InputError) as err:
        gt.synthesize(replace(g, friction=None))
    assert err.value.code == "no-friction"
    assert err.value.message == "grasp 'sphere-equator' has no friction: give friction= (--friction)"
    none = replace(g, mass=None, wrenches=(), object=replace(g.object, mass=None, density=None))
    with pytest.raises(gt.InputError) as err:
        gt.synthesize(none)
    assert err.value.code == "nothing-to-hold" and err.value.message == (
        "grasp 'sphere-equator' has nothing to hold: give the object a mass (mass=, --mass) "
        "or a wrench (wrenches=, --wrench)"
    )


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


def test_an_object_with_a_mass_of_its_own_is_held_without_mass_given():
    # the document's object weighs 0.1 kg, the document has no top-level mass and none is given:
    # its weight is held all the same (it was 'nothing-to-hold')
    g = next(iter(gt.read_grasps(GRASPS / "box-edge.yaml")))
    g = replace(g, object=replace(g.object, mass=0.1, density=None), mass=None)
    task = grasp_problem(g, friction=0.5, **OPTIONS)
    assert task.names[0] == "hold" and task.problem.weight.mass == 0.1
    np.testing.assert_allclose(task.problem.wrenches[0, :3], [0, 0, 0.981])


def test_mass_given_with_an_object_weighs_it_as_with_its_grasp():
    # the trial's: gt.synthesize(g.object, mu, mass=0.1) raised "hold=True needs the object's mass": the
    # keyword was taken for a Grasp alone; the object with that mass now, the grasp form's same grasps
    g = gt.read_grasps(GRASPS / "box-edge.yaml")[0]
    bare = replace(g.object, mass=None, density=None)  # neither the object nor its file weighs anything
    kw = {"count": 1, "candidates": 300, "loads": "weight"}
    by_grasp = gt.synthesize(replace(g, object=bare, mass=None), 0.5, mass=0.1, **kw)
    by_object = gt.synthesize(bare, 0.5, mass=0.1, wrist=g.wrist, **kw)
    assert by_object.total_normal_force.shape == (1, 1)  # the weight alone: 0.1 kg's
    np.testing.assert_array_equal(by_object.points, by_grasp.points)
    np.testing.assert_allclose(by_object.total_normal_force, by_grasp.total_normal_force, rtol=1e-12)
    # and as the mass the object already has (mass= replaces a density too)
    dense = gt.synthesize(replace(bare, density=7.0e6), 0.5, mass=0.1, wrist=g.wrist, **kw)
    np.testing.assert_array_equal(dense.points, by_grasp.points)
