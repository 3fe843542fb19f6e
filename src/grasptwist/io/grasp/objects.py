"""The ``object`` section: the shape the fingers hold, and the contacts put on its surface.

One shape, a primitive centred at the object's origin or a mesh file::

    object:
      box: [0.065, 0.065, 0.065]        # edge lengths along x, y, z
      # or  sphere: 0.03                # radius
      # or  cylinder: {radius: 0.03, height: 0.1}      # axis z
      # or  capsule: {radius: 0.03, height: 0.1}       # height: between the caps' centres
      # or  mesh: meshes/bottle.stl     # STL, OBJ or PLY beside the grasp file
      #     scale: 0.001                # a mesh's units to the grasp's (a number, or 3)
      # or  mesh: {file: meshes/bottle.stl, units: mm}   # the mesh file's own unit (or scale:)
      pose: {position: [0, 0, 0.1], rotation: [1, 0, 0, 0]}   # as a path's pose target
      density: 700                      # kg/m^3 (or mass: 0.2 kg, not both)

Lengths stay in the grasp file's unit (``units``, metres without it); a ``density`` in kg/m^3
weighs the volume through that unit's length (:mod:`grasptwist.engine.units`), and a mesh
with its own ``units`` is scaled into it.  The object is checked by the engine's one gate,
:func:`~grasptwist.engine.objects.checks.checked`, as an object built in Python is.

With an object a contact may leave out its ``normal``: its point is then
put on the surface (the nearest point) and its normal is the inward normal
there.  A contact that gives its normal stays as written (the user's point
and direction), checked against the surface.  A point farther from the surface than the tolerance
(``Reading.surface_tol`` times the object's size; ``--surface-tol``) is
``contact-off-surface``; a given normal pointing out of the object is
``outward-normal``.  Two warnings are found here too, where their places are known, and
carried in ``Grasp.warnings``: a given normal far from the surface's (``normal-disagrees``)
and a pose's rotation vector over pi (``rotation-over-pi``, as a path's).  The geometry is :mod:`grasptwist.engine.objects`'; a
mesh is read by :mod:`grasptwist.io.mesh_file`.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from ...engine.units import LENGTH_UNITS
from ...model import GraspObject, InputError, Shape
from .paths import read_pose
from .problems import Reject, join, located
from .values import Section, read_mapping, read_name, read_number, read_vector, readonly

__all__ = [
    "OBJECT_KEYS",
    "SHAPE_KEYS",
    "SIZE_KEYS",
    "MESH_KEYS",
    "UNKNOWN_UNITS",
    "SECTION",
    "read_object",
    "on_surface",
    "mesh_solid",
]

#: The shapes, one of which an object gives.
SHAPE_KEYS = ("box", "sphere", "cylinder", "capsule", "mesh")
OBJECT_KEYS = (*SHAPE_KEYS, "scale", "pose", "density", "mass")
#: The keys of a cylinder's or capsule's size.
SIZE_KEYS = ("radius", "height")
#: The keys of a mesh given as a mapping: its file, and its own unit or scale.
MESH_KEYS = ("file", "units", "scale")
#: The error of a unit whose length is needed but not known (a label such as ``units: px``).
UNKNOWN_UNITS = "unknown-units"


def read_object(node, file, reading, problems, warnings, units=None, hand=False):
    """The :class:`~grasptwist.model.GraspObject` of an ``object`` node (None after a problem);
    a mesh is read from ``file``'s folder within ``reading``'s limits, in the
    grasp file's ``units`` (a density weighs the volume through them).  A pose's rotation vector
    over pi adds its ``rotation-over-pi`` warning to ``warnings``, as a path's; a mesh whose size
    is unlikely in its unit, without a ``hand`` to compare with, ``mesh-size-unlikely``."""
    fields = read_mapping(node, "object", OBJECT_KEYS, (), problems)
    if fields is None:
        return None
    shapes = [key for key in fields if key in SHAPE_KEYS]  # in the file's order: the first is kept
    if not shapes:
        problems.add(Reject("missing-key", "object", f"needs one shape: {', '.join(SHAPE_KEYS)}", **located(node)))
    for key in shapes[1:]:
        problems.add(
            Reject(
                "conflicting-keys",
                f"object.{key}",
                f"cannot be combined with '{shapes[0]}' (an object has one shape)",
                **located(fields[key]),
            )
        )
    if "scale" in fields and "mesh" not in fields:
        problems.add(Reject("conflicting-keys", "object.scale", "only with 'mesh'", **located(fields["scale"])))
    if "density" in fields and "mass" in fields:
        problems.add(
            Reject(
                "conflicting-keys",
                "object.mass",
                "cannot be combined with 'density' (give the mass, or the density it follows from)",
                **located(fields["mass"]),
            )
        )
    density, mass = (
        _positive(fields[key], f"object.{key}", problems) if key in fields else None for key in ("density", "mass")
    )
    pose = np.eye(4)
    if "pose" in fields:
        read = read_pose(fields["pose"], "object.pose", problems)
        if read is not None:
            pose[:3, 3], pose[:3, :3] = read[0], read[1]
            warnings += _radians(read[2])
    shape = _shape(shapes[0], fields, file, reading, problems, warnings, units) if shapes else None
    if shape is None or problems.count:
        return None
    pose.setflags(write=False)
    from ...engine.objects import mass_properties
    from ...engine.objects.checks import ObjectError, accept, checked
    from ...engine.units import largest_extent, mesh_span_warning, unit_length

    try:
        with np.errstate(over="ignore", invalid="ignore"):  # a size that overflows is the gate's non-finite
            obj = checked(GraspObject(shape, pose, mass=mass, density=density, line=node.line))
    except ObjectError as err:
        problems.add(Reject(err.code, "object", str(err), **located(node)))
        return None
    if shape.kind == "mesh" and not hand:
        said = mesh_span_warning(largest_extent("mesh", None, obj.shape.vertices), units)
        warnings += [said] if said else []
    if density is None:
        return obj
    metres = unit_length(units)
    if metres is None:
        problems.add(
            Reject(
                UNKNOWN_UNITS,
                "object.density",
                f"a density is in kg/m^3: weighing the object needs the length of the file's units, "
                f"and {units!r} is none of {', '.join(LENGTH_UNITS)} (give its mass in kg instead)",
                **located(fields["density"]),
            )
        )
        return None
    try:
        with np.errstate(over="ignore", invalid="ignore"):
            weighed = float(mass_properties(obj).mass) * metres**3
    except OverflowError:  # a volume beyond a double, in Python floats
        weighed = math.inf
    if not 0 < weighed < math.inf:
        where = fields["density"]
        problems.add(
            Reject(
                "non-finite" if weighed else "invalid-mass",
                "object.density",
                f"the mass (density x volume) {'overflows' if weighed else 'underflows'} double precision",
                **located(where),
            )
        )
        return None
    return accept(replace(obj, mass=weighed))  # a mass > 0 on an object the gate accepted


def _radians(given) -> list:
    """The warning of a pose's rotation vector over pi (``given``: :func:`~.paths.read_pose`'s), if it is."""
    if "rotvec" not in given:
        return []
    from ...engine.degeneracy import radians_warning
    from ...engine.judgements import rotation_over_pi

    return [radians_warning(**given)] if rotation_over_pi(given["rotvec"]) else []


def _shape(kind, fields, file, reading, problems, warnings, units=None):
    """The :class:`~grasptwist.model.Shape` of the ``kind`` key (None after a problem); a mesh's
    warnings are added to ``warnings``."""
    node, path = fields[kind], f"object.{kind}"
    if kind == "mesh":
        return _mesh(node, fields.get("scale"), file, reading, problems, warnings, units)
    if kind == "box":
        size = read_vector(node, 3, path, problems)
        sizes = (
            None if size is None else [(v, f"{path}[{i}]", item) for i, (v, item) in enumerate(zip(size, node.value))]
        )
    elif kind == "sphere":
        radius = read_number(node, path, problems)
        sizes = None if radius is None else [(radius, path, node)]
    else:
        parts = read_mapping(node, path, SIZE_KEYS, SIZE_KEYS, problems)
        if parts is None or len(parts) < 2:
            return None
        sizes = [(read_number(parts[key], join(path, key), problems), join(path, key), parts[key]) for key in SIZE_KEYS]
        if any(value is None for value, _, _ in sizes):
            return None
    if sizes is None:
        return None
    for value, where, item in sizes:
        if not value > 0:
            problems.add(Reject("invalid-size", where, f"must be > 0, got {value!r}", **located(item)))
            return None
    return Shape(kind, readonly([value for value, _, _ in sizes]))


def _mesh(node, scale_node, file, reading, problems, warnings, units=None):
    """A mesh shape: its file read (:func:`grasptwist.io.mesh_file.read_mesh`), scaled by its own
    unit into the grasp file's (``mesh: {file, units}``) and by ``scale``; its
    repairs and its solid's warnings are added to ``warnings`` (:func:`mesh_solid`)."""
    if node.kind == "mapping":
        parts = read_mapping(node, "object.mesh", MESH_KEYS, ("file",), problems)
        if parts is None or "file" not in parts:
            return None
        if "scale" in parts and scale_node is not None:
            problems.add(
                Reject(
                    "conflicting-keys",
                    "object.scale",
                    "cannot be combined with the mesh's own 'scale'",
                    **located(scale_node),
                )
            )
            return None
        reference = read_name(parts["file"], "object.mesh.file", problems)
        scale_node = parts.get("scale", scale_node)
        factor = _unit_factor(parts["units"], units, problems) if "units" in parts else 1.0
        where = parts["file"]
    else:
        reference, factor, where = read_name(node, "object.mesh", problems), 1.0, node
    scale = _scale(scale_node, problems) if scale_node is not None else np.ones(1)
    if reference is None or scale is None or factor is None or problems.count:
        return None
    # trimesh and the mesh reader load with the first mesh (a grasp file with a primitive never pays)
    from pathlib import Path

    from ..mesh_file import read_mesh

    folder = Path(file).parent if not file.startswith("<") else Path.cwd()
    try:
        vertices, faces = read_mesh(
            reference,
            folder,
            max_bytes=reading.max_mesh_bytes,
            max_triangles=reading.max_triangles,
            allow_outside=reading.allow_outside,
            output=reading.output,
            warnings=(repaired := []),
        )
    except InputError as err:
        problems.add(Reject(err.code, "object.mesh", str(err), **located(where)))
        return None
    scale = readonly(scale * factor)
    shape = Shape("mesh", readonly(np.zeros(0)), readonly(vertices * scale), faces, reference, scale)
    said = mesh_solid(shape, reference, repaired)
    if isinstance(said, InputError):
        problems.add(Reject(said.code, "object.mesh", str(said), **located(where)))
        return None
    warnings += said
    return shape


