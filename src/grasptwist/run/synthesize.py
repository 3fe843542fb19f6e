"""Synthesize grasps: objects in, the grasps found (or why none) out, one record set per object.

Each input is a grasp file whose documents name an ``object`` (the file's contacts are not
searched from: the search finds its own), or a mesh file (STL, OBJ, PLY) with the command
line's friction and mass.  A hand (the file's ``hand``, or the job's: ``--hand``) must reach
every grasp: its fingertips (``--tip-radius``, else each finger's ``tip_radius``) on the
surface, its joints within their limits, its links (a URDF's meshes) out of the object; a
hand given inline has its tips where the file's contacts are (its joints are given there).  The command
line's ``--friction`` and ``--mass`` replace the file's; ``--wrench`` replaces its other wrenches, beside
the weight (``hold``), which is held whenever there is a mass.  Each document's problem is
:func:`grasptwist.run.grasp_search.grasp_problem`'s (the library's and Dask's too), searched by
:func:`grasptwist.engine.synthesis.search.solve_steps`; with ``-o
FILE.yaml`` the grasps found are also written as a grasp file (atomically, at the end).
No math here: only reading, routing and labelling.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, replace
from typing import NamedTuple

import numpy as np

from ..engine.synthesis.clearance import grasp_clearance
from ..engine.synthesis.search import Synthesis, solve_steps
from ..engine.units import fingers_reach, hand_fit_warning, largest_extent, mesh_span_warning
from ..io.grasp.forces import HOLD
from ..io.inputs import read as read_unplaced
from ..io.limits import MESH_SUFFIXES, OUTPUT_IS_INPUT
from ..io.mesh_file import read_mesh
from ..model import CONTACT_NAMES, Environment, Grasp, GraspObject, Hand, InputError, Shape
from ..output import synthesis_records as sr
from ..output.formats import FORMATS
from ..output.names import escaped
from ..output.records import diagnostics, dumps, error_record
from .grasp_search import grasp_problem, search_options
from .outputs import Output
from .pool import Pool, pool_size
from .target import opened

__all__ = [
    "Found",
    "Progress",
    "synthesize_inputs",
    "synthesize_outputs",
    "searched",
    "input_records",
]


@dataclass(frozen=True, eq=False)
class Found:
    """One object's search: what it was asked and what it found (its grasps are its rows)."""

    file: str
    name: str
    line: int | None
    units: str | None
    wrist: np.ndarray | None
    object: GraspObject
    friction: float
    wrench_names: tuple[str, ...]
    wrenches: np.ndarray
    hold: tuple | None  # (mass, centre of mass, gravity) of the wrench named hold, written as top-level keys
    synthesis: Synthesis
    contact_names: tuple[str, str, str] = CONTACT_NAMES
    hold_name: str = HOLD
    hand: Hand | None = None  # with a hand: its fingers in contact order, at the synthesis' joint positions
    hand_file: str | None = None  # the file the hand's URDF reference is relative to
    joints_at: tuple | None = None  # an inline hand's joints at each grasp: per finger (screws (n, 6), points (n, 3))
    twists: tuple = ()  # the input's twists and paths, written with each grasp found (-o FILE.yaml)
    paths: tuple = ()
    warnings: tuple = ()  # of the object: a mesh's as read (mesh-repaired, mesh-open, mesh-bodies), its size, its pose
    environment: Environment | None = None  # the table and boxes the grasps keep clear of
    clearance: np.ndarray | None = None  # each grasp's least distance of a finger from them (None: no environment)
    dropped: int = 0  # --simulate: grasps found that did not hold in MuJoCo, left out
    simulated: tuple | None = None  # --simulate: each grasp's hold test in MuJoCo (a HoldTest), else None
    torsion: float | None = None  # soft contacts' torsional radius the search used (None: point contacts)

    def __len__(self) -> int:
        return len(self.synthesis.points)


def _inline_joints(hand, synthesis):
    """An inline hand's joints moved to each grasp's joint positions (its file gives them there)."""
    if hand is None or hand.source is not None:
        return None
    from ..engine.placement import joints_at

    return tuple(joints_at(hand, q) for q in synthesis.joint_positions)


