"""The contact settings make MuJoCo's friction Coulomb's: a block on a plane tilted just under
``atan(mu)`` stays, just over it slides with the closed-form acceleration ``g (sin a - mu cos a)``."""

import math

import numpy as np
import pytest

from grasptwist.sim.contact import CONTACT, SOFT_CONDIM, option_xml, tip_friction

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


# A rod pinched along its axis (x) by two pads pressing SQUEEZE each, turned about its axis by a
# moment: a point contact's friction has no moment about the axis (its forces pass through it); a soft
# contact's torsional friction resists up to mu e SQUEEZE per pad (grasptwist's cone, MuJoCo's mu e).
E, SQUEEZE, SPIN = 0.01, 10.0, 0.05


def _spin_rate(moment: float, torsion) -> tuple[float, float]:
    """The rod's rate about its axis after SPIN seconds under ``moment`` (and its inertia about it)."""
    friction, condim = tip_friction(MU, torsion)
    pads = "".join(
        f'''<body pos="{side * 0.055} 0 0"><joint type="slide" axis="1 0 0" damping="5"/>
<geom type="sphere" size="0.005" mass="0.01" friction="{" ".join(map(str, friction))}" condim="{condim}"/></body>'''
        for side in (-1, 1)
    )
    xml = f"""<mujoco>{option_xml([0, 0, 0])}<worldbody>
<body name="rod"><freejoint/><geom type="box" size="0.05 0.01 0.01" mass="0.1" friction="0 0 0"/></body>{pads}
</worldbody></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    data.qfrc_applied[6:8] = SQUEEZE, -SQUEEZE  # the pads' slides, towards the rod
    mujoco.mj_step(model, data, nstep=50)  # the squeeze settles
    data.xfrc_applied[1, 3] = moment
    mujoco.mj_step(model, data, nstep=round(SPIN / model.opt.timestep))
    return float(data.qvel[3]), float(model.body_inertia[1][0])


def test_a_soft_contact_is_mujocos_torsional_friction_mu_e():
    assert tip_friction(MU, E) == ((MU, MU * E, 0.0), SOFT_CONDIM)
    assert tip_friction(MU, 0.0) == tip_friction(MU) == ((MU, 0.0, 0.0), CONTACT.condim)


@pytest.mark.parametrize("share", [0.5, 0.97])
def test_soft_pads_hold_a_rod_turned_just_under_their_torsional_limit(share):
    limit = 2 * MU * E * SQUEEZE  # two pads, each |tau| <= mu e f_n
    soft, inertia = _spin_rate(share * limit, E)
    point, _ = _spin_rate(share * limit, None)
    assert abs(soft) < 1e-9
    # point contacts do not resist it at all: the rod spins up freely, M t / I
    assert point == pytest.approx(share * limit * SPIN / inertia, rel=1e-3)


def test_soft_pads_let_a_rod_turn_just_over_it_with_coulombs_torsional_friction():
    limit = 2 * MU * E * SQUEEZE
    moment = 1.1 * limit
    soft, inertia = _spin_rate(moment, E)
    # sliding: the pads' torsional friction mu e f_n each, the rest accelerates it (71.6 rad/s for 75)
    assert soft == pytest.approx((moment - limit) * SPIN / inertia, rel=0.1)
