"""Hands from robot descriptions (URDF), read as untrusted input.

A URDF names its links and the joints between them; a finger is the chain of
joints from the root link to the link that touches the object (its tip).
The robot model is read from lxml's tree by :mod:`.urdf_model`, with yourdfpy's
conventions but without importing it (it imports trimesh: 0.43 s a command);
reading a URDF needs the optional extra ``grasptwist[urdf]`` all the same (lxml,
and yourdfpy for pictures of the hand).  Only the tip link's collision mesh is
opened, for the fingertip's radius.  Around it:

* the reference: ``package://PKG/path`` is resolved inside the installed
  Python package ``PKG``, any other path relative to the referring file's
  folder; one that resolves (symbolic links followed) outside that package
  or folder is refused (``path-outside``);
* the bytes: at most ``max_bytes`` are read (a regular file only), and the XML
  is parsed by lxml with entity resolution, DTD loading and network access
  off and its size limits on; a document type
  declaration (DTDs, entities, external references: a robot description needs
  none) is refused outright (``forbidden-dtd``);
* the joints: mimic, floating and planar joints on a finger are refused
  (``unsupported-joint``); ``continuous`` joints are revolute.

Every refusal is a :class:`~grasptwist.model.InputError` with a code:

=====================  ==========================================================
``read-error``         missing or unreadable file, not a regular file
``too-large``          more than ``max_bytes``
``unsupported-url``    a URL scheme other than ``package://``
``package-not-found``  ``package://PKG``: no installed Python package ``PKG``
``path-outside``       the path resolves outside its package or folder
``urdf-syntax``        not well-formed XML
``forbidden-dtd``      a document type declaration
``invalid-urdf``       not a URDF tree (root element, links, joints, numbers)
``unknown-link``       a tip that is no link of the URDF
``fixed-finger``       a tip that no movable joint moves (the root link, or fixed to it)
``shared-joint``       two fingers moved by one joint (the same tip link, or a link above both)
``unsupported-joint``  a mimic, floating or planar joint on a finger
``urdf-unavailable``   the extra ``grasptwist[urdf]`` (lxml, yourdfpy) is not installed
=====================  ==========================================================
"""

from __future__ import annotations

import errno
import io
import os
import re
import stat
from contextlib import suppress
from dataclasses import replace
from importlib.util import find_spec
from pathlib import Path

import numpy as np

from ..engine.kinematics import chain_from_origins, chain_length
from ..model import Finger, Hand, InputError, Joint
from .limits import MAX_URDF_BYTES, MESH_SUFFIXES, OUTPUT_IS_INPUT
from .urdf_model import merged, read_model

__all__ = ["finger_problems", "load_urdf_hand", "resolve_urdf", "urdf_name"]

_PACKAGE = "package://"
_URL = re.compile(r"^[A-Za-z][A-Za-z0-9+.-]*://")
_MOVABLE = {"revolute": "revolute", "continuous": "revolute", "prismatic": "prismatic", "fixed": "fixed"}
_UNSUPPORTED = {"floating", "planar"}


def resolve_urdf(reference, folder=None, *, allow_outside=False, output=None):
    """The file a URDF (or mesh) reference names, refused if it leaves its package or folder.

    Parameters
    ----------
    reference : str or os.PathLike
        ``package://PKG/path`` (``PKG`` an installed Python package) or a path.
    folder : str or os.PathLike, optional
        The referring file's folder: a path is taken relative to it and must
        stay inside it.  None: a path is used as given (the caller chose it).
    allow_outside : bool
        Take a relative path wherever it leads (``--allow-outside``: the
        user vouches for the files the grasp files name).
    output : (int, int), optional
        The ``(device, inode)`` of the file ``-o`` replaces: a path outside the folder that is
        it is ``output-is-input`` rather than ``path-outside`` (it is refused either way, and
        the run must not replace it).

    Returns
    -------
    pathlib.Path
        Absolute, symbolic links resolved.

    Raises
    ------
    InputError
        ``unsupported-url``, ``package-not-found`` or ``path-outside``.

    >>> resolve_urdf("package://grasptwist/io/urdf.py").name
    'urdf.py'
    """
    text = os.fspath(reference)
    if text.startswith(_PACKAGE):
        package, _, rest = text[len(_PACKAGE) :].partition("/")
        return _inside(_package_folder(package, text), rest, text)
    if _URL.match(text):
        raise InputError("unsupported-url", f"only package:// URLs and file paths are read, got {text!r}", text)
    if folder is None:
        return _resolved(Path(text), text)
    if allow_outside:
        return _resolved(Path(folder) / text, text)
    return _inside(_resolved(Path(folder), text), text, text, output)


