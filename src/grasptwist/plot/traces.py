"""A :class:`~grasptwist.plot.scene.Scene` as plotly.js traces: plain dicts, no plotly needed.

One trace per kind of element (and per method for a method's own kinds), so
that each is one legend entry the reader can toggle: its points joined with
gaps (``None``) for segments and arrows, a ``mesh3d`` for flat patches, and a
``cone`` per arrow head.  The hover text carries the numbers the scene holds:
a screw axis its pitch and its component's amplitude, an arrow its vector.
No math beyond placing what the scene gives.
"""

from __future__ import annotations

import numpy as np

from ..engine.screws import norm
from .scene import FORCE_KINDS, GRASP_COLOURS, Arrow, Marker, Scene, legend_text

__all__ = ["COMMON_KINDS", "MESH_NAME", "force_traces", "group_traces", "mesh_trace", "scene_traces", "slot_name"]

#: The legend entry of a hand's link meshes.
MESH_NAME = "hand (URDF visual meshes)"

#: Kinds the same whichever method is drawn: shown once for all methods.
COMMON_KINDS = (
    "contact",
    "wrist",
    "hand-base",
    "normal",
    "contact-plane",
    "tangent-plane",
    "twist-axis",
    "twist-translation",
    "contact-velocity",
    "finger-link",
    "joint-axis",
    "object",
    "table",
    "fingertip",
    "beyond",
)

# kind -> plotly colour, line width, dash; matplotlib's tab10 colours, as the static pictures
_STYLE = {
    "contact": ("black", 0, None),
    "wrist": ("#9467bd", 0, None),
    "hand-base": ("#8c564b", 0, None),
    "normal": ("#737373", 3, None),
    "tangent-plane": ("#17becf", 0, None),
    "contact-plane": ("#999999", 0, None),
    "sigma-axis": ("#1f77b4", 4, None),
    "psi-axis": ("#ff7f0e", 4, None),
    "theta-axis": ("#2ca02c", 4, None),
    "twist-axis": ("#d62728", 6, "dash"),
    "twist-translation": ("#d62728", 6, None),
    "contact-velocity": ("black", 6, None),
    "sigma-part": ("#1f77b4", 4, None),
    "psi-part": ("#ff7f0e", 4, None),
    "theta-part": ("#2ca02c", 4, None),
    "joint-axis": ("#8c564b", 6, None),
    "finger-link": ("#c7a17a", 10, None),
    "friction-cone": ("#bcbd22", 0, None),
    "grip-force": ("#e377c2", 6, None),
    "object": ("#d2b48c", 0, None),
    "table": ("#595959", 0, None),
    "fingertip": ("#8c564b", 0, None),
    "beyond": ("#9467bd", 6, None),
}
_DASHED_METHOD = {"tangent": "dot"}  # the tangent method's Sigma axes are the off-tangent's lines: tell them apart
_OPACITY = {
    "tangent-plane": 0.35,
    "contact-plane": 0.2,
    "friction-cone": 0.25,
    "object": 0.35,
    "table": 0.2,
    "fingertip": 0.5,
}
_HEAD = 0.07  # arrow-head length, of the scene's half-width
_HIDDEN = ("sigma-part", "psi-part", "theta-part", "tangent-plane")  # off at first: toggled in the legend


def slot_name(kind: str, method: str | None) -> str:
    """The legend entry of a kind: a method's own kinds are prefixed with the method.

    >>> slot_name("contact", "tangent"), slot_name("sigma-axis", "off-tangent")
    ('contact', 'off-tangent: Σ axis (line p_j p_k)')
    """
    text = legend_text(kind, method or "")
    return text if kind in COMMON_KINDS or method is None else f"{method}: {text}"


