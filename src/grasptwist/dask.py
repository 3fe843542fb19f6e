"""The engine over Dask collections, unchanged: data sets beyond one machine.

:func:`resolve_dataframe` maps a Dask DataFrame with the columns of a
Parquet data set (see docs/guide/data-sets.md, "Parquet") to a Dask
DataFrame with the columns ``-f parquet`` writes, one partition at a time
(``map_partitions`` with an explicit ``meta``): each partition goes through
the same reader, blocks and columns as ``grasptwist resolve data.parquet -f
parquet``, so the values are the command line's, bit for bit.
:func:`resolve_array` maps dask arrays of points, normals, wrists and
twists chunked by rows (``map_blocks``) to a dask array of records whose
fields are the npz arrays.  :func:`synthesize_bag` maps a Dask bag of
objects (grasp files with an ``object``, mesh files) to a bag of the
records ``grasptwist synthesize -f json`` gives, one object a task.  None computes anything until asked: run
them on any Dask scheduler, e.g. a ``distributed.LocalCluster`` or a
cluster's ``distributed.Client``.

Dask, distributed, pandas and pyarrow are the extra ``grasptwist[dask]``
(imported when these functions run, not with this module).  For example
(tests/run/test_dask.py runs such code on a cluster)::

    points = da.from_array(np.array([[[1, 0, 0], [-0.5, 0.866, 0], [-0.5, -0.866, 0]]] * 4), chunks=(2, 3, 3))
    r = resolve_array(points, -points, da.zeros((4, 3)) + [0, 0, 1], da.zeros((4, 6)) + [0, 0, 0, 0, 0, 1])
    r["x"].compute()[0]  # array([0.6667, 0.6667, 0.6667]), in 2 chunks of 2 rows
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from .extras import require
from .model import Twist
from .output.columns import arrays
from .output.formats import FORMATS

__all__ = ["resolve_dataframe", "to_parquet", "resolve_array", "result_dtype", "synthesize_bag"]

_WHAT = "grasptwist.dask"
#: npz groups that are labels, not numbers: not fields of resolve_array's records.
_LABELS = ("file", "grasp", "twist_name")


def _twists(twists: Mapping[str, object] | None) -> list[Twist] | None:
    """``name -> (omega; v)`` as the command line's ``--twist`` values (at the origin)."""
    if twists is None:
        return None
    return [
        Twist(name=name, screw=np.asarray(screw, dtype=float).reshape(6), line=None) for name, screw in twists.items()
    ]


def _frame(table):
    """An Arrow table as pandas with Arrow types (nulls, booleans, int8 and dictionaries kept)."""
    pd = require("pandas", _WHAT)
    return table.to_pandas(types_mapper=pd.ArrowDtype)


def _resolve_partition(df, twists, method: str, order: str, file: str):
    """One partition's results, as ``grasptwist resolve part.parquet -f parquet`` makes them."""
    import pyarrow as pa

    from .io.parquet import NAME_COLUMN, table_dataset
    from .output.parquet_writer import schema, table
    from .run.batch import dataset_blocks

    rows = pa.Table.from_pandas(df, preserve_index=False)
    if NAME_COLUMN not in df.columns:  # rows named by the frame's index, as a file's by their row number
        rows = rows.append_column(NAME_COLUMN, pa.array(df.index.astype(str)))
    ds = table_dataset(rows, file)
    blocks = dataset_blocks(ds, twists, method, bases=FORMATS["parquet"].bases) if len(ds) else []
    return _frame(pa.concat_tables([table(b, order) for b in blocks] or [schema().empty_table()]))


def resolve_dataframe(ddf, twists: Mapping[str, object] | None = None, *, method="both", order="omega-v", file=""):
    """Resolve every row of a Dask DataFrame of grasps, lazily, partition by partition.

    Parameters
    ----------
    ddf : dask.dataframe.DataFrame
        Columns of a Parquet data set: ``p1_x ... p3_z``, ``n1_x ... n3_z``,
        optional ``c_x c_y c_z`` (wrist), ``w_x ... v_z`` (twist), ``name``
        (else rows are named by the index).  Other columns are ignored.
        Read with ``dd.read_parquet(..., dtype_backend="pyarrow")``, the
        columns reach the engine without a round trip through numpy types.
    twists : mapping of str to 6-vector, optional
        Named twists ``(omega; v)`` for every grasp (as ``--twist``; rows
        grasp-major); default: each row's own.
    method, order : as ``--method`` and ``--order``.
    file : str
        The ``file`` column's value.

    Returns
    -------
    dask.dataframe.DataFrame
        The columns ``-f parquet`` writes, with Arrow types (``pandas.ArrowDtype``);
        write them with ``.to_parquet(folder)``.
    """
    from .output.parquet_writer import schema

    meta = _frame(schema().empty_table())
    return ddf.map_partitions(
        _resolve_partition, _twists(twists), method, order, file, meta=meta, enforce_metadata=False
    )


def to_parquet(results, folder: str, **options):
    """Write :func:`resolve_dataframe`'s results as a folder of Parquet shards (one per partition).

    The files are those of ``-f parquet`` (same columns, types and writer
    options); ``options`` go to ``dask.dataframe.DataFrame.to_parquet()``
    (e.g. ``storage_options`` for an object store).  Computes the results.
    """
    from .output.parquet_writer import schema, write_options

    return results.to_parquet(folder, write_index=False, schema=schema(), **{**write_options(), **options})


