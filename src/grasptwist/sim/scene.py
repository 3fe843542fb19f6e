r"""A grasp as a MuJoCo scene (MJCF): the object, the table, and the hand at the grasp.

- **Object**: a body with a free joint at the object's pose.  A primitive is one geom
  (MuJoCo's box, sphere, cylinder and capsule take half sizes); a mesh collides as convex
  pieces (:func:`convex_pieces`: MuJoCo collides a mesh's convex hull only).  Its mass,
  centre and inertia are those of the solid (:func:`mass_geom`: the one geom that carries
  them, MuJoCo integrating the solid exactly), uniform density.
- **Table** and **boxes** (the grasp file's ``environment``): a plane ``z = table_height``
  (normal +z) when asked for, and boxes.  They are there for the hand, never to carry the
  object (:data:`COLLIDES`): the fingertips touch them, the object passes through them, so
  that a hold test or a path credits the fingers alone.
- **Hand**: a URDF hand read by MuJoCo's URDF reader (:func:`_with_urdf_hand`: the description
  and its meshes, which the run layer reads); otherwise built from grasptwist's own model of it
  (joints given inline): each joint a hinge or a slide through its point along its axis, with
  its limits; nested bodies whose frames coincide with the grasp frame at home (the product of
  exponentials).  Links are capsules between successive joints, for
  the eye only (grasptwist checks the links against the object itself,
  ``finger-collides``); each fingertip is a sphere of the finger's tip radius touching its
  contact (:data:`POINT_TIP` of the object's size for a point tip).  A grasp without a hand
  gets three such spheres, each on three slides (x, y, z).
- Every finger body compensates its own gravity (MuJoCo's ``gravcomp``); the object does too
  when the caller applies its load itself (the hold test).

The contact settings are :mod:`.contact`'s.
"""

from __future__ import annotations

import os
import struct
from dataclasses import dataclass

import numpy as np

from ..engine.fingertips import tip_centers
from ..engine.hands import tip_poses
from ..engine.objects.geometry import object_size
from ..engine.se3 import matrix_to_quaternion
from ..extras import require
from ..model import Grasp, GraspObject
from .contact import CONTACT, ContactSettings, option_xml, tip_friction

__all__ = [
    "Scene",
    "Drive",
    "build_scene",
    "convex_pieces",
    "mass_geom",
    "stl_bytes",
    "POINT_TIP",
    "OBJECT",
    "TIP",
    "COLLIDES",
]

#: Each finger link's and fingertip's mass, as a fraction of the object's (their gravity is
#: compensated and their joints' armature outweighs them: they barely matter).
PART = 0.05

#: Most convex pieces a mesh object collides as (:func:`convex_pieces`).
MAX_PIECES = 32

#: A point tip's sphere radius, as a fraction of the object's size (MuJoCo needs a radius).
POINT_TIP = 0.02

#: The object's colour in MuJoCo's viewer.
OBJECT_RGBA = "0.95 0.55 0.15 1"

#: Names in the scene: the object's body, and fingertip ``f``'s geom (``TIP.format(f)``).
OBJECT, TIP = "object", "tip{}"

#: Each colliding part's MuJoCo ``(contype, conaffinity)`` bits: two geoms collide when one's
#: ``contype`` shares a bit with the other's ``conaffinity``.  The object touches the fingertips
#: only; the environment (table, boxes) touches the fingertips only; the fingertips touch all,
#: each other too.  So the environment never supports the object (a grasp that "holds" only on
#: its table does not hold), and a finger cannot go through it.
COLLIDES = {"object": (1, 2), "tip": (2, 7), "environment": (4, 2)}


def _bits(part: str) -> str:
    contype, conaffinity = COLLIDES[part]
    return f'contype="{contype}" conaffinity="{conaffinity}"'


@dataclass(frozen=True)
class Drive:
    """How stiffly each joint is held about the grasp: joint stiffness, damping and armature.

    ``stiffness`` (per joint) lets the whole load move the tip by :data:`COMPLIANCE` times the
    distance tolerance: a spring about the grasp that keeps the fingers where they are, soft
    enough that following the object by the contacts' compression (hundredths of a millimetre)
    costs a small part of the grip, so that the grip's torques, not the springs, hold the
    object.  Measured on the bundled grasps (``docs/guide/simulation.md``): 20 times stiffer, a
    finger lets go where the object sinks into the others; 5 times softer, the fingertips give
    way sideways and a ball rolls between them;
    The hold test stiffens each direction's drive by its largest finger force over the load,
    when above 1 (:func:`grasptwist.sim.hold.hold_test`);
    ``armature`` makes that stiffness stable at the time step (``omega dt = STABLE``); damping
    is critical.
    """

    stiffness: np.ndarray
    damping: np.ndarray
    armature: np.ndarray