def _mesh_grasp(path: str, job) -> Grasp | InputError:
    """A mesh file as a grasp document with only its object (the command line gives the rest), in
    ``--units`` (metres without it)."""
    from ..io.grasp.objects import mesh_solid

    try:
        limits = job.reading  # a mesh's caps however it is named (io/limits.py), as a grasp file's mesh gets
        vertices, faces = read_mesh(
            path,
            None,
            max_bytes=limits.max_mesh_bytes,
            max_triangles=limits.max_triangles,
            warnings=(repaired := []),
        )
    except InputError as exc:
        return exc.with_traceback(None)  # kept until written: not with the reader's frames (the mesh's bytes)
    # the path as a grasp file beside the mesh would name it: -o FILE.yaml finds it from the file's folder
    shape = Shape("mesh", np.zeros(0), vertices=vertices, faces=faces, source=os.path.basename(path))
    said = mesh_solid(shape, path, repaired)
    if isinstance(said, InputError):
        return said
    obj = GraspObject(shape, np.eye(4))
    name = os.path.splitext(os.path.basename(path))[0]
    p = np.full((3, 3), np.nan)  # no contacts: as a document read without them
    r = job.reading  # --table and --clearance: the world around it
    env = None if r.table is None and r.clearance is None else Environment(r.table, (), r.clearance)
    return Grasp(
        name,
        job.options.units or "m",
        path,
        0,
        CONTACT_NAMES,
        p,
        p,
        None,
        (),
        1,
        object=obj,
        warnings=tuple(said),
        environment=env,
    )


#: The warnings of an object that a search's records carry (the others are about the file's contacts):
#: its pose's, and its mesh's as read.
OBJECT_WARNINGS = ("rotation-over-pi", "mesh-")


def _object_warnings(entry: Grasp, obj: GraspObject, hand: Hand | None) -> tuple[str, ...]:
    """The warnings of the object searched: its pose's, its mesh's, and its size against the hand
    that must reach it (the file's or ``--hand``'s), else against its unit (a mesh)."""
    said = [w for w in entry.warnings if w.startswith(OBJECT_WARNINGS)]
    shape = obj.shape
    extent = largest_extent(shape.kind, shape.size, shape.vertices)
    if hand is not None:
        said.append(hand_fit_warning(extent, fingers_reach(hand), entry.units, urdf=hand.source is not None))
    elif shape.kind == "mesh":
        said.append(mesh_span_warning(extent, entry.units))
    return tuple(w for w in said if w)


def _contacts_warnings(entry: Grasp, torsion) -> tuple[str, ...]:
    """A document whose contacts are soft in part, searched without ``--contact``: with point contacts
    (a search's contacts are all of one model), which the records' ``contact_model`` says, and this."""
    e = entry.torsion
    if torsion is not None or e is None or not (np.asarray(e) > 0).any() or (np.asarray(e) > 0).all():
        return ()
    return (
        "its contacts are soft in part: searched as point contacts (give every contact model: soft, or "
        "--contact soft --torsion E)",
    )


class Progress(NamedTuple):
    """Work for a progress bar: ``extra`` units found (a search's budget), ``done`` units done."""

    extra: int
    done: int


def synthesize_inputs(job, inputs: Iterable) -> Iterator[InputError | Found | Progress]:
    """Every object of ``inputs`` (paths or the errors of ``expand``) searched, in order, with the
    progress of each search (its candidates) and of each input (one unit).  An object whose search
    raises (a fault of ours, not of the input) is its ``internal-error`` record, and the others run on."""
    for item in inputs:
        if isinstance(item, InputError):
            yield item
            yield Progress(0, 1)
            continue
        # a hand is placed on the contacts found, not on the file's: the grasps are read unplaced
        mesh = item.lower().endswith(MESH_SUFFIXES)
        # the contacts are found: a document need not give them (an object and the weight suffice)
        reading = replace(job.reading, contacts=False)
        try:
            entries = [_mesh_grasp(item, job)] if mesh else read_unplaced(item, job.max_bytes, reading)
        except Exception as exc:  # noqa: BLE001 - this input's record; the others run on
            entries = [_internal(item, None, exc)]
        for entry in entries:
            if isinstance(entry, InputError):
                yield entry
                continue
            extra = done = 0
            try:
                for step in _searched_entry(job, entry):
                    if isinstance(step, Progress):
                        extra, done = extra + step.extra, done + step.done
                    yield step
            except Exception as exc:  # noqa: BLE001 - this object's record; the others run on
                yield _internal(entry.file, entry.line, exc)
                yield Progress(0, extra - done)  # its search's budget, unspent
        yield Progress(0, 1)


