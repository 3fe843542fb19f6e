"""A grasp file, document by document: the loader's entry points.

Each document is composed (:mod:`.compose`) and checked (:mod:`.document`)
as soon as it is parsed; every problem becomes a located
:class:`~grasptwist.model.InputError` entry among the grasps.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass, replace
from itertools import chain
from pathlib import Path

import yaml

from ...model import InputError
from ..limits import DEFAULT_MAX_BYTES, MAX_DOCUMENTS, MAX_MESH_BYTES, MAX_TRIANGLES
from .compose import PARSER, compose, syntax_error
from .document import read_document
from .fast import Bail, Parts, fast_document
from .problems import MAX_ERRORS, Problems, Reject, StreamStop, located_mark
from .text import file_text

__all__ = [
    "MAX_DOCUMENTS",
    "Reading",
    "READING",
    "read_grasps",
    "load_grasps",
    "one_per_document",
    "read_text",
    "check_surface_tol",
    "stem_name",
]


@dataclass(frozen=True)
class Reading:
    """How :func:`read_grasps` reads a file: its YAML parser, per-file limits, and paths.

    The defaults are what the command line uses; tests pass others to run
    both parsers, small limits, or the general path alone.

    Attributes
    ----------
    parser : type
        The PyYAML loader class whose events are read: libyaml's
        ``CSafeLoader`` where PyYAML has it, else the pure ``SafeLoader``.
    max_documents : int
        Documents read from one file (see :data:`MAX_DOCUMENTS`).
    max_errors : int
        Problems reported for one file (see :data:`MAX_ERRORS`).
    fast : bool
        Try the fast path on each document first (False: every document
        through the general composer, which must give the same entries).
    surface_tol : float or None
        How far a contact may be from its object's surface, relative to the
        object's size (``--surface-tol``); None:
        :data:`grasptwist.objects.SURFACE_TOL`.
    allow_outside : bool
        Read a mesh (or URDF) that a relative path names outside the grasp
        file's folder (``--allow-outside``).
    max_triangles : int
        Most triangles of an object's mesh (see :data:`~grasptwist.io.limits.MAX_TRIANGLES`).
    max_mesh_bytes : int
        Most bytes of an object's mesh file, however it is named (see
        :data:`~grasptwist.io.limits.MAX_MESH_BYTES`).
    contacts : bool
        Documents must give ``contacts`` (False: ``synthesize``'s, which finds its own; a document
        without them has NaN points and normals, contacts named ``1``, ``2``, ``3``).
    output : (int, int) or None
        The ``(device, inode)`` of the file the run's ``-o`` replaces: a mesh or URDF that a
        document names and that is that file is refused (``output-is-input``); None: no such file.
    table : float or None
        A table at this height under every document's object (``--table``), replacing its
        ``environment``'s; None: the file's.
    clearance : float or None
        The fingers' clearance from the environment (``--clearance``), replacing the file's.
    """

    parser: type = PARSER
    max_documents: int = MAX_DOCUMENTS
    max_errors: int = MAX_ERRORS
    fast: bool = True
    surface_tol: float | None = None
    allow_outside: bool = False
    max_triangles: int = MAX_TRIANGLES
    max_mesh_bytes: int = MAX_MESH_BYTES
    contacts: bool = True
    output: tuple[int, int] | None = None
    table: float | None = None
    clearance: float | None = None


#: The command line's way of reading.
READING = Reading()


def read_grasps(
    source, *, file=None, max_bytes=DEFAULT_MAX_BYTES, reading=READING, surface_tol=None, allow_outside=None
):
    """Read every grasp of a grasp file, keeping errors as values.

    Parameters
    ----------
    source : str, os.PathLike or bytes
        A path (``"-"`` reads standard input) or the file's content.  A
        ``str`` is content exactly when ``file`` is given, else a path;
        bytes are always content.
    file : str, optional
        Name used in results and messages; default the path, ``"<stdin>"``
        or ``"<string>"``.
    max_bytes : int
        Size cap; a larger input fails with ``too-large`` before parsing.
    reading : Reading
        The parser and per-file limits (default: the command line's).
    surface_tol : float, optional
        How far a contact may be from its object's surface, relative to the
        object's size (default :data:`grasptwist.objects.SURFACE_TOL`):
        ``reading.surface_tol``, as the command line's ``--surface-tol``.
    allow_outside : bool, optional
        Read meshes and URDFs that relative paths name outside the file's
        folder (``reading.allow_outside``, ``--allow-outside``).

    Returns
    -------
    list of Grasp or InputError
        In file order: a Grasp for each good document and an error for each
        problem of a bad one (several per document, each with its own
        position).  A syntax error, a too-deep document or more than
        ``reading.max_documents`` documents stop the reading: one error after the
        entries before it.  Beyond ``reading.max_errors`` problems one last
        ``too-many-errors`` error counts the rest.  A whole-file failure
        gives a single error.

    Examples
    --------
    >>> text = "contacts:\\n  - {point: [0, 0], normal: [1, 0, '0']}\\n"
    >>> for error in read_grasps(text, file="g.yaml"):
    ...     print(error)
    g.yaml:2:3: contacts: expected exactly 3 contacts, got 1
    g.yaml:2:13: contacts[0].point: expected 3 numbers, got 2
    g.yaml:2:36: contacts[0].normal[2]: expected a number, got the string '0'
    """
    reading = _with(reading, surface_tol, allow_outside)
    is_content = isinstance(source, (bytes, bytearray, memoryview)) or (isinstance(source, str) and file is not None)
    if file is None:
        file = "<string>" if is_content else "<stdin>" if source == "-" else os.fspath(source)
    try:
        text = file_text(source, is_content, max_bytes)
    except Reject as reject:
        return [reject.error(file, None)]
    return read_text(text, file, reading)


def load_grasps(
    source, *, file=None, max_bytes=DEFAULT_MAX_BYTES, reading=READING, surface_tol=None, allow_outside=None
):
    """Like :func:`read_grasps` (the same keywords), but raise its first :class:`InputError`.

    Returns
    -------
    list of Grasp
        Every grasp of the file, in file order.

    Raises
    ------
    InputError
        The first problem :func:`read_grasps` finds.

    Examples
    --------
    >>> load_grasps(b"contacts: []\\n", file="g.yaml")
    Traceback (most recent call last):
    grasptwist.model.InputError: g.yaml:1:11: contacts: expected exactly 3 contacts, got 0
    """
    entries = read_grasps(
        source, file=file, max_bytes=max_bytes, reading=reading, surface_tol=surface_tol, allow_outside=allow_outside
    )
    for entry in entries:
        if isinstance(entry, InputError):
            raise entry
    return entries


def _with(reading, surface_tol, allow_outside):
    """``reading`` with the tolerance and path rule given as keywords (None: its own)."""
    given = {"surface_tol": surface_tol, "allow_outside": allow_outside}
    given = {key: value for key, value in given.items() if value is not None}
    if "surface_tol" in given:
        check_surface_tol(given["surface_tol"])
    return replace(reading, **given) if given else reading


def check_surface_tol(value):
    """A surface tolerance: a finite number >= 0 (relative to the object's size).

    Raises
    ------
    ValueError
        Saying what it got.

    >>> check_surface_tol(-1)
    Traceback (most recent call last):
    ...
    ValueError: surface_tol must be a finite number >= 0 (relative to the object's size), got -1
    """
    if not (isinstance(value, (int, float)) and 0 <= value < float("inf")):
        raise ValueError(f"surface_tol must be a finite number >= 0 (relative to the object's size), got {value!r}")


def one_per_document(entries):
    """``entries`` of :func:`read_grasps` with one error per failed document (the command
    line's records): its first problem, carrying them all in ``problems``.

    A problem of the whole file stands alone; the file's closing
    ``too-many-errors`` joins the document before it.

    >>> text = "contacts: [1, 2]\\n---\\nwrist: 1\\n"
    >>> [(e.code, [p.code for p in e.problems]) for e in one_per_document(read_grasps(text, file="g.yaml"))]
    [('contact-count', ['contact-count', 'not-a-mapping', 'not-a-mapping']), ('missing-key', ['missing-key', 'not-a-list'])]
    """
    out = []
    for entry in entries:
        last = out[-1] if out else None
        joins = (
            isinstance(entry, InputError)
            and isinstance(last, InputError)
            and last.file == entry.file
            and last.document is not None
            and (entry.document == last.document or entry.code == "too-many-errors")
        )
        if joins:
            out[-1] = InputError(*last.args[:6], (*last.problems, entry))
        else:
            out.append(entry)
    return out


# --------------------------------------------------------------------------
# Stream -> grasps.


def read_text(text, file, reading, name=None):
    """Parse ``text`` and turn each document into a Grasp or its errors, as it is read
    (an unnamed grasp called ``name`` if given; the files it names, such as meshes,
    read within ``reading``'s limits)."""
    entries = _Entries(file, reading, name)
    stop = None
    parser = reading.parser(text)
    get_event = parser.get_event
    document_line = 0  # where the document being read starts (0-based)
    try:
        get_event()  # StreamStartEvent
        while not parser.check_event(yaml.StreamEndEvent):
            if entries.documents == reading.max_documents:
                raise StreamStop(
                    "too-many-documents",
                    "",
                    f"more than {reading.max_documents} documents; the rest of the file is not read",
                    **located_mark(parser.peek_event().start_mark),
                )
            start = get_event()  # DocumentStartEvent
            document_line = start.start_mark.line
            events = []
            problems = None
            try:
                if not reading.fast:
                    raise Bail
                root = fast_document(get_event, events.append, file, reading)
            except Bail:
                # The general composer, from the document's first event.
                problems = Problems(reading.max_errors - entries.reported)
                root = compose(chain(events, iter(get_event, None)).__next__, problems)
            entries.add(start.start_mark.line + 1, root, problems)
    except StreamStop as reject:
        stop = reject
    except yaml.YAMLError as exc:
        stop = syntax_error(exc, text, document_line)
    finally:
        parser.dispose()
    return entries.close(stop)


class _Entries:
    """The entries of one file, made as its documents are read.

    Unnamed grasps are called after the file's stem, ``stem#k`` when the
    file has several documents (or a stop after the first): the first
    document's grasp is named ``stem`` until a second document shows up.
    """

    def __init__(self, file, reading, name=None):
        self.file = file
        self.reading = reading
        self.max_errors = reading.max_errors
        self.name = name  # the default name, if not the file's stem
        self.entries = []
        self.documents = 0
        self.reported = 0  # problems given an entry, at most max_errors
        self.unreported = 0
        self._stem = None
        self._first_unnamed = None  # the first document's grasp, when it took the default name

    def add(self, line, root, problems):
        """The entries of the next document, from its ``Parts`` (``problems``
        None) or its node tree (with the problems found composing it)."""
        document = self.documents
        self.documents += 1
        if document == 1:
            self._number_the_first()
        if type(root) is Parts:
            named = root.name is not None
            name = root.name if named else self._default_name(document)
            grasp = root.grasp(file=self.file, document=document, name=name, line=line)
        else:
            grasp = read_document(
                root,
                problems,
                file=self.file,
                document=document,
                name=self._default_name(document),
                line=line,
                reading=self.reading,
            )
            if grasp is None:
                first, covered = problems.first()
                self.reported += len(first)
                self.unreported += problems.count - covered
                self.entries += [reject.error(self.file, document) for reject in first]
                return
            named = "name" in root.value
        if document == 0 and not named:
            self._first_unnamed = len(self.entries)
        self.entries.append(grasp)

    def close(self, stop):
        """All the entries, ``stop`` (the problem that ended the reading, or None) among them."""
        if stop is not None:
            self._number_the_first()
            self.entries.append(stop.error(self.file, self.documents))
        elif not self.documents:
            return [InputError("empty-document", "no YAML document in the file", self.file)]
        if self.unreported:
            self.entries.append(
                InputError(
                    "too-many-errors",
                    f"{self.unreported} more problems in this file not reported (only the first {self.max_errors} are)",
                    self.file,
                )
            )
        return self.entries

    def _default_name(self, document):
        if self.name is not None:
            return self.name
        if self._stem is None:
            self._stem = stem_name(self.file)
        return self._stem if document == 0 else f"{self._stem}#{document + 1}"

    def _number_the_first(self):
        """The file has more than one document: an unnamed first grasp is ``stem#1``."""
        if self._first_unnamed is not None:
            grasp = self.entries[self._first_unnamed]
            self.entries[self._first_unnamed] = replace(grasp, name=f"{grasp.name}#1")
            self._first_unnamed = None


# Characters a grasp name must not hold (see NOT_IN_A_NAME), and the
# surrogates that stand for undecodable bytes in a file name.
_NOT_IN_A_STEM = re.compile("[\x00-\x1f\x7f-\x9f\u2028\u2029\ud800-\udfff]")


def stem_name(file):
    """A file's stem as a valid grasp name: bytes that are not UTF-8 (which
    Python keeps as surrogates) and control characters shown escaped,
    ``\\xff``, ``\\x1b``, as in a Python string."""

    def escape(match):
        code = ord(match.group())
        if 0xDC80 <= code <= 0xDCFF:  # os.fsdecode's stand-in for byte code - 0xDC00
            code -= 0xDC00
        return f"\\x{code:02x}" if code < 0x100 else f"\\u{code:04x}"

    return _NOT_IN_A_STEM.sub(escape, Path(file).stem)
