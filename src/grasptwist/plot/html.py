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

import numpy as np
import orjson

from .render import Note, image_paths, read_grasps
from .scene import Scene, check_method, default_method, grasp_scene
from .traces import force_traces, mesh_trace, scene_traces

__all__ = [
    "HTML",
    "JS_NAME",
    "MissingPlotly",
    "grasp_page",
    "grasp_scenes",
    "html_inputs",
    "read_figures",
    "require_plotly",
    "twist_figure",
    "write_page",
]

HTML = ".html"
#: plotly.js's file name beside the pages (``js_beside``).
JS_NAME = "plotly.min.js"
INSTALL_HINT = (
    "grasptwist plot -o FILE.html needs plotly: pip install plotly (from a clone of grasptwist: pip install '.[html]')"
)
_CONFIG = {"displaylogo": False, "responsive": True}
_EYE = 1.8  # the camera's distance, in plotly's units of the scene box


class MissingPlotly(RuntimeError):
    """plotly is not installed; the message says how to install it."""


def require_plotly():
    """Import and return plotly, or raise :class:`MissingPlotly`."""
    try:
        import plotly
    except ImportError as exc:
        raise MissingPlotly(INSTALL_HINT) from exc
    return plotly


# --- figures -------------------------------------------------------------------


def methods_of(grasp, method: str | None = None) -> tuple[str, ...]:
    """The methods a view draws: ``method``, else both when the grasp has a wrist, else the tangent one.

    >>> methods_of(type("G", (), {"wrist": None})())
    ('tangent',)
    """
    if method is not None:
        return (check_method(method, grasp.wrist),)
    return ("off-tangent", "tangent") if default_method(grasp.wrist) == "off-tangent" else ("tangent",)


def grasp_scenes(grasp, twist, methods, velocity_scale=None) -> list[Scene]:
    """One scene per method of ``grasp`` and ``twist``, every basis screw and the hand's fingers in each.

    Without ``velocity_scale`` the scenes are drawn again at the smallest of
    their fitted scales, so that every velocity arrow of a view has one scale.
    """
    scenes = [
        grasp_scene(grasp, twist, method=m, all_bases=True, links=True, velocity_scale=velocity_scale) for m in methods
    ]
    if velocity_scale is None and len(scenes) > 1:
        return grasp_scenes(grasp, twist, methods, velocity_scale_of(scenes))
    return scenes


def velocity_scale_of(scenes) -> float | None:
    """The smallest drawn length per unit velocity of the scenes' velocity arrows (None: none drawn)."""
    scales = [a.scale for s in scenes for a in s.arrows if a.kind == "contact-velocity"]
    return min(scales) if scales else None


def view_traces(scenes, units, half) -> dict[str, list[dict]]:
    """Traces of one view: the common kinds of the first scene, each scene's own kinds, and forces."""
    out = scene_traces(scenes[0], units, own=False, half=half)
    for s in scenes:
        out.update(scene_traces(s, units, common=False, half=half))
    out.update(force_traces(scenes[0], units))
    return out


def view_title(scenes) -> str:
    """The first scene's title line, then each method's line(s), as plotly's ``<br>``-separated text."""
    lines = scenes[0].title.split("\n")[:1] + [line for s in scenes for line in s.title.split("\n")[1:]]
    return "<br>".join(html.escape(line, quote=False) for line in lines)


def bounds(scenes) -> tuple[np.ndarray, float]:
    """Centre and half-width of a cube holding every scene."""
    boxes = [s.bounds() for s in scenes]
    lo = np.min([c - h for c, h in boxes], axis=0)
    hi = np.max([c + h for c, h in boxes], axis=0)
    return (lo + hi) / 2, float(np.max(hi - lo)) / 2


