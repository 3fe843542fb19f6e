"""Follow object paths: grasps in, sample blocks and per-path findings out.

For each grasp of each input and each of its paths (or the command line's),
the engine moves the grasp along the path and resolves every sample's
instantaneous twist (:func:`grasptwist.engine.path.follow`, a chunk of
samples at a time so that memory stays bounded), then finds the path's
degeneracies between the samples (:func:`grasptwist.engine.path.degeneracies`).
A grasp with a ``mass`` and a ``friction`` also gets the grip that holds its
weight at each sample and the stretches where none does
(:mod:`grasptwist.engine.forces.hold`).
A grasp with a hand has its fingers follow the contacts first
(:func:`grasptwist.engine.hands.track`): each sample's joint rates are the hand
result at the integrated joint positions, as ``resolve`` computes it.
Samples come out as ordinary result :class:`~grasptwist.run.batch.Block`
objects, so that records, columns and warnings are the ones ``resolve``
writes.  No math here: only slicing and labelling.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, replace

import numpy as np

from ..engine import hands
from ..engine.degeneracy import radians_warning
from ..engine.forces.grip import Grip
from ..engine.forces.hold import HoldStretch, Unjudged, grip_along, hold_verdicts
from ..engine.hands import HandTrack
from ..engine.judgements import rotation_over_pi
from ..engine.path import PathDegeneracies, Poses, degeneracies, follow, pose_overflowed
from ..engine.placement import home_at, place
from ..io.datasets import DATASET_SUFFIXES
from ..io.limits import MAX_SAMPLES
from ..model import Grasp, InputError, ObjectPath
from ..output import follow_records as fr
from ..output.formats import FORMATS
from ..output.records import diagnostics, error_record
from ..results import BY_KEY, selected
from .batch import Block, with_reasons
from .collisions import CODES, PathCollisions
from .options import FollowOptions
from .outputs import Output
from .placement import read

__all__ = [
    "Samples",
    "Summary",
    "follow_grasp",
    "follow_inputs",
    "follow_outputs",
    "sample_times",
    "NO_PATH",
    "COMMAND_LINE",
]

#: Error code of a grasp with no path to follow (or none of the name asked for).
NO_PATH = "no-path"

#: Name of the path given on the command line (``--twist``/``--duration``).
COMMAND_LINE = "command-line"

#: Samples per engine call.
CHUNK = 4096


@dataclass(frozen=True, eq=False)
class Samples:
    """Consecutive samples of one path: the results block and where each sample is.

    ``block``'s ``twist_name`` holds the path's name; ``poses`` are the
    samples' times, segments, poses and space twists; ``joint_positions``
    ``(N, n_joints)`` the hand's integrated joint positions (None: no hand);
    ``grip`` the grip holding the grasp's weight at each sample (None: the grasp
    has no ``mass`` or no ``friction``).
    """

    path: str
    block: Block
    poses: Poses
    joint_positions: np.ndarray | None = None
    grip: Grip | None = None

    def __len__(self) -> int:
        return len(self.block)


@dataclass(frozen=True, eq=False)
class Summary:
    """What a path does to one grasp, after its samples."""

    file: str
    grasp: Grasp
    path: str
    samples: int
    found: PathDegeneracies
    labels: tuple[str, ...]  # the methods run
    hand: HandTrack | None = None  # the fingers' tracks, when the grasp has a hand
    cannot_hold: tuple[HoldStretch, ...] | None = None  # where no grip holds its weight, with mass and friction
    unjudged: tuple[Unjudged, ...] | None = None  # where the grip fails otherwise: held or not is unknown there
    tip_error: np.ndarray | None = None  # (3,) with a hand: each finger's largest tip error at the samples
    # the grasp's as read (its object's pose, its normals); rotation vectors over pi (the path as given);
    # links through the object
    warnings: tuple[str, ...] = ()


def sample_times(duration: float, samples: int | None = None, dt: float | None = None) -> np.ndarray:
    """Sample times over ``[0, duration]``: ``samples`` evenly spaced, or every ``dt`` and the end.

    >>> sample_times(2.0, samples=3).tolist(), sample_times(1.0, dt=0.4).tolist()
    ([0.0, 1.0, 2.0], [0.0, 0.4, 0.8, 1.0])
    """
    if dt is None:
        return np.linspace(0.0, duration, samples if samples is not None else 21)
    count = math.ceil(duration / dt)
    if count >= MAX_SAMPLES:
        raise ValueError(f"a step of {dt!r} gives more than {MAX_SAMPLES} samples over a duration of {duration!r}")
    return np.append(np.arange(count) * dt, duration)


def follow_inputs(job, inputs: Iterable) -> Iterator[InputError | Samples | Summary]:
    """Every path of every grasp of ``inputs`` (paths or the errors of ``expand``), in order;
    ``job`` a :class:`~grasptwist.run.pipeline.Job` of the path family."""
    for item in inputs:
        if isinstance(item, InputError):
            yield item
        elif item.endswith(DATASET_SUFFIXES):
            yield InputError("read-error", "follow reads grasp files, not data sets", item)
        else:
            for entry in read(item, job.max_bytes, job.reading):
                yield from follow_grasp(job.options, entry) if isinstance(entry, Grasp) else (entry,)


def follow_outputs(job, inputs: Iterable, w, workers: int = 1, tuning=None) -> Iterator[Output]:
    """Follow every path: per input error, sample chunk and summary, the
    :class:`~grasptwist.run.outputs.Output` of its encoded records (a block format's
    samples go to ``w`` here), counts and stderr lines (a path's lines are its summary's:
    samples are counted, not told).  One process: a path's samples come in order."""
    fmt = FORMATS[job.fmt]
    job = replace(job, options=replace(job.options, bases=fmt.bases))
    encoding = fr.encodings(job.hand)[job.fmt]
    for item in follow_inputs(job, inputs):
        if isinstance(item, Samples):
            encoded = []
            if fmt.takes_blocks:
                w.write(item)
            else:
                encoded = list(encoding.samples(item, job.order))
            failed = int(item.block.failed_rows().sum())
            yield Output(encoded=encoded, records=len(item), failed=failed, degenerate=item.block.failure_codes())
            continue
        error = isinstance(item, InputError)
        rec = error_record(item) if error else fr.summary_record(item)
        encode = encoding.error if error else encoding.summary
        errors, warnings = diagnostics(rec) if error else fr.diagnostics(rec, item.grasp.contact_names)
        out = Output(encoded=[] if encode is None else [encode(rec)], errors=errors, warnings=warnings, records=1)
        out.count(rec)
        yield out


