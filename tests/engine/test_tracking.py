"""A finger following its contact along a path (grasptwist.path.track_finger).

The finger: a turntable joint about z, a shoulder about y at the origin and an
elbow about y at (1, 0, 0), links of length 1, the tip's contact point at the
end of the second link.  Holding a point at distance ``r`` from the shoulder in
the plane y = 0, the elbow is at ``cos q3 = (r^2 - 2) / 2`` (two unit links);
a point moving along x at speed ``u`` from ``(1, 0, 0)`` is at ``r = 1 + u t``.
"""

import math

import numpy as np
import pytest

from grasptwist.engine.kinematics import forward_kinematics, joint_rates
from grasptwist.engine.tracking import track_fingers
from grasptwist.path import Segment, track_finger

SCREWS = np.array([[0, 0, 1.0, 0, 0, 0], [0, 1.0, 0, 0, 0, 0], [0, 1.0, 0, 0, 0, 1.0]])
POINTS = np.array([[0, 0, 0], [0, 0, 0], [1.0, 0, 0]])
TIP = np.eye(4)
TIP[:3, 3] = [2.0, 0, 0]
Q0 = np.array([0, -math.pi / 3, 2 * math.pi / 3])  # the tip at (1, 0, 0)
START = np.array([1.0, 0, 0])


def elbow(r):
    return math.acos((r * r - 2) / 2)


def test_the_start_is_where_the_finger_touches():
    np.testing.assert_allclose(forward_kinematics(SCREWS, POINTS, TIP, Q0).tip[:3, 3], START, atol=1e-15)


def test_the_tip_stays_on_a_contact_that_moves_and_turns_and_the_elbow_follows_the_closed_form():
    path = [
        Segment(1.0, twist=[0, 0, 0, 0.3, 0, 0]),  # out along x to r = 1.3
        Segment(1.0, twist=[0, 0, 0.5, 0, 0, 0]),  # turned about z (the turntable follows, r stays)
        Segment(1.0, twist=[0, 0, 0, 0, 0, 0.2], frame="body"),  # up by 0.2
    ]
    t = np.linspace(0, 3, 7)
    track = track_finger(SCREWS, POINTS, TIP, Q0, START, path, t)
    assert track.error.max() < 1e-6 * 2  # the grasp's size: the finger's reach
    np.testing.assert_allclose(track.positions[2, 2], elbow(1.3), atol=1e-7)  # t = 1
    np.testing.assert_allclose(track.positions[4, 0], 0.5, atol=1e-7)  # t = 2: the turntable turned by 0.5
    np.testing.assert_allclose(track.positions[6, 2], elbow(math.hypot(1.3, 0.2)), atol=1e-7)
    assert track.rank.tolist() == [3] * 7 and track.limit_exit is None and track.warning is None
    # the rates at a sample move the tip with the contact's velocity
    state = forward_kinematics(SCREWS, POINTS, TIP, track.positions[1])
    r = joint_rates(state.screws, state.tip[:3, 3], [0.3, 0, 0])
    np.testing.assert_allclose(track.rates[1], r.rates, atol=1e-6)


@pytest.mark.parametrize("samples", [2, 3, 11])
@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_the_first_exit_from_a_joint_limit_is_located_between_samples(samples):
    # the elbow opens as the contact moves away: it passes 1.9 rad where r^2 = 2 + 2 cos 1.9
    exact = (math.sqrt(2 + 2 * math.cos(1.9)) - 1) / 0.3
    lower = np.array([np.nan, np.nan, 1.9])
    track = track_finger(
        SCREWS, POINTS, TIP, Q0, START, [Segment(1.0, twist=[0, 0, 0, 0.3, 0, 0])], np.linspace(0, 1, samples),
        lower=lower,
    )  # fmt: skip
    t, joint = track.limit_exit
    assert joint == 2 and abs(t - exact) < 1e-5  # to the integration's accuracy (16 steps a sample)


