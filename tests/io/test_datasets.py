"""Array data sets: .npz and .npy in, JSONL/CSV/npz out, equal to the per-file path."""

import json
from pathlib import Path

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

import grasptwist as gt
from grasp_gen import grasps
from grasptwist.cli import app
from grasptwist.io import datasets
from grasptwist.model import Twist
from grasptwist.output.npz import NpzWriter
from grasptwist.output.records import dumps, records
from grasptwist.run.batch import dataset_blocks
from places import GRASPS

N = 240


def run(*args):
    return CliRunner().invoke(app, [str(a) for a in args])


def jsonl(result):
    return [json.loads(line) for line in result.stdout.splitlines()]


@pytest.fixture(scope="module")
def data():
    """Random grasps with a few rows made degenerate in each way the engine names."""
    rng = np.random.default_rng(5)
    points, normals, wrist, twist = grasps(rng, N)
    wrist[3] = points[3].mean(0)  # wrist in the contacts' plane
    points[7, 2] = points[7, 0] + 2 * (points[7, 1] - points[7, 0])  # collinear contacts
    points[11, 1] = points[11, 0]  # coincident contacts
    m = np.cross(points[15, 1] - points[15, 0], points[15, 2] - points[15, 0])
    normals[15, 1] = np.cross(m, normals[15, 1])  # a normal in the contacts' plane
    normals[19, 2] = 0  # zero normal
    return points, normals, wrist, twist


def write_yaml_files(folder, points, normals, wrist, twist):
    """One grasp file per row, named so that sorting keeps the row order."""
    for i in range(len(points)):
        doc = {
            "name": str(i),
            "wrist": wrist[i].tolist(),
            "contacts": [{"point": points[i, c].tolist(), "normal": normals[i, c].tolist()} for c in range(3)],
            "twists": [{"name": "twist", "screw": twist[i].tolist()}],
        }
        if not np.any(normals[i, :, :].any(axis=1) == 0):
            (folder / f"g{i:04d}.yaml").write_text(yaml.safe_dump(doc))


def comparable(rec):
    """The numbers and verdicts of a record, without its file name."""
    out = {k: rec[k] for k in ("grasp", "twist", "contact_velocity", "ok")}
    for method in ("off_tangent", "tangent"):
        out[method] = rec[method]
    return out


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_npz_gives_the_same_records_as_one_yaml_file_per_grasp(tmp_path, data):
    points, normals, wrist, twist = data
    np.savez(
        tmp_path / "set.npz", points=points, normals=normals, wrist=wrist, twist=twist, names=np.arange(N).astype(str)
    )
    folder = tmp_path / "files"
    folder.mkdir()
    write_yaml_files(folder, points, normals, wrist, twist)
    from_arrays = jsonl(run("resolve", tmp_path / "set.npz", "-f", "jsonl"))
    from_files = {r["grasp"]: r for r in jsonl(run("resolve", folder, "-f", "jsonl"))}
    assert len(from_arrays) == N and len(from_files) == N - 1  # the zero normal cannot be written as a file
    for rec in from_arrays:
        if rec["grasp"] in from_files:
            assert comparable(rec) == comparable(from_files[rec["grasp"]]), rec["grasp"]
    codes = {
        r["grasp"]: (r["off_tangent"].get("error", {}).get("code"), r["tangent"].get("error", {}).get("code"))
        for r in from_arrays
    }
    assert codes["3"] == ("wrist-coplanar", None)
    assert codes["7"] == ("collinear-contacts", "collinear-contacts")
    assert codes["11"] == ("coincident-contacts", "coincident-contacts")
    assert codes["15"][0] is None and codes["15"][1] in {
        "normals-rank-deficient",
        "theta-not-unique",
        "theta-sigma-zero",
        "normal-in-contact-plane",
    }
    assert codes["19"] == (None, "zero-normal")


