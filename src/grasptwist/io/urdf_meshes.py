"""The meshes of a hand's URDF: its finger links' collision geometry, and its visual meshes for pictures.

:mod:`grasptwist.io.urdf` reads a URDF for its joints and opens no mesh but
the tip's; the collision checks want the finger links' shapes
(:func:`link_geometry`: read from the same model, :mod:`.urdf_model`, its
STL, OBJ and PLY meshes by :func:`~grasptwist.io.mesh_formats.parse_mesh`,
so that neither yourdfpy nor trimesh is imported), and a picture of the hand
its visual meshes (:func:`hand_meshes`: this reads the same URDF again with
the same checks, size cap and no DTD, then lets yourdfpy load them, through
trimesh, and pose them by its own forward kinematics of the same joints).
Each mesh file is resolved
as the URDF itself is (:func:`~grasptwist.io.urdf.resolve_urdf`: inside its
``package://`` package, or inside the URDF's folder) and must be a regular
file that decodes to at most :data:`~grasptwist.io.limits.MAX_MESH_BYTES`
(:func:`decoded_size`: an archive or compressed stream is measured before the
mesh library inflates it; a glTF with the buffer and image files it names,
which must stay in its folder, and its accessors' extent, :func:`gltf_bytes`),
and an STL, OBJ or PLY must declare at most the mesh caps' vertices and
triangles and read within the caps (:func:`~grasptwist.io.mesh_formats.parse_mesh`: a polygon
of millions of corners, a PLY header that lies), as an object's mesh must, before the library
parses it again.  A mesh the library cannot read, whatever it raises, is an
:class:`~grasptwist.model.InputError` naming it.
"""

from __future__ import annotations

import bz2
import gzip
import io
import json
import lzma
import os
import stat
import warnings
import zipfile
import zlib
from pathlib import Path
from urllib.parse import unquote

import numpy as np

from ..engine.collision import LinkGeometry
from ..model import InputError
from .limits import MAX_MESH_BYTES, MAX_TRIANGLES, MAX_URDF_BYTES, MESH_SUFFIXES
from .urdf import _library, _parse, _read, resolve_urdf, urdf_name
from .urdf_model import merged, read_model

__all__ = [
    "MERGE_DECIMALS",
    "decoded_size",
    "gltf_bytes",
    "grasp_folder",
    "hand_meshes",
    "link_geometry",
    "mesh_file",
    "urdf_files",
]

#: A link mesh's vertices that round to the same multiples of ``10**-MERGE_DECIMALS`` are one (as
#: trimesh merges a mesh it loads: ``trimesh.tol.merge`` 1e-8).
MERGE_DECIMALS = 8

#: Compressed streams by their first bytes, and how to open one.
_STREAMS = {b"\x1f\x8b": gzip.open, b"BZh": bz2.open, b"\xfd7zXZ\x00": lzma.open}
_CHUNK = 1 << 20
#: A glTF accessor's bytes a component, by ``componentType``, and its components, by ``type``.
_COMPONENT_BYTES = {5120: 1, 5121: 1, 5122: 2, 5123: 2, 5125: 4, 5126: 4}
_COMPONENTS = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT2": 4, "MAT3": 9, "MAT4": 16}


def decoded_size(path, cap: int) -> int:
    """The bytes the file at ``path`` decodes to, counted no further than just past ``cap``.

    A zip archive (``.zip``, ``.3mf``: whatever its name, as a mesh library may
    open it by its content) decodes to the sizes its directory declares, which
    reading never exceeds; a gzip, bzip2 or xz stream (``.gz``, ``.tar.bz2``,
    ...) is inflated and counted, a megabyte at a time, up to ``cap``; any
    other file is its size.

    Raises
    ------
    OSError, EOFError, zipfile.BadZipFile, zlib.error, lzma.LZMAError
        A damaged archive or stream.

    >>> import tempfile
    >>> with tempfile.NamedTemporaryFile(suffix=".gz") as f:
    ...     f.write(gzip.compress(bytes(5_000_000))) and None
    ...     f.flush()
    ...     os.path.getsize(f.name) < 10_000, decoded_size(f.name, 1 << 20) > 1 << 20
    (True, True)
    """
    with open(path, "rb") as f:
        if zipfile.is_zipfile(f):
            with zipfile.ZipFile(f) as archive:
                return sum(info.file_size for info in archive.infolist())
        f.seek(0)
        head = f.read(6)
        opener = next((o for magic, o in _STREAMS.items() if head.startswith(magic)), None)
        if opener is None:
            return os.fstat(f.fileno()).st_size
        f.seek(0)
        size = 0
        with opener(f) as stream:
            while size <= cap and (chunk := stream.read(_CHUNK)):
                size += len(chunk)
        return size


