"""The bytes of a mesh file (STL, OBJ or PLY) to vertices and faces, within the mesh caps.

:mod:`grasptwist.io.mesh_file` reads an object's mesh with these and checks it as a surface;
:mod:`grasptwist.io.urdf_meshes` reads a URDF's link meshes with them before its library parses
them again.  First the counts a file declares (:func:`check_counts`: a binary STL's count, an ASCII
STL's ``endfacet`` words, a PLY header's elements against its body, an OBJ's ``v`` and ``f``
lines), then the readers, which stop at the caps whatever the file says: STL, OBJ and ASCII PLY
are read here (a line, a word or a record at a time, never an object a word of the whole file), a
binary PLY by trimesh (the extra ``grasptwist[mesh]``) once its rows with a list were walked.
Errors name the file and, where there is one, its line.
"""

from __future__ import annotations

import re
import warnings
from array import array as packed

import numpy as np

from ..model import InputError
from .limits import MAX_TRIANGLES, MAX_VERTICES

__all__ = ["parse_mesh", "check_counts"]

#: An OBJ's vertex and face lines (others are passed over unsplit), their keyword and the rest.
_OBJ_LINES = re.compile(rb"^[ \t]*([vf])[ \t]([^\r\n]*)", re.MULTILINE)
_ASCII_STL = re.compile(rb"\s*solid", re.IGNORECASE)
#: A binary STL: an 80-byte header, a little-endian uint32 count, then 50 bytes per triangle.
_STL_HEADER, _STL_TRIANGLE = 84, 50
_STL_RECORD = np.dtype([("normal", "<f4", 3), ("corners", "<f4", (3, 3)), ("attribute", "<u2")])
#: An ASCII STL's corner: the word ``vertex`` (in any letter case) and three numbers.
_STL_VERTICES = re.compile(rb"(?i)\bvertex\s+(\S+)\s+(\S+)\s+(\S+)")


def parse_mesh(data, suffix, file, max_triangles=MAX_TRIANGLES):
    """``(vertices, faces)`` as the bytes ``data`` of a mesh file (``suffix`` ``.stl``, ``.obj`` or
    ``.ply``) give them, unchecked as a surface, once their declared counts pass (:func:`check_counts`):
    read within the caps whatever the file says.

    Raises
    ------
    InputError
        ``invalid-mesh`` (located at the file's line where there is one), ``too-many-vertices``,
        ``too-many-triangles`` or ``mesh-unavailable``.

    >>> parse_mesh(b"v 0 0 0\\nf 1 1 0\\n", ".obj", "a.obj")
    Traceback (most recent call last):
    grasptwist.model.InputError: a.obj:2: a face names vertex 0, which the file does not have
    """
    check_counts(data, suffix, file, max_triangles)
    try:
        return _READERS[suffix](data, max_triangles, file)
    except (ValueError, IndexError):
        raise InputError("invalid-mesh", f"not a readable {suffix[1:].upper()} file", file) from None