def test_npz_output_arrays_match_the_records_and_carry_a_status_legend(tmp_path, data):
    points, normals, wrist, twist = data
    np.savez(tmp_path / "set.npz", points=points, normals=normals, wrist=wrist, twist=twist)
    r = run("resolve", tmp_path / "set.npz", "-f", "npz", "-o", tmp_path / "out.npz")
    assert r.exit_code == 1  # degenerate rows fail; every row is still written
    z = np.load(tmp_path / "out.npz")
    off = gt.decompose_off_tangent(points, wrist, twist)
    tan = gt.decompose_tangent(points, gt.screws.direction(normals), twist)  # unit as loaded
    np.testing.assert_array_equal(z["x"], off.x)
    np.testing.assert_array_equal(z["beta"], tan.beta)
    np.testing.assert_array_equal(z["tangent_status"], tan.status)
    np.testing.assert_array_equal(z["contact_velocity"], gt.contact_velocities(points, twist))
    assert [z["status_legend"][s] for s in z["off_tangent_status"][[0, 3, 7]]] == [
        "ok",
        "wrist-coplanar",
        "collinear-contacts",
    ]
    assert z["grasp"][:3].tolist() == ["0", "1", "2"] and z["twist"].shape == (N, 6)
    assert z["files"].tolist() == [str(tmp_path / "set.npz")] and not z["file_index"].any()
    assert z["twist_names"].tolist() == ["twist"] and not z["twist_index"].any()
    assert r.stderr.strip().splitlines()[-1] == (
        f"{N} records: 5 with a degenerate method (off-tangent: 1 coincident-contacts, 1 collinear-contacts, "
        "1 wrist-coplanar; tangent: 1 coincident-contacts, 1 collinear-contacts, 1 normal-in-contact-plane, "
        "1 zero-normal), "
        "0 inputs failed"
    )


def test_npy_rows_with_a_wrist_or_a_twist_point(tmp_path, data):
    points, normals, wrist, twist = data
    rows = np.concatenate([points.reshape(N, 9), normals.reshape(N, 9), wrist], axis=1)
    np.save(tmp_path / "rows21.npy", rows)
    np.save(tmp_path / "rows18.npy", rows[:, :18])
    spin = "0,0,1,0,0.5,0"
    screw = np.array([0, 0, 1, 0, 0.5, 0.0])
    with_wrist = jsonl(run("resolve", tmp_path / "rows21.npy", "--twist", spin, "-f", "jsonl"))
    off = gt.decompose_off_tangent(points, wrist, screw)
    assert [r["off_tangent"].get("x") for r in with_wrist[:3]] == off.x[:3].tolist()
    no_wrist = jsonl(run("resolve", tmp_path / "rows18.npy", "--twist", spin, "-f", "jsonl"))
    assert all(r["off_tangent"] is None for r in no_wrist)
    # the 19th-21st columns as the point whose velocity the twist's linear part gives
    at = jsonl(run("resolve", tmp_path / "rows21.npy", "--twist", spin, "--extra-point", "at", "-f", "jsonl"))
    moved = gt.screws.twist_at(screw[:3], screw[3:], wrist)
    assert [r["twist"]["screw"] for r in at[:3]] == moved[:3].tolist()
    np.testing.assert_allclose([r["contact_velocity"] for r in at[:3]], gt.contact_velocities(points[:3], moved[:3]))


def test_npz_output_spills_to_disk_and_reads_back_the_same(tmp_path, data):
    points, normals, wrist, twist = data
    np.savez(tmp_path / "set.npz", points=points, normals=normals, wrist=wrist, twist=twist)
    run("resolve", tmp_path / "set.npz", "-f", "npz", "-o", tmp_path / "held.npz")
    ds = datasets.open_dataset(str(tmp_path / "set.npz"))
    with open(tmp_path / "spilled.npz", "wb") as out:
        w = NpzWriter(out, spill_bytes=1000)
        for block in dataset_blocks(ds, None, "both", rows=50, bases=False):
            w.write(block)
        w.close()
    assert w.spilled
    held, spilled = np.load(tmp_path / "held.npz"), np.load(tmp_path / "spilled.npz")
    assert sorted(held.files) == sorted(spilled.files)
    for name in held.files:
        np.testing.assert_array_equal(held[name], spilled[name], err_msg=name)