def _unit_factor(node, units, problems):
    """How many of the grasp file's ``units`` one unit of a mesh's own (``node``) is; None after a problem."""
    from ...engine.units import unit_length

    own = read_name(node, "object.mesh.units", problems)
    if own is None:
        return None
    lengths = unit_length(own), unit_length(units)
    for length, name, what in zip(lengths, (own, units), ("the mesh's", "the file's")):
        if length is None:
            problems.add(
                Reject(
                    UNKNOWN_UNITS,
                    "object.mesh.units",
                    f"scaling the mesh into the file's units needs both lengths, and {what} {name!r} is none of "
                    f"{', '.join(LENGTH_UNITS)}",
                    **located(node),
                )
            )
            return None
    return lengths[0] / lengths[1]


def mesh_solid(shape, file, repaired=()):
    """The warnings of a mesh shape read from ``file`` (its reader's ``repaired`` ones, then its solid's:
    :func:`~grasptwist.engine.objects.solid.solid_warnings`), each naming the file, or the
    ``mesh-not-solid`` InputError where no inside can be told."""
    from ...engine.objects.checks import NOT_SOLID_HINT
    from ...engine.objects.mesh import solid_of
    from ...engine.objects.solid import solid_warnings

    try:
        found = solid_of(shape)
    except ValueError as err:
        return InputError("mesh-not-solid", f"{err}: {NOT_SOLID_HINT}", file)
    said = [*repaired, *solid_warnings(found)]
    return [f"{code}: {file}:{rest}" for code, _, rest in (w.partition(":") for w in said)]


