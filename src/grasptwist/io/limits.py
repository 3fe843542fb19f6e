"""Limits on untrusted input files: one cap per kind of input, whichever way it arrives.

=================  =============================================  ==========================================
kind               arrives as                                     cap
=================  =============================================  ==========================================
grasp file         a path, a folder's file, standard input;       :data:`DEFAULT_MAX_BYTES` (``--max-bytes``),
                   a JSON Lines line; a hand file (``--hand``)    :data:`MAX_DOCUMENTS`, :data:`MAX_ERRORS`,
                                                                  :data:`MAX_DEPTH`
URDF               a grasp file's ``hand: {urdf: ...}``, a hand   :data:`MAX_URDF_BYTES`
                   file's, for a picture or a collision check
mesh               an object's ``mesh:``, a path or a folder's    :data:`MAX_MESH_BYTES` (decoded),
                   file (``synthesize``), a URDF link's           :data:`MAX_TRIANGLES`, :data:`MAX_VERTICES`
data set           ``.npy``, ``.npz``, ``.parquet``               streamed; :func:`check_inflation`
path's samples     ``follow --samples``, ``--dt``                 :data:`MAX_SAMPLES`
=================  =============================================  ==========================================

Here, not in any one reader, so that each (the URDF reader, which the grasp
loader's ``hand:`` section calls; the ``.npz`` and Parquet readers; the folder
lister, which needs the mesh formats but not the mesh reader) need not import
another for its constants, and no reader has a cap of its own.
"""

__all__ = [
    "DEFAULT_MAX_BYTES",
    "INFLATION_FLOOR",
    "MAX_DEPTH",
    "MAX_DOCUMENTS",
    "MAX_ERRORS",
    "MAX_INFLATION",
    "MAX_MESH_BYTES",
    "MAX_SAMPLES",
    "MAX_TRIANGLES",
    "MAX_URDF_BYTES",
    "MAX_VERTICES",
    "MESH_SUFFIXES",
    "NOT_REGULAR",
    "OUTPUT_IS_INPUT",
    "check_inflation",
]

#: The error of a file a grasp file names (a mesh, a URDF) that is the file ``-o`` replaces: the run
#: would replace what it reads, so the output is not written.
OUTPUT_IS_INPUT = "output-is-input"

DEFAULT_MAX_BYTES = 1 << 20
"""A grasp file's size cap in bytes by default (``--max-bytes``, ``max_bytes=``); larger ones are
refused before parsing."""

MAX_DOCUMENTS = 10_000
"""Most documents read from one grasp file; the rest of a longer file is refused
with one ``too-many-documents`` entry.  A grasp takes at least about 110
bytes, so no valid file within the default size cap has this many; a file of
``---`` lines would otherwise give one entry per 4 bytes."""

MAX_ERRORS = 100
"""Most problems reported for one grasp file (the first, in file order); one more
``too-many-errors`` entry says how many were left out."""

MAX_DEPTH = 32
"""Deepest collection nesting of a grasp file accepted.  A valid grasp needs 4 (document,
``contacts``, a contact, its ``point``); the margin lets mistyped nested
values get their specific error instead of ``too-deep``."""

MAX_URDF_BYTES = 1 << 20
"""Most bytes of a URDF (:mod:`grasptwist.io.urdf`), however it is named: the TriFinger's is 30 kB."""

MAX_MESH_BYTES = 64 << 20
"""Most bytes a mesh file may hold, or decode to when it is an archive or compressed (a glTF: with
the buffers it names), however it is named: an ASCII STL of :data:`MAX_TRIANGLES` triangles is
about 50 MB, a binary one 10 MB.  A reader holds at most a few times this much."""

MESH_SUFFIXES = (".stl", ".obj", ".ply")
"""The mesh formats read (:mod:`grasptwist.io.mesh_file`), by file suffix (in any letter case)."""

MAX_TRIANGLES = 200_000
"""Most triangles of an object's mesh (:mod:`grasptwist.io.mesh_file`): a grasp needs a few
thousand, ``bench/`` projects onto 10^5; a file within the size cap that holds more (an OBJ's
long polygons, a PLY's compact faces) is refused."""

MAX_VERTICES = 3 * MAX_TRIANGLES
"""Most vertices of a mesh file: a triangle soup's (an STL's three per triangle) at the triangle
cap; a file that holds more (an OBJ of ``v`` lines, a PLY header's count) is refused before they
are parsed."""

MAX_SAMPLES = 1_000_000
"""Most samples of one path, whether ``--samples`` asks for them or ``--dt`` cuts them (the
per-path analysis holds them all at once): a larger ``--samples`` is a usage error, a path that
``--dt`` cuts into more a ``too-many-samples`` error record."""

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