def gltf_bytes(path) -> tuple[int, int]:
    """``(read, built)``: the bytes a glTF (``.gltf`` text, or ``.glb``) makes a mesh library read,
    itself and the buffer and image files it names (each resolved as a URDF's mesh is, inside the
    glTF's folder), and the bytes its accessors declare (``count`` elements of their type, which
    a library allocates), both found from its JSON before a buffer is opened.

    Raises
    ------
    InputError
        ``path-outside`` (or another of :func:`~grasptwist.io.urdf.resolve_urdf`'s) for a file it names.
    OSError, ValueError
        A file that cannot be read, JSON that is not a glTF's.

    >>> import tempfile
    >>> doc = {"buffers": [{"uri": "data:,"}], "accessors": [{"count": 10**9, "type": "VEC3", "componentType": 5126}]}
    >>> with tempfile.NamedTemporaryFile("w", suffix=".gltf") as f:
    ...     f.write(json.dumps(doc)) and None
    ...     f.flush()
    ...     gltf_bytes(f.name)[1]
    12000000000
    """
    path = Path(path)
    with open(path, "rb") as f:
        head = f.read(20)
        if head.startswith(b"glTF"):  # a 12-byte header, then the JSON chunk's length and type
            document = f.read(int.from_bytes(head[12:16], "little"))
        else:
            document = head + f.read(MAX_MESH_BYTES)
        read = os.fstat(f.fileno()).st_size
    gltf = json.loads(document)
    for item in [*gltf.get("buffers", []), *gltf.get("images", [])]:
        uri = item.get("uri")
        if isinstance(uri, str) and not uri.startswith("data:"):
            read += os.stat(resolve_urdf(unquote(uri), path.parent)).st_size
    built = sum(
        int(a["count"]) * _COMPONENTS[a["type"]] * _COMPONENT_BYTES[a["componentType"]]
        for a in gltf.get("accessors", [])
    )
    return read, built


def hand_meshes(hand, positions=None, *, folder=None, max_bytes=MAX_URDF_BYTES) -> list[tuple]:
    """Every visual mesh of ``hand``'s URDF at joint ``positions``, in the hand's root frame.

    Parameters
    ----------
    hand : Hand
        Read from a URDF (``hand.source``); inline joints have no meshes.
    positions : (n_joints,) array, optional
        In ``hand.joint_names`` order (the URDF's other joints at 0); None: home.
    folder : str or os.PathLike, optional
        The referring grasp file's folder, for a URDF given by path.
    max_bytes : int
        Size cap of the URDF.

    Returns
    -------
    list of (vertices (n, 3) array, faces (m, 3) int array)
        Empty for a hand without a URDF.

    Raises
    ------
    InputError
        The URDF's errors (:mod:`grasptwist.io.urdf`), and for a mesh file
        ``path-outside``, ``read-error`` or ``too-large``.
    """
    if hand.source is None:
        return []
    model = _loaded(hand, folder, max_bytes)
    if positions is not None:
        moved = dict(zip(hand.joint_names, map(float, positions)))
        model.update_cfg({j: moved.get(j, 0.0) for j in model.actuated_joint_names})
    return [(np.asarray(m.vertices, dtype=float), np.asarray(m.faces)) for m in model.scene.dump(concatenate=False)]