def follow_grasp(job: FollowOptions, grasp: Grasp) -> Iterator[InputError | Samples | Summary]:
    """Every path of one grasp (or the options' own): its samples, then its summary; an error for a path not
    there."""
    paths = (ObjectPath(COMMAND_LINE, job.segments, None),) if job.segments else grasp.paths
    chosen = [p for p in paths if job.path is None or p.name == job.path]
    if not chosen:
        yield _no_path(grasp, job.path)
    for p in chosen:
        yield from _path(job, grasp, p)


def _path(job, grasp, p):
    labels = tuple(k.label for k in selected(job.method))
    # a grasp without a wrist gets NaN, as resolve gives it: off-tangent is then null, not missing
    wrist = grasp.wrist if grasp.wrist is not None else np.full(3, np.nan)
    duration = float(sum(s.duration for s in p.segments))
    try:
        times = sample_times(duration, job.samples, job.dt)
    except ValueError as exc:
        yield InputError("too-many-samples", f"path '{p.name}': {exc}", grasp.file, p.line, None)
        return
    tracked = (
        None
        if grasp.hand is None
        else hands.track(grasp.hand, grasp.joint_positions, grasp.points, p.segments, times, normals=grasp.normals)
    )
    # the weight, gravity fixed in space: needs a mass to hold and a friction to hold it with
    weight = (
        None
        if grasp.mass is None or grasp.friction is None
        else (grasp.points, grasp.normals, grasp.friction, grasp.mass, grasp.center_of_mass, grasp.gravity, p.segments)
    )
    largest = None  # each finger's largest tip error at the samples, as their records give it
    collided = PathCollisions(grasp)
    for start in range(0, len(times), CHUNK):
        q = None if tracked is None else tracked.positions[start : start + CHUNK]
        grip = None if weight is None else grip_along(*weight, times[start : start + CHUNK], torsion=grasp.torsion)[1]
        f = follow(
            grasp.points,
            grasp.normals,
            wrist,
            p.segments,
            times[start : start + CHUNK],
            method=job.method,
            bases=job.bases,
        )
        said, clearance = collided.at(q, f.poses)
        block = replace(_block(grasp, p.name, f, job.bases, job.method, q), grasp_warnings=said, clearance=clearance)
        if tracked is not None:
            seen = block.results["hand"].tip_error.max(axis=0)
            largest = seen if largest is None else np.maximum(largest, seen)
        yield Samples(p.name, block, f.poses, q, grip)
    found = degeneracies(grasp.points, grasp.normals, grasp.wrist, p.segments, times)
    stretches, unjudged = (None, None) if weight is None else hold_verdicts(*weight, times, torsion=grasp.torsion)
    # the grasp's own warnings as read (its object's pose, its normals), not its collisions at rest:
    # the samples' own (t = 0 among them) say those
    read_warnings = tuple(w for w in grasp.warnings if not w.startswith(tuple(f"{code}:" for code in CODES)))
    said = read_warnings + _radians(p) + collided.warnings(len(times))
    yield Summary(grasp.file, grasp, p.name, len(times), found, labels, tracked, stretches, unjudged, largest, said)