def scene_layout(scene: Scene, units: str | None, cube=None) -> dict:
    """Plotly's 3D scene: axis titles with units, equal scales, the camera on the scene's oblique view.

    ``cube`` ``(centre, half)`` fixes the ranges (an animation's, so that
    they do not jump between frames); without it the ranges follow the data
    (``aspectmode`` ``"data"``: equal scales too).
    """
    axes = {}
    for n, c in enumerate("xyz"):
        axes[f"{c}axis"] = {"title": {"text": f"{c} ({units})" if units else c}}
        if cube is not None:
            axes[f"{c}axis"]["range"] = [cube[0][n] - cube[1], cube[0][n] + cube[1]]
    eye = _EYE * scene.views[0][1] if scene.views else np.array([1.25, 1.25, 1.25])
    camera = {"eye": dict(zip("xyz", map(float, eye))), "up": {"x": 0, "y": 0, "z": 1}}
    return axes | {"aspectmode": "data" if cube is None else "cube", "camera": camera}


def twist_figure(grasp, twists=None, *, method: str | None = None, active: int = 0, meshes=()) -> dict:
    """The figure of a grasp and its twists: a dropdown switches between twists.

    Parameters
    ----------
    grasp : Grasp
    twists : sequence of Twist, optional
        Default the grasp's own; none draws the grasp and its bases only.
    method : str, optional
        One method's bases only; default both (the tangent one without a wrist).
    active : int
        The twist shown first.
    meshes : sequence of (vertices, faces)
        The hand's link meshes (:func:`grasptwist.io.urdf_meshes.hand_meshes`),
        one legend entry shown with every twist.

    Returns
    -------
    dict
        A plotly.js figure ``{"data", "layout"}``: for each twist its traces
        (only the active twist's visible), and with several twists a
        dropdown whose buttons show one twist's traces each.
    """
    methods = methods_of(grasp, method)
    items = list(grasp.twists if twists is None else twists) or [None]
    views = [grasp_scenes(grasp, t, methods) for t in items]
    half = bounds([s for v in views for s in v])[1]
    data, owner, shown, titles = [], [], [], []
    for k, scenes in enumerate(views):
        for traces in view_traces(scenes, grasp.units, half).values():
            for t in traces:
                shown.append(t.get("visible", True))  # True, or "legendonly" for the kinds off at first
                if k != active:
                    t["visible"] = False
                data.append(t)
                owner.append(k)
        titles.append(view_title(scenes))
    if len(meshes):
        data.append(mesh_trace(meshes, half))
        owner.append(None)
        shown.append(True)
    layout = {
        "title": {"text": titles[active], "font": {"size": 13}, "x": 0.01, "xanchor": "left"},
        "scene": scene_layout(views[active][0], grasp.units),
        "legend": {"groupclick": "togglegroup", "itemsizing": "constant"},
        "margin": {"l": 0, "r": 0, "t": 90, "b": 0},
        "uirevision": "keep",  # switching twists keeps the camera
    }
    if len(items) > 1:
        buttons = []
        for k, t in enumerate(items):
            visible = [v if o in (k, None) else False for v, o in zip(shown, owner)]
            buttons.append(
                {"label": t.name, "method": "update", "args": [{"visible": visible}, {"title.text": titles[k]}]}
            )
        layout["updatemenus"] = [
            {"buttons": buttons, "active": active, "x": 1.0, "xanchor": "right", "y": 1.0, "yanchor": "bottom"}
        ]
    return {"data": data, "layout": layout}


# --- pages ---------------------------------------------------------------------

_SCRIPT = """
for (const div of document.querySelectorAll("div.grasptwist-figure")) {
  const figure = JSON.parse(document.getElementById(div.id + "-json").textContent);
  Plotly.newPlot(div, figure);
}
"""


def grasp_page(grasp, *, twists=None, method=None, active=0, path_name=None, samples=None):
    """The sections of a grasp's page ``[(heading, figure)]`` and a :class:`Note` per path it cannot follow.

    The twists' figure first (:func:`twist_figure`, with a URDF hand's link
    meshes: a warning note when they cannot be read), then one animation per
    path (:func:`grasptwist.plot.animation.path_figures`; every path of the
    grasp, or the one called ``path_name``).
    """
    from .animation import path_figures

    meshes, notes = [], []
    if grasp.hand is not None and grasp.hand.source is not None:
        from ..io.urdf_meshes import grasp_folder, hand_meshes
        from ..model import InputError

        try:
            meshes = hand_meshes(grasp.hand, grasp.joint_positions, folder=grasp_folder(grasp))
        except InputError as exc:  # the chains are drawn all the same
            notes.append(Note(f"{exc.file}: warning: no link meshes: {exc.message}", error=False))
    figure = twist_figure(grasp, twists, method=method, active=active, meshes=meshes)
    sections = [(f"{grasp.name}: twists", figure)]
    if grasp.paths or path_name is not None:
        for item in path_figures(grasp, path_name, method=method, samples=samples):
            if isinstance(item, Note):
                notes.append(item)
            else:
                sections.append(item)
    return sections, notes


