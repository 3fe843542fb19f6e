"""Tables of a data set: ``grasptwist resolve in.npz`` (the default table) against ``-f jsonl``.

Run: ``python bench/table.py [--n 20000]``.  Prints, for ``n`` records, a
tenth and five times as many, the records per second of the table and of JSONL in
the same run, start-up included, written to a pipe (``| cat > /dev/null``),
their ratio (target: the table at least 0.1 of JSONL's rate) and each
run's peak memory (the largest resident set of the process and its
workers).  Both grow with an ``.npz``'s size, whose arrays are read whole;
the table's own memory, its peak less JSONL's, must not grow with the
record count.
"""

import argparse
import os
import resource
import shlex
import subprocess
import sys
import tempfile

from _data import grasptwist_command, save_npz, timed

_PEAK = """
import resource, subprocess, sys
subprocess.run(sys.argv[1:], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)
"""


def peak_mb(command):
    """Largest resident set, in MB, of ``command`` and the processes it waited for."""
    done = subprocess.run([sys.executable, "-c", _PEAK, *command], capture_output=True, text=True, check=True)
    return int(done.stdout) * resource.getpagesize() / 4096 / 1024  # ru_maxrss is in KiB on Linux


def measure(src, fmt):
    """Seconds (through a pipe) and peak MB of ``grasptwist resolve src -f fmt``."""
    command = grasptwist_command() + ["resolve", src, "-f", fmt, "-q"]
    seconds = timed(["sh", "-c", " ".join(map(shlex.quote, command)) + " | cat > /dev/null"])
    return seconds, peak_mb(command)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=20_000)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        for n in (args.n // 10, args.n, args.n * 5):
            src = os.path.join(tmp, f"in{n}.npz")
            save_npz(src, n)
            t_table, mb_table = measure(src, "table")
            t_jsonl, mb_jsonl = measure(src, "jsonl")
            ratio = (n / t_table) / (n / t_jsonl)
            print(
                f"{n:>7,} records  table {n / t_table:9,.0f} records/s ({t_table:6.2f} s, peak {mb_table:4.0f} MB)"
                f"   jsonl {n / t_jsonl:9,.0f} records/s ({t_jsonl:5.2f} s, peak {mb_jsonl:4.0f} MB)"
                f"   table/jsonl {ratio:.2f} (target >= 0.1), table's own memory {mb_table - mb_jsonl:+.0f} MB"
            )


if __name__ == "__main__":
    main()
