r"""A path executed in MuJoCo: the fingers driven by grasptwist's joint rates, the object carried.

The object carries its own weight (gravity acts on it).  Every control step (:data:`CONTROL_DT`)
each joint is driven to the hand's track (:func:`grasptwist.engine.hands.track`, the joint
positions ``follow`` integrates): velocity control, the joint's damping pulling its rate to the
track's ``qdot(t)`` and its spring to ``q(t)``, plus the torques ``J^T f(t)`` of the grip that
holds the weight at the pose the path plans (:func:`grasptwist.engine.forces.hold.grip_along`).
A grasp without a hand drives its fingertips' slides along the contacts' paths.  At each
sample the object's pose is compared with the planned one, and each contact's slip is the
distance from the fingertip's centre to where the path carries it (``p(t) - r n(t)``, a point
fixed on the object): a contact that rolled as planned has none.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..engine import se3
from ..engine.fingertips import tip_centers
from ..engine.forces.hold import grip_along
from ..engine.hands import track
from ..engine.hold_test import joint_torques
from ..engine.path import integrate
from ..extras import require
from .hold import CHUNK, Unstable, diverged, load_model, rotation_angle
from .scene import OBJECT, TIP, Scene

__all__ = ["PathRun", "run_path", "CONTROL_DT"]

#: Time between two updates of the joints' targets and torques (seconds).
CONTROL_DT = 0.01

#: Time between two samples of the hand's track (its joint positions are interpolated between).
TRACK_DT = 0.05


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


def _targets(grasp, scene, segments, grid, radii):
    """The joints' positions along the path ``(G, n)``: the hand's track, or the tips' slides."""
    if grasp.hand is not None:
        return track(grasp.hand, scene.positions, grasp.points, segments, grid, normals=grasp.normals).positions
    poses = integrate(segments, grid)
    centres = tip_centers(grasp.points, grasp.normals, radii)
    moved = se3.transform(poses.rotation[:, None], poses.position[:, None], centres)
    return (moved - centres).reshape(len(grid), 9)


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

    Returns
    -------
    PathRun
    """
    mujoco = require("mujoco", "grasptwist simulate")
    model = load_model(scene)
    data = mujoco.MjData(model)
    times = np.asarray(times, dtype=float)
    grid = _grid(times, CONTROL_DT)
    coarse = _grid(times, TRACK_DT)  # the hand's track, interpolated between its samples
    tracked = _targets(grasp, scene, segments, coarse, scene.radii)
    q = np.stack([np.interp(grid, coarse, tracked[:, j]) for j in range(tracked.shape[1])], axis=1)
    rates = np.gradient(q, grid, axis=0) if len(grid) > 1 else np.zeros_like(q)
    poses, held = grip_along(
        grasp.points, grasp.normals, friction, scene.mass, center_of_mass, gravity, segments, grid, safety=safety
    )
    moved = se3.transform(poses.rotation[:, None], poses.position[:, None], np.asarray(grasp.points, float))
    forces = np.nan_to_num(held.force)
    torques = np.array([joint_torques(grasp.hand, q[k], moved[k], forces[k]) for k in range(len(grid))])
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
    # each tip's centre in the object's frame at the start: where the path carries it
    carried = (data.geom_xpos[tips] - origin) @ rot0
    sampled = np.isin(grid, times)
    out = {"time": [], "position": [], "angle": [], "slip": []}
    unstable = None
    step = 0
    for k, t in enumerate(grid):
        if sampled[k]:
            planned_origin = poses.rotation[k] @ origin + poses.position[k]
            planned = np.zeros(4)
            mujoco.mju_mat2Quat(planned, (poses.rotation[k] @ rot0).ravel())
            rot = data.xmat[body].reshape(3, 3)
            out["time"].append(t)
            out["position"].append(float(np.linalg.norm(data.qpos[free : free + 3] - planned_origin)))
            out["angle"].append(rotation_angle(mujoco, planned, data.qpos[free + 3 : free + 7]))
            out["slip"].append(
                np.linalg.norm(data.geom_xpos[tips] - (carried @ rot.T + data.qpos[free : free + 3]), axis=1)
            )
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
    status = held.status[sampled][: len(out["time"])]
    return PathRun(np.array(out["time"]), np.array(out["position"]), np.array(out["angle"]), slip, status, unstable)