def write_page(path, sections, *, title: str, js_beside: bool = False) -> Path:
    """Write an HTML page of figures ``[(heading, figure)]`` to ``path``.

    plotly.js goes inside the page, or with ``js_beside`` into
    :data:`JS_NAME` beside it (written once: an up-to-date copy is left
    alone) and the page refers to it.  Each figure's JSON is in an element
    :func:`read_figures` reads back.
    """
    from plotly.offline import get_plotlyjs  # plotly is needed for its plotly.js only

    require_plotly()
    path = Path(path)
    js = get_plotlyjs()
    if js_beside:
        beside = path.parent / JS_NAME
        if not beside.is_file() or beside.read_text("utf-8") != js:
            beside.write_text(js, "utf-8")
        script = f'<script src="{JS_NAME}"></script>'
    else:
        script = f"<script>{js}</script>"
    body = []
    for n, (heading, figure) in enumerate(sections):
        text = orjson.dumps(figure | {"config": _CONFIG}, option=orjson.OPT_SERIALIZE_NUMPY).decode()
        text = text.replace("</", "<\\/")  # "</" cannot end the element early: JSON reads "<\/" as "</"
        body.append(
            f"<h2>{html.escape(heading)}</h2>\n"
            f'<div id="figure-{n}" class="grasptwist-figure" style="height:85vh"></div>\n'
            f'<script type="application/json" id="figure-{n}-json">{text}</script>'
        )
    path.write_text(
        "<!DOCTYPE html>\n<html><head><meta charset='utf-8'>"
        f"<title>{html.escape(title)}</title>"
        "<style>body{font-family:sans-serif;margin:0 1em}h2{font-size:1.1em;margin:0.6em 0 0}</style>\n"
        f"{script}</head><body>\n" + "\n".join(body) + f"\n<script>{_SCRIPT}</script>\n</body></html>\n",
        "utf-8",
    )
    return path


def read_figures(text: str) -> list[dict]:
    """The figures of a page written by :func:`write_page`, in order.

    >>> read_figures('<script type="application/json" id="figure-0-json">{"data": []}</script>')
    [{'data': []}]
    """
    found = re.findall(r'<script type="application/json" id="figure-\d+-json">(.*?)</script>', text, flags=re.S)
    return [orjson.loads(f) for f in found]


# --- what the plot command does ------------------------------------------------


def html_inputs(
    path: str,
    output,
    *,
    twists=(),
    twist_name: str | None = None,
    method: str | None = None,
    path_name: str | None = None,
    js_beside: bool = False,
    max_bytes=None,
    samples=None,
) -> Iterator[Path | Note]:
    """What ``grasptwist plot PATH -o OUTPUT.html`` (or a folder's ``-o FOLDER``) writes.

    Like :func:`grasptwist.plot.render.render_inputs`, one page per grasp:
    for a file its first grasp into ``output``; for a folder each grasp into
    ``output/<grasp>.html`` (named as :func:`~grasptwist.plot.render.image_paths`
    names them).  Yields each page written and a :class:`Note` for each input
    or path that gives none.
    """
    from .render import chosen_twist

    require_plotly()
    grasps = []
    for item in read_grasps(path, twists, max_bytes):
        if isinstance(item, Note):
            yield item
        else:
            grasps.append(item)
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
        if twist_name is not None and not twists and not os.path.isdir(path):
            active = grasp.twists.index(chosen_twist(grasp, twist_name))
        sections, notes = grasp_page(grasp, method=method, active=active, path_name=path_name, samples=samples)
        yield from notes
        yield write_page(page, sections, title=f"grasptwist: {grasp.name}", js_beside=js_beside)
