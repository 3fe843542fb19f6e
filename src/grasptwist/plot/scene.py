"""Pictures of a grasp, its basis screw axes and the finger-tip motions of a twist.

Two layers, so the geometry can be tested without pixels:

* :func:`scene` (pure numpy, no matplotlib) turns a grasp, a twist and a method
  into a :class:`Scene`: labelled points, segments (screw axes), arrows
  (normals and velocities) and plane patches, each with a *kind* that the
  renderer styles and the legend names.  Everything in it comes from the
  engine (:mod:`grasptwist.engine.decompose`) and :mod:`grasptwist.engine.screws`.
* :func:`render` draws a scene with matplotlib, two 3D views side by side.
  matplotlib is an optional extra: it is imported only inside the functions
  that draw, so ``import grasptwist.plot`` works without it, and
  :func:`require_matplotlib` says how to install it.

:func:`plot_grasp` and :func:`render_grasps` do both for objects shaped like
the grasp-file loader's ``Grasp`` (``name, contact_names, points, normals,
wrist, twists``) and ``Twist`` (``name, screw``).

Velocity arrows keep their true vectors; the scene also gives the one length
per unit velocity (``Arrow.scale``) that draws them all at a common scale
fitted to the grasp, so their lengths compare with each other.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..engine.decompose import contact_velocities, decompose_off_tangent, decompose_tangent
from ..engine.degeneracy import Status, conditioning_warning, status_message
from ..engine.screws import axis_point, cross, dot, field_at, norm, pitch, unit

__all__ = [
    "KINDS",
    "METHODS",
    "Arrow",
    "Marker",
    "MissingMatplotlib",
    "Patch",
    "Scene",
    "Segment",
    "default_method",
    "grasp_scene",
    "legend_text",
    "plot_grasp",
    "render",
    "render_grasps",
    "require_matplotlib",
    "scene",
]

METHODS = ("off-tangent", "tangent")
FORMATS = (".png", ".svg", ".pdf")
INSTALL_HINT = "grasptwist plot needs matplotlib: pip install 'grasptwist[plot]'"

_J = [1, 2, 0]
_K = [2, 0, 1]

# Lengths drawn relative to the grasp's size (the longest side of the contact triangle).
_AXIS_HALF = 0.9  # half-length of an axis segment: reaches every contact from the centroid
_NORMAL_LEN = 0.25
_PATCH_HALF = 0.15  # half-side of a tangent-plane square
_VELOCITY_LEN = 0.45  # the longest chain of velocity arrows at one contact
_FAR_AXIS = 3.0  # a twist axis further than this from the centroid is not drawn


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


# --- scene data ---------------------------------------------------------------


@dataclass(frozen=True)
class Marker:
    """A labelled point, ``position (3,)``."""

    position: np.ndarray
    label: str
    kind: str


@dataclass(frozen=True)
class Segment:
    """A straight piece of a line (a screw axis) from ``start`` to ``end``, each ``(3,)``."""

    start: np.ndarray
    end: np.ndarray
    label: str
    kind: str

    @property
    def direction(self) -> np.ndarray:
        """``end - start``."""
        return self.end - self.start


@dataclass(frozen=True)
class Arrow:
    """An arrow carrying ``vector (3,)`` at ``origin (3,)``, drawn to ``origin + scale * vector``.

    For velocities ``vector`` is the true velocity and ``scale`` the scene's
    drawing length per unit velocity; for normals ``scale`` is their drawn length.
    """

    origin: np.ndarray
    vector: np.ndarray
    label: str
    kind: str
    scale: float = 1.0

    @property
    def tip(self) -> np.ndarray:
        """``origin + scale * vector``."""
        return self.origin + self.scale * self.vector


@dataclass(frozen=True)
class Patch:
    """A flat polygon, ``corners (n, 3)`` in order."""

    corners: np.ndarray
    label: str
    kind: str


@dataclass(frozen=True)
class Scene:
    """Everything a picture of one grasp and twist shows, as plain data.

    Attributes
    ----------
    title : str
        Grasp name, twist, method and amplitudes (or the status message), one
        item a line.
    method : str
        ``"off-tangent"`` or ``"tangent"``.
    status : int
        The engine's :class:`~grasptwist.engine.degeneracy.Status` for this grasp
        and method; when not 0 the scene has no basis axes or components.
    markers, segments, arrows, patches : tuple
        The drawn elements; see :data:`KINDS` for their kinds.
    views : tuple of (str, (3,) array)
        Named unit directions from the scene towards the camera: an oblique
        view, then one looking down the normal of the contacts' plane.
    """

    title: str
    method: str
    status: int
    markers: tuple[Marker, ...] = ()
    segments: tuple[Segment, ...] = ()
    arrows: tuple[Arrow, ...] = ()
    patches: tuple[Patch, ...] = ()
    views: tuple[tuple[str, np.ndarray], ...] = field(default=())

    def of_kind(self, kind: str) -> list:
        """Every element of the given kind, in drawing order."""
        return [e for e in self.markers + self.segments + self.arrows + self.patches if e.kind == kind]

    def drawn_arrows(self) -> list[Arrow]:
        """The arrows long enough to see (a zero amplitude gives a zero part)."""
        tiny = 1e-6 * self.bounds()[1]
        return [a for a in self.arrows if float(norm(a.scale * a.vector)) > tiny]

    def kinds(self) -> list[str]:
        """The kinds drawn, in :data:`KINDS` order (the legend's order)."""
        present = {e.kind for e in self.markers + self.segments + self.patches + tuple(self.drawn_arrows())}
        return [k for k in KINDS if k in present]

    def bounds(self):
        """Centre ``(3,)`` and half-width of a cube holding every drawn point.

        A cube, so that the renderer's axes get equal scales.
        """
        pts = [m.position for m in self.markers]
        pts += [p for s in self.segments for p in (s.start, s.end)]
        pts += [p for a in self.arrows for p in (a.origin, a.tip)]
        pts += [c for p in self.patches for c in p.corners]
        pts = np.array(pts, dtype=float).reshape(-1, 3)
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        half = 0.5 * float(np.max(hi - lo))
        return (lo + hi) / 2, (half if half > 0 else 1.0)


#: Every element kind and its legend text, in legend order.
KINDS = {
    "contact": "contact",
    "wrist": "wrist c",
    "normal": "surface normal",
    "tangent-plane": "tangent plane",
    "contact-plane": "plane of the contacts",
    "sigma-axis": "Σ axis (line p_j p_k)",
    "psi-axis": "Ψ axis (line c p_i)",
    "theta-axis": "Θ axis (fixes p_i)",
    "twist-axis": "twist axis",
    "twist-translation": "twist (pure translation)",
    "contact-velocity": "contact velocity T(p_i)",
    "sigma-part": "part x_i Σ_i(p_i)",  # β_i Σ_i(p_i) in the tangent method: see legend_text
    "psi-part": "part y_j Ψ_j(p_i)",
    "theta-part": "part α_j Θ_j(p_i)",
}


def legend_text(kind: str, method: str) -> str:
    """The legend's words for a kind; the Sigma parts' amplitude is named by the method.

    >>> legend_text("sigma-part", "tangent")
    'part β_i Σ_i(p_i)'
    """
    if kind == "sigma-part" and method == "tangent":
        return "part β_i Σ_i(p_i)"
    return KINDS[kind]


def default_method(wrist) -> str:
    """``"off-tangent"`` when the grasp has a wrist, else ``"tangent"`` (it needs none).

    >>> default_method(None), default_method([0, 0, 1])
    ('tangent', 'off-tangent')
    """
    return "tangent" if wrist is None else "off-tangent"


def scene(
    points,
    normals,
    wrist,
    twist=None,
    method: str | None = None,
    *,
    names=("1", "2", "3"),
    grasp_name: str = "grasp",
    twist_name: str | None = None,
) -> Scene:
    """The picture of one grasp and twist, as plain data (no matplotlib).

    Parameters
    ----------
    points, normals : (3, 3) arrays
        Contacts and their surface normals (any non-zero length).
    wrist : (3,) array or None
        Needed by the off-tangent method.
    twist : (6,) array ``(omega; v)`` or None
        None draws the grasp and its basis axes only.
    method : ``"off-tangent"``, ``"tangent"`` or None (:func:`default_method`).
    names : 3 str
        Contact names, used in labels and the status message.
    grasp_name, twist_name : str
        For the title.

    Returns
    -------
    Scene
        Contacts, wrist, normals, tangent-plane squares and the contacts'
        triangle; the axes of the method's basis (``Sigma_i``, ``Psi_i`` or
        ``Theta_i``), each a segment centred on the axis point nearest the
        contacts' centroid; the twist's axis (or its direction when it is a
        pure translation); each contact's velocity ``T(p_i)`` and, chained
        tip to tail from the contact so that they end where ``T(p_i)`` does,
        the parts that make it up: off-tangent ``x_i Sigma_i(p_i)`` and
        ``y_j Psi_j(p_i)`` (``j != i``); tangent ``alpha_j Theta_j(p_i)``
        (``j != i``) and ``beta_i Sigma_i(p_i)``.  A grasp degenerate for the
        method keeps its contacts and velocities, loses its basis axes and
        parts, and says why in the title.

    Raises
    ------
    ValueError
        Unknown method, or the off-tangent method without a wrist.
    """
    method = method or default_method(wrist)
    if method not in METHODS:
        raise ValueError(f"unknown method {method!r}: choose one of {', '.join(METHODS)}")
    if method == "off-tangent" and wrist is None:
        raise ValueError("the off-tangent method needs a wrist point; use --method tangent or add a wrist")
    points = np.asarray(points, dtype=float)
    normals = np.asarray(normals, dtype=float)
    wrist = None if wrist is None else np.asarray(wrist, dtype=float)
    names = tuple(str(n) for n in names)
    t = np.zeros(6) if twist is None else np.asarray(twist, dtype=float)

    centroid = points.mean(axis=0)
    size = _grasp_size(points)
    if method == "off-tangent":
        r = decompose_off_tangent(points, wrist, t)
        bases = (("sigma", "Σ", r.sigma), ("psi", "Ψ", r.psi))
        amplitudes = (("x", r.x), ("y", r.y))
    else:
        r = decompose_tangent(points, normals, t)
        bases = (("theta", "Θ", r.theta),)
        amplitudes = (("α", r.alpha), ("β", r.beta))
    ok = int(r.status) == Status.OK

    markers = [Marker(points[i], names[i], "contact") for i in range(3)]
    if wrist is not None:
        markers.append(Marker(wrist, "c", "wrist"))
    arrows = [Arrow(points[i], unit(normals[i]), f"n{_sub(names[i])}", "normal", _NORMAL_LEN * size) for i in range(3)]
    patches = [Patch(points, "p1 p2 p3", "contact-plane")]
    patches += [
        Patch(_square(points[i], normals[i], _PATCH_HALF * size), f"Π{_sub(names[i])}", "tangent-plane")
        for i in range(3)
    ]
    segments = []
    if ok:
        for kind, symbol, basis in bases:
            for i in range(3):
                segments.append(
                    _axis_segment(basis[i], centroid, _AXIS_HALF * size, symbol + _sub(names[i]), f"{kind}-axis")
                )

    lines = [f"{grasp_name}" + (f" — {twist_name}" if twist_name else "")]
    notes = []
    if twist is not None:
        lines[0] += f": T = {_vec(t[:3])[:-1]}; {_vec(t[3:])[1:]}"
        twist_element = _twist_element(t, centroid, size)
        if isinstance(twist_element, str):
            notes.append(twist_element)
        elif twist_element is not None:
            (segments if isinstance(twist_element, Segment) else arrows).append(twist_element)
        arrows += _velocity_arrows(points, t, r, method, names, size, ok)
    if ok:
        largest = max(float(np.max(np.abs(a))) for _, a in amplitudes)
        amp = "   ".join(f"{n} = {_vec(a, largest)}" for n, a in amplitudes) if twist is not None else "basis only"
        lines.append(f"{method}: {amp}")
        warning = conditioning_warning(r.conditioning, method)
        if warning:
            notes.append(warning)
    else:
        lines.append(f"{method}: degenerate — {status_message(r.status, r.culprit, names)}")
    return Scene(
        title="\n".join(lines + notes),
        method=method,
        status=int(r.status),
        markers=tuple(markers),
        segments=tuple(s for s in segments if _finite(s.start, s.end)),
        arrows=tuple(a for a in arrows if _finite(a.origin, a.vector)),
        patches=tuple(p for p in patches if _finite(p.corners)),
        views=_views(points, wrist),
    )


def _velocity_arrows(points, t, r, method, names, size, ok):
    """Contact velocities ``T(p_i)`` and, when the basis is sound, their parts chained tip to tail."""
    velocity = contact_velocities(points, t)
    parts = [[] for _ in range(3)]  # per contact: (vector, label, kind)
    if ok and method == "off-tangent":
        sigma_at = field_at(r.sigma, points)  # Sigma_i(p_i)
        psi_at = field_at(r.psi[None, :, :], points[:, None, :])  # [i, j] = Psi_j(p_i)
        for i in range(3):
            at = f"(p{_sub(names[i])})"
            parts[i].append((r.x[i] * sigma_at[i], f"x{_sub(names[i])} Σ{_sub(names[i])}{at}", "sigma-part"))
            for j in (_J[i], _K[i]):
                parts[i].append((r.y[j] * psi_at[i, j], f"y{_sub(names[j])} Ψ{_sub(names[j])}{at}", "psi-part"))
    elif ok:
        theta_velocity, sigma_velocity = r.contact_split()
        for i in range(3):
            at = f"(p{_sub(names[i])})"
            for j in (_J[i], _K[i]):
                parts[i].append((theta_velocity[i, j], f"α{_sub(names[j])} Θ{_sub(names[j])}{at}", "theta-part"))
            parts[i].append((sigma_velocity[i], f"β{_sub(names[i])} Σ{_sub(names[i])}{at}", "sigma-part"))
    # One length per unit velocity for every arrow, fitted so that the longest
    # drawn chain at any contact is _VELOCITY_LEN of the grasp's size.
    longest = max(max(norm(velocity)), max((sum(float(norm(v)) for v, _, _ in p) for p in parts), default=0.0))
    scale = _VELOCITY_LEN * size / longest if longest > 0 else 1.0
    arrows = [Arrow(points[i], velocity[i], f"T(p{_sub(names[i])})", "contact-velocity", scale) for i in range(3)]
    for i in range(3):
        origin = points[i]
        for vector, label, kind in parts[i]:
            arrows.append(Arrow(origin, vector, label, kind, scale))
            origin = origin + scale * vector
    return arrows


def _twist_element(t, centroid, size):
    """The twist's axis as a segment, its direction as an arrow for a pure
    translation, a note when the axis is too far to draw, or None for zero."""
    omega = t[:3]
    if not np.any(omega):
        if not np.any(t[3:]):
            return None
        return Arrow(centroid, unit(t[3:]), "T (translation, pitch ∞)", "twist-translation", 0.5 * size)
    h = float(pitch(t))
    seg = _axis_segment(t, centroid, _AXIS_HALF * size, f"T axis, pitch {h:.3g}", "twist-axis")
    mid = (seg.start + seg.end) / 2
    distance = float(norm(mid - centroid))
    if distance > _FAR_AXIS * size:
        return f"twist axis (pitch {h:.3g}) passes {distance:.3g} from the contacts' centroid: not drawn"
    return seg


def _axis_segment(s, centre, half, label, kind) -> Segment:
    """The piece of the axis of screw ``s (6,)`` of half-length ``half``
    centred on the axis point nearest ``centre``."""
    a = axis_point(s)
    d = unit(s[:3])
    foot = a + dot(centre - a, d) * d
    return Segment(foot - half * d, foot + half * d, label, kind)


def _square(p, n, half):
    """Corners ``(4, 3)`` of a square of half-side ``half`` centred on ``p``, normal to ``n``."""
    n = unit(n)
    # Cross with the coordinate axis least aligned with n, so e1 is never tiny.
    e1 = unit(cross(n, np.eye(3)[np.argmin(np.abs(n))]))
    e2 = cross(n, e1)
    return np.array([p + half * (a * e1 + b * e2) for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1))])


