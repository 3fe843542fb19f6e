"""Inputs to encoded output, a group of files at a time, on one or more processes.

A command is a :class:`Job`: what every command shares, and the options of
its family of rows (:mod:`grasptwist.run.families`).  :func:`outputs` runs
any command.  For the families that go by groups (twist and wrench rows),
:func:`record_outputs` splits the inputs into groups of grasp files (and
data sets, each a stream of row blocks), turns each group into records,
their diagnostics and their encoded bytes with :func:`run_group`, and
yields the results in input order; the family says how a group's grasps
become blocks, and its command how blocks become records.  With several
workers the groups of files (or a data set's rows) are spread over a
:class:`~grasptwist.run.pool.Pool`; everything a worker sends back is already
encoded, so the parent only writes.  How big a group or a task is, and how
much may wait in memory, is one :class:`Tuning`.
"""

from __future__ import annotations

import os
import shutil
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field, replace
from functools import partial
from typing import TYPE_CHECKING, Any, NamedTuple

from ..io.datasets import DATASET_SUFFIXES, open_dataset
from ..io.grasp import READING, Reading
from ..io.lines import grasp_batches
from ..model import InputError
from ..output.formats import FORMATS
from ..output.records import error_record
from .batch import check_positions
from .families import COMMANDS, Command
from .outputs import Output
from .placement import placed, read
from .pool import Pool, pool_size
from .scratch import owned_prefix, remove_orphans
from .stream import is_stream

if TYPE_CHECKING:
    from ..model.hands import Hand

__all__ = [
    "Job",
    "Tuning",
    "TUNING",
    "Output",
    "Spool",
    "outputs",
    "record_outputs",
    "run_group",
    "blocks",
    "write_blocks",
]

#: Name stem of the spool folders in /dev/shm.
SPOOL_STEM = "grasptwist-"


@dataclass(frozen=True, kw_only=True, eq=False)  # never compared (its options are)
class Job:
    """What a command asks for (everything a worker needs): what every command shares, and
    ``options``, its family's own (None: the family's defaults; the options a command fixes,
    like ``basis``'s zero twist, are applied here)."""

    command: Command = field(default_factory=lambda: COMMANDS["resolve"])
    fmt: str = "jsonl"
    max_bytes: int | None = None
    reading: Reading = READING  # --surface-tol, --allow-outside: how grasp files and the files they name are read
    order: str = "omega-v"
    extra_point: str = "wrist"
    hand: Hand | None = None  # --hand: the hand of a data set's rows, whose joints CSV and npz columns name
    options: Any = None

    def __post_init__(self):
        kind = self.command.family.options()
        options = self.options if self.options is not None else kind()
        if not isinstance(options, kind):
            raise TypeError(f"{self.command.name} takes {kind.__name__}, got {type(options).__name__}")
        object.__setattr__(self, "options", replace(options, **self.command.fixed))

    @property
    def family(self):
        """The family of the command's rows."""
        return self.command.family


class Tuning(NamedTuple):
    """How work is cut up and how much of it may wait: sizes that change
    speed and memory, never output.

    >>> Tuning(files_per_group=2).records_at_once
    1024
    """

    #: Grasp files per group: enough rows for the engine's vectors, small enough to stream.
    files_per_group: int = 64
    #: Records built and encoded at once (and per output written, for data sets).
    records_at_once: int = 1024
    #: Grasps per task when a data set is spread over processes.
    grasps_per_task: int = 4096
    #: Groups of files from which a pool pays for its start.
    min_groups: int = 4
    #: Tasks a worker may hold that the parent has not yet taken: a slow reader stops the workers.
    in_flight: int = 2
    #: Bytes all workers together may leave in /dev/shm (at most a quarter of its free space).
    spool_bytes: int = 64 << 20


#: The tuning the command line uses.
TUNING = Tuning()


