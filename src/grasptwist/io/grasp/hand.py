"""The ``hand`` section of a grasp file: joint screws given inline, or a URDF.

Two forms (README, "Hands and joint rates"), never mixed:

* inline: ``fingers``, each a list of ``joints`` (``type``, ``axis``,
  ``point``, ``velocity_limit``) at the current configuration;
* URDF: ``urdf`` (a path relative to the grasp file, or ``package://``),
  ``joint_positions`` and ``fingers``, each naming the ``tip`` link that
  touches its contact.  Without ``joint_positions``, they are solved by
  inverse kinematics from ``seed`` (else every joint at 0): each finger's
  tip link origin on its contact, ``tip_radius`` behind it.

Either form takes ``tip_radius``, the radius of the fingertip's sphere about
the tip link's origin (or the point its last link touches), for the hand or
per finger (the finger's wins); a URDF finger without one gets its tip
link's spherical collision geometry's (:func:`grasptwist.io.urdf.load_urdf_hand`).

Checked with the loader's shared typed-value checks (:mod:`.values`), so
problems are located and coded like the rest of the format; a URDF's own problems
(:mod:`grasptwist.io.urdf`) are reported at the ``urdf`` key, the URDF's
file and line in the message.  The loader only reads: a URDF hand comes
with its :class:`~grasptwist.model.HandPlacement` (positions given or a
seed, and where each finger's ``tip`` stood), and the run layer puts it on
the contacts (:func:`grasptwist.run.placement.place`: the engine's inverse
kinematics and contact-off-finger check), reporting a finger that cannot
be placed at its ``tip``.
"""

from __future__ import annotations

import os
from dataclasses import replace
from pathlib import Path

import numpy as np
import yaml

from ...model import InputError
from ..limits import DEFAULT_MAX_BYTES
from .compose import PARSER, compose, syntax_error
from .problems import MAX_ERRORS, Problems, Reject, join, located
from .text import file_text
from .values import (
    Section,
    describe,
    read_entry_name,
    read_mapping,
    read_name,
    read_number,
    read_sequence,
    read_vector,
    readonly,
)

__all__ = [
    "load_hand_file",
    "HAND_KEYS",
    "INLINE_FINGER_KEYS",
    "URDF_FINGER_KEYS",
    "JOINT_KEYS",
    "JOINT_TYPES",
    "SECTION",
    "read_hand",
    "inline_hand",
]

HAND_KEYS = ("urdf", "joint_positions", "seed", "tip_radius", "fingers")
INLINE_FINGER_KEYS = ("name", "joints", "tip_radius")
URDF_FINGER_KEYS = ("name", "tip", "tip_radius")
JOINT_KEYS = ("name", "type", "axis", "point", "velocity_limit")
JOINT_TYPES = ("revolute", "prismatic")


