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
(``tests/api/test_layers.py``) holds that.

What a family adds to another's records is a :class:`Contribution`:
``check`` shows, beside each method's verdict, the least friction that
closes the grasp, which the wrench family computes.

How to add a family
-------------------
Say, grasps synthesised on an object's surface (``grasptwist synthesise``):

1. Its options in :mod:`.family_options` (named in :mod:`.options`' ``_ELSEWHERE``): a frozen
   dataclass whose defaults are a command line without options (``rows_per_grasp()`` if it
   reads data sets).
2. Compute its rows in a module of ``run/``: its block type (``__len__`` and
   ``part(start, stop)``) and ``rows(items, job)``: read grasps and errors
   in, blocks and errors (:class:`~grasptwist.model.InputError`, written as
   error records) out, in order.  The math stays in ``engine/``.  Rows of a
   data set: ``dataset(ds, job, start, stop, bases)``.  A family that is not
   cut into groups of files (``follow``: its paths stream in order) gives
   ``outputs`` instead.
3. Its columns: a :class:`~grasptwist.output.columns.ColumnSet` beside its
   records in an ``output/`` module (CSV header and lines, npz arrays,
   Parquet's typed columns).
4. Register a :class:`Family` here, and a :class:`Command` per command that
   shows it: its records, its table writer (a class in
   :mod:`grasptwist.output`, named), its formats, what it adds to other
   commands (a :class:`Contribution`).  Its compute, records and columns are
   reached through small functions that import them when first called, so
   that other commands never load them.
5. A module in ``cli/`` declaring the command's options, building the
   :class:`~grasptwist.run.pipeline.Job` of ``COMMANDS[name]`` and calling
   :func:`grasptwist.cli.records.write_records`; the formats, the table, the
   progress bar, stderr and the exit status follow from the registry.

To add a result kind to an existing family (a new decomposition) see
:mod:`grasptwist.results`.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field
from functools import partial
from typing import Any, NamedTuple

from ..io.inputs import GRASP_SUFFIXES, OBJECT_SUFFIXES
from ..output.formats import FORMATS
from ..output.json_rows import encode_records
from ..output.records import basis_record, check_record, dumps, records, talking_rows
from .batch import ZERO_TWIST, dataset_blocks, resolve
from .options import NOT_SIMULATED
from .stream import twist_stream

__all__ = [
    "Family",
    "Contribution",
    "Command",
    "FAMILIES",
    "COMMANDS",
    "TWIST",
    "WRENCH",
    "PATH",
    "SYNTHESIS",
    "SIMULATION",
    "CLOSURE",
]


class Family(NamedTuple):
    """One family of rows: its options, how they are computed, their columns.

    Attributes
    ----------
    name : str
        What its rows are (``twist``, ``wrench``, ``path``).
    options : callable
        ``() -> type``: its options (:mod:`.options`), a frozen dataclass, defaults when called
        without arguments (the other families' are defined when first asked for).
    columns : callable
        ``() -> ColumnSet``: its rows as CSV, npz and Parquet columns (loaded when a format
        writes columns).
    rows : callable or None
        ``(items, job) -> blocks and errors``: a group's read grasps and loader
        errors (a group of files, a stream's batch of lines), in order; anything
        but an :class:`~grasptwist.model.InputError` is a block (``__len__``,
        ``part(start, stop)``).
    dataset : callable or None
        ``(ds, job, start, stop, bases) -> blocks``: the rows of a data set's grasps
        ``start:stop`` (``stop`` None: to its end), ``options.rows_per_grasp()`` each.
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
    long_inputs : bool
        Each input is long work (``synthesize``'s searches): a progress bar even for one
        input, advanced by the work its outputs report.
    suffixes : tuple of str
        The files a folder gives its commands (:func:`~grasptwist.io.inputs.expand`): grasp
        files, and mesh files for ``synthesize``.
    """

    name: str
    options: Callable[[], type]
    columns: Callable[[], Any]
    rows: Callable[[list, Any], Iterator] | None = None
    dataset: Callable[..., Iterator] | None = None
    check_dataset: Callable[[Any, Any], None] = lambda ds, job: None
    beside: Callable[..., Any] = lambda job, paths, tuning: None
    outputs: Callable[..., Iterator] | None = None
    tells_progress: bool = True
    long_inputs: bool = False
    suffixes: tuple[str, ...] = GRASP_SUFFIXES


class Contribution(NamedTuple):
    """What a family adds to another command's records: fields per row and a table column.

    Attributes
    ----------
    family : Family
        The family that computes it.
    fields : callable
        ``(block, options) -> list of dict``: the fields it adds to each row's record (the command's options).
    header : str
        Its column in the command's table.
    cell : str
        Name of its cell renderer (``record -> Text``) in :mod:`grasptwist.output.table`.
    """

    family: Family
    fields: Callable[[Any, Any], list[dict]]
    header: str
    cell: str


def _all_talking(block, job) -> list[dict]:
    return [rec for rec in job.command.records(block, job) if not rec["ok"] or rec["warnings"]]


@dataclass(frozen=True, eq=False)  # one per command (COMMANDS): compared by identity
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
    failed_words : str
        What the closing summary line says of its records that are not ok (and not an input that
        failed): ``3 records: 1 with a degenerate method``, ``2 records: 1 not held``.
    apart : tuple of str
        Kinds of its failed records counted in a clause of their own in the summary (``simulate``'s
        ``not simulated``: ``3 records: 1 not held, 2 not simulated (2 no-mass), 0 inputs failed``).
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
    failed_words: str = "with a degenerate method"
    apart: tuple[str, ...] = ()

    def __post_init__(self):
        unknown = [f for f in self.formats if f not in FORMATS]
        if unknown:
            raise ValueError(f"{self.name}: no output format {unknown}")


# Each family's compute, records and columns load with its first run, through the
# small functions below: a JSON resolve never imports the force engine, follow's
# paths or the hand's kinematics (tests/api/test_layers.py, bench/startup.py).


def _options(name: str) -> type:
    """The options class ``name`` of :mod:`.options` (a family other than the twist rows' defines
    its own when first asked for: a ``resolve`` compiles none of their dataclasses)."""
    from . import options

    return getattr(options, name)


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
    return twist_stream(paths, o.twists_from, o.method, job.max_bytes, tuning.files_per_group, job.reading)


def _twist_columns():
    from ..output.column_sets import TWIST_COLUMNS  # CSV, npz and Parquet only

    return TWIST_COLUMNS


TWIST = Family(
    name="twist",
    options=partial(_options, "TwistOptions"),
    columns=_twist_columns,
    rows=_twist_rows,
    dataset=_twist_dataset,
    check_dataset=_twist_check,
    beside=_twists_beside,
)

# -- wrench rows --------------------------------------------------------------


def _wrench_rows(items, job):
    from .forces import force_blocks  # the force engine, with the first force run

    return force_blocks(items, job.options)


def _wrench_dataset(ds, job, start, stop, bases):
    from .forces import force_dataset_blocks

    return force_dataset_blocks(ds, job.options, start=start, stop=stop)


def _wrench_columns():
    from ..output.force_records import WRENCH_COLUMNS

    return WRENCH_COLUMNS


def _closure(block, options):
    from .forces import closure_fields  # check's closure: the force engine, with the first check

    return closure_fields(block, options.torsion)


WRENCH = Family(
    name="wrench",
    options=partial(_options, "ForceOptions"),
    columns=_wrench_columns,
    rows=_wrench_rows,
    dataset=_wrench_dataset,
)

#: The wrench family's part of ``check`` records: each grasp's closure.
CLOSURE = Contribution(WRENCH, _closure, "closure mu", "closure_cell")

# -- path samples -------------------------------------------------------------


def _path_outputs(job, inputs, w, workers, tuning):
    from .follow import follow_outputs  # paths, a hand's tracking and the weight's grip, with the first follow

    return follow_outputs(job, inputs, w, workers, tuning)


def _path_columns():
    from ..output.follow_records import PATH_COLUMNS

    return PATH_COLUMNS


PATH = Family(
    name="path",
    options=partial(_options, "FollowOptions"),
    columns=_path_columns,
    outputs=_path_outputs,
    tells_progress=False,
)

# -- grasps synthesised ---------------------------------------------------------


def _synthesis_outputs(job, inputs, w, workers, tuning):
    from .synthesize import synthesize_outputs  # the search, with the first synthesize

    return synthesize_outputs(job, inputs, w, workers, tuning)


def _synthesis_columns():
    from ..output.synthesis_records import SYNTHESIS_COLUMNS

    return SYNTHESIS_COLUMNS


SYNTHESIS = Family(
    name="synthesis",
    options=partial(_options, "SynthesisOptions"),
    columns=_synthesis_columns,
    outputs=_synthesis_outputs,
    long_inputs=True,
    suffixes=OBJECT_SUFFIXES,
)

# -- grasps simulated ------------------------------------------------------------


def _simulation_outputs(job, inputs, w, workers, tuning):
    from .simulate import simulate_outputs  # the scene and MuJoCo, with the first simulate

    return simulate_outputs(job, inputs, w, workers, tuning)


def _simulation_columns():
    from ..output.simulate_records import SIMULATE_COLUMNS

    return SIMULATE_COLUMNS


SIMULATION = Family(
    name="simulation",
    options=partial(_options, "SimulateOptions"),
    columns=_simulation_columns,
    outputs=_simulation_outputs,
    long_inputs=True,
)

#: Every family.
FAMILIES: tuple[Family, ...] = (TWIST, WRENCH, PATH, SYNTHESIS, SIMULATION)

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
    added = [c.fields(block, job.options) for c in job.command.contributions]
    return [check_record(block, i, {k: v for part in added for k, v in part[i].items()}) for i in range(len(block))]


def _sample_records(samples, job):
    from ..output.follow_records import sample_records

    return sample_records(samples, job.order)


def _synthesis_records(found, job):
    from ..output.synthesis_records import synthesis_records

    return synthesis_records(found)


def _simulate_records(sim, job):
    from ..output.simulate_records import simulate_record

    return [simulate_record(sim)]


def _force_records(block, job):
    from ..output.force_records import force_records

    return force_records(block)


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
        Command("follow", PATH, (*_RECORDS, "csv", "npz"), _sample_records, "follow_table.FollowTable"),
        Command("forces", WRENCH, _ROWS, _force_records, "table.ForceTableWriter"),
        Command(
            "synthesize",
            SYNTHESIS,
            (*_RECORDS, "csv", "parquet"),
            _synthesis_records,
            "synthesis_records.SynthesisTable",
        ),
        Command(
            "simulate",
            SIMULATION,
            (*_RECORDS, "csv"),
            _simulate_records,
            "simulate_records.SimulateTable",
            failed_words="not held",
            apart=(NOT_SIMULATED,),
        ),
    )
}
