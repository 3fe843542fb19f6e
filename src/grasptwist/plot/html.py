"""Interactive 3D views of grasps, as one self-contained HTML page each (plotly.js).

``grasptwist plot FILE -o FILE.html`` writes a page a reader can turn, hover
and play in any browser, offline: a figure of the grasp with its twists (a
dropdown switches them) and, for each of its paths, an animation along the
samples of ``follow`` (:mod:`grasptwist.plot.animation`).  The figures are
built here as plain dicts from the scenes of :mod:`grasptwist.plot.scene`
(:mod:`grasptwist.plot.traces`), so they need no plotly; plotly (the
optional extra ``grasptwist[html]``) supplies only plotly.js, put inside the
page or, with ``js_beside``, written once beside it.  Each figure's JSON
sits in the page in a ``<script type="application/json">`` element, which
:func:`read_figures` reads back (the tests do).
"""

from __future__ import annotations

import html
import os
import re
from collections.abc import Iterator
from pathlib import Path

import orjson

from .animation import path_figures
from .figures import twist_figure
from .render import Note, image_paths, opened_for_writing
from .scene import check_method

__all__ = [
    "HTML",
    "JS_NAME",
    "MissingPlotly",
    "grasp_page",
    "html_loaded",
    "read_figures",
    "require_plotly",
    "twist_figure",
    "write_page",
]

HTML = ".html"
#: plotly.js's file name beside the pages (``js_beside``).
JS_NAME = "plotly.min.js"
INSTALL_HINT = "grasptwist plot -o FILE.html needs plotly: pip install plotly (from a clone of grasptwist: pip install -e '.[html]')"
_CONFIG = {"displaylogo": False, "responsive": True}


class MissingPlotly(RuntimeError):
    """plotly is not installed; the message says how to install it."""


def require_plotly():
    """Import and return plotly, or raise :class:`MissingPlotly`."""
    try:
        import plotly
    except ImportError as exc:
        raise MissingPlotly(INSTALL_HINT) from exc
    return plotly


# --- pages ---------------------------------------------------------------------

_SCRIPT = """
for (const div of document.querySelectorAll("div.grasptwist-figure")) {
  const figure = JSON.parse(document.getElementById(div.id + "-json").textContent);
  Plotly.newPlot(div, figure);
}
"""


def grasp_page(grasp, *, twists=None, method=None, active=0, meshes=(), followed=(), forces=None):
    """The sections of a grasp's page ``[(heading, figure)]``: the twists' figure first
    (:func:`twist_figure`, with a URDF hand's link ``meshes``), then one animation per
    path of ``followed``."""
    figure = twist_figure(grasp, twists, method=method, active=active, meshes=meshes, forces=forces)
    return [(f"{grasp.name}: twists", figure), *path_figures(grasp, followed, method=method)]


def write_page(path, sections, *, title: str, js_beside: bool = False, opener=None) -> Path:
    """Write an HTML page of figures ``[(heading, figure)]`` to ``path``.

    plotly.js goes inside the page, or with ``js_beside`` into
    ``plotly.min.js`` beside it (written once: an up-to-date copy is left
    alone) and the page refers to it.  Each figure's JSON is in an element
    :func:`read_figures` reads back.  ``opener`` opens each file, as for
    ``grasptwist.plot.render.render``.
    """
    from plotly.offline import get_plotlyjs  # plotly is needed for its plotly.js only

    require_plotly()
    path = Path(path)
    js = get_plotlyjs()
    opener = opener or opened_for_writing
    if js_beside:
        beside = path.parent / JS_NAME
        if not beside.is_file() or beside.read_text("utf-8") != js:
            with opener(beside) as f:
                f.write(js.encode("utf-8"))
        script = f'<script src="{JS_NAME}"></script>'
    else:
        script = f"<script>{js}</script>"
    body = []
    for n, (heading, figure) in enumerate(sections):
        text = orjson.dumps(figure | {"config": _CONFIG}, option=orjson.OPT_SERIALIZE_NUMPY).decode()
        text = script_json(text)
        body.append(
            f"<h2>{html.escape(heading)}</h2>\n"
            f'<div id="figure-{n}" class="grasptwist-figure" style="height:85vh"></div>\n'
            f'<script type="application/json" id="figure-{n}-json">{text}</script>'
        )
    page = (
        "<!DOCTYPE html>\n<html><head><meta charset='utf-8'>"
        f"<title>{html.escape(title)}</title>"
        "<style>body{font-family:sans-serif;margin:0 1em}h2{font-size:1.1em;margin:0.6em 0 0}</style>\n"
        f"{script}</head><body>\n" + "\n".join(body) + f"\n<script>{_SCRIPT}</script>\n</body></html>\n"
    )
    with opener(path) as f:
        f.write(page.encode("utf-8"))
    return path


