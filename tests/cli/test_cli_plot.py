"""`grasptwist plot` through the command line."""

import subprocess
import sys

import pytest
from typer.testing import CliRunner

from grasptwist.cli import app
from places import GRASPS

pytest.importorskip("matplotlib")


def run(*args):
    return CliRunner().invoke(app, [str(a) for a in args])


def png_size(path):
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    return int.from_bytes(data[16:20], "big"), int.from_bytes(data[20:24], "big")


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_one_grasp_and_twist_to_png_and_svg(tmp_path):
    r = run("plot", GRASPS / "cylinder.yaml", "--select", "spin-z", "-o", tmp_path / "c.png")
    assert r.exit_code == 0, r.output
    assert r.stdout == f"{tmp_path / 'c.png'}\n"
    assert png_size(tmp_path / "c.png") == (1400, 700)
    r = run(
        "plot", GRASPS / "polyhedron.yaml", "--twist", "0,0,1,0,0,0", "--method", "tangent", "-o", tmp_path / "p.svg"
    )
    assert r.exit_code == 0 and (tmp_path / "p.svg").read_text().lstrip().startswith("<?xml")


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_a_folder_gives_one_image_per_grasp_and_twist_and_an_error_line_per_bad_input(tmp_path):
    # one good grasp (drawn once: the drawing itself is tested in test_plot), one the method
    # cannot draw, one file that cannot be read
    folder = tmp_path / "in"
    folder.mkdir()
    cylinder = (GRASPS / "cylinder.yaml").read_text()
    (folder / "a.yaml").write_text(cylinder.replace("name: cylinder", "name: cylinder/a"))
    (folder / "b.yaml").write_text(cylinder.replace("name: cylinder", "name: no-wrist").replace("wrist:", "#"))
    (folder / "c.yaml").write_text("contacts: [\n")
    r = run(
        "plot",
        folder,
        "-o",
        tmp_path / "out",
        "--twist",
        "0,0,1,0,0,0",
        "--twist-name",
        "spin",
        "--method",
        "off-tangent",
    )
    assert r.exit_code == 1
    assert r.stdout == f"{tmp_path / 'out' / 'cylinder_a-spin.png'}\n"
    assert png_size(tmp_path / "out" / "cylinder_a-spin.png") == (1400, 700)
    errors = r.stderr.splitlines()
    assert len(errors) == 2
    assert errors[0].startswith(f"{folder / 'c.yaml'}:2:1: error: ")
    assert errors[1] == (
        f"{folder / 'b.yaml'}: grasp 'no-wrist': error: "
        "the off-tangent method needs a wrist point; use --method tangent or add a wrist"
    )


def test_usage_errors_exit_2(tmp_path):
    r = run("plot", GRASPS / "cylinder.yaml", "--select", "nope", "-o", tmp_path / "x.png")
    assert r.exit_code == 2 and "has no twist 'nope' (it has: sigma-1, spin-z, lift-z)" in r.output
    for args, message in [
        (["--select", "spin-z", "--select", "lift-z"], "a picture draws one twist: give one (got 2)"),
        (["--select", "spin-z", "--twist", "0,0,1,0,0,0"], "--twist replaces them: give one"),
        (["--select", "spin-z", "--twist-name", "lift-z"], "names --twist only: give the file's twist by --select"),
    ]:
        r = run("plot", GRASPS / "cylinder.yaml", *args, "-o", tmp_path / "x.png")
        assert r.exit_code == 2 and message in " ".join(r.output.split()), r.output
    r = run("plot", GRASPS, "--select", "spin-z", "-o", tmp_path / "pictures")
    assert r.exit_code == 2 and "a folder gets every twist" in r.output
    r = run("plot", GRASPS / "cylinder.yaml", "-o", tmp_path / "x.gif")
    assert r.exit_code == 2 and "cannot write '.gif': use one of .png, .svg, .pdf" in r.output
    r = run("plot", tmp_path / "rows.npz", "-o", tmp_path / "x.png")
    assert r.exit_code == 2 and "plot draws grasp files (.yaml, .yml) or folders of them, not data sets" in r.output
    (tmp_path / "g.yaml").write_text((GRASPS / "cylinder.yaml").read_text().replace("wrist:", "#"))
    r = run("plot", tmp_path / "g.yaml", "--method", "off-tangent", "-o", tmp_path / "x.png")
    assert r.exit_code == 2 and "the off-tangent method needs a wrist point" in r.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["g.yaml"]


def test_without_matplotlib_it_says_how_to_install_it(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "matplotlib", None)  # makes `import matplotlib` fail
    r = run("plot", GRASPS / "cylinder.yaml", "-o", tmp_path / "c.png")
    assert r.exit_code == 1 and r.stdout == "" and not (tmp_path / "c.png").exists()
    # one line, the word "grasptwist" once at its start (0.1 doubled it: "grasptwist: error: grasptwist plot ...")
    assert (
        r.stderr
        == "grasptwist plot needs matplotlib: pip install matplotlib (from a clone of grasptwist: pip install -e '.[plot]')\n"
    )


def test_the_other_commands_never_import_matplotlib_or_rich_for_machine_output():
    code = (
        "import sys; from typer.testing import CliRunner; from grasptwist.cli import app; "
        f"r = CliRunner().invoke(app, ['resolve', {str(GRASPS / 'polyhedron.yaml')!r}, '--json']); "
        "print(r.exit_code, 'matplotlib' in sys.modules, 'rich' in sys.modules)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert out.stdout.split() == ["0", "False", "False"]


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_the_old_twist_name_still_picks_a_twist_with_one_deprecation_line(tmp_path):
    new = run("plot", GRASPS / "cylinder.yaml", "--select", "lift-z", "-o", tmp_path / "new.png")
    old = run("plot", GRASPS / "cylinder.yaml", "--twist-name", "lift-z", "-o", tmp_path / "old.png")
    first = run("plot", GRASPS / "cylinder.yaml", "-o", tmp_path / "first.png")  # sigma-1
    assert new.exit_code == old.exit_code == first.exit_code == 0 and new.stderr == ""
    assert old.stderr == "grasptwist: warning: plot --twist-name without --twist is deprecated: use --select lift-z\n"
    drawn = {name: (tmp_path / f"{name}.png").read_bytes() for name in ("new", "old", "first")}
    assert drawn["old"] == drawn["new"] != drawn["first"]