def urdf_name(reference, folder=None):
    """A URDF as its errors name it: its ``package://`` reference, else its path from the referring
    file's ``folder`` (as given: relative when that is).

    >>> urdf_name("hand.urdf", "."), urdf_name("package://pkg/hand.urdf", "grasps")
    ('./hand.urdf', 'package://pkg/hand.urdf')
    """
    text = os.fspath(reference)
    return text if text.startswith(_PACKAGE) or folder is None else os.path.join(os.fspath(folder), text)


def _package_folder(package, reference):
    # A dotted name would import its parent package (running its code) to find it.
    spec = find_spec(package) if package.isidentifier() else None
    if spec is None or not spec.submodule_search_locations:
        # the distribution's name is the package's with '-' for '_' (robot_properties_fingers: robot-properties-fingers)
        hint = package.replace("_", "-")
        raise InputError(
            "package-not-found", f"no installed Python package {package!r} (pip install {hint})", reference
        )
    return Path(next(iter(spec.submodule_search_locations))).resolve()


def _resolved(path, reference):
    """``path`` made absolute, its symbolic links followed; a loop of them is a ``read-error``."""
    try:
        return path.resolve()
    except (RuntimeError, OSError):  # Python 3.11-3.12: RuntimeError; 3.13: OSError (ELOOP)
        # the system's words, as a folder's listing and an open() give them
        raise InputError("read-error", f"cannot read: {os.strerror(errno.ELOOP)}", reference) from None


def _inside(base, relative, reference, output=None):
    path = _resolved(base / relative, reference)
    if not path.is_relative_to(base):
        with suppress(OSError):
            info = path.stat()
            if output is not None and (info.st_dev, info.st_ino) == tuple(output):
                raise _output_is_input(reference)
        raise InputError("path-outside", f"{reference!r} resolves outside {str(base)!r}", reference)
    return path


def _output_is_input(file):
    return InputError(OUTPUT_IS_INPUT, "is the file -o writes (the same file): give -o another file name", file)


def _read(path, max_bytes, file, output=None):
    """At most ``max_bytes + 1`` bytes of a regular file (a FIFO or device would block or never end);
    ``output``, the ``(device, inode)`` of the file ``-o`` replaces, is refused (``output-is-input``)."""
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0))
        try:
            info = os.fstat(fd)
            if not stat.S_ISREG(info.st_mode):
                raise InputError("read-error", "cannot read: not a regular file", file)
            if output is not None and (info.st_dev, info.st_ino) == tuple(output):
                raise _output_is_input(file)
            with os.fdopen(fd, "rb", closefd=False) as handle:
                data = handle.read(max_bytes + 1)
        finally:
            os.close(fd)
    except OSError as exc:
        raise InputError("read-error", f"cannot read: {exc.strerror or exc}", file) from None
    if len(data) > max_bytes:
        raise InputError("too-large", f"larger than the size limit of {max_bytes} bytes", file)
    return data


_SPACE = re.compile(rb"[ \t\r\n]*")
_LXML_WHERE = re.compile(r", line \d+, column \d+$")


def _doctype_offset(data):
    """Offset of a ``<!DOCTYPE`` in the prolog (the only place XML allows one), or None.

    A linear scan over the XML declaration, comments, processing instructions
    and white space, so that every document type declaration gets the same
    code whatever lxml would make of it (refused entity, amplification limit).
    """
    i = 3 if data.startswith(b"\xef\xbb\xbf") else 0
    while True:
        i = _SPACE.match(data, i).end()
        for opening, closing in ((b"<?", b"?>"), (b"<!--", b"-->")):
            if data.startswith(opening, i):
                end = data.find(closing, i + len(opening))
                if end < 0:
                    return None
                i = end + len(closing)
                break
        else:
            return i if data.startswith(b"<!DOCTYPE", i) else None