def link_geometry(hand, *, folder=None, max_bytes=MAX_URDF_BYTES) -> tuple[LinkGeometry, ...]:
    """Every finger link's collision geometry from ``hand``'s URDF, at home in the hand's root frame.

    A link is a finger's when the movable joints above it are the first ones of that finger (a link
    above every finger's first joint, the palm, moves with none and is no finger's).  Its geometry
    is its ``<collision>`` elements (meshes, boxes, spheres, cylinders, with their origins and
    scales); a URDF with no ``<collision>`` at all falls back to its ``<visual>`` ones.  Only one
    of the two is read: a URDF that has collision geometry keeps its visual-only links (the
    TriFinger's ``*_visuals_*`` decorations) out of the check.

    The URDF is read by :func:`~grasptwist.io.urdf_model.read_model` (not yourdfpy, which imports
    trimesh) and only the finger links' meshes are opened, each by :func:`mesh_file`; the links'
    poses at home are the products of the joints' origins down the tree.  The vertices and faces
    are those yourdfpy's collision scene gives (a link's shapes in the file's order, each mesh's
    vertices merged to 8 decimals as trimesh merges them, a scale whose product is negative
    re-winding the faces), to round-off; boxes, spheres and cylinders are trimesh's
    (``trimesh.primitives``), which is imported for them only.

    Parameters
    ----------
    hand : Hand
        Read from a URDF (``hand.source``); inline joints have no geometry.
    folder : str or os.PathLike, optional
        The referring grasp file's folder, for a URDF given by path.
    max_bytes : int
        Size cap of the URDF.

    Returns
    -------
    tuple of LinkGeometry
        Finger by finger, base to tip; empty for a hand without a URDF.

    Raises
    ------
    InputError
        As :func:`hand_meshes`.

    Examples
    --------
    >>> import grasptwist as gt
    >>> (g,) = gt.read_grasps("grasps/trifinger-cube.yaml")
    >>> [(l.finger, l.link, l.joints) for l in link_geometry(g.hand)][:4]
    [(0, 'finger_upper_link_0', 1), (0, 'finger_middle_link_0', 2), (0, 'finger_lower_link_0', 3), (0, 'finger_tip_link_0', 3)]
    """
    if hand.source is None:
        return ()
    source = urdf_name(hand.source, folder)  # as the hand's reading named it
    _library(source)  # trimesh (yourdfpy's) makes the primitives and reads other formats
    urdf = resolve_urdf(hand.source, folder)
    model = read_model(_parse(_read(urdf, max_bytes, source), source), source)
    collision = any(link.collisions for link in model.links.values())
    meshes, out = {}, []  # each mesh file read once
    for link, (finger, joints, pose) in _finger_links(hand, model).items():
        shapes = model.links[link].collisions if collision else model.links[link].visuals
        parts = [_shape_mesh(shape, urdf, source, meshes, turn=not collision) for shape in shapes]
        if not parts:
            continue
        offsets = np.cumsum([0] + [len(v) for v, _ in parts[:-1]])
        vertices = np.concatenate([v for v, _ in parts]) @ pose[:3, :3].T + pose[:3, 3]
        faces = np.concatenate([f + o for (_, f), o in zip(parts, offsets)])
        out.append(LinkGeometry(finger, link, joints, vertices, faces))
    return tuple(sorted(out, key=lambda g: (g.finger, g.joints)))


def _shape_mesh(shape, urdf, source, meshes, turn):
    """A ``<collision>`` (or ``<visual>``) shape's ``(vertices, faces)`` in its link's frame:
    its mesh scaled (a scale of 1 to ``np.allclose`` left alone, as trimesh does) or trimesh's
    primitive, moved by its origin.  A sphere's tessellation is only moved, not turned, unless
    ``turn`` (trimesh turns the primitive's pose but makes its sphere's mesh from the centre alone;
    a visual shape is posed by the scene)."""
    if shape.kind == "mesh":
        if shape.filename not in meshes:
            meshes[shape.filename] = mesh_file(shape.filename, urdf, source, shape.line)
        v, f = meshes[shape.filename]
        if shape.scale is not None and not np.allclose(shape.scale, 1.0):
            v = v * shape.scale
            f = f[:, ::-1] if np.prod(shape.scale) < 0 else f  # a mirror turns the faces inside out
    else:
        v, f = _primitive(shape)
    origin = shape.origin
    if shape.kind == "sphere" and not turn:
        return v + origin[:3, 3], f
    return v @ origin[:3, :3].T + origin[:3, 3], f


def _primitive(shape):
    """trimesh's box, sphere or cylinder (``trimesh.primitives``, as yourdfpy makes them): ``(vertices, faces)``."""
    import trimesh

    size = shape.size
    if shape.kind == "box":
        made = trimesh.primitives.Box(extents=np.asarray(size, dtype=float))
    elif shape.kind == "sphere":
        made = trimesh.primitives.Sphere(radius=size[0])
    else:
        made = trimesh.primitives.Cylinder(radius=size[0], height=size[1])
    return np.asarray(made.vertices, dtype=float), np.asarray(made.faces, dtype=np.int64)


