"""The checks of test_dask.py, each run in a process of its own: ``python tests/dask_checks.py CHECK FOLDER [ROWS]``.

Dask, pandas and a cluster's client take the test process past 150 MB, and
every process the tests start afterwards would inherit that peak (Linux
carries ``ru_maxrss`` across fork and exec; the fault tests measure it).
Each check asserts, then prints what it compared for the test to read.
"""

import sys
from pathlib import Path

import dask.array as da
import dask.dataframe as dd
import distributed
import numpy as np
import pandas as pd
import pyarrow.parquet as pq
from typer.testing import CliRunner

import dask
import grasptwist as gt
from grasp_gen import grasps
from grasptwist.cli import app
from grasptwist.dask import resolve_array, resolve_dataframe, result_dtype, to_parquet
from grasptwist.io import parquet


def grasp_arrays(n, seed=0):
    """Random grasps, every 97th with collinear contacts (both methods fail) and every 13th without a wrist."""
    points, normals, wrist, twist = grasps(np.random.default_rng(seed), n)
    points[::97, 2] = points[::97, 0] + 2 * (points[::97, 1] - points[::97, 0])
    wrist[::13] = np.nan
    return points, normals, wrist, twist


def save_parquet(folder, n, shards):
    """``n`` random grasps as ``shards`` Parquet files in ``folder`` (named rows, row groups of 10,000)."""
    table = parquet.grasp_table(*grasp_arrays(n), names=np.arange(n).astype(str))
    folder.mkdir()
    size = -(-n // shards)
    paths = [folder / f"part-{i:03d}.parquet" for i in range(shards)]
    for i, path in enumerate(paths):
        pq.write_table(table.slice(i * size, size), path, row_group_size=10_000)
    return paths


def cli_parquet(shards, out):
    assert CliRunner().invoke(app, ["resolve", *map(str, shards), "-f", "parquet", "-o", str(out), "-q"]).exit_code in (
        0,
        1,
    )
    return pq.read_table(out).to_pandas(types_mapper=pd.ArrowDtype)


def assert_dask_equals_the_command_line(tmp_path, n, shards):
    tmp_path.mkdir(exist_ok=True)
    paths = save_parquet(tmp_path / "in", n, shards=shards)
    to_parquet(resolve_dataframe(dd.read_parquet(tmp_path / "in")), str(tmp_path / "out"))
    ours = pq.read_table(tmp_path / "out").to_pandas(types_mapper=pd.ArrowDtype).drop(columns="file")
    theirs = cli_parquet(paths, tmp_path / "cli.parquet").drop(columns="file")
    failed = int((ours["tangent_status"] != 0).sum())
    assert len(ours) == n and failed  # a few degenerate rows are in there
    # every value, bit for bit (NaN and null in the same places)
    pd.testing.assert_frame_equal(ours, theirs, check_exact=True, check_dtype=False, check_categorical=False)
    for name in ours.columns:  # and the floats' bits (a NaN's sign and payload too)
        if str(ours[name].dtype) == "double[pyarrow]":
            bits = [f[name].to_numpy(dtype=float, na_value=np.nan).view(np.int64) for f in (ours, theirs)]
            assert (bits[0] == bits[1]).all(), name
    print(f"{n} rows equal, {failed} with the tangent method failed")


def on_a_cluster(tmp_path, n):
    """resolve_dataframe on two worker processes, against the command line."""
    tmp_path.mkdir(exist_ok=True)
    with (
        distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0") as cluster,
        distributed.Client(cluster) as client,
    ):
        assert len(client.scheduler_info()["workers"]) == 2
        print("2 workers")
        assert_dask_equals_the_command_line(tmp_path, n, shards=3 if n < 10_000 else 6)


def the_default_run(tmp_path):
    """Every check on Dask's synchronous scheduler in this process (Python, dask and pandas start
    once; a cluster's worker processes take seconds more, so the cluster runs with ``-m slow``)."""
    with dask.config.set(scheduler="synchronous"):
        assert_dask_equals_the_command_line(tmp_path / "sharded", 3000, shards=3)
        types_and_named_twists(tmp_path)
        array_equals_the_engine()


def types_and_named_twists(tmp_path):
    save_parquet(tmp_path / "in", 100, shards=2)
    spin = {"spin-z": [0, 0, 1, 0, 0, 0], "lift": [0, 0, 0, 0, 0, 1]}
    ddf = resolve_dataframe(dd.read_parquet(tmp_path / "in"), twists=spin, method="tangent", file="set")
    out = ddf.compute()
    assert str(ddf.dtypes["tangent_status"]) == str(out.dtypes["tangent_status"]) == "int8[pyarrow]"
    assert list(out["twist"][:3]) == ["spin-z", "lift", "spin-z"] and len(out) == 200
    assert out["x1"].isna().all() and not out["alpha1"].isna().all()  # off-tangent not asked for: null
    assert set(out["file"]) == {"set"}
    print(f"{len(out)} rows, {out['twist'].nunique()} twists, types kept")


def array_equals_the_engine():
    points, normals, wrist, twist = grasp_arrays(5000, seed=3)
    chunks = (1300,)
    r = resolve_array(
        da.from_array(points, chunks=chunks + (3, 3)),
        da.from_array(normals, chunks=chunks + (3, 3)),
        da.from_array(wrist, chunks=chunks + (3,)),
        da.from_array(twist, chunks=chunks + (6,)),
    )
    assert r.numblocks == (4,) and r.dtype == result_dtype()
    got = r.compute()
    off, tan = gt.decompose_off_tangent(points, wrist, twist), gt.decompose_tangent(points, normals, twist)
    for name, expected in (
        ("x", off.x),
        ("y", off.y),
        ("alpha", tan.alpha),
        ("normal_velocity", tan.normal_velocity),
        ("tangent_conditioning", tan.conditioning),
        ("contact_velocity", gt.contact_velocities(points, twist)),
    ):
        np.testing.assert_array_equal(got[name], expected, err_msg=name, strict=True)
    assert (got["off_tangent_status"][::13] == -1).all() and (
        got["off_tangent_status"][1::13] == off.status[1::13]
    ).all()
    assert (got["tangent_status"] == tan.status).all() and (tan.status[::97] != 0).all()
    print(f"{len(got)} rows in {r.numblocks[0]} chunks equal the engine")


def synthesis_on_a_cluster(tmp_path):
    """synthesize_bag over three objects on two worker processes, against the command line."""
    import json
    import shutil

    from grasptwist.dask import synthesize_bag
    from places import GRASPS

    tmp_path.mkdir(exist_ok=True)
    for name in ("sphere.yaml", "box-edge.yaml", "cylinder.yaml"):
        shutil.copy(GRASPS / name, tmp_path / name)
    paths = sorted(str(p) for p in tmp_path.glob("*.yaml"))
    options = {"count": 2, "candidates": 1500, "mass": 0.2, "friction": 0.3}
    cli = CliRunner().invoke(
        app,
        [
            "synthesize",
            *paths,
            "-n",
            "2",
            "--candidates",
            "1500",
            "--mass",
            "0.2",
            "--friction",
            "0.3",
            "-f",
            "jsonl",
            "-q",
        ],
    )
    theirs = [json.loads(line) for line in cli.stdout.splitlines()]
    with (
        distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0") as cluster,
        distributed.Client(cluster) as client,
    ):
        assert len(client.scheduler_info()["workers"]) == 2
        ours = synthesize_bag(paths, **options).compute()
    for rec in ours + theirs:
        rec["search"].pop("seconds")
    assert ours == theirs and len(ours) >= 3
    print(f"{len(ours)} records equal, {sum(not r['ok'] for r in ours)} objects without a grasp")


def readme_block(folder):
    """The docs' Dask example as printed (the python block marked ``runner=dask``), run in ``folder``
    on 3 shards of 3,000 grasps in ``shards/``."""
    import os

    from docs_blocks import all_blocks

    save_parquet(folder / "shards", 3000, shards=3)
    (block,) = [b for b in all_blocks() if b.lang == "python" and b.options.get("runner") == "dask"]
    os.chdir(folder)
    exec(compile(block.text, block.where, "exec"), {})
    print(f"{pq.read_table(folder / 'results').num_rows} rows in results/")


if __name__ == "__main__":
    check, folder, *rows = sys.argv[1:]
    globals()[check](Path(folder), *map(int, rows))
