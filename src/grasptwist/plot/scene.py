"""The picture of a grasp, its basis screw axes and a twist's finger-tip motions, as data.

:func:`scene` (numpy only, no matplotlib) turns a grasp, a twist and a method
into a :class:`Scene`: labelled points, segments (screw axes), arrows (normals
and velocities) and plane patches, each with a *kind* that the renderer
(:mod:`grasptwist.plot.render`) styles and the legend names.  Every number in
it comes from the engine (:mod:`grasptwist.engine.decompose`,
``grasptwist.engine.screws``), so tests check the geometry, not pixels.

Velocity arrows keep their true vectors; the scene also gives the one length
per unit velocity (``Arrow.scale``) that draws them all at a common scale
fitted to the grasp, so their lengths compare with each other.

A scene is framed on its subject, the contacts, the object and the fingertips
(:func:`framed`): what lies farther than :data:`REACH` times the subject's size
is cut at the edge (segments) or becomes an arrow at the edge pointing to it
(a far wrist), so that a far point never shrinks the grasp into a corner.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ..engine.decompose import contact_velocities, decompose_off_tangent, decompose_tangent
from ..engine.degeneracy import NOISE_FLOOR, Status, conditioning_warning, status_message
from ..engine.hands import finger_states
from ..engine.objects import tessellate
from ..engine.screws import J, K, axis_point, cross, dot, field_at, norm, pitch, rigid_motion, unit
from ..model import GraspObject, Shape

__all__ = [
    "KINDS",
    "METHODS",
    "REACH",
    "Arrow",
    "FORCE_KINDS",
    "Marker",
    "Mesh",
    "Patch",
    "Scene",
    "LinePiece",
    "Sphere",
    "check_method",
    "clip_segment",
    "cube_of",
    "edge_arrow",
    "default_method",
    "finger_bases",
    "finger_links",
    "fingertips",
    "force_parts",
    "framed",
    "GRASP_COLOURS",
    "grasp_scene",
    "grasps_scene",
    "joint_segments",
    "legend_text",
    "object_mesh",
    "with_table",
    "reach_box",
    "scene",
]

#: The decompositions a scene can show, as the command line spells them.
METHODS = ("off-tangent", "tangent")

# Lengths drawn relative to the grasp's size (the longest side of the contact triangle).
_AXIS_HALF = 0.9  # half-length of an axis segment: reaches every contact from the centroid
_NORMAL_LEN = 0.25
_PATCH_HALF = 0.15  # half-side of a tangent-plane square
_VELOCITY_LEN = 0.45  # the longest chain of velocity arrows at one contact
_FAR_AXIS = 3.0  # a twist axis further than this from the centroid is not drawn
_JOINT_HALF = 0.12  # half-length of a finger joint's axis segment
_CONE_HEIGHT = 0.3  # a friction cone's height along its normal
_CONE_SIDES = 24  # a cone's rim is drawn as this polygon
_FORCE_LEN = 0.45  # the largest grip force's drawn length
_SPHERE_SEGMENTS = 16  # a fingertip sphere's tessellation (the object engine's segments)

#: What a picture frames: its subject's bounding box (the contacts, the object and the fingertip
#: spheres) grown to this many times its half-width about its centre (so the subject fills at
#: least ``1 / REACH`` of the picture across); anything farther is cut at the edge or pointed at.
REACH = 2.0
_EDGE_ARROW = 0.25  # an arrow to a point beyond the picture: its length, of the picture's half-width
_EDGE_INSET = 0.02  # its tip this far inside the edge, of the half-width
_SAME_PLACE = 0.1  # points beyond the picture this close (of its half-width) share one arrow


# --- scene data ---------------------------------------------------------------


@dataclass(frozen=True)
class Marker:
    """A labelled point, ``position (3,)``; ``group``: the index of its grasp in a picture of
    several (:func:`grasps_scene`), else None."""

    position: np.ndarray
    label: str
    kind: str
    group: int | None = None


@dataclass(frozen=True)
class LinePiece:
    """A straight piece of a line (a screw axis) from ``start`` to ``end``, each ``(3,)``.

    A screw's axis also carries the screw's ``pitch`` and, for a basis screw,
    the ``amplitude`` of its component in the twist (None where that does not apply).
    """

    start: np.ndarray
    end: np.ndarray
    label: str
    kind: str
    pitch: float | None = None
    amplitude: float | None = None

    @property
    def direction(self) -> np.ndarray:
        """``end - start``."""
        return self.end - self.start


@dataclass(frozen=True)
class Arrow:
    """An arrow carrying ``vector (3,)`` at ``origin (3,)``, drawn to ``origin + scale * vector``.

    For velocities ``vector`` is the true velocity and ``scale`` the scene's
    drawing length per unit velocity; for normals ``scale`` is their drawn length.
    ``group``: the index of its grasp in a picture of several, else None.
    """

    origin: np.ndarray
    vector: np.ndarray
    label: str
    kind: str
    scale: float = 1.0
    group: int | None = None

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
class Mesh:
    """A triangle mesh (the object): ``vertices (V, 3)`` and ``faces (F, 3)`` int, rows of vertex indices."""

    vertices: np.ndarray
    faces: np.ndarray
    label: str
    kind: str

    def triangles(self) -> tuple[np.ndarray, np.ndarray]:
        """``(vertices, faces)``, as drawn."""
        return self.vertices, self.faces

    def corners(self) -> np.ndarray:
        """The points its bounding box holds, ``(V, 3)``."""
        return self.vertices


@dataclass(frozen=True)
class Sphere:
    """A sphere (a fingertip) of ``radius`` centred at ``centre (3,)``."""

    centre: np.ndarray
    radius: float
    label: str
    kind: str

    def triangles(self, segments: int = _SPHERE_SEGMENTS) -> tuple[np.ndarray, np.ndarray]:
        """``(vertices, faces)``: the object engine's tessellation of a sphere, as drawn."""
        pose = np.eye(4)
        pose[:3, 3] = self.centre
        return tessellate(GraspObject(Shape("sphere", np.array([self.radius])), pose), segments=segments)

    def corners(self) -> np.ndarray:
        """The two opposite corners of its bounding box, ``(2, 3)``."""
        return self.centre + np.array([[-1.0], [1.0]]) * self.radius


