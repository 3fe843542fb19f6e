"""Random grasp data sets for the benchmarks (built here, so every script is self-contained)."""

import numpy as np

from grasptwist.engine import formulas, screws


def grasp_arrays(n, seed=0):
    """``n`` random grasps: points, normals, wrist ``(n, 3)``, twist ``(n, 6)``.

    Contacts on a unit sphere around a random centre, normals pointing
    roughly inward, the wrist above the contacts: a few near-degenerate rows
    occur, as in real data.
    """
    rng = np.random.default_rng(seed)
    centre = rng.uniform(-1, 1, (n, 1, 3))
    directions = rng.normal(size=(n, 3, 3))
    directions /= np.linalg.norm(directions, axis=-1, keepdims=True)
    points = centre + directions
    normals = -directions + 0.3 * rng.normal(size=(n, 3, 3))
    wrist = centre[:, 0] + rng.normal(size=(n, 3)) + [0, 0, 2.0]
    twist = rng.normal(size=(n, 6))
    return points, normals, wrist, twist


def solve_baseline(points, normals, wrist, twist):
    """Both decompositions and the contact velocities the plain way, batched or for one grasp.

    The basis screws of :mod:`grasptwist.engine.formulas`, the amplitudes by
    ``numpy.linalg.solve`` of the two 6x6 systems ``[Sigma Psi] (x; y) = T``
    and ``[Theta Sigma] (alpha; beta) = T``.  Returns ``(x; y)``,
    ``(alpha; beta)`` ``(..., 6)`` and the contact velocities ``(..., 3, 3)``.
    """
    sigma = formulas.sigma_lines(points)
    psi = formulas.psi_lines(points, wrist)
    theta = formulas.theta_lines(points, normals)
    rhs = twist[..., None]
    xy = np.linalg.solve(np.swapaxes(np.concatenate([sigma, psi], axis=-2), -1, -2), rhs)[..., 0]
    ab = np.linalg.solve(np.swapaxes(np.concatenate([theta, sigma], axis=-2), -1, -2), rhs)[..., 0]
    return xy, ab, screws.field_at(twist[..., None, :], points)


def save_npz(path, n, seed=0):
    """A data set of ``n`` grasps as the ``.npz`` that ``grasptwist resolve`` reads."""
    points, normals, wrist, twist = grasp_arrays(n, seed)
    np.savez(path, points=points, normals=normals, wrist=wrist, twist=twist)


def timed(command, repeats=1):
    """Best wall-clock time of a shell-less command, in seconds; it must succeed (exit 0 or 1)."""
    import subprocess
    import time

    best = float("inf")
    for _ in range(repeats):
        t0 = time.perf_counter()
        done = subprocess.run(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        best = min(best, time.perf_counter() - t0)
        if done.returncode not in (0, 1):
            raise SystemExit(f"{' '.join(map(str, command))} failed: {done.stderr.decode()[-500:]}")
    return best


def byte_compiled():
    """grasptwist's modules byte-compiled, as ``pip install`` leaves them: an editable install under
    ``PYTHONDONTWRITEBYTECODE`` would otherwise compile every module from source at every run."""
    import compileall
    import os

    import grasptwist

    compileall.compile_dir(os.path.dirname(grasptwist.__file__), quiet=1)


def grasptwist_command():
    """The installed ``grasptwist`` script next to this interpreter (else ``python -m grasptwist``)."""
    import shutil
    import sys
    from pathlib import Path

    script = Path(sys.executable).parent / "grasptwist"
    return (
        [str(script)]
        if script.exists()
        else [
            shutil.which("grasptwist") or sys.executable,
            *([] if shutil.which("grasptwist") else ["-m", "grasptwist"]),
        ]
    )


def save_parquet(folder, n, shards=8, seed=0):
    """A data set of ``n`` grasps as ``shards`` Parquet files (``part-000.parquet`` ...) in ``folder``,
    in the columns ``grasptwist resolve`` reads; returns their paths."""
    import os

    import pyarrow.parquet as pq

    from grasptwist.io import parquet

    table = parquet.grasp_table(*grasp_arrays(n, seed), names=np.arange(n).astype(str))
    os.makedirs(folder, exist_ok=True)
    paths = []
    for i, start in enumerate(range(0, n, -(-n // shards))):
        paths.append(os.path.join(folder, f"part-{i:03d}.parquet"))
        part = table.slice(start, -(-n // shards))
        pq.write_table(part, paths[-1], row_group_size=65536, use_dictionary=[parquet.NAME_COLUMN])
    return paths