def script_json(text: str) -> str:
    """JSON ``text`` made safe inside a ``<script>`` element: every ``<`` written ``\\u003c``.

    An HTML parser reads a script element's text for ``</script``, and after
    ``<!--`` followed by ``<script`` for a second ``</script>`` before the
    first ends it; one rule for every ``<`` leaves it nothing to find.
    Outside strings JSON has no ``<``, and in a string ``\\u003c`` reads
    back as ``<``.

    >>> script_json('{"name": "<!--<script></script>"}')
    '{"name": "\\\\u003c!--\\\\u003cscript>\\\\u003c/script>"}'
    """
    return text.replace("<", "\\u003c")


def read_figures(text: str) -> list[dict]:
    """The figures of a page written by :func:`write_page`, in order.

    >>> read_figures('<script type="application/json" id="figure-0-json">{"data": []}</script>')
    [{'data': []}]
    """
    found = re.findall(r'<script type="application/json" id="figure-\d+-json">(.*?)</script>', text, flags=re.S)
    return [orjson.loads(f) for f in found]


# --- what the plot command does ------------------------------------------------


def html_loaded(
    path: str,
    output,
    grasps,
    *,
    twist_name: str | None = None,
    method: str | None = None,
    js_beside: bool = False,
    extras=None,
    grips=None,
    opener=None,
) -> Iterator[Path | Note]:
    """What ``grasptwist plot PATH -o OUTPUT.html`` (or a folder's ``-o FOLDER``) writes for
    ``grasps``, the grasps read from ``path``.

    Like :func:`grasptwist.plot.render.render_loaded`, one page per grasp:
    for a file its first grasp into ``output``; for a folder each grasp into
    ``output/<grasp>.html`` (named as :func:`~grasptwist.plot.render.image_paths`
    names them).  ``extras(grasp)`` gives what a page shows beside the grasp
    itself, ``(meshes, followed, notes)``: its hand's link meshes, its followed
    paths for :func:`grasp_page`, and a :class:`Note` for each that could not
    be had; ``grips(grasp)`` the grip forces ``(3, 3)`` drawn with its friction cones (or
    None); ``opener`` opens each file (:func:`write_page`).  Yields each page written and each note.
    """
    from .render import chosen_twist

    require_plotly()
    if os.path.isdir(path):
        plan = [(p, g) for p, g, _ in image_paths(grasps, output, HTML, per_twist=False)]
        Path(output).mkdir(parents=True, exist_ok=True)
    else:
        plan = [(Path(output), g) for g in grasps[:1]]
        if len(grasps) > 1:
            yield Note(f"{path}: warning: drawing the first of its {len(grasps)} grasps, '{grasps[0].name}'", False)
    for page, grasp in plan:
        try:
            check_method(method, grasp.wrist)
        except ValueError as exc:
            if not os.path.isdir(path):
                raise
            yield Note(f"{grasp.file}: grasp '{grasp.name}': error: {exc}")
            continue
        active = 0
        if twist_name is not None and not os.path.isdir(path):
            active = grasp.twists.index(chosen_twist(grasp, twist_name))
        meshes, followed, notes = extras(grasp) if extras else ((), (), ())
        yield from notes
        forces = grips(grasp) if grips else None
        sections = grasp_page(grasp, method=method, active=active, meshes=meshes, followed=followed, forces=forces)
        yield write_page(page, sections, title=f"grasptwist: {grasp.name}", js_beside=js_beside, opener=opener)