def _scale(node, problems):
    """A mesh's ``scale``: one number > 0, or three (per axis)."""
    if node.kind == "sequence":
        values = read_vector(node, 3, "object.scale", problems)
        items = node.value
    else:
        values = read_number(node, "object.scale", problems)
        values, items = (None, None) if values is None else ([values], [node])
    if values is None:
        return None
    for i, (value, item) in enumerate(zip(values, items)):
        if not value > 0:
            where = "object.scale" if node.kind != "sequence" else f"object.scale[{i}]"
            problems.add(Reject("invalid-scale", where, f"must be > 0, got {value!r}", **located(item)))
            return None
    return np.array(values)


def _positive(node, path, problems):
    """A number > 0 (a mass, a density)."""
    value = read_number(node, path, problems)
    if value is not None and not value > 0:
        code = "invalid-mass" if path.endswith("mass") else "invalid-density"
        problems.add(Reject(code, path, f"must be > 0, got {value!r}", **located(node)))
        return None
    return value


def on_surface(obj, points, normals, tolerance):
    """The contacts put on ``obj``'s surface: ``(points, normals, distance, problems, disagree)``.

    Parameters
    ----------
    obj : GraspObject
    points : (3, 3) array
        The points as given.
    normals : (3, 3) array
        The given unit normals, a row of NaN where a contact gives none.
    tolerance : float
        The farthest a point may be from the surface, relative to the object's size.

    Returns
    -------
    points : (3, 3) array
        Each given point where the contact gives its normal, else the nearest surface point.
    normals : (3, 3) array
        Each given normal, or the inward surface normal where none is given.
    distance : (3,) array
        Each given point's signed distance from the surface (> 0 outside).
    problems : list of (code, contact, message)
        ``contact-inside-object`` (on a mesh's face inside its solid: a piece's inside another, a
        cavity's), ``contact-off-surface`` (farther than the tolerance) and ``outward-normal`` (a given
        normal pointing out of the object), per contact.
    disagree : list of (contact, angle)
        The given normals more than :data:`~grasptwist.objects.NORMAL_DISAGREE_DEG` from the
        surface's (``normal-disagrees``), with their angles in degrees.
    """
    from ...engine.judgements import normal_angles
    from ...engine.objects import NORMAL_DISAGREE_DEG, object_size, project_to_surface
    from ...engine.objects.geometry import on_hidden_face

    surface = project_to_surface(obj, points)
    limit = tolerance * object_size(obj)
    hidden = on_hidden_face(obj, points, surface.distance, limit)
    given = ~np.isnan(normals).any(axis=1)
    problems = []
    for i in range(len(points)):
        if hidden[i]:
            problems.append(
                (
                    "contact-inside-object",
                    i,
                    f"on a face of the mesh inside its solid (a piece inside another, or a cavity), "
                    f"{-surface.distance[i]:.3g} deep: no finger reaches it",
                )
            )
        elif abs(surface.distance[i]) > limit:
            problems.append(
                (
                    "contact-off-surface",
                    i,
                    f"{abs(surface.distance[i]):.3g} from the object's surface "
                    f"({'outside' if surface.distance[i] > 0 else 'inside'}; the tolerance is {limit:.3g})",
                )
            )
        elif given[i] and np.dot(normals[i], surface.normals[i]) < 0:
            problems.append(("outward-normal", i, "the normal points out of the object (normals point into it)"))
    angles = normal_angles(np.where(given[:, None], normals, surface.normals), surface.normals)
    disagree = [(i, float(angles[i])) for i in range(len(points)) if angles[i] > NORMAL_DISAGREE_DEG]
    points = np.where(given[:, None], points, surface.points)
    return points, np.where(given[:, None], normals, surface.normals), surface.distance, problems, disagree


