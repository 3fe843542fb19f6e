"""The contact settings make MuJoCo's friction Coulomb's: a block on a plane tilted just under
``atan(mu)`` stays, just over it slides with the closed-form acceleration ``g (sin a - mu cos a)``."""

import math

import numpy as np
import pytest

from grasptwist.sim.contact import CONTACT, option_xml

mujoco = pytest.importorskip("mujoco")

G, MU, SECONDS = 9.81, 0.5, 0.3


def _slide(angle: float, seconds: float = SECONDS) -> float:
    """How far a block slides down a plane tilted by ``angle`` in ``seconds`` (gravity tilted instead)."""
    gravity = G * np.array([math.sin(angle), 0.0, -math.cos(angle)])
    xml = f"""<mujoco><compiler angle="radian"/>{option_xml(gravity)}
<worldbody><geom type="plane" size="0 0 1" friction="0"/>
<body pos="0 0 0.01"><freejoint/><geom type="box" size="0.02 0.02 0.01" mass="0.1" friction="{MU}"/></body>
</worldbody></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    mujoco.mj_step(model, data, nstep=round(seconds / model.opt.timestep))
    return float(data.qpos[0])


def test_a_block_stays_just_under_the_friction_angle():
    # the soft contact settles within 0.1 s (8.5 um along the plane, as it sinks 0.1 mm into it);
    # from then on the block does not creep: 0.01 um in the next 0.2 s (0.3 um without noslip)
    angle = math.atan(MU) - math.radians(1)
    settled = _slide(angle, 0.1)
    assert abs(settled) < 2e-5
    assert abs(_slide(angle) - settled) < 1e-7


def test_a_block_slides_just_over_it_as_coulomb_says():
    angle = math.atan(MU) + math.radians(1)
    expected = 0.5 * G * (math.sin(angle) - MU * math.cos(angle)) * SECONDS**2
    assert _slide(angle) == pytest.approx(expected, rel=0.05)


def test_the_cone_is_elliptic_and_the_contact_a_point_with_friction():
    assert (CONTACT.cone, CONTACT.condim) == ("elliptic", 3)