def read_hand(node, points, file, problems, allow_outside=False, output=None):
    """``(Hand, joint positions, placement)`` of a ``hand`` node, or None after a problem.

    ``points`` are the contacts (None: a hand file, whose rows bring their own);
    ``file`` is the grasp file, whose folder a relative ``urdf`` path stays
    inside unless ``allow_outside`` (and which is not ``output``, the ``(device, inode)`` of the
    file ``-o`` replaces).  A URDF hand of a grasp file comes with its
    :class:`~grasptwist.model.HandPlacement` (the positions are then the ones
    given, or the seed), to be put on its contacts by the run layer; else the
    placement is None.
    """
    fields = read_mapping(node, "hand", HAND_KEYS, ("fingers",), problems)
    if fields is None:
        return None
    urdf = "urdf" in fields
    for key in ("joint_positions", "seed"):
        if not urdf and key in fields:
            problems.add(
                Reject(
                    "conflicting-keys",
                    f"hand.{key}",
                    "only with 'urdf' (inline joints are given at their current configuration)",
                    **located(fields[key]),
                )
            )
    if "seed" in fields and "joint_positions" in fields:
        problems.add(
            Reject(
                "conflicting-keys",
                "hand.seed",
                "only without 'joint_positions' (the seed is where inverse kinematics starts from)",
                **located(fields["seed"]),
            )
        )
    radius = _radius(fields, "hand", problems)
    items = read_sequence(fields["fingers"], "hand.fingers", problems) if "fingers" in fields else None
    if items is None:
        return None
    if len(items) != 3:
        problems.add(
            Reject(
                "finger-count",
                "hand.fingers",
                f"expected exactly 3 fingers (one per contact), got {len(items)}",
                **located(fields["fingers"]),
            )
        )
        return None
    keys, required = (URDF_FINGER_KEYS, ("tip",)) if urdf else (INLINE_FINGER_KEYS, ("joints",))
    other = "joints" if urdf else "tip"  # the other form's key: a mix-up, not a misspelling
    names, fingers = {}, []
    for i, item in enumerate(items):
        path = f"hand.fingers[{i}]"
        finger = read_mapping(item, path, (*keys, other), required, problems)
        if finger is None:
            continue
        if other in finger:
            problems.add(
                Reject(
                    "conflicting-keys",
                    f"{path}.{other}",
                    "mixes the two forms of a hand: "
                    + ("a URDF hand's fingers name their 'tip' link" if urdf else "'tip' needs 'urdf' in the hand"),
                    **located(finger[other]),
                )
            )
        read_entry_name(finger, item, "hand.fingers", i, names, problems)
        fingers.append(finger)
    radii = [_radius(f, f"hand.fingers[{i}]", problems) for i, f in enumerate(fingers)]
    if problems.count:
        return None
    names = list(names)
    radii = [radius if r is None else r for r in radii]  # the finger's, else the hand's (None: not given)
    if urdf:
        read = _urdf_hand(fields, fingers, names, points is None, file, problems, allow_outside, output)
    else:
        taken = {}  # joint names, unique over the hand
        joints = [_joints(f["joints"], f"hand.fingers[{i}]", names[i], taken, problems) for i, f in enumerate(fingers)]
        if problems.count:
            return None
        hand = inline_hand(names, joints, points)
        read = hand, np.zeros(len(hand.joint_names)), None
    if read is None:
        return None
    hand = read[0]
    given = tuple(f if r is None else replace(f, tip_radius=r) for f, r in zip(hand.fingers, radii))
    return (replace(hand, fingers=given), *read[1:])


def _radius(fields, path, problems):
    """The ``tip_radius`` of a hand's or finger's fields: a number at least 0, None when not given."""
    if "tip_radius" not in fields:
        return None
    node = fields["tip_radius"]
    radius = read_number(node, path + ".tip_radius", problems)
    if radius is not None and radius < 0:
        problems.add(
            Reject("invalid-radius", path + ".tip_radius", f"must be 0 or more, got {radius:g}", **located(node))
        )
        return None
    return radius


def _joints(node, path, finger, taken, problems):
    """An inline finger's joints as ``(name or None, type, axis, point, limit, line)`` tuples;
    ``taken`` maps the joint names so far (given, or ``<finger>.<k>``) to their paths."""
    items = read_sequence(node, path + ".joints", problems)
    if items is None:
        return None
    out = []
    for j, item in enumerate(items):
        where = f"{path}.joints[{j}]"
        fields = read_mapping(item, where, JOINT_KEYS, ("axis",), problems)
        if fields is None:
            continue
        name = read_name(fields["name"], where + ".name", problems) if "name" in fields else None
        final = f"{finger}.{j + 1}" if name is None else name
        if final in taken:
            named = "name" in fields
            problems.add(
                Reject(
                    "duplicate-name",
                    where + ".name" if named else where,
                    f"duplicate joint name {final!r} (also {taken[final]})",
                    **located(fields["name"] if named else item),
                )
            )
        else:
            taken[final] = where
        kind = read_name(fields["type"], where + ".type", problems) if "type" in fields else "revolute"
        if kind is not None and kind not in JOINT_TYPES:
            problems.add(
                Reject(
                    "unsupported-joint",
                    where + ".type",
                    f"expected one of: {', '.join(JOINT_TYPES)}, got {kind!r}",
                    **located(fields["type"]),
                )
            )
        axis = read_vector(fields["axis"], 3, where + ".axis", problems) if "axis" in fields else None
        if axis is not None and not any(axis):
            problems.add(
                Reject("zero-axis", where + ".axis", "a zero vector has no direction", **located(fields["axis"]))
            )
        point = read_vector(fields["point"], 3, where + ".point", problems) if "point" in fields else None
        if "point" not in fields and kind == "revolute":
            problems.add(
                Reject("missing-key", where + ".point", "a revolute joint needs a point on its axis", **located(item))
            )
        limit = (
            read_number(fields["velocity_limit"], where + ".velocity_limit", problems)
            if "velocity_limit" in fields
            else None
        )
        if limit is not None and limit <= 0:
            problems.add(
                Reject(
                    "invalid-limit",
                    where + ".velocity_limit",
                    f"must be positive, got {limit:g}",
                    **located(fields["velocity_limit"]),
                )
            )
        out.append((name, kind, axis, point, limit, item.line))
    return out