def test_several_twists_per_grasp_and_small_blocks_give_the_same_rows(tmp_path, data):
    points, normals, wrist, _ = data
    np.savez(tmp_path / "set.npz", points=points[:20], normals=normals[:20], wrist=wrist[:20])
    args = ("resolve", tmp_path / "set.npz", "--twist", "0,0,1,0,0,0", "--twist", "0,0,0,0,0,1", "-f", "jsonl")
    whole = run(*args).stdout.encode().splitlines()
    twists = [
        Twist(name, np.array(screw, float), None)
        for name, screw in (("0,0,1,0,0,0", [0, 0, 1, 0, 0, 0]), ("0,0,0,0,0,1", [0, 0, 0, 0, 0, 1]))
    ]
    blocks = list(dataset_blocks(datasets.open_dataset(str(tmp_path / "set.npz")), twists, "both", rows=7))
    assert [len(b) for b in blocks[:2]] == [6, 6]  # 3 grasps a block, each with its 2 twists
    assert [dumps(rec) for b in blocks for rec in records(b)] == whole
    assert [(r["grasp"], r["twist"]["name"]) for r in map(json.loads, whole[:4])] == [
        ("0", "0,0,1,0,0,0"),
        ("0", "0,0,0,0,0,1"),
        ("1", "0,0,1,0,0,0"),
        ("1", "0,0,0,0,0,1"),
    ]


def test_a_npy_is_read_through_a_memory_map(tmp_path, data):
    points, normals, *_ = data
    np.save(tmp_path / "rows.npy", np.concatenate([points.reshape(N, 9), normals.reshape(N, 9)], axis=1))
    ds = datasets.open_dataset(str(tmp_path / "rows.npy"))
    assert isinstance(ds.points.base, np.memmap) or isinstance(ds.points, np.memmap)
    np.testing.assert_array_equal(ds.normals, normals)


@pytest.mark.parametrize(
    "arrays, fragment",
    [
        (
            {"points": np.zeros((4, 3, 2)), "normals": np.zeros((4, 3, 3))},
            "points: expected shape (N, 3, 3), got (4, 3, 2)",
        ),
        ({"points": np.zeros((4, 3, 3))}, "missing array 'normals'"),
        (
            {"points": np.zeros((4, 3, 3)), "normals": np.zeros((4, 3, 3)), "wrists": np.zeros((4, 3))},
            "unknown array(s) wrists",
        ),
        ({"points": np.zeros((4, 3, 3)), "normals": np.zeros((5, 3, 3))}, "normals: 5 rows, but points has 4"),
        ({"points": np.full((4, 3, 3), "a"), "normals": np.zeros((4, 3, 3))}, "points: expected numbers"),
        (
            {"points": np.zeros((4, 3, 3)), "normals": np.zeros((4, 3, 3)), "twist": np.zeros(5)},
            "twist: expected shape (N, 6)",
        ),
    ],
)
def test_bad_npz_files_fail_with_one_line(tmp_path, arrays, fragment):
    np.savez(tmp_path / "bad.npz", **arrays)
    r = run("resolve", tmp_path / "bad.npz", "--twist", "0,0,1,0,0,0", "-f", "jsonl")
    assert r.exit_code == 1
    [rec] = jsonl(r)
    assert rec["error"]["code"] == "bad-dataset" and fragment in rec["error"]["message"]
    assert f"{tmp_path / 'bad.npz'}: error: bad-dataset: " in r.stderr and "Traceback" not in r.output