@dataclass(frozen=True)
class Scene:
    """Everything a picture of one grasp and twist shows, as plain data.

    Attributes
    ----------
    title : str
        Grasp name, twist, method and amplitudes (or the status message), one
        item a line.
    method : str
        ``"off-tangent"`` or ``"tangent"``; ``""`` for a picture of several grasps (no basis).
    status : int
        The engine's :class:`~grasptwist.engine.degeneracy.Status` for this grasp
        and method; when not 0 the scene has no basis axes or components.
    markers, segments, arrows, patches : tuple
        The drawn elements; see :data:`KINDS` for their kinds.
    views : tuple of (str, (3,) array)
        Named unit directions from the scene towards the camera: an oblique
        view, then one looking down the normal of the contacts' plane.
    meshes, spheres : tuple
        The object (a :class:`Mesh`, in the grasp's frame) and the fingertips (:class:`Sphere`).
    extent : ((3,) array, float) or None
        The cube the picture shows, centre and half-width (:func:`framed`); None: not framed.
    groups : tuple of str
        A picture of several grasps (:func:`grasps_scene`): each grasp's legend text; the
        elements of grasp ``k`` have ``group`` ``k``.  Empty for one grasp.
    """

    title: str
    method: str
    status: int
    markers: tuple[Marker, ...] = ()
    segments: tuple[LinePiece, ...] = ()
    arrows: tuple[Arrow, ...] = ()
    patches: tuple[Patch, ...] = ()
    views: tuple[tuple[str, np.ndarray], ...] = field(default=())
    meshes: tuple[Mesh, ...] = ()
    spheres: tuple[Sphere, ...] = ()
    extent: tuple[np.ndarray, float] | None = None
    groups: tuple[str, ...] = ()

    def elements(self) -> tuple:
        """Every element, in drawing order."""
        return self.meshes + self.spheres + self.markers + self.segments + self.arrows + self.patches

    def of_kind(self, kind: str) -> list:
        """Every element of the given kind, in drawing order."""
        return [e for e in self.elements() if e.kind == kind]

    def drawn_arrows(self) -> list[Arrow]:
        """The arrows long enough to see (a zero amplitude gives a zero part)."""
        tiny = 1e-6 * self.bounds()[1]
        return [a for a in self.arrows if float(norm(a.scale * a.vector)) > tiny]

    def kinds(self) -> list[str]:
        """The kinds drawn, in :data:`KINDS` order (the legend's order), but for those of a grasp
        of a picture of several (the legend names the grasps instead: ``groups``)."""
        drawn = [e for e in self.elements() if not isinstance(e, Arrow)] + self.drawn_arrows()
        present = {e.kind for e in drawn if getattr(e, "group", None) is None}
        return [k for k in KINDS if k in present]

    def of_group(self, group: int) -> list:
        """Every element of the grasp ``group`` of a picture of several, in drawing order."""
        return [e for e in self.elements() if getattr(e, "group", None) == group]

    def points(self) -> np.ndarray:
        """Every drawn point ``(n, 3)``: markers, ends of segments and arrows, corners of patches,
        mesh vertices and the corners of the spheres' boxes."""
        pts = [m.position[None] for m in self.markers]
        pts += [np.array([s.start, s.end]) for s in self.segments]
        pts += [np.array([a.origin, a.tip]) for a in self.arrows]
        pts += [p.corners for p in self.patches] + [m.corners() for m in self.meshes + self.spheres]
        return np.concatenate([np.reshape(p, (-1, 3)) for p in pts] or [np.zeros((0, 3))]).astype(float)

    def bounds(self):
        """Centre ``(3,)`` and half-width of the cube the picture shows: its ``extent``
        when framed, else a cube holding every drawn point.

        A cube, so that the renderer's axes get equal scales.
        """
        return self.extent if self.extent is not None else cube_of(self.points())