def _obj(data, max_triangles, file):
    """``(vertices, faces)`` of a Wavefront OBJ's ``v`` and ``f`` lines (polygons as fans of
    triangles; ``a/b/c`` takes ``a``; negative indices count back from the vertices so far),
    read here: it is the format this project writes (``grasps/meshes/make_bottle.py``), and trimesh
    costs a second to import.  Other lines (normals, texture coordinates, groups, materials)
    are passed over unsplit.

    Memory stays within the caps whatever the lines: at most :data:`MAX_VERTICES` vertices and
    ``max_triangles`` triangles are kept, and a face line is split into no more corners than the
    triangles left allow (a polygon of ``k`` corners is ``k - 2`` of them), so one polygon of
    millions of corners is refused without making a word of each.

    Raises
    ------
    InputError
        ``invalid-mesh``, ``too-many-vertices`` or ``too-many-triangles``, at the file's line.

    >>> v, f = _obj(b"v 0 0 0\\nv 1 0 0\\nv 0 1 0\\nv 1 1 0\\nf 1 2 4 -2\\n", 10, "a.obj")
    >>> f.tolist()
    [[0, 1, 3], [0, 3, 2]]
    >>> _obj(b"v 0 0 0\\nf 1 2 99999999999999999999999\\n", 10, "a.obj")
    Traceback (most recent call last):
    grasptwist.model.InputError: a.obj:2: a face names vertex 99999999999999999999999, which the file does not have
    """
    if data.count(b"\r") > data.count(b"\r\n"):  # lines that end in \r alone (a copy for those files only)
        data = data.replace(b"\r\n", b"\n").replace(b"\r", b"\n")
    vertices, triangles = packed("d"), packed("q")
    for match in _OBJ_LINES.finditer(data):
        kind, body = match.groups()
        try:
            if kind == b"v":
                _vertex(body, vertices)
            else:
                _face(body, len(vertices) // 3, triangles, max_triangles)
        except _Refused as why:
            raise InputError(*why.args, file, _line(data, match.start())) from None
    return np.frombuffer(vertices, dtype=float).reshape(-1, 3), np.frombuffer(triangles, dtype=np.int64).reshape(-1, 3)


class _Refused(Exception):
    """An OBJ line that cannot be read: ``(code, message)``, located by the caller."""


def _vertex(body, vertices):
    """Append a ``v`` line's three coordinates (a fourth, or colours, passed over) to ``vertices``."""
    if len(vertices) == 3 * MAX_VERTICES:
        raise _Refused("too-many-vertices", f"more than the limit of {MAX_VERTICES:,} vertices")
    words = body.split(None, 3)[:3]
    try:
        coordinates = [float(w) for w in words]
    except ValueError:
        raise _Refused("invalid-mesh", "a vertex's coordinates are not numbers") from None
    if len(coordinates) < 3:
        raise _Refused("invalid-mesh", "a vertex needs three coordinates")
    vertices.extend(coordinates)


def _face(body, so_far, triangles, max_triangles):
    """Append the fan of an ``f`` line's polygon to ``triangles``, its corners split no further than
    the triangles left allow (``so_far``: the vertices read before it)."""
    budget = max_triangles - len(triangles) // 3 + 2  # the corners a polygon may have
    words = body.split(None, budget)
    if len(words) > budget:
        raise _Refused(
            "too-many-triangles",
            f"a polygon of more than {budget:,} corners takes the mesh past the limit of {max_triangles:,} triangles",
        )
    try:
        corners = [int(w.partition(b"/")[0]) for w in words]
    except ValueError:
        raise _Refused("invalid-mesh", "a face's corners are not vertex numbers") from None
    if len(corners) < 3:
        raise _Refused("invalid-mesh", "a face needs three corners")
    for c in corners:  # numbered from 1 (a vertex further on too), or back from the last one so far
        if not (-so_far <= c <= MAX_VERTICES and c):
            raise _Refused("invalid-mesh", f"a face names vertex {c}, which the file does not have")
    first, *rest = [c - 1 if c > 0 else so_far + c for c in corners]
    for b, c in zip(rest, rest[1:]):
        triangles.extend((first, b, c))


def _line(data, offset):
    """The 1-based line of ``data`` that byte ``offset`` is on (counted only for an error)."""
    return data.count(b"\n", 0, offset) + 1


def _stl(data, max_triangles, file):
    """``(vertices, faces)`` of an STL, each triangle its own three corners (:func:`check_mesh`
    merges them): a binary one (its count checked by :func:`_declared`) as numpy's records, an
    ASCII one by its ``vertex`` words, no more than ``3 * max_triangles`` of them.

    >>> v, f = _stl(b"solid t\\n facet normal 0 0 1\\n  outer loop\\n   vertex 0 0 0\\n   VERTEX 1 0 0\\n"
    ...             b"   vertex 0 1 0\\n  endloop\\n endfacet\\nendsolid t\\n", 10, "t.stl")
    >>> v.tolist(), f.tolist()
    ([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], [[0, 1, 2]])
    """
    count = int.from_bytes(data[80:84], "little") if len(data) >= _STL_HEADER else -1
    if len(data) == _STL_HEADER + _STL_TRIANGLE * count:
        corners = np.frombuffer(data, _STL_RECORD, count, _STL_HEADER)["corners"].reshape(-1, 3).astype(float)
    else:
        corners = packed("d")
        for match in _STL_VERTICES.finditer(data):
            if len(corners) == 9 * max_triangles:
                raise InputError(
                    "too-many-triangles",
                    f"more than the limit of {max_triangles:,} triangles",
                    file,
                    _line(data, match.start()),
                )
            try:
                corners.extend([float(x) for x in match.groups()])
            except ValueError:
                raise InputError(
                    "invalid-mesh", "a vertex's coordinates are not numbers", file, _line(data, match.start())
                ) from None
        if len(corners) % 9:
            raise InputError("invalid-mesh", f"{len(corners) // 3:,} vertex lines, not three a triangle", file)
        corners = np.frombuffer(corners, dtype=float).reshape(-1, 3)
    return corners, np.arange(len(corners)).reshape(-1, 3)


def _parsed(data, max_triangles, file):
    """``(vertices, faces)`` of a PLY file, parsed by trimesh once :func:`check_counts` passed it."""
    trimesh = _library(file)
    try:
        mesh = trimesh.load(
            trimesh.util.wrap_as_stream(data), file_type="ply", force="mesh", process=False, skip_materials=True
        )
        return np.asarray(mesh.vertices, dtype=float), np.asarray(mesh.faces, dtype=np.int64).reshape(-1, 3)
    except Exception:  # a parser's failure on hostile bytes has no one type; what it says varies by version
        raise ValueError("not a readable PLY file") from None


def _declared(data, suffix, file):
    r"""``(vertices, triangles)``: how many the file says it holds, found without parsing it
    (a polygon counts as one triangle until it is read).

    A binary STL gives its count in its header, and is exactly that long; an ASCII STL starts with
    ``solid`` and closes each triangle with ``endfacet``; a PLY's header declares its elements
    (:func:`_ply_elements`); an OBJ has a ``v`` line per vertex, an ``f`` line per face.  Bytes
    that are neither kind of STL are ``invalid-mesh``.

    >>> import struct
    >>> _declared(bytes(80) + struct.pack("<I", 2) + bytes(100), ".stl", "a.stl")
    (6, 2)
    >>> _declared(b"v 0 0 0\nf 1 2 3\r\nf 1 3 4\n", ".obj", "a.obj")
    (1, 2)
    >>> _declared(b"not a mesh", ".stl", "junk.stl")
    Traceback (most recent call last):
    grasptwist.model.InputError: junk.stl: not a readable STL file (neither a binary STL of the length its count gives nor text starting with 'solid')
    """
    if suffix == ".ply":
        elements = _ply_elements(data, file)
        return elements.get(b"vertex", 0), elements.get(b"face", 0)
    if suffix == ".obj":
        v, f = ((b"\n" + key + b" ", b"\n" + key + b"\t") for key in (b"v", b"f"))
        return tuple(sum(map(data.count, lines)) + data.startswith(lines[0][1:]) for lines in (v, f))
    if len(data) >= _STL_HEADER:
        count = int.from_bytes(data[80:84], "little")
        if len(data) == _STL_HEADER + _STL_TRIANGLE * count:
            return 3 * count, count
    if _ASCII_STL.match(data[:1024]):
        count = data.count(b"endfacet")
        return 3 * count, count
    raise InputError(
        "invalid-mesh",
        "not a readable STL file (neither a binary STL of the length its count gives nor text starting with 'solid')",
        file,
    )


def check_counts(data, suffix, file, max_triangles=MAX_TRIANGLES):
    """Refuse the bytes ``data`` of a mesh file (``suffix`` ``.stl``, ``.obj`` or ``.ply``) when
    they declare more than :data:`~grasptwist.io.limits.MAX_VERTICES` vertices or ``max_triangles``
    triangles, or (a PLY) more elements than its body holds: before a parser allocates for them.

    Raises
    ------
    InputError
        ``too-many-vertices``, ``too-many-triangles`` or ``invalid-mesh`` (located at the line
        of a PLY header that declares what the body does not hold).

    >>> check_counts(b"v 0 0 0\\n" * 3 + b"f 1 2 3\\n" * 2, ".obj", "a.obj", max_triangles=1)
    Traceback (most recent call last):
    grasptwist.model.InputError: a.obj: the file declares 2 faces, more than the limit of 1 triangles
    """
    vertices, triangles = _declared(data, suffix, file)
    if vertices > MAX_VERTICES:
        raise InputError(
            "too-many-vertices",
            f"the file declares {vertices:,} vertices, more than the limit of {MAX_VERTICES:,}",
            file,
        )
    if triangles > max_triangles:
        raise InputError(
            "too-many-triangles",
            f"the file declares {triangles:,} faces, more than the limit of {max_triangles:,} triangles",
            file,
        )


#: A PLY property's bytes in a binary body, by its type's names.
_PLY_SIZES = dict.fromkeys((b"char", b"uchar", b"int8", b"uint8"), 1)
_PLY_SIZES |= dict.fromkeys((b"short", b"ushort", b"int16", b"uint16"), 2)
_PLY_SIZES |= dict.fromkeys((b"int", b"uint", b"int32", b"uint32", b"float", b"float32"), 4)
_PLY_SIZES |= dict.fromkeys((b"double", b"float64"), 8)
_PLY_FORMATS = (b"ascii", b"binary_little_endian", b"binary_big_endian")
#: Most bytes of a PLY header (a few hundred hold a mesh's).
_PLY_HEADER = 1 << 16


def _ply_header(data, file):
    """``(format, body, elements)`` of a PLY file: its format (an index of ``_PLY_FORMATS``), where
    its body starts, and per element ``(name, count, header line, properties)``, each property
    ``(name, bytes, list?, item bytes)`` (a list's bytes: its count's)."""
    end = data.find(b"end_header", 0, _PLY_HEADER)
    if not data.startswith(b"ply") or end < 0:
        raise InputError(
            "invalid-mesh", f"not a PLY file: no 'ply' ... 'end_header' in its first {_PLY_HEADER:,} bytes", file
        )
    form, elements = None, []
    for number, line in enumerate(data[:end].split(b"\n"), 1):
        words = line.split()
        try:
            if words[:1] == [b"format"]:
                form = _PLY_FORMATS.index(words[1])
            elif words[:1] == [b"element"]:
                elements.append((words[1], int(words[2]), number, []))
                if elements[-1][1] < 0:
                    raise ValueError
            elif words[:1] == [b"property"]:
                listed = words[1] == b"list"
                size, item = (_PLY_SIZES[words[2]], _PLY_SIZES[words[3]]) if listed else (_PLY_SIZES[words[1]], 0)
                elements[-1][3].append((words[-1], size, listed, item))
        except (IndexError, ValueError, KeyError):
            raise InputError(
                "invalid-mesh", f"not a PLY header line: {line[:80].decode(errors='replace')!r}", file, number
            ) from None
    if form is None:
        raise InputError("invalid-mesh", "not a PLY file: its header gives no format", file)
    return form, data.find(b"\n", end) + 1 or len(data), elements


def _ply_elements(data, file):
    r"""``{name: count}`` of a PLY header's elements, once the body can hold them.

    In ASCII, one line an element: the body's lines must be as many as the header's elements;
    in binary, the body must hold at least their fixed-size properties (a list's count, no
    items).  Either way a count the body cannot hold is named at its line of the header, before
    a parser allocates for it.

    >>> header = b"ply\nformat ascii 1.0\nelement vertex 2000000000\nproperty float x\nend_header\n"
    >>> _ply_elements(header + b"0\n1\n", "m.ply")
    Traceback (most recent call last):
    grasptwist.model.InputError: m.ply:3: the header declares 2,000,000,000 vertex elements, one a line, but the body holds 2 lines
    """
    form, body, elements = _ply_header(data, file)
    text = form == 0
    held = _ply_lines(data[body:], file) if text else len(data) - body
    need = 0
    for name, count, number, properties in elements:
        row = sum(size for _, size, _, _ in properties)
        need += count if text else count * row
        if need > held:
            what = "one a line" if text else f"of {row} bytes or more"
            raise InputError(
                "invalid-mesh",
                f"the header declares {count:,} {name.decode(errors='replace')} elements, {what}, "
                f"but the body holds {held:,} {'lines' if text else 'bytes'}",
                file,
                number,
            )
    if text and need != held:
        raise InputError(
            "invalid-mesh", f"the body holds {held:,} lines, the header declares {need:,} elements, one a line", file
        )
    return {name: count for name, count, _, _ in elements}


def _ply(data, max_triangles, file):
    """``(vertices, faces)`` of a PLY file (:func:`check_counts` passed it): an ASCII one read here,
    its numbers parsed at once by numpy (no object a line or a word), a binary one by trimesh.

    >>> v, f = _ply(b"ply\\nformat ascii 1.0\\nelement vertex 4\\nproperty float x\\nproperty float y\\n"
    ...             b"property float z\\nelement face 1\\nproperty list uchar int vertex_indices\\n"
    ...             b"end_header\\n0 0 0\\n1 0 0\\n1 1 0\\n0 1 0\\n4 0 1 2 3\\n", 10, "q.ply")
    >>> f.tolist()
    [[0, 1, 2], [0, 2, 3]]
    """
    form, body, elements = _ply_header(data, file)
    if form:
        _binary_fans(data, body, elements, form == 2, max_triangles, file)
        return _parsed(data, max_triangles, file)
    # each row's numbers, two more a list and its corners within the triangle cap: no more are parsed
    most = max_triangles + sum(n * (len(p) + sum(2 for _, _, listed, _ in p if listed)) for _, n, _, p in elements)
    words = _words(data, body)
    if words > most:
        raise InputError(
            "invalid-mesh", f"the body holds {words:,} numbers, more than the header's elements can ({most:,})", file
        )
    with warnings.catch_warnings():
        warnings.simplefilter("error", DeprecationWarning)  # numpy's word for a word that is no number
        try:
            numbers = np.fromstring(data[body:], sep=" ")
        except (ValueError, DeprecationWarning):
            raise InputError("invalid-mesh", "a word of the body is not a number", file) from None
    at, vertices, triangles = 0, np.zeros((0, 3)), packed("q")
    for name, count, number, properties in elements:
        names = [p for p, _, _, _ in properties]
        if not any(listed for _, _, listed, _ in properties):  # fixed rows: one slice of the numbers
            rows = numbers[at : at + count * len(names)]
            at += count * len(names)
            if len(rows) < count * len(names):
                break
            if name == b"vertex":
                try:
                    vertices = rows.reshape(count, -1)[:, [names.index(axis) for axis in (b"x", b"y", b"z")]]
                except ValueError:
                    raise InputError("invalid-mesh", "the vertex element has no x, y and z", file, number) from None
            continue
        for _ in range(count):  # rows with a list: walked, at most the triangle cap's faces
            for prop, _, listed, _ in properties:
                n = int(numbers[at]) if listed and at < len(numbers) and numbers[at] >= 0 else 0
                corners, at = numbers[at + 1 : at + 1 + n], at + 1 + n if listed else at + 1
                if name == b"face" and prop in (b"vertex_indices", b"vertex_index"):
                    try:
                        _polygon(corners, len(vertices), triangles, max_triangles)
                    except _Refused as why:
                        raise InputError(*why.args, file) from None
    if at != len(numbers):
        raise InputError(
            "invalid-mesh", "the body's numbers are not those of the header's elements (a line too long or short)", file
        )
    return vertices, np.frombuffer(triangles, dtype=np.int64).reshape(-1, 3)


def _binary_fans(data, at, elements, big, max_triangles, file):
    """Refuse a binary PLY whose faces' fans hold more than ``max_triangles`` triangles, or whose
    rows run past its body, walking the rows with a list (at most :data:`MAX_VERTICES` an element)
    from byte ``at``, before trimesh allocates for them."""
    order, triangles = "big" if big else "little", 0
    for name, count, number, properties in elements:
        if not any(listed for _, _, listed, _ in properties):
            at += count * sum(size for _, size, _, _ in properties)
            continue
        if count > MAX_VERTICES:
            raise InputError("invalid-mesh", f"{count:,} rows with a list, more than {MAX_VERTICES:,}", file, number)
        for _ in range(count):
            for prop, size, listed, item in properties:
                n = int.from_bytes(data[at : at + size], order) if listed else 0
                at += size + n * item
                if name == b"face" and prop in (b"vertex_indices", b"vertex_index"):
                    triangles += max(n - 2, 0)
            if at > len(data):
                raise InputError(
                    "invalid-mesh", f"the body ends inside a {name.decode(errors='replace')} row", file, number
                )
        if triangles > max_triangles:
            raise InputError(
                "too-many-triangles",
                f"the faces hold {triangles:,} triangles, more than the limit of {max_triangles:,}",
                file,
                number,
            )


#: The bytes that separate words (Python's ``bytes.split``), as a table of the 256.
_SPACE = np.isin(np.arange(256), list(b" \t\n\r\x0b\x0c"))


def _words(data, start, chunk=1 << 20):
    """How many words ``data[start:]`` holds, counted a megabyte at a time without making them.

    >>> _words(b"ply 1 2  3 4 ", 3, chunk=3)  # split across chunks of 3 bytes
    4
    """
    count, after_space = 0, True
    for at in range(start, len(data), chunk):
        space = _SPACE[np.frombuffer(data, np.uint8, min(chunk, len(data) - at), at)]
        count += int(np.count_nonzero(~space & np.concatenate(([after_space], space[:-1]))))
        after_space = bool(space[-1])
    return count


def _polygon(corners, vertices, triangles, max_triangles):
    """Append the fan of a PLY face's ``corners`` (numbered from 0, of ``vertices``) to ``triangles``."""
    if len(corners) < 3 or len(corners) - 2 > max_triangles - len(triangles) // 3:
        raise _Refused(
            "invalid-mesh" if len(corners) < 3 else "too-many-triangles", f"a face of {len(corners)} corners"
        )
    if not ((corners >= 0) & (corners < vertices) & (corners == np.floor(corners))).all():
        raise _Refused("invalid-mesh", "a face names a vertex the file does not have")
    index = corners.astype(np.int64)
    for b, c in zip(index[1:-1].tolist(), index[2:].tolist()):
        triangles.extend((int(index[0]), b, c))


#: The readers of the formats, by suffix (a binary PLY is trimesh's: :func:`_parsed`).
_READERS = {".obj": _obj, ".stl": _stl, ".ply": _ply}


def _ply_lines(body, file):
    """The lines of an ASCII PLY body (trailing blank ones aside), after checking that it is ASCII
    text (a stray control character would split a line for some readers and not for others)."""
    body = body.rstrip()
    stray = re.search(rb"[^\x20-\x7e\t\r\n]", body)
    if stray:
        raise InputError(
            "invalid-mesh", f"byte {body[stray.start()]:#04x} in an ASCII PLY body, which holds text", file
        )
    breaks = body.count(b"\n") + body.count(b"\r") - body.count(b"\r\n")
    return breaks + 1 if body else 0


def _library(file):
    """trimesh, or the error that says which extra to install."""
    try:
        import trimesh
    except ImportError:
        raise InputError(
            "mesh-unavailable",
            "reading a mesh needs trimesh: pip install trimesh (from a clone of grasptwist: pip install -e '.[mesh]')",
            file,
        ) from None
    return trimesh