def _parse(data, file):
    """The XML tree of a URDF, parsed without entities, DTDs or network."""
    from lxml import etree

    offset = _doctype_offset(data)
    if offset is not None:
        raise _dtd_error(file, data.count(b"\n", 0, offset) + 1, offset - data.rfind(b"\n", 0, offset))
    parser = etree.XMLParser(
        resolve_entities=False,
        no_network=True,
        load_dtd=False,
        dtd_validation=False,
        huge_tree=False,
        remove_comments=True,
    )
    try:
        root = etree.fromstring(data, parser)
    except etree.XMLSyntaxError as exc:
        line, column = exc.position if exc.position else (None, None)
        message = _LXML_WHERE.sub("", exc.msg)  # the position is in the error's own fields
        raise InputError("urdf-syntax", f"not well-formed XML: {message}", file, line or None, column or None) from None
    info = root.getroottree().docinfo
    if info.doctype or info.internalDTD is not None or info.externalDTD is not None:  # e.g. in UTF-16, unseen above
        raise _dtd_error(file, None, None)
    if root.tag != "robot" or not root.get("name"):
        raise InputError("invalid-urdf", "the root element must be <robot name=...>", file, root.sourceline)
    return root


def _dtd_error(file, line, column):
    return InputError(
        "forbidden-dtd",
        "a document type declaration (DTD, entities): a robot description needs none",
        file,
        line,
        column,
    )


def _library(file):
    """Refuse (``urdf-unavailable``) unless the extra ``grasptwist[urdf]`` is installed: lxml (which
    :func:`_parse` reads with) and yourdfpy (pictures of the hand), found without importing them
    (yourdfpy imports trimesh, 0.43 s: :mod:`.urdf_model` reads the URDF without it)."""
    if find_spec("lxml") is None or find_spec("yourdfpy") is None:
        raise InputError(
            "urdf-unavailable",
            "reading a URDF needs yourdfpy: pip install yourdfpy (from a clone of grasptwist: pip install -e '.[urdf]')",
            file,
        )


def load_urdf_hand(
    urdf, tips, *, names=None, folder=None, max_bytes=MAX_URDF_BYTES, allow_outside=False, output=None, check=True
):
    """A hand from a URDF: one finger per tip link, its joints at home (all 0).

    The hand's frame (and so the grasp's) is the URDF's root link's frame.
    Finger ``f``'s joints are the movable joints on the path from the root to
    ``tips[f]``; fixed joints only carry frames along.  Move the fingers to
    joint positions with :func:`grasptwist.hand.finger_states`.  Its
    ``tip_radius`` is that of the tip link's spherical collision geometry
    about the link's origin: a ``<sphere>`` centred there, or a mesh that is
    a sphere or a cap of one about it
    (``grasptwist.engine.fingertips.sphere_radius``, the TriFinger's
    fingertips); 0 (a point tip) without one, or when the mesh cannot be
    read (a ``package://`` of no installed Python package, a file outside the
    mesh caps, a format trimesh does not read): a grasp file's ``tip_radius``
    then gives it.

    Parameters
    ----------
    urdf : str or os.PathLike
        ``package://PKG/path`` (``PKG`` an installed Python package) or a path.
    tips : sequence of str
        The link touching each contact, in contact order.
    names : sequence of str, optional
        Finger names; default ``"1"``, ``"2"``, ...
    folder : str or os.PathLike, optional
        The referring grasp file's folder; a path must stay inside it, unless ``allow_outside``.
    max_bytes : int
        Size cap of the URDF (default 1 MiB, as for grasp files).
    allow_outside : bool
        Take a relative path wherever it leads (``--allow-outside``).
    output : (int, int), optional
        The ``(device, inode)`` of the file ``-o`` replaces: a URDF that is it is ``output-is-input``.
    check : bool
        Refuse a finger that cannot be placed (``finger_problems``); False: the caller
        reports them (a grasp file at each finger's ``tip``).

    Returns
    -------
    Hand

    Raises
    ------
    InputError
        With one of the codes of the URDF's errors (docs/guide/hands.md).

    Examples
    --------
    >>> hand = load_urdf_hand("package://robot_properties_fingers/urdf/pro/trifingerpro.urdf",
    ...                       ["finger_tip_link_0", "finger_tip_link_120", "finger_tip_link_240"])
    >>> hand.root, len(hand.joint_names), [j.name for j in hand.fingers[0].joints]  # doctest: +NORMALIZE_WHITESPACE
    ('base_link', 9, ['finger_base_to_upper_joint_0', 'finger_upper_to_middle_joint_0',
                      'finger_middle_to_lower_joint_0'])
    >>> [f.tip_radius for f in hand.fingers]  # from the hemisphere of the tip links' collision mesh
    [0.01, 0.01, 0.01]
    """
    text = os.fspath(urdf)
    file = urdf_name(text, folder)
    _library(file)  # before the reference: a package:// one may be missing for the same reason
    where = resolve_urdf(urdf, folder, allow_outside=allow_outside, output=output)
    data = _read(where, max_bytes, file, output)
    model = read_model(_parse(data, file), file)
    parent_joint = _tree(model, file)
    names = [str(i + 1) for i in range(len(tips))] if names is None else list(names)
    if len(names) != len(tips):
        raise ValueError(f"names: expected {len(tips)} finger names, got {len(names)}")
    fingers, joint_names, meshes = [], {}, {}
    for name, tip in zip(names, tips, strict=True):
        path = _path(model, parent_joint, tip, file)
        finger = _finger(name, tip, path, file, joint_names)
        fingers.append(replace(finger, tip_radius=_tip_radius(model, tip, where, max_bytes, meshes)))
    roots = [link for link in model.links if link not in parent_joint]
    hand = Hand(tuple(fingers), tuple(joint_names), text, roots[0])
    for _, code, message, line in finger_problems(hand) if check else ():
        raise InputError(code, message, file, line)
    return hand