def _internal(file, line, exc: Exception) -> InputError:
    """The ``internal-error`` record of an object whose reading or search raised ``exc``."""
    return InputError("internal-error", f"{type(exc).__name__}: {exc}", file, line, None)


def _searched_entry(job, entry: Grasp) -> Iterator[InputError | Found | Progress]:
    """One grasp document's search (:func:`synthesize_inputs`): its errors, or its progress and what it found."""
    o = job.options
    given = o.hand_file is not None  # --hand; else job.hand only names the columns (the file's)
    task = grasp_problem(
        entry,
        friction=o.friction,
        mass=o.mass,
        wrenches=o.wrenches,
        hand=job.hand if given else None,
        hand_file=o.hand_file,
        tip_radius=o.tip_radius,
        **search_options(o),
    )
    if isinstance(task, InputError):
        yield task
        return
    problem, hand = task.problem, task.hand
    obj, reach = problem.object, problem.hand
    said = _object_warnings(entry, obj, hand) + _contacts_warnings(entry, o.torsion)
    yield Progress(o.candidates, 0)
    for step in solve_steps(problem):
        if isinstance(step, int):
            yield Progress(0, step)
    yield Progress(0, o.candidates - step.candidates)  # the budget left unspent
    found = Found(
        entry.file,
        entry.name,
        entry.line,
        entry.units,
        entry.wrist,
        obj,
        task.friction,
        task.names,
        problem.wrenches,
        None if problem.weight is None else tuple(problem.weight[:3]),
        step,
        entry.contact_names,
        hand=hand,
        hand_file=None if hand is None else (o.hand_file or entry.file),
        joints_at=_inline_joints(hand, step),
        twists=entry.twists,
        paths=entry.paths,
        warnings=said,
        environment=entry.environment,
        clearance=grasp_clearance(step.points, entry.environment, reach, step.joint_positions),
        torsion=problem.torsion,
    )
    if o.simulate is not None:
        from .simulate import held_only  # MuJoCo, with the first synthesize --simulate

        found, dropped = held_only(found, o.simulate)
        found = replace(found, dropped=dropped)
    yield found


def searched(job, inputs: list, workers: int = 1) -> Iterator[InputError | Found | Progress]:
    """:func:`synthesize_inputs`, each input on one of ``workers`` forked processes
    (:class:`~grasptwist.run.pool.Pool`) when there are several: the same items in the same order
    (a search depends on its seed alone), each input's as its search ends."""
    if pool_size(workers, len(inputs)) <= 1:
        yield from synthesize_inputs(job, inputs)
        return
    with Pool(lambda i: list(synthesize_inputs(job, inputs[i : i + 1])), workers, in_flight=1) as pool:
        for items in pool.results(len(inputs)):
            yield from items


def input_records(job, path: str) -> list[dict]:
    """The JSON records of one input, as ``grasptwist synthesize PATH -f json`` gives them
    (``grasptwist.dask``'s unit of work)."""
    out = []
    for item in synthesize_inputs(job, [path]):
        if isinstance(item, InputError):
            out.append(error_record(item))
        elif isinstance(item, Found):
            out.extend(sr.synthesis_records(item) if len(item) else [sr.failure_record(item)])
    return out


