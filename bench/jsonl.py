"""Records as JSON lines: ``grasptwist resolve in.npz -f jsonl`` on 10^6 grasps, and json vs orjson.

Run: ``python bench/jsonl.py [--n 1000000]``.  Prints the command's records
per second, start-up included (target >= 100,000), and, on a sample of the
same records in this process, the encoding rate of the standard library's
``json`` against ``orjson`` (the encoder grasptwist uses).
"""

import argparse
import json
import os
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
        t_cli = timed(grasptwist_command() + ["resolve", src, "-f", "jsonl", "-o", dst, "-q"])
        with open(dst, "rb") as f:
            lines = f.readlines()
    records = [json.loads(line) for line in lines[: args.sample]]
    rates = {}
    for name, dumps in (("json", lambda r: json.dumps(r).encode()), ("orjson", orjson.dumps)):
        t0 = time.perf_counter()
        for r in records:
            dumps(r)
        rates[name] = len(records) / (time.perf_counter() - t0)
    print(f"records: {len(lines):,} ({sum(map(len, lines)) / len(lines):.0f} bytes each)")
    print(f"grasptwist resolve -f jsonl      {t_cli:7.2f} s   {len(lines) / t_cli:10,.0f} records/s (target >= 100,000)")
    print(f"encoding alone, json             {rates['json']:10,.0f} records/s")
    print(f"encoding alone, orjson           {rates['orjson']:10,.0f} records/s   ({rates['orjson'] / rates['json']:.1f}x json)")


if __name__ == "__main__":
    main()
