"""Make the picture of docs/guide/simulation.md: docs/images/simulate-trifinger.png.

The TriFinger Pro holding the 65 mm cube (``grasps/trifinger-cube.yaml``, 94 g, ``mu = 1``) on its
table at the end of each of the six directions of the hold test, the load drawn as a red arrow
through the cube's centre on the camera's side (onto the near face where the load points away); rendered offscreen by MuJoCo (``MUJOCO_GL=egl``; Debian's
libgl1-mesa-dri where there is no GPU) and tiled by matplotlib.

    MUJOCO_GL=egl .venv/bin/python docs/make_simulation_picture.py
"""

import os
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import mujoco  # noqa: E402
import numpy as np  # noqa: E402

from grasptwist.engine.hold_test import DIRECTIONS, UNITS  # noqa: E402
from grasptwist.run.options import SimulateOptions  # noqa: E402
from grasptwist.run.placement import read  # noqa: E402
from grasptwist.run.simulate import simulate_grasp  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
os.environ.setdefault("MUJOCO_GL", "egl")


def main():
    grasp = read(str(ROOT / "grasps" / "trifinger-cube.yaml"))[0]
    frames = {}
    renderer = {}

    def observe(name, model, data):
        camera = mujoco.MjvCamera()
        camera.lookat[:] = [0, 0, 0.04]
        camera.distance, camera.azimuth, camera.elevation = 0.38, 150, -30
        if "r" not in renderer:
            renderer["r"] = mujoco.Renderer(model, 360, 360)
            # a first frame drawn and dropped: the first (mesa's EGL) has stripes of shadow across the sky
            renderer["r"].update_scene(data, camera)
            renderer["r"].render()
        r = renderer["r"]
        r.update_scene(data, camera)
        centre = data.xpos[model.body("object").id]
        arrow = r.scene.geoms[r.scene.ngeom]
        u = UNITS[DIRECTIONS.index(name)]
        # on the camera's side of the cube: from its face outwards, or, where that side faces away
        # (-x, +y, -z: the cube or the table would hide it), pushing onto the near face
        eye = r.scene.camera[0].pos
        start, tip = centre + 0.035 * u, centre + 0.1 * u
        if np.dot(u, eye - centre) < 0:
            start, tip = centre - 0.1 * u, centre - 0.035 * u
        mujoco.mjv_initGeom(arrow, mujoco.mjtGeom.mjGEOM_ARROW, np.zeros(3), np.zeros(3), np.zeros(9), [1, 0, 0, 1])
        mujoco.mjv_connector(arrow, mujoco.mjtGeom.mjGEOM_ARROW, 0.006, start, tip)
        r.scene.ngeom += 1
        frames[name] = r.render().copy()

    sim = simulate_grasp(SimulateOptions(mass=0.094, friction=1.0, table=0.0), grasp, observe=observe)
    fig, axes = plt.subplots(2, 3, figsize=(9, 6.3))
    for ax, d in zip(axes.ravel(), sim.test.directions):
        ax.imshow(frames[d.name])
        ax.set_title(f"{d.name}: {'held' if d.held else 'not held'}, moved {d.displacement * 1000:.2g} mm", fontsize=10)
        ax.axis("off")
    fig.suptitle("grasptwist simulate: the TriFinger holds the cube, its weight along each direction (red)")
    fig.tight_layout()
    out = ROOT / "docs" / "images" / "simulate-trifinger.png"
    fig.savefig(out, dpi=80)
    print(out)


if __name__ == "__main__":
    main()