#: Every element kind and its legend text, in legend order.
KINDS = {
    "contact": "contact",
    "wrist": "wrist c",
    "hand-base": "finger base (its first joint)",
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
    "joint-axis": "finger joint axis",
    "finger-link": "finger (joint to joint to tip)",
    "friction-cone": "friction cone (half-angle atan μ_i)",
    "grip-force": "grip force f_i",
    "object": "object",
    "table": "table",
    "fingertip": "fingertip sphere",
    "beyond": "beyond the picture (arrow towards it)",
}

#: The force side's kinds (issue 19): drawn when the grasp has a friction.
FORCE_KINDS = ("friction-cone", "grip-force")

#: The colour of each grasp of a picture of several (:func:`grasps_scene`), by its index, in
#: turn: matplotlib's tab10 without its grey, brown and the tan of the object, for both drawings.
GRASP_COLOURS = ("#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#e377c2", "#17becf", "#bcbd22")


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


def check_method(method: str | None, wrist) -> str:
    """The method a picture of a grasp with this ``wrist`` uses: ``method``, or the default.

    Raises
    ------
    ValueError
        An unknown ``method``, or ``"off-tangent"`` with no ``wrist``.

    >>> check_method(None, None)
    'tangent'
    >>> check_method("off-tangent", None)
    Traceback (most recent call last):
    ...
    ValueError: the off-tangent method needs a wrist point; use --method tangent or add a wrist
    """
    method = method or default_method(wrist)
    if method not in METHODS:
        raise ValueError(f"unknown method {method!r}: choose one of {', '.join(METHODS)}")
    if method == "off-tangent" and wrist is None:
        raise ValueError("the off-tangent method needs a wrist point; use --method tangent or add a wrist")
    return method