def finger_problems(hand):
    """The fingers of a URDF hand that cannot be placed, as ``(finger index, code, message, line)``.

    Inverse kinematics moves each finger by its own joints, alone: a finger whose tip no movable
    joint moves (``fixed-finger``: the root link, or a link fixed to it) has nothing to move, and
    a finger moved by a joint of an earlier finger (``shared-joint``: the same tip link, or a link
    above both) would give that joint a second position.  ``line`` is the shared joint's in the
    URDF (None for a fixed finger).

    >>> hand = load_urdf_hand("package://robot_properties_fingers/urdf/pro/trifingerpro.urdf",
    ...                       ["finger_tip_link_0", "base_link", "finger_lower_link_0"], check=False)
    >>> [(f, code) for f, code, _, _ in finger_problems(hand)]
    [(1, 'fixed-finger'), (2, 'shared-joint')]
    """
    out, owner = [], {}
    for f, finger in enumerate(hand.fingers):
        if not finger.joints:
            out.append(
                (
                    f,
                    "fixed-finger",
                    f"finger {finger.name!r}: no movable joint moves its tip link {finger.tip!r} "
                    f"(the root link, or fixed to it): it cannot be put on its contact",
                    None,
                )
            )
            continue
        shared = [(k, joint) for k, joint in zip(finger.joint_index, finger.joints) if k in owner]
        if shared:
            k, joint = shared[-1]  # the joint nearest the tip: the link the two fingers part at is below it
            other = hand.fingers[owner[k]]
            what = (
                f"has the same tip link {finger.tip!r} as"
                if other.tip == finger.tip
                else f"shares joint {joint.name!r} with"
            )
            out.append(
                (
                    f,
                    "shared-joint",
                    f"finger {finger.name!r} {what} finger {other.name!r}: each finger needs joints "
                    "of its own (inverse kinematics moves each alone, so a shared joint would get two positions)",
                    joint.line,
                )
            )
        for k in finger.joint_index:
            owner.setdefault(k, f)
    return out


def _tip_radius(model, tip, urdf, max_bytes, meshes):
    """The radius of link ``tip``'s spherical collision geometry about its origin (0: none);
    ``meshes`` keeps each mesh file's vertices read so far (a hand's fingers share their tip's)."""
    from ..engine.fingertips import SPHERE_TOL, sphere_radius

    for shape in model.links[tip].collisions:
        origin = shape.origin
        if shape.kind == "sphere" and float(np.linalg.norm(origin[:3, 3])) <= SPHERE_TOL * shape.size[0]:
            return shape.size[0]
        if shape.kind == "mesh" and shape.filename not in meshes:
            meshes[shape.filename] = _mesh_vertices(shape.filename, urdf, max_bytes)
        vertices = meshes[shape.filename] if shape.kind == "mesh" else None
        if vertices is not None:
            scale = np.ones(3) if shape.scale is None else shape.scale
            radius = sphere_radius(vertices * scale @ origin[:3, :3].T + origin[:3, 3])
            if radius is not None:  # digits past the sphere's own tolerance are the file's round-off
                return float(f"{radius:.{-int(np.log10(SPHERE_TOL))}g}")
    return 0.0


