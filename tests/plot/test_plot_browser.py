"""The HTML views in a real browser: headless Chromium opens the page, a screenshot shows the 3D
plot drawn (coloured pixels in its plot area, which only WebGL's lines and meshes give: axes,
text and the dropdown are grey), and no JavaScript error reached the console.

Needs Debian's chromium (`apt-get install chromium`; .ci/run installs it as root) and the test
extra's websocket-client; skipped, saying so, without them.  All with -m slow (a Chromium
start and plotly.js's 5 MB parse: several seconds on a busy machine); the default run checks the
pages' HTML in test_plot_html.py.
"""

import tempfile
from pathlib import Path

import numpy as np
import pytest

from grasptwist.plot.browser import CHROMIUM, capture, chromium
from places import GRASPS

pytest.importorskip("plotly")
pytest.importorskip("websocket", reason="the browser tests need websocket-client (the test extra)")
Image = pytest.importorskip("PIL.Image")
pytestmark = pytest.mark.skipif(chromium() is None, reason=f"no Chromium at {CHROMIUM}: apt-get install chromium")


def coloured_pixels(png, box) -> int:
    """Pixels of ``box`` ``[x, y, w, h]`` with a colour (channels more than 80 apart), not grey or white."""
    x, y, w, h = (int(round(v)) for v in box)
    rgb = np.asarray(Image.open(png).convert("RGB"), dtype=int)[max(y, 0) : y + h, max(x, 0) : x + w]
    return int(np.sum(rgb.max(axis=2) - rgb.min(axis=2) > 80))


def page(tmp_path, grasp, *options):
    from typer.testing import CliRunner

    from grasptwist.cli import app

    out = tmp_path / f"{grasp}.html"
    r = CliRunner().invoke(app, ["plot", str(GRASPS / f"{grasp}.yaml"), "-o", str(out), *options])
    assert r.exit_code == 0, r.output
    return out


def chromium_leftovers():
    """What a Chromium visit could leave in the temporary folder: its profile, its own files."""
    tmp = Path(tempfile.gettempdir())
    return {*tmp.glob("org.chromium.Chromium.*"), *tmp.glob("grasptwist-chromium-*")}


@pytest.mark.slow  # a Chromium start, 3-6 s (the page's HTML: test_plot_html.py): docs/reference/development.md, Test time
def test_a_grasp_page_is_drawn_without_javascript_errors(tmp_path):
    before = chromium_leftovers()
    shot = capture(page(tmp_path, "box-edge"), tmp_path / "box-edge.png", size=(1000, 800))
    assert chromium_leftovers() <= before  # no debris of the visit
    assert shot.errors == []
    (box,) = shot.scenes
    assert box[2] > 500 and box[3] > 400  # the plot area fills most of the window
    assert coloured_pixels(shot.png, box) > 1000  # the screw axes, velocities, planes


@pytest.mark.slow
def test_a_path_animation_and_a_urdf_hand_are_drawn_too(tmp_path):
    pytest.importorskip("yourdfpy")
    pytest.importorskip("robot_properties_fingers")
    shot = capture(page(tmp_path, "cylinder", "--path", "turn-x"), tmp_path / "c.png", scroll_to=1)
    assert shot.errors == [] and len(shot.scenes) == 2
    assert coloured_pixels(shot.png, shot.scenes[1]) > 1000
    shot = capture(page(tmp_path, "trifinger-cube", "--js-beside"), tmp_path / "t.png")
    # the hand's grey meshes hide most of the coloured axes; a blank or failed canvas has none
    assert shot.errors == [] and coloured_pixels(shot.png, shot.scenes[0]) > 100


@pytest.mark.slow
def test_a_javascript_error_is_caught(tmp_path):
    out = page(tmp_path, "box-edge", "--js-beside")
    out.write_text(out.read_text("utf-8").replace("</body>", "<script>notAFunction()</script></body>"), "utf-8")
    shot = capture(out, tmp_path / "e.png")
    assert any("notAFunction is not defined" in e for e in shot.errors)


@pytest.mark.slow
def test_a_page_with_a_comment_and_script_opening_in_a_name_is_drawn(tmp_path):
    from test_plot_html import hostile_names_page

    shot = capture(hostile_names_page(tmp_path), tmp_path / "h.png")
    assert shot.errors == [] and len(shot.scenes) == 1  # 0.3: nothing drew, the page's script was swallowed
    assert coloured_pixels(shot.png, shot.scenes[0]) > 1000


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_the_object_is_drawn(tmp_path):
    from test_plot_objects import sphere_tripod

    from grasptwist.plot import grasp_page, write_page

    page = write_page(tmp_path / "ball.html", grasp_page(sphere_tripod()), title="ball", js_beside=True)
    only = 'Plotly.restyle(figures[0], {visible: figures[0].data.map(t => t.name === "object")})'
    shot = capture(page, tmp_path / "ball.png", size=(900, 700), before=only)
    assert shot.errors == []
    x, y, w, h = (int(round(v)) for v in shot.scenes[0])
    rgb = np.asarray(Image.open(shot.png).convert("RGB"), dtype=int)[y : y + h, x : x + w]
    # everything else hidden: the tan ball (red over blue, where the grey axes have neither) fills
    # some 38,000 pixels; an undrawn mesh none
    assert np.sum(rgb[..., 0] - rgb[..., 2] > 15) > 10000


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_several_grasps_of_one_object_are_drawn_each_in_its_colour(tmp_path):
    from test_plot_several import found_text
    from typer.testing import CliRunner

    from grasptwist.cli import app
    from grasptwist.plot.scene import GRASP_COLOURS

    found = tmp_path / "found.yaml"
    found.write_text(found_text())
    out = tmp_path / "found.html"
    r = CliRunner().invoke(app, ["plot", str(found), "-o", str(out), "--js-beside"])
    assert r.exit_code == 0, r.output
    # the object hidden, so that the contacts behind it keep their colours
    hide = 'Plotly.restyle(figures[0], {visible: figures[0].data.map(t => t.name !== "object")})'
    shot = capture(out, tmp_path / "found.png", size=(1000, 800), before=hide)
    assert shot.errors == [] and len(shot.scenes) == 1
    x, y, w, h = (int(round(v)) for v in shot.scenes[0])
    rgb = np.asarray(Image.open(shot.png).convert("RGB"), dtype=int)[y : y + h, x : x + w]
    for colour in GRASP_COLOURS[:3]:  # each grasp's dots, arrows and labels in its own colour
        want = np.array([int(colour[i : i + 2], 16) for i in (1, 3, 5)])
        assert np.sum(np.abs(rgb - want).max(axis=2) < 12) > 30, colour