def scene(
    points,
    normals,
    wrist,
    twist=None,
    *,
    method: str | None = None,
    names=("1", "2", "3"),
    grasp_name: str = "grasp",
    twist_name: str | None = None,
    all_bases: bool = False,
    velocity_scale: float | None = None,
    extent=None,
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
    method : ``"off-tangent"``, ``"tangent"`` or None
        None: off-tangent with a wrist, else tangent.
    names : 3 str
        Contact names, used in labels and the status message.
    grasp_name, twist_name : str
        For the title.
    all_bases : bool
        Draw every screw of the method's basis: with the tangent method its
        ``Sigma_i`` axes too (by default only its ``Theta_i``, since the
        ``Sigma_i`` are the off-tangent method's lines).
    velocity_scale : float or None
        Drawn length per unit velocity of every velocity arrow; None fits it
        to this scene (several scenes drawn together share the smallest).
    extent : ((3,) array, float), None or False
        The cube to show (several scenes drawn together share one); None
        frames the contacts (:func:`framed`); False leaves the scene unframed,
        for a caller that frames several scenes on one cube.

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
        parts, and says why in the title.  Framed by :func:`framed`.

    Raises
    ------
    ValueError
        Unknown method, or the off-tangent method without a wrist.
    """
    picture = _unframed_scene(
        points, normals, wrist, twist, method, names, grasp_name, twist_name, all_bases, velocity_scale
    )
    return picture if extent is False else framed(picture, extent=extent)


def _unframed_scene(points, normals, wrist, twist, method, names, grasp_name, twist_name, all_bases, velocity_scale):
    """:func:`scene`'s elements, every one where it is (not yet framed)."""
    method = check_method(method, wrist)
    points = np.asarray(points, dtype=float)
    normals = np.asarray(normals, dtype=float)
    wrist = None if wrist is None else np.asarray(wrist, dtype=float)
    names = tuple(str(n) for n in names)
    t = np.zeros(6) if twist is None else np.asarray(twist, dtype=float)

    centroid = points.mean(axis=0)
    size = _grasp_size(points)
    if method == "off-tangent":
        r = decompose_off_tangent(points, wrist, t)
        bases = (("sigma", "Σ", r.sigma, r.x), ("psi", "Ψ", r.psi, r.y))
        amplitudes = (("x", r.x), ("y", r.y))
    else:
        r = decompose_tangent(points, normals, t)
        bases = (("theta", "Θ", r.theta, r.alpha),) + ((("sigma", "Σ", r.sigma, r.beta),) if all_bases else ())
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
        for kind, symbol, basis, amplitude in bases:
            for i in range(3):
                axis = _axis_segment(basis[i], centroid, _AXIS_HALF * size, symbol + _sub(names[i]), f"{kind}-axis")
                # an amplitude only means something for a given twist
                segments.append(replace(axis, amplitude=None if twist is None else float(amplitude[i])))

    lines = [f"{grasp_name}" + (f" — {twist_name}" if twist_name else "")]
    notes = []
    if twist is not None:
        lines[0] += f": T = {_vec(t[:3])[:-1]}; {_vec(t[3:])[1:]}"
        twist_element = _twist_element(t, centroid, size)
        if isinstance(twist_element, str):
            notes.append(twist_element)
        elif twist_element is not None:
            (segments if isinstance(twist_element, LinePiece) else arrows).append(twist_element)
        arrows += _velocity_arrows(points, t, r, method, names, size, ok, velocity_scale)
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


# --- framing -------------------------------------------------------------------


def cube_of(points) -> tuple[np.ndarray, float]:
    """Centre ``(3,)`` and half-width of the cube centred on the bounding box of ``points (n, 3)``
    that holds them (half-width 1 for a single point).

    >>> centre, half = cube_of([[0, 0, 0], [2, 1, 0]])
    >>> centre.tolist(), half
    ([1.0, 0.5, 0.0], 1.0)
    """
    pts = np.asarray(points, dtype=float).reshape(-1, 3)
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    half = 0.5 * float(np.max(hi - lo))
    return (lo + hi) / 2, (half if half > 0 else 1.0)


def reach_box(subject, reach: float = REACH) -> tuple[np.ndarray, float]:
    r"""The cube a picture may show around its subject's points ``(n, 3)``: centred on their
    bounding box, ``reach`` times its half-width :math:`h`,

    .. math:: [c - \text{reach}\, h,\; c + \text{reach}\, h]^3,

    so the subject spans at least ``1 / reach`` of it across.

    >>> centre, half = reach_box([[0, 0, 0], [0.06, 0.02, 0]])
    >>> centre.tolist(), round(half, 12)
    ([0.03, 0.01, 0.0], 0.06)
    """
    centre, half = cube_of(subject)
    return centre, reach * half


def clip_segment(start, end, centre, half):
    r"""The piece of the segment from ``start`` to ``end`` (each ``(3,)``) inside the cube of
    ``centre (3,)`` and half-width ``half``, as ``(start, end)``; None when none of it is.

    The points :math:`a + t (b - a)`, :math:`0 \le t \le 1`, inside every slab
    :math:`|x_k - c_k| \le h` (Liang and Barsky's clipping).

    >>> [p.tolist() for p in clip_segment([0, 0, 0], [4, 0, 0], np.zeros(3), 1.0)]
    [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]
    >>> clip_segment([2, 2, 0], [4, 0, 0], np.zeros(3), 1.0) is None
    True
    """
    a, b = np.asarray(start, dtype=float), np.asarray(end, dtype=float)
    d = b - a
    lo, hi = centre - half, centre + half
    with np.errstate(divide="ignore", invalid="ignore"):
        t_lo, t_hi = (lo - a) / d, (hi - a) / d
    inside = (a >= lo) & (a <= hi)  # where d_k = 0 the segment is in the slab or never
    enter = np.where(d == 0, np.where(inside, -np.inf, np.inf), np.minimum(t_lo, t_hi))
    leave = np.where(d == 0, np.where(inside, np.inf, -np.inf), np.maximum(t_lo, t_hi))
    t0, t1 = max(0.0, float(enter.max())), min(1.0, float(leave.min()))
    if t0 > t1 or (t0 == t1 and np.any(d)):
        return None
    return a + t0 * d, a + t1 * d


def edge_arrow(centre, half, target) -> tuple[np.ndarray, np.ndarray, float]:
    r"""An arrow inside the cube of ``centre (3,)`` and half-width ``half`` pointing from its
    centre towards ``target (3,)``, its tip at the cube's edge: ``(origin, direction, length)``.

    The ray :math:`c + t d` leaves the cube at :math:`t_e = h / \max_k |d_k|`; the tip sits
    :data:`_EDGE_INSET` of :math:`h` before it, the arrow is :data:`_EDGE_ARROW` of :math:`h` long.

    >>> origin, d, length = edge_arrow(np.zeros(3), 1.0, [0, 0, 25.0])
    >>> (origin + length * d).tolist(), d.tolist(), length
    ([0.0, 0.0, 0.98], [0.0, 0.0, 1.0], 0.25)
    """
    d = unit(np.asarray(target, dtype=float) - centre)
    tip = centre + (half / float(np.max(np.abs(d))) - _EDGE_INSET * half) * d
    length = _EDGE_ARROW * half
    return tip - length * d, d, length


def framed(picture: Scene, *, extent=None) -> Scene:
    """``picture`` framed on its subject: the contacts, the object and the fingertip spheres.

    Segments are cut to the subject's ``reach_box`` (or to ``extent``, a given cube
    ``(centre, half)``), and dropped when none of them is in it; a marker outside it (a far
    wrist, a finger's base), or a twist axis wholly outside it, becomes an arrow of kind
    ``"beyond"`` at the edge of the picture pointing to it (``edge_arrow``), labelled with its
    distance from the picture's centre (points at one place share an arrow and its label).
    The picture's ``extent`` is then ``extent``, or the cube
    holding everything kept: a far point never shrinks the subject, which spans at least
    ``1 / REACH`` of the picture across.

    >>> contacts = [Marker(np.array([x, 0.0, 0.0]), str(x), "contact") for x in (0, 1)]
    >>> picture = framed(Scene("t", "tangent", 0, markers=(*contacts, Marker(np.array([0.5, 0, 9]), "c", "wrist"))))
    >>> [(a.label, a.tip.tolist()) for a in picture.arrows], picture.bounds()[1]
    ([('c (9 away)', [0.5, 0.0, 0.49])], 0.5)
    """
    if extent is None:
        subject = [m.position[None] for m in picture.of_kind("contact")]
        subject += [m.corners() for m in picture.meshes + picture.spheres]
        box = reach_box(np.concatenate(subject))
    else:
        box = (np.asarray(extent[0], dtype=float), float(extent[1]))
    far, markers, segments = [], [], []
    for m in picture.markers:
        if m.kind == "contact" or np.all(np.abs(m.position - box[0]) <= box[1]):
            markers.append(m)
        else:
            far.append((m.position, m.label))
    for s in picture.segments:
        piece = clip_segment(s.start, s.end, *box)
        if piece is not None:
            segments.append(replace(s, start=piece[0], end=piece[1]))
        elif s.kind == "twist-axis":
            far.append(((s.start + s.end) / 2, s.label))
    kept = replace(picture, markers=tuple(markers), segments=tuple(segments))
    cube = box if extent is not None else cube_of(kept.points())
    beyond = []
    for point, labels in _places(far, _SAME_PLACE * cube[1]):
        origin, d, length = edge_arrow(*cube, point)
        away = float(norm(point - cube[0]))
        beyond.append(Arrow(origin, d, f"{', '.join(labels)} ({away:.3g} away)", "beyond", length))
    return replace(kept, arrows=kept.arrows + tuple(beyond), extent=cube)


def _places(points, tol):
    """``[(point, label)]`` gathered by place: points within ``tol`` of an earlier one (the
    TriFinger's three finger bases at its wrist) share its arrow, their labels in order."""
    places = []
    for point, label in points:
        near = next((p for p in places if float(norm(p[0] - point)) <= tol), None)
        if near is None:
            places.append((point, [label]))
        else:
            near[1].append(label)
    return places


def _velocity_arrows(points, t, r, method, names, size, ok, scale=None):
    """Contact velocities ``T(p_i)`` and, when the basis is sound, their parts chained tip to tail."""
    velocity = contact_velocities(points, t)
    parts = [[] for _ in range(3)]  # per contact: (vector, label, kind)
    if ok and method == "off-tangent":
        sigma_at = field_at(r.sigma, points)  # Sigma_i(p_i)
        psi_at = field_at(r.psi[None, :, :], points[:, None, :])  # [i, j] = Psi_j(p_i)
        for i in range(3):
            at = f"(p{_sub(names[i])})"
            parts[i].append((r.x[i] * sigma_at[i], f"x{_sub(names[i])} Σ{_sub(names[i])}{at}", "sigma-part"))
            for j in (J[i], K[i]):
                parts[i].append((r.y[j] * psi_at[i, j], f"y{_sub(names[j])} Ψ{_sub(names[j])}{at}", "psi-part"))
    elif ok:
        theta_velocity, sigma_velocity = r.contact_split()
        for i in range(3):
            at = f"(p{_sub(names[i])})"
            for j in (J[i], K[i]):
                parts[i].append((theta_velocity[i, j], f"α{_sub(names[j])} Θ{_sub(names[j])}{at}", "theta-part"))
            parts[i].append((sigma_velocity[i], f"β{_sub(names[i])} Σ{_sub(names[i])}{at}", "sigma-part"))
    # One length per unit velocity for every arrow, fitted so that the longest
    # drawn chain at any contact is _VELOCITY_LEN of the grasp's size.
    longest = max(max(norm(velocity)), max((sum(float(norm(v)) for v, _, _ in p) for p in parts), default=0.0))
    if scale is None:
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


def _axis_segment(s, centre, half, label, kind) -> LinePiece:
    """The piece of the axis of screw ``s (6,)`` of half-length ``half``
    centred on the axis point nearest ``centre``."""
    # The axis point nearest the origin, in a frame moved so that `centre` is its origin.
    foot = centre + axis_point(rigid_motion(s, np.eye(3), -centre))
    d = unit(s[:3])
    return LinePiece(foot - half * d, foot + half * d, label, kind, pitch=float(pitch(s)))


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
    size = float(np.max(norm(points - points[list(J)])))
    return size if size > 0 and np.isfinite(size) else 1.0


def _finite(*arrays) -> bool:
    return all(np.all(np.isfinite(a)) for a in arrays)


def _sub(name: str) -> str:
    """A contact name as a subscript: ``1`` stays ``1``, ``thumb`` becomes ``(thumb)``."""
    return name if len(name) <= 2 else f"({name})"


def _vec(a, ref=0.0) -> str:
    """``(a, b, c)`` with 3 significant digits.

    Entries below ``NOISE_FLOOR`` (1e-12) of the largest of ``a`` and ``ref`` are round-off and
    shown as 0 (and ``-0`` as ``0``).

    >>> _vec([1.0, -2e-17, -0.0]), _vec([8e-17, 0, 0], ref=0.6)
    ('(1, 0, 0)', '(0, 0, 0)')
    """
    a = np.asarray(a, dtype=float).ravel()
    a = np.where(np.abs(a) <= NOISE_FLOOR * max(float(np.max(np.abs(a), initial=0.0)), ref), 0.0, a)
    return "(" + ", ".join(f"{x + 0.0:.3g}" for x in a) + ")"


# --- objects from the grasp-file loader ---------------------------------------


def grasp_scene(
    grasp,
    twist=None,
    *,
    twist_name: str | None = None,
    method: str | None = None,
    all_bases=False,
    links=False,
    velocity_scale=None,
    forces=None,
    extent=None,
) -> Scene:
    """:func:`scene` for a loaded ``Grasp``, with its object (translucent, ``object_mesh``),
    its hand's fingertip spheres (``fingertips``) and joint axes (and, with ``links``, its
    fingers' chains from joint to joint to tip), and with a ``friction`` its friction cones and
    the grip ``forces (3, 3)`` given; framed on the contacts, object and fingertips (:func:`framed`).

    ``twist`` is a ``Twist`` (its ``name`` and ``screw`` are used), a ``(6,)``
    array (named ``twist_name``), or None for the grasp and its basis only.
    ``all_bases``, ``velocity_scale`` and ``extent`` are :func:`scene`'s.
    """
    if twist is not None and hasattr(twist, "screw"):
        twist_name = twist_name or twist.name
        twist = twist.screw
    picture = _unframed_scene(
        grasp.points,
        grasp.normals,
        grasp.wrist,
        twist,
        method,
        grasp.contact_names,
        grasp.name,
        twist_name,
        all_bases,
        velocity_scale,
    )
    friction = getattr(grasp, "friction", None)
    if friction is not None:
        cones, arrows = force_parts(grasp.points, grasp.normals, friction, forces, grasp.contact_names)
        picture = replace(picture, patches=picture.patches + cones, arrows=picture.arrows + arrows)
    if getattr(grasp, "object", None) is not None:
        picture = replace(picture, meshes=(object_mesh(grasp.object),))
    if grasp.hand is not None:
        joints = joint_segments(grasp.hand, grasp.joint_positions, _JOINT_HALF * _grasp_size(grasp.points))
        chains = finger_links(grasp.hand, grasp.joint_positions, grasp.points, grasp.contact_names) if links else ()
        tips = fingertips(grasp.hand, grasp.points, grasp.normals, grasp.contact_names)
        bases = finger_bases(grasp.hand, grasp.joint_positions, grasp.contact_names)
        picture = replace(
            picture, markers=picture.markers + bases, segments=picture.segments + joints + chains, spheres=tips
        )
    return picture if extent is False else with_table(framed(picture, extent=extent), grasp)


def with_table(picture: Scene, grasp) -> Scene:
    """A framed ``picture`` with the table of ``grasp``'s environment, a square patch of kind
    ``"table"`` at its height across the picture (none without a table, or one outside the picture).

    >>> from types import SimpleNamespace as G
    >>> from grasptwist.model import Environment
    >>> picture = Scene("t", "tangent", 0, extent=(np.array([0.0, 0, 0.03]), 0.05))
    >>> (table,) = with_table(picture, G(environment=Environment(0.0))).of_kind("table")
    >>> table.corners.tolist()
    [[-0.05, -0.05, 0.0], [0.05, -0.05, 0.0], [0.05, 0.05, 0.0], [-0.05, 0.05, 0.0]]
    """
    env = getattr(grasp, "environment", None)
    if env is None or env.table_height is None or picture.extent is None:
        return picture
    centre, half = picture.extent
    z = float(env.table_height)
    if abs(z - centre[2]) > half:
        return picture
    square = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], float) * half + centre[:2]
    corners = np.column_stack([square, np.full(4, z)])
    return replace(picture, patches=picture.patches + (Patch(corners, f"table z = {z:g}", "table"),))


