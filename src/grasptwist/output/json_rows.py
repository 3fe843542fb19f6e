"""JSON text of many plain records at once, by a template derived from :func:`report.records`.

A million-record JSONL run spends most of its time making a dict per record
and encoding it.  Most records are *plain*: every method asked for
succeeded, with no warning.  Their JSON differs only in numbers and names,
so it is ``template % values``: the template is found by running the real
record builder (:func:`grasptwist.output.records.records`) once on a one-row block
whose numbers and names are unique markers, encoding that record, and
cutting the text at each marker.  The layout therefore lives in one place;
this module only learns it.  The numbers of all rows are then encoded by
orjson in one call (shortest round-trip form, as for single records) and
split.  Rows that are not plain go through the ordinary builder.
"""

from __future__ import annotations

import re
from dataclasses import fields, replace

import numpy as np
import orjson

from ..run.batch import Block
from .records import talking_rows

__all__ = ["encode_records"]

_MARK = 1 << 20  # number marker: column * _MARK + position + 0.5 (exact, unique)
_STRING_COLUMNS = ("file", "grasp", "units", "twist_name")
_TOKEN = re.compile(rb'"\\u0001(\w+)\\u0001"|-?\d+\.5')


def encode_records(block: Block, order: str, records, dumps) -> tuple[list[bytes], list[dict]]:
    """The JSON of each row's record, and the records that are not plain.

    Plain rows go by template, the others through ``records`` and ``dumps``;
    the texts equal, byte for byte, ``dumps`` of every record.  The records
    returned are the ones with something to say (errors, warnings).
    """
    plain = _plain_rows(block)
    out: list = [None] * len(block)
    others = []
    rows = np.flatnonzero(~plain)
    for i, rec in zip(rows, records(block.take(rows), order) if rows.size else []):
        if not rec["ok"] or rec["warnings"]:
            others.append(rec)
        out[i] = dumps(rec)
    for in_planes in (False, True):
        rows = plain & (_in_planes(block) == in_planes)
        if rows.any():
            for i, text in zip(np.flatnonzero(rows), _by_template(block, order, records, dumps, rows, in_planes)):
                out[i] = text
    return out, others


def _plain_rows(block: Block) -> np.ndarray:
    """Rows with nothing to say and every method asked for present."""
    plain = ~talking_rows(block)
    if block.off_tangent is not None:
        plain &= block.has_wrist  # a skipped method is a null: another template
    return plain


def _in_planes(block: Block) -> np.ndarray:
    return np.zeros(len(block), bool) if block.tangent is None else np.asarray(block.tangent.in_tangent_planes)


def _numeric(obj):
    """The float-array fields of a block or result, in a fixed order."""
    return [
        f.name
        for f in fields(obj)
        if isinstance(getattr(obj, f.name), np.ndarray) and getattr(obj, f.name).dtype.kind == "f"
    ]


def _columns(block: Block):
    """``(owner, field)`` of every float column, block first, then each result."""
    cols = [("block", n) for n in _numeric(block)]
    for owner in ("off_tangent", "tangent"):
        r = getattr(block, owner)
        if r is not None:
            cols += [(owner, n) for n in _numeric(r)] + [(owner, "residual")]
    return cols


def _value(block, owner, name):
    obj = block if owner == "block" else getattr(block, owner)
    return np.asarray(getattr(obj, name))


def _marker_block(block: Block, in_planes: bool) -> Block:
    """A one-row copy of ``block`` whose numbers and names are markers."""
    cols = _columns(block)
    marked = {
        c: (k * _MARK + np.arange(_value(block, *c)[0].size) + 0.5).reshape((1,) + _value(block, *c).shape[1:])
        for k, c in enumerate(cols)
    }

    def result(owner):
        r = getattr(block, owner)
        if r is None:
            return None
        values = {n: marked[(owner, n)] for n in _numeric(r)}
        values.update(status=np.zeros(1, np.int8), culprit=np.full(1, -1, np.int8))
        if owner == "tangent":
            values["in_tangent_planes"] = np.full(1, in_planes)
        one = replace(r.row(slice(0, 1)), **values)
        one.__dict__["residual"] = marked[(owner, "residual")]
        return one

    names = {c: [f"\x01{c}\x01"] for c in _STRING_COLUMNS}
    return replace(
        block.part(0, 1),
        **{n: marked[("block", n)] for n in _numeric(block)},
        **names,
        contact_names=[tuple(f"\x01contact{c}\x01" for c in range(3))],
        has_wrist=np.ones(1, bool),
        off_tangent=result("off_tangent"),
        tangent=result("tangent"),
    )


def _template(block, order, records, dumps, in_planes):
    """``(template, slots)`` for plain rows of this kind of block.

    A slot is a string column's name, or a *run*: ``[start, stop, rows]``,
    consecutive numbers of one column that the JSON writes as one vector or
    table (``,`` within a row, ``],[`` between rows), so that a run's text
    for every record comes from one orjson call on that column slice.
    """
    text = dumps(records(_marker_block(block, in_planes), order)[0])
    cols = _columns(block)
    offsets = np.cumsum([0] + [_value(block, *c)[0].size for c in cols])
    pieces, slots = [], []
    last = 0
    for m in _TOKEN.finditer(text):
        between = text[last : m.start()]
        last = m.end()
        if m.group(1) is not None:
            pieces.append(between)
            slots.append(m.group(1).decode())
            continue
        k, pos = divmod(int(float(m.group(0))), _MARK)
        flat = offsets[k] + pos
        run = slots[-1] if slots and isinstance(slots[-1], list) and slots[-1][1] == flat else None
        if run is not None and between == b",":
            run[1] = flat + 1  # the run goes on in the same row
        elif run is not None and between == b"],[":
            run[1], run[2] = flat + 1, run[2] + 1  # and on into the next row of a table
        else:
            pieces.append(between)
            slots.append([flat, flat + 1, 1])  # start, stop, rows
    pieces.append(text[last:])
    return b"%s".join(p.replace(b"%", b"%%") for p in pieces), slots


def _by_template(block, order, records, dumps, rows, in_planes):
    template, slots = _template(block, order, records, dumps, in_planes)
    part = np.flatnonzero(rows)
    numbers = np.concatenate([_value(block, *c)[part].reshape(len(part), -1) for c in _columns(block)], axis=1)
    numbers += 0.0  # no -0.0, as in report._rows
    columns = []
    for slot in slots:
        if isinstance(slot, list):
            start, stop, rows = slot
            run = np.ascontiguousarray(
                numbers[:, start:stop].reshape(len(part), rows, -1) if rows > 1 else numbers[:, start:stop]
            )
            cut = rows > 1  # a table: records are "[[...]]" inside the outer brackets
            text = orjson.dumps(run, option=orjson.OPT_SERIALIZE_NUMPY)
            columns.append(text[3:-3].split(b"]],[[") if cut else text[2:-2].split(b"],["))
        elif slot.startswith("contact"):
            columns.append(_labels([block.contact_names[i][int(slot[-1])] for i in part]))
        else:
            columns.append(_labels([getattr(block, slot)[i] for i in part]))
    return [template % values for values in zip(*columns)]


def _labels(values):
    """JSON of each value, encoding each distinct value once (names repeat)."""
    encoded = {v: orjson.dumps(v) for v in set(values)}
    return [encoded[v] for v in values]
