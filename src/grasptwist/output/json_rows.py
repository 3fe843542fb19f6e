"""JSON text of many plain records at once, by a template derived from :func:`records.records`.

A million-record JSONL run spends most of its time making a dict per record
and encoding it.  Most records are *plain*: every kind asked for applies
and succeeded, with no warning.  Their JSON differs only in numbers, names
and a few verdicts (the ``flag`` and ``fingers`` fields of the registry,
:data:`grasptwist.results.KINDS`), so plain rows with the same verdicts
share one text ``template % values``.  The template is found by running the
real record builder (:func:`grasptwist.output.records.records`) once on a
one-row block of those verdicts whose numbers and names are unique
markers, encoding that record, and cutting the text at each marker.  The
layout therefore lives in one place; this module only learns it.  The
numbers of all rows are then encoded by orjson in one call (shortest
round-trip form, as for single records) and split.  Rows that are not
plain go through the ordinary builder.
"""

from __future__ import annotations

import re
from dataclasses import fields, replace

import numpy as np
import orjson

from .names import escaped
from .records import present, talking_rows

__all__ = ["encode_records"]

_MARK = 1 << 20  # number marker: column * _MARK + position + 0.5 (exact, unique)
_STRING_COLUMNS = ("file", "grasp", "units", "twist_name")
_TOKEN = re.compile(rb'"\\u0001(\w+)\\u0001"|-?\d+\.5')
_CODED = ("flag", "fingers")  # field kinds whose few distinct values go into the template
_TEMPLATE_FROM = 4  # rows in a block from which plain rows go by template


def encode_records(block, order: str, records, dumps) -> tuple[list[bytes], list[dict]]:
    """The JSON of each row's record, and the records that are not plain.

    Plain rows go by template, the others through ``records`` and ``dumps``;
    the texts equal, byte for byte, ``dumps`` of every record.  The records
    returned are the ones with something to say (errors, warnings).
    """
    if len(block) < _TEMPLATE_FROM:  # a stream's line: learning a template costs more than it saves
        recs = records(block, order)
        return [dumps(rec) for rec in recs], [rec for rec in recs if not rec["ok"] or rec["warnings"]]
    plain = _plain_rows(block)
    codes = _verdicts(block)  # judged once here, for the non-plain rows' records too
    out: list = [None] * len(block)
    others = []
    rows = np.flatnonzero(~plain)
    for i, rec in zip(rows, records(block.take(rows), order) if rows.size else []):
        if not rec["ok"] or rec["warnings"]:
            others.append(rec)
        out[i] = dumps(rec)
    rows = np.flatnonzero(plain)
    if rows.size:
        _, variant = np.unique(codes[rows], axis=0 if codes.ndim > 1 else None, return_inverse=True)
        for v in range(variant.max() + 1):
            part = rows[variant.reshape(-1) == v]
            for i, text in zip(part, _by_template(block, order, records, dumps, part)):
                out[i] = text
    return out, others


def _plain_rows(block) -> np.ndarray:
    """Rows with nothing to say and every kind asked for present."""
    plain = ~talking_rows(block)
    for kind in block.kinds():
        if kind.record is not None:  # objects whose shape depends on the row: no template
            plain &= ~block.applies(kind.key)
        else:
            plain &= block.applies(kind.key)  # a skipped kind is a null: another template
    return plain


def _coded(block) -> list:
    """``(kind key, field)`` of every coded field."""
    return [(kind.key, f) for kind in block.kinds() for f in present(block, kind.fields) if f.kind in _CODED]


def _verdicts(block) -> np.ndarray:
    """Integers equal where every coded field's JSON is, and whether there is a
    wrist (a list or ``null``): ``(N,)`` when their bits fit one int64 (the
    usual case, and quick to sort), else ``(N, k)``."""
    bits = [block.finite_wrist()[:, None]]
    bits += [np.asarray(block.value(*c), dtype=bool).reshape(len(block), -1) for c in _coded(block)]
    bits = np.concatenate(bits, axis=1)
    words = [bits[:, k : k + 62] for k in range(0, bits.shape[1], 62)] or [bits]
    codes = [w @ (1 << np.arange(w.shape[1], dtype=np.int64)) for w in words]
    return codes[0] if len(codes) == 1 else np.stack(codes, axis=1)


def _columns(block):
    """``(owner, field)`` of every float column: the block's own (owner None,
    field a name), then each kind's number fields (owner its key)."""
    own = [
        (None, f.name)
        for f in fields(block)
        if isinstance(getattr(block, f.name), np.ndarray) and getattr(block, f.name).dtype.kind == "f"
    ]
    return own + [(kind.key, f) for kind in block.kinds() for f in present(block, kind.fields) if f.kind not in _CODED]


def _value(block, owner, name):
    return np.asarray(getattr(block, name) if owner is None else block.value(owner, name))


def _marker_block(block, row: int):
    """A one-row copy of row ``row`` (a plain one) whose numbers and names are markers;
    its coded fields keep the row's values, and so do numbers that are not finite
    (a missing wrist is NaN, which the record writes as null)."""
    cols = _columns(block)
    marked = {}
    for k, c in enumerate(cols):
        own = _value(block, *c)[[row]]
        markers = (k * _MARK + np.arange(own.size) + 0.5).reshape(own.shape)
        marked[c] = np.where(np.isfinite(own), markers, own)
    names = {c: [f"\x01{c}\x01"] for c in _STRING_COLUMNS}
    one = replace(
        block.take([row]),
        **{name: marked[(owner, name)] for owner, name in cols if owner is None},
        **names,
        contact_names=[tuple(f"\x01contact{c}\x01" for c in range(3))],
    )
    one.values.update({c: marked[c] for c in cols if c[0] is not None})
    one.values.update({c: block.value(*c)[[row]] for c in _coded(block)})  # known already: no need to judge again
    block.outward()  # the block's own verdicts (owner None) are judged on its real numbers, not on markers
    one.values.update({c: v[[row]] for c, v in block.values.items() if c[0] is None})
    return one


def _template(block, order, records, dumps, row):
    """``(template, slots)`` for plain rows with the verdicts of row ``row``.

    A slot is a string column's name, or a *run*: ``[start, stop, rows]``,
    consecutive numbers of one column that the JSON writes as one vector or
    table (``,`` within a row, ``],[`` between rows), so that a run's text
    for every record comes from one orjson call on that column slice.
    """
    text = dumps(records(_marker_block(block, row), order)[0])
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


def _by_template(block, order, records, dumps, part):
    """The texts of the plain rows ``part``, which share their verdicts."""
    template, slots = _template(block, order, records, dumps, part[0])
    numbers = np.concatenate([_value(block, *c)[part].reshape(len(part), -1) for c in _columns(block)], axis=1)
    numbers += 0.0  # no -0.0, as in records._rows
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
            names, c = block.contact_names, int(slot[-1])
            columns.append(_labels([names[i][c] for i in part]))
        else:
            labels = getattr(block, slot)  # a list, or a numpy array of a data set's labels
            columns.append(
                _labels(labels[part].tolist() if isinstance(labels, np.ndarray) else [labels[i] for i in part])
            )
    return [template % values for values in zip(*columns)]


def _labels(values):
    """JSON of each value, escaped as in the records (:func:`~grasptwist.output.names.escaped`),
    encoding each distinct value once (names repeat)."""
    encoded = {v: orjson.dumps(escaped(v, controls=False)) for v in set(values)}
    return [encoded[v] for v in values]
