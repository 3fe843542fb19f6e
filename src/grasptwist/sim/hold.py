r"""The six-direction hold test, run in MuJoCo.

For each direction ``d`` of :data:`~grasptwist.engine.hold_test.DIRECTIONS`, from the grasp
afresh: the hand stands at the grasp's joint positions, held there by stiff joint springs
(:class:`~grasptwist.sim.scene.Drive`, stiffened by the ratio of the direction's largest finger force
to the load when that exceeds 1: fingers pushing ``F`` on an object of radius ``r`` roll it away
unless their springs' stiffness exceeds ``F / r``), its own gravity compensated; its joints exert
the torques ``tau = J^T f_d`` of grasptwist's grip ``f_d`` for the load (with soft contacts, the soft
grip: each finger's force and its torsion about its normal, ``tau = J^T (f; tau_n n)``), squeezed so that every
finger presses at least ``squeeze`` times the load (:func:`~grasptwist.engine.hold_test.squeezed`); the object, released,
carries its weight ``m |g|`` along ``d`` (its own gravity compensated) for ``duration``.
The grasp holds in ``d`` when the object's centre moved less than the distance tolerance and
it turned less than the angle tolerance.  A direction whose grip does not exist is not
simulated (it does not hold).  A simulation that diverges (a NaN, MuJoCo's bad-acceleration
or full-contact warnings) stops there: the test says where.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..engine.forces.grip import grip
from ..engine.hold_test import DIRECTIONS, UNITS, direction_wrenches, held, joint_torques, squeezed
from ..extras import require
from .scene import OBJECT, TIP, Scene

__all__ = [
    "Direction",
    "HoldTest",
    "Unstable",
    "hold_test",
    "load_model",
    "contact_forces",
    "rotation_angle",
    "diverged",
    "CHUNK",
    "SQUEEZE",
]

#: Each finger's least normal force in the hold test, in loads (:func:`hold_test`'s ``squeeze``): the
#: least grip leaves a finger idle where two suffice, and the object turns about them
#: (``docs/guide/simulation.md``, "Choices measured").
SQUEEZE = 0.5

#: Steps simulated between two checks for divergence (and for an object already gone).
CHUNK = 50

#: MuJoCo's warnings that mean the simulation diverged.
_DIVERGED = ("mjWARN_BADQACC", "mjWARN_CONTACTFULL", "mjWARN_CNSTRFULL", "mjWARN_BADQPOS", "mjWARN_BADQVEL")


@dataclass(frozen=True)
class Unstable:
    """Where a simulation diverged: the direction (or path), the step and its time, and why."""

    where: str
    step: int
    time: float
    reason: str


@dataclass(frozen=True, eq=False)
class Direction:
    """One direction of the hold test.

    ``displacement`` (length) and ``rotation`` (radians) of the object at the end (NaN when not
    simulated); ``forces`` ``(3, 3)`` each finger's contact force on the object in MuJoCo at the
    end, ``planned`` grasptwist's grip; ``grip_status`` the grip's status (0: it exists);
    ``torsion`` and ``planned_torsion`` ``(3,)`` each soft contact's moment about its normal on the
    object, in MuJoCo and planned (None with point contacts).
    """

    name: str
    held: bool
    displacement: float
    rotation: float
    forces: np.ndarray
    planned: np.ndarray
    grip_status: int
    simulated: bool
    torsion: np.ndarray | None = None
    planned_torsion: np.ndarray | None = None


@dataclass(frozen=True, eq=False)
class HoldTest:
    """The six directions, and whether all held; ``unstable`` where a simulation diverged."""

    directions: tuple[Direction, ...]
    load: float
    unstable: Unstable | None = None

    @property
    def held(self) -> bool:
        return self.unstable is None and all(d.held for d in self.directions)


def _quiet(message: str) -> None:
    """MuJoCo's warnings kept from stderr and from its log file (``MUJOCO_LOG.TXT`` in the working
    folder): the simulation reads them from its data's counters (:func:`diverged`)."""


