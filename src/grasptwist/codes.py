"""Every code grasptwist writes, in one table: statuses, errors, failures, warnings, exit statuses.

The engines build their status enums from :data:`STATUSES` (one number space: a number means one
condition whichever engine gives it), the command line its exit statuses from :data:`EXIT`, and
``tests/model/test_codes.py`` holds the rest of the package to this module: every code a module
writes is here, every code here is written somewhere, documented on its page and in the index of
``docs/reference/bad-input-and-faults.md`` (generated from here: ``python tests/code_tables.py
--update``). Numbers, codes and exit statuses are a contract (records and users' scripts hold
them): they never change, and a new one is added here first.

>>> STATUSES[2].code, STATUSES[2].number, ERRORS["too-large"].exit
('coincident-contacts', 2, 1)
"""

from __future__ import annotations

from enum import IntEnum
from typing import NamedTuple

__all__ = [
    "EXIT_OK",
    "EXIT_FAILED",
    "EXIT_USAGE",
    "EXIT_WRITE",
    "EXIT_WORKER",
    "EXIT_SIGNAL",
    "EXIT_BROKEN_PIPE",
    "EXIT",
    "StatusCode",
    "STATUSES",
    "CodedStatus",
    "status_enum",
    "status_messages",
    "Code",
    "ERRORS",
    "NO_GRASP_CONSTRAINTS",
    "WARNINGS",
]

# --- exit statuses --------------------------------------------------------------------------

EXIT_OK, EXIT_FAILED, EXIT_USAGE, EXIT_WRITE, EXIT_WORKER, EXIT_BROKEN_PIPE = 0, 1, 2, 3, 4, 141
#: A run stopped by a signal exits with this plus the signal's number, as shells report it.
EXIT_SIGNAL = 128

#: Exit status -> when a run ends with it (``docs/guide/command-line.md``, "Exit codes and diagnostics").
EXIT = {
    EXIT_OK: "every record is ok",
    EXIT_FAILED: "some record is not ok (a status, an error, a failure), or an internal error",
    EXIT_USAGE: "usage error, before any work",
    EXIT_WRITE: "the output could not be written, or a standard stream is closed",
    EXIT_WORKER: "a worker process died",
    EXIT_BROKEN_PIPE: "the reader of stdout went away",
}

# --- statuses: a row of a batch that has no numbers ----------------------------------------


class StatusCode(NamedTuple):
    """One status: its number, its code, and the sentence each engine gives it.

    ``twist`` is the twist engine's message (:func:`grasptwist.status_message`), ``force`` the
    force engine's (:func:`grasptwist.forces.status_message`); None where that engine never gives
    it.  ``{i}`` is the culprit contact's name, ``{j}`` and ``{k}`` the next ones cyclically,
    ``{n}`` the culprit's 1-based number; a pair is the sentence with a culprit and without one.
    """

    number: int
    code: str
    twist: str | None
    force: str | tuple[str, str] | None


