"""Sharded Parquet to sharded Parquet: grasptwist.dask on a 2-worker LocalCluster vs the command line.

Run: ``python bench/dask.py [--n 2000000]`` (needs the extra ``grasptwist[dask]``).
Both resolve the same ``n`` grasps, stored as 8 Parquet shards: Dask reads
the folder (Arrow types: no conversion to numpy and back), runs :func:`grasptwist.dask.resolve_dataframe` on a
``distributed.LocalCluster(n_workers=2, processes=True)`` and writes a folder
of Parquet shards; the command line runs ``grasptwist resolve shards... -f
parquet -o out.parquet`` (one process, start-up included).  The cluster's
start is timed apart: a real deployment keeps its cluster.
"""

import argparse
import glob
import os
import sys
import tempfile
import time

# This file is named dask.py: take its folder off the path while dask is imported.
HERE = os.path.dirname(os.path.abspath(__file__))
sys.path = [p for p in sys.path if os.path.abspath(p or ".") != HERE]
import dask.dataframe as dd  # noqa: E402
import pyarrow.parquet as pq  # noqa: E402
from distributed import Client, LocalCluster  # noqa: E402

from grasptwist.dask import resolve_dataframe, to_parquet  # noqa: E402

sys.path.insert(0, HERE)
from _data import grasptwist_command, save_parquet, timed  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=2_000_000, help="grasps (default 2 * 10^6)")
    ap.add_argument("--repeats", type=int, default=2)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        shards = save_parquet(os.path.join(tmp, "in"), args.n)
        t_cli = timed(grasptwist_command() + ["resolve", *shards, "-f", "parquet", "-o", f"{tmp}/cli.parquet", "-q"])
        t0 = time.perf_counter()
        with LocalCluster(n_workers=2, threads_per_worker=1, processes=True) as cluster, Client(cluster):
            t_start = time.perf_counter() - t0
            t_dask = float("inf")
            for i in range(args.repeats):
                t0 = time.perf_counter()
                results = resolve_dataframe(dd.read_parquet(os.path.join(tmp, "in"), dtype_backend="pyarrow"))
                to_parquet(results, f"{tmp}/dask{i}")
                t_dask = min(t_dask, time.perf_counter() - t0)
        rows = sum(pq.ParquetFile(p).metadata.num_rows for p in glob.glob(f"{tmp}/dask0/*.parquet"))
        assert rows == pq.ParquetFile(f"{tmp}/cli.parquet").metadata.num_rows == args.n
    print(f"grasps: {args.n:,} in {len(shards)} Parquet shards")
    print(f"{'grasptwist resolve -f parquet':36s} {t_cli:7.2f} s  {args.n / t_cli:10,.0f} rows/s (one process)")
    print(
        f"{'grasptwist.dask, 2-worker cluster':36s} {t_dask:7.2f} s  {args.n / t_dask:10,.0f} rows/s "
        f"(cluster start {t_start:.1f} s apart)"
    )
    print(f"ratio dask / command line: {t_cli / t_dask:.2f}x the rate")


if __name__ == "__main__":
    main()