def scene_traces(scene: Scene, units: str | None, *, common=True, own=True, half=None) -> dict[str, list[dict]]:
    """The traces of ``scene``, by legend entry (:func:`slot_name`).

    Parameters
    ----------
    scene : Scene
    units : str or None
        Appended to lengths in the hover text.
    common, own : bool
        Include the kinds in :data:`COMMON_KINDS`, and the method's own kinds.
    half : float or None
        The drawing's half-width (arrow heads are a fixed part of it);
        default the scene's own (:meth:`Scene.bounds`).

    Returns
    -------
    dict of str to list of dict
        Each entry one or more plotly.js traces in one legend group, the
        first carrying the legend item.
    """
    half = scene.bounds()[1] if half is None else half
    out = {}
    for kind in scene.kinds():
        if kind in FORCE_KINDS:  # force_traces' own
            continue
        if (kind in COMMON_KINDS and not common) or (kind not in COMMON_KINDS and not own):
            continue
        name = slot_name(kind, scene.method)
        elements = scene.of_kind(kind)
        if kind in {"object", "fingertip"}:
            traces = [mesh_trace([e.triangles() for e in elements], half, name, _STYLE[kind][0], _OPACITY[kind])]
        elif kind.endswith("-part") or kind in {"normal", "contact-velocity", "twist-translation", "beyond"}:
            elements = [a for a in elements if _shown(a, half)]
            traces = _arrows(elements, kind, name, units, half)
        elif kind in {"contact", "wrist", "hand-base"}:
            traces = [_markers(elements, kind, name, units)]
        elif kind.endswith("plane"):
            traces = [_patches(elements, kind, name)]
        else:
            traces = [_segments(elements, kind, name, units, scene.method)]
        if traces:
            traces[0]["showlegend"] = True
            for t in traces:
                t["legendgroup"] = name
                if kind in _HIDDEN:
                    t["visible"] = "legendonly"
            out[name] = traces
    return out


def force_traces(scene: Scene, units: str | None) -> dict[str, list[dict]]:
    """The force side (issue 19): friction cones and grip forces, by legend entry.

    A scene's friction cones (patches of kind ``"friction-cone"``, fans from each apex:
    :func:`~grasptwist.plot.scene.force_parts`) as one mesh, its grip forces (arrows of kind
    ``"grip-force"``) as :func:`scene_traces` draws arrows; nothing for a grasp without a friction.
    """
    half = scene.bounds()[1]
    out = {}
    for kind in FORCE_KINDS:
        elements = scene.of_kind(kind)
        if not elements:
            continue
        name = slot_name(kind, None)
        traces = (
            [_patches(elements, kind, name)] if kind == "friction-cone" else _arrows(elements, kind, name, units, half)
        )
        traces[0]["showlegend"] = True
        for t in traces:
            t["legendgroup"] = name
        out[name] = traces
    return out


def group_traces(scene: Scene, units: str | None, half: float) -> dict[str, list[dict]]:
    """Each grasp of a picture of several (``scene.groups``) as one legend entry in its colour
    (``GRASP_COLOURS``): its contacts, labelled, and its surface normals, drawn as
    :func:`scene_traces` draws the contacts and normals of one grasp."""
    out = {}
    for k, name in enumerate(scene.groups):
        colour = GRASP_COLOURS[k % len(GRASP_COLOURS)]
        elements = scene.of_group(k)
        markers = [e for e in elements if isinstance(e, Marker)]
        arrows = [e for e in elements if isinstance(e, Arrow) and _shown(e, half)]
        traces = [_markers(markers, "contact", name, units, colour)]
        traces += _arrows(arrows, "normal", name, units, half, colour)
        traces[0]["showlegend"] = True
        for t in traces:
            t["legendgroup"] = name
        out[name] = traces
    return out


def mesh_trace(meshes, half, name=MESH_NAME, color="#b0b0b0", opacity=0.5) -> dict:
    """Triangle meshes ``[(vertices (n, 3), faces (m, 3))]`` as one ``mesh3d`` trace, shaded:
    by default a hand's link meshes; a scene's object and fingertips are named by their kind.

    Coordinates are rounded to a millionth of ``half`` (the drawing's
    half-width): invisible, and it halves the page's share of them.
    """
    decimals = 6 - int(np.floor(np.log10(half))) if half > 0 else 6
    vertices = np.round(np.concatenate([v for v, _ in meshes]), decimals)
    offsets = np.cumsum([0] + [len(v) for v, _ in meshes[:-1]])
    faces = np.concatenate([f + o for (_, f), o in zip(meshes, offsets)])
    trace = {"type": "mesh3d", "name": name, "showlegend": True, "legendgroup": name}
    trace.update({c: vertices[:, n].tolist() for n, c in enumerate("xyz")})
    trace.update({c: faces[:, n].tolist() for n, c in enumerate("ijk")})
    trace.update(color=color, opacity=opacity, hoverinfo="name", flatshading=True)
    return trace


def _shown(arrow, half) -> bool:
    return float(norm(arrow.scale * arrow.vector)) > 1e-6 * half