#: Every status, by number.  9 is the one number with two codes: the same condition (the numbers
#: overflow double precision) named by each engine as 0.2 and 0.3 first wrote it.
STATUSES = (
    StatusCode(0, "ok", "ok", "ok"),
    StatusCode(
        1,
        "nonfinite-input",
        "the input holds NaN or infinity: give finite numbers",
        "the input holds NaN or infinity",
    ),
    StatusCode(
        2,
        "coincident-contacts",
        "contacts {j} and {k} coincide, so Sigma_{n} has no axis: three distinct contacts are needed",
        "contacts {j} and {k} coincide, so the grasp map has rank < 6",
    ),
    StatusCode(
        3,
        "collinear-contacts",
        "the contacts are collinear: {i} lies on the line through {j} and {k}; "
        "neither method can work until a contact is moved off that line",
        "the contacts are collinear, so no finger forces make a moment about their line (rank G < 6)",
    ),
    StatusCode(
        4,
        "wrist-coplanar",
        "the wrist lies in the plane of the contacts, so every [Sigma_i|Psi_i] is 0 (Proposition 1 needs it off the "
        "plane): move the wrist off that plane, or use the tangent method",
        None,
    ),
    StatusCode(
        5,
        "zero-normal",
        "the normal at contact {i} has zero length: give its direction",
        "the normal at contact {i} has zero length",
    ),
    StatusCode(
        6,
        "normals-rank-deficient",
        "the three normal lines have rank < 3, so the tangent twists are not a three-system "
        "(a normal lies in the contacts' plane): tilt a normal out of that plane, or use the off-tangent method",
        None,
    ),
    StatusCode(
        7,
        "theta-not-unique",
        "Theta_{n} is not unique: the normals at {j} and {k} leave more than one axis through contact {i} "
        "that keeps them in their tangent planes: tilt the normal at {j} or {k} out of the contacts' plane, "
        "or use the off-tangent method",
        None,
    ),
    StatusCode(
        8,
        "theta-sigma-zero",
        "[Theta_{n}|Sigma_{n}] = 0: the axis of Theta_{n} (through contact {i}) meets or is parallel to the line "
        "through {j} and {k}: tilt a normal out of the contacts' plane, or use the off-tangent method",
        None,
    ),
    StatusCode(
        9,
        "overflow",
        "the numbers overflow double precision (coordinates or twist too large): rescale them",
        None,
    ),
    StatusCode(
        9,
        "nonfinite-result",
        None,
        "the result overflows double precision (a force is infinite or NaN): rescale the wrench, mass or coordinates",
    ),
    StatusCode(
        10,
        "normal-in-contact-plane",
        "the normal at contact {i} lies in the plane of the contacts, so no tangent-plus-Sigma motion "
        "can move contact {i} along it: tilt it out of that plane, or use the off-tangent method",
        None,
    ),
    StatusCode(
        11,
        "finger-cannot-follow",
        "finger {i} cannot follow its contact: no joint rates move it with the object's velocity there "
        "(relative residual above 1e-6): move the finger away from that pose, or use a method "
        "whose components it can follow",
        None,
    ),
    StatusCode(  # set where a grasp has none (grasptwist.results), never by a decomposition
        12,
        "no-wrist",
        "the grasp has no wrist, and each Psi_i is a line from it: give one "
        "('wrist: [x, y, z]' in a grasp file, a 'wrist' array in a data set)",
        None,
    ),
    StatusCode(  # a hand's: a contact farther from its finger's tip than the finger is long
        13,
        "contact-off-finger",
        "contact {i} is farther from its finger's tip than the finger is long at the row's joint positions: "
        "give the contacts in the hand's root frame and the joint positions of that row",
        None,
    ),
    StatusCode(  # a hand's inverse kinematics (grasptwist.engine.ik)
        14,
        "unreachable",
        "finger {i}'s tip cannot reach its contact within the finger's joint limits: move the contact within its reach",
        None,
    ),
    StatusCode(
        15,
        "outside-limits",
        "finger {i}'s tip reaches its contact only with a joint outside its position limits: "
        "move the contact, or widen the limits where the hand allows it",
        None,
    ),
    StatusCode(  # a path's: its pose at a sample overflows (grasptwist.engine.path), never a decomposition's
        16,
        "nonfinite-pose",
        "the object's pose overflows double precision here (a turn through more than about 1e154 radians, "
        "a distance or a twist beyond 1.8e308): rescale the twist or shorten the path",
        "the object's pose overflows double precision here: rescale the twist or shorten the path",
    ),
    StatusCode(
        20,
        "cannot-hold",
        None,
        (
            "cannot-hold: the friction cone at contact {i} is too narrow (mu/safety) for any forces that make the wrench",
            "cannot-hold: the wrench needs a finger to pull (no pushing forces make it, whatever the friction)",
        ),
    ),
    StatusCode(
        21,
        "no-closure",
        None,
        (
            "no friction makes the grasp force closure: the normal at contact {i} is at right angles to the contacts' plane",
            "no friction makes the grasp force closure: no internal force pushes at all three contacts",
        ),
    ),
    StatusCode(
        22,
        "mixed-frictionless",
        None,
        "contacts with and without friction in one grasp are not solved yet (give every contact mu > 0, or all 0)",
    ),
)


class CodedStatus(IntEnum):
    """The base of the engines' status enums: a number with its stable kebab-case code."""

    @property
    def code(self) -> str:
        """Stable kebab-case name used in JSON output, e.g. ``wrist-coplanar``."""
        return self.name.lower().replace("_", "-")