def grasps_scene(grasps) -> Scene:
    """One picture of several grasps of one object (the grasp file ``synthesize -o`` writes): the
    first grasp's object once (the object engine's triangles, as :func:`grasp_scene` draws it) and
    each grasp's contacts and surface normals.

    Grasp ``k``'s elements have ``group`` ``k`` (drawn in ``GRASP_COLOURS[k]``), its contacts are
    labelled ``k + 1`` and their name, and the legend names it (``groups``, ``"k + 1: name"``); no
    basis, twist or forces, which a picture of one grasp shows.  Seen from the first grasp's views
    (:func:`scene`'s) and framed on the contacts and the object (:func:`framed`).

    >>> from types import SimpleNamespace as G
    >>> ball = GraspObject(Shape("sphere", np.array([1.0])), np.eye(4))
    >>> p = np.array([[1.0, 0, 0], [-0.5, 0.866, 0], [-0.5, -0.866, 0]])
    >>> two = [G(name=n, contact_names=("a", "b", "c"), points=q, normals=-q, wrist=None, object=ball)
    ...        for n, q in (("one", p), ("two", p[:, [0, 2, 1]]))]
    >>> s = grasps_scene(two)
    >>> len(s.meshes), [m.label for m in s.of_kind("contact")][3:], s.groups, s.title
    (1, ['2 a', '2 b', '2 c'], ('1: one', '2: two'), '2 grasps of one sphere: one to two')
    """
    markers, arrows, groups = [], [], []
    for k, grasp in enumerate(grasps):
        points = np.asarray(grasp.points, dtype=float)
        normals = unit(np.asarray(grasp.normals, dtype=float))
        length = _NORMAL_LEN * _grasp_size(points)
        rank = str(k + 1)
        for i, name in enumerate(grasp.contact_names):
            markers.append(Marker(points[i], f"{rank} {name}", "contact", k))
            arrows.append(Arrow(points[i], normals[i], f"{rank} n{_sub(name)}", "normal", length, k))
        groups.append(f"{rank}: {grasp.name}")
    first, last = grasps[0], grasps[-1]
    obj = getattr(first, "object", None)
    picture = Scene(
        title=f"{len(grasps)} grasps of one {obj.shape.kind if obj is not None else 'object'}: "
        f"{first.name} to {last.name}",
        method="",
        status=int(Status.OK),
        markers=tuple(markers),
        arrows=tuple(arrows),
        views=tuple(
            (f"{name} of 1" if n else name, d)
            for n, (name, d) in enumerate(_views(np.asarray(first.points, dtype=float), first.wrist))
        ),
        meshes=(object_mesh(obj),) if obj is not None else (),
        groups=tuple(groups),
    )
    return with_table(framed(picture), first)