def test_a_file_that_is_not_numpy_and_a_wrong_row_length(tmp_path):
    (tmp_path / "junk.npz").write_bytes(b"not a zip")
    np.save(tmp_path / "rows.npy", np.zeros((3, 20)))
    r = run("resolve", tmp_path / "junk.npz", tmp_path / "rows.npy", "--twist", "0,0,1,0,0,0", "-f", "jsonl")
    codes = [(rec["error"]["code"], rec["error"]["message"]) for rec in jsonl(r)]
    assert codes[0][0] == "read-error"
    assert codes[1] == (
        "bad-dataset",
        "expected rows of 18 or 21 numbers (p1 p2 p3 n1 n2 n3 [point]), got shape (3, 20)",
    )


def test_a_data_set_over_two_workers_gives_the_same_output(tmp_path, data):

    from grasptwist.run.pipeline import Job, Tuning, record_outputs

    def written(workers):
        text, lines = b"", []
        for out in record_outputs(Job(fmt="jsonl"), [str(tmp_path / "set.npz")], workers, tuning):
            text += b"".join(x + b"\n" for x in out.encoded) + (
                Path(out.spool).read_bytes() + b"\n" if out.spool else b""
            )
            lines += out.errors + out.warnings
        return text, lines

    points, normals, wrist, twist = data
    np.savez(tmp_path / "set.npz", points=points, normals=normals, wrist=wrist, twist=twist)
    tuning = Tuning(grasps_per_task=50, records_at_once=17)  # 5 tasks of 3 outputs
    one, two = written(1), written(2)
    assert two == one and len(one[0].splitlines()) == N


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_workers_spool_through_the_kernel_to_pipes_and_files(tmp_path, data):
    import subprocess
    import sys

    from grasptwist.run.pipeline import TUNING

    points, normals, wrist, twist = (np.tile(a, (1 + TUNING.grasps_per_task // N,) + (1,) * (a.ndim - 1)) for a in data)
    n = len(points)  # two tasks of several outputs each for the pool
    np.savez(tmp_path / "set.npz", points=points, normals=normals, wrist=wrist, twist=twist)
    exe = Path(sys.executable).parent / "grasptwist"
    cmd = [str(exe)] if exe.exists() else [sys.executable, "-m", "grasptwist"]
    args = ["resolve", str(tmp_path / "set.npz"), "-f", "json"]
    one = subprocess.run(cmd + args + ["-j", "1"], capture_output=True, timeout=120)
    piped = subprocess.run(cmd + args + ["-j", "2"], capture_output=True, timeout=120)
    to_file = subprocess.run(
        cmd + args + ["-j", "2", "-o", str(tmp_path / "out.json")], capture_output=True, timeout=120
    )
    assert piped.stdout == one.stdout == (tmp_path / "out.json").read_bytes()
    assert piped.returncode == to_file.returncode == one.returncode == 1
    assert len(json.loads(one.stdout)) == n


# --- failed rows on stderr: the --warnings rule (issue 21) ------------------------------------

#: Coincident contacts: the tangent method fails on the row, the off-tangent method is skipped
#: for want of a wrist (a warning), the record says both.
COINCIDENT = np.array([[1.0, 0, 0], [1.0, 0, 0], [-0.5, -0.866, 0]])


@pytest.fixture
def failing_rows(tmp_path):
    """A data set of 30 grasps, rows 0..24 with coincident contacts, and a grasp file that cannot be read."""
    good = np.array([[1.0, 0, 0], [-0.5, 0.866, 0], [-0.5, -0.866, 0]])
    points = np.stack([COINCIDENT] * 25 + [good] * 5)
    normals = np.broadcast_to([[-1, 0.1, 0.2], [0.5, -0.9, 0.1], [0.5, 0.9, 0.3]], points.shape)
    np.savez(tmp_path / "rows.npz", points=points, normals=normals, twist=np.array([0, 0, 1.0, 0, 0, 0]))
    (tmp_path / "bad.yaml").write_text("contacts: 3\n")  # one problem, a file-level error
    return tmp_path


@pytest.mark.parametrize("fmt", ["jsonl", "npz"])  # records encoded where made, and blocks to a writer
def test_failed_rows_follow_the_warnings_rule_and_the_files_errors_are_always_printed(failing_rows, fmt):
    from grasptwist.cli.diagnostics import WARNINGS_SHOWN

    args = ("resolve", failing_rows / "rows.npz", failing_rows / "bad.yaml", "-f", fmt)
    said, written = {}, {}
    for mode in ("all", "summary", "none"):
        out = failing_rows / f"{mode}.{fmt}"
        r = run(*args, "-o", out, "--warnings", mode)
        assert r.exit_code == 1, r.stderr
        said[mode] = r.stderr.splitlines()
        written[mode] = out.read_bytes() if fmt == "jsonl" else dict(np.load(out))
    row = [line for line in said["all"] if ": error: tangent: coincident-contacts: " in line]
    assert [line.split(": grasp ")[1].split(",")[0] for line in row] == [f"'{k}'" for k in range(25)]
    bad = [line for line in said["all"] if line.startswith(f"{failing_rows / 'bad.yaml'}:")]
    assert len(bad) == 1 and ": error: " in bad[0]
    closing = "31 records: 25 with a degenerate method (tangent: 25 coincident-contacts), 1 input failed"
    assert said["all"][-1] == closing
    # summary: the first 20 rows' errors, the file's error, then the rest counted by code
    assert [line for line in said["summary"] if ": error: " in line] == row[:WARNINGS_SHOWN] + bad
    assert (
        f"grasptwist: {25 - WARNINGS_SHOWN} more row errors not shown (--warnings all): 5 tangent coincident-contacts"
        in said["summary"]
    )
    assert said["summary"][-1] == closing
    # none: no row's error, the file's still, and no count of what was not shown
    assert said["none"] == bad + [closing]
    # the records do not depend on what stderr says
    if fmt == "jsonl":
        assert written["all"] == written["summary"] == written["none"]
    else:
        for key in written["all"]:
            np.testing.assert_array_equal(written["all"][key], written["none"][key])


def test_an_npz_named_npy_is_one_error_record_and_the_others_keep_theirs(tmp_path):
    # 0.3: internal error: AttributeError ('NpzFile' object has no attribute 'ndim'), every record lost
    np.savez(tmp_path / "a.npz", points=np.zeros((2, 3, 3)), normals=np.ones((2, 3, 3)))
    (tmp_path / "a.npz").rename(tmp_path / "renamed.npy")
    (tmp_path / "text.npy").write_text("p1_x,p1_y\n")
    grasp = GRASPS / "polyhedron.yaml"
    r = CliRunner().invoke(app, ["resolve", str(tmp_path / "renamed.npy"), str(tmp_path / "text.npy"), str(grasp)])
    assert r.exit_code == 1 and "internal error" not in r.output
    prefix = "error: bad-dataset: not a .npy file: it does not start with numpy's b'\\x93NUMPY'"
    assert r.stderr.splitlines()[:2] == [
        f"{tmp_path / 'renamed.npy'}: {prefix} (it is a zip archive: an .npz named .npy?)",
        f"{tmp_path / 'text.npy'}: {prefix}",
    ]
    assert "polyhedron" in r.stdout  # the grasp file's records


def test_check_inflation_refuses_only_large_and_highly_compressed_input():
    from grasptwist.io.limits import INFLATION_FLOOR, MAX_INFLATION, check_inflation

    check_inflation(INFLATION_FLOOR, 1, "zip bomb")  # small: any ratio
    check_inflation(INFLATION_FLOOR + 1, (INFLATION_FLOOR + 1) // MAX_INFLATION + 1, "zip bomb")  # large, ratio below
    with pytest.raises(ValueError, match=r"^declares 67,108,865 bytes decoded from 671,088 \(over 100 times\): "):
        check_inflation(INFLATION_FLOOR + 1, (INFLATION_FLOOR + 1) // MAX_INFLATION, "zip bomb")