def status_enum(name: str, engine: str, module: str, doc: str) -> type[CodedStatus]:
    """The status enum of ``engine`` (``"twist"`` or ``"force"``): the statuses of
    :data:`STATUSES` it gives, each named after its code.

    >>> Status = status_enum("Status", "force", __name__, "A row's status.")
    >>> Status.CANNOT_HOLD.value, Status(9).code
    (20, 'nonfinite-result')
    """
    members = [(s.code.upper().replace("-", "_"), s.number) for s in STATUSES if getattr(s, engine) is not None]
    enum = CodedStatus(name, members, module=module, qualname=name)
    enum.__doc__ = doc
    return enum


def status_messages(engine: str) -> dict:
    """Number -> ``engine``'s sentence (or pair of sentences) for each of its statuses.

    >>> status_messages("twist")[0]
    'ok'
    """
    return {s.number: getattr(s, engine) for s in STATUSES if getattr(s, engine) is not None}


# --- errors: an input, or a grasp, a command cannot use --------------------------------------


class Code(NamedTuple):
    """An error or warning code: what it means, the pages that explain it (relative to ``docs/``,
    the first the main one), and the exit status a run that writes it ends with."""

    meaning: str
    pages: tuple[str, ...]
    exit: int = EXIT_FAILED


_FILES = ("guide/grasp-files.md",)
_HANDS = ("guide/hands.md",)
_MESHES = ("guide/grasp-files.md", "reference/bad-input-and-faults.md")
_PYTHON = ("guide/objects.md",)
_PATHS = ("guide/paths.md",)
_COMMANDS = ("guide/command-line.md",)
_SEARCH = ("reference/bad-input-and-faults.md",)
_SIMULATION = ("reference/bad-input-and-faults.md",)