def object_mesh(obj) -> Mesh:
    """The object as drawn: the object engine's triangles of it in the grasp's frame
    (``engine.objects.tessellate``, the geometry every other use of it sees).

    >>> box = object_mesh(GraspObject(Shape("box", np.array([1.0, 2.0, 3.0])), np.eye(4)))
    >>> box.faces.shape, box.vertices.max(axis=0).tolist(), box.label
    ((12, 3), [0.5, 1.0, 1.5], 'box')
    """
    vertices, faces = tessellate(obj)
    return Mesh(vertices, faces, obj.shape.kind, "object")


def fingertips(hand, points, normals, names=("1", "2", "3")) -> tuple[Sphere, ...]:
    r"""Each finger's fingertip sphere of radius ``tip_radius`` (those with a radius > 0): centred
    at :math:`p_i - r_i n_i` (the unit normal into the object), touching it at the contact.

    >>> from grasptwist.io.grasp import inline_hand
    >>> h = inline_hand(["a", "b", "c"], [[("j", "revolute", [0, 0, 2], [1, 0, 0], None, 1)]] * 3, None)
    >>> h = replace(h, fingers=tuple(replace(f, tip_radius=0.5) for f in h.fingers))
    >>> tip = fingertips(h, 3 * np.eye(3), -2 * np.eye(3))[0]
    >>> tip.centre.tolist(), tip.radius, tip.label
    ([3.5, 0.0, 0.0], 0.5, 'tip 1')
    """
    n = unit(np.asarray(normals, dtype=float))
    return tuple(
        Sphere(
            np.asarray(points[i], dtype=float) - f.tip_radius * n[i], float(f.tip_radius), f"tip {name}", "fingertip"
        )
        for i, (f, name) in enumerate(zip(hand.fingers, names))
        if f.tip_radius > 0
    )