def _views(points, wrist):
    """An oblique view and one down the contacts' plane normal (on the wrist's side).

    The oblique view tilts 50 degrees from the normal towards a direction in
    the plane that leans upwards, so that it shows the plane, what stands off
    it, and some height even when the plane is vertical.
    """
    m = unit(cross(points[1] - points[0], points[2] - points[0]))
    if not np.all(np.isfinite(m)):  # collinear contacts: no plane, look down z
        m = np.array([0.0, 0.0, 1.0])
    if wrist is not None and dot(wrist - points.mean(axis=0), m) < 0:
        m = -m
    z = np.array([0.0, 0.0, 1.0])
    across = cross(m, z)
    if norm(across) > 1e-6:
        up = unit(z - dot(z, m) * m)
        u = np.cos(np.radians(55)) * unit(across) + np.sin(np.radians(55)) * up
    else:  # horizontal plane: matplotlib's default azimuth
        u = np.array([np.cos(np.radians(-60)), np.sin(np.radians(-60)), 0.0])
    tilt = np.radians(50)
    return (("oblique", np.cos(tilt) * m + np.sin(tilt) * u), ("down the contact-plane normal", m))


def _grasp_size(points) -> float:
    """Longest side of the contact triangle (1 if the contacts coincide)."""
    size = float(np.max(norm(points - points[_J])))
    return size if size > 0 and np.isfinite(size) else 1.0