def inline_hand(names, fingers, points):
    """A :class:`~grasptwist.model.Hand` from joints given at the current configuration.

    Parameters
    ----------
    names : sequence of 3 str
        Finger names.
    fingers : sequence of 3 lists
        Each finger's joints, base to tip, as ``(name or None, type, axis,
        point or None, velocity limit or None, line)``; a joint without a
        name is ``"<finger>.<k>"``, a prismatic joint without a point is
        drawn through the contact.
    points : (3, 3) array or None
        The contacts, finger ``f`` touching row ``f``: each finger's length
        runs from its first joint to its contact.  None (a hand file): to
        its last joint, and a prismatic joint without a point is drawn
        through the origin.

    Returns
    -------
    Hand

    >>> h = inline_hand(["a", "b", "c"], [[(None, "revolute", [0, 0, 2], [0, 0, 0], 3.0, 1)]] * 3, np.eye(3))
    >>> h.joint_names, h.fingers[0].screws.tolist(), h.fingers[1].length
    (('a.1', 'b.1', 'c.1'), [[0.0, 0.0, 1.0, 0.0, 0.0, 0.0]], 1.0)
    """
    # a hand's kinematics and types load with the first hand: grasp files without one never pay for them
    from ...engine.kinematics import chain_length, joint_screw
    from ...model.hands import Finger, Hand, Joint

    out, joint_names = [], []
    contacts = [None] * 3 if points is None else np.asarray(points, dtype=float)
    for name, joints, contact in zip(names, fingers, contacts, strict=True):
        first = len(joint_names)
        made = []
        for k, (joint, kind, _, _, limit, line) in enumerate(joints):
            made.append(Joint(joint or f"{name}.{k + 1}", kind, limit, None, None, line))
            joint_names.append(made[-1].name)
        through = np.zeros(3) if contact is None else contact
        at = np.array([through if p is None else p for _, _, _, p, _, _ in joints], dtype=float).reshape(-1, 3)
        screws = joint_screw(np.reshape([j[2] for j in joints], (-1, 3)), at, [j[1] == "prismatic" for j in joints])
        for a in (screws, at):
            a.flags.writeable = False
        out.append(
            Finger(
                name=name,
                tip=None,
                joints=tuple(made),
                screws=screws,
                points=at,
                tip_pose=None,
                length=float(chain_length(at, at[-1] if contact is None else contact)),
                joint_index=tuple(range(first, len(joint_names))),
            )
        )
    return Hand(tuple(out), tuple(joint_names), None, None)


