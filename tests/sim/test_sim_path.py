"""A path executed in MuJoCo (issue 38, item 3): a path that stands still holds; the paper's claim in
physics, the resolved finger twists commanded move the object with the desired twist (the TriFinger
spins the cube as planned, slid fingertips spin a ball).  The TriFinger's: seconds of tracking, slow."""

import math
from dataclasses import replace

import numpy as np
import pytest

from grasptwist.engine.objects.geometry import mass_properties
from grasptwist.model import Segment
from grasptwist.run.placement import read
from grasptwist.sim.path import run_path
from grasptwist.sim.scene import build_scene
from places import GRASPS


def _spin(rate):
    g = read(str(GRASPS / "trifinger-cube.yaml"))[0]
    mass, mu = 0.094, np.ones(3)
    obj = replace(g.object, mass=mass)
    scene = build_scene(
        replace(g, object=obj), mass=mass, friction=mu, load=mass * 9.81, tolerance=0.002, object_gravcomp=False
    )
    segments = [Segment(1.0, twist=np.array([0, 0, rate, 0, 0, 0]))]
    return run_path(
        scene,
        g,
        segments,
        np.linspace(0, 1, 6),
        friction=mu,
        center_of_mass=mass_properties(obj).center_of_mass,
        gravity=np.array([0, 0, -9.81]),
        safety=1.25,
    )


@pytest.mark.slow
def test_the_fingers_hold_the_cube_still_along_a_path_that_stands_still():
    run = _spin(0.0)
    assert run.unstable is None and len(run.times) == 6
    assert run.position_error.max() < 5e-4 and run.angle_error.max() < math.radians(0.5)
    assert run.slip.max() < 5e-4 and (run.grip_status == 0).all()


@pytest.mark.slow
def test_commanding_the_resolved_finger_twists_spins_the_cube_with_the_desired_twist():
    # the paper's claim: the fingers driven by the resolved rates (each tip rolling, without slip)
    # turn the cube 0.5 rad about the vertical; measured: it ends 0.38 deg and 0.15 mm from the plan,
    # its contacts 0.1-0.4 mm from the planned ones (the grip's settling: 0.22 deg standing still);
    # driven to follow's track instead (each contact held fixed on the cube) it ended 9 deg behind
    run = _spin(0.5)
    assert run.unstable is None and (run.grip_status == 0).all()
    assert run.angle_error.max() < math.radians(2.0) and run.position_error.max() < 1e-3
    assert run.slip.max() < 1e-3


def test_slid_fingertips_spin_a_ball_as_planned_rolling_round_it():
    # sphere-tripod's ball (radius 35 mm) turned about z at 1 rad/s for 0.3 s by three tips on slides,
    # each rolling round it (its centre moving with the ball's point at the contact); measured: 0.34 deg
    # (the grip settling) and 0.03 mm from the plan, the tips 0.06 mm from theirs.  Driven to follow's track (the tips' centres carried by the ball) the
    # full 1 rad ended 4.3 deg behind, each tip 2.4 mm off
    g = read(str(GRASPS / "sphere.yaml"))[0]
    mass, mu = 0.1, np.full(3, 0.8)
    obj = replace(g.object, mass=mass)
    scene = build_scene(
        replace(g, object=obj), mass=mass, friction=mu, load=mass * 9.81, tolerance=0.002, object_gravcomp=False
    )
    run = run_path(
        scene,
        g,
        [Segment(0.3, twist=np.array([0, 0, 1.0, 0, 0, 0]))],
        np.linspace(0, 0.3, 4),
        friction=mu,
        center_of_mass=np.zeros(3),
        gravity=np.array([0, 0, -9.81]),
        safety=1.25,
    )
    assert run.unstable is None and (run.grip_status == 0).all()
    assert run.angle_error.max() < math.radians(1.0) and run.position_error.max() < 2e-4
    assert run.slip.max() < 3e-4
