r"""The solid a triangle mesh bounds, by its generalized winding number; its outer surface and mass properties.

A mesh as it comes (open, with slits, self-intersecting, made of overlapping pieces) bounds
the solid where its generalized winding number is above 1/2 (Jacobson, Kavan and
Sorkine-Hornung 2013; libigl's fast evaluation, Barill et al. 2018):

.. math::

    w(q) = \frac{1}{4\pi} \sum_f \Omega_f(q), \qquad S = \{q : w(q) > 1/2\}

with :math:`\Omega_f(q)` the signed solid angle face :math:`f` subtends at :math:`q`.  On a
closed, consistently wound mesh :math:`w` is 1 inside and 0 outside (the mesh's own solid);
over a hole it falls to 1/2 across the hole's span, and pieces that overlap add up (their
union).

The surface a finger may touch is the solid's outer boundary.  A face is tested just off each
side, at :data:`SIDE_OFFSET` of the mesh's size: with the solid on one side it bounds it (wound
to face away from the solid), on both sides it is internal (a face of a piece inside another
piece), on neither it bounds nothing.  A face partly inside another piece is split in four, and
again where a part is partly inside, :data:`SPLIT_DEPTH` times, each part kept where it bounds the
solid; a part still crossed at the last split is cut along the plane of each face crossing it
(:data:`CUTS` times), and each side kept by its centre: the outer surface follows the pieces'
intersection exactly where they are flat (before, the last split's parts were kept whole by their
centres, up to 1/64 of a face inside).  A piece is the faces joined across edges of two faces
exactly: pieces sharing a vertex or an edge (a file's equal vertices merged) stay apart.  A connected
part of that surface that encloses a negative volume (faces turned inwards, round a void) is a
cavity, out of reach.  Connected pieces of the mesh that overlap or touch are one body.

A mesh that is closed, consistently wound and made of one piece, or of pieces whose boxes
do not meet, is its own outer surface: nothing is evaluated (and libigl is not needed).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ...extras import require

__all__ = [
    "SIDE_OFFSET",
    "SPLIT_DEPTH",
    "SPLIT_PARTS",
    "CUTS",
    "GAP_BODIES",
    "MOMENT_RAYS",
    "Solid",
    "solid",
    "winding_number",
    "winding_function",
    "moments",
    "surface_moments",
    "components",
    "solid_warnings",
]

#: A face's sides are tested at this fraction of the mesh's size (its bounding box's diagonal)
#: off it: far above round-off (1e-16), far below any wall one would hold (1 mm of a 100 m object).
SIDE_OFFSET = 1e-5

#: A face another piece crosses is split in four, and each part that it crosses again, at most
#: this many times; a part the other piece no longer crosses is kept where it bounds the solid, and
#: at the last split each part still crossed is cut along the crossing faces' planes (:data:`CUTS`).
SPLIT_DEPTH = 6

#: The splitting stops sooner (the parts at that depth cut) where its next
#: depth would hold more parts than this or twice the mesh's faces (a mesh of many pieces that
#: cross along long curves): the time stays a few times the probes' of the faces themselves.
SPLIT_PARTS = 20_000

#: The times a part still crossed is cut along the plane of a face crossing it (:func:`_cut`): a part by a
#: corner where three faces of another piece meet needs three.
CUTS = 4

#: The rays per side of the grid that integrates the solid's mass properties when the mesh is
#: not one closed surface: the volume is then within about 3e-3 of the exact (overlapping boxes').
#: An open mesh, whose winding number is evaluated once a stretch of each ray, takes 3/4 of them
#: (96: the open cylinder's volume within 1.4e-3 in half the time).
MOMENT_RAYS = 128


class Solid(NamedTuple):
    """What a mesh bounds (:func:`solid`).

    Attributes
    ----------
    vertices, faces : numpy.ndarray
        ``(V, 3)`` float, ``(F, 3)`` int: the outer surface, wound counter-clockwise seen from
        outside (cavities and internal faces left out; faces partly inside another piece split).
    body : numpy.ndarray
        ``(F,)`` int: the body each face of the outer surface belongs to, from 0.
    bodies : int
        How many bodies (pieces that neither overlap nor touch).
    gap : float
        The least distance between two bodies (0 with one).
    open_edges : int
        Edges of the given mesh in one face only.
    largest_hole : float
        The largest extent along an axis of the largest loop of open edges (0 closed).
    internal : int
        Faces of the given mesh with the solid on both sides, wholly.
    partly : int
        Faces of the given mesh partly inside the solid (crossed by another piece, the part inside
        left out of the outer surface).
    cavities : int
        Closed parts of the boundary round a void inside the solid.
    loose : int
        Faces with the solid on neither side (bounding nothing).
    closed : bool
        The given mesh is one closed surface (each face bounds the solid, wound outwards, and
        no two meet but along their edges): its outer surface and cavities are its faces, and
        its mass properties follow from the divergence theorem.
    seam : numpy.ndarray
        ``(F,)`` bool: a face of the outer surface with a corner on one of its open edges,
        where the sign of a distance is taken from the winding number.
    source : tuple
        ``(vertices, faces)`` of the given mesh, with the faces that bound the solid wound
        outwards: whose winding number defines it.
    """

    vertices: np.ndarray
    faces: np.ndarray
    body: np.ndarray
    bodies: int
    gap: float
    open_edges: int
    largest_hole: float
    internal: int
    partly: int
    cavities: int
    loose: int
    closed: bool
    seam: np.ndarray
    source: tuple


def winding_number(vertices, faces, points) -> np.ndarray:
    r"""The generalized winding number of the mesh ``vertices (V, 3), faces (F, 3)`` at ``points (N, 3)``: ``(N,)``.

    :math:`w(q) = \frac{1}{4\pi}\sum_f \Omega_f(q)`, libigl's fast evaluation (exact near the
    surface, a Taylor expansion far from it).

    >>> from grasptwist.engine.objects.primitives import triangles
    >>> v, f = triangles("box", [2.0, 2.0, 2.0], 0)
    >>> (winding_number(v, f, np.array([[0.0, 0, 0], [0, 0, 3]])).round(3) + 0.0).tolist()
    [1.0, 0.0]
    """
    igl = require("igl", "a mesh's winding number")
    q = np.ascontiguousarray(points, dtype=float).reshape(-1, 3)
    if not len(q):
        return np.zeros(0)
    return igl.fast_winding_number(
        np.ascontiguousarray(vertices, dtype=float), np.ascontiguousarray(faces, dtype=np.int64), q
    )


def winding_function(vertices, faces):
    """``w(points (N, 3)) -> (N,)``: the mesh's winding number (:func:`winding_number`), for many calls of a
    few points each.  Where every piece of the mesh is closed (each edge once each way), the sum of
    the pieces' whose boxes hold a point (a closed piece's is 0 outside its box), each evaluated alone:
    libigl's evaluation builds its tree over the faces it is given at each call.

    >>> from grasptwist.engine.objects.primitives import triangles
    >>> v, f = triangles("box", [2.0, 2.0, 2.0], 0)
    >>> w = winding_function(np.concatenate([v, v + [1, 0, 0]]), np.concatenate([f, f + len(v)]))
    >>> (w(np.array([[0.5, 0, 0], [3, 0, 0]])).round(3) + 0.0).tolist()
    [2.0, 0.0]
    """
    v, f = np.asarray(vertices, dtype=float), np.asarray(faces, dtype=np.int64)
    if not _open(f)[0]:
        return lambda q: winding_number(v, f, q)
    piece = _face_components(f, len(v))
    count = int(piece.max()) + 1
    corners = v[f]
    lo = np.full((count, 3), np.inf)
    hi = np.full((count, 3), -np.inf)
    np.minimum.at(lo, piece, corners.min(axis=1))
    np.maximum.at(hi, piece, corners.max(axis=1))
    by_piece = np.argsort(piece, kind="stable")
    starts = np.searchsorted(piece[by_piece], np.arange(count + 1))

    def w(q):
        out = np.zeros(len(q))
        held = ((q[:, None] >= lo[None]) & (q[:, None] <= hi[None])).all(axis=2)  # (N, pieces)
        for j in np.flatnonzero(held.any(axis=0)).tolist():
            near = np.flatnonzero(held[:, j])
            out[near] += winding_number(v, f[by_piece[starts[j] : starts[j + 1]]], q[near])
        return out

    return w


def components(n, pairs) -> np.ndarray:
    """Connected components of ``n`` nodes joined by ``pairs (E, 2)``: ``(n,)`` labels, each its least node.

    >>> components(5, np.array([[0, 1], [3, 4], [1, 2]])).tolist()
    [0, 0, 0, 3, 3]
    """
    label = np.arange(n)
    pairs = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    while True:
        low = np.minimum(label[pairs[:, 0]], label[pairs[:, 1]])
        new = label.copy()
        np.minimum.at(new, pairs[:, 0], low)
        np.minimum.at(new, pairs[:, 1], low)
        new = new[new]  # pointer jumping
        if np.array_equal(new, label):
            return label
        label = new


def _face_components(faces, n_vertices):
    """Each face's connected piece (faces sharing a vertex): ``(F,)`` labels 0, 1, ..."""
    f = np.asarray(faces)
    vertex = components(n_vertices, np.concatenate([f[:, [0, 1]], f[:, [1, 2]]]))
    _, label = np.unique(vertex[f[:, 0]], return_inverse=True)
    return label.reshape(-1)