#: Every error code of an error record (``{"error": {"code", "message"}}``, the stderr line
#: ``file:line:column: error: code: message``).  The message is written where the error is found
#: and says what is wrong in that input's words; here is what the code always means.
ERRORS = {
    # reading a file
    "read-error": Code(
        "the file cannot be read (missing, a directory, no permission, a loop of links, not a regular file)",
        (*_FILES, *_COMMANDS),
    ),
    "no-grasp-files": Code("a folder with no grasp file in it or below it", _FILES),
    "too-large": Code("the file exceeds its kind's size cap", (*_FILES, "reference/bad-input-and-faults.md")),
    "output-is-input": Code("a file the input names is the file `-o` writes: nothing is written", _FILES, EXIT_USAGE),
    "path-outside": Code("a file the input names leaves the grasp file's folder, without `--allow-outside`", _FILES),
    # a grasp file's text and YAML
    "invalid-utf8": Code("not valid UTF-8", _FILES),
    "control-character": Code("a character YAML does not allow", _FILES),
    "yaml-syntax": Code("not valid YAML, including tabs used for indentation", _FILES),
    "too-deep": Code("nesting beyond `MAX_DEPTH` levels", _FILES),
    "alias": Code("a YAML alias `*name`", _FILES),
    "forbidden-tag": Code("a tag other than YAML's core ones", _FILES),
    "bad-scalar": Code("a `!!bool` or `!!null` tag on text that is not one", _FILES),
    "duplicate-key": Code("a key given twice in one mapping", _FILES),
    "invalid-key": Code("a key that is not a string", _FILES),
    "empty-document": Code("a document with no content, or a file with no document", _FILES),
    "too-many-documents": Code("more than `MAX_DOCUMENTS` documents in one file", _FILES),
    "too-many-errors": Code("more than `MAX_ERRORS` problems in one file", _FILES),
    # a grasp document's keys and values
    "not-a-mapping": Code("a document or an entry is not a mapping", _FILES),
    "not-a-list": Code("a list or a vector is not a list", _FILES),
    "not-a-string": Code("a name or `units` that is null, a list or a mapping", _FILES),
    "invalid-name": Code("a name or `units` that is empty, spans lines or holds a control character", _FILES),
    "unknown-key": Code("a key the format does not have", _FILES),
    "missing-key": Code("a key the format needs is missing", (*_FILES, *_HANDS)),
    "conflicting-keys": Code("keys that exclude each other given together", (*_FILES, *_HANDS, *_PATHS)),
    "duplicate-name": Code("two entries of one list with the same name", (*_FILES, *_HANDS)),
    "contact-count": Code("not exactly three contacts", _FILES),
    "vector-length": Code("a vector with the wrong number of entries", _FILES),
    "not-a-number": Code("a value that is not a number", (*_FILES, *_PYTHON)),
    "non-finite": Code("a number that is NaN or infinite, or overflows double precision", (*_FILES, *_PYTHON)),
    "zero-normal": Code("a normal of length zero", _FILES),
    "invalid-friction": Code(
        "a friction below 0 (a file's, or a data set's row)", (*_FILES, "reference/bad-input-and-faults.md")
    ),
    "invalid-contact-model": Code("a contact's `model` that is not `point` or `soft`", _FILES),
    "invalid-torsion": Code(
        "a soft contact's `torsion` that is not above 0, or a soft contact with friction 0", _FILES
    ),
    "invalid-mass": Code("a mass that is not above 0", (*_FILES, *_PYTHON)),
    # the object and the world around it
    "invalid-size": Code("an object's or a box's size that is not a size", (*_FILES, *_PYTHON)),
    "invalid-scale": Code("a mesh's `scale` that is not above 0", _FILES),
    "invalid-density": Code("an object's density that is not above 0", (*_FILES, *_PYTHON)),
    "unknown-units": Code("a `units` that is no length unit where a length unit is needed", _FILES),
    "invalid-clearance": Code("an environment's `clearance` below 0", _FILES),
    "object-below-table": Code("the object below its table by more than the surface tolerance", _FILES),
    "contact-off-surface": Code("a contact farther from its object's surface than the tolerance", _FILES),
    "contact-inside-object": Code("a contact on a mesh's triangle inside its solid", _FILES),
    "outward-normal": Code("a contact's given normal pointing out of its object", _FILES),
    "invalid-pose": Code("an object's pose that is not a rigid motion (only Python can give one)", _PYTHON),
    "invalid-object": Code("not a `GraspObject` or `Shape` (only Python can give one)", _PYTHON),
    # meshes
    "unsupported-mesh": Code("a mesh file that is not `.stl`, `.obj` or `.ply`", _FILES),
    "invalid-mesh": Code("a mesh unreadable as its format, or with malformed arrays", (*_MESHES, *_PYTHON)),
    "empty-mesh": Code("a mesh with no triangles", _MESHES),
    "too-many-triangles": Code("a mesh of more than `MAX_TRIANGLES` triangles", _MESHES),
    "too-many-vertices": Code("a mesh of more than `MAX_VERTICES` vertices", _MESHES),
    "mesh-not-solid": Code("a mesh that bounds no solid", (*_MESHES, *_PYTHON)),
    "mesh-unavailable": Code("a binary PLY without trimesh installed", _FILES),
    # paths
    "invalid-frame": Code("a path's `frame` that is not `space` or `body`", _PATHS),
    "invalid-duration": Code("a duration not above 0, or durations adding up beyond double precision", _PATHS),
    "empty-path": Code("a path with no segment", _PATHS),
    "invalid-rotation": Code("a quaternion of zero length", _PATHS),
    # hands and URDF
    "finger-count": Code("not exactly three fingers", _HANDS),
    "unsupported-joint": Code("a joint type other than revolute or prismatic", _HANDS),
    "zero-axis": Code("a joint axis of length zero", _HANDS),
    "invalid-limit": Code("a velocity limit that is not positive", _HANDS),
    "invalid-radius": Code("a `tip_radius` below 0", _HANDS),
    "unknown-joint": Code("a joint name that is no joint of the fingers", _HANDS),
    "contact-off-finger": Code("a contact farther from its finger's tip than the finger is long", _HANDS),
    "unreachable": Code("no joint positions put a finger's tip on its contact", _HANDS),
    "outside-limits": Code("a finger reaches its contact only outside its joint limits", _HANDS),
    "package-not-found": Code("a URDF's `package://` names no installed package", _HANDS),
    "unsupported-url": Code("a URDF reference that is neither a `package://` URL nor a file path", _HANDS),
    "unknown-link": Code("a finger's `tip` that is no link of the URDF", _HANDS),
    "fixed-finger": Code("a finger's `tip` that no movable joint moves (the URDF's root, or fixed to it)", _HANDS),
    "shared-joint": Code("two fingers moved by one joint: the same `tip` link, or a link above both", _HANDS),
    "urdf-syntax": Code("a URDF that is not well-formed XML", _HANDS),
    "forbidden-dtd": Code("a URDF with a DTD or entities", _HANDS),
    "invalid-urdf": Code("a URDF that is no robot description grasptwist can use", _HANDS),
    "urdf-unavailable": Code("a URDF hand without the extra `urdf` (lxml, yourdfpy) installed", _HANDS),
    # data sets and the twists of a grasp
    "bad-dataset": Code("a data set whose arrays or file cannot be read as the documented layout", _COMMANDS),
    "no-twist": Code("a grasp or data set with no twist to resolve", _COMMANDS),
    "unknown-twist": Code("a grasp without the twist `--select` names", _COMMANDS),
    "no-path": Code("a grasp with no path (or twist) of the name asked for", (*_PATHS, *_SIMULATION)),
    "too-many-samples": Code("a path's `--dt` that gives more than `MAX_SAMPLES` samples", _PATHS),
    # a grasp or an object a command cannot use
    "no-object": Code("a grasp document without the `object` the command needs", _SEARCH),
    "no-friction": Code("neither the document nor `--friction` gives a friction", _SEARCH),
    "no-mass": Code("neither the object, the document nor `--mass` gives a mass", _SIMULATION),
    "nothing-to-hold": Code("no weight and no wrench: nothing to hold", _SEARCH),
    "no-weight": Code("`gt.synthesize(..., hold=True)` on an object without a mass or density", _SEARCH),
    "no-tip-points": Code("an inline hand with no contacts for its tips to start at", _SEARCH),
    "unsearchable-hand": Code("a hand whose fingers share a joint", _SEARCH),
    "tolerance-too-large": Code("`--tolerance`'s distance not below the object's size", _SIMULATION),
    "internal-error": Code("an exception of grasptwist's own while an object was read or searched", _SEARCH),
    # failures: what a command found
    "no-grasp": Code(
        "no candidate in the budget was feasible (its `constraint` says which held it back)",
        (*_SEARCH, "guide/synthesis.md"),
    ),
    "scene-error": Code("MuJoCo cannot compile the grasp's scene", _SIMULATION),
    "simulation-unstable": Code("the simulation diverged", _SIMULATION),
}