def test_the_conditioning_warning_and_the_rank_loss_are_located_where_the_geometry_puts_them():
    # a base joint about the x axis, then slides along x and y: at the contact (1, y, 0) the
    # Jacobian's columns are (0, 0, y), (1, 0, 0), (0, 1, 0), so its conditioning is |y|; the
    # contact moving to y = 0 needs only the y slide, so the rates stay finite.
    screws = [[1.0, 0, 0, 0, 0, 0], [0, 0, 0, 1.0, 0, 0], [0, 0, 0, 0, 1.0, 0]]
    tip = np.eye(4)
    tip[:3, 3] = [1.0, 0, 0]
    path = [Segment(1.0, twist=[0, 0, 0, 0, -0.5, 0])]  # y = 0.5 (1 - t)
    track = track_finger(screws, np.zeros((3, 3)), tip, [0, 0, 0.5], [1.0, 0.5, 0], path, [0.0, 0.5, 1.0])
    assert abs(track.warning - (1 - 2e-3)) < 1e-9  # |y| = 1e-3
    assert abs(track.rank_loss - 1) < 1e-8  # |y| <= RANK_TOL (1e-9) times the largest singular value, 1
    np.testing.assert_allclose(track.conditioning, [0.5, 0.25, 0], atol=1e-12)
    assert track.rank.tolist() == [3, 3, 2] and track.error.max() < 1e-12


def test_fingers_stepped_together_track_as_each_alone_events_and_all():
    # the batch (one forward kinematics and one decomposition per stage for every finger) against
    # the finger alone: a finger's track, events included, never depends on the others beside it.
    # Along x 0.3 t and y -0.5 t: the arm's elbow leaves its limit of 1.9 rad, the slides' finger
    # (conditioning |y|) warns, then loses rank at t = 1; the arm turned by 0.5 also follows.
    slides = [[1.0, 0, 0, 0, 0, 0], [0, 0, 0, 1.0, 0, 0], [0, 0, 0, 0, 1.0, 0]]
    tip = np.eye(4)
    tip[:3, 3] = [1.0, 0, 0]
    fingers = [  # screws, points, tip, q0, contact, lower
        (SCREWS, POINTS, TIP, Q0, START, [np.nan, np.nan, 1.9]),
        (slides, np.zeros((3, 3)), tip, [0, 0, 0.5], [1.0, 0.5, 0], [np.nan] * 3),
        (SCREWS, POINTS, TIP, [0.5, Q0[1], Q0[2]], [math.cos(0.5), math.sin(0.5), 0], [np.nan] * 3),
    ]
    path, times = [Segment(1.0, twist=[0, 0, 0, 0.3, -0.5, 0])], [0.0, 0.5, 1.0]
    batch = track_fingers(*(np.array(a, float) for a in list(zip(*fingers))[:5]), path, times,
                          lower=np.array([f[5] for f in fingers]), steps=4)  # fmt: skip
    for got, (screws, points, home, q0, contact, lower) in zip(batch, fingers):
        alone = track_finger(screws, points, home, q0, contact, path, times, lower=np.array(lower), steps=4)
        for name in ("positions", "rates", "conditioning", "error"):
            np.testing.assert_allclose(getattr(got, name), getattr(alone, name), rtol=0, atol=1e-12)
        assert got.rank.tolist() == alone.rank.tolist()
        for name in ("rank_loss", "warning"):
            assert (getattr(got, name) is None) == (getattr(alone, name) is None)
            assert getattr(alone, name) is None or abs(getattr(got, name) - getattr(alone, name)) < 1e-12
        assert (got.limit_exit is None) == (alone.limit_exit is None)
        assert got.limit_exit is None or (
            got.limit_exit[1] == alone.limit_exit[1] and abs(got.limit_exit[0] - alone.limit_exit[0]) < 1e-12
        )
    (limit, joint), slid = batch[0].limit_exit, batch[1]
    r2 = 2 + 2 * math.cos(1.9)  # the arm's elbow at 1.9 rad: (1 + 0.3 t)^2 + (0.5 t)^2 = r2
    exact = (-0.6 + math.sqrt(0.36 - 4 * 0.34 * (1 - r2))) / (2 * 0.34)
    assert joint == 2 and abs(limit - exact) < 1e-4  # to the integration's accuracy (4 steps a sample)
    assert abs(slid.warning - (1 - 2e-3)) < 1e-9 and abs(slid.rank_loss - 1) < 1e-8
    assert batch[2].limit_exit is None and batch[2].warning is None and batch[2].error.max() < 1e-9
