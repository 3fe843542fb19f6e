"""The grasp file's force keys (io/grasp/forces.py): friction, wrenches, mass, center_of_mass, gravity."""

import numpy as np
import pytest

from grasptwist.io.grasp import InputError, load_grasps, read_grasps
from places import ROOT

CONTACTS = """contacts:
  - point: [1, 0, 0]
    normal: [-1, 0, 0]{f1}
  - point: [-0.5, 0.866, 0]
    normal: [0.5, -0.866, 0]{f2}
  - point: [-0.5, -0.866, 0]
    normal: [0.5, 0.866, 0]{f3}
"""


def grasp(top="", f1="", f2="", f3=""):
    def own(mu):
        return f"\n    friction: {mu}" if mu != "" else ""

    text = top + CONTACTS.format(f1=own(f1), f2=own(f2), f3=own(f3))
    (g,) = load_grasps(text, file="g.yaml")
    return g


def error(text):
    with pytest.raises(InputError) as caught:
        load_grasps(text + CONTACTS.format(f1="", f2="", f3=""), file="g.yaml")
    return caught.value


def test_no_force_keys_leave_the_defaults():
    g = grasp()
    assert (g.friction, g.wrenches, g.mass, g.center_of_mass, g.gravity) == (None, (), None, None, None)


def test_a_contacts_friction_overrides_the_grasps():
    assert grasp("friction: 0.5\n").friction.tolist() == [0.5, 0.5, 0.5]
    assert grasp("friction: 0.5\n", f2=0.25).friction.tolist() == [0.5, 0.25, 0.5]
    assert grasp(f1=0.1, f2=0.2, f3=0).friction.tolist() == [0.1, 0.2, 0.0]
    assert not grasp("friction: 0.5\n").friction.flags.writeable


def test_a_wrench_is_force_then_moment_about_the_origin():
    g = grasp(
        "wrenches:\n"
        "  - {name: a, wrench: [1, 2, 3, 4, 5, 6]}\n"
        "  - {force: [1, 0, 0], moment: [0, 0, 2], at: [0, 0, 1]}\n"
        "  - {moment: [0, 0, 1]}\n"
    )
    assert [w.name for w in g.wrenches] == ["a", "2", "3"]
    assert g.wrenches[0].wrench.tolist() == [1, 2, 3, 4, 5, 6]
    # moment about the origin = moment about `at` + at x force = (0, 0, 2) + (0, 1, 0)
    assert g.wrenches[1].wrench.tolist() == [1, 0, 0, 0, 1, 2]
    assert g.wrenches[2].wrench.tolist() == [0, 0, 0, 0, 0, 1]
    assert [w.line for w in g.wrenches] == [2, 3, 4]


def test_mass_adds_hold_which_balances_the_weight():
    g = grasp("mass: 2\ncenter_of_mass: [1, 0, 0]\nwrenches: [{name: push, force: [1, 0, 0]}]\n")
    assert [w.name for w in g.wrenches] == ["push", "hold"]
    # weight m g = (0, 0, -19.62) at c = (1, 0, 0): the fingers exert (-m g; -c x m g)
    hold = g.wrenches[1].wrench
    np.testing.assert_array_equal(hold, [0, 0, 19.62, 0, -19.62, 0])
    assert not np.signbit(hold[hold == 0]).any()  # no -0.0 in the output
    assert (g.mass, g.center_of_mass.tolist(), g.gravity.tolist()) == (2.0, [1, 0, 0], [0, 0, -9.81])
    moon = grasp("mass: 1\ncenter_of_mass: [0, 0, 0]\ngravity: [0, 0, -1.62]\n")
    assert moon.wrenches[0].wrench.tolist() == [0, 0, 1.62, 0, 0, 0]
    assert moon.gravity.tolist() == [0, 0, -1.62]


@pytest.mark.parametrize(
    "top, code, where, match",
    [
        ("friction: -0.1\n", "invalid-friction", (1, 11), r"friction: must be >= 0, got -0\.1"),
        ("friction: [0.5]\n", "not-a-number", (1, 11), "friction: expected a number"),
        ("mass: -1\ncenter_of_mass: [0, 0, 0]\n", "invalid-mass", (1, 7), r"mass: must be > 0"),
        ("mass: 1\n", "missing-key", (1, 7), "center_of_mass: required with 'mass'"),
        ("center_of_mass: [0, 0, 0]\n", "missing-key", (1, 17), "mass: required with 'center_of_mass'"),
        ("mass: 1\ncenter_of_mass: [0, 0]\n", "vector-length", (2, 17), "center_of_mass: expected 3 numbers"),
        ("mass: 1e308\ncenter_of_mass: [0, 0, 0]\n", "non-finite", (1, 7), "mass: the weight .* overflows"),
        ("wrenches: {force: [1, 0, 0]}\n", "not-a-list", (1, 11), "wrenches: expected a list"),
        ("wrenches: [{wrench: [1, 0, 0]}]\n", "vector-length", (1, 21), "a 3-vector goes under `force:` or `moment:`"),
        ("wrenches: [{force: [1, 0, 0, 0, 0, 0]}]\n", "vector-length", (1, 20), "goes under `wrench:`"),
        ("wrenches: [{wrench: [1, 0, 0, 0, 0, 0], at: [0, 0, 1]}]\n", "conflicting-keys", (1, 45), "'wrench'"),
        ("wrenches: [{at: [0, 0, 1]}]\n", "missing-key", (1, 12), "needs 'wrench', or 'force' and/or 'moment'"),
        ("wrenches: [{forse: [0, 0, 1]}]\n", "unknown-key", (1, 13), "did you mean 'force'"),
        ("wrenches: [{name: a, force: [1, 0, 0]}, {name: a, moment: [1, 0, 0]}]\n", "duplicate-name", (1, 48), "a"),
        ("mass: 1\ncenter_of_mass: [0, 0, 0]\nwrenches: [{name: hold, force: [1, 0, 0]}]\n", "duplicate-name",
         (3, 19), "duplicate name 'hold' \\(the wrench that 'mass' adds\\)"),
    ],
)  # fmt: skip
def test_each_bad_force_value_is_a_located_coded_error(top, code, where, match):
    e = error(top)
    assert (e.code, (e.line, e.column)) == (code, where)
    assert e.file == "g.yaml"
    with pytest.raises(InputError, match=match):
        raise e


def test_a_contact_without_friction_beside_others_needs_the_grasps():
    (e,) = read_grasps(CONTACTS.format(f1="\n    friction: 0.5", f2="", f3=""), file="g.yaml")
    assert (e.code, e.line, e.column) == ("missing-key", 5, 5)
    assert e.message.startswith("contacts[1].friction: ")
    (e,) = read_grasps(CONTACTS.format(f1="", f2="", f3="\n    friction: -2"), file="g.yaml")
    assert (e.code, e.message) == ("invalid-friction", "contacts[2].friction: must be >= 0, got -2.0")


def test_the_bundled_ball_is_held_by_its_weight():
    g = read_grasps(str(ROOT / "grasps/sphere.yaml"))[1]
    assert g.name == "sphere-equator"
    assert g.friction.tolist() == [0.5, 0.5, 0.5]
    assert [(w.name, w.wrench.tolist()) for w in g.wrenches] == [
        ("turn-z", [0, 0, 0, 0, 0, 0.01]),
        ("hold", [0, 0, 9.81, 0, 0, 0]),
    ]