def _finite(*arrays) -> bool:
    return all(np.all(np.isfinite(a)) for a in arrays)


def _sub(name: str) -> str:
    """A contact name as a subscript: ``1`` stays ``1``, ``thumb`` becomes ``(thumb)``."""
    return name if len(name) <= 2 else f"({name})"


def _vec(a, ref=0.0) -> str:
    """``(a, b, c)`` with 3 significant digits.

    Entries below 1e-12 of the largest of ``a`` and ``ref`` are round-off and
    shown as 0 (and ``-0`` as ``0``).

    >>> _vec([1.0, -2e-17, -0.0]), _vec([8e-17, 0, 0], ref=0.6)
    ('(1, 0, 0)', '(0, 0, 0)')
    """
    a = np.asarray(a, dtype=float).ravel()
    a = np.where(np.abs(a) <= 1e-12 * max(float(np.max(np.abs(a), initial=0.0)), ref), 0.0, a)
    return "(" + ", ".join(f"{x + 0.0:.3g}" for x in a) + ")"


# --- objects from the grasp-file loader ---------------------------------------


def grasp_scene(grasp, twist=None, *, twist_name: str | None = None, method: str | None = None) -> Scene:
    """:func:`scene` for a loaded ``Grasp``.

    ``twist`` is a ``Twist`` (its ``name`` and ``screw`` are used), a ``(6,)``
    array (named ``twist_name``), or None for the grasp and its basis only.
    """
    if twist is not None and hasattr(twist, "screw"):
        twist_name = twist_name or twist.name
        twist = twist.screw
    return scene(
        grasp.points,
        grasp.normals,
        grasp.wrist,
        twist,
        method,
        names=grasp.contact_names,
        grasp_name=grasp.name,
        twist_name=twist_name,
    )


