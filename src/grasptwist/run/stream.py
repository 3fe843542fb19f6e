"""Streams: the records of each line of input out as soon as the line arrives.

``resolve -`` (as JSON Lines) and ``*.jsonl`` files give a grasp per line;
``--twists-from`` gives a twist per line for the grasps of the files named.
Each yields lists of resolved rows and errors, one list per line when the
lines may come one by one (a pipe), so that the caller can write and flush
each line's records before the next line is read; memory stays that of
one line.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence

from ..io.grasp import READING, Reading
from ..io.inputs import STDIN
from ..io.lines import grasp_batches, is_json_lines, twist_batches
from ..model import Grasp, InputError, Twist
from .batch import Block, resolve
from .placement import placed, read

__all__ = ["is_stream", "twist_stream"]


def is_stream(path) -> bool:
    """Whether ``path`` is read a line at a time: ``-`` or a ``*.jsonl`` file.

    >>> [is_stream(p) for p in ("-", "a.jsonl", "a.yaml")]
    [True, True, False]
    """
    return isinstance(path, str) and (path == STDIN or is_json_lines(path))


def twist_stream(
    paths: Sequence, twists_from: str, method: str, max_bytes: int | None, per_batch: int, reading: Reading = READING
) -> Iterator[list]:
    """The grasps of ``paths`` resolved with each twist of the stream
    ``twists_from`` in turn: first the errors of the grasps' files, then for
    each twist line its rows (one per grasp, in order) or its errors."""
    grasps, errors = [], []
    for p in paths:
        for item in _items(p, max_bytes, per_batch, reading):
            (grasps if isinstance(item, Grasp) else errors).append(item)
    yield errors
    for batch in twist_batches(twists_from, max_bytes, per_batch):
        out: list[Block | InputError] = []
        run: list[Twist] = []  # consecutive good twists, resolved together
        for twist in [*batch, None]:
            if isinstance(twist, Twist):
                run.append(twist)
                continue
            out.extend(_twist_major(grasps, run, method))
            run = []
            if twist is not None:
                out.append(twist)
        yield out


def _twist_major(grasps, twists, method):
    """The rows of each twist with every grasp, twist by twist."""
    if not twists:
        return []
    if len(grasps) == 1:  # one grasp: its rows with the twists are in twist order already
        return resolve(grasps, twists, method)
    return [x for t in twists for x in resolve(grasps, [t], method)]


def _items(path, max_bytes, per_batch, reading):
    """The grasps and errors of one input (a file, a stream or an error found listing folders)."""
    if not isinstance(path, str):
        return [path]
    if is_stream(path):
        return [item for batch in grasp_batches(path, max_bytes, per_batch, reading) for item in placed(batch)]
    return read(path, max_bytes, reading)
