"""The grasp loader: read YAML grasp descriptions into arrays, strictly checked.

A grasp file holds one grasp per YAML document (see "Grasp files" in README.md
for the format).  Reading never constructs arbitrary Python objects and
never lets a parser exception escape: every problem becomes a
:class:`InputError` that names the file, line, column and field path.
Every problem of a document is reported, in file order, not just its
first: each at its own place, four misspelt keys as four entries; nothing
inside the value of a key reported unknown (at most ``MAX_ERRORS`` entries
per file; one more entry counts the rest).

How the YAML is read, and why
-----------------------------
The file is parsed into *events* by the safe loader (libyaml's
``CSafeLoader`` when available, else the pure-Python ``SafeLoader``) and the
events are assembled here into a small node tree, instead of letting PyYAML
compose or construct.  Doing the composition ourselves lets us

- stop at a nesting depth of ``MAX_DEPTH`` before anything recurses: both
  PyYAML composers recurse once per level (the pure one raises
  ``RecursionError`` near 500 levels; the C one, in PyYAML 6.0, crashes the
  interpreter with a segmentation fault at 100,000 levels, a 200 kB file),
  and both scanners slow down quadratically with depth, so a deep document
  must end the parse at once;
- reject aliases outright, so no alias bomb can expand, and reject every
  tag except the core ones, so no tag can ever construct an object, and go
  on composing after either, to find the document's other problems;
- see duplicate keys, which PyYAML silently merges;
- resolve plain scalars with the YAML 1.2 core schema (``1e-3`` is a
  number, ``yes`` is a string, as in editors' YAML language servers),
  identically for both parsers.

The two parsers report the same events and marks, so results and error
positions do not depend on whether libyaml is installed; only the wording
of YAML syntax errors differs between them.

For speed, a plainly written valid document is first read straight from
its events into floats and strings (:mod:`.fast`); at anything it is
not sure of, the document's recorded events go through the general path
above, which gives every error.  Both paths give the same grasps.

The modules
-----------
``text``       size cap, reading, strict decoding (the limits: :mod:`grasptwist.io.limits`)
``compose``    YAML events -> node tree, with the safety rules above
``problems``   located problems as values: every one, in file order, a file's total capped
``values``     typed values of nodes (numbers, vectors, names, mappings), shared by the sections
``document``   a document as a whole, and :data:`SECTIONS`, where a section module is registered
``contacts``, ``twists``, ``paths``, ``hand``, ``forces``: one module per section of the format
``fast``       the fast path (bench/loader.py measures what it saves)
``reader``     a file of documents: :func:`read_grasps`, :func:`one_per_document`
``lines``      one line of a JSON Lines stream (the stream: :mod:`grasptwist.io.lines`)
"""

from ...model import Grasp, InputError, Twist
from ..limits import DEFAULT_MAX_BYTES, NOT_REGULAR
from .compose import MAX_DEPTH
from .contacts import CONTACT_KEYS
from .document import GRASP_KEYS, SECTIONS, grasp_schema
from .forces import FORCE_KEYS, WRENCH_KEYS
from .hand import inline_hand, load_hand_file
from .lines import read_line, read_twist_line
from .paths import PATH_KEYS, POSE_KEYS, SEGMENT_KEYS
from .problems import MAX_ERRORS
from .reader import MAX_DOCUMENTS, READING, Reading, load_grasps, one_per_document, read_grasps
from .twists import TWIST_KEYS

__all__ = [
    "read_grasps",
    "load_grasps",
    "one_per_document",
    "read_line",
    "read_twist_line",
    "load_hand_file",
    "inline_hand",
    "grasp_schema",
    "Reading",
    "READING",
    "Grasp",
    "InputError",
    "Twist",
    "DEFAULT_MAX_BYTES",
    "NOT_REGULAR",
    "MAX_DEPTH",
    "MAX_DOCUMENTS",
    "MAX_ERRORS",
    "SECTIONS",
    "GRASP_KEYS",
    "CONTACT_KEYS",
    "TWIST_KEYS",
    "FORCE_KEYS",
    "WRENCH_KEYS",
    "PATH_KEYS",
    "SEGMENT_KEYS",
    "POSE_KEYS",
]
