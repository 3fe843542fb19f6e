"""grasptwist.dask on a distributed LocalCluster: the command line's results, bit for bit."""

import numpy as np
import pytest
from typer.testing import CliRunner

import grasptwist as gt
from grasptwist.cli import app

pytest.importorskip("dask.dataframe")
distributed = pytest.importorskip("distributed")
pq = pytest.importorskip("pyarrow.parquet")
pd = pytest.importorskip("pandas")

import dask.array as da  # noqa: E402
import dask.dataframe as dd  # noqa: E402

from grasp_gen import grasps  # noqa: E402
from grasptwist.dask import resolve_array, resolve_dataframe, result_dtype, to_parquet  # noqa: E402
from grasptwist.io import parquet  # noqa: E402


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


@pytest.fixture(scope="module")
def client():
    """Two worker processes: a real cluster, whose tasks are pickled and sent."""
    with (
        distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0") as cluster,
        distributed.Client(cluster) as c,
    ):
        yield c


@pytest.fixture
def synchronous():
    """Dask's scheduler in this process (the cluster's start is paid once, by the tests that need it)."""
    import dask

    with dask.config.set(scheduler="synchronous"):
        yield


def cli_parquet(shards, out):
    assert CliRunner().invoke(app, ["resolve", *map(str, shards), "-f", "parquet", "-o", str(out), "-q"]).exit_code in (
        0,
        1,
    )
    return pq.read_table(out).to_pandas(types_mapper=pd.ArrowDtype)


def assert_dask_equals_the_command_line(tmp_path, n, shards):
    paths = save_parquet(tmp_path / "in", n, shards=shards)
    to_parquet(resolve_dataframe(dd.read_parquet(tmp_path / "in")), str(tmp_path / "out"))
    ours = pq.read_table(tmp_path / "out").to_pandas(types_mapper=pd.ArrowDtype).drop(columns="file")
    theirs = cli_parquet(paths, tmp_path / "cli.parquet").drop(columns="file")
    assert len(ours) == n and (ours["tangent_status"] != 0).any()  # a few degenerate rows are in there
    # every value, bit for bit (NaN and null in the same places)
    pd.testing.assert_frame_equal(ours, theirs, check_exact=True, check_dtype=False, check_categorical=False)
    assert (
        ours["x1"].to_numpy(na_value=np.nan).view(np.int64) == theirs["x1"].to_numpy(na_value=np.nan).view(np.int64)
    ).all()


def test_resolve_dataframe_on_a_two_worker_cluster_equals_the_command_line(client, tmp_path):
    assert len(client.scheduler_info()["workers"]) == 2
    assert_dask_equals_the_command_line(tmp_path, 3000, shards=3)


@pytest.mark.slow
def test_a_few_hundred_thousand_rows_of_sharded_parquet(client, tmp_path):
    assert_dask_equals_the_command_line(tmp_path, 300_000, shards=6)


def test_resolve_dataframe_keeps_the_types_and_takes_named_twists(synchronous, tmp_path):
    save_parquet(tmp_path / "in", 100, shards=2)
    spin = {"spin-z": [0, 0, 1, 0, 0, 0], "lift": [0, 0, 0, 0, 0, 1]}
    ddf = resolve_dataframe(dd.read_parquet(tmp_path / "in"), twists=spin, method="tangent", file="set")
    out = ddf.compute()
    assert str(ddf.dtypes["tangent_status"]) == str(out.dtypes["tangent_status"]) == "int8[pyarrow]"
    assert list(out["twist"][:3]) == ["spin-z", "lift", "spin-z"] and len(out) == 200
    assert out["x1"].isna().all() and not out["alpha1"].isna().all()  # off-tangent not asked for: null
    assert set(out["file"]) == {"set"}


def test_resolve_array_equals_the_engine_bit_for_bit(synchronous):
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