def _read(fields, found, problems):
    if "object" not in fields:
        return {}
    said = []
    obj = read_object(
        fields["object"],
        found["file"],
        found["reading"],
        problems,
        said,
        units=found.get("units"),
        hand="hand" in fields,
    )
    points = found.get("points")
    if obj is not None and points is None and not found["reading"].contacts:  # synthesize finds them
        return {"object": obj, "warnings": tuple(said)}
    if obj is None or points is None:
        return None
    from ...engine.degeneracy import normal_disagrees_warning
    from ...engine.objects import NORMAL_DISAGREE_DEG, SURFACE_TOL

    tolerance = SURFACE_TOL if found["reading"].surface_tol is None else found["reading"].surface_tol
    points, normals, distance, off, disagree = on_surface(obj, points, found["normals"], tolerance)
    for code, i, message in off:
        key = "normal" if code == "outward-normal" else "point"
        problems.add(Reject(code, f"contacts[{i}].{key}", message, **located(_contact_node(fields, i, key))))
    if off:
        return None
    for i, angle in disagree:
        where = located(_contact_node(fields, i, "normal"))
        said.append(normal_disagrees_warning(i, angle, where["line"], where["column"], NORMAL_DISAGREE_DEG))
    return {
        "object": obj,
        "points": readonly(points),
        "normals": readonly(normals),
        "surface_distance": readonly(distance),
        "warnings": tuple(said),
    }


def _contact_node(fields, i, key):
    """Where contact ``i``'s ``key`` is written: its node, else the contact's, else the object's
    (the fast reader composes no contacts: it reads again when a contact must be located)."""
    contacts = fields.get("contacts")
    if contacts is None or contacts.kind != "sequence":
        return fields["object"]
    item = contacts.value[i]
    return item.value.get(key, (None, item))[1] if item.kind == "mapping" else item


SECTION = Section(("object",), _read)