def load_model(scene: Scene):
    """MuJoCo's model of ``scene``, its hand's joint springs at rest at the grasp; ``ValueError``:
    the reason MuJoCo cannot compile it."""
    mujoco = require("mujoco", "grasptwist simulate")
    mujoco.set_mju_user_warning(_quiet)
    model = mujoco.MjModel.from_xml_string(scene.xml, scene.assets)
    adr = [model.jnt_qposadr[model.joint(j).id] for j in scene.joints]
    model.qpos_spring[adr] = scene.positions
    return model


def contact_forces(mujoco, model, data, body: int, tips, torsion=None) -> np.ndarray:
    """Each fingertip's contact force on ``body`` (world frame), summed over its contacts, ``(3, 3)``;
    with ``torsion`` (an array ``(3,)``, filled) also each one's moment about its contact's normal
    (a soft contact's torsional friction; 0 for a point contact), signed about the normal into ``body``."""
    out = np.zeros((len(tips), 3))
    local = np.zeros(6)
    for i in range(data.ncon):
        c = data.contact[i]
        g1, g2 = c.geom1, c.geom2
        b1, b2 = model.geom_bodyid[g1], model.geom_bodyid[g2]
        for f, tip in enumerate(tips):
            if (g1 == tip and b2 == body) or (g2 == tip and b1 == body):
                mujoco.mj_contactForce(model, data, i, local)
                world = c.frame.reshape(3, 3).T @ local[:3]  # the force geom1 exerts on geom2
                out[f] += world if g1 == tip else -world
                if torsion is not None:  # about the frame's normal, which points from geom1 to geom2
                    torsion[f] += local[3] if g1 == tip else -local[3]
    return out


def rotation_angle(mujoco, q0, q1) -> float:
    """The angle between two unit quaternions' rotations (radians), exact near zero."""
    rel, neg = np.zeros(4), np.zeros(4)
    mujoco.mju_negQuat(neg, q0)
    mujoco.mju_mulQuat(rel, neg, q1)
    return 2 * math.atan2(float(np.linalg.norm(rel[1:])), abs(float(rel[0])))


def diverged(mujoco, data) -> str | None:
    if not (np.isfinite(data.qpos).all() and np.isfinite(data.qvel).all()):
        return "a position or velocity is not finite"
    for name in _DIVERGED:
        if data.warning[getattr(mujoco.mjtWarning, name)].number:
            return f"MuJoCo's {name[7:].lower()} warning"
    return None


def _torsions(planned, d):
    """A direction's ``(torsion, planned_torsion)`` before it is simulated: NaN and the grip's (None, None
    with point contacts)."""
    if planned.torsion is None:
        return None, None
    return np.full(3, np.nan), planned.torsion[d]