def outputs(job: Job, inputs: Sequence, w, workers: int = 1, tuning: Tuning = TUNING) -> Iterator[Output]:
    """Every input's outputs, in order, for any command: by its family's own way (``follow``'s
    paths), or by groups of files and data sets; a block format's rows go to ``w`` here."""
    if job.family.outputs is not None:
        return job.family.outputs(job, inputs, w, workers, tuning)
    if FORMATS[job.fmt].takes_blocks:
        return write_blocks(job, inputs, w, tuning)
    return record_outputs(job, inputs, workers, tuning)


def record_outputs(job: Job, paths: Sequence, workers: int = 1, tuning: Tuning = TUNING) -> Iterator[Output]:
    """Every input's output, in order.  ``paths`` holds file names, ``-``,
    and errors found while listing folders."""
    beside = job.family.beside(job, paths, tuning)
    if beside is not None:
        yield from _streamed(job, beside, tuning, files_first=True)  # the grasp files' errors come first
        return
    groups = list(_groups(paths, tuning.files_per_group))
    files = [g for g in groups if not _is_dataset(g)]
    # a pool pays for itself from a few groups on (stdin, a stream, is the parent's to read)
    if workers > 1 and len(files) >= tuning.min_groups:

        def task(spool, i):
            return [run_group(job, files[i], tuning, spool)]

        with _parallel(task, len(files), workers, tuning) as done:
            for g in groups:
                yield from (_alone(job, g, workers, tuning) if _is_dataset(g) else next(done))
        return
    for g in groups:
        yield from (_alone(job, g, workers, tuning) if _is_dataset(g) else [run_group(job, g, tuning)])


def _alone(job: Job, path: str, workers: int, tuning: Tuning) -> Iterator[Output]:
    """The outputs of an input read on its own: a stream, or a data set."""
    if not is_stream(path):
        return _dataset(job, path, workers, tuning)
    return _streamed(job, _stream_batches(job, path, tuning), tuning)


def _stream_batches(job: Job, path: str, tuning: Tuning):
    """The blocks and errors of the grasps of the stream ``path``, a batch of lines at a time
    (each batch's records are written as soon as it is read)."""
    for batch in grasp_batches(path, job.max_bytes, tuning.files_per_group, job.reading):
        yield list(job.family.rows(placed(batch), job))


def _streamed(job: Job, batches, tuning: Tuning, files_first: bool = False) -> Iterator[Output]:
    """An output per batch of a stream (see :mod:`~grasptwist.run.stream`): each
    line's records are written as soon as it is read."""
    done = 1  # the stream is one unit of progress
    for batch in batches:
        out = Output(done=done, rows=not files_first)
        done, files_first = 0, False
        for x in batch:
            _encode_into(job, x, out, tuning.records_at_once)
        yield _sealed(job, out)


@contextmanager
def _parallel(task, count: int, workers: int, tuning: Tuning) -> Iterator[Iterator[list[Output]]]:
    """``task(spool, i)`` for ``i < count`` on a pool of forked workers, in
    order; the workers share the parent's open files and data sets, and
    leave their encoded output in a :class:`Spool`."""
    workers = pool_size(workers, count)  # never a process with nothing to do
    with (
        Spool.opened(workers, tuning.spool_bytes) as spool,
        Pool(partial(task, spool), workers, tuning.in_flight) as pool,
    ):
        yield pool.results(count)