def _resolve_rows(rows: np.ndarray, has_wrist: bool, method: str, order: str, dtype: np.dtype) -> np.ndarray:
    """Records of one chunk of stacked rows ``p (9), n (9), [wrist (3)], twist (6)``."""
    from .run.batch import resolve_arrays

    n = len(rows)
    wrist = rows[:, 18:21] if has_wrist else None
    block = resolve_arrays(
        rows[:, :9].reshape(n, 3, 3), rows[:, 9:18].reshape(n, 3, 3), wrist, rows[:, -6:], method, bases=False
    )
    out = np.empty(n, dtype)
    for name, values in arrays(block, order).items():
        if name not in _LABELS:
            out[name] = values
    return out


def result_dtype(*, method: str = "both", order: str = "omega-v") -> np.dtype:
    """The record type of :func:`resolve_array`: one field per npz array (``x (3,)``, ``tangent_status``, ...).

    >>> result_dtype()["off_tangent_status"], result_dtype()["x"].shape
    (dtype('int8'), (3,))
    """
    from .run.batch import resolve_arrays

    one = resolve_arrays(np.zeros((1, 3, 3)), np.ones((1, 3, 3)), None, np.zeros((1, 6)), method, bases=False)
    fields = arrays(one, order).items()
    return np.dtype([(k, np.asarray(v).dtype, np.shape(v)[1:]) for k, v in fields if k not in _LABELS])


def resolve_array(points, normals, wrist, twist, *, method="both", order="omega-v"):
    """Resolve dask arrays of grasps chunked by rows, lazily, chunk by chunk.

    Parameters
    ----------
    points, normals : dask.array.Array, shape (N, 3, 3)
        Contact points and normals (any length: the engine normalises them).
    wrist : dask.array.Array, shape (N, 3), or None
        Wrists (NaN rows for grasps without one).
    twist : dask.array.Array, shape (N, 6)
        The twists ``(omega; v)``.
    method, order : as ``--method`` and ``--order``.

    Returns
    -------
    dask.array.Array, shape (N,), of :func:`result_dtype`
        Chunked as ``points``; ``r["x"]`` is the ``(N, 3)`` array of ``x``.
    """
    da = require("dask.array", _WHAT)
    n = points.shape[0]
    rows = points.chunks[0]
    parts = [points.reshape(n, 9), normals.reshape(n, 9), *([] if wrist is None else [wrist]), twist]
    stacked = da.concatenate([da.asarray(p, dtype=float).rechunk({0: rows, 1: -1}) for p in parts], axis=1)
    dtype = result_dtype(method=method, order=order)
    return stacked.rechunk({1: -1}).map_blocks(
        _resolve_rows, wrist is not None, method, order, dtype, dtype=dtype, drop_axis=1
    )


def _synthesized(path: str, options: dict, hand_file: str | None) -> list[dict]:
    """One object's records, as ``grasptwist synthesize PATH -f json`` gives them."""
    from .io.grasp import load_hand_file
    from .run.families import COMMANDS
    from .run.options import SynthesisOptions
    from .run.pipeline import Job
    from .run.synthesize import input_records

    hand = None if hand_file is None else load_hand_file(hand_file)[0]
    job = Job(
        command=COMMANDS["synthesize"],
        fmt="json",
        hand=hand,
        options=SynthesisOptions(**options, hand_file=hand_file),
    )
    return input_records(job, path)


def synthesize_bag(objects, *, hand: str | None = None, **options):
    """Synthesize grasps for every object of a data set, lazily: a Dask bag of records, one object a task.

    Each object's problem is built as the command line and :func:`grasptwist.synthesize` build it
    (one builder, ``grasptwist.run.grasp_search.grasp_problem``): the same options give the same
    grasps through all three.

    Parameters
    ----------
    objects : dask.bag.Bag or sequence of str
        Paths of grasp files with an ``object`` (each document searched) or of mesh files
        (STL, OBJ, PLY: give ``friction`` and ``mass``); a sequence becomes a bag of one
        path a partition.
    hand : str, optional
        As ``--hand``: a YAML file holding just ``hand:`` that must reach every grasp.
    **options
        As the command line's, by their names in ``grasptwist.run.options.SynthesisOptions``: ``count`` (5), ``friction``,
        ``mass``, ``safety``, ``objective``, ``method``, ``min_conditioning`` (0.05),
        ``min_spacing``, ``quality``, ``seed`` (0), ``candidates`` (20000), ``seconds`` (60),
        ``position_error``, ``friction_error`` (0.2), ``perturbations`` (64),
        ``tip_radius``, ``loads`` (``"six"``: a grip for the hold test's loads too; ``"weight"``).

    Returns
    -------
    dask.bag.Bag of dict
        The JSON records of ``grasptwist synthesize -f json`` (a grasp each, or an object's
        error: ``no-grasp`` with its reason), in the objects' order; ``.compute()`` them,
        or write them with ``.map(json.dumps).to_textfiles(...)``.
    """
    db = require("dask.bag", _WHAT)
    bag = objects if isinstance(objects, db.Bag) else db.from_sequence(list(objects), npartitions=len(objects) or 1)
    return bag.map(_synthesized, options, hand).flatten()
