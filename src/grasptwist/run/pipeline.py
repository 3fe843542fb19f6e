"""Inputs to encoded output, a group of files at a time, on one or more processes.

A command is a :class:`Job`.  :func:`run` splits its inputs into groups of
grasp files (and data sets, each a stream of row blocks), turns each group
into records, their diagnostics and their encoded bytes with
:func:`run_group`, and yields the results in input order.  With several
workers the groups of files are spread over a process pool; everything a
worker sends back is already encoded, so the parent only writes.
"""

from __future__ import annotations

import gc
import os
import tempfile
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from functools import partial

import numpy as np

from ..io.datasets import DATASET_SUFFIXES, NpzWriter, dataset_blocks, open_dataset
from ..io.inputs import STDIN, read
from ..model import GraspFileError, Twist
from ..output.json_rows import encode_records
from ..output.records import (
    ENCODERS,
    JOINERS,
    basis_record,
    check_record,
    diagnostics,
    dumps,
    error_record,
    records,
    talking_rows,
)
from .batch import ZERO_TWIST, Block, resolve

__all__ = ["Job", "Output", "run", "run_group", "blocks", "write_npz", "FILES_PER_GROUP"]

#: Grasp files per group: enough rows for the engine's vectors, small enough to stream.
FILES_PER_GROUP = 64

#: Records built and encoded at once (and per output written, for data sets).
RECORDS_AT_ONCE = 1024


@dataclass(frozen=True)
class Job:
    """What a command asks for (everything a worker needs, picklable)."""

    kind: str = "resolve"  # resolve, basis or check
    twists: tuple[Twist, ...] | None = None
    method: str = "both"
    order: str = "omega-v"
    fmt: str = "jsonl"
    max_bytes: int | None = None
    extra_point: str = "wrist"


@dataclass
class Output:
    """The encoded records of one group, with their stderr lines and counts."""

    encoded: list = field(default_factory=list)
    errors: list[str] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    records: int = 0
    failed: int = 0
    done: int = 0  # progress: files read, or data-set records made
    grows: int = 0  # progress: work found beyond the one unit an input was counted as
    spool: str | None = None  # a file holding ``encoded`` (see _sealed)

    def add(self, rec: dict, encode) -> None:
        self._note(rec)
        self.records += 1
        self.encoded.append(encode(rec))

    def add_encoded(self, texts: list[bytes], talking: list[dict]) -> None:
        """Records already encoded; ``talking`` are those with errors or warnings."""
        for rec in talking:
            self._note(rec)
        self.records += len(texts)
        self.encoded += texts

    def _note(self, rec: dict) -> None:
        errors, warnings = diagnostics(rec)
        self.errors += errors
        self.warnings += warnings
        self.failed += not rec["ok"]


def run(job: Job, paths: Sequence, workers: int = 1) -> Iterator[Output]:
    """Every input's output, in order.  ``paths`` holds file names, ``-``,
    and errors found while listing folders."""
    groups = list(_groups(paths))
    files = [g for g in groups if not _is_dataset(g)]
    # a pool pays for itself from a few groups on; stdin is the parent's to read
    if workers > 1 and len(files) >= 4 and not any(STDIN in g for g in files):
        with _pool(workers) as pool:
            done = pool.imap(partial(run_group, job), files)
            for g in groups:
                yield from (_dataset(job, g, workers) if _is_dataset(g) else [next(done)])
        return
    for g in groups:
        yield from (_dataset(job, g, workers) if _is_dataset(g) else [run_group(job, g)])


@contextmanager
def _pool(workers):
    """A forked pool (workers start at once and share the parent's open data
    set) and a spool folder in which they leave their encoded output."""
    import multiprocessing
    import shutil

    shm = "/dev/shm"
    spool = tempfile.mkdtemp(prefix="grasptwist-", dir=shm if os.access(shm, os.W_OK) else None)
    _SHARED.update(spool=spool, parent=os.getpid())
    try:
        with multiprocessing.get_context("fork").Pool(workers) as pool:
            yield pool
    finally:
        shutil.rmtree(spool, ignore_errors=True)
        _SHARED.pop("spool", None)


def _sealed(job: Job, out: Output) -> Output:
    """An output ready to send: its records joined into one bytes object (one
    write), and in a worker moved to a spool file, which the parent copies to
    its output in the kernel instead of receiving the bytes by pipe."""
    if job.fmt not in JOINERS or not out.encoded:
        return out
    blob = JOINERS[job.fmt](out.encoded)
    spool = _SHARED.get("spool")
    if spool and os.getpid() != _SHARED["parent"]:
        fd, path = tempfile.mkstemp(dir=spool)
        with os.fdopen(fd, "wb") as f:
            f.write(blob)
        out.encoded, out.spool = [], path
    else:
        out.encoded = [blob]
    return out


def run_group(job: Job, paths: Sequence) -> Output:
    """Read a group of grasp files and resolve them into one encoded :class:`Output`."""
    items = []
    for p in paths:
        items.extend(read(p, job.max_bytes) if isinstance(p, str) else [p])
    out = Output(done=len(paths))
    twists = [ZERO_TWIST] if job.kind != "resolve" else job.twists
    for x in resolve(items, twists, job.method):
        _emit(job, x, out)
    return _sealed(job, out)


