"""grasptwist.dask: the command line's results, bit for bit (on Dask's synchronous scheduler by
default, on a two-worker distributed LocalCluster with -m slow).

The checks are in dask_checks.py, each run in a fresh process (why: its docstring).
"""

import importlib.util
import subprocess
import sys

import pytest

from places import TESTS

pytestmark = pytest.mark.skipif(
    any(importlib.util.find_spec(m) is None for m in ("dask", "distributed", "pandas", "pyarrow")),
    reason="needs the extra grasptwist[dask]",
)


def check(name, *args) -> list[str]:
    """Run ``dask_checks.name(*args)`` in a new process; the lines it printed."""
    script = TESTS / "dask_checks.py"
    out = subprocess.run([sys.executable, script, name, *map(str, args)], capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr[-3000:]
    return out.stdout.splitlines()


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_sharded_parquet_named_twists_and_arrays_on_the_synchronous_scheduler(tmp_path):
    # resolve_dataframe over 3 Parquet shards equals `grasptwist resolve shards -f parquet` bit for bit
    assert check("the_default_run", tmp_path) == [
        "3000 rows equal, 31 with the tangent method failed",
        "200 rows, 2 twists, types kept",
        "5000 rows in 4 chunks equal the engine",
    ]


@pytest.mark.slow
def test_a_few_hundred_thousand_rows_of_sharded_parquet_on_a_two_worker_cluster(tmp_path):
    # LocalCluster(n_workers=2, processes=True), as the issue asks
    lines = check("on_a_cluster", tmp_path, 300_000)
    assert lines[0] == "2 workers" and lines[1].startswith("300000 rows equal")


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_synthesize_bag_gives_the_command_line_s_records_on_a_two_worker_cluster(tmp_path):
    lines = check("synthesis_on_a_cluster", tmp_path)
    assert lines[-1].endswith("objects without a grasp") and int(lines[-1].split()[0]) >= 3