def force_parts(points, normals, friction, forces=None, names=("1", "2", "3")):
    r"""The friction cones of a grasp and its grip forces, as patches and arrows (geometry only).

    Cone ``i`` has its apex at the contact, its axis along the unit normal ``n_i`` (into the
    object, where a finger's force points) and the half-angle ``atan(mu_i)``: the patch's
    corners are the apex, then a rim of :data:`_CONE_SIDES` points
    ``p_i + h (n_i + mu_i (cos(phi) b_1 + sin(phi) b_2))`` (a fan of triangles from the apex;
    ``h`` a fixed part of the grasp's size).  A frictionless contact (a ray) or an unlimited
    friction (a half-space) has no cone.  ``forces (3, 3)``, computed by the engine, become
    arrows at the contacts with their true vectors, the largest drawn a fixed part of the
    grasp's size (NaN forces: none).

    Returns
    -------
    (tuple of Patch, tuple of Arrow)

    Examples
    --------
    >>> p = np.array([[1.0, 0, 0], [-0.5, 0.866, 0], [-0.5, -0.866, 0]])
    >>> cones, arrows = force_parts(p, -p, 0.5, [[0, 0, 1.0]] * 3)
    >>> c = cones[0].corners
    >>> c[0].tolist(), round(float(np.degrees(np.arctan2(np.linalg.norm(np.cross(c[1] - c[0], -p[0])), (c[1] - c[0]) @ -p[0]))), 6)
    ([1.0, 0.0, 0.0], 26.565051)
    >>> [a.vector.tolist() for a in arrows][0], arrows[0].kind
    ([0.0, 0.0, 1.0], 'grip-force')
    """
    points, normals = np.asarray(points, dtype=float), np.asarray(normals, dtype=float)
    mu = np.broadcast_to(np.asarray(friction, dtype=float), (3,))
    size = _grasp_size(points)
    n = unit(normals)
    helper = np.where(np.abs(n[:, :1]) < 0.9, [[1.0, 0, 0]], [[0.0, 1, 0]])
    b1 = unit(cross(n, helper))
    b2 = cross(n, b1)
    phi = np.linspace(0, 2 * np.pi, _CONE_SIDES, endpoint=False)[:, None]
    h = _CONE_HEIGHT * size
    cones = []
    for i in range(3):
        if not 0 < mu[i] < np.inf:
            continue
        rim = points[i] + h * (n[i] + mu[i] * (np.cos(phi) * b1[i] + np.sin(phi) * b2[i]))
        cones.append(
            Patch(np.vstack((points[i], rim, rim[:1])), f"cone{_sub(names[i])} μ = {mu[i]:g}", "friction-cone")
        )
    arrows = []
    if forces is not None:
        f = np.asarray(forces, dtype=float)
        largest = float(np.max(norm(f))) if np.isfinite(f).all() else 0.0
        if largest > 0:
            arrows = [
                Arrow(points[i], f[i], f"f{_sub(names[i])}", "grip-force", _FORCE_LEN * size / largest)
                for i in range(3)
            ]
    return tuple(c for c in cones if _finite(c.corners)), tuple(arrows)