def _fmt(v, units=None) -> str:
    text = "(" + ", ".join(f"{x:.4g}" for x in np.asarray(v, dtype=float).ravel()) + ")"
    return text + (f" {units}" if units else "")


def _base(kind, name, mode) -> dict:
    return {"type": "scatter3d", "mode": mode, "name": name, "hoverinfo": "text", "showlegend": False}


def _markers(markers, kind, name, units, colour=None) -> dict:
    colour = colour or _STYLE[kind][0]
    trace = _base(kind, name, "markers+text")
    trace.update(_xyz([m.position for m in markers]))
    trace["text"] = [m.label for m in markers]
    trace["hovertext"] = [f"{m.label}: {_fmt(m.position, units)}" for m in markers]
    trace["textposition"] = "top center"
    trace["textfont"] = {"color": colour, "size": 14}
    symbol = {"wrist": "diamond", "hand-base": "square"}.get(kind, "circle")
    trace["marker"] = {"color": colour, "size": 6, "symbol": symbol}
    return trace


def _segments(segments, kind, name, units, method) -> dict:
    colour, width, dash = _STYLE[kind]
    if kind == "sigma-axis" and method in _DASHED_METHOD:
        dash = _DASHED_METHOD[method]
    points, hover = [], []
    for s in segments:
        text = s.label
        if s.pitch is not None:
            text += f"<br>pitch {s.pitch:.4g}" + (f" {units}/rad" if units else "")
        if s.amplitude is not None:
            text += f"<br>amplitude {s.amplitude:.4g}"
        points += [s.start, s.end, None]
        hover += [text, text, None]
    trace = _base(kind, name, "lines")
    trace.update(_xyz(points))
    trace["hovertext"] = hover
    trace["line"] = {"color": colour, "width": width} | ({"dash": dash} if dash else {})
    return trace


def _arrows(arrows, kind, name, units, half, colour=None) -> list[dict]:
    """Shafts as one line trace, heads as one cone trace (both in the legend group); ``colour``
    instead of the kind's."""
    if not arrows:
        return []
    own, width, _ = _STYLE[kind]
    colour = colour or own
    points, hover = [], []
    for a in arrows:
        what = "direction" if kind == "normal" else "vector"
        text = f"{a.label}<br>{what} {_fmt(a.vector)}"
        points += [a.origin, a.tip, None]
        hover += [text, text, None]
    shafts = _base(kind, name, "lines+text" if kind == "beyond" else "lines")
    shafts.update(_xyz(points))
    shafts["hovertext"] = hover
    if kind == "beyond":  # what it points to, and how far, at its tail
        shafts["text"] = [t for a in arrows for t in (a.label, "", None)]
        shafts["textposition"] = "bottom center"
        shafts["textfont"] = {"color": colour}
    shafts["line"] = {"color": colour, "width": width}
    tips = np.array([a.tip for a in arrows])
    drawn = np.array([a.scale * a.vector for a in arrows])
    lengths = np.linalg.norm(drawn, axis=1, keepdims=True)
    heads = drawn / lengths * np.minimum(_HEAD * half, 0.4 * lengths)
    cones = {
        "type": "cone",
        "name": name,
        **{c: tips[:, n].tolist() for n, c in enumerate("xyz")},
        **{c: heads[:, n].tolist() for n, c in enumerate("uvw")},
        "anchor": "tip",
        "sizemode": "raw",
        "sizeref": 1,
        "colorscale": [[0, colour], [1, colour]],
        "showscale": False,
        "hoverinfo": "skip",
        "showlegend": False,
    }
    return [shafts, cones]


def _patches(patches, kind, name) -> dict:
    """Every patch of a kind as one mesh, each polygon a fan of triangles from its first corner."""
    corners, i, j, k = [], [], [], []
    for p in patches:
        first = len(corners)
        corners += list(p.corners)
        for c in range(1, len(p.corners) - 1):
            i.append(first)
            j.append(first + c)
            k.append(first + c + 1)
    trace = {"type": "mesh3d", "name": name, "i": i, "j": j, "k": k, "showlegend": False}
    trace.update(_xyz(corners))
    trace.update(color=_STYLE[kind][0], opacity=_OPACITY[kind], hoverinfo="name", flatshading=True)
    return trace


def _xyz(points) -> dict:
    """Columns ``x, y, z`` of a list of ``(3,)`` points, None (a gap in a line) kept."""
    return {c: [None if p is None else float(p[n]) for p in points] for n, c in enumerate("xyz")}