def _radians(path) -> tuple[str, ...]:
    """A warning per pose target of ``path`` given by a rotation vector over pi (degrees, most likely)."""
    given = [s for s in path.segments if s.rotvec is not None]
    over = rotation_over_pi([s.rotvec for s in given]) if given else ()
    return tuple(radians_warning(s.rotvec, s.line, s.column) for s, bad in zip(given, over) if bad)


def _block(grasp, name, f, bases, method, positions=None) -> Block:
    n = len(f.poses.time)
    results = {"off_tangent": f.off_tangent, "tangent": f.tangent}
    results = {k: r for k, r in results.items() if r is not None}
    if positions is not None:  # the hand's joint rates at its integrated positions, as resolve's
        states = hands.finger_states(grasp.hand, positions)
        screws, limits = hands.padded(grasp.hand, [s.screws for s in states])
        # where each fingertip is against its moving contact (the tracker's error, the gap), in the records
        home = home_at(grasp.hand, grasp.points, grasp.normals)
        placement = place(grasp.hand, f.points, f.normals, positions, home=home).fields()
        inputs = {"joint_screws": screws, "joint_limits": limits, "points": f.points, "twist": f.poses.twist}
        inputs["placement"] = placement
        # where the pose overflows, the hand's rates are no result of the path either (as the methods')
        results["hand"] = pose_overflowed(BY_KEY["hand"].compute({**inputs, **results}, bases), f.overflowed)
    block = Block(
        file=[grasp.file] * n,
        grasp=[grasp.name] * n,
        units=[grasp.units] * n,
        twist_name=[name] * n,
        contact_names=[grasp.contact_names] * n,
        points=f.points,
        normals=f.normals,
        twist=f.poses.twist,
        wrist=np.broadcast_to(grasp.wrist if grasp.wrist is not None else np.full(3, np.nan), (n, 3)),
        has_wrist=np.full(n, grasp.wrist is not None),
        velocity=f.velocities,
        results=results,
        bases=bases,
        hands=None if positions is None else [grasp.hand] * n,
        method=method,
        center_of_mass=None
        if grasp.center_of_mass is None
        else f.poses.rotation @ grasp.center_of_mass + f.poses.position,
        # the contacts move with the object: each keeps its distance from the surface
        surface_distance=None if grasp.surface_distance is None else np.broadcast_to(grasp.surface_distance, (n, 3)),
    )
    return with_reasons(block)  # a method asked for by name that cannot run fails, as in resolve


def _no_path(grasp: Grasp, name: str | None) -> InputError:
    if grasp.paths:  # a name that is not among them: say which there are
        names = ", ".join(f"'{p.name}'" for p in grasp.paths)
        message = f"grasp '{grasp.name}' has no path named '{name}' (its paths: {names})"
    else:
        message = (
            f"grasp '{grasp.name}' has no path to follow: add a 'paths:' list to the file "
            "or pass --twist W1,W2,W3,V1,V2,V3 --duration T (repeatable)"
        )
    return InputError(
        code=NO_PATH,
        message=message,
        file=grasp.file,
        line=grasp.line,
        column=1,
    )
