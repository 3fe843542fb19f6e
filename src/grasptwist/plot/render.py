"""Drawing a :class:`~grasptwist.plot.scene.Scene` with matplotlib, and the files it goes to.

matplotlib is an optional extra: it is imported only inside the functions
that draw, so ``import grasptwist.plot`` works without it, and
:func:`require_matplotlib` says how to install it.  Drawing uses a ``Figure``
on an Agg canvas, never pyplot, so it runs headless and leaves the caller's
matplotlib backend alone.

:func:`plot_grasp`, :func:`render_grasps` and :func:`render_loaded` take
objects shaped like :class:`~grasptwist.model.Grasp` (``name, contact_names,
points, normals, wrist, twists``) and :class:`~grasptwist.model.Twist`
(``name, screw``).
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..engine.screws import cross, norm, unit
from .scene import GRASP_COLOURS, Scene, check_method, grasp_scene, legend_text

__all__ = [
    "FORMATS",
    "MissingMatplotlib",
    "Note",
    "TwistNotFound",
    "chosen_twist",
    "figure",
    "image_name",
    "image_paths",
    "opened_for_writing",
    "plot_grasp",
    "render",
    "render_grasps",
    "render_loaded",
    "require_matplotlib",
]

#: Image formats, by file suffix.
FORMATS = (".png", ".svg", ".pdf")
INSTALL_HINT = (
    "grasptwist plot needs matplotlib: pip install matplotlib (from a clone of grasptwist: pip install -e '.[plot]')"
)


class MissingMatplotlib(RuntimeError):
    """matplotlib is not installed; the message says how to install it."""


def require_matplotlib():
    """Import and return matplotlib, or raise :class:`MissingMatplotlib`.

    The CLI turns the error into its message and exit status 1.
    """
    try:
        import matplotlib
    except ImportError as exc:
        raise MissingMatplotlib(INSTALL_HINT) from exc
    return matplotlib


# --- files --------------------------------------------------------------------


def opened_for_writing(path):
    """How a picture is written unless the caller says otherwise: ``path`` opened
    for writing in binary (the command line passes its own opener, which replaces
    a file atomically)."""
    return open(path, "wb")  # noqa: SIM115 - a context manager for the caller's `with`


def plot_grasp(
    grasp, path, twist=None, *, twist_name=None, method=None, size=(1400, 700), dpi=100, forces=None, opener=None
) -> Path:
    """Render one grasp and twist to ``path``.

    See :func:`~grasptwist.pictures.grasp_scene` for ``twist``,
    ``twist_name``, ``method`` and ``forces``, and :func:`render` for the rest.
    """
    picture = grasp_scene(grasp, twist, twist_name=twist_name, method=method, forces=forces)
    return render(picture, path, size=size, dpi=dpi, opener=opener)


def image_name(grasp_name: str, twist_name: str | None = None) -> str:
    """The file stem of a picture: ``<grasp>-<twist>``, or ``<grasp>`` without a twist.

    Each name is sanitised to letters, digits, ``.``, ``_`` and ``-`` (any run
    of other characters becomes one ``_``; leading and trailing ``.`` and ``_``
    go, so a name never hides the file or climbs out of the folder).

    >>> image_name("Example 1/b", "spin z"), image_name("../x"), image_name("???")
    ('Example_1_b-spin_z', 'x', 'unnamed')
    """
    safe = [re.sub(r"[^A-Za-z0-9._-]+", "_", str(n)).strip("._") or "unnamed" for n in (grasp_name, twist_name)]
    return safe[0] if twist_name is None else "-".join(safe)


def image_paths(grasps, folder, suffix=".png", *, per_twist=True) -> list[tuple[Path, object, object]]:
    """Where :func:`render_grasps` draws each grasp and twist: ``(path, grasp, twist)``.

    One entry per twist of each grasp, in order, and one with twist None for a
    grasp without twists (or, without ``per_twist``, one per grasp: an HTML
    page shows them all).  Paths are ``folder / (image_name(...) + suffix)``;
    a name already used (ignoring case, for case-insensitive file systems)
    gets ``-2``, ``-3``...
    """
    _check_suffix(suffix, FORMATS + (".html",))
    folder = Path(folder)
    plan, used = [], set()
    for grasp in grasps:
        for twist in (tuple(grasp.twists) if per_twist else ()) or (None,):
            stem = image_name(grasp.name, None if twist is None else twist.name)
            name, n = stem, 1
            while name.lower() in used:
                n += 1
                name = f"{stem}-{n}"
            used.add(name.lower())
            plan.append((folder / (name + suffix), grasp, twist))
    return plan


def render_grasps(
    grasps, folder, *, method=None, suffix=".png", size=(1400, 700), dpi=100, grips=None, opener=None
) -> list[Path]:
    """One image per grasp and twist in ``folder`` (created if missing), named by :func:`image_name`.

    A grasp without twists is drawn with its basis only; ``method`` None picks
    off-tangent for a grasp with a wrist, else tangent; ``grips(grasp)`` gives the grip
    forces to draw (``(3, 3)`` or None); ``opener`` as for :func:`render`.

    Returns
    -------
    list of Path, in the order of ``grasps`` and their twists.
    """
    plan = image_paths(grasps, folder, suffix)
    require_matplotlib()
    Path(folder).mkdir(parents=True, exist_ok=True)
    return [
        plot_grasp(
            grasp, path, twist, method=method, size=size, dpi=dpi, forces=grips(grasp) if grips else None, opener=opener
        )
        for path, grasp, twist in plan
    ]


class TwistNotFound(ValueError):
    """The grasp has no twist of the name asked for."""


def chosen_twist(grasp, name: str | None = None):
    """The twist a single picture shows: the one called ``name``, else the first (None when there are none).

    Raises
    ------
    TwistNotFound
        No twist has that name; the message lists the names there are.
    """
    if name is None:
        return grasp.twists[0] if grasp.twists else None
    for twist in grasp.twists:
        if twist.name == name:
            return twist
    known = ", ".join(t.name for t in grasp.twists) or "none"
    raise TwistNotFound(f"grasp '{grasp.name}' has no twist '{name}' (it has: {known})")


@dataclass(frozen=True)
class Note:
    """A line for standard error: an input or grasp that gives no picture (``error``), or a warning."""

    line: str
    error: bool = True


def render_loaded(
    path: str, output, grasps, *, twist_name: str | None = None, method: str | None = None, grips=None, opener=None
):
    """What ``grasptwist plot PATH -o OUTPUT`` draws of the grasps read from ``PATH``.

    Yields each image written (a :class:`~pathlib.Path`) and a :class:`Note`
    for each grasp that could not be drawn.  Reading ``PATH`` (and reporting
    what could not be read) is the caller's: the command line reads as every
    command does.

    Parameters
    ----------
    path : str
        The grasp file or folder the grasps were read from.
    output : str or Path
        For a folder ``path``, the folder that gets one image per grasp and
        twist (:func:`render_grasps`, named across all the folder's grasps; a
        grasp the method cannot draw gives an error note and the others go on).  For a file, the one image, of its
        first grasp (a warning note when it has more).
    grasps : list of Grasp
        The grasps read, in file order (their twists already replaced by the
        command line's ``--twist``).
    twist_name : str or None
        For a single file, which of its twists to draw (default its first).
    method : ``"off-tangent"``, ``"tangent"`` or None (the default per grasp).
    grips : callable or None
        ``grips(grasp)``: the grip forces ``(3, 3)`` to draw with a grasp's friction cones
        (None: cones only); the command line asks the engine for them.
    opener : callable or None
        How each image file is opened, as for :func:`render`.

    Raises
    ------
    MissingMatplotlib
        Before anything is drawn.
    TwistNotFound, ValueError
        For a single file: no twist called ``twist_name``; an unknown method,
        the off-tangent method without a wrist, or an unsupported suffix.
    """
    require_matplotlib()
    if os.path.isdir(path):
        drawable = []
        for grasp in grasps:
            try:
                check_method(method, grasp.wrist)
                drawable.append(grasp)
            except ValueError as exc:  # off-tangent asked of a grasp without a wrist
                yield Note(f"{grasp.file}: grasp '{grasp.name}': error: {exc}")
        yield from render_grasps(drawable, output, method=method, grips=grips, opener=opener)
    elif grasps:
        grasp = grasps[0]
        if len(grasps) > 1:
            yield Note(f"{path}: warning: drawing the first of its {len(grasps)} grasps, '{grasp.name}'", error=False)
        forces = grips(grasp) if grips else None
        yield plot_grasp(grasp, output, chosen_twist(grasp, twist_name), method=method, forces=forces, opener=opener)


def _check_suffix(suffix: str, formats=FORMATS):
    if suffix.lower() not in formats:
        raise ValueError(f"cannot write {suffix or 'a file without suffix'!r}: use one of {', '.join(formats)}")


# --- drawing (matplotlib, imported here only) ----------------------------------

#: Most columns of the legend under the views, and most ticks along each axis.
LEGEND_COLUMNS, TICKS = 7, 5

# kind -> matplotlib style
_STYLE = {
    "contact": {"color": "black", "marker": "o", "s": 40},
    "wrist": {"color": "tab:purple", "marker": "^", "s": 60},
    "hand-base": {"color": "tab:brown", "marker": "s", "s": 40},
    "normal": {"color": "0.45", "lw": 1.2},
    "tangent-plane": {"color": "tab:cyan", "alpha": 0.25},
    "contact-plane": {"color": "0.6", "alpha": 0.15},
    "sigma-axis": {"color": "tab:blue", "lw": 1.4, "ls": "-"},
    "psi-axis": {"color": "tab:orange", "lw": 1.4, "ls": "-"},
    "theta-axis": {"color": "tab:green", "lw": 1.4, "ls": "-"},
    "twist-axis": {"color": "tab:red", "lw": 2.2, "ls": "--"},
    "twist-translation": {"color": "tab:red", "lw": 2.2},
    "contact-velocity": {"color": "black", "lw": 2.4},
    "sigma-part": {"color": "tab:blue", "lw": 1.4},
    "psi-part": {"color": "tab:orange", "lw": 1.4},
    "theta-part": {"color": "tab:green", "lw": 1.4},
    "joint-axis": {"color": "tab:brown", "lw": 2.0, "ls": "-"},
    "friction-cone": {"color": "tab:olive", "alpha": 0.18},
    "grip-force": {"color": "tab:pink", "lw": 2.6},
    "object": {"color": "tan", "alpha": 0.3},
    "table": {"color": "0.35", "alpha": 0.2},
    "fingertip": {"color": "tab:brown", "alpha": 0.45},
    "beyond": {"color": "tab:purple", "lw": 2.0},
}


def render(scene: Scene, path, *, size=(1400, 700), dpi=100, opener=None) -> Path:
    """Draw ``scene`` to ``path`` in two 3D views side by side.

    The format follows the suffix (``.png``, ``.svg``, ``.pdf``).  Drawing
    uses a ``Figure`` on an Agg canvas, never pyplot, so it works headless and
    leaves the caller's matplotlib backend alone.

    Parameters
    ----------
    scene : Scene
    path : str or Path
    size : (int, int)
        Width and height in pixels (a PNG has exactly this size).
    dpi : float
        Pixels per inch: font sizes are in points, so a higher dpi makes the
        text larger relative to the picture.
    opener : callable or None
        ``opener(path)``: a binary file to write, as a context manager
        (default ``opened_for_writing``; the command line's replaces the
        file atomically when the block ends without an error).

    Returns
    -------
    Path
    """
    path = Path(path)
    _check_suffix(path.suffix)
    fig = figure(scene, size=size, dpi=dpi)
    with (opener or opened_for_writing)(path) as f:
        fig.savefig(f, dpi=dpi, format=path.suffix[1:].lower())
    return path


def figure(scene: Scene, *, size=(1400, 700), dpi=100):
    """The matplotlib ``Figure`` :func:`render` saves: the two views, the title, the legend.

    Its tick labels, axis names, titles and legend do not overlap (``tests/plot``'s
    layout test draws it and compares their boxes).
    """
    require_matplotlib()
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(size[0] / dpi, size[1] / dpi), dpi=dpi)
    FigureCanvasAgg(fig)
    centre, half = scene.bounds()
    for n, (view_name, direction) in enumerate(scene.views or (("view", np.array([0.0, 0.0, 1.0])),)):
        ax = fig.add_subplot(1, len(scene.views or [0]), n + 1, projection="3d")
        _draw(ax, scene, direction, head=0.07 * half)
        for setter, c in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), centre):
            setter(c - half, c + half)
        ax.set_proj_type("ortho")  # lengths compare across the picture
        # a little smaller than the panel: a view from above puts tick labels around the cube's
        # edges, and they must stay off the title above and the legend below
        ax.set_box_aspect((1, 1, 1), zoom=0.95)
        _label_axes(ax, direction)
        elev, azim = _elev_azim(direction)
        ax.view_init(elev=elev, azim=azim)
        ax.set_title(view_name, fontsize=9)
    fig.suptitle(scene.title, fontsize=10)
    handles = [_legend_handle(k, scene.method) for k in scene.kinds()] + _group_handles(scene)
    rows = -(-len(handles) // LEGEND_COLUMNS)  # as few rows as the columns allow, the columns then balanced
    fig.legend(handles=handles, loc="lower center", ncol=-(-len(handles) // rows), fontsize=8, frameon=False)
    fig.subplots_adjust(left=0.0, right=1.0, top=0.9, bottom=0.04 + 0.03 * rows, wspace=0.0)
    return fig


def _draw(ax, scene: Scene, view, head: float):
    """Put every element of ``scene`` on one 3D axes seen along ``view``; arrow heads about ``head`` long."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    for solid in scene.meshes + scene.spheres:  # shaded, so that a translucent body still shows its form
        st = _STYLE[solid.kind]
        vertices, faces = solid.triangles()
        ax.add_collection3d(
            Poly3DCollection(vertices[faces], facecolors=st["color"], alpha=st["alpha"], edgecolor="none", shade=True)
        )
    for p in scene.patches:
        st = _STYLE[p.kind]
        # a cone's patch is a fan from its apex (scene.force_parts), a plane's one polygon
        polygons = (
            [[p.corners[0], a, b] for a, b in zip(p.corners[1:-1], p.corners[2:])]
            if p.kind == "friction-cone"
            else [p.corners]
        )
        ax.add_collection3d(Poly3DCollection(polygons, facecolor=st["color"], alpha=st["alpha"], edgecolor="none"))
    for s in scene.segments:
        st = _STYLE[s.kind]
        ax.plot(*np.transpose([s.start, s.end]), color=st["color"], lw=st["lw"], ls=st["ls"])
        ax.text(*s.end, " " + s.label, color=st["color"], fontsize=8)
    for a in scene.drawn_arrows():
        st = _STYLE[a.kind]
        for line in _arrow_lines(a.origin, a.scale * a.vector, view, head):
            ax.plot(*line.T, color=_colour(a), lw=st["lw"], solid_capstyle="round")
        if a.kind == "beyond":  # what it points to, and how far
            ax.text(*a.origin, a.label + " ", color=st["color"], fontsize=8, ha="right")
    for m in scene.markers:
        st = _STYLE[m.kind]
        ax.scatter(*m.position, color=_colour(m), marker=st["marker"], s=st["s"], depthshade=False)
        ax.text(*m.position, "  " + m.label, color=_colour(m), fontsize=9, fontweight="bold")


def _colour(element) -> str:
    """A marker's or arrow's colour: its grasp's in a picture of several, else its kind's."""
    if element.group is None:
        return _STYLE[element.kind]["color"]
    return GRASP_COLOURS[element.group % len(GRASP_COLOURS)]


def _group_handles(scene: Scene) -> list:
    """The legend's entry of each grasp of a picture of several: its contacts' dot and normals' line."""
    from matplotlib.lines import Line2D

    return [
        Line2D([], [], color=GRASP_COLOURS[k % len(GRASP_COLOURS)], marker="o", lw=1.2, label=text)
        for k, text in enumerate(scene.groups)
    ]


def _arrow_lines(origin, vector, view, head):
    """Shaft and two barbs of an arrow, as ``(2, 3)`` point pairs.

    The barbs lie in the plane facing the camera (``view``), so an arrow is
    never seen edge-on (matplotlib's 3D quiver keeps them in a vertical plane,
    which hides them for horizontal arrows seen from above).
    """
    tip = origin + vector
    length = float(norm(vector))
    h = min(head, 0.4 * length)
    back = vector / length
    side = cross(view, back)
    if float(norm(side)) < 1e-6:  # arrow points at the camera: any side will do
        side = cross(np.eye(3)[np.argmin(np.abs(back))], back)
    side = unit(side)
    barbs = [np.array([tip, tip - h * back + sign * 0.45 * h * side]) for sign in (1, -1)]
    return [np.array([origin, tip])] + barbs


def _label_axes(ax, direction):
    """Name the x, y, z axes, except one seen end-on, whose ticks would pile up; at most
    :data:`TICKS` ticks on each, so that their labels (``-0.025``) do not run together."""
    from matplotlib.ticker import MaxNLocator

    for e, (name, axis) in enumerate(zip("xyz", (ax.xaxis, ax.yaxis, ax.zaxis))):
        axis.set_major_locator(MaxNLocator(TICKS, steps=[1, 2, 2.5, 5, 10]))
        if abs(float(unit(direction)[e])) > 0.95:
            axis.set_ticklabels([])
        else:
            axis.set_label_text(name)


def _legend_handle(kind, method):
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch as PatchArtist

    st = _STYLE[kind]
    text = legend_text(kind, method)
    if "marker" in st:
        return Line2D([], [], color=st["color"], marker=st["marker"], ls="none", label=text)
    if "alpha" in st:
        return PatchArtist(facecolor=st["color"], alpha=max(st["alpha"], 0.4), label=text)
    return Line2D([], [], color=st["color"], lw=st["lw"], ls=st.get("ls", "-"), label=text)


def _elev_azim(direction):
    """matplotlib's ``(elev, azim)`` in degrees for a camera along ``direction``."""
    d = unit(direction)
    return float(np.degrees(np.arcsin(np.clip(d[2], -1, 1)))), float(np.degrees(np.arctan2(d[1], d[0])))