def _mesh_vertices(filename, urdf, max_bytes):
    """A collision mesh's vertices ``(V, 3)`` in its own frame, None when it cannot be read.

    Resolved as a URDF is (:func:`resolve_urdf`: ``package://`` inside its Python package, a
    path inside the URDF's folder), at most ``max_bytes``, an STL, OBJ or PLY parsed within the
    mesh caps (:func:`~grasptwist.io.mesh_formats.parse_mesh`), another format by trimesh (imported
    only then) from the bytes, so that it opens no other file; its vertices merged as trimesh
    merges them (:func:`~grasptwist.io.urdf_model.merged`).
    """
    from .mesh_formats import parse_mesh

    try:
        path = resolve_urdf(filename, urdf.parent)
        data = _read(path, max_bytes, filename)
        suffix = path.suffix.lower()
        if suffix in MESH_SUFFIXES:
            return merged(*parse_mesh(data, suffix, filename))[0]
        import trimesh

        loaded = trimesh.load(io.BytesIO(data), file_type=suffix[1:], force="mesh", process=False)
        return merged(loaded.vertices, loaded.faces)[0]
    except Exception:  # noqa: BLE001 - an unreadable mesh only gives no radius: the hand's kinematics do not need it
        return None


def _tree(model, file):
    """Each link's parent joint, after checking that the links form one tree."""
    parent_joint = {}
    for joint in model.joints:
        for link in (joint.parent, joint.child):
            if link not in model.links:
                raise InputError("invalid-urdf", f"joint {joint.name!r}: no link named {link!r}", file, joint.line)
        if joint.child in parent_joint:
            raise InputError("invalid-urdf", f"link {joint.child!r} is the child of two joints", file, joint.line)
        parent_joint[joint.child] = joint
    roots = [link for link in model.links if link not in parent_joint]
    if len(roots) != 1:
        raise InputError("invalid-urdf", f"expected one root link, found {len(roots)}: {', '.join(roots[:5])}", file)
    return parent_joint


def _path(model, parent_joint, tip, file):
    """The joints from the root to ``tip``."""
    if tip not in model.links:
        raise InputError("unknown-link", f"no link named {tip!r} in the URDF", file)
    path, link = [], tip
    while link in parent_joint:
        joint = parent_joint[link]
        if len(path) > len(parent_joint):  # every link has one parent, so only a cycle can get here
            raise InputError("invalid-urdf", f"the joints above link {tip!r} form a cycle", file, joint.line)
        path.append(joint)
        link = joint.parent
    return path[::-1]


def _finger(name, tip, path, file, joint_names):
    origins, axes, kinds, joints = [], [], [], []
    for joint in path:
        where = joint.line
        if joint.type in _UNSUPPORTED or joint.mimic:
            what = "a mimic joint" if joint.mimic else f"a {joint.type} joint"
            raise InputError("unsupported-joint", f"joint {joint.name!r} on finger {name!r} is {what}", file, where)
        kind = _MOVABLE.get(joint.type)
        if kind is None:
            raise InputError("invalid-urdf", f"joint {joint.name!r}: unknown type {joint.type!r}", file, where)
        axis = joint.axis
        if kind != "fixed" and not np.any(axis):
            raise InputError("invalid-urdf", f"joint {joint.name!r}: zero axis", file, where)
        origins.append(joint.origin)
        axes.append(axis)
        kinds.append(kind)
        if kind != "fixed":
            joints.append(_joint(joint, kind, where, file))
            joint_names.setdefault(joint.name, len(joint_names))
    screws, points, tip_pose = chain_from_origins(np.reshape(origins, (-1, 4, 4)), np.reshape(axes, (-1, 3)), kinds)
    # A prismatic joint lengthens the finger by up to its travel.
    travel = sum(max(abs(j.lower or 0.0), abs(j.upper or 0.0)) for j in joints if j.type == "prismatic")
    for array in (screws, points, tip_pose):
        array.flags.writeable = False
    return Finger(
        name=name,
        tip=tip,
        joints=tuple(joints),
        screws=screws,
        points=points,
        tip_pose=tip_pose,
        length=float(chain_length(points, tip_pose[:3, 3])) + travel,
        joint_index=tuple(joint_names[j.name] for j in joints),
    )


def _joint(joint, kind, line, file):
    limit = joint.limit
    velocity = None if limit is None else limit.velocity
    if velocity is not None and velocity < 0:
        raise InputError("invalid-urdf", f"joint {joint.name!r}: negative velocity limit {velocity}", file, line)
    bounded = limit is not None and joint.type != "continuous"
    return Joint(
        name=joint.name,
        type=kind,
        velocity_limit=velocity or None,  # URDFs write velocity="0" for "no limit"
        lower=limit.lower if bounded else None,
        upper=limit.upper if bounded else None,
        line=line,
    )
