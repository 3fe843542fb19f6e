"""A path executed in MuJoCo (issue 38, item 3): a path that stands still holds; the paper's claim in
physics, the resolved finger twists commanded move the object with the desired twist (the TriFinger
spins the cube as planned).  Slow: seconds of tracking."""

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

pytestmark = pytest.mark.slow


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


def test_the_fingers_hold_the_cube_still_along_a_path_that_stands_still():
    run = _spin(0.0)
    assert run.unstable is None and len(run.times) == 6
    assert run.position_error.max() < 5e-4 and run.angle_error.max() < math.radians(0.5)
    assert run.slip.max() < 5e-4 and (run.grip_status == 0).all()


def test_commanding_the_resolved_finger_twists_spins_the_cube_with_the_desired_twist():
    # the paper's claim: the fingers driven by the resolved rates (each tip rolling, without slip)
    # turn the cube 0.5 rad about the vertical; measured: it ends 0.38 deg and 0.15 mm from the plan,
    # its contacts 0.1-0.4 mm from the planned ones (the grip's settling: 0.22 deg standing still);
    # driven to follow's track instead (each contact held fixed on the cube) it ended 9 deg behind
    run = _spin(0.5)
    assert run.unstable is None and (run.grip_status == 0).all()
    assert run.angle_error.max() < math.radians(2.0) and run.position_error.max() < 1e-3
    assert run.slip.max() < 1e-3