#: The tip's deflection under the whole load, in distance tolerances (:class:`Drive`).
COMPLIANCE = 2.0

#: The drive's natural frequency times the time step (well inside explicit stability, 2).
STABLE = 0.2


@dataclass(frozen=True, eq=False)
class Scene:
    """An MJCF scene and what the simulation needs to know of it.

    Attributes
    ----------
    xml : str
        The MJCF document.
    assets : dict of str to bytes
        Its mesh files by name (binary STL), beside it.
    joints : tuple of str
        The hand's joints in the scene, in ``hand.joint_names`` order (three slides per tip without a hand).
    positions : (n,) array
        Their positions at the grasp.
    mass : float
        The object's mass.
    radii : (3,) array
        The fingertips' radii in the scene.
    """

    xml: str
    assets: dict
    joints: tuple[str, ...]
    positions: np.ndarray
    mass: float
    radii: np.ndarray


def _v(values) -> str:
    return " ".join(f"{float(v):.17g}" for v in np.asarray(values, dtype=float).ravel())


def stl_bytes(vertices, faces) -> bytes:
    """A binary STL of a triangle mesh (float32, as every STL).

    >>> len(stl_bytes(np.eye(3), [[0, 1, 2]]))
    134
    """
    v = np.asarray(vertices, dtype=np.float32)[np.asarray(faces)]
    rows = np.zeros(len(v), dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
    rows["v"] = v
    return b"\0" * 80 + struct.pack("<I", len(v)) + rows.tobytes()


def convex_pieces(vertices, faces) -> list[tuple[np.ndarray, np.ndarray]]:
    """The convex pieces a mesh collides as in MuJoCo: CoACD's decomposition (the ``sim`` extra).

    CoACD (Wei et al., SIGGRAPH 2022) cuts a mesh where its concavity exceeds a threshold
    and keeps the collision-aware pieces; its default threshold (0.05 of the size) keeps a
    convex mesh in one piece.  At most :data:`MAX_PIECES` pieces (time and memory bounded),
    seeded (the same pieces every run).  Each piece is returned as ``(vertices, faces)``.
    """
    coacd = require("coacd", "a mesh object in grasptwist simulate")
    coacd.set_log_level("error")
    mesh = coacd.Mesh(np.asarray(vertices, dtype=float), np.asarray(faces, dtype=np.int64))
    pieces = coacd.run_coacd(mesh, max_convex_hull=MAX_PIECES, seed=0)
    return [(np.asarray(v, float), np.asarray(f, int)) for v, f in pieces]


def mass_geom(obj: GraspObject, mass: float) -> tuple[str, dict]:
    """The geom that carries the object's mass (its element, and mesh assets): the solid itself.

    MuJoCo computes a geom's centre and inertia from its shape at uniform density, exactly
    for a primitive and for a closed mesh (``inertia="exact"``), so the body's mass
    properties are the solid's.  One function, so that an inertia tensor computed elsewhere
    can replace it with an ``<inertial>`` element.
    """
    shape = obj.shape
    if shape.kind == "mesh":
        geom = f'<geom name="solid" type="mesh" mesh="solid" mass="{mass:.17g}" contype="0" conaffinity="0" group="1"/>'
        return geom, {"solid.stl": stl_bytes(shape.vertices, shape.faces)}
    return "", {}  # a primitive's one geom carries it (_object_geoms)


def _primitive(kind, size) -> str:
    """MuJoCo's size of a primitive: a box's half edges, a sphere's radius, a cylinder's or capsule's
    radius and half height (between its caps' centres: both conventions agree)."""
    half = size / 2 if kind == "box" else (size[:1] if kind == "sphere" else np.array([size[0], size[1] / 2]))
    return f'type="{kind}" size="{_v(half)}"'


def _object_geoms(obj: GraspObject, mass: float, pieces=None) -> tuple[str, dict, str]:
    """The object's geoms, mesh assets and mesh elements."""
    shape = obj.shape
    carrier, assets = mass_geom(obj, mass)
    if shape.kind != "mesh":
        return (
            f'<geom name="piece0" {_primitive(shape.kind, shape.size)} mass="{mass:.17g}" friction="0 0 0" {_bits("object")} rgba="{OBJECT_RGBA}"/>',
            {},
            "",
        )
    pieces = convex_pieces(shape.vertices, shape.faces) if pieces is None else pieces
    geoms, meshes = [carrier], ['<mesh name="solid" file="solid.stl" inertia="exact"/>']
    for k, (v, f) in enumerate(pieces):
        assets[f"piece{k}.stl"] = stl_bytes(v, f)
        meshes.append(f'<mesh name="piece{k}" file="piece{k}.stl"/>')
        geoms.append(
            f'<geom name="piece{k}" type="mesh" mesh="piece{k}" density="0" friction="0 0 0" {_bits("object")} rgba="{OBJECT_RGBA}"/>'
        )
    return "\n".join(geoms), assets, "\n".join(meshes)


def _drive(lever, load, tolerance, timestep, compliance=COMPLIANCE) -> Drive:
    """Joint stiffness from each joint's lever to its tip (NaN: a slide): the tip moves
    ``COMPLIANCE * tolerance`` under ``load`` (``k = load / (COMPLIANCE * tolerance)`` at the tip and on
    a slide, ``k r^2`` at a hinge ``r`` from the tip)."""
    k = load / (compliance * tolerance) * np.where(np.isnan(lever), 1.0, np.maximum(lever, tolerance) ** 2)
    armature = k * (timestep / STABLE) ** 2
    return Drive(k, 2 * np.sqrt(k * armature), armature)


def _joint_xml(name, kind, point, axis, limits, drive, i, q0) -> str:
    lo, hi = limits
    limited = f' limited="true" range="{lo:.17g} {hi:.17g}"' if lo is not None and hi is not None else ""
    return (
        f'<joint name="{name}" type="{kind}" pos="{_v(point)}" axis="{_v(axis)}"{limited} '
        f'stiffness="{drive.stiffness[i]:.17g}" springref="{q0:.17g}" damping="{drive.damping[i]:.17g}" '
        f'armature="{drive.armature[i]:.17g}"/>'
    )


def _tip_geom(f, centre, radius, mu, mass, torsion=None) -> str:
    friction, condim = tip_friction(mu, torsion)
    return (
        f'<geom name="{TIP.format(f)}" type="sphere" size="{radius:.17g}" pos="{_v(centre)}" '
        f'friction="{_v(friction)}" condim="{condim}" mass="{mass:.17g}" {_bits("tip")} rgba="0.2 0.4 0.9 1"/>'
    )


def _hand_drive(grasp, centres, load, tolerance, timestep, compliance):
    """Each finger's tip body frame at the grasp, ``g_f(q)`` (the product of exponentials), and the
    hand's :class:`Drive` from each joint's lever to its fingertip's centre."""
    hand = grasp.hand
    q = np.asarray(grasp.joint_positions, dtype=float)
    moved = tip_poses(hand, q, np.tile(np.eye(4), (3, 1, 1)))
    lever = np.zeros(len(hand.joint_names))
    for f, finger in enumerate(hand.fingers):
        reach = np.linalg.norm(finger.points - (np.linalg.inv(moved[f]) @ np.append(centres[f], 1))[:3], axis=1)
        lever[list(finger.joint_index)] = np.where([j.type == "prismatic" for j in finger.joints], np.nan, reach)
    return moved, _drive(lever, load, tolerance, timestep, compliance)


def _hand_xml(grasp, radii, mu, torsion, load, tolerance, timestep, part, compliance) -> tuple[str, tuple, np.ndarray]:
    """The fingers' bodies (each link and tip of mass ``part``), their joint names and positions at the grasp."""
    hand = grasp.hand
    centres = tip_centers(grasp.points, grasp.normals, radii)
    if hand is None:  # three free fingertips, each on three slides
        drive = _drive(np.full(9, np.nan), load, tolerance, timestep, compliance)
        bodies, names = [], []
        for f in range(3):
            joints = [
                _joint_xml(f"tip{f}_{a}", "slide", centres[f], np.eye(3)[i], (None, None), drive, 3 * f + i, 0.0)
                for i, a in enumerate("xyz")
            ]
            names += [f"tip{f}_{a}" for a in "xyz"]
            body = "\n".join(joints) + "\n" + _tip_geom(f, centres[f], radii[f], mu[f], part, torsion[f])
            bodies.append(f'<body name="finger{f}" gravcomp="1">\n{body}\n</body>')
        return "\n".join(bodies), tuple(names), np.zeros(9)
    q = np.asarray(grasp.joint_positions, dtype=float)
    moved, drive = _hand_drive(grasp, centres, load, tolerance, timestep, compliance)
    bodies = []
    for f, finger in enumerate(hand.fingers):
        home_centre = (np.linalg.inv(moved[f]) @ np.append(centres[f], 1))[:3]
        ends = np.vstack([finger.points, home_centre])
        opened = []
        for k, (joint, i) in enumerate(zip(finger.joints, finger.joint_index)):
            screw = finger.screws[k]
            kind = "slide" if joint.type == "prismatic" else "hinge"
            axis = screw[3:] if kind == "slide" else screw[:3]
            # each link's mass at its joint (a link may be of zero length: joints through one point)
            inertia = part * radii[f] ** 2
            link = f'<inertial pos="{_v(ends[k])}" mass="{part:.17g}" diaginertia="{_v([inertia] * 3)}"/>'
            if np.linalg.norm(ends[k + 1] - ends[k]) > 0:
                link += (
                    f'\n<geom type="capsule" fromto="{_v(ends[k])} {_v(ends[k + 1])}" size="{radii[f] / 2:.17g}" '
                    'contype="0" conaffinity="0" group="1"/>'
                )
            opened.append(
                f'<body name="f{f}_link{k}" gravcomp="1">\n'
                + _joint_xml(f"joint{i}", kind, finger.points[k], axis, (joint.lower, joint.upper), drive, i, q[i])
                + f"\n{link}"
            )
        tip = _tip_geom(f, home_centre, radii[f], mu[f], part, torsion[f])
        bodies.append("\n".join(opened) + "\n" + tip + "\n" + "</body>" * len(opened))
    return "\n".join(bodies), tuple(f"joint{i}" for i in range(len(hand.joint_names))), q


#: The prefix of a URDF hand's names in the scene.
HAND = "hand/"


def _with_urdf_hand(xml, grasp, urdf, radii, mu, torsion, load, tolerance, timestep, compliance, part):
    """The scene ``xml`` with the hand as MuJoCo reads its URDF (``(text, meshes by file name)``):
    its links' own masses and inertias, their meshes drawn but not colliding, each joint driven as
    :class:`Drive` says, each tip link carrying a fingertip sphere at its origin.  The MJCF, its
    mesh files, the hand's joints in the scene and their positions at the grasp."""
    mujoco = require("mujoco", "grasptwist simulate")
    text, meshes = urdf
    hand = grasp.hand
    try:
        spec = mujoco.MjSpec.from_string(text, assets=meshes)
    except ValueError as exc:  # MuJoCo's URDF reader: its reason, with the line
        raise ValueError(f"MuJoCo cannot read the URDF {hand.source}: {exc}") from None
    q = np.asarray(grasp.joint_positions, dtype=float)
    _, drive = _hand_drive(
        grasp, tip_centers(grasp.points, grasp.normals, radii), load, tolerance, timestep, compliance
    )
    for i, name in enumerate(hand.joint_names):
        joint = spec.joint(name)
        joint.stiffness, joint.damping = [drive.stiffness[i], 0, 0], [drive.damping[i], 0, 0]
        joint.armature, joint.springref = drive.armature[i], q[i]
    for body in spec.bodies:
        body.gravcomp = 1
    for geom in spec.geoms:
        geom.contype = geom.conaffinity = 0
        geom.group = 1
    scene = mujoco.MjSpec.from_string(xml)
    scene.attach(spec, frame=scene.worldbody.add_frame(), prefix=HAND)
    for f, finger in enumerate(hand.fingers):
        friction, condim = tip_friction(mu[f], torsion[f])
        scene.body(HAND + finger.tip).add_geom(
            name=TIP.format(f),
            type=mujoco.mjtGeom.mjGEOM_SPHERE,
            size=[radii[f], 0, 0],
            friction=list(friction),
            condim=condim,
            mass=part,
            contype=COLLIDES["tip"][0],
            conaffinity=COLLIDES["tip"][1],
            rgba=[0.2, 0.4, 0.9, 1],
        )
    for mesh in scene.meshes:  # beside the scene, by file name (as MuJoCo's URDF reader finds them)
        mesh.file = os.path.basename(mesh.file)
    files = {os.path.basename(name): data for name, data in meshes.items()}
    try:
        xml = scene.to_xml()  # compiles: a mesh it cannot open or read fails here
    except ValueError as exc:
        raise ValueError(f"MuJoCo cannot read the URDF {hand.source}: {exc}") from None
    return xml, files, tuple(HAND + name for name in hand.joint_names), q


def build_scene(
    grasp: Grasp,
    *,
    mass: float,
    friction,
    load: float,
    tolerance: float,
    torsion=None,
    table_height: float | None = None,
    table_friction: float | None = None,
    boxes=(),
    urdf=None,
    gravity=(0.0, 0.0, -9.81),
    object_gravcomp: bool = True,
    compliance: float = COMPLIANCE,
    settings: ContactSettings = CONTACT,
    pieces=None,
) -> Scene:
    """The MJCF scene of ``grasp`` (module docstring): object, table, hand at its joint positions.

    Parameters
    ----------
    grasp : Grasp
        With an ``object``; its hand placed (joint positions solved), or none.
    mass : float
        The object's mass.
    friction : (3,) array
        Each contact's ``mu``, carried by its fingertip.
    torsion : (3,) array or None
        Each contact's torsional radius ``e`` (0: a point contact; None: all are): a soft
        contact's fingertip carries MuJoCo's torsional friction ``mu e`` (``condim`` 4,
        :func:`~grasptwist.sim.contact.tip_friction`).
    load, tolerance : float
        The largest load on the object and the distance it may move: the joints' stiffness.
    table_height : float or None
        A table plane at this height (None: none), with ``table_friction`` (default: the least ``mu``).
    boxes : sequence of Obstacle
        Boxes (``grasptwist.model.Obstacle``: edge lengths and pose), with the table's friction.
    urdf : (str, dict) or None
        A URDF hand's description and its mesh files by file name
        (:func:`grasptwist.io.urdf_meshes.urdf_files`): MuJoCo reads the hand from them (else it is
        built from grasptwist's model of it, as an inline hand is).
    gravity : (3,) array
    object_gravcomp : bool
        The object's weight compensated (the hold test applies its load itself).
    compliance : float
        How far the whole load moves a fingertip against its joints' springs, in ``tolerance``
        (:class:`Drive`; a path's execution tracks the fingers' targets more stiffly).
    pieces : list of (vertices, faces) or None
        A mesh object's convex pieces, given (else :func:`convex_pieces`).

    Returns
    -------
    Scene
    """
    obj = grasp.object
    size = object_size(obj)
    mu = np.broadcast_to(np.asarray(friction, dtype=float), (3,))
    radii = np.array([f.tip_radius for f in grasp.hand.fingers]) if grasp.hand is not None else np.zeros(3)
    radii = np.where(radii > 0, radii, POINT_TIP * size)
    torsion = np.zeros(3) if torsion is None else np.broadcast_to(np.asarray(torsion, dtype=float), (3,))
    geoms, assets, meshes = _object_geoms(obj, mass, pieces)
    by_urdf = urdf is not None and grasp.hand is not None and grasp.hand.source is not None
    hand, joints, q = (
        ("", (), None)
        if by_urdf
        else _hand_xml(grasp, radii, mu, torsion, load, tolerance, settings.timestep, PART * mass, compliance)
    )
    tmu = float(np.min(mu)) if table_friction is None else table_friction
    table = "".join(
        f'<geom name="box{k}" type="box" pos="{_v(box.pose[:3, 3])}" quat="{_v(matrix_to_quaternion(box.pose[:3, :3]))}" '
        f'size="{_v(np.asarray(box.size, float) / 2)}" friction="{tmu:.17g} 0 0" {_bits("environment")} rgba="0.6 0.6 0.6 1"/>\n'
        for k, box in enumerate(boxes)
    )
    if table_height is not None:
        table += f'<geom name="table" type="plane" size="0 0 1" pos="0 0 {table_height:.17g}" friction="{tmu:.17g} 0 0" {_bits("environment")} rgba="0.8 0.8 0.75 1"/>'
    pose = obj.pose
    xml = f"""<mujoco model="{_attribute(grasp.name)}">
<compiler angle="radian"/>
{option_xml(gravity, settings)}
<visual><headlight ambient="0.35 0.35 0.35" diffuse="0.6 0.6 0.6"/></visual>
<asset>
{meshes}
</asset>
<worldbody>
<light pos="0 0 {10 * size:.17g}" dir="0 0 -1" directional="true"/>
{table}
<body name="{OBJECT}" pos="{_v(pose[:3, 3])}" quat="{_v(matrix_to_quaternion(pose[:3, :3]))}" gravcomp="{int(object_gravcomp)}">
<freejoint name="{OBJECT}"/>
{geoms}
</body>
{hand}
</worldbody>
</mujoco>
"""
    if by_urdf:
        xml, files, joints, q = _with_urdf_hand(
            xml, grasp, urdf, radii, mu, torsion, load, tolerance, settings.timestep, compliance, PART * mass
        )
        assets = {**assets, **files}
    return Scene(xml, assets, joints, q, float(mass), radii)


def _attribute(text: str) -> str:
    return text.replace("&", "&amp;").replace('"', "&quot;").replace("<", "&lt;")