#: A ``no-grasp`` record's ``constraint``: the furthest any candidate got, or why there is none to judge.
NO_GRASP_CONSTRAINTS = {
    "degenerate": "every candidate's contacts were coincident or collinear",
    "conditioning": "no candidate's conditioning reached `--min-conditioning`",
    "force_closure": "no candidate is force closure at the friction over the safety factor",
    "clearance": "no force-closure candidate keeps the clearance from the environment",
    "constraints": "no force-closure candidate passed a constraint given from Python",
    "grip": "no candidate's grip holds every wrench within the friction cones",
    "fingertips": "on every candidate a fingertip sphere goes into the object or within the clearance",
    "reach": "the hand reaches no candidate's contacts within its joint limits",
    "collision": "every grasp the hand reaches puts a link into the object, another finger or the clearance",
    "budget": "too few candidates scored to judge the object",
    "verification": "candidates passed every test but none was verified (or `--seconds` ran out first)",
}

#: Every warning code: the start of a record's ``warnings`` entry and of its stderr line.  A
#: warning never changes the exit status.
WARNINGS = {
    "outward-normals": Code(
        "a normal points away from the other contacts or the centre of mass", ("reference/conventions.md",)
    ),
    "normal-disagrees": Code("a given normal far from the object's surface normal", _FILES),
    "rotation-over-pi": Code("a rotation vector over pi: rotations are in radians", _FILES),
    "finger-collides": Code("a finger link inside the object", _HANDS),
    "fingers-collide": Code("two fingers' links overlap", _HANDS),
    "finger-hits-environment": Code("a finger within the clearance of the table or a box", _HANDS),
    "tip-off-contact": Code(
        "given joint positions leave a fingertip off its contact by over 1% of its finger's length", _HANDS
    ),
    "hand-size-mismatch": Code("an object over 10 times its hand's reach, or under a tenth of it", _SIMULATION),
    "mesh-size-unlikely": Code("a mesh in metres over 5 m or under 1 mm across", _SIMULATION),
    "mesh-repaired": Code("a mesh's faces re-wound outwards, or degenerate ones dropped", _PYTHON),
    "mesh-open": Code("a mesh with holes, taken as the solid its winding number bounds", _PYTHON),
    "mesh-internal": Code("a mesh with pieces inside others, or cavities", _PYTHON),
    "mesh-bodies": Code("a mesh of pieces apart", _PYTHON),
}
