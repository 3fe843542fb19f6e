"""Figures of a grasp's twists as plain plotly.js dicts (``{"data", "layout"}``), built from the
scenes of :mod:`grasptwist.plot.scene` through :mod:`grasptwist.plot.traces`: no plotly needed.
:mod:`grasptwist.plot.html` puts them in pages, :mod:`grasptwist.plot.animation` in frames."""

from __future__ import annotations

import html

import numpy as np

from .scene import Scene, check_method, default_method, framed, grasp_scene, grasps_scene
from .traces import force_traces, group_traces, mesh_trace, scene_traces, slot_name

__all__ = [
    "bounds",
    "framed_together",
    "grasp_scenes",
    "grasps_figure",
    "methods_of",
    "scene_layout",
    "twist_figure",
    "velocity_scale_of",
    "view_title",
]

_EYE = 1.8  # the camera's distance, in plotly's units of the scene box
# The same whatever the twist: drawn once, shown with every twist (an object's mesh can be large).
_EVERY_TWIST = {slot_name("object", None), slot_name("fingertip", None)}


def methods_of(grasp, method: str | None = None) -> tuple[str, ...]:
    """The methods a view draws: ``method``, else both when the grasp has a wrist, else the tangent one.

    >>> methods_of(type("G", (), {"wrist": None})())
    ('tangent',)
    """
    if method is not None:
        return (check_method(method, grasp.wrist),)
    return ("off-tangent", "tangent") if default_method(grasp.wrist) == "off-tangent" else ("tangent",)


def grasp_scenes(grasp, twist, methods, velocity_scale=None, forces=None, extent=None) -> list[Scene]:
    """One scene per method of ``grasp`` and ``twist``, every basis screw and the hand's fingers in each
    (and with a friction its cones and the grip ``forces`` given), framed as ``extent`` says (:func:`grasp_scene`).

    Without ``velocity_scale`` the scenes are drawn again at the smallest of
    their fitted scales, so that every velocity arrow of a view has one scale.
    """
    scenes = [
        grasp_scene(
            grasp,
            twist,
            method=m,
            all_bases=True,
            links=True,
            velocity_scale=velocity_scale,
            forces=forces,
            extent=extent,
        )
        for m in methods
    ]
    shared = velocity_scale_of(scenes) if velocity_scale is None and len(scenes) > 1 else None
    if shared is not None:  # None: no arrow drawn (a zero twist), nothing to share
        return grasp_scenes(grasp, twist, methods, shared, forces, extent)
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


def framed_together(views) -> tuple[list[list[Scene]], tuple[np.ndarray, float]]:
    """Unframed scenes (lists of them) framed on one cube, the smallest holding each one's own
    frame (:func:`~grasptwist.plot.scene.framed`), so that switching between them, or playing
    them, keeps the picture still: the framed scenes, in the same lists, and the cube."""
    cube = bounds([framed(s) for v in views for s in v])
    return [[framed(s, extent=cube) for s in v] for v in views], cube


def view_title(scenes) -> str:
    """The first scene's title line, then each method's line(s), as plotly's ``<br>``-separated text."""
    lines = scenes[0].title.split("\n")[:1] + [line for s in scenes for line in s.title.split("\n")[1:]]
    return "<br>".join(html.escape(line, quote=False) for line in lines)


def bounds(scenes) -> tuple[np.ndarray, float]:
    """Centre and half-width of a cube holding every scene's (each scene's framed cube)."""
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


def grasps_figure(grasps) -> dict:
    """The figure of several grasps of one object (``grasps_scene``): the object, and each grasp's
    contacts and normals as one legend entry in its colour (``GRASP_COLOURS``), on the picture's cube.

    Returns
    -------
    dict
        A plotly.js figure ``{"data", "layout"}``.
    """
    picture = grasps_scene(grasps)
    units = grasps[0].units
    cube = picture.bounds()
    traces = scene_traces(picture, units, half=cube[1]) | group_traces(picture, units, cube[1])
    layout = _layout(view_title([picture]), picture, units, cube)
    return {"data": [t for group in traces.values() for t in group], "layout": layout}


def _layout(title: str, scene: Scene, units: str | None, cube) -> dict:
    """A figure's layout: its title, the 3D scene on ``cube`` (:func:`scene_layout`), its legend."""
    return {
        "title": {"text": title, "font": {"size": 13}, "x": 0.01, "xanchor": "left"},
        "scene": scene_layout(scene, units, cube),
        "legend": {"groupclick": "togglegroup", "itemsizing": "constant"},
        "margin": {"l": 0, "r": 0, "t": 90, "b": 0},
    }


def twist_figure(grasp, twists=None, *, method: str | None = None, active: int = 0, meshes=(), forces=None) -> dict:
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
        The hand's link meshes (a URDF hand's, as the ``plot`` command reads
        them), one legend entry shown with every twist (cut at the picture's
        cube, which frames the object and the contacts).
    forces : (3, 3) array or None
        The grip forces drawn with a grasp's friction cones (the engine's, from the caller).

    Returns
    -------
    dict
        A plotly.js figure ``{"data", "layout"}``: for each twist its traces
        (only the active twist's visible), and with several twists a
        dropdown whose buttons show one twist's traces each.
    """
    methods = methods_of(grasp, method)
    items = list(grasp.twists if twists is None else twists) or [None]
    views, cube = framed_together([grasp_scenes(grasp, t, methods, forces=forces, extent=False) for t in items])
    half = cube[1]
    data, owner, shown, titles = [], [], [], []
    for k, scenes in enumerate(views):
        for name, traces in view_traces(scenes, grasp.units, half).items():
            if name in _EVERY_TWIST and k:
                continue
            for t in traces:
                shown.append(t.get("visible", True))  # True, or "legendonly" for the kinds off at first
                if k != active and name not in _EVERY_TWIST:
                    t["visible"] = False
                data.append(t)
                owner.append(None if name in _EVERY_TWIST else k)
        titles.append(view_title(scenes))
    if len(meshes):
        data.append(mesh_trace(meshes, half))
        owner.append(None)
        shown.append(True)
    # switching twists keeps the camera
    layout = _layout(titles[active], views[active][0], grasp.units, cube) | {"uirevision": "keep"}
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
