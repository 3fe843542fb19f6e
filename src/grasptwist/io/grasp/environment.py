"""The ``environment`` section: a table under the object and boxes beside it, that the fingers keep clear of::

    environment:
      table: {height: 0}               # the plane z = 0 of the grasp frame (gravity along -z)
      boxes:                           # obstacles: edge lengths along their own axes, and a pose
        - {size: [0.1, 0.02, 0.2], pose: {position: [0.15, 0, 0.1]}}
      clearance: 0.001                 # the least distance of every finger part (default 1 mm in metres)

The command line's ``--table Z`` gives a table at ``Z`` (replacing the file's) and ``--clearance``
the clearance, both through :class:`~.reader.Reading`.  An object below the table (its lowest
point deeper than the contacts' surface tolerance) is ``object-below-table``: it rests on the
table or above it.  The geometry is :mod:`grasptwist.engine.environment`'s.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .paths import read_pose
from .problems import Reject, located
from .values import Section, read_mapping, read_number, read_sequence, read_vector, readonly

if TYPE_CHECKING:
    from ...model.environment import Environment

__all__ = ["ENVIRONMENT_KEYS", "BOX_KEYS", "SECTION", "OBJECT_BELOW_TABLE", "read_environment"]

ENVIRONMENT_KEYS = ("table", "boxes", "clearance")
BOX_KEYS = ("size", "pose")

#: The error of an object that goes below its table.
OBJECT_BELOW_TABLE = "object-below-table"


def read_environment(node, problems) -> Environment | None:
    """The :class:`~grasptwist.model.Environment` of an ``environment`` node (None after a problem)."""
    from ...model.environment import Environment, Obstacle  # with the first environment: most grasps have none

    fields = read_mapping(node, "environment", ENVIRONMENT_KEYS, (), problems)
    if fields is None:
        return None
    height = None
    if "table" in fields:
        table = read_mapping(fields["table"], "environment.table", ("height",), ("height",), problems)
        if table is not None and "height" in table:
            height = read_number(table["height"], "environment.table.height", problems)
    boxes = []
    items = read_sequence(fields["boxes"], "environment.boxes", problems) if "boxes" in fields else []
    for i, item in enumerate(items or ()):
        path = f"environment.boxes[{i}]"
        box = read_mapping(item, path, BOX_KEYS, ("size",), problems)
        if box is None or "size" not in box:
            continue
        size = read_vector(box["size"], 3, f"{path}.size", problems)
        if size is not None and not min(size) > 0:
            problems.add(
                Reject("invalid-size", f"{path}.size", f"edge lengths must be > 0, got {size}", **located(box["size"]))
            )
            size = None
        pose = np.eye(4)
        if "pose" in box:
            read = read_pose(box["pose"], f"{path}.pose", problems)
            if read is not None:
                pose[:3, 3], pose[:3, :3] = read[0], read[1]
        pose.setflags(write=False)
        if size is not None:
            boxes.append(Obstacle(readonly(size), pose, item.line))
    clearance = read_number(fields["clearance"], "environment.clearance", problems) if "clearance" in fields else None
    if clearance is not None and clearance < 0:
        where = located(fields["clearance"])
        problems.add(Reject("invalid-clearance", "environment.clearance", f"must be >= 0, got {clearance!r}", **where))
    if problems.count:
        return None
    return Environment(height, tuple(boxes), clearance, node.line)


def _below(obj, height) -> float:
    """How far the object's lowest point (of its tessellation: on the surface) goes below the table."""
    from ...engine.objects import tessellate

    vertices, _ = tessellate(obj)
    return float(height - vertices[:, 2].min())


def _read(fields, found, problems):
    reading = found["reading"]
    env = read_environment(fields["environment"], problems) if "environment" in fields else None
    if "environment" in fields and env is None:
        return None
    if reading.table is not None or reading.clearance is not None:
        from ...model.environment import Environment

        env = env or Environment()
        table = env.table_height if reading.table is None else reading.table
        clearance = env.clearance if reading.clearance is None else reading.clearance
        env = Environment(table, env.boxes, clearance, env.line)
    if env is None:
        return {}
    obj = found.get("object")
    if obj is not None and env.table_height is not None:
        from ...engine.objects import SURFACE_TOL, object_size

        tolerance = SURFACE_TOL if reading.surface_tol is None else reading.surface_tol
        depth = _below(obj, env.table_height)
        if depth > tolerance * object_size(obj):
            table = fields["environment"].value.get("table") if "environment" in fields else None
            where = located(table[1]) if table is not None else {"line": obj.line, "column": None}
            problems.add(
                Reject(
                    OBJECT_BELOW_TABLE,
                    "environment.table" if table is not None else "object",
                    f"the object goes {depth:.3g} below the table at z = {env.table_height:g} (beyond the surface "
                    "tolerance): it rests on the table or above it",
                    **where,
                )
            )
            return None
    return {"environment": env}


SECTION = Section(("environment",), _read, reads_also=("object",))