def finger_links(hand, positions, contacts, names=("1", "2", "3")) -> tuple[LinePiece, ...]:
    """Each finger as its kinematic chain at ``positions``: segments from joint
    to joint, on to the tip link's origin (URDF fingers) and to its contact,
    labelled by that contact's name (``names``), as every output names a finger.

    >>> from grasptwist.io.grasp import inline_hand
    >>> h = inline_hand(["a", "b", "c"], [[("j", "revolute", [0, 0, 2], [1, 0, 0], None, 1)]] * 3, None)
    >>> s = finger_links(h, None, 3 * np.eye(3))[0]  # the joint at (1, 0, 0), its contact at (3, 0, 0)
    >>> s.label, s.start.tolist(), s.end.tolist()
    ('finger 1', [1.0, 0.0, 0.0], [3.0, 0.0, 0.0])
    """
    out = []
    for name, state, contact in zip(names, finger_states(hand, positions), contacts):
        stops = list(state.points) + ([] if state.tip is None else [state.tip[:3, 3]]) + [contact]
        out += [LinePiece(a, b, f"finger {name}", "finger-link") for a, b in zip(stops[:-1], stops[1:])]
    return tuple(out)


def finger_bases(hand, positions, names=("1", "2", "3")) -> tuple[Marker, ...]:
    """Where each finger starts (its first joint's point at ``positions``), labelled by its
    contact's name: the hand's base, pointed at from the picture's edge when it lies beyond.

    >>> from grasptwist.io.grasp import inline_hand
    >>> h = inline_hand(["a", "b", "c"], [[("j", "revolute", [0, 0, 2], [1, 0, 0], None, 1)]] * 3, None)
    >>> b = finger_bases(h, None)[0]
    >>> b.label, b.position.tolist()
    ('base 1', [1.0, 0.0, 0.0])
    """
    states = finger_states(hand, positions)
    return tuple(Marker(s.points[0], f"base {name}", "hand-base") for name, s in zip(names, states) if len(s.points))


def joint_segments(hand, positions, half) -> tuple[LinePiece, ...]:
    """Each finger joint's axis at ``positions``: a segment of half-length ``half``
    through its point (a prismatic joint's along its direction).

    >>> from grasptwist.io.grasp import inline_hand
    >>> h = inline_hand(["a", "b", "c"], [[("j", "revolute", [0, 0, 2], [1, 0, 0], None, 1)]] * 3, None)
    >>> s = joint_segments(h, None, 0.5)[0]
    >>> s.label, s.start.tolist(), s.end.tolist()
    ('j', [1.0, 0.0, -0.5], [1.0, 0.0, 0.5])
    """
    out = []
    for finger, state in zip(hand.fingers, finger_states(hand, positions)):
        for joint, screw, point in zip(finger.joints, state.screws, state.points):
            d = unit(screw[:3] if joint.type == "revolute" else screw[3:])
            out.append(LinePiece(point - half * d, point + half * d, joint.name, "joint-axis"))
    return tuple(out)