class Spool:
    """A folder in ``/dev/shm`` where workers leave encoded output, which the
    parent copies to its own output in the kernel (``sendfile``) instead of
    receiving the bytes by pipe.

    Each worker keeps at most ``share`` bytes there not yet taken by the
    parent (which deletes a file once copied); past that, or when a write
    fails (``/dev/shm`` full), :meth:`put` declines and the bytes go by pipe.
    """

    def __init__(self, folder: str, share: int):
        self.folder = folder
        self.share = share
        self._mine: list[tuple[str, int]] = []  # (path, size) put by this process

    @classmethod
    @contextmanager
    def opened(cls, workers: int, budget: int) -> Iterator[Spool | None]:
        """A spool for ``workers`` processes holding at most ``budget`` bytes
        in all (less when ``/dev/shm`` has little free: a quarter of its free
        space), removed on exit; None where there is no ``/dev/shm``."""
        shm = "/dev/shm"
        if not os.access(shm, os.W_OK):
            yield None
            return
        import tempfile  # with the first worker pool: a run of one process never needs it (bench/startup.py)

        remove_orphans(shm, SPOOL_STEM)  # what runs killed by SIGKILL left
        folder = None
        try:
            folder = tempfile.mkdtemp(prefix=owned_prefix(SPOOL_STEM), dir=shm)
            fs = os.statvfs(folder)
            yield cls(folder, min(budget, fs.f_bavail * fs.f_frsize // 4) // max(1, workers))
        finally:
            if folder is not None:
                shutil.rmtree(folder, ignore_errors=True)

    def put(self, blob: bytes) -> str | None:
        """A new spool file holding ``blob``, or None if it must go by pipe."""
        self._mine = [(path, size) for path, size in self._mine if os.path.exists(path)]
        if sum(size for _, size in self._mine) + len(blob) > self.share:
            return None
        import tempfile  # loaded by opened() already

        fd, path = tempfile.mkstemp(dir=self.folder)
        try:
            with os.fdopen(fd, "wb") as f:
                f.write(blob)
        except OSError:  # /dev/shm is full after all
            os.unlink(path)
            return None
        self._mine.append((path, len(blob)))
        return path


def _sealed(job: Job, out: Output, spool: Spool | None = None) -> Output:
    """An output ready to send: its records joined into one bytes object (one
    write), and in a worker put in the ``spool`` when it has room."""
    join = FORMATS[job.fmt].join
    if join is None or not out.encoded:
        return out
    blob = join(out.encoded)
    out.spool = spool.put(blob) if spool is not None else None
    out.encoded = [] if out.spool else [blob]
    return out


def run_group(job: Job, paths: Sequence, tuning: Tuning = TUNING, spool: Spool | None = None) -> Output:
    """Read a group of grasp files and turn them into one encoded :class:`Output`."""
    out = Output(done=len(paths))
    for x in job.family.rows(_read(job, paths), job):
        _encode_into(job, x, out, tuning.records_at_once)
    return _sealed(job, out, spool)


def _read(job: Job, paths: Sequence) -> list:
    """The grasps and errors of a group of files (and errors found listing folders), in order."""
    items = []
    for p in paths:
        items.extend(read(p, job.max_bytes, job.reading) if isinstance(p, str) else [p])
    return items


def blocks(job: Job, paths: Sequence, tuning: Tuning = TUNING) -> Iterator[tuple[Any, int | None, bool]]:
    """Blocks and errors of every input, in order (for writers that take
    blocks, like npz), each with its progress news: None for a group of
    files (one unit a file), else the records a data set holds beyond the
    one unit it counted as (on its first block; 0 after); and whether it
    holds rows of a data set or stream (whose errors stderr prints like
    warnings).  Data sets are resolved without basis screws when the format
    shows none."""
    bases = FORMATS[job.fmt].bases
    beside = job.family.beside(job, paths, tuning)
    if beside is not None:
        for k, batch in enumerate(beside):
            yield from ((x, None, k > 0) for x in batch)  # the first batch: the grasp files' errors
        return
    for g in _groups(paths, tuning.files_per_group):
        if is_stream(g):
            yield from ((x, None, True) for batch in _stream_batches(job, g, tuning) for x in batch)
        elif _is_dataset(g):
            try:
                ds = open_dataset(g, job.extra_point)
                extra_work = len(ds) * job.options.rows_per_grasp() - 1
                for block in job.family.dataset(ds, job, 0, None, bases):
                    if isinstance(block, InputError):  # one row's (a negative friction): one unit
                        yield block, None, True
                        continue
                    yield block, extra_work, True
                    extra_work = 0
            except InputError as err:
                yield err, None, False
        else:
            yield from ((x, None, False) for x in job.family.rows(_read(job, g), job))


def _encode_into(job: Job, x, out: Output, at_once: int) -> None:
    """Records of ``x`` (a block, or an input's error) encoded into ``out``, by the command's
    records and the format's encoding."""
    fmt = FORMATS[job.fmt]
    if isinstance(x, InputError):
        out.add(error_record(x), partial(fmt.error, job=job))
        return
    # a few thousand records at a time: their floats as Python objects would otherwise fill memory
    for start in range(0, len(x), at_once):
        out.add_encoded(*fmt.rows(x.part(start, start + at_once), job))


def _dataset(job: Job, path: str, workers: int, tuning: Tuning) -> Iterator[Output]:
    """A data set's outputs, a few thousand records each; the first one
    tells the progress bar how many records the data set holds."""
    try:
        ds = open_dataset(path, job.extra_point)
        check_positions(ds, job.hand)
        job.family.check_dataset(ds, job)
    except InputError as err:
        out = Output(done=1)
        _encode_into(job, err, out, tuning.records_at_once)
        yield _sealed(job, out)
        return
    rows = len(ds) * job.options.rows_per_grasp()
    step = tuning.grasps_per_task
    tasks = [(start, min(len(ds), start + step)) for start in range(0, len(ds), step)]
    if workers > 1 and len(tasks) > 1:

        def task(spool, i):
            return _dataset_task(job, ds, tasks[i], tuning, spool)

        with _parallel(task, len(tasks), workers, tuning) as parts:
            yield from _counted(parts, rows)
    else:
        yield from _counted((_dataset_task(job, ds, t, tuning) for t in tasks), rows)


def _counted(parts, rows):
    """The outputs of a data set's tasks, with their progress: records made,
    and on the first, the records beyond the one unit the input counted as."""
    first = True
    for outs in parts:
        for out in outs:
            out.done, out.extra_work = out.records, rows - 1 if first else 0
            first = False
            yield out


def _dataset_task(job: Job, ds, rows: tuple[int, int], tuning: Tuning, spool: Spool | None = None) -> list[Output]:
    """Records of the data set's grasps ``rows``, in outputs of ``tuning.records_at_once``."""
    at_once = tuning.records_at_once
    outs = []
    made = job.family.dataset(ds, job, rows[0], rows[1], FORMATS[job.fmt].bases)
    try:
        for block in made:
            if isinstance(block, InputError):  # one row's (a negative friction), in its place
                out = Output()
                _encode_into(job, block, out, at_once)
                outs.append(_sealed(job, out, spool))
                continue
            for start in range(0, len(block), at_once):
                out = Output(rows=True)
                _encode_into(job, block.part(start, start + at_once), out, at_once)
                outs.append(_sealed(job, out, spool))
    except InputError as err:  # a damaged .npz member or Parquet row group, found only as it is read
        out = Output()
        _encode_into(job, err, out, at_once)
        outs.append(_sealed(job, out, spool))
    return outs


def _is_dataset(group) -> bool:
    return isinstance(group, str)


def _groups(paths, size: int):
    """Consecutive grasp files in lists of ``size``; each data set and stream on its own (a str)."""
    group = []
    for p in paths:
        if is_stream(p) or isinstance(p, str) and p.endswith(DATASET_SUFFIXES) and os.path.isfile(p):
            if group:
                yield group
                group = []
            yield p
            continue
        group.append(p)
        if len(group) >= size:
            yield group
            group = []
    if group:
        yield group


def write_blocks(job: Job, paths: Sequence, w, tuning: Tuning = TUNING) -> Iterator[Output]:
    """Resolve everything into ``w``, a writer that takes blocks (npz).

    Yields an :class:`Output` per block with its counts and stderr lines
    (records are built only for the rows that need a line: failed or
    nearly degenerate ones); the caller closes ``w``.
    """
    for x, extra_work, rows in blocks(job, paths, tuning):
        o = Output(done=len(x) if extra_work is not None else 1, extra_work=extra_work or 0, rows=rows)
        if not isinstance(x, InputError):
            w.write(x)
            for rec in job.command.talking(x, job):
                o.add(rec, lambda rec: None)
            o.records = len(x)
        else:
            o.add(error_record(x), lambda rec: None)
        o.encoded = []  # the rows went to ``w``; an input that failed has its stderr line only
        yield o