def _finger_links(hand, model) -> dict:
    """Each link moved by some finger's first joints: ``{link: (finger, joints, pose)}`` (the first
    finger whose joints they are, when fingers share joints; ``pose`` ``(4, 4)`` the link's at home,
    in the root's frame)."""
    parent = {j.child: j for j in model.joints}
    prefixes = {}
    for f, finger in enumerate(hand.fingers):
        names = tuple(j.name for j in finger.joints)
        for k in range(1, len(names) + 1):
            prefixes.setdefault(names[:k], (f, k))
    owners = {}
    for link in model.links:
        chain, at = [], link
        while at in parent and len(chain) <= len(parent):  # a cycle (no hand's link) ends the walk
            chain.append(parent[at])
            at = parent[at].parent
        owner = prefixes.get(tuple(j.name for j in reversed(chain) if j.type != "fixed"))
        if owner is not None and at not in parent:
            pose = np.eye(4)
            for joint in reversed(chain):
                pose = pose @ joint.origin
            owners[link] = (*owner, pose)
    return owners


def mesh_file(name, urdf, source, line=None):
    """A URDF's mesh file ``name`` as ``(vertices (V, 3), faces (F, 3))`` in its own frame.

    Resolved as the URDF's meshes are (:func:`~grasptwist.io.urdf.resolve_urdf`, from the folder
    of the URDF at ``urdf``) and within the mesh caps (:func:`_checked_mesh`); an STL, OBJ or PLY
    read by :func:`~grasptwist.io.mesh_formats.parse_mesh`, another format by trimesh (imported
    only then).  As trimesh loads a mesh (:func:`~grasptwist.io.urdf_model.merged`): faces with a
    corner that is not finite dropped, vertices equal to 8 decimals merged into the first of them,
    unused ones left out.  (An OBJ's vertices merge by position alone, where trimesh keeps apart
    those of different normals.)

    Raises
    ------
    InputError
        The URDF's (``source``, at ``line``, its ``<mesh>`` element's), naming the mesh:
        ``path-outside``, ``read-error``, ``too-large`` or a mesh format's.
    """
    path, parsed = _checked_mesh(name, urdf, source, line)
    if parsed is None:
        import trimesh

        try:
            loaded = trimesh.load(str(path), force="mesh", ignore_broken=True, skip_materials=True)
            parsed = np.asarray(loaded.vertices, dtype=float), np.asarray(loaded.faces, dtype=np.int64)
        except Exception as exc:  # noqa: BLE001 - a malformed mesh: each format's parser raises its own kinds
            message = f"mesh {name!r}: cannot read: {type(exc).__name__}: {exc}"
            raise InputError("read-error", message, source, line) from None
    return merged(*parsed)


def _checked_mesh(name, urdf, source, line=None):
    """The mesh file ``name`` of the URDF at ``urdf``: its path, resolved and within the mesh caps
    (:func:`_check_mesh_file`), and its ``(vertices, faces)`` when it is an STL, OBJ or PLY (None
    for another format); errors are the URDF's (``source``, at ``line``, its ``<mesh>``'s),
    naming the mesh (and the mesh file's own line, when it has one)."""
    try:
        path = resolve_urdf(name, urdf.parent)
        return path, _check_mesh_file(name, path)
    except InputError as exc:  # the error is the URDF's, about one of its meshes
        raise InputError(exc.code, _about(name, exc), source, line) from None


def _about(name, exc):
    """A mesh file's error said as the URDF's: ``mesh 'm.stl' resolves outside ...`` (an error that
    names it first), else ``mesh 'm.stl', line 4: <what>`` (the mesh file's own line, when it has one)."""
    if exc.message.startswith(repr(name)):
        return f"mesh {exc.message}"
    inside = f", line {exc.line}" if exc.line else ""
    return f"mesh {name!r}{inside}: {exc.message}"


