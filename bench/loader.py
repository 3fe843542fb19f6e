"""The grasp loader's fast path against its general path, in process, on the files users have.

Run: ``python bench/loader.py [--files 10000]``.  For each bundled grasp file,
and for a folder of generated grasp files (bench/folder.py's, with and without
the bundled files' ``paths:``), reads every file with ``read_grasps`` through
the default reading (fast path first) and with ``Reading(fast=False)`` (every
document through the general composer).  CPU time of this process
(``time.process_time``), best of the repeats, the two paths interleaved so that
a loaded machine slows both alike.  The fast path pays where ratio > 1.
First, the seconds three hostile inputs take (the loader must refuse them at once).
"""

import argparse
import glob
import os
import tempfile
import time

from folder import HERE, make_folder
from grasptwist.io.grasp import READING, Reading, read_grasps

GENERAL = Reading(fast=False)


def best_of(repeats, **jobs):
    """Best CPU seconds of each job, the jobs run in turn ``repeats`` times."""
    best = dict.fromkeys(jobs, float("inf"))
    for _ in range(repeats):
        for name, job in jobs.items():
            t0 = time.process_time()
            job()
            best[name] = min(best[name], time.process_time() - t0)
    return best


def compare(label, contents, repeats, per_file):
    def run(reading):
        return lambda: [read_grasps(data, file=name, reading=reading) for name, data in contents]

    t = best_of(repeats, fast=run(READING), general=run(GENERAL))
    unit, scale = ("us/file", 1e6 / len(contents)) if per_file else ("s", 1.0)
    print(
        f"{label:34s} fast {t['fast'] * scale:9.1f} {unit}  general {t['general'] * scale:9.1f} {unit}"
        f"  general/fast {t['general'] / t['fast']:.2f}",
        flush=True,
    )


# Hostile files the loader must refuse at once (tests/io/test_grasp_file.py checks what it says).
HOSTILE = {
    "billion laughs": 'a: &a ["lol","lol","lol","lol","lol","lol","lol","lol","lol"]\n'
    + "".join(f"{b}: &{b} [*{a},*{a},*{a},*{a},*{a},*{a},*{a},*{a},*{a}]\n" for a, b in zip("abcdefgh", "bcdefghi")),
    "1 MiB of '---'": "---\n" * (1 << 18),
    "100,000 '[' after a bad tag": "bad: !!python/none 1\nx: " + "[" * 100_000 + "\n",
}


def hostile(repeats):
    """Seconds each hostile input takes (target: well under one)."""
    for label, text in HOSTILE.items():
        t = best_of(repeats, read=lambda text=text: read_grasps(text, file="h.yaml"))["read"]
        print(f"{label:34s} {t:9.3f} s", flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--files", type=int, default=10_000)
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args()
    hostile(args.repeats)
    for path in sorted(glob.glob(os.path.join(HERE, "..", "grasps", "*.yaml"))):
        with open(path, "rb") as f:
            data = f.read()
        copies = max(1, 20_000 // len(data))  # about 20 kB of each
        compare(os.path.basename(path), [(path, data)] * copies, args.repeats, per_file=True)
    with tempfile.TemporaryDirectory() as tmp:
        for with_paths in (False, True):
            files = make_folder(os.path.join(tmp, f"paths{with_paths}"), args.files, with_paths=with_paths)
            contents = []
            for name in files:
                with open(name, "rb") as f:
                    contents.append((name, f.read()))
            label = f"{args.files} files" + (" with paths" if with_paths else " (bench/folder.py)")
            compare(label, contents, max(2, args.repeats // 2), per_file=False)


if __name__ == "__main__":
    main()
