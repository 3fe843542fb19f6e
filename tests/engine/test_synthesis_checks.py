"""The checks of a search's options (engine/synthesis/checks.py): each branch, and the library refusing
what the command line refuses (tests/cli/test_synthesize_cli.py holds the two to the same words)."""

import numpy as np
import pytest

from grasptwist.engine.synthesis import checks
from grasptwist.engine.synthesis.budget import Budget
from grasptwist.engine.synthesis.search import synthesize
from grasptwist.model import GraspObject, Shape


def ball(mass=0.1):
    return GraspObject(Shape("sphere", np.array([0.05])), np.eye(4), mass=mass)


@pytest.mark.parametrize(
    ("check", "good", "expected"),
    [
        (checks.check_count, np.int64(3), 3),
        (checks.check_count, checks.MAX_COUNT, 10_000),
        (checks.check_candidates, 10**9, 10**9),
        (checks.check_seed, 0, 0),
        (checks.check_seed, 2**63 - 1, 2**63 - 1),
        (checks.check_seconds, None, None),
        (checks.check_seconds, 2, 2.0),
        (checks.check_min_spacing, 0, 0.0),
        (checks.check_min_spacing, None, None),
        (checks.check_tip_radius, 0, 0.0),
        (checks.check_tip_radius, np.float32(0.01), pytest.approx(0.01)),
        (checks.check_mass, 1e300, 1e300),
        (checks.check_search_friction, float("inf"), float("inf")),
        (checks.check_search_friction, 0, 0.0),
    ],
)
def test_a_good_value_comes_back_as_a_plain_number(check, good, expected):
    value = check(good)
    assert value == expected and type(value) in (int, float, type(None))


@pytest.mark.parametrize(
    ("check", "bad", "words"),
    [
        (checks.check_count, 0, "count must be an integer from 1 to 10000, got 0"),
        (checks.check_count, 10_001, "count must be an integer from 1 to 10000, got 10001"),
        (checks.check_count, 2.5, "count must be an integer from 1 to 10000, got 2.5"),
        (checks.check_count, True, "count must be an integer from 1 to 10000, got True"),
        (checks.check_candidates, 10**9 + 1, "candidates must be an integer from 1 to 1000000000"),
        (checks.check_seed, -1, "seed must be an integer from 0 to 9223372036854775807, got -1"),
        (checks.check_seed, 2**63, "seed must be an integer from 0 to 9223372036854775807, got 9223372036854775808"),
        (checks.check_seed, None, "seed must be an integer from 0 to 9223372036854775807, got None"),
        (checks.check_seconds, 0, "seconds must be a finite number > 0, got 0"),
        (checks.check_seconds, "1", "seconds must be a finite number > 0, got '1'"),
        (checks.check_min_spacing, float("nan"), "min_spacing must be a finite number >= 0, got nan"),
        (checks.check_min_spacing, -1e-9, "min_spacing must be a finite number >= 0, got -1e-09"),
        (checks.check_tip_radius, float("inf"), "tip_radius must be a finite number >= 0, got inf"),
        (checks.check_mass, 0.0, "mass must be a finite number > 0, got 0.0"),
        (checks.check_mass, float("inf"), "mass must be a finite number > 0, got inf"),
        (checks.check_search_friction, float("nan"), "friction must be a number >= 0 (inf: no limit), got nan"),
        (checks.check_search_friction, -0.1, "friction must be a number >= 0 (inf: no limit), got -0.1"),
        (checks.check_search_friction, [0.5], "friction must be a number >= 0 (inf: no limit), got [0.5]"),
        (checks.check_wrenches, [[0, 0, 1, 0, 0, np.inf]], "wrenches[0] must be finite"),
        (checks.check_wrenches, [[0, 0, 1, 0, 0, 0], [np.nan] * 6], "wrenches[1] must be finite"),
        (checks.check_wrenches, [0, 0, 1], "wrench must have shape (..., 6), got (3,)"),
    ],
)
def test_a_bad_value_is_refused_naming_the_option(check, bad, words):
    with pytest.raises(ValueError) as refused:
        check(bad)
    assert str(refused.value).startswith(words)