def plot_grasp(grasp, path, twist=None, *, twist_name=None, method=None, size=(1400, 700), dpi=100) -> Path:
    """Render one grasp and twist to ``path`` (see :func:`grasp_scene`, :func:`render`)."""
    return render(grasp_scene(grasp, twist, twist_name=twist_name, method=method), path, size=size, dpi=dpi)


def render_grasps(grasps, folder, *, method=None, suffix=".png", size=(1400, 700), dpi=100) -> list[Path]:
    """One image per (grasp, twist) in ``folder`` (created if missing).

    Files are named ``<grasp>-<twist><suffix>`` (``<grasp><suffix>`` for a
    grasp without twists, drawn with its basis only), sanitised to letters,
    digits, ``.``, ``_`` and ``-``; a name already used gets ``-2``, ``-3``...
    ``method`` None picks :func:`default_method` per grasp.

    Returns
    -------
    list of Path, in the order of ``grasps`` and their twists.
    """
    _check_suffix(suffix)
    require_matplotlib()
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    written, used = [], set()
    for grasp in grasps:
        for twist in tuple(grasp.twists) or (None,):
            stem = _safe_name(grasp.name) + ("" if twist is None else "-" + _safe_name(twist.name))
            path = folder / (_unused(stem, used) + suffix)
            written.append(plot_grasp(grasp, path, twist, method=method, size=size, dpi=dpi))
    return written


