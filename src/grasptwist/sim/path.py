r"""A path executed in MuJoCo: the fingers driven by grasptwist's resolved joint rates, the object carried.

The object carries its own weight (gravity acts on it).  The fingers' plan is
:func:`grasptwist.engine.rolling.roll`'s: the paper's resolved rates, each finger's point at its
contact moving with the object's twist there, integrated with the contact taken afresh where the
fingertip sphere touches, so that each sphere rolls on the object without slipping.  Every
control step (:data:`CONTROL_DT`) each joint is driven to that plan: velocity control, the joint's
damping pulling its rate to the plan's ``qdot(t)`` (feed-forward) and its spring to ``q(t)``,
plus the torques ``J^T f(t)`` of the grip (:func:`~grasptwist.engine.forces.grip.grip`) that holds
the weight at the planned pose with the planned contacts.  A grasp without a hand drives its
fingertips' slides the same way.  At each sample the object's pose is compared with the planned
one, and each contact's slip is the distance, in the object's frame, from the fingertip's centre to
the plan's: a contact that rolled as planned has none.

Why the plan rolls (measured on the TriFinger's 0.5 rad ``spin`` of the bundled cube): driven to
``follow``'s track (:func:`grasptwist.engine.hands.track`, each contact held fixed on the object),
the plan asks each 10 mm tip to slide 5.1 mm over the cube while its link turns; friction holds
instead (the tips slid 0.3 to 0.9 mm), so they rolled and dragged the cube back: it ended 9.0
degrees behind the plan, though the joints tracked theirs within 0.004 rad.  Driven to the
rolling plan, it ends 0.5 degree and 0.14 mm from it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..engine import se3
from ..engine.forces.grip import grip
from ..engine.forces.hold import hold_wrench
from ..engine.hold_test import joint_torques
from ..engine.path import integrate
from ..engine.rolling import roll
from ..extras import require
from .hold import CHUNK, Unstable, diverged, load_model, rotation_angle
from .scene import OBJECT, TIP, Scene

__all__ = ["PathRun", "run_path", "CONTROL_DT", "PLAN_DT"]

#: Time between two updates of the joints' targets and torques (seconds).
CONTROL_DT = 0.01

#: Time between two samples of the rolling plan (its joint positions, rates and torques are
#: interpolated between them).
PLAN_DT = 0.05


@dataclass(frozen=True, eq=False)
class PathRun:
    """A path executed: at each sample time, the object's position and angle errors from the plan
    and each contact's slip ``(T, 3)``; ``unstable`` where the simulation diverged (the samples end there)."""

    times: np.ndarray
    position_error: np.ndarray
    angle_error: np.ndarray
    slip: np.ndarray
    grip_status: np.ndarray
    unstable: Unstable | None = None


def _grid(times, dt):
    end = float(times[-1])
    return np.union1d(np.append(np.arange(0.0, end, dt), end), times)


def run_path(
    scene: Scene,
    grasp,
    segments,
    times,
    *,
    friction,
    center_of_mass,
    gravity,
    safety: float = 1.0,
    torsion=None,
) -> PathRun:
    """Execute ``segments`` (module docstring), sampled at ``times`` (increasing, from 0).

    Parameters
    ----------
    scene : Scene
        Built with ``object_gravcomp=False``.
    grasp : Grasp
    segments : sequence of Segment
    times : (T,) array
    friction : (3,) array
    center_of_mass, gravity : (3,) arrays
    safety : float
        The grip's safety factor.
    torsion : (3,) array or None
        Soft contacts' torsional radii (the scene built with them): the soft grip, its moments about
        the planned normals exerted through the joints too.

    Returns
    -------
    PathRun
    """
    mujoco = require("mujoco", "grasptwist simulate")
    model = load_model(scene)
    data = mujoco.MjData(model)
    times = np.asarray(times, dtype=float)
    grid = _grid(times, CONTROL_DT)
    coarse = _grid(times, PLAN_DT)  # the plan, interpolated between its samples
    plan = roll(grasp.hand, scene.positions, grasp.object, grasp.points, grasp.normals, scene.radii, segments, coarse)
    poses = integrate(segments, coarse)
    wrench = hold_wrench(scene.mass, center_of_mass, gravity, poses.rotation, poses.position)
    held = grip(plan.points, plan.normals, wrench, friction, safety=safety, torsion=torsion)
    forces = np.nan_to_num(held.force)
    unit = plan.normals / np.linalg.norm(plan.normals, axis=-1, keepdims=True)
    moments = np.zeros_like(forces) if held.torsion is None else np.nan_to_num(held.torsion)[..., None] * unit
    torques = np.array([joint_torques(grasp.hand, *row) for row in zip(plan.positions, plan.points, forces, moments)])
    q, rates, torques = (
        np.stack([np.interp(grid, coarse, a[:, j]) for j in range(a.shape[1])], axis=1)
        for a in (plan.positions, plan.rates, torques)
    )
    body = model.body(OBJECT).id
    free = model.jnt_qposadr[model.joint(OBJECT).id]
    qadr = [model.jnt_qposadr[model.joint(j).id] for j in scene.joints]
    vadr = [model.jnt_dofadr[model.joint(j).id] for j in scene.joints]
    tips = [model.geom(TIP.format(f)).id for f in range(3)]
    damping = model.dof_damping[vadr]
    data.qpos[qadr] = scene.positions
    mujoco.mj_forward(model, data)
    origin = data.qpos[free : free + 3].copy()
    rot0 = data.xmat[body].reshape(3, 3).copy()
    index = np.searchsorted(coarse, times)
    # each planned centre where the object was at the start (the planned pose undone)
    back = se3.inverse(poses.rotation[index], poses.position[index])
    planned_centres = se3.transform(back[0][:, None], back[1][:, None], plan.centers[index])
    sampled = np.isin(grid, times)
    out = {"time": [], "position": [], "angle": [], "slip": []}
    unstable = None
    step = 0
    s = 0
    for k, t in enumerate(grid):
        if sampled[k]:
            j = index[s]
            planned_origin = poses.rotation[j] @ origin + poses.position[j]
            planned = np.zeros(4)
            mujoco.mju_mat2Quat(planned, (poses.rotation[j] @ rot0).ravel())
            rot = data.xmat[body].reshape(3, 3)
            here = data.qpos[free : free + 3]
            out["time"].append(t)
            out["position"].append(float(np.linalg.norm(here - planned_origin)))
            out["angle"].append(rotation_angle(mujoco, planned, data.qpos[free + 3 : free + 7]))
            # each tip's centre where the object was at the start (its actual pose undone)
            at_start = (data.geom_xpos[tips] - here) @ rot @ rot0.T + origin
            out["slip"].append(np.linalg.norm(at_start - planned_centres[s], axis=1))
            s += 1
        if k + 1 == len(grid):
            break
        model.qpos_spring[qadr] = q[k + 1]
        data.qfrc_applied[vadr] = torques[k] + damping * rates[k]
        n = max(1, round((grid[k + 1] - t) / model.opt.timestep))
        for start in range(0, n, CHUNK):
            mujoco.mj_step(model, data, nstep=min(CHUNK, n - start))
            why = diverged(mujoco, data)
            if why is not None:
                step += start + min(CHUNK, n - start)
                unstable = Unstable(f"t = {t:g}", step, step * model.opt.timestep, why)
                break
        if unstable is not None:
            break
        step += n
    slip = np.array(out["slip"]).reshape(-1, 3)
    status = held.status[index][: len(out["time"])]
    return PathRun(np.array(out["time"]), np.array(out["position"]), np.array(out["angle"]), slip, status, unstable)
