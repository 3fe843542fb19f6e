"""Synthesize grasps: objects in, the grasps found (or why none) out, one record set per object.

Each input is a grasp file whose documents name an ``object`` (the file's contacts are not
searched from: the search finds its own), or a mesh file (STL, OBJ, PLY) with the command
line's friction and mass.  A hand (the file's ``hand``, or the job's: ``--hand``) must reach
every grasp: its fingertips (``--tip-radius``, else each finger's ``tip_radius``) on the
surface, its joints within their limits, its links (a URDF's meshes) out of the object; a
hand given inline has its tips where the file's contacts are (its joints are given there).  The command
line's ``--friction`` and ``--mass`` replace the file's; ``--wrench`` replaces its other wrenches, beside
the weight (``hold``), which is held whenever there is a mass.  The search is :func:`grasptwist.engine.synthesis.search.search`; with ``-o
FILE.yaml`` the grasps found are also written as a grasp file (atomically, at the end).
No math here: only reading, routing and labelling.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, replace
from typing import NamedTuple

import numpy as np

from ..engine.forces.hold import Weight, hold_wrench, object_weight
from ..engine.synthesis.clearance import environment_search, grasp_clearance
from ..engine.synthesis.scores import METHODS, MIN_CONDITIONING
from ..engine.synthesis.search import GRAVITY, Synthesis, search_steps, surface_of
from ..engine.units import fingers_reach, hand_fit_warning, largest_extent, mesh_span_warning
from ..io.grasp.forces import HOLD
from ..io.inputs import read as read_unplaced
from ..io.limits import MESH_SUFFIXES, OUTPUT_IS_INPUT
from ..io.mesh_file import read_mesh
from ..model import CONTACT_NAMES, Environment, Grasp, GraspFileError, GraspObject, Hand, InputError, Shape
from ..output import synthesis_records as sr
from ..output.formats import FORMATS
from ..output.names import escaped
from ..output.records import diagnostics, dumps, error_record
from .grasp_search import file_tips
from .options import SynthesisOptions
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
    "NO_OBJECT",
    "NOTHING_TO_HOLD",
    "NO_FRICTION",
    "NO_TIP_POINTS",
    "UNSEARCHABLE_HAND",
]

#: Error codes of an input the search cannot start from.
NO_OBJECT, NOTHING_TO_HOLD, NO_FRICTION = "no-object", "nothing-to-hold", "no-friction"

#: An inline hand without the contacts its tips touch (``--hand`` with a mesh); a hand whose
#: fingers share joints (the search solves each finger on its own).
NO_TIP_POINTS, UNSEARCHABLE_HAND = "no-tip-points", "unsearchable-hand"

#: A weight beyond a double (``--mass`` times the file's gravity): the grasp file's own code for it.
NON_FINITE = "non-finite"


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


def _problem(file, code, message, line=None) -> GraspFileError:
    return GraspFileError(code, message, file, line, None)


def _task(options: SynthesisOptions, grasp: Grasp):
    """What one grasp document asks: ``(object, friction, names, wrenches, hold)``, or its error."""
    if grasp.object is None:
        return _problem(grasp.file, NO_OBJECT, f"grasp '{grasp.name}' has no object to search", grasp.line)
    obj = grasp.object if options.mass is None else replace(grasp.object, mass=options.mass, density=None)
    if options.friction is not None:
        friction = options.friction
    elif grasp.friction is not None:
        friction = float(np.min(grasp.friction))  # the contacts found are none of the file's: the least
    else:
        return _problem(grasp.file, NO_FRICTION, f"grasp '{grasp.name}' has no friction: give --friction", grasp.line)
    # --wrench replaces the file's other wrenches; the weight is always held (beside them)
    named = [] if options.wrenches is not None else [(w.name, w.wrench) for w in grasp.wrenches if w.name != HOLD]
    named += [(w.name, w.wrench) for w in options.wrenches or ()]
    hold = None
    if options.mass is not None or grasp.mass is not None:
        gravity = np.asarray(GRAVITY if grasp.gravity is None else grasp.gravity, float)
        with np.errstate(over="ignore", invalid="ignore"):  # an overflow is said below
            weight = object_weight(obj, gravity)
        if weight is None:  # a weight apart from the object: the file's top-level mass and center_of_mass
            mass, center = grasp.mass, grasp.center_of_mass
            weight = Weight(mass, center, gravity, hold_wrench(mass, center, gravity))
        if not np.isfinite(weight.wrench).all():  # --mass 1e308: as the same mass in the file is
            return _problem(
                grasp.file,
                NON_FINITE,
                f"grasp '{grasp.name}': the weight or its moment about the origin overflows "
                "(mass x gravity, center_of_mass x weight)",
                grasp.line,
            )
        hold = (weight.mass, weight.center_of_mass, weight.gravity)
        named.insert(0, (HOLD, weight.wrench))
    if not named:
        return _problem(
            grasp.file,
            NOTHING_TO_HOLD,
            f"grasp '{grasp.name}' has nothing to hold: give the object a mass (--mass) or --wrench",
            grasp.line,
        )
    return obj, friction, tuple(n for n, _ in named), np.array([w for _, w in named]), hold


def _hand(job, grasp: Grasp, obj: GraspObject):
    """The hand that must reach the grasps of ``grasp`` (``(HandReach, Hand, its file)``), None
    without one, or the error of the document."""
    given = job.options.hand_file is not None  # --hand; else job.hand only names the columns (the file's)
    hand = job.hand if given else grasp.hand
    if hand is None:
        return None
    radius = job.options.tip_radius
    if radius is not None:
        hand = replace(hand, fingers=tuple(replace(f, tip_radius=radius) for f in hand.fingers))
    # an inline finger's tip point is where the file's contact is (its joints are given at that configuration)
    tips = None
    if any(f.tip_pose is None for f in hand.fingers):
        if given or np.isnan(grasp.points).any():  # --hand, a mesh, a document without contacts
            return _problem(
                grasp.file,
                NO_TIP_POINTS,
                "an inline hand has no tip points without the contacts its fingers touch: put it in a grasp file",
                grasp.line,
            )
        tips = file_tips(grasp, hand)
    from ..io.urdf_meshes import grasp_folder  # the finger links' meshes: with the first URDF hand
    from .collisions import hand_constraints

    # a URDF's meshes are found from the file that names it: the grasp file, or --hand's
    named_by = replace(grasp, file=job.options.hand_file if given else grasp.file)
    try:
        reach = hand_constraints(
            obj,
            hand,
            environment=grasp.environment,
            tips=tips,
            folder=grasp_folder(named_by),
        )
        return reach, hand
    except InputError as exc:
        return GraspFileError(exc.code, f"hand: {exc.message}", grasp.file, grasp.line, None, grasp.document)
    except ValueError as exc:
        return _problem(grasp.file, UNSEARCHABLE_HAND, str(exc), grasp.line)


def _inline_joints(hand, synthesis):
    """An inline hand's joints moved to each grasp's joint positions (its file gives them there)."""
    if hand is None or hand.source is not None:
        return None
    from ..engine.kinematics import forward_kinematics

    return tuple(
        tuple(forward_kinematics(f.screws, f.points, None, q[list(f.joint_index)])[:2] for f in hand.fingers)
        for q in synthesis.joint_positions
    )


def _mesh_grasp(path: str, job) -> Grasp | GraspFileError:
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


class Progress(NamedTuple):
    """Work for a progress bar: ``extra`` units found (a search's budget), ``done`` units done."""

    extra: int
    done: int


def synthesize_inputs(job, inputs: Iterable) -> Iterator[GraspFileError | Found | Progress]:
    """Every object of ``inputs`` (paths or the errors of ``expand``) searched, in order, with the
    progress of each search (its candidates) and of each input (one unit).  An object whose search
    raises (a fault of ours, not of the input) is its ``internal-error`` record, and the others run on."""
    for item in inputs:
        if isinstance(item, GraspFileError):
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
            if isinstance(entry, GraspFileError):
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


def _torsion(options, entry: Grasp, friction: float) -> float | None:
    """The soft contacts' radius of a search: ``--torsion``, else the least of the document's contacts' when
    every one is ``model: soft`` (as its friction, the least), else None (point contacts); None with a
    friction of 0 (``--friction 0`` over a file's soft contacts: frictionless, as the engine's models)."""
    if options.torsion is not None:
        return options.torsion
    soft = entry.torsion
    every = soft is not None and (np.asarray(soft) > 0).all() and friction > 0
    return float(np.min(soft)) if every else None


def _internal(file, line, exc: Exception) -> GraspFileError:
    """The ``internal-error`` record of an object whose reading or search raised ``exc``."""
    return _problem(file, "internal-error", f"{type(exc).__name__}: {exc}", line)


def _searched_entry(job, entry: Grasp) -> Iterator[GraspFileError | Found | Progress]:
    """One grasp document's search (:func:`synthesize_inputs`): its errors, or its progress and what it found."""
    o = job.options
    task = _task(o, entry)
    if isinstance(task, GraspFileError):
        yield task
        return
    obj, friction, names, wrenches, hold = task
    hand = _hand(job, entry, obj)
    if isinstance(hand, GraspFileError):
        yield hand
        return
    reach, hand = hand if hand is not None else (None, None)
    said = _object_warnings(entry, obj, hand)
    torsion = _torsion(o, entry, friction)
    yield Progress(o.candidates, 0)
    surface, clear = environment_search(surface_of(obj, o.span_bodies), entry.environment, None, reach)
    for step in search_steps(
        surface,
        wrenches,
        friction,
        count=o.count,
        safety=o.safety,
        objective=o.objective,
        wrist=entry.wrist,
        methods=METHODS if o.method == "both" else (o.method.replace("-", "_"),),
        min_conditioning=MIN_CONDITIONING if o.min_conditioning is None else o.min_conditioning,
        min_spacing=o.min_spacing,
        constraints=clear,
        hand=reach,
        quality=o.quality,
        seed=o.seed,
        candidates=o.candidates,
        seconds=o.seconds,
        position_error=o.position_error,
        friction_error=o.friction_error,
        perturbations=o.perturbations,
        torsion=torsion,
    ):
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
        friction,
        names,
        wrenches,
        hold,
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
        torsion=torsion,
    )
    if o.simulate is not None:
        from .simulate import held_only  # MuJoCo, with the first synthesize --simulate

        found, dropped = held_only(found, o.simulate)
        found = replace(found, dropped=dropped)
    yield found


def searched(job, inputs: list, workers: int = 1) -> Iterator[GraspFileError | Found | Progress]:
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
        if isinstance(item, GraspFileError):
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
        if isinstance(item, GraspFileError):
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
    if 0 < len(found) < o.count:  # fewer distinct feasible grasps than wanted: the spacing may be why
        spacing = "default" if o.min_spacing is None else f"{o.min_spacing:g}"
        found_count = f"{len(found)} of {o.count} grasps wanted (min spacing {spacing})"
    late = f"; {s.unverified} found but not verified before --seconds ran out" if s.unverified else ""
    if found.dropped:
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