def _safe_name(name: str) -> str:
    """A file-name-safe form of ``name``.

    >>> _safe_name("Example 1/b: spin z")
    'Example_1_b_spin_z'
    """
    return re.sub(r"[^A-Za-z0-9._-]+", "_", str(name)).strip("._") or "unnamed"


def _unused(stem: str, used: set) -> str:
    """``stem``, or ``stem-2``, ``stem-3``... whichever is not in ``used`` yet (then added)."""
    name, n = stem, 1
    while name.lower() in used:  # lower: case-insensitive file systems
        n += 1
        name = f"{stem}-{n}"
    used.add(name.lower())
    return name


def _check_suffix(suffix: str):
    if suffix.lower() not in FORMATS:
        raise ValueError(f"cannot write {suffix or 'a file without suffix'!r}: use one of {', '.join(FORMATS)}")


# --- rendering (matplotlib, imported here only) -------------------------------

# kind -> matplotlib style
_STYLE = {
    "contact": {"color": "black", "marker": "o", "s": 40},
    "wrist": {"color": "tab:purple", "marker": "^", "s": 60},
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
}


def render(scene: Scene, path, *, size=(1400, 700), dpi=100) -> Path:
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

    Returns
    -------
    Path
    """
    path = Path(path)
    _check_suffix(path.suffix)
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
        ax.set_box_aspect((1, 1, 1), zoom=1.05)
        _label_axes(ax, direction)
        elev, azim = _elev_azim(direction)
        ax.view_init(elev=elev, azim=azim)
        ax.set_title(view_name, fontsize=9)
    fig.suptitle(scene.title, fontsize=10)
    handles = [_legend_handle(k, scene.method) for k in scene.kinds()]
    fig.legend(handles=handles, loc="lower center", ncol=min(len(handles), 7), fontsize=8, frameon=False)
    fig.subplots_adjust(left=0.0, right=1.0, top=0.9, bottom=0.1, wspace=0.0)
    fig.savefig(path, dpi=dpi)
    return path


def _draw(ax, scene: Scene, view, head: float):
    """Put every element of ``scene`` on one 3D axes seen along ``view``; arrow heads about ``head`` long."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    for p in scene.patches:
        st = _STYLE[p.kind]
        ax.add_collection3d(Poly3DCollection([p.corners], facecolor=st["color"], alpha=st["alpha"], edgecolor="none"))
    for s in scene.segments:
        st = _STYLE[s.kind]
        ax.plot(*np.transpose([s.start, s.end]), color=st["color"], lw=st["lw"], ls=st["ls"])
        ax.text(*s.end, " " + s.label, color=st["color"], fontsize=8)
    for a in scene.drawn_arrows():
        st = _STYLE[a.kind]
        for line in _arrow_lines(a.origin, a.scale * a.vector, view, head):
            ax.plot(*line.T, color=st["color"], lw=st["lw"], solid_capstyle="round")
    for m in scene.markers:
        st = _STYLE[m.kind]
        ax.scatter(*m.position, color=st["color"], marker=st["marker"], s=st["s"], depthshade=False)
        ax.text(*m.position, "  " + m.label, color=st["color"], fontsize=9, fontweight="bold")


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
    """Name the x, y, z axes, except one seen end-on, whose ticks would pile up."""
    for e, (name, axis) in enumerate(zip("xyz", (ax.xaxis, ax.yaxis, ax.zaxis))):
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
