"""Data set to data set: ``grasptwist resolve in.npz -f npz -o out.npz`` on 10^6 grasps.

Run: ``python bench/npz.py [--n 1000000]``.  The baseline, in this process,
is the least any tool must do: ``numpy.load`` the input, the three engine
calls, and ``numpy.savez`` of the same result arrays.  Target: the command,
start-up included, within 2x of that.  Each run starts after ``os.sync()``,
so that none pays for writing back the previous one's output.
"""

import argparse
import os
import tempfile
import time

import numpy as np

import grasptwist as gt
from _data import grasptwist_command, save_npz, timed


def baseline(src, dst):
    os.sync()  # start with no dirty pages of an earlier run to write back
    t0 = time.perf_counter()
    with np.load(src) as z:
        p, n, w, t = z["points"], z["normals"], z["wrist"], z["twist"]
    off = gt.decompose_off_tangent(p, w, t)
    tan = gt.decompose_tangent(p, n, t)
    v = gt.contact_velocities(p, t)
    np.savez(
        dst,
        twist=t,
        contact_velocity=v,
        x=off.x,
        y=off.y,
        off_tangent_status=off.status,
        off_tangent_conditioning=off.conditioning,
        alpha=tan.alpha,
        beta=tan.beta,
        normal_velocity=tan.normal_velocity,
        in_tangent_planes=tan.in_tangent_planes,
        tangent_status=tan.status,
        tangent_conditioning=tan.conditioning,
    )
    return time.perf_counter() - t0


def _synced_cli(src, dst):
    os.sync()
    return timed(grasptwist_command() + ["resolve", src, "-f", "npz", "-o", dst, "-q"])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=1_000_000)
    ap.add_argument("--repeats", type=int, default=2)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        src, dst = os.path.join(tmp, "in.npz"), os.path.join(tmp, "out.npz")
        save_npz(src, args.n)
        t_base = min(baseline(src, os.path.join(tmp, "base.npz")) for _ in range(args.repeats))
        t_cli = min(_synced_cli(src, dst) for _ in range(args.repeats))
        with np.load(dst) as z:
            rows = len(z["x"])
    print(f"grasps: {args.n:,} -> {rows:,} result rows")
    print(f"{'numpy.load + engine + numpy.savez':36s} {t_base:7.2f} s")
    print(f"{'grasptwist resolve -f npz (end to end)':36s} {t_cli:7.2f} s   ratio {t_cli / t_base:4.2f} (target <= 2)")


if __name__ == "__main__":
    main()
