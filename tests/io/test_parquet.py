"""Parquet in and out: the data-set columns read, the CSV's columns written typed, bad files one record each."""

import csv
import io
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import grasptwist as gt
from grasp_gen import grasps
from grasptwist.cli import app
from grasptwist.io import parquet
from grasptwist.model import InputError
from grasptwist.output.columns import CSV_COLUMNS, TYPED_COLUMNS
from grasptwist.output.parquet_writer import ParquetWriter, table
from grasptwist.run.batch import resolve_arrays
from places import GRASPS

pa = pytest.importorskip("pyarrow")
pq = pytest.importorskip("pyarrow.parquet")

N = 300


def run(*args):
    return CliRunner().invoke(app, [str(a) for a in args])


@pytest.fixture(scope="module")
def data():
    """Random grasps, a few degenerate, a few without a wrist (null), one with a null twist value."""
    rng = np.random.default_rng(7)
    points, normals, wrist, twist = grasps(rng, N)
    points[7, 2] = points[7, 0] + 2 * (points[7, 1] - points[7, 0])  # collinear contacts
    normals[19, 2] = 0  # zero normal
    return points, normals, wrist, twist


def data_table(points, normals, wrist, twist, names=None, no_wrist=(), no_twist=()):
    """The grasps as a Parquet data set's columns (nulls where a row's wrist or twist value is missing)."""
    n = len(points)
    cols = {}
    for names_, values in (
        (parquet.POINT_COLUMNS, points.reshape(n, 9)),
        (parquet.NORMAL_COLUMNS, normals.reshape(n, 9)),
        (parquet.WRIST_COLUMNS, wrist),
        (parquet.TWIST_COLUMNS, twist),
    ):
        for j, name in enumerate(names_):
            nulls = np.zeros(n, bool)
            nulls[list(no_wrist if names_ is parquet.WRIST_COLUMNS else no_twist if j == 0 else [])] = True
            cols[name] = pa.array(values[:, j], mask=nulls)
    if names is not None:
        cols["name"] = pa.array(names)
    return pa.table(cols)


@pytest.fixture(scope="module")
def files(tmp_path_factory, data):
    """The same grasps as a Parquet data set (small row groups) and as an npz (NaN where Parquet has nulls)."""
    folder = tmp_path_factory.mktemp("parquet")
    points, normals, wrist, twist = (a.copy() for a in data)
    names = [f"g{i}" for i in range(N)]
    pq.write_table(
        data_table(points, normals, wrist, twist, names, no_wrist=[4, 5], no_twist=[9]),
        folder / "set.parquet",
        row_group_size=70,
    )
    wrist[[4, 5]] = np.nan
    twist[9, 0] = np.nan
    np.savez(folder / "set.npz", points=points, normals=normals, wrist=wrist, twist=twist, names=np.array(names))
    return folder


def csv_rows(text):
    return list(csv.DictReader(io.StringIO(text)))


def test_a_parquet_data_set_gives_the_records_of_the_same_npz(files):
    from_parquet, from_npz = (
        run("resolve", files / "set.parquet", "-f", "csv"),
        run("resolve", files / "set.npz", "-f", "csv"),
    )
    assert from_parquet.exit_code == from_npz.exit_code == 1  # the degenerate rows fail
    a, b = csv_rows(from_parquet.stdout), csv_rows(from_npz.stdout)
    assert len(a) == N and [r["grasp"] for r in a] == [f"g{i}" for i in range(N)]
    assert [{**r, "file": ""} for r in a] == [{**r, "file": ""} for r in b]
    assert a[4]["x1"] == "" and a[4]["alpha1"] != ""  # a null wrist: off-tangent fails, tangent resolved
    assert a[4]["off_tangent_error"].startswith("nonfinite-input")
    assert a[9]["ok"] == "false" and a[9]["twist1"] == "nan"  # a null twist value reads as NaN