def synthesize_outputs(job, inputs: Iterable, w, workers: int = 1, tuning=None) -> Iterator[Output]:
    """The :class:`~grasptwist.run.outputs.Output` of each object searched (one object a process:
    a search is vectorised already); the grasp file of ``-o FILE.yaml`` is written once every
    search is done."""
    fmt = FORMATS[job.fmt]
    inputs = list(inputs)
    documents = []
    reads_output = False  # a grasp file names -o FILE.yaml as its mesh or URDF: it is not written
    for item in searched(job, inputs, workers):
        if isinstance(item, Progress):
            yield Output(extra_work=item.extra, done=item.done)
            continue
        if isinstance(item, InputError):
            reads_output = reads_output or any(p.code == OUTPUT_IS_INPUT for p in item.problems)
            rec = error_record(item)
            out = Output(encoded=[_encode(job, rec, error=True)], records=1)
            out.errors.extend(diagnostics(rec)[0])
            out.count(rec)
            yield out
            continue
        warnings = _unchecked(job, item)
        if not len(item):
            rec = sr.failure_record(item)
            out = Output(
                encoded=[_encode(job, rec, error=True)], records=1, notes=[_summary(job, item)], warnings=warnings
            )
            out.errors.extend(diagnostics(rec)[0])
            out.count(rec)
            yield out
            continue
        recs = sr.synthesis_records(item)
        if job.options.grasp_file is not None:
            documents.append(sr.grasp_documents(item, os.path.dirname(os.path.abspath(job.options.grasp_file))))
        if fmt.takes_blocks:
            w.write(item)
            encoded = []
        elif job.fmt == "csv":
            encoded = _csv(job, item)
        else:
            encoded = [_encode(job, rec) for rec in recs]
        yield Output(encoded=encoded, records=len(recs), notes=[_summary(job, item)], warnings=warnings)
    if job.options.grasp_file is not None and documents and not reads_output:
        with opened(job.options.grasp_file, [p for p in inputs if isinstance(p, str)]) as out:
            out.write("---\n".join(documents).encode())


def _unchecked(job, found) -> list[str]:
    """Warnings of an object, once each: its own (its mesh's as read, ``mesh-repaired``,
    ``mesh-open``, ``mesh-internal``, ``mesh-bodies``; its size against its unit or its hand), and
    an option that does not apply to it.  The off-tangent
    method asked without a wrist (its conditioning cannot be checked: the tangent method's alone
    is), ``--tip-radius`` without a hand (no fingertip to size: the contacts are points)."""
    where = f"{escaped(found.file)}: grasp '{escaped(found.name)}': warning:"
    said = [f"{where} {escaped(w)}" for w in found.warnings]
    if found.wrist is None and job.options.method in ("off-tangent", "both"):
        said.append(f"{where} off-tangent conditioning not checked without a wrist (a grasp file's 'wrist')")
    if job.options.tip_radius is not None and found.hand is None:
        said.append(f"{where} --tip-radius ignored: no hand (give --hand, or a grasp file's 'hand')")
    return said


def _summary(job, found) -> str:
    s, o = found.synthesis, job.options
    found_count = f"{len(found)} grasp" if len(found) == 1 else f"{len(found)} grasps"
    if 0 < len(found) < o.count:  # fewer than wanted: the spacing may be why, unless MuJoCo dropped them
        spacing = "default" if o.min_spacing is None else f"{o.min_spacing:g}"
        why = "" if len(found) + found.dropped >= o.count else f" (min spacing {spacing})"
        found_count = f"{len(found)} of {o.count} grasps wanted{why}"
    late = f"; {s.unverified} found but not verified before --seconds ran out" if s.unverified else ""
    if o.simulate is not None:  # said even when none: the filter ran
        late += f"; {found.dropped} dropped: they did not hold in all six directions in MuJoCo (--simulate)"
    return (
        f"{found.file}: grasp '{found.name}': {found_count} from {s.candidates} candidates scored "
        f"in {s.seconds:.2f} s ({s.candidates / max(s.seconds, 1e-9):.3g} per second){late}"
    )


def _csv(job, found) -> list[bytes]:
    from ..output.csv_rows import lines

    return lines(sr.SYNTHESIS_COLUMNS.flat(found, hand=job.hand))


def _encode(job, rec, error=False):
    if job.fmt == "table":
        return rec
    if job.fmt == "csv" and error:
        return sr.SYNTHESIS_COLUMNS.error_row(rec, job.hand)
    return dumps(rec)