@pytest.mark.parametrize(
    ("options", "words"),
    [
        ({"count": 0}, "count must be an integer"),
        ({"count": -1}, "count must be an integer"),
        ({"count": 2.5}, "count must be an integer"),
        ({"min_spacing": float("nan")}, "min_spacing must be a finite number >= 0"),
        ({"wrenches": [[0, 0, np.nan, 0, 0, 0]]}, r"wrenches\[0\] must be finite"),
        ({"seed": 2**64}, "seed must be an integer"),
        ({"candidates": 0}, "candidates must be an integer"),
        ({"seconds": float("nan")}, "seconds must be a finite number > 0"),
        ({"tip_radius": float("nan")}, "tip_radius must be a finite number >= 0"),  # without a hand too
    ],
)
def test_the_library_refuses_what_the_command_line_refuses(options, words):
    with pytest.raises(ValueError, match=words.replace("(", r"\(")):
        synthesize(ball(), 0.5, **{"candidates": 100, **options})


def test_nan_friction_is_refused_not_a_search_that_finds_nothing():
    with pytest.raises(ValueError, match="friction must be a number >= 0"):
        synthesize(ball(), float("nan"), candidates=100)


def test_a_weight_beyond_a_double_is_refused():
    with pytest.raises(ValueError, match="weight or its moment about the origin overflows"):
        synthesize(ball(mass=1e308), 0.5, candidates=100)


def test_a_budget_checks_its_candidates_and_seconds():
    assert Budget(5, 1).seconds == 1.0 and Budget().candidates == 20000 and Budget().seconds is None
    with pytest.raises(ValueError, match="seconds must be a finite number > 0, got -1"):
        Budget(5, -1)


def test_a_surface_no_finite_friction_closes_is_said_so_not_that_it_needs_no_friction():
    # a plane seen from one side: every normal +z, so no friction pulls the object down (closure friction inf)
    from grasptwist.engine.synthesis.problem import Surface
    from grasptwist.engine.synthesis.search import search

    def sample(n, rng):
        return np.c_[rng.uniform(-1, 1, (n, 2)), np.zeros(n)], np.tile([0, 0, 1.0], (n, 1))

    def project(q):
        p = q * [1, 1, 0]
        return p, np.broadcast_to([0, 0, 1.0], q.shape).copy(), q[..., 2], np.zeros(q.shape[:-1], bool)

    s = search(Surface(sample, project, 3.0), [[0, 0, 1.0, 0, 0, 0]], 0.5, candidates=300)
    assert s.failure.constraint == "force_closure" and s.failure.best == np.inf
    assert s.failure.message.endswith("none is at any finite friction") and "needs" not in s.failure.message


def test_spending_stops_on_the_time_only_while_candidates_are_left():
    from grasptwist.engine.synthesis.budget import PROBE, Spending

    now = [0.0]
    b = Spending(Budget(100, 10.0, lambda: now[0]), 0.8)
    assert b.take(60) == PROBE == 32 and b.stopped_by == "candidates"  # no rate yet: a probe
    b.spent(32)  # in no time: no limit from the rate
    assert b.take(60) == 60 and b.stopped_by == "candidates"
    b.spent(60)
    assert b.take(60) == 8
    b.spent(8)
    now[0] = 9.0  # past the search's 8 s, but every candidate is spent: not the time's doing
    assert b.take(60) == 0 and b.stopped_by == "candidates" and not b.late()
    now[0] = 10.0
    assert b.late() and b.stopped_by == "seconds" and b.seconds() == 10.0
    early = Spending(Budget(100, 10.0, lambda: now[0]), 0.8)
    now[0] = 18.0
    assert early.take(10) == 0 and early.stopped_by == "seconds"


def test_a_take_is_sized_by_the_rate_measured_to_end_at_the_search_deadline():
    """At 4 ms a candidate (a TriFinger hand's rate) a 2048 chunk took 8 s past a 0.8 s deadline."""
    from grasptwist.engine.synthesis.budget import PROBE, Spending

    now = [0.0]
    b = Spending(Budget(10**6, 1.0, lambda: now[0]), 0.8)
    assert b.take(2048) == PROBE
    b.spent(PROBE)
    now[0] = 0.004 * PROBE  # 0.128 s
    assert b.take(2048) == 168 and b.stopped_by == "seconds"  # (0.8 - 0.128) / 0.004 = 168


def test_the_command_line_and_python_share_one_conditioning_floor():
    """Python's ``min_conditioning`` defaulted to 0 while ``--min-conditioning`` was 0.001."""
    import inspect

    from grasptwist.cli.synthesize import synthesize as command
    from grasptwist.engine.synthesis.problem import surface_problem
    from grasptwist.engine.synthesis.scores import MIN_CONDITIONING, score_triples

    option = inspect.signature(command).parameters["min_conditioning"].default
    assert MIN_CONDITIONING == 0.05 == option
    for f in (surface_problem, score_triples):
        assert inspect.signature(f).parameters["min_conditioning"].default == MIN_CONDITIONING