def test_parquet_out_has_the_csv_values_and_typed_columns(files, tmp_path):
    out = tmp_path / "out.parquet"
    assert run("resolve", files / "set.parquet", "-f", "parquet", "-o", out).exit_code == 1
    table = pq.read_table(out)
    assert table.column_names == list(TYPED_COLUMNS)
    assert [c for c in table.column_names if c in CSV_COLUMNS] == CSV_COLUMNS
    types = {f.name: str(f.type) for f in table.schema}
    assert types["ok"] == types["in_tangent_planes"] == "bool"
    assert types["off_tangent_status"] == types["tangent_status"] == "int8"
    assert types["x1"] == types["twist6"] == "double"
    assert types["file"] == types["tangent_error"] == "dictionary<values=string, indices=int32, ordered=0>"
    meta = pq.ParquetFile(out).metadata
    assert "RLE_DICTIONARY" in meta.row_group(0).column(table.column_names.index("file")).encodings

    rows = csv_rows(run("resolve", files / "set.parquet", "-f", "csv").stdout)
    for name in CSV_COLUMNS:
        values = table.column(name).to_pylist()
        cells = [r[name] for r in rows]
        if TYPED_COLUMNS[name] == "f8":
            expected = [None if c == "" else float(c) for c in cells]
            assert [None if v is None else repr(v + 0.0) for v in values] == [
                None if e is None else repr(e) for e in expected
            ], name
        elif TYPED_COLUMNS[name] == "?":
            assert values == [None if c == "" else c == "true" for c in cells], name
        else:
            assert values == cells, name

    npz = np.load(run_npz(files, tmp_path))
    assert table.column("tangent_status").to_pylist() == npz["tangent_status"].tolist()
    statuses = table.column("off_tangent_status").to_pylist()
    assert statuses == npz["off_tangent_status"].tolist() and statuses[4] == gt.Status.NONFINITE_INPUT  # null wrist
    assert set(statuses) == {0, gt.Status.NONFINITE_INPUT, gt.Status.COLLINEAR_CONTACTS}


def run_npz(files, tmp_path):
    out = tmp_path / "out.npz"
    assert run("resolve", files / "set.parquet", "-f", "npz", "-o", out).exit_code == 1
    return out


def test_a_parquet_file_is_written_in_row_groups_as_blocks_arrive(tmp_path, data):
    points, normals, wrist, twist = data
    with open(tmp_path / "out.parquet", "wb") as f:
        w = ParquetWriter(f, row_group_rows=100)
        for start in range(0, N, 60):
            w.write(resolve_arrays(*(a[start : start + 60] for a in (points, normals, wrist, twist))))
        w.close()
    meta = pq.ParquetFile(tmp_path / "out.parquet").metadata
    assert [meta.row_group(i).num_rows for i in range(meta.num_row_groups)] == [120, 120, 60]
    whole, at_once = pq.read_table(tmp_path / "out.parquet"), table(resolve_arrays(points, normals, wrist, twist))
    for name in ("x1", "alpha3", "tangent_status", "in_tangent_planes", "tangent_error"):
        assert whole.column(name).to_pylist() == at_once.column(name).to_pylist()


def test_the_twist_from_the_command_line_and_a_missing_name(tmp_path, data):
    points, normals, wrist, twist = (a[:5] for a in data)
    pq.write_table(data_table(points, normals, wrist, twist), tmp_path / "set.parquet")
    records = [
        json.loads(x)
        for x in run(
            "resolve", tmp_path / "set.parquet", "--twist", "0,0,1,0,0,0", "--twist", "1,0,0,0,0,0", "-f", "jsonl"
        ).stdout.splitlines()
    ]
    assert [(r["grasp"], r["twist"]["name"]) for r in records[:3]] == [
        ("0", "0,0,1,0,0,0"),
        ("0", "1,0,0,0,0,0"),
        ("1", "0,0,1,0,0,0"),
    ]
    assert len(records) == 10


@pytest.mark.parametrize(
    "change, fragment",
    [
        (lambda t: t.drop_columns(["p2_y"]), "missing column(s) p2_y (the points)"),
        (lambda t: t.drop_columns(["c_z"]), "missing column(s) c_z (the wrist)"),
        (lambda t: t.set_column(3, "p2_x", pa.array(["a"] * t.num_rows)), "column p2_x: expected numbers, got string"),
        (
            lambda t: t.append_column("name", pa.array([1.5] * t.num_rows)),
            "column name: expected text or integers, got double",
        ),
    ],
)
def test_missing_columns_and_wrong_types_are_bad_dataset_records(tmp_path, data, change, fragment):
    pq.write_table(change(data_table(*(a[:4] for a in data))), tmp_path / "bad.parquet")
    result = run("resolve", tmp_path / "bad.parquet", "-f", "jsonl")
    rec = json.loads(result.stdout)
    assert result.exit_code == 1 and rec["error"]["code"] == "bad-dataset"
    assert fragment in rec["error"]["message"]


