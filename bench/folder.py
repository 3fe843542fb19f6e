"""A folder of 10,000 grasp files to JSONL, against yaml.load(CSafeLoader) alone on one core.

Run: ``python bench/folder.py [--files 10000]``.  The folder holds copies of
the bundled grasps with their numbers perturbed.  The baseline parses every
file with ``yaml.load_all(f, Loader=yaml.CSafeLoader)`` in this process (one
core, nothing else; ``load_all`` since one bundled file holds two grasps); the command reads, validates and resolves them and
writes JSONL, start-up included, with its default workers (both cores).
Target: files per second at least the baseline's.
"""

import argparse
import glob
import os
import random
import tempfile
import time
from pathlib import Path

import yaml

from _data import grasptwist_command, timed

HERE = os.path.dirname(os.path.abspath(__file__))


def make_folder(root, count, seed=0, with_paths=False):
    rng = random.Random(seed)
    sources = sorted(glob.glob(os.path.join(HERE, "..", "grasps", "*.yaml")))
    # the grasp files of 0.1: without the files with a hand (URDF and kinematics: bench/hand.py) and
    # with their paths (last in the file) cut off, which only `follow` reads and which send a file
    # to the loader's general path (--with-paths keeps them)
    texts = [t for t in (Path(s).read_text() for s in sources) if "\nhand:" not in t]
    if not with_paths:
        texts = [t.split("\npaths:")[0] + "\n" for t in texts]
    for i in range(count):
        sub = os.path.join(root, f"set{i // 1000:02d}")
        os.makedirs(sub, exist_ok=True)
        text = texts[i % len(texts)].replace("0.5", f"{0.5 + rng.random() * 1e-3:.6f}")
        with open(os.path.join(sub, f"grasp{i:05d}.yaml"), "w") as f:
            f.write(text)
    return sorted(glob.glob(os.path.join(root, "*", "*.yaml")))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--files", type=int, default=10_000)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--with-paths", action="store_true", help="keep the bundled files' paths: sections")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        files = make_folder(os.path.join(tmp, "grasps"), args.files, with_paths=args.with_paths)
        t_yaml = float("inf")
        for _ in range(args.repeats):
            t0 = time.perf_counter()
            for name in files:
                with open(name, "rb") as f:
                    list(yaml.load_all(f, Loader=yaml.CSafeLoader))  # some files hold two grasps
            t_yaml = min(t_yaml, time.perf_counter() - t0)
        out = os.path.join(tmp, "out.jsonl")
        t_cli = timed(
            grasptwist_command() + ["resolve", os.path.join(tmp, "grasps"), "-f", "jsonl", "-o", out, "-q"],
            args.repeats,
        )
        records = len(Path(out).read_bytes().splitlines())
    print(f"files: {len(files):,} -> {records:,} records; cores: {os.cpu_count()}")
    print(f"yaml.load(CSafeLoader) alone, one core   {t_yaml:6.2f} s   {len(files) / t_yaml:8,.0f} files/s")
    print(
        f"grasptwist resolve FOLDER -f jsonl       {t_cli:6.2f} s   {len(files) / t_cli:8,.0f} files/s   "
        f"ratio {t_yaml / t_cli:4.2f} (target >= 1)"
    )


if __name__ == "__main__":
    main()
