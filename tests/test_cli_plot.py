"""`grasptwist plot` through the command line."""

import subprocess
import sys
from pathlib import Path

import pytest
from typer.testing import CliRunner

from grasptwist import plot
from grasptwist.cli import app

pytest.importorskip("matplotlib")
GRASPS = Path(__file__).parent.parent / "grasps"


def run(*args):
    return CliRunner().invoke(app, [str(a) for a in args])


def png_size(path):
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    return int.from_bytes(data[16:20], "big"), int.from_bytes(data[20:24], "big")


def test_one_grasp_and_twist_to_png_and_svg(tmp_path):
    r = run("plot", GRASPS / "cylinder.yaml", "--twist-name", "spin-z", "-o", tmp_path / "c.png")
    assert r.exit_code == 0, r.output
    assert r.stdout == f"{tmp_path / 'c.png'}\n"
    assert png_size(tmp_path / "c.png") == (1400, 700)
    r = run(
        "plot", GRASPS / "polyhedron.yaml", "--twist", "0,0,1,0,0,0", "--method", "tangent", "-o", tmp_path / "p.svg"
    )
    assert r.exit_code == 0 and (tmp_path / "p.svg").read_text().lstrip().startswith("<?xml")


def test_a_folder_gives_one_image_per_grasp_and_twist(tmp_path):
    r = run("plot", GRASPS, "-o", tmp_path / "out")
    assert r.exit_code == 0, r.output
    written = r.stdout.split()
    assert len(written) == 15 and all(Path(p).exists() for p in written)
    assert Path(written[0]).name == "box-edge-tip-over-edge.png"


def test_usage_errors_exit_2(tmp_path):
    r = run("plot", GRASPS / "cylinder.yaml", "--twist-name", "nope", "-o", tmp_path / "x.png")
    assert r.exit_code == 2 and "has no twist 'nope' (it has: sigma-1, spin-z, lift-z)" in r.output
    assert run("plot", GRASPS / "cylinder.yaml", "-o", tmp_path / "x.gif").exit_code == 2
    assert not (tmp_path / "x.png").exists()


def test_without_matplotlib_it_says_how_to_install_it(tmp_path, monkeypatch):
    def missing():
        raise plot.MissingMatplotlib("grasptwist plot needs matplotlib: pip install 'grasptwist[plot]'")

    monkeypatch.setattr(plot, "require_matplotlib", missing)
    r = run("plot", GRASPS / "cylinder.yaml", "-o", tmp_path / "c.png")
    assert r.exit_code == 1
    assert r.stderr == "grasptwist: error: grasptwist plot needs matplotlib: pip install 'grasptwist[plot]'\n"


def test_the_other_commands_never_import_matplotlib_or_rich_for_machine_output():
    code = (
        "import sys; from typer.testing import CliRunner; from grasptwist.cli import app; "
        f"r = CliRunner().invoke(app, ['resolve', {str(GRASPS / 'polyhedron.yaml')!r}, '--json']); "
        "print(r.exit_code, 'matplotlib' in sys.modules, 'rich' in sys.modules)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert out.stdout.split() == ["0", "False", "False"]
