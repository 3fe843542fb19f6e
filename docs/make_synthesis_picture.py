"""Make the picture of docs/guide/synthesis.md: docs/images/synthesize-trifinger.png.

The best grasp ``grasptwist synthesize`` finds for the TriFinger Pro on the bundled 65 mm cube on
its table (``grasps/trifinger-cube.yaml``, 94 g, ``mu = 1``, the default seed and objective), the
hand at the grasp's joint positions: MuJoCo's scene of it (``grasptwist simulate --mjcf``'s, the
table a plane at z = 0), rendered offscreen by MuJoCo from two sides (``MUJOCO_GL=egl``; Debian's
libgl1-mesa-dri where there is no GPU), each contact's inward normal drawn as a red arrow, tiled
by matplotlib.

    MUJOCO_GL=egl .venv/bin/python docs/make_synthesis_picture.py
"""

import os
import subprocess
import sys
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import mujoco  # noqa: E402
import numpy as np  # noqa: E402

from grasptwist.run.options import SimulateOptions  # noqa: E402
from grasptwist.run.placement import read  # noqa: E402
from grasptwist.run.simulate import _prepared  # noqa: E402
from grasptwist.sim.hold import load_model  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
os.environ.setdefault("MUJOCO_GL", "egl")
MASS, MU = 0.094, 1.0


def found_grasp(folder):
    """The search's best grasp, read back from the grasp file ``synthesize -o`` writes."""
    out = Path(folder) / "found.yaml"
    args = ["synthesize", ROOT / "grasps" / "trifinger-cube.yaml", "-n", "1", "--mass", MASS, "--friction", MU]
    run = subprocess.run([sys.executable, "-m", "grasptwist", *map(str, args), "-o", out, "-q"], capture_output=True)
    if run.returncode:
        sys.exit(run.stderr.decode())
    return read(str(out))[0]


def main():
    with tempfile.TemporaryDirectory() as folder:
        grasp = found_grasp(folder)
        *_, scene, _ = _prepared(SimulateOptions(mass=MASS, friction=MU), grasp, None, hold=True)
    model = load_model(scene)
    data = mujoco.MjData(model)
    data.qpos[[model.jnt_qposadr[model.joint(j).id] for j in scene.joints]] = scene.positions
    mujoco.mj_forward(model, data)
    renderer = mujoco.Renderer(model, 420, 420)
    frames = []
    for azimuth, elevation in ((60, -20), (270, -12)):
        camera = mujoco.MjvCamera()
        camera.lookat[:] = [0, 0, 0.05]
        camera.distance, camera.azimuth, camera.elevation = 0.5, azimuth, elevation
        renderer.update_scene(data, camera)
        for p, n in zip(grasp.points, grasp.normals):  # each contact's normal, into the cube
            arrow = renderer.scene.geoms[renderer.scene.ngeom]
            mujoco.mjv_initGeom(arrow, mujoco.mjtGeom.mjGEOM_ARROW, np.zeros(3), np.zeros(3), np.zeros(9), [1, 0, 0, 1])
            mujoco.mjv_connector(arrow, mujoco.mjtGeom.mjGEOM_ARROW, 0.003, p - 0.03 * n, p)
            renderer.scene.ngeom += 1
        frames.append(renderer.render().copy())
    fig, axes = plt.subplots(1, 2, figsize=(9, 4.7))
    for ax, frame in zip(axes, frames):
        ax.imshow(frame)
        ax.axis("off")
    fig.suptitle("grasptwist synthesize: the TriFinger Pro's best grasp of the cube on its table")
    fig.tight_layout()
    out = ROOT / "docs" / "images" / "synthesize-trifinger.png"
    fig.savefig(out, dpi=80)
    print(out)


if __name__ == "__main__":
    main()
