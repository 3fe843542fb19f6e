"""A grasp moving along a path, as a plotly.js animation: a play button and a time slider.

The samples are ``follow``'s (:func:`grasptwist.run.follow.follow_grasp`: the
moved contacts and normals, the instantaneous twist, the hand's integrated
joint positions, and the stretches where a method is degenerate).  Each
sample is one frame, the scenes of the moved grasp under its twist
(:func:`grasptwist.plot.figures.grasp_scenes`); the slider's steps in a
degenerate stretch are marked ``✗`` and the frame's title names the method
and the reason.  Every frame has the same traces in the same order (an
element missing from a frame, like the basis axes of a degenerate grasp, is
an empty trace), and one velocity scale and one cube of axis ranges hold
for the whole path, so nothing jumps but what moves.  The grasp's object
moves with the contacts: at each sample it is carried by the path's pose there.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import replace

import numpy as np

from ..engine.objects import moved
from .figures import framed_together, grasp_scenes, methods_of, scene_layout, velocity_scale_of, view_title
from .traces import force_traces, scene_traces

__all__ = ["DEFAULT_SAMPLES", "degenerate_marks", "hold_marks", "path_figure", "path_figures"]

#: Frames of an animation: follow's default samples over the path, both ends included (a hand's
#: fingers are tracked between samples, which is most of the cost: about 0.3 s a sample).
DEFAULT_SAMPLES = 21
_FRAME_MS = 100  # per frame when playing


def path_figures(grasp, followed, *, method=None) -> Iterator[tuple[str, dict]]:
    """``(heading, figure)`` for each followed path of ``grasp``: ``followed`` holds, per path,
    ``(chunks, summary)`` as :func:`grasptwist.run.follow.follow_grasp` gives them (the command
    line runs it: pictures compute nothing of their own)."""
    for chunks, summary in followed:
        yield f"{grasp.name}: path '{summary.path}'", path_figure(grasp, chunks, summary, method=method)


def path_figure(grasp, chunks, summary, *, method=None) -> dict:
    """The animation of one followed path: ``chunks`` its :class:`~grasptwist.run.follow.Samples`,
    ``summary`` its :class:`~grasptwist.run.follow.Summary`.

    Returns
    -------
    dict
        A plotly.js figure ``{"data", "layout", "frames"}``: one frame per
        sample, named by its index, with the slider's steps in the same order.
    """

    methods = methods_of(grasp, method)
    points = np.concatenate([c.block.points for c in chunks])
    normals = np.concatenate([c.block.normals for c in chunks])
    twists = np.concatenate([c.poses.twist for c in chunks])
    times = np.concatenate([c.poses.time for c in chunks])
    joints = None if grasp.hand is None else np.concatenate([c.joint_positions for c in chunks])
    objects = _moved_objects(grasp.object, chunks)
    moved = [
        replace(
            grasp,
            points=points[k],
            normals=normals[k],
            joint_positions=None if joints is None else joints[k],
            object=objects[k],
        )
        for k in range(len(times))
    ]
    forces = _frame_forces(chunks, len(times))
    fitted = [grasp_scenes(g, t, methods, forces=f, extent=False) for g, t, f in zip(moved, twists, forces)]
    scale = min((s for s in map(velocity_scale_of, fitted) if s is not None), default=None)
    frames_scenes = (
        [grasp_scenes(g, t, methods, scale, f, extent=False) for g, t, f in zip(moved, twists, forces)]
        if scale
        else fitted
    )
    frames_scenes, cube = framed_together(frames_scenes)  # one cube for the whole path
    per_frame = []
    for scenes in frames_scenes:
        traces = scene_traces(scenes[0], grasp.units, own=False, half=cube[1])
        for s in scenes:
            traces.update(scene_traces(s, grasp.units, common=False, half=cube[1]))
        traces.update(force_traces(scenes[0], grasp.units))
        per_frame.append(traces)
    slots = _slots(per_frame)
    marks = degenerate_marks(times, summary.found.crossings)
    dropped = hold_marks(times, summary.cannot_hold or ())
    titles = [
        f"t = {t:.4g}"
        + (f" — degenerate: {'; '.join(m)}" if m else "")
        + (" — cannot hold the weight" if d else "")
        + "<br>"
        + view_title(s)
        for t, m, d, s in zip(times, marks, dropped, frames_scenes)
    ]
    frames = []
    for k, traces in enumerate(per_frame):
        data = [{key: v for key, v in t.items() if key != "visible"} for t in _filled(traces, slots)]
        frames.append({"name": str(k), "data": data, "layout": {"title": {"text": titles[k]}}})
    play = {"frame": {"duration": _FRAME_MS, "redraw": True}, "fromcurrent": True, "transition": {"duration": 0}}
    pause = {"frame": {"duration": 0, "redraw": False}, "mode": "immediate", "transition": {"duration": 0}}
    steps = [
        {
            "label": ("✗ " if m or d else "") + f"{t:.3g}",
            "method": "animate",
            "args": [[str(k)], {"frame": {"duration": 0, "redraw": True}, "mode": "immediate"}],
        }
        for k, (t, m, d) in enumerate(zip(times, marks, dropped))
    ]
    layout = {
        "title": {"text": titles[0], "font": {"size": 13}, "x": 0.01, "xanchor": "left"},
        "scene": scene_layout(frames_scenes[0][0], grasp.units, cube),
        "legend": {"groupclick": "togglegroup", "itemsizing": "constant"},
        "margin": {"l": 0, "r": 0, "t": 110, "b": 0},
        "uirevision": "keep",
        "updatemenus": [
            {
                "type": "buttons",
                "showactive": False,
                "x": 0.0,
                "y": 0.0,
                "xanchor": "right",
                "yanchor": "top",
                "pad": {"t": 50, "r": 10},
                "buttons": [
                    {"label": "▶ play", "method": "animate", "args": [None, play]},
                    {"label": "❚❚ pause", "method": "animate", "args": [[None], pause]},
                ],
            }
        ],
        "sliders": [
            {
                "active": 0,
                "steps": steps,
                "x": 0.0,
                "len": 1.0,
                "pad": {"t": 40},
                "currentvalue": {"prefix": f"path '{summary.path}', t = ", "font": {"size": 12}},
                "transition": {"duration": 0},
            }
        ],
        "annotations": _stretches(summary.found.crossings, summary.cannot_hold or ()),
    }
    return {"data": _filled(per_frame[0], slots), "layout": layout, "frames": frames}


def degenerate_marks(times, crossings) -> list[list[str]]:
    """For each sample time, the degenerate stretches it lies in, as ``"method (code)"``.

    A stretch of zero length (a crossing at an instant) marks the sample nearest it.

    >>> from grasptwist.engine.path import Crossing
    >>> degenerate_marks([0.0, 0.5, 1.0], [Crossing("tangent", "collinear", 0.4, 0.4, -1)])
    [[], ['tangent (collinear)'], []]
    """
    times = np.asarray(times, dtype=float)
    marks = [[] for _ in times]
    for c in crossings:
        inside = np.flatnonzero((times >= c.t_start) & (times <= c.t_end))
        if not len(inside):
            inside = [int(np.argmin(np.abs(times - c.t_start)))]
        for k in inside:
            marks[k].append(f"{c.method} ({c.code})")
    return marks


def hold_marks(times, stretches) -> list[bool]:
    """For each sample time, whether it lies in a ``cannot-hold`` stretch
    (:class:`~grasptwist.engine.forces.hold.HoldStretch`).

    >>> from grasptwist.engine.forces.hold import HoldStretch
    >>> hold_marks([0.0, 0.5, 1.0], [HoldStretch(0.4, 0.9, -1)])
    [False, True, False]
    """
    times = np.asarray(times, dtype=float)
    inside = np.zeros(times.shape, dtype=bool)
    for c in stretches:
        inside |= (times >= c.t_start) & (times <= c.t_end)
    return inside.tolist()


def _moved_objects(obj, chunks) -> list:
    """The grasp's object at each sample, carried by the path's pose there (None: no object)."""
    if obj is None:
        return [None] * sum(len(c) for c in chunks)
    rotation = np.concatenate([c.poses.rotation for c in chunks])
    poses = np.zeros((len(rotation), 4, 4))
    poses[:, :3, :3] = rotation
    poses[:, :3, 3] = np.concatenate([c.poses.position for c in chunks])
    poses[:, 3, 3] = 1.0
    return [moved(obj, pose) for pose in poses]


def _frame_forces(chunks, count) -> list:
    """Each sample's grip forces ``(3, 3)`` from follow's samples (None: no grip there or at all)."""
    if any(c.grip is None for c in chunks):
        return [None] * count
    force = np.concatenate([c.grip.force for c in chunks])
    return [f if np.isfinite(f).all() else None for f in force]


def _stretches(crossings, stretches=()) -> list[dict]:
    """A line under the plot naming each degenerate stretch and each stretch that cannot hold, if any."""
    parts = []
    if crossings:
        parts.append(
            "degenerate: "
            + "; ".join(
                f"{c.method} ({c.code}) at t = {c.t_start:.4g}"
                if c.t_start == c.t_end
                else f"{c.method} ({c.code}) for t in [{c.t_start:.4g}, {c.t_end:.4g}]"
                for c in crossings
            )
        )
    if stretches:
        parts.append(
            "cannot hold the weight: " + "; ".join(f"t in [{c.t_start:.4g}, {c.t_end:.4g}]" for c in stretches)
        )
    if not parts:
        return []
    text = "<br>".join(parts)
    return [{"text": text, "showarrow": False, "xref": "paper", "yref": "paper", "x": 0, "y": 0, "xanchor": "left"}]


def _slots(per_frame) -> dict[str, list[dict]]:
    """Every legend entry of any frame, in first-seen order, with the traces it first had (a template)."""
    slots = {}
    for traces in per_frame:
        for name, t in traces.items():
            slots.setdefault(name, t)
    return slots


def _filled(traces, slots) -> list[dict]:
    """A frame's traces in slot order, an empty trace of the same type where it has none of a slot."""
    out = []
    for name, template in slots.items():
        out += traces.get(name) or [_empty(t) for t in template]
    return out


def _empty(trace) -> dict:
    empty = {k: [] for k in ("x", "y", "z", "u", "v", "w", "i", "j", "k", "text", "hovertext") if k in trace}
    return trace | empty
