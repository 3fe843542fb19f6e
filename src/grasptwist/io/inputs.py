"""Which files a command reads: paths, folders and stdin, in a stable order.

A folder is searched at any depth for grasp files: names ending in ``.yaml``,
``.yml`` or ``.json`` (JSON is YAML), in any letter case, or in the suffixes a
command's family reads (``synthesize`` also takes mesh files: :data:`OBJECT_SUFFIXES`).  Its files come
sorted by their path relative to it.  The walk keeps its own stack instead
of recursing, so no depth of folders can exhaust Python's recursion limit.
Symbolic links are followed, but a folder reached twice (a link cycle, or two
links to one place) is read only the first time.  A path that cannot be read,
a folder that cannot be listed, and a folder with no grasp file at all each
become a :class:`InputError` in its place, so that the rest of the batch
goes on.  JSON Lines files (``*.jsonl``) are read when named, not found
in folders (:mod:`~grasptwist.io.lines` reads them, and ``-``, a line at a
time).  Names are ``str`` throughout: bytes that are not UTF-8 are kept
as Python's surrogate escapes (``os.fsdecode``), so every path still opens.
"""

from __future__ import annotations

import errno
import os
from collections.abc import Iterable, Iterator

from ..model import Grasp, InputError
from .grasp import READING, Reading, one_per_document, read_grasps
from .limits import DEFAULT_MAX_BYTES, MESH_SUFFIXES, NOT_REGULAR

__all__ = ["GRASP_SUFFIXES", "OBJECT_SUFFIXES", "STDIN", "expand", "is_grasp_file", "read"]

GRASP_SUFFIXES = (".yaml", ".yml", ".json")
#: The files a folder gives a command that reads objects (``synthesize``): grasp and mesh files.
OBJECT_SUFFIXES = (*GRASP_SUFFIXES, *MESH_SUFFIXES)
STDIN = "-"


def is_grasp_file(name: str, suffixes: tuple[str, ...] = GRASP_SUFFIXES) -> bool:
    """Whether a folder's entry ``name`` is read (its suffix among ``suffixes``, in any case).

    >>> [is_grasp_file(n) for n in ("box.yaml", "BOX.YML", "hand.json", "notes.txt", "yaml", "can.STL")]
    [True, True, True, False, False, False]
    >>> is_grasp_file("can.STL", OBJECT_SUFFIXES)
    True
    """
    return name.lower().endswith(suffixes)


def expand(paths: Iterable[str], suffixes: tuple[str, ...] = GRASP_SUFFIXES) -> Iterator[str | InputError]:
    """Every file named by ``paths``, folders expanded (their files ending in ``suffixes``), in order."""
    stdin_seen = False
    for path in paths:
        if path == STDIN and stdin_seen:
            yield _io_error(path, "standard input can be read only once")
        elif path == STDIN or os.path.isfile(path):
            stdin_seen |= path == STDIN
            yield path
        elif os.path.isdir(path):
            yield from _walk(path, suffixes)
        else:
            yield _io_error(path, _not_a_file(path))


def _not_a_file(path: str) -> str:
    """Why ``path`` is neither a regular file nor a folder (a pipe, socket or
    device would block or never end: never open one)."""
    try:
        os.stat(path)
    except OSError as exc:
        if exc.errno == errno.ENOENT:
            return "a symbolic link to nothing" if os.path.islink(path) else "no such file or folder"
        return exc.strerror or str(exc)  # e.g. a link to itself: too many levels of symbolic links
    return NOT_REGULAR


def _walk(top: str, suffixes: tuple[str, ...]) -> Iterator[str | InputError]:
    """The files ending in ``suffixes`` under the folder ``top``, depth first in name order.

    Visiting each folder's entries in name order, a subfolder's files at its
    name's place, gives the files sorted by their path's components.
    """
    seen: set[tuple[int, int]] = set()  # (device, inode) of the folders listed
    pending: list[tuple[bool, str | InputError]] = [(True, top)]  # (a folder?, path or error), next last
    empty = True
    while pending:
        folder, item = pending.pop()
        if not folder:
            empty = False
            yield item
            continue
        try:
            info = os.stat(item)
            if (info.st_dev, info.st_ino) in seen:
                continue  # a cycle, or a second link to a folder already read
            seen.add((info.st_dev, info.st_ino))
            with os.scandir(item) as listing:
                entries = sorted(listing, key=lambda entry: entry.name)
        except OSError as exc:
            empty = False
            yield _io_error(item, exc.strerror or str(exc))
            continue
        for entry in reversed(entries):
            if _is_dir(entry):
                pending.append((True, entry.path))
            elif is_grasp_file(entry.name, suffixes):
                pending.append(
                    (False, entry.path if _is_file(entry) else _io_error(entry.path, _not_a_file(entry.path)))
                )
    if empty:
        names = ", ".join(suffixes[:-1]) + " or " + suffixes[-1]
        yield InputError(
            "no-grasp-files",
            f"no grasp files in this folder or below it (looked for names ending in {names}, in any letter case)",
            top,
        )


def _is_dir(entry: os.DirEntry) -> bool:
    try:
        return entry.is_dir()  # follows a link
    except OSError:
        return False


def _is_file(entry: os.DirEntry) -> bool:
    try:
        return entry.is_file()  # follows a link; no system call for a plain file
    except OSError:
        return False


def read(path: str, max_bytes: int | None = None, reading: Reading = READING) -> list[Grasp | InputError]:
    """The grasps (or errors: one per failed document, every problem in its ``problems``)
    of one file; ``-`` reads standard input; ``reading`` as for :func:`~grasptwist.read_grasps`."""
    cap = DEFAULT_MAX_BYTES if max_bytes is None else max_bytes
    return one_per_document(read_grasps(path, max_bytes=cap, reading=reading))


def _io_error(path: str, why: str) -> InputError:
    return InputError(code="read-error", message=f"cannot read: {why}", file=path, line=None, column=None)
