"""Limits on untrusted input files, shared by the readers of grasp files, URDFs, meshes and data sets.

Here, not in any one reader, so that each (the URDF reader, which the grasp
loader's ``hand:`` section calls; the ``.npz`` and Parquet readers; the folder
lister, which needs the mesh formats but not the mesh reader) need not import
another for its constants.
"""

__all__ = [
    "DEFAULT_MAX_BYTES",
    "INFLATION_FLOOR",
    "MAX_INFLATION",
    "MAX_TRIANGLES",
    "MESH_SUFFIXES",
    "NOT_REGULAR",
    "OUTPUT_IS_INPUT",
    "check_inflation",
]

#: The error of a file a grasp file names (a mesh, a URDF) that is the file ``-o`` replaces: the run
#: would replace what it reads, so the output is not written.
OUTPUT_IS_INPUT = "output-is-input"

DEFAULT_MAX_BYTES = 1 << 20
"""Default size cap in bytes; larger files are rejected before parsing."""

MESH_SUFFIXES = (".stl", ".obj", ".ply")
"""The mesh formats read (:mod:`grasptwist.io.mesh_file`), by file suffix (in any letter case)."""

MAX_TRIANGLES = 200_000
"""Most triangles of an object's mesh (:mod:`grasptwist.io.mesh_file`): a grasp needs a few
thousand, ``bench/`` projects onto 10^5; a file within the size cap that holds more (an OBJ's
long polygons, a PLY's compact faces) is refused."""

#: Why a path that is not a regular file (or folder) is not read.
NOT_REGULAR = "not a regular file (a pipe, socket or device)"

#: Compressed input (an ``.npz`` member, a Parquet file's columns, a mesh archive) may decode
#: to at most this many times the bytes that hold it (zlib's own limit is about 1,000; real
#: grasp data compresses 1-10 times) ...
MAX_INFLATION = 100
#: ... once it declares more than this many bytes: smaller ones (one twist, repeated names)
#: may compress as much as they like.
INFLATION_FLOOR = 64 << 20


def check_inflation(declared: int, stored: int, kind: str) -> None:
    """Refuse input that declares ``declared`` bytes once decoded from ``stored`` bytes, as a likely
    ``kind`` (a zip bomb, a decompression bomb), when it is over both :data:`INFLATION_FLOOR`
    and :data:`MAX_INFLATION` times ``stored``: checked before a byte is decoded.

    Raises
    ------
    ValueError
        Saying what was declared, in how much, and why it is refused.

    >>> check_inflation(72_000_128, 70_000, "zip bomb")
    Traceback (most recent call last):
    ...
    ValueError: declares 72,000,128 bytes decoded from 70,000 (over 100 times): refused unread, as a likely zip bomb
    >>> check_inflation(64 << 20, 1, "zip bomb")  # at the floor: small enough to decode
    """
    if declared > INFLATION_FLOOR and declared > MAX_INFLATION * stored:
        raise ValueError(
            f"declares {declared:,} bytes decoded from {stored:,} (over {MAX_INFLATION} times): refused unread, as a likely {kind}"
        )