def blocks(job: Job, paths: Sequence) -> Iterator[tuple[Block | GraspFileError, int | None]]:
    """Blocks and errors of every input, in order (for writers that take
    blocks, like npz), each with its progress news: None for a group of
    files (one unit a file), else the records a data set holds beyond the
    one unit it counted as (on its first block; 0 after)."""
    for g in _groups(paths):
        if _is_dataset(g):
            try:
                ds = open_dataset(g, job.extra_point)
                grows = len(ds) * (len(job.twists) if job.twists else 1) - 1
                for block in dataset_blocks(ds, job.twists, job.method, bases=False):  # npz shows no screws
                    yield block, grows
                    grows = 0
            except GraspFileError as err:
                yield err, None
            continue
        items = []
        for p in g:
            items.extend(read(p, job.max_bytes) if isinstance(p, str) else [p])
        for x in resolve(items, job.twists, job.method):
            yield x, None


@contextmanager
def _no_gc():
    """Records are acyclic dicts and lists: building thousands of them with the
    cyclic garbage collector on spends more time collecting than building."""
    was_on = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was_on:
            gc.enable()


def _emit(job: Job, x, out: Output) -> None:
    with _no_gc():
        _emit_records(job, x, out)


def _emit_records(job: Job, x, out: Output) -> None:
    encode = ENCODERS[job.fmt]
    if not isinstance(x, Block):
        out.add(error_record(x), encode)
    elif job.kind == "resolve":
        # a few thousand records at a time: their floats as Python objects
        # would otherwise fill memory and keep the garbage collector busy
        for start in range(0, len(x), RECORDS_AT_ONCE):
            part = x.part(start, start + RECORDS_AT_ONCE)
            if job.fmt in ("json", "jsonl"):
                texts, talking = encode_records(part, job.order, records, dumps)
                out.add_encoded(texts, talking)
            else:
                for rec in records(part, job.order):
                    out.add(rec, encode)
    else:
        for i in range(len(x)):
            out.add(basis_record(x, i, job.order) if job.kind == "basis" else check_record(x, i), encode)


#: The data set being resolved, for the workers forked to share it.
_SHARED: dict = {}

#: Grasps per task when a data set is spread over processes.
GRASPS_PER_TASK = 4096


def _dataset(job: Job, path: str, workers: int = 1) -> Iterator[Output]:
    """A data set's outputs, a few thousand records each; the first one
    tells the progress bar how many records the data set holds."""
    try:
        ds = open_dataset(path, job.extra_point)
        if job.twists is None and ds.twist is None and job.kind == "resolve":
            next(dataset_blocks(ds, None, job.method))  # raises the no-twist error
    except GraspFileError as err:
        out = Output(done=1)
        _emit(job, err, out)
        yield _sealed(job, out)
        return
    rows = len(ds) * (len(job.twists) if job.twists and job.kind == "resolve" else 1)
    tasks = [(start, min(len(ds), start + GRASPS_PER_TASK)) for start in range(0, len(ds), GRASPS_PER_TASK)]
    _SHARED["dataset"] = ds
    try:
        if workers > 1 and len(tasks) > 1:
            with _pool(workers) as pool:
                parts = pool.imap(partial(_dataset_task, job), tasks)
                yield from _counted(parts, rows)
        else:
            yield from _counted((_dataset_task(job, t) for t in tasks), rows)
    finally:
        _SHARED.clear()


def _counted(parts, rows):
    """The outputs of a data set's tasks, with their progress: records made,
    and on the first, the records beyond the one unit the input counted as."""
    first = True
    for outs in parts:
        for out in outs:
            out.done, out.grows = out.records, rows - 1 if first else 0
            first = False
            yield out


def _dataset_task(job: Job, rows: tuple[int, int]) -> list[Output]:
    """Records of the data set's grasps ``rows``, in outputs of RECORDS_AT_ONCE."""
    twists = [ZERO_TWIST] if job.kind != "resolve" else job.twists
    outs = []
    for block in dataset_blocks(_SHARED["dataset"], twists, job.method, start=rows[0], stop=rows[1]):
        for start in range(0, len(block), RECORDS_AT_ONCE):
            out = Output()
            _emit(job, block.part(start, start + RECORDS_AT_ONCE), out)
            outs.append(_sealed(job, out))
    return outs


def _is_dataset(group) -> bool:
    return isinstance(group, str)


def _groups(paths):
    """Consecutive grasp files in lists of FILES_PER_GROUP; each data set on its own (a str)."""
    group = []
    for p in paths:
        if isinstance(p, str) and p.endswith(DATASET_SUFFIXES) and os.path.isfile(p):
            if group:
                yield group
                group = []
            yield p
            continue
        group.append(p)
        if len(group) >= FILES_PER_GROUP:
            yield group
            group = []
    if group:
        yield group


def write_npz(job: Job, paths: Sequence, out) -> Iterator[Output]:
    """Resolve everything into one ``.npz`` on ``out``.

    Yields an :class:`Output` per block with its counts and stderr lines
    (records are built only for the rows that need a line: failed or
    nearly degenerate ones); the archive is complete when the iterator is.
    """
    w = NpzWriter(out, job.order)
    for x, grows in blocks(job, paths):
        o = Output(done=len(x) if grows is not None else 1, grows=grows or 0)
        if isinstance(x, Block):
            w.write(x)
            talking = np.flatnonzero(talking_rows(x))
            for rec in records(x.take(talking), job.order) if talking.size else []:
                o.add(rec, lambda rec: None)
            o.records = len(x)
            o.encoded = []
        else:
            o.add(error_record(x), lambda rec: None)
        yield o
    w.close()
