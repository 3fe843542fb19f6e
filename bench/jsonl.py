"""Records as JSON lines: ``grasptwist resolve in.npz -f jsonl`` on 10^6 grasps, and json vs orjson.

Run: ``python bench/jsonl.py [--n 1000000]``.  Prints the command's records
per second, start-up included (target >= 100,000), written to a pipe
(``| cat > /dev/null``) and to a file (-o); for the file, the time this
machine's disk takes to write the same bytes from memory, which bounds it;
and, on a sample of the same records in this process, the encoding rate of
the standard library's ``json`` against ``orjson`` (the encoder grasptwist
uses).
"""

import argparse
import json
import os
import shlex
import tempfile
import time

import orjson

from _data import grasptwist_command, save_npz, timed


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=1_000_000)
    ap.add_argument("--sample", type=int, default=20_000)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        src, dst = os.path.join(tmp, "in.npz"), os.path.join(tmp, "out.jsonl")
        save_npz(src, args.n)
        command = " ".join(shlex.quote(a) for a in grasptwist_command() + ["resolve", src, "-f", "jsonl", "-q"])
        t_pipe = timed(["sh", "-c", f"{command} | cat > /dev/null"])
        t_file = timed(grasptwist_command() + ["resolve", src, "-f", "jsonl", "-o", dst, "-q"])
        with open(dst, "rb") as f:
            data = f.read()
        lines = data.splitlines()[: args.sample]
        copy = os.path.join(tmp, "copy.jsonl")
        t0 = time.perf_counter()
        with open(copy, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        t_disk = time.perf_counter() - t0
        count, size = data.count(b"\n"), len(data)
        del data
    records = [json.loads(line) for line in lines]
    rates = {}
    for name, dumps in (("json", lambda r: json.dumps(r).encode()), ("orjson", orjson.dumps)):
        t0 = time.perf_counter()
        for r in records:
            dumps(r)
        rates[name] = len(records) / (time.perf_counter() - t0)
    print(f"records: {count:,} ({size / count:.0f} bytes each, {size / 1e9:.2f} GB)")
    print(
        f"grasptwist resolve -f jsonl | cat    {t_pipe:7.2f} s   {count / t_pipe:10,.0f} records/s (target >= 100,000)"
    )
    print(f"grasptwist resolve -f jsonl -o file  {t_file:7.2f} s   {count / t_file:10,.0f} records/s")
    print(
        f"the same bytes from memory to disk   {t_disk:7.2f} s   {count / t_disk:10,.0f} records/s (the disk's ceiling)"
    )
    print(f"encoding alone, json             {rates['json']:10,.0f} records/s")
    print(
        f"encoding alone, orjson           {rates['orjson']:10,.0f} records/s   ({rates['orjson'] / rates['json']:.1f}x json)"
    )


if __name__ == "__main__":
    main()
