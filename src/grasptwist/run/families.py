"""The families of rows and the commands that show them, registered once; every layer loops over them.

A *family* is a kind of row a command writes: twist rows (a grasp and a
twist: ``resolve``, ``basis``, ``check``), wrench rows (a grasp and a
wrench: ``forces``) and path samples (a grasp moved along a path:
``follow``).  Each owns its options, its compute (how a group of read
grasps, a stream's lines or a data set's rows become blocks of results) and
its columns (:mod:`grasptwist.output.column_sets`).  A *command* shows a
family's rows: its records, its table and the formats it offers.  The
pipeline (:mod:`grasptwist.run.pipeline`), the output formats
(:mod:`grasptwist.output.formats`) and the command line read a job's
command and family here and never compare a command's name; a test
(``tests/test_layers.py``) holds that.

What a family adds to another's records is a :class:`Contribution`:
``check`` shows, beside each method's verdict, the least friction that
closes the grasp, which the wrench family computes.

How to add a family
-------------------
Say, grasps synthesised on an object's surface (``grasptwist synthesise``):

1. Compute its rows in ``run/``: a module with its options (a frozen
   dataclass whose defaults are a command line without options), its block
   type (``__len__`` and ``part(start, stop)``; anything else a family
   yields is an input's error, written as an error record) and ``rows(items,
   job)``: read grasps and errors in, blocks and errors out, in order.  The
   math stays in ``engine/``.  Rows of a data set: ``dataset(ds, job,
   start, stop, bases)`` and ``per_grasp(options)``; else leave them None.
   A family that is not cut into groups of files (``follow``: its paths
   stream in order) gives ``outputs`` instead.
2. Its columns: a :class:`~grasptwist.output.columns.ColumnSet` in
   :mod:`grasptwist.output.column_sets` (CSV header and lines, npz arrays,
   Parquet's typed columns), and its records in an ``output/`` module.
3. Register a :class:`Family` here, and a :class:`Command` per command that
   shows it: its records, its table writer (a class in
   :mod:`grasptwist.output`, named), its formats, what it adds to other
   commands (a :class:`Contribution`).
4. A module in ``cli/`` declaring the command's options, building the
   :class:`~grasptwist.run.pipeline.Job` of ``COMMANDS[name]`` and calling
   :func:`grasptwist.cli.records.write_records`; the formats, the table, the
   progress bar, stderr and the exit status follow from the registry.

To add a result kind to an existing family (a new decomposition) see
:mod:`grasptwist.results`.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field
from typing import Any

from ..output import follow_records
from ..output.column_sets import PATH_COLUMNS, TWIST_COLUMNS, WRENCH_COLUMNS
from ..output.columns import ColumnSet
from ..output.force_records import force_records
from ..output.formats import FORMATS
from ..output.json_rows import encode_records
from ..output.records import basis_record, check_record, dumps, records, talking_rows
from .batch import ZERO_TWIST, Block, TwistOptions, dataset_blocks, resolve
from .follow import FollowOptions, Samples, follow_outputs
from .forces import ForceBlock, ForceOptions, closure_fields, force_blocks, force_dataset_blocks, rows_per_grasp
from .stream import twist_stream

__all__ = ["Family", "Contribution", "Command", "FAMILIES", "COMMANDS", "TWIST", "WRENCH", "PATH", "CLOSURE"]


@dataclass(frozen=True)
class Family:
    """One family of rows: its options, how they are computed, their columns.

    Attributes
    ----------
    name : str
        What its rows are (``twist``, ``wrench``, ``path``).
    options : type
        Its options: a frozen dataclass, defaults when called without arguments.
    block : type
        Its blocks of results; anything else its compute yields is an input's error.
    columns : ColumnSet
        Its rows as CSV, npz and Parquet columns.
    rows : callable or None
        ``(items, job) -> blocks and errors``: a group's read grasps and loader
        errors (a group of files, a stream's batch of lines), in order.
    dataset : callable or None
        ``(ds, job, start, stop, bases) -> blocks``: the rows of a data set's grasps
        ``start:stop`` (``stop`` None: to its end).
    per_grasp : callable
        ``options -> int``: rows each grasp of a data set gives.
    check_dataset : callable
        ``(ds, job) -> None``: raises the data set's error before any row.
    beside : callable
        ``(job, paths, tuning) -> batches or None``: rows whose other half streams
        beside the files (``--twists-from``), a batch per line; None: none.
    outputs : callable or None
        ``(job, inputs, w, workers, tuning) -> outputs``: its own way from inputs
        to :class:`~grasptwist.run.outputs.Output` objects; None: the pipeline's
        groups and data sets.
    tells_progress : bool
        A progress bar and the table hint count its records (``follow`` tells
        a path by its summary instead).
    """

    name: str
    options: type
    block: type
    columns: ColumnSet
    rows: Callable[[list, Any], Iterator] | None = None
    dataset: Callable[..., Iterator] | None = None
    per_grasp: Callable[[Any], int] = lambda options: 1
    check_dataset: Callable[[Any, Any], None] = lambda ds, job: None
    beside: Callable[..., Any] = lambda job, paths, tuning: None
    outputs: Callable[..., Iterator] | None = None
    tells_progress: bool = True


@dataclass(frozen=True)
class Contribution:
    """What a family adds to another command's records: fields per row and a table column.

    Attributes
    ----------
    family : Family
        The family that computes it.
    fields : callable
        ``block -> list of dict``: the fields it adds to each row's record.
    header : str
        Its column in the command's table.
    cell : str
        Name of its cell renderer (``record -> Text``) in :mod:`grasptwist.output.table`.
    """

    family: Family
    fields: Callable[[Any], list[dict]]
    header: str
    cell: str


def _all_talking(block, job) -> list[dict]:
    return [rec for rec in job.command.records(block, job) if not rec["ok"] or rec["warnings"]]


@dataclass(frozen=True)
class Command:
    """One command: the family whose rows it shows, its records, its table and formats.

    Attributes
    ----------
    name : str
        The command (``grasptwist <name>``).
    family : Family
        The family of its rows.
    formats : tuple of str
        The ``-f`` values it offers, in :data:`~grasptwist.output.formats.FORMATS` order.
    records : callable
        ``(block, job) -> list of dict``: the records of a block's rows.
    table : str
        Its table writer, ``"module.Class"`` in :mod:`grasptwist.output` (rich loads
        only when a table is asked for).
    json_rows : callable or None
        ``(block, job) -> (JSON texts, records with something to say)``, faster than
        encoding ``records``; None: ``records``, encoded one by one.
    talking : callable
        ``(block, job) -> records``: the records of the rows with something for stderr.
    contributions : tuple of Contribution
        What other families add to its records.
    fixed : mapping
        Options of its family that the command fixes.
    """

    name: str
    family: Family
    formats: tuple[str, ...]
    records: Callable[[Any, Any], list[dict]]
    table: str
    json_rows: Callable[[Any, Any], tuple[list, list[dict]]] | None = None
    talking: Callable[[Any, Any], list[dict]] = _all_talking
    contributions: tuple[Contribution, ...] = ()
    fixed: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self):
        unknown = [f for f in self.formats if f not in FORMATS]
        if unknown:
            raise ValueError(f"{self.name}: no output format {unknown}")


# -- twist rows ---------------------------------------------------------------


def _twist_rows(items, job):
    o = job.options
    return resolve(items, o.twists, o.method, select=o.select)


def _twist_dataset(ds, job, start, stop, bases):
    o = job.options
    return dataset_blocks(ds, o.twists, o.method, start=start, stop=stop, bases=bases, hand_of_rows=job.hand)


def _twist_check(ds, job):
    if job.options.twists is None and ds.twist is None:
        next(_twist_dataset(ds, job, 0, None, True))  # raises the no-twist error


def _twists_beside(job, paths, tuning):
    o = job.options
    if o.twists_from is None:
        return None
    return twist_stream(paths, o.twists_from, o.method, job.max_bytes, tuning.files_per_group)


TWIST = Family(
    name="twist",
    options=TwistOptions,
    block=Block,
    columns=TWIST_COLUMNS,
    rows=_twist_rows,
    dataset=_twist_dataset,
    per_grasp=lambda options: len(options.twists) if options.twists else 1,
    check_dataset=_twist_check,
    beside=_twists_beside,
)

# -- wrench rows --------------------------------------------------------------

WRENCH = Family(
    name="wrench",
    options=ForceOptions,
    block=ForceBlock,
    columns=WRENCH_COLUMNS,
    rows=lambda items, job: force_blocks(items, job.options),
    dataset=lambda ds, job, start, stop, bases: force_dataset_blocks(ds, job.options, start=start, stop=stop),
    per_grasp=rows_per_grasp,
)

#: The wrench family's part of ``check`` records: each grasp's closure.
CLOSURE = Contribution(WRENCH, closure_fields, "closure mu", "closure_cell")

# -- path samples -------------------------------------------------------------

PATH = Family(
    name="path",
    options=FollowOptions,
    block=Samples,
    columns=PATH_COLUMNS,
    outputs=follow_outputs,
    tells_progress=False,
)

#: Every family.
FAMILIES: tuple[Family, ...] = (TWIST, WRENCH, PATH)

# -- commands -----------------------------------------------------------------


def _resolve_records(block, job):
    return records(block, job.order)


def _resolve_json(block, job):
    return encode_records(block, job.order, records, dumps)


def _resolve_talking(block, job):
    talking = talking_rows(block).nonzero()[0]
    return records(block.take(talking), job.order) if talking.size else []


def _basis_records(block, job):
    return [basis_record(block, i, job.order) for i in range(len(block))]


def _check_records(block, job):
    added = [c.fields(block) for c in job.command.contributions]
    return [check_record(block, i, {k: v for part in added for k, v in part[i].items()}) for i in range(len(block))]


_RECORDS = ("table", "json", "jsonl")
_ROWS = (*_RECORDS, "csv", "npz", "parquet")

#: Every command by name, in the order of ``grasptwist -h``.
COMMANDS: dict[str, Command] = {
    c.name: c
    for c in (
        Command(
            "resolve",
            TWIST,
            _ROWS,
            _resolve_records,
            "table.TableWriter",
            json_rows=_resolve_json,
            talking=_resolve_talking,
        ),
        Command("basis", TWIST, _RECORDS, _basis_records, "table.BasisTableWriter", fixed={"twists": (ZERO_TWIST,)}),
        Command(
            "check",
            TWIST,
            _RECORDS,
            _check_records,
            "table.CheckTableWriter",
            contributions=(CLOSURE,),
            fixed={"twists": (ZERO_TWIST,)},
        ),
        Command(
            "follow",
            PATH,
            (*_RECORDS, "csv", "npz"),
            lambda samples, job: follow_records.sample_records(samples, job.order),
            "follow_table.FollowTable",
        ),
        Command("forces", WRENCH, _ROWS, lambda block, job: force_records(block), "table.ForceTableWriter"),
    )
}