def test_a_corrupt_parquet_file_is_one_bad_dataset_record_and_the_others_keep_theirs(tmp_path, files):
    whole = (files / "set.parquet").read_bytes()
    (tmp_path / "truncated.parquet").write_bytes(whole[: len(whole) // 2])
    (tmp_path / "text.parquet").write_text("name,p1_x\n")
    middle = bytearray(whole)
    middle[len(whole) // 3 : len(whole) // 3 + 4000] = b"\x55" * 4000  # pages of a row group overwritten
    (tmp_path / "pages.parquet").write_bytes(bytes(middle))
    for fmt in ("jsonl", "parquet"):
        out = tmp_path / f"out.{fmt}"
        result = run(
            "resolve",
            tmp_path / "truncated.parquet",
            tmp_path / "text.parquet",
            tmp_path / "pages.parquet",
            files / "set.parquet",
            "-f",
            fmt,
            "-o",
            out,
        )
        assert result.exit_code == 1
        errors = [line for line in result.stderr.splitlines() if "bad-dataset" in line]
        assert [e.split(":")[0] for e in errors] == [
            str(tmp_path / n) for n in ("truncated.parquet", "text.parquet", "pages.parquet")
        ]
        assert "cannot read as Parquet" in errors[0] and "row group" in errors[2] and "Traceback" not in result.stderr
        if fmt == "parquet":
            files_out = pq.read_table(out).column("file").to_pylist()
        else:
            files_out = [json.loads(x)["file"] for x in out.read_text().splitlines()]
        assert files_out.count(str(files / "set.parquet")) == N  # every record of the good file


def test_a_parquet_data_set_over_two_workers_gives_the_same_output(files):

    from grasptwist.run.pipeline import Job, Tuning, record_outputs

    def written(workers):
        text = b""
        for out in record_outputs(Job(fmt="jsonl"), [str(files / "set.parquet")], workers, tuning):
            text += b"".join(x + b"\n" for x in out.encoded) + (
                Path(out.spool).read_bytes() + b"\n" if out.spool else b""
            )
        return text

    tuning = Tuning(grasps_per_task=50, records_at_once=17)  # tasks across row groups of 70, read by forked workers
    one, two = written(1), written(2)
    assert two == one and len(one.splitlines()) == N


def without(*modules):
    return "import sys\n" + "".join(f"sys.modules[{m!r}] = None\n" for m in modules)


def test_without_pyarrow_parquet_says_how_to_install_it(tmp_path, files):
    hint = "pip install pyarrow (from a clone of grasptwist: pip install -e '.[parquet]')"
    code = without("pyarrow") + (
        "from typer.testing import CliRunner; from grasptwist.cli import app\n"
        f"r = CliRunner().invoke(app, ['resolve', {str(files / 'set.npz')!r}, '-f', 'parquet', '-o', {str(tmp_path / 'o.parquet')!r}])\n"
        "print(r.exit_code); print(r.stderr, end='')\n"
        f"r = CliRunner().invoke(app, ['resolve', {str(files / 'set.parquet')!r}, '-f', 'jsonl'])\n"
        "print(r.exit_code); print(r.stdout, end='')\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert done.stderr == ""  # nothing more, not even "Exception ignored in ... __del__" at exit
    out = done.stdout.splitlines()
    assert out[:2] == ["2", f"grasptwist: error: -f parquet needs pyarrow: {hint}"]
    assert out[2] == "1" and json.loads(out[3])["error"] == {
        "code": "read-error",
        "message": f"reading Parquet needs pyarrow: {hint}",
        "line": None,
        "column": None,
    }
    assert not (tmp_path / "o.parquet").exists()


def test_resolving_grasp_files_never_imports_pyarrow_dask_or_pandas():

    grasp = GRASPS / "polyhedron.yaml"
    code = (
        "import sys; from typer.testing import CliRunner; from grasptwist.cli import app; "
        f"r = CliRunner().invoke(app, ['resolve', {str(grasp)!r}, '-f', 'csv']); "
        "print(r.exit_code, *(m in sys.modules for m in ('pyarrow', 'dask', 'pandas', 'distributed')))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert out.stdout.split() == ["0", "False", "False", "False", "False"]


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_a_stop_signal_leaves_no_parquet_file_and_no_debris(tmp_path):
    import os
    import signal

    from test_faults import Run, assert_no_debris

    rng = np.random.default_rng(11)
    names = (*parquet.POINT_COLUMNS, *parquet.NORMAL_COLUMNS, *parquet.WRIST_COLUMNS)
    pq.write_table(pa.table({n: rng.normal(size=200_000) for n in names}), tmp_path / "rows.parquet")
    (tmp_path / "out.parquet").write_text("old\n")
    run = Run(
        tmp_path,
        "resolve",
        tmp_path / "rows.parquet",
        "--twist",
        "0,0,1,0,0,0",
        "-f",
        "parquet",
        "-o",
        tmp_path / "out.parquet",
    )
    run.wait_started()  # the first block's warnings: the writer is open
    os.kill(run.p.pid, signal.SIGTERM)
    code, _ = run.finish()
    assert code == 128 + signal.SIGTERM
    assert run.said() == ["grasptwist: stopped by SIGTERM"]  # nothing from pyarrow's writer either
    assert (tmp_path / "out.parquet").read_text() == "old\n"
    assert_no_debris(run, tmp_path)


def test_without_dask_grasptwist_dask_says_how_to_install_it():
    code = without("dask", "dask.array") + (
        "import numpy as np; from grasptwist.dask import resolve_array; from grasptwist.extras import MissingExtra\n"
        "try:\n    resolve_array(np.zeros((1, 3, 3)), np.ones((1, 3, 3)), None, np.zeros((1, 6)))\n"
        "except MissingExtra as exc:\n    print(exc)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert out.stdout == (
        "grasptwist.dask needs dask: pip install 'dask[dataframe]' distributed "
        "(from a clone of grasptwist: pip install -e '.[dask]')\n"
    )


def test_a_hands_joint_columns_flow_to_parquet(tmp_path):

    grasp = GRASPS / "three-finger-hand.yaml"
    assert run("resolve", grasp, "-f", "parquet", "-o", tmp_path / "hand.parquet").exit_code == 0
    table, rows = pq.read_table(tmp_path / "hand.parquet"), csv_rows(run("resolve", grasp, "-f", "csv").stdout)
    statuses = ["off_tangent_status", "tangent_status", "hand_status"]
    assert [c for c in table.column_names if c not in statuses] == list(rows[0])
    assert str(table.schema.field("hand_status").type) == "int8" and table.column("hand_status").to_pylist() == [
        0
    ] * len(rows)
    joints = [c for c in rows[0] if c.startswith("qdot_")]
    assert len(joints) == 9 and all(table.column(c).to_pylist() == [float(r[c]) for r in rows] for c in joints)


# --------------------------------------------------------------------------
# Hostile Parquet: footers that lie, bombs, failed checksums, values a float cannot hold


def zigzag_varint(n: int) -> bytes:
    """``n`` as Thrift's compact protocol writes an i64: zigzag (-1 is 1, 1 is 2), then 7 bits a byte."""
    n, out = 2 * n if n >= 0 else -2 * n - 1, bytearray()
    while True:
        out.append(n & 0x7F | (0x80 if n >> 7 else 0))
        n >>= 7
        if not n:
            return bytes(out)


def declaring(data: bytes, rows: int, new: int, which=None) -> bytes:
    """A Parquet file's bytes whose footer says ``new`` where it said ``rows`` (the file's row
    count, then each column chunk's value count, then the row group's), at the places ``which``
    (their order; None: all).  Each is field 3 or 5 after field 2 or 4: header byte 0x16."""
    import struct

    (length,) = struct.unpack("<i", data[-8:-4])
    old = b"\x16" + zigzag_varint(rows)
    parts = data[-8 - length : -8].split(old)
    said = [b"\x16" + zigzag_varint(new) if which is None or k in which else old for k in range(len(parts) - 1)]
    footer = b"".join(p + s for p, s in zip(parts, [*said, b""]))
    return data[: -8 - length] + footer + struct.pack("<i", len(footer)) + b"PAR1"


def small_table(rows=50, seed=3, **columns):
    rng = np.random.default_rng(seed)
    cols = {n: rng.normal(size=rows) for n in (*parquet.POINT_COLUMNS, *parquet.NORMAL_COLUMNS)}
    return pa.table({**cols, **columns})


def footer_lies(tmp_path, new, which):
    buf = io.BytesIO()
    pq.write_table(small_table(), buf, write_statistics=False)
    data = buf.getvalue()
    assert data.count(b"\x16" + zigzag_varint(50)) == 2 + 18  # the file's and the row group's, each column's
    (tmp_path / "lies.parquet").write_bytes(declaring(data, 50, new, which))
    return tmp_path / "lies.parquet"


#: The good file beside each hostile one: the data set's first rows (two degenerate, two without a wrist
#: and a null twist value among them), in three row groups; all 300 rows cost each of its 15 tests 0.05 s
#: of CPU more.
GOOD_ROWS = 20


@pytest.fixture(scope="module")
def good(tmp_path_factory, data):
    """The first ``GOOD_ROWS`` grasps of ``files``' data set, as a Parquet file of three row groups."""
    path = tmp_path_factory.mktemp("good") / "good.parquet"
    points, normals, wrist, twist = (a[:GOOD_ROWS].copy() for a in data)
    table = data_table(points, normals, wrist, twist, [f"g{i}" for i in range(GOOD_ROWS)], [4, 5], [9])
    pq.write_table(table, path, row_group_size=7)
    return path


def resolved_beside_a_good_file(bad, good):
    """``resolve BAD GOOD``: exit 1, the one error line of BAD, and the good file's records all there."""
    r = run("resolve", bad, good, "--twist", "0,0,1,0,0,0", "-f", "jsonl")
    records = [json.loads(x) for x in r.stdout.splitlines()]
    assert r.exit_code == 1 and "Traceback" not in r.output and "internal error" not in r.output
    [line] = [x for x in r.stderr.splitlines() if x.startswith(f"{bad}: ")]
    assert [rec["file"] for rec in records] == [str(bad)] + [str(good)] * GOOD_ROWS
    assert records[0]["error"]["code"] == "bad-dataset"
    return line.removeprefix(f"{bad}: error: bad-dataset: ")


@pytest.mark.parametrize(
    ("new", "which", "said"),
    [
        (60, {0}, "the footer declares 60 rows, its row groups 50"),
        (60, {19}, "the footer declares 50 rows, its row groups 60"),
        (60, {0, 19}, "row group 0: declares 60 rows, its column p1_x 50"),
        (40, {0, 19}, "row group 0: declares 40 rows, its column p1_x 50"),
        (60, {1}, "row group 0: declares 50 rows, its column p1_x 60"),
        (60, None, "row group 0: declares 60 rows, holds 50"),  # every count agrees: found as it is read
        # negative counts (issue 36: an internal error, every record of the run lost)
        (-50, {0}, "the footer declares -50 rows, its row groups 50"),
        (-50, {19}, "row group 0: declares -50 rows, fewer than none"),
        (-50, {1}, "row group 0: declares 50 rows, its column p1_x -50"),
        (-50, None, "row group 0: declares -50 rows, fewer than none"),
    ],
    ids=["file", "row-group", "both", "both-fewer", "column", "all", "-file", "-row-group", "-column", "-all"],
)
def test_a_footer_whose_row_counts_lie_is_one_error_record(tmp_path, good, new, which, said):
    # 0.3: 50 records, or an internal error that lost every record of the run
    assert resolved_beside_a_good_file(footer_lies(tmp_path, new, which), good) == said


def test_a_footer_declaring_10_to_the_15_rows_is_refused_unread(tmp_path):
    # 0.3: past 500 MB within 2 s (a task list for 10^15 rows)
    path = footer_lies(tmp_path, 10**15, None)
    with pytest.raises(InputError, match=f"its 18 columns read declares {10**15 * 18 * 8:,} bytes decoded from"):
        parquet.open_parquet(str(path))


def zeros_bomb(tmp_path, rows=4_000_000):
    """The issue's decompression bomb: one row group of ``rows`` rows of zeros in a few hundred kB
    (one zero-filled buffer, never written to, shared by the columns: nearly no memory here)."""
    zeros = pa.array(np.zeros(rows))
    names = (*parquet.POINT_COLUMNS, *parquet.NORMAL_COLUMNS)
    path = tmp_path / "zeros.parquet"
    pq.write_table(pa.table(dict.fromkeys(names, zeros)), path, row_group_size=rows, compression="zstd")
    return path


def test_a_decompression_bomb_is_refused_from_its_footer(tmp_path):
    path = zeros_bomb(tmp_path, rows=1_000_000)  # 144 MB: over the 64 MiB any file may decode to
    size = path.stat().st_size
    assert size < 1_000_000
    with pytest.raises(InputError, match="refused unread, as a likely decompression bomb") as err:
        parquet.open_parquet(str(path))
    assert str(err.value).endswith(
        f"its 18 columns read declares {1_000_000 * 18 * 8:,} bytes decoded from {size:,} (over 100 times): "
        "refused unread, as a likely decompression bomb"
    )


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
@pytest.mark.parametrize("bomb", ["zeros", "rows"])
def test_parquet_bombs_cost_little_memory_and_no_other_record(tmp_path, bomb):
    from hostile import jsonl, run_measured

    path = zeros_bomb(tmp_path) if bomb == "zeros" else footer_lies(tmp_path, 10**15, None)
    grasp = GRASPS / "polyhedron.yaml"
    code, stderr, peak = run_measured("resolve", path, grasp, "-f", "jsonl", "-o", "out.jsonl", cwd=tmp_path)
    print(f"parquet {bomb} bomb: peak {peak:.0f} MB")
    assert code == 1 and peak < 200  # 0.3: past 500 MB within 2 s
    assert stderr.splitlines()[0].startswith(f"{path}: error: bad-dataset: its 18 columns read declares ")
    records = jsonl((tmp_path / "out.jsonl").read_text())
    assert [r["file"] for r in records] == [str(path), str(grasp)] and records[1]["ok"]
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([path.name, "out.jsonl"])


def test_a_page_whose_checksum_fails_is_one_error_record(tmp_path, good):
    # 0.3 did not look at checksums: 50 ok records, one of them with a changed number
    path = tmp_path / "damaged.parquet"
    pq.write_table(small_table(), path, write_page_checksum=True, use_dictionary=False, compression="none")
    chunk = pq.ParquetFile(path).metadata.row_group(0).column(0)
    data = bytearray(path.read_bytes())
    data[chunk.data_page_offset + chunk.total_compressed_size - 4] ^= 0x10  # in p1_x's last value
    path.write_bytes(bytes(data))
    assert resolved_beside_a_good_file(path, good).startswith("row group 0: cannot read: ")


@pytest.mark.parametrize(
    ("columns", "said"),
    # made in the test: an Arrow array loads pandas (0.4 s), which collecting the tests need not
    [
        (
            lambda: {"p1_x": pa.array(2**53 + np.arange(50, dtype=np.int64))},
            "column p1_x: an integer beyond 2^53 in rows 0-49",
        ),
        (lambda: {"c_z": pa.array(np.ones(50))}, None),  # the wrist's other columns missing: a known error
    ],
    ids=["beyond-2^53", "missing"],
)
def test_values_a_float_cannot_hold_are_one_error_record(tmp_path, good, columns, said):
    pq.write_table(small_table(**columns()), tmp_path / "odd.parquet")
    line = resolved_beside_a_good_file(tmp_path / "odd.parquet", good)
    assert line.startswith(said or "missing column(s) c_x, c_y (the wrist)")


def test_a_column_given_twice_is_one_error_record(tmp_path, good):
    # 0.3: internal error: KeyError, and every record of the run lost
    table = small_table().append_column("p2_y", pa.array(np.zeros(50)))
    pq.write_table(table, tmp_path / "twice.parquet")
    line = resolved_beside_a_good_file(tmp_path / "twice.parquet", good)
    assert line == "column(s) p2_y given more than once"


def test_rows_are_read_in_bounded_batches_forward_and_back(tmp_path, monkeypatch):
    monkeypatch.setattr(parquet, "BATCH_ROWS", 16)
    table = small_table(rows=300)
    pq.write_table(table, tmp_path / "set.parquet", row_group_size=70)
    ds = parquet.open_parquet(str(tmp_path / "set.parquet"))
    want = np.stack([table.column(n).to_numpy() for n in parquet.POINT_COLUMNS], axis=-1).reshape(300, 3, 3)
    for start, stop in [(0, 5), (3, 90), (90, 91), (60, 300), (10, 20), (295, 400), (0, 300)]:
        np.testing.assert_array_equal(ds.points[start:stop], want[start:stop])
        assert ds.points.reader.cursor.batch.num_rows <= 16