def hold_test(
    scene: Scene,
    grasp,
    *,
    center_of_mass,
    friction,
    load: float,
    duration: float = 1.0,
    distance_tol: float = 0.002,
    angle_tol: float = math.radians(2.0),
    safety: float = 1.0,
    squeeze: float = SQUEEZE,
    torsion=None,
    observe=None,
) -> HoldTest:
    """The six-direction hold test of ``grasp`` in ``scene`` (module docstring).

    Parameters
    ----------
    scene : Scene
        Built with ``object_gravcomp=True`` (:func:`~grasptwist.sim.scene.build_scene`).
    grasp : Grasp
        Its contacts, normals and hand (placed).
    center_of_mass : (3,) array
    friction : (3,) array
    load : float
        The load's size, ``m |g|``.
    duration : float
        Simulated time per direction.
    distance_tol, angle_tol : float
        How far the object may move and turn (radians) and still count as held.
    safety : float
        The grip's safety factor (:func:`~grasptwist.engine.forces.grip.grip`).
    squeeze : float
        Each finger's least normal force, in loads (:data:`SQUEEZE`).
    torsion : (3,) array or None
        Soft contacts' torsional radii ``e`` (the scene built with them): the grip is the soft one
        (:func:`~grasptwist.engine.forces.grip.grip`'s ``torsion``), its moments about the normals
        exerted through the joints too.
    observe : callable or None
        ``(direction, model, data)``, called at the end of each direction simulated (pictures:
        ``docs/make_simulation_picture.py``).

    Returns
    -------
    HoldTest
    """
    mujoco = require("mujoco", "grasptwist simulate")
    model = load_model(scene)
    data = mujoco.MjData(model)
    body = model.body(OBJECT).id
    free = model.jnt_qposadr[model.joint(OBJECT).id]
    tips = [model.geom(TIP.format(f)).id for f in range(3)]
    qadr = [model.jnt_qposadr[model.joint(j).id] for j in scene.joints]
    vadr = [model.jnt_dofadr[model.joint(j).id] for j in scene.joints]
    wrenches = direction_wrenches(scene.mass, center_of_mass, load)
    planned = grip(grasp.points, grasp.normals, wrenches, friction, safety=safety, torsion=torsion)
    unit = grasp.normals / np.linalg.norm(grasp.normals, axis=-1, keepdims=True)
    forces = squeezed(grasp.points, unit, planned.force, np.asarray(friction) / safety, squeeze * load)
    moments = None if planned.torsion is None else np.nan_to_num(planned.torsion)[..., None] * unit
    torques = joint_torques(grasp.hand, scene.positions, grasp.points, np.nan_to_num(forces), moments)
    # each direction's drive as stiff against its largest finger force as the scene's against the load
    stiffer = np.maximum(1.0, np.nan_to_num(np.linalg.norm(forces, axis=-1).max(axis=-1)) / load)
    jnt = [model.joint(j).id for j in scene.joints]
    drive = model.jnt_stiffness[jnt].copy(), model.dof_damping[vadr].copy(), model.dof_armature[vadr].copy()
    steps = max(1, round(duration / model.opt.timestep))
    # gone: the object moved this far, so that it cannot come back within the tolerances
    gone = 10 * distance_tol + 1e-9
    out = []
    for d, name in enumerate(DIRECTIONS):
        if planned.status[d] != 0:
            nan = np.full((3, 3), np.nan)
            out.append(
                Direction(
                    name, False, math.nan, math.nan, nan, nan, int(planned.status[d]), False, *_torsions(planned, d)
                )
            )
            continue
        model.jnt_stiffness[jnt], model.dof_damping[vadr], model.dof_armature[vadr] = (a * stiffer[d] for a in drive)
        mujoco.mj_resetData(model, data)
        data.qpos[qadr] = scene.positions
        mujoco.mj_forward(model, data)
        start, quat = data.qpos[free : free + 3].copy(), data.qpos[free + 3 : free + 7].copy()
        data.qfrc_applied[vadr] = torques[d]
        data.xfrc_applied[body, :3] = load * UNITS[d]
        done = 0
        while done < steps:
            n = min(CHUNK, steps - done)
            mujoco.mj_step(model, data, nstep=n)
            done += n
            why = diverged(mujoco, data)
            if why is not None:
                return HoldTest(tuple(out), load, Unstable(name, done, done * model.opt.timestep, why))
            if np.linalg.norm(data.qpos[free : free + 3] - start) > gone:
                break
        if observe is not None:
            observe(name, model, data)
        moved = float(np.linalg.norm(data.qpos[free : free + 3] - start))
        turned = rotation_angle(mujoco, quat, data.qpos[free + 3 : free + 7])
        twisted = None if planned.torsion is None else np.zeros(3)
        exerted = contact_forces(mujoco, model, data, body, tips, twisted)
        ok = bool(held(moved, turned, distance_tol, angle_tol))
        out.append(Direction(name, ok, moved, turned, exerted, forces[d], 0, True, twisted, _torsions(planned, d)[1]))
    return HoldTest(tuple(out), load)