def _loaded(hand, folder, max_bytes):
    """``hand``'s URDF read by yourdfpy with its visual meshes loaded, every mesh file resolved and
    size-checked first (see the module's docstring)."""
    urdf = resolve_urdf(hand.source, folder)
    data = _read(urdf, max_bytes, hand.source)
    _parse(data, hand.source)  # refuses a DTD, as the joints' reading did
    _library(hand.source)
    import yourdfpy

    def handler(fname):  # yourdfpy passes it by this name
        path, _ = _checked_mesh(fname, urdf, hand.source)
        asked.append(fname)
        return str(path)

    asked = []  # the mesh files handed to the library, the one it is reading last
    try:
        with warnings.catch_warnings():  # yourdfpy's own call of a trimesh method trimesh deprecates
            warnings.filterwarnings("ignore", r".*Scene\.dump", DeprecationWarning)
            return yourdfpy.URDF.load(io.BytesIO(data), filename_handler=handler)
    except InputError:
        raise
    except Exception as exc:  # noqa: BLE001 - a malformed mesh: each format's parser raises its own kinds
        what = f"mesh {asked[-1]!r}" if asked else "its meshes"
        raise InputError("read-error", f"{what}: cannot read: {type(exc).__name__}: {exc}", hand.source) from None


def _check_mesh_file(name, path):
    """Refuse the mesh file ``name`` (at ``path``) unless it is a regular file within the mesh caps:
    :data:`~grasptwist.io.limits.MAX_MESH_BYTES` held, decoded or read with the files a glTF names,
    and an STL's, OBJ's or PLY's declared vertices and triangles; errors name the file as ``name``.
    Returns an STL's, OBJ's or PLY's ``(vertices, faces)`` as read within the caps (None for another format)."""
    from .mesh_formats import parse_mesh

    cap = MAX_MESH_BYTES
    try:
        info = os.stat(path)
        if not stat.S_ISREG(info.st_mode):
            raise InputError("read-error", "not a regular file", name)
        if info.st_size > cap:
            raise InputError("too-large", f"larger than {cap} bytes", name)
        size = decoded_size(path, cap)
        if size > cap:
            raise InputError("too-large", f"decodes to more than {cap} bytes ({info.st_size:,} compressed)", name)
        suffix = path.suffix.lower()
        if suffix in (".gltf", ".glb"):
            read, built = gltf_bytes(path)
            if max(read, built) > cap:
                what = (
                    f"reads {read:,} bytes with the files it names"
                    if read > cap
                    else f"declares accessors of {built:,} bytes"
                )
                raise InputError("too-large", f"{what}, more than {cap} bytes", name)
        if suffix in MESH_SUFFIXES:
            return parse_mesh(_read(path, cap, name), suffix, name, MAX_TRIANGLES)
        return None
    except (OSError, EOFError, zipfile.BadZipFile, zlib.error, lzma.LZMAError) as exc:
        raise InputError("read-error", f"cannot read: {getattr(exc, 'strerror', None) or exc}", name) from None
    except (ValueError, KeyError, TypeError, AttributeError) as exc:  # JSON that is no glTF's
        raise InputError("read-error", f"cannot read: {type(exc).__name__}: {exc}", name) from None


def grasp_folder(grasp) -> Path | None:
    """The folder of the file a grasp was read from (None for standard input or a string)."""
    return None if grasp.file.startswith("<") else Path(grasp.file).parent


def urdf_files(hand, *, folder=None, max_bytes=MAX_URDF_BYTES) -> tuple[str, dict]:
    """A URDF hand's description and its mesh files by file name, for MuJoCo's URDF reader (which
    looks a mesh up by its file name alone): every mesh resolved (``package://`` and paths, as
    yourdfpy's are) and within :data:`MAX_MESH_BYTES`.

    Raises
    ------
    InputError
        The URDF's, or one of its meshes': unreadable, outside its folder, too large.
    """
    urdf = resolve_urdf(hand.source, folder)
    data = _read(urdf, max_bytes, hand.source)
    root = _parse(data, hand.source)
    meshes = {}
    for element in root.iter("mesh"):
        name, line = element.get("filename", ""), element.sourceline
        try:
            path = resolve_urdf(name, urdf.parent)
        except InputError as exc:  # the error is the URDF's, about one of its meshes
            raise InputError(exc.code, _about(name, exc), hand.source, line) from None
        try:
            if path.stat().st_size > MAX_MESH_BYTES:
                raise InputError("too-large", f"mesh {name!r}: larger than {MAX_MESH_BYTES} bytes", hand.source, line)
            meshes[os.path.basename(name)] = path.read_bytes()
        except OSError as exc:
            raise InputError("read-error", f"mesh {name!r}: cannot read: {exc.strerror}", hand.source, line) from None
    return data.decode("utf-8"), meshes