def _pieces(faces):
    """Each face's piece: faces joined across the edges of two faces exactly (``(F,)`` labels 0, 1, ...).  Pieces
    that share only a vertex, or an edge of more than two faces (two boxes with a corner or an edge in common,
    once a file's equal vertices are merged), stay apart: where they cross, their faces are split.

    >>> from grasptwist.engine.objects.primitives import triangles
    >>> v, f = triangles("box", [2.0, 2.0, 2.0], 0)
    >>> w, g = np.concatenate([v, v + 2.0]), np.concatenate([f, f + len(v)])
    >>> g[g == len(v) + int(np.argmin(v.sum(axis=1)))] = int(np.argmax(v.sum(axis=1)))  # the corner (1, 1, 1) shared
    >>> int(_face_components(g, len(w)).max()) + 1, int(_pieces(g).max()) + 1
    (1, 2)
    """
    f = np.asarray(faces, dtype=np.int64)
    _, _, undirected, _ = _edges(f)
    order = np.argsort(undirected, kind="stable")
    _, start, count = np.unique(undirected[order], return_index=True, return_counts=True)
    two = start[count == 2]
    pairs = np.stack([order[two] // 3, order[two + 1] // 3], axis=1)
    _, label = np.unique(components(len(f), pairs), return_inverse=True)
    return label.reshape(-1)


def _edges(faces):
    """Directed edge keys of the faces, the undirected ones and their counts."""
    f = np.asarray(faces, dtype=np.int64)
    n = int(f.max()) + 1
    tail, head = f.reshape(-1), f[:, [1, 2, 0]].reshape(-1)
    undirected = np.minimum(tail, head) * n + np.maximum(tail, head)
    return tail * n + head, head * n + tail, undirected, n


def _open(faces):
    """``(closed, open_edges (k, 2))``: whether each directed edge is there once with its reverse, and the
    undirected edges in one face only."""
    directed, reverse, undirected, n = _edges(faces)
    keys, counts = np.unique(directed, return_counts=True)
    closed = bool((counts == 1).all() and np.array_equal(keys, np.sort(reverse)))
    edge, count = np.unique(undirected, return_counts=True)
    single = edge[count == 1]
    return closed, np.stack([single // n, single % n], axis=1)


def _hole_size(vertices, open_edges):
    """The largest extent (along x, y or z) of the largest loop of open edges (0 without): a round hole's diameter."""
    if not len(open_edges):
        return 0.0
    label = components(len(vertices), open_edges)[open_edges[:, 0]]
    sizes = []
    for loop in np.unique(label):
        corners = vertices[np.unique(open_edges[label == loop])]
        sizes.append(float((corners.max(axis=0) - corners.min(axis=0)).max()))
    return max(sizes)


def _volumes(vertices, faces, part, count):
    """The signed volume each part's faces enclose (tetrahedra to the part's bounding-box centre): ``(count,)``."""
    corners = vertices[faces]
    lo = np.full((count, 3), np.inf)
    hi = np.full((count, 3), -np.inf)
    np.minimum.at(lo, part, corners.min(axis=1))
    np.maximum.at(hi, part, corners.max(axis=1))
    a, b, c = (corners[:, i] - 0.5 * (lo + hi)[part] for i in range(3))
    return np.bincount(part, weights=np.einsum("ij,ij->i", a, np.cross(b, c)) / 6.0, minlength=count)


def _boxes_apart(vertices, faces, piece, count):
    """Whether no two pieces' bounding boxes meet."""
    lo = np.full((count, 3), np.inf)
    hi = np.full((count, 3), -np.inf)
    for i in range(3):
        np.minimum.at(lo, piece, vertices[faces[:, i]])
        np.maximum.at(hi, piece, vertices[faces[:, i]])
    return not len(_meeting(lo, hi)), lo, hi


def _meeting(lo, hi, margin=0.0):
    """The pairs ``(K, 2)``, ``i < j``, of boxes ``lo, hi (P, 3)`` that meet (within ``margin``): sorted along x and
    swept, so that pieces many and apart cost no ``P x P`` table."""
    order = np.argsort(lo[:, 0], kind="stable")
    pairs = []
    for k, i in enumerate(order):
        # the boxes after i in x that start before it ends
        later = order[k + 1 : k + 1 + int(np.searchsorted(lo[order[k + 1 :], 0], hi[i, 0] + margin, side="right"))]
        near = later[((lo[later] <= hi[i] + margin) & (lo[i] <= hi[later] + margin)).all(axis=1)]
        pairs += [(min(i, j), max(i, j)) for j in near.tolist()]
    return np.array(sorted(pairs), dtype=np.int64).reshape(-1, 2)


def _split(corners, depth):
    """Each triangle ``corners (F, 3, 3)`` split ``depth`` times in four: ``(F * 4**depth, 3, 3)``."""
    for _ in range(depth):
        a, b, c = corners[:, 0], corners[:, 1], corners[:, 2]
        ab, bc, ca = (a + b) / 2, (b + c) / 2, (c + a) / 2
        corners = np.stack(
            [np.stack(t, axis=1) for t in ((a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca))], axis=1
        ).reshape(-1, 3, 3)
    return corners


def solid(vertices, faces) -> Solid:
    """The solid of a mesh whose faces have no zero area (:func:`~.checks.repair_mesh`): :class:`Solid`.

    Raises ValueError when no inside can be told (no face has the solid on one side).

    >>> from grasptwist.engine.objects.primitives import triangles
    >>> v, f = triangles("box", [1.0, 1.0, 1.0], 0)
    >>> s = solid(np.concatenate([v, v + [3, 0, 0]]), np.concatenate([f, f + len(v)]))
    >>> s.bodies, s.gap, s.closed, len(s.faces)
    (2, 2.0, True, 24)
    """
    v = np.asarray(vertices, dtype=float)
    f = _oriented(v, np.asarray(faces, dtype=np.int64))
    size = float(np.linalg.norm(v.max(axis=0) - v.min(axis=0)))
    closed, open_edges = _open(f)
    hole = _hole_size(v, open_edges)
    piece = _pieces(f)
    count = int(piece.max()) + 1
    apart, lo, hi = _boxes_apart(v, f, piece, count)
    if closed and apart and (_volumes(v, f, piece, count) > 0).all():
        body = piece
        internal = partly = cavities = loose = 0
        outer_v, outer_f, source_f = v, f, f
    else:
        outer_v, outer_f, body, internal, partly, cavities, loose, source_f, whole = _classify(
            v, f, piece, size, lo, hi, closed
        )
        closed = closed and whole
    bodies = int(body.max()) + 1 if len(body) else 0
    if not len(outer_f):
        raise ValueError(
            "mesh bounds no solid: its winding number is nowhere above 1/2 (a sheet, or faces wound inwards)"
        )
    _, seam_edges = _open(outer_f) if not closed else (True, np.zeros((0, 2), np.int64))
    on_seam = np.zeros(len(outer_v), dtype=bool)
    on_seam[seam_edges.reshape(-1)] = True
    for array in (outer_v, outer_f, body):
        array.setflags(write=False)
    return Solid(
        outer_v,
        outer_f,
        body,
        bodies,
        _gap(outer_v, outer_f, body, bodies),
        len(open_edges),
        hole,
        internal,
        partly,
        cavities,
        loose,
        closed,
        on_seam[outer_f].any(axis=1),
        (v, source_f),
    )


def _oriented(v, f):
    """The faces, where some are wound against their neighbours (an edge run the same way by two),
    wound as their neighbours, each patch turned to enclose a positive volume (libigl's
    ``bfs_orient``); else as given (a cavity's shell, wound inwards, stays so)."""
    directed, _, _, _ = _edges(f)
    if len(np.unique(directed)) == len(directed):
        return f
    igl = require("igl", "a mesh's winding")
    turned, patch = igl.bfs_orient(np.ascontiguousarray(f))
    _, patch = np.unique(patch, return_inverse=True)
    patch = patch.reshape(-1)
    inward = _volumes(v, turned, patch, int(patch.max()) + 1)[patch] < 0
    turned[inward] = turned[inward][:, ::-1]
    return turned


def _classify(v, f, piece, size, lo, hi, closed):
    """The outer surface of a mesh that is not one closed surface of pieces apart (module docstring)."""
    offset = SIDE_OFFSET * size
    corners = v[f]
    partners = _crossings(corners, piece, lo, hi)
    crossed = np.zeros(len(f), dtype=bool)
    crossed[partners[0]] = True
    # a face no other piece crosses is wholly on one side of each: its centre tells
    sides = _judge(v, f, piece, lo, hi, offset, closed)
    front, back = sides(corners.mean(axis=1), _normals(corners), piece)
    whole = (front != back) & ~crossed
    internal = front & back & ~crossed
    loose = ~front & ~back & ~crossed
    # faces that bound the solid wholly, wound to face away from it
    kept = np.where(back[whole][:, None], f[whole], f[whole][:, ::-1])
    pieces = [v[kept]]
    owner = [piece[whole]]
    small, mine, parent = corners[crossed], piece[crossed], np.flatnonzero(crossed)
    inner = [np.zeros(0, np.int64)]  # the crossed faces with a part inside the solid
    for level in range(SPLIT_DEPTH):  # the faces another piece crosses, split where it does
        small, mine, parent = _split(small, 1), np.repeat(mine, 4), np.repeat(parent, 4)
        if level == SPLIT_DEPTH - 1 or 4 * len(small) > max(SPLIT_PARTS, 2 * len(f)):
            break
        fr, bk = sides(small.mean(axis=1), _normals(small), mine)
        again = _crossing_face(small, parent, corners, partners) >= 0
        take = ~again & (fr != bk)
        pieces.append(np.where(bk[take, None, None], small[take], small[take][:, ::-1]))
        owner.append(mine[take])
        inner.append(parent[~again & fr & bk])
        small, mine, parent = small[again], mine[again], parent[again]
    # the last split's parts: those still crossed cut along the planes of the faces crossing them, each part
    # then on one side of every face near it, kept by its centre
    small, mine, parent = _cut(small, parent, corners, partners, mine)
    fr, bk = sides(small.mean(axis=1), _normals(small), mine)
    take = fr != bk
    pieces.append(np.where(bk[take, None, None], small[take], small[take][:, ::-1]))
    owner.append(mine[take])
    inner.append(parent[fr & bk])
    # the source: the faces that bound the solid wound outwards, the others as given
    source = f.copy()
    source[whole] = kept
    owner = np.concatenate(owner)
    outer_v, index = np.unique(np.concatenate(pieces).reshape(-1, 3), axis=0, return_inverse=True)
    outer_f = index.reshape(-1, 3)
    # cavities: closed parts of the boundary enclosing a negative volume
    part = _face_components(outer_f, len(outer_v)) if len(outer_f) else np.zeros(0, np.int64)
    parts = int(part.max()) + 1 if len(part) else 0
    seams = _open(outer_f)[1] if len(outer_f) else np.zeros((0, 2), np.int64)
    on_part = np.zeros(len(outer_v), dtype=np.int64)
    on_part[outer_f.reshape(-1)] = np.repeat(part, 3)
    cavity = _volumes(outer_v, outer_f, part, parts) < 0 if parts else np.zeros(0, dtype=bool)
    cavity[on_part[seams.reshape(-1)]] = False  # an open part encloses nothing
    reach = ~cavity[part] if len(part) else np.zeros(0, dtype=bool)
    joined = np.unique(piece[partners.T], axis=0) if partners.size else np.zeros((0, 2), np.int64)
    body = _bodies(v, f, piece, lo, hi, offset, joined)[owner[reach]]
    _, body = np.unique(body, return_inverse=True)
    used, remap = np.unique(outer_f[reach], return_inverse=True)
    return (
        outer_v[used],
        remap.reshape(-1, 3),
        body.reshape(-1),
        int(internal.sum()),
        len(np.unique(np.concatenate(inner))),
        int(cavity.sum()),
        int(loose.sum()),
        source,
        bool(whole.all()),
    )


def _cut(small, parent, corners, partners, mine):
    """The parts ``small (K, 3, 3)`` of faces ``parent (K,)`` of pieces ``mine (K,)`` cut along the plane of a face
    crossing each, again while one does (:data:`CUTS` times): ``(parts (M, 3, 3), their pieces (M,), their faces
    (M,))``, none of zero area."""
    done, owners, parents = [], [], []
    for _ in range(CUTS):
        if not len(small):
            break
        plane = _crossing_face(small, parent, corners, partners)
        cut = plane >= 0
        done.append(small[~cut])
        owners.append(mine[~cut])
        parents.append(parent[~cut])
        small, parent, mine = small[cut], parent[cut], mine[cut]
        small, k = _cut_by_plane(small, corners[plane[cut]])
        parent, mine = np.repeat(parent, k), np.repeat(mine, k)
    done.append(small)
    owners.append(mine)
    parents.append(parent)
    empty = np.zeros(0, np.int64)
    return (
        np.concatenate([np.zeros((0, 3, 3)), *done]),
        np.concatenate([empty, *owners]),
        np.concatenate([empty, *parents]),
    )


def _crossing_face(small, parent, corners, partners):
    """For each part ``small (K, 3, 3)`` of face ``parent (K,)``, a face of another piece crossing it (-1 none)."""
    first, count = np.unique(partners[0], return_index=True)[1], np.bincount(partners[0], minlength=len(corners))
    start = np.zeros(len(corners), dtype=np.int64)
    start[partners[0][first]] = first
    k = count[parent]
    row = np.repeat(np.arange(len(small)), k)
    other = partners[1][np.repeat(start[parent], k) + np.arange(len(row)) - np.repeat(np.cumsum(k) - k, k)]
    near = (small.min(axis=1)[row] <= corners.max(axis=1)[other]).all(axis=1)
    near &= (corners.min(axis=1)[other] <= small.max(axis=1)[row]).all(axis=1)
    row, other = row[near], other[near]
    out = np.full(len(small), -1, dtype=np.int64)
    hit = _triangles_cross(small[row], corners[other])
    out[row[hit][::-1]] = other[hit][::-1]  # the first crossing face of each
    return out


def _cut_by_plane(t, by):
    """Each triangle ``t (K, 3, 3)`` cut along the plane of ``by (K, 3, 3)`` into three, wound as it (the lone
    corner's side one, the other side two; those of zero area dropped): ``(parts, how many of each (K,))``.

    >>> t = np.array([[[0.0, 0, 0], [2, 0, 0], [0, 2, 0]]])
    >>> parts, k = _cut_by_plane(t, np.array([[[1.0, 0, 0], [1, 1, 0], [1, 0, 1]]]))  # the plane x = 1
    >>> k.tolist(), sorted(round(float(np.linalg.norm(np.cross(p[1] - p[0], p[2] - p[0]))) / 2, 6) for p in parts)
    ([3], [0.5, 0.5, 1.0])
    """
    n = np.cross(by[:, 1] - by[:, 0], by[:, 2] - by[:, 0])
    d = np.einsum("kij,kj->ki", t - by[:, :1], n)  # (K, 3): each corner's side
    s = np.sign(d)
    differs = (s[:, :, None] != s[:, None, :]).sum(axis=2)  # (K, 3): the other corners on another side
    lone = np.argmax(np.where(s != 0, differs, -1), axis=1)
    rows = np.arange(len(t))
    i, j, k = lone, (lone + 1) % 3, (lone + 2) % 3
    a, b, c = t[rows, i], t[rows, j], t[rows, k]
    da, db, dc = d[rows, i], d[rows, j], d[rows, k]
    with np.errstate(invalid="ignore", divide="ignore"):
        pb = a + np.clip(np.nan_to_num(da / (da - db)), 0.0, 1.0)[:, None] * (b - a)
        pc = a + np.clip(np.nan_to_num(da / (da - dc)), 0.0, 1.0)[:, None] * (c - a)
    parts = np.stack([np.stack(x, axis=1) for x in ((a, pb, pc), (pb, b, c), (pb, c, pc))], axis=1)  # (K, 3, 3, 3)
    # a triangle the plane does not cross to round-off (no corner strictly on each side) is kept whole
    uncut = ~((s > 0).any(axis=1) & (s < 0).any(axis=1))
    parts[uncut] = np.stack([t[uncut], t[uncut], t[uncut]], axis=1)
    area = np.linalg.norm(np.cross(parts[:, :, 1] - parts[:, :, 0], parts[:, :, 2] - parts[:, :, 0]), axis=2)
    whole = np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1)
    keep = (area > 1e-12 * whole[:, None]) & ~(uncut[:, None] & (np.arange(3) > 0))
    return parts[keep], keep.sum(axis=1)


def _normals(corners):
    """The unit normals ``(F, 3)`` of the triangles ``corners (F, 3, 3)``."""
    n = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    return n / np.linalg.norm(n, axis=1, keepdims=True)


def _segments_cross(p, q, tri):
    """Whether the segments ``p -> q (N, 3)`` pass through the triangles ``tri (N, 3, 3)``, strictly inside both."""
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
    n = np.cross(b - a, c - a)
    dp = np.einsum("ij,ij->i", p - a, n)
    dq = np.einsum("ij,ij->i", q - a, n)
    meets = dp * dq < 0  # strictly: an edge in another face's plane, or ending on it, is the probes' to judge
    x = p + (dp / np.where(meets, dp - dq, 1.0))[:, None] * (q - p)
    for u, w in ((a, b), (b, c), (c, a)):
        meets &= np.einsum("ij,ij->i", np.cross(w - u, x - u), n) > 0
    return meets


def _triangles_cross(t, s):
    """Whether the triangles ``t (N, 3, 3)`` and ``s (N, 3, 3)`` cross (an edge of one through the other)."""
    out = np.zeros(len(t), dtype=bool)
    for i, j in ((0, 1), (1, 2), (2, 0)):
        out |= _segments_cross(t[:, i], t[:, j], s) | _segments_cross(s[:, i], s[:, j], t)
    return out


def _crossings(corners, piece, lo, hi, chunk=200_000):
    """The pairs of faces of different pieces that cross: ``(2, K)`` int, each pair both ways, sorted by the first.
    Tested ``chunk`` pairs at a time (the memory stays some 100 MB)."""
    flo, fhi = corners.min(axis=1), corners.max(axis=1)
    by_piece = np.argsort(piece, kind="stable")
    starts = np.searchsorted(piece[by_piece], np.arange(len(lo) + 1))
    found = []
    for i, j in _meeting(lo, hi).tolist():
        mine, theirs = by_piece[starts[i] : starts[i + 1]], by_piece[starts[j] : starts[j + 1]]
        a = mine[((flo[mine] <= hi[j]) & (fhi[mine] >= lo[j])).all(axis=1)]
        b = theirs[((flo[theirs] <= hi[i]) & (fhi[theirs] >= lo[i])).all(axis=1)]
        step = max(1, chunk // max(len(b), 1))
        for start in range(0, len(a), step):
            pa = np.repeat(a[start : start + step], len(b))
            pb = np.tile(b, len(pa) // max(len(b), 1))
            meet = (flo[pa] <= fhi[pb]).all(axis=1) & (flo[pb] <= fhi[pa]).all(axis=1)
            pa, pb = pa[meet], pb[meet]
            hit = _triangles_cross(corners[pa], corners[pb])
            found.append(np.stack([pa[hit], pb[hit]]))
    pairs = np.concatenate([np.zeros((2, 0), np.int64), *found, *(x[::-1] for x in found)], axis=1)
    return pairs[:, np.argsort(pairs[0], kind="stable")]


def _judge(v, f, piece, lo, hi, offset, closed):
    """``sides(points (N, 3), normals (N, 3), own (N,)) -> (front, back)``: whether the solid is just in front of
    and just behind each point of a face of piece ``own``, ``offset`` along its unit normal.

    Where every piece is closed (``closed``: each edge once each way), the winding number is the
    pieces' sum, and a piece's own is known off its face: 0 in front and 1 behind (-1 and 0 for a
    piece wound inwards, a cavity's shell); only the pieces whose boxes hold the point are
    evaluated, each alone.  Else the whole mesh's at every point.
    """
    if not closed:

        def sides(points, normals, own):
            w = winding_number(v, f, np.concatenate([points + offset * normals, points - offset * normals]))
            return w[: len(points)] > 0.5, w[len(points) :] > 0.5

        return sides
    count = len(lo)
    by_piece = np.argsort(piece, kind="stable")
    starts = np.searchsorted(piece[by_piece], np.arange(count + 1))
    front_own = -(_volumes(v, f, piece, count) < 0).astype(float)
    pairs = _meeting(lo, hi, offset)
    pairs = np.concatenate([pairs, pairs[:, ::-1]])

    def sides(points, normals, own):
        q = np.concatenate([points + offset * normals, points - offset * normals])
        owner = np.concatenate([own, own])
        w = np.concatenate([front_own[own], front_own[own] + 1.0])
        order = np.argsort(owner, kind="stable")
        at = np.searchsorted(owner[order], np.arange(count + 1))
        for i, j in pairs.tolist():
            mine = order[at[i] : at[i + 1]]
            near = mine[((q[mine] >= lo[j] - offset) & (q[mine] <= hi[j] + offset)).all(axis=1)]
            if len(near):
                w[near] += winding_number(v, f[by_piece[starts[j] : starts[j + 1]]], q[near])
        return w[: len(points)] > 0.5, w[len(points) :] > 0.5

    return sides


def _bodies(v, f, piece, lo, hi, offset, joined):
    """Each piece's body: pieces that cross (``joined (K, 2)``), or whose boxes meet and that touch (a
    vertex within ``offset`` of the other's surface) or overlap (a vertex inside the other) are one."""
    count = int(piece.max()) + 1
    pairs = [tuple(p) for p in joined.tolist()]
    known = set(pairs)
    for i, j in _meeting(lo, hi, offset).tolist():
        if (i, j) not in known and _meet(v, f, piece, i, j, offset):
            pairs.append((i, j))
    return components(count, np.array(pairs, dtype=np.int64).reshape(-1, 2))


def _meet(v, f, piece, i, j, offset):
    """Whether piece ``i`` and piece ``j`` touch or overlap (by their vertices)."""
    for a, b in ((i, j), (j, i)):
        fb = f[piece == b]
        va = v[np.unique(f[piece == a])]
        if (winding_number(v, fb, va) > 0.5).any() or (_distance(v, fb, va) <= offset).any():
            return True
    return False


def _distance(v, f, points):
    """Each point's distance to the triangles ``f`` of ``v`` (libigl's exact search)."""
    igl = require("igl", "a mesh's nearest points")
    d, _, _ = igl.point_mesh_squared_distance(
        np.ascontiguousarray(points, dtype=float), np.ascontiguousarray(v), np.ascontiguousarray(f, dtype=np.int64)
    )
    return np.sqrt(d)


#: Bodies up to this many get their least gap from their vertices and faces; more, from their boxes.
GAP_BODIES = 16


def _gap(v, f, body, bodies):
    """The least distance from a vertex of one body to another body's surface (0 with one body); over
    :data:`GAP_BODIES` bodies, the least distance between two bodies' bounding boxes (a bound below it)."""
    if bodies < 2:
        return 0.0
    if bodies > GAP_BODIES:
        lo = np.full((bodies, 3), np.inf)
        hi = np.full((bodies, 3), -np.inf)
        for i in range(3):
            np.minimum.at(lo, body, v[f[:, i]])
            np.maximum.at(hi, body, v[f[:, i]])
        order = np.argsort(lo[:, 0])
        least = np.inf
        for k, i in enumerate(order[:-1]):
            rest = order[k + 1 :]
            apart = np.maximum(np.maximum(lo[rest] - hi[i], lo[i] - hi[rest]), 0.0)
            least = min(least, float(np.linalg.norm(apart, axis=1).min()))
        return least
    least = np.inf
    for b in range(bodies):
        mine = np.unique(f[body == b])
        least = min(least, float(_distance(v, f[body != b], v[mine]).min()))
    return least


#: Where each line of :func:`moments` passes in its cell, off the centre by these fractions of the
#: cell's sides (x, y): never through a vertex or an edge laid on the grid's diagonals, and a
#: shift of the midpoint rule far below its own error.
_JITTER = np.array([2**0.5, 3**0.5]) * 1e-3


def moments(source, rays: int | None = None, closed: bool = False) -> tuple[float, np.ndarray, np.ndarray]:
    r"""The volume, first moment ``(3,)`` and second moment ``(3, 3)`` of the solid :math:`w > 1/2` of the mesh
    ``source = (vertices, faces)``: :math:`\int dV, \int x\, dV, \int x x^T dV`.

    Integrated along ``rays x rays`` lines (default :data:`MOMENT_RAYS`) parallel to z through a grid over the bounding box
    (near the cells' centres): each line crosses the faces (and the box's bottom and top) at
    heights :math:`z_k`; between two crossings the winding number is constant, and the stretch is
    solid when it is above 1/2.  ``closed`` (every edge of the mesh in two faces: pieces each
    closed, overlapping or not): the winding number counts the crossings from below, +1 through a
    face turned down, -1 through one turned up; else it is evaluated at the stretch's middle.
    Along a line the integrals are exact (:math:`\int_a^b z^k dz`); across the lines, the midpoint
    rule (with :math:`h^2/12` for the squares of x and y over a cell of side :math:`h`): the error
    is of the order of the cell's side over the object's (a box's wall between two lines), 3e-3 at
    128 rays.

    >>> from grasptwist.engine.objects.primitives import triangles
    >>> v, f = triangles("box", [1.0, 2.0, 3.0], 0)
    >>> volume, first, second = moments((v, f), 16, closed=True)
    >>> round(volume, 9), first.round(9).tolist(), round(float(second[2, 2]), 9)
    (6.0, [0.0, 0.0, 0.0], 4.5)
    """
    v, f = (np.asarray(a) for a in source)
    rays = rays or (MOMENT_RAYS if closed else MOMENT_RAYS * 3 // 4)
    lo, hi = v.min(axis=0), v.max(axis=0)
    h = (hi[:2] - lo[:2]) / rays
    h = np.where(h > 0, h, 1.0)
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    det = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0]) * (b[:, 1] - a[:, 1])
    upright = np.abs(det) > 0  # a face along z crosses no line in its plane (to round-off)
    a, b, c, det = a[upright], b[upright], c[upright], det[upright]
    tri = np.stack([a, b, c], axis=1)
    shift = 0.5 + _JITTER
    first_cell = np.clip(np.ceil((tri[:, :, :2].min(axis=1) - lo[:2]) / h - shift), 0, rays - 1).astype(np.int64)
    last_cell = np.clip(np.floor((tri[:, :, :2].max(axis=1) - lo[:2]) / h - shift), 0, rays - 1).astype(np.int64)
    span = np.maximum(last_cell - first_cell + 1, 0)
    per = span[:, 0] * span[:, 1]
    face = np.repeat(np.arange(len(tri)), per)
    k = np.arange(len(face)) - np.repeat(np.cumsum(per) - per, per)
    ix = first_cell[face, 0] + k % np.maximum(span[face, 0], 1)
    iy = first_cell[face, 1] + k // np.maximum(span[face, 0], 1)
    x = lo[0] + (ix + shift[0]) * h[0]
    y = lo[1] + (iy + shift[1]) * h[1]
    pa, pb, pc, d = a[face], b[face], c[face], det[face]
    l1 = ((x - pa[:, 0]) * (pc[:, 1] - pa[:, 1]) - (pc[:, 0] - pa[:, 0]) * (y - pa[:, 1])) / d
    l2 = ((pb[:, 0] - pa[:, 0]) * (y - pa[:, 1]) - (x - pa[:, 0]) * (pb[:, 1] - pa[:, 1])) / d
    hit = (l1 >= 0) & (l2 >= 0) & (l1 + l2 <= 1)
    z = (pa[:, 2] + l1 * (pb[:, 2] - pa[:, 2]) + l2 * (pc[:, 2] - pa[:, 2]))[hit]
    ray = (iy * rays + ix)[hit]
    step = -np.sign(d[hit])  # through a face turned down (its normal's z < 0) going up: into the solid
    if not closed:  # each line also ends at the box's bottom and top: through a hole it crosses one face only
        every = np.arange(rays * rays)
        z = np.concatenate([z, np.full(len(every), lo[2]), np.full(len(every), hi[2])])
        ray = np.concatenate([ray, every, every])
        step = np.concatenate([step, np.zeros(2 * len(every))])
    order = np.lexsort((z, ray))
    z, ray, step = z[order], ray[order], step[order]
    stretch = np.flatnonzero(ray[1:] == ray[:-1])
    z0, z1, line = z[stretch], z[stretch + 1], ray[stretch]
    lx = lo[0] + (line % rays + 0.5) * h[0]  # the cell's centre: its line passes just off it
    ly = lo[1] + (line // rays + 0.5) * h[1]
    if closed:
        count = np.cumsum(step)
        start = np.flatnonzero(np.r_[True, ray[1:] != ray[:-1]])
        below = np.repeat(count[start] - step[start], np.diff(np.r_[start, len(ray)]))
        solidly = (count - below)[stretch] > 0.5
    else:
        long = z1 > z0
        solidly = np.zeros(len(z0), dtype=bool)
        mid = np.stack([lx[long] + _JITTER[0] * h[0], ly[long] + _JITTER[1] * h[1], 0.5 * (z0 + z1)[long]], axis=1)
        solidly[long] = winding_number(v, f, mid) > 0.5
    z0, z1, lx, ly = z0[solidly], z1[solidly], lx[solidly], ly[solidly]
    cell = h[0] * h[1]
    m0 = cell * (z1 - z0)
    m1 = cell * (z1**2 - z0**2) / 2
    m2 = cell * (z1**3 - z0**3) / 3
    volume = float(m0.sum())
    first = np.array([(lx * m0).sum(), (ly * m0).sum(), m1.sum()])
    xx = ((lx**2 + h[0] ** 2 / 12) * m0).sum()
    yy = ((ly**2 + h[1] ** 2 / 12) * m0).sum()
    xy = (lx * ly * m0).sum()
    xz, yz = (lx * m1).sum(), (ly * m1).sum()
    second = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, m2.sum()]])
    return volume, first, second


def surface_moments(vertices, faces) -> tuple[float, np.ndarray, np.ndarray]:
    r"""The volume, first and second moments of the solid a closed, outward-wound mesh bounds, by the divergence theorem.

    Each face and a point :math:`o` (the bounding box's centre, so the cancelling parts stay small)
    make a tetrahedron of signed volume :math:`V_f = a \cdot (b \times c) / 6` (corners about
    :math:`o`); its first moment is :math:`V_f (a + b + c) / 4` and its second

    .. math::

        \int x x^T dV = \frac{V_f}{20}\left(a a^T + b b^T + c c^T + s s^T\right), \qquad s = a + b + c.

    Returned about the mesh's own origin.

    >>> from grasptwist.engine.objects.primitives import triangles
    >>> v, f = triangles("box", [1.0, 2.0, 3.0], 0)
    >>> volume, first, second = surface_moments(v + 1, f)
    >>> round(volume, 12), first.round(12).tolist(), round(float(second[2, 2]), 12)
    (6.0, [6.0, 6.0, 6.0], 10.5)
    """
    v = np.asarray(vertices, dtype=float)
    origin = 0.5 * (v.max(axis=0) + v.min(axis=0))
    a, b, c = (v[faces[:, i]] - origin for i in range(3))
    parts = np.einsum("ij,ij->i", a, np.cross(b, c)) / 6.0
    s = a + b + c
    volume = float(parts.sum())
    first = parts @ s / 4.0
    second = np.einsum("f,fi,fj->ij", parts / 20.0, a, a)
    second += np.einsum("f,fi,fj->ij", parts / 20.0, b, b)
    second += np.einsum("f,fi,fj->ij", parts / 20.0, c, c)
    second += np.einsum("f,fi,fj->ij", parts / 20.0, s, s)
    # back to the mesh's origin: x = y + o
    second = second + np.outer(first, origin) + np.outer(origin, first) + volume * np.outer(origin, origin)
    return volume, first + volume * origin, second


def solid_warnings(s: Solid, scale: float = 1.0) -> list:
    """The warnings of what a mesh's solid :class:`Solid` found, each starting with its code: ``mesh-open``
    (its open edges and largest hole) and ``mesh-bodies`` (pieces apart: how many, how far).
    ``scale``: the lengths' factor to the object's units.

    >>> from grasptwist.engine.objects.primitives import triangles
    >>> v, f = triangles("box", [1.0, 1.0, 1.0], 0)
    >>> solid_warnings(solid(np.concatenate([v, v + [3, 0, 0]]), np.concatenate([f, f + len(v)])))
    ['mesh-bodies: the mesh is 2 bodies, 2 apart at the least: a synthesized grasp keeps to one (--span-bodies, span_bodies=True: across them)']
    """
    said = []
    if s.open_edges:
        said.append(
            f"mesh-open: {s.open_edges} open edge{'s' * (s.open_edges != 1)} (the largest hole {s.largest_hole * scale:.3g} "
            "across): the inside is where the winding number is above 1/2"
        )
    if s.internal or s.partly or s.cavities:
        said.append(
            f"mesh-internal: {s.internal} face{'s' * (s.internal != 1)} inside the solid, {s.partly} partly, and {s.cavities} "
            f"cavit{'y' if s.cavities == 1 else 'ies'}: out of a finger's reach"
        )
    if s.bodies > 1:
        said.append(
            f"mesh-bodies: the mesh is {s.bodies} bodies, {s.gap * scale:.3g} apart at the least: "
            "a synthesized grasp keeps to one (--span-bodies, span_bodies=True: across them)"
        )
    return said