def _urdf_hand(fields, fingers, names, hand_file, file, problems, allow_outside=False, output=None):
    """The URDF form: load the hand, with its ``joint_positions`` (checked on the contacts later)
    or ``seed`` (solved from later) and where each finger's tip stands in the file; in a hand file
    (``hand_file``), at its joint positions."""
    # URDF reading loads with the first such hand (bench/startup.py)
    from ...engine.hands import joint_positions
    from ...model.hands import HandPlacement
    from ..urdf import finger_problems, load_urdf_hand

    node = fields["urdf"]
    reference = read_name(node, "hand.urdf", problems)
    given = "joint_positions" in fields
    key = "joint_positions" if given else "seed"
    positions = _positions(fields.get(key), key, problems)
    tips = [read_name(f["tip"], f"hand.fingers[{i}].tip", problems) for i, f in enumerate(fingers)]
    if problems.count:
        return None
    folder = Path(file).parent if not file.startswith("<") else Path.cwd()
    try:
        hand = load_urdf_hand(
            reference, tips, names=names, folder=folder, allow_outside=allow_outside, output=output, check=False
        )
    except InputError as err:
        problems.add(Reject(err.code, "hand.urdf", str(err), **located(node)))
        return None
    hand = replace(hand, urdf_at=(file, node.line, node.column))  # where its meshes' problems are reported
    for f, code, message, _ in finger_problems(hand):  # a finger inverse kinematics cannot place, at its tip
        problems.add(Reject(code, f"hand.fingers[{f}].tip", message, **located(fingers[f]["tip"])))
    values = {}
    for name, (value, key_node) in positions.items():
        if name not in hand.joint_names:
            problems.add(
                Reject(
                    "unknown-joint",
                    f"hand.{key}.{name}",
                    f"not a joint of the hand's fingers ({', '.join(hand.joint_names)})",
                    **located(key_node),
                )
            )
        values[name] = value
    if problems.count:
        return None
    q = joint_positions(hand, values)
    if hand_file:  # the contacts come with each row
        if "seed" in fields:  # not silently dropped: --hand's rows are solved from home
            problems.add(
                Reject(
                    "conflicting-keys",
                    "hand.seed",
                    "only in a grasp file (a data set's rows without joint_positions are solved from every joint at 0)",
                    **located(fields["seed"]),
                )
            )
            return None
        return hand, q, None
    tips = tuple((f["tip"].line, f["tip"].column) for f in fingers)
    return hand, q, HandPlacement(given=given, tips=tips)


def _positions(node, key, problems):
    """``{joint: (position, key node)}`` of ``joint_positions`` or ``seed`` (``key``; empty when not given)."""
    if node is None or node.kind == "invalid":
        return {}
    if node.kind != "mapping":
        problems.add(
            Reject(
                "not-a-mapping",
                f"hand.{key}",
                f"expected a mapping of joint names to positions, got {describe(node)}",
                **located(node),
            )
        )
        return {}
    out = {}
    for name, (key_node, value) in node.value.items():
        number = read_number(value, join(f"hand.{key}", name), problems)
        if number is not None:
            out[str(name)] = (number, key_node)
    return out


def load_hand_file(path, *, max_bytes=DEFAULT_MAX_BYTES):
    """The hand of a YAML file that holds just a ``hand:`` mapping (``--hand``).

    Checked like a grasp file's ``hand`` (without contacts, so without
    ``contact-off-finger``: a data set's rows bring their own).

    Returns
    -------
    (Hand, (n_joints,) joint positions)

    Raises
    ------
    InputError
        The file's first problem, located and coded like a grasp file's.
    """
    file = os.fspath(path)
    problems = Problems(MAX_ERRORS)
    text = ""
    try:
        text = file_text(path, False, max_bytes)
        parser = PARSER(text)
        try:
            parser.get_event()  # StreamStartEvent
            if parser.check_event(yaml.StreamEndEvent):
                raise Reject("empty-document", "", "no YAML document in the file")
            parser.get_event()  # DocumentStartEvent
            root = compose(parser.get_event, problems)
        finally:
            parser.dispose()
    except Reject as reject:
        raise reject.error(file, None) from None
    except yaml.YAMLError as exc:
        raise syntax_error(exc, text).error(file, 0) from None
    fields = read_mapping(root, "", ("hand",), ("hand",), problems)
    hand = read_hand(fields["hand"], None, file, problems) if fields and "hand" in fields else None
    if problems.count:
        raise problems.first()[0][0].error(file, 0)
    return hand[:2]


def _read(fields, found, problems):
    if "hand" not in fields:
        return {}
    reading = found["reading"]
    hand = read_hand(
        fields["hand"], found.get("points"), found["file"], problems, reading.allow_outside, reading.output
    )
    if hand is None:
        return None
    out = {"hand": hand[0], "joint_positions": readonly(hand[1]), "placement": hand[2]}
    obj = found.get("object")
    if obj is not None:  # an object a hand 10 times too small or too big: a unit mixed up
        from ...engine.units import fingers_reach, hand_fit_warning, largest_extent

        said = hand_fit_warning(
            largest_extent(obj.shape.kind, obj.shape.size, obj.shape.vertices),
            fingers_reach(hand[0]),
            found.get("units"),
            urdf=hand[0].source is not None,
        )
        out["warnings"] = (*found.get("warnings", ()), *([said] if said else []))
    return out


SECTION = Section(("hand",), _read)
