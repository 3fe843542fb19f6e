"""Simulate grasps in MuJoCo: grasp files in, one hold test (or, with ``--path``, one path
executed) per grasp out.

Each grasp (hand placed, as every command reads it) needs an object, a mass (the object's,
the file's ``mass``, or ``--mass``) and a friction (the file's or ``--friction``); a URDF hand's
description and meshes are read here for MuJoCo's URDF reader; its scene is
:func:`grasptwist.sim.scene.build_scene`'s, its test :func:`grasptwist.sim.hold.hold_test`'s
(:func:`grasptwist.sim.path.run_path`'s).
With ``-j`` each input file is simulated in a worker process.  No math here: only reading,
routing and labelling.
"""

from __future__ import annotations

import itertools
import math
import os
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, replace

import numpy as np

from ..engine.hold_test import check_distance_tol
from ..engine.objects.geometry import mass_properties, object_size
from ..engine.synthesis.diagnosis import Failure
from ..io.urdf_meshes import grasp_folder, urdf_files
from ..model import Grasp, InputError
from ..output import simulate_records as sr
from ..output.records import diagnostics, dumps, error_record
from ..sim.hold import HoldTest, hold_test
from ..sim.path import PathRun, run_path
from ..sim.scene import Scene, build_scene
from .options import NOT_SIMULATED, SimulateOptions
from .outputs import Output
from .placement import place_grasp, read
from .pool import Pool, pool_size

__all__ = [
    "Simulated",
    "PathSimulated",
    "NotSimulated",
    "simulate_grasp",
    "simulate_path",
    "simulate_inputs",
    "simulate_outputs",
    "write_mjcf",
    "NO_OBJECT",
    "NO_MASS",
    "NO_FRICTION",
    "NO_PATH",
    "BAD_TOLERANCE",
    "PATH_SAMPLES",
    "SCENE_ERROR",
    "UNSTABLE",
    "GRAVITY",
    "SIMULATED",
    "held_only",
    "simulate",
]

#: Error codes of a grasp that cannot be simulated, and of a simulation that diverged.
NO_OBJECT, NO_MASS, NO_FRICTION, NO_PATH = "no-object", "no-mass", "no-friction", "no-path"

#: The error code of a distance tolerance not below the object's size.
BAD_TOLERANCE = "tolerance-too-large"

#: Samples of a path executed (``simulate --path``), ends included.
PATH_SAMPLES = 21
SCENE_ERROR, UNSTABLE = "scene-error", "simulation-unstable"

#: The constraint a search's grasps failed when none held in MuJoCo (``synthesize --simulate``).
SIMULATED = "simulation"

#: Gravity when the file gives none.
GRAVITY = (0.0, 0.0, -9.81)


@dataclass(frozen=True, eq=False)
class Simulated:
    """One grasp's hold test, with what it was run with."""

    grasp: Grasp
    mass: float
    friction: np.ndarray
    test: HoldTest
    options: SimulateOptions
    scene: str | None = None  # the MJCF file its scene was written to (--mjcf)


@dataclass(frozen=True, eq=False)
class NotSimulated:
    """A grasp that was read but could not be simulated: the grasp, why, and its scene's file if one
    was written before it failed (a simulation that diverged)."""

    grasp: Grasp
    error: InputError
    scene: str | None = None


def _problem(grasp: Grasp, code: str, message: str) -> InputError:
    return InputError(code, f"grasp '{grasp.name}': {message}", grasp.file, grasp.line, None, grasp.document)


def _mass(options, grasp, obj):
    if options.mass is not None:
        return options.mass
    return mass_properties(obj).mass if mass_properties(obj).mass is not None else grasp.mass


def _prepared(options: SimulateOptions, grasp: Grasp, mjcf, hold: bool):
    """What a simulation of ``grasp`` needs: ``(mass, friction, gravity, load, centre of mass, scene, its
    file)``, or why it cannot be run; the scene compensates the object's weight for the hold test
    (``hold``); ``mjcf`` (a path, or a callable giving one) is where its scene is written, if not None."""
    obj = grasp.object
    if obj is None:
        return _problem(grasp, NO_OBJECT, "has no object to simulate: add an 'object' key")
    too_large = check_distance_tol(options.distance_tol, object_size(obj))
    if too_large is not None:
        return _problem(grasp, BAD_TOLERANCE, f"{too_large}: give --tolerance a smaller distance")
    mass = _mass(options, grasp, obj)
    if mass is None:
        return _problem(grasp, NO_MASS, "has no mass: give the object a mass or density, the file a mass, or --mass")
    if options.friction is None and grasp.friction is None:
        return _problem(grasp, NO_FRICTION, "has no friction: give the file a friction, or --friction")
    friction = np.full(3, options.friction) if options.friction is not None else np.asarray(grasp.friction, float)
    gravity = np.asarray(GRAVITY if grasp.gravity is None else grasp.gravity, float)
    load = mass * float(np.linalg.norm(gravity))
    obj = replace(obj, mass=mass, density=None)
    urdf, env = None, grasp.environment  # the file's table and boxes; --table replaces its table
    if grasp.hand is not None and grasp.hand.source is not None:  # MuJoCo reads the URDF and its meshes
        try:
            urdf = urdf_files(grasp.hand, folder=grasp_folder(grasp))
        except InputError as exc:
            return _problem(grasp, exc.code, f"hand: {exc.message}")
    try:
        scene = build_scene(
            replace(grasp, object=obj),
            mass=mass,
            friction=friction,
            load=load,
            tolerance=options.distance_tol,
            torsion=grasp.torsion,
            table_height=options.table if options.table is not None or env is None else env.table_height,
            boxes=() if env is None else env.boxes,
            urdf=urdf,
            gravity=gravity,
            object_gravcomp=hold,
        )
    except ValueError as exc:  # MuJoCo's URDF reader or compiler: its reason
        return _compile_error(grasp, exc)
    written = None if mjcf is None else (mjcf() if callable(mjcf) else mjcf)
    if written is not None:
        write_mjcf(scene, written)
    return mass, friction, gravity, load, mass_properties(obj).center_of_mass, scene, written


def _unstable(grasp, where: str, u) -> InputError:
    return _problem(
        grasp, UNSTABLE, f"{where}: the simulation diverged at step {u.step} (t = {u.time:g} s): {u.reason}"
    )


def _compile_error(grasp, exc) -> InputError:
    return _problem(grasp, SCENE_ERROR, f"MuJoCo cannot compile its scene: {exc}".strip())


def simulate_grasp(
    options: SimulateOptions, grasp: Grasp, mjcf: str | Callable[[], str] | None = None, observe=None
) -> Simulated | PathSimulated | InputError:
    """The hold test of one grasp (its path's execution with ``options.path``), or why it cannot be
    run (module docstring); ``mjcf``: write its scene there (a callable: called for the file's name once
    the scene is built, so that only scenes written are numbered); ``observe``:
    :func:`~grasptwist.sim.hold.hold_test`'s."""
    if options.path is not None:
        return simulate_path(options, grasp, mjcf)
    ready = _prepared(options, grasp, mjcf, hold=True)
    if isinstance(ready, InputError):
        return ready
    mass, friction, _, load, center, scene, written = ready
    try:
        test = hold_test(
            scene,
            grasp,
            center_of_mass=center,
            friction=friction,
            load=load,
            duration=options.duration,
            distance_tol=options.distance_tol,
            angle_tol=np.radians(options.angle_tol),
            safety=options.safety,
            torsion=grasp.torsion,
            observe=observe,
        )
    except ValueError as exc:  # MuJoCo's compiler: its reason
        return _compile_error(grasp, exc)
    if test.unstable is not None:
        return _unstable(grasp, f"direction {test.unstable.where}", test.unstable)
    return Simulated(grasp, mass, friction, test, options, written)


@dataclass(frozen=True, eq=False)
class PathSimulated:
    """One grasp's path executed in MuJoCo (``simulate --path``), with what it was run with."""

    grasp: Grasp
    path: str
    mass: float
    friction: np.ndarray
    run: PathRun
    options: SimulateOptions
    scene: str | None = None  # the MJCF file its scene was written to (--mjcf)


def _segments(grasp: Grasp, name: str):
    """The segments of the grasp's path ``name``, or its twist ``name`` held for one unit of time."""
    from ..model import Segment

    for p in grasp.paths:
        if p.name == name:
            return p.segments
    for t in grasp.twists:
        if t.name == name:
            return (Segment(1.0, twist=t.screw),)
    names = ", ".join(f"'{n}'" for n in [p.name for p in grasp.paths] + [t.name for t in grasp.twists]) or "none"
    return _problem(grasp, NO_PATH, f"has no path or twist named '{name}' (its paths and twists: {names})")


def simulate_path(
    options: SimulateOptions, grasp: Grasp, mjcf: str | Callable[[], str] | None = None
) -> PathSimulated | InputError:
    """The grasp's path (or twist, held for one unit of time) ``options.path`` executed in MuJoCo
    (:func:`grasptwist.sim.path.run_path`), :data:`PATH_SAMPLES` samples compared with the plan."""
    segments = _segments(grasp, options.path)
    if isinstance(segments, InputError):
        return segments
    ready = _prepared(options, grasp, mjcf, hold=False)
    if isinstance(ready, InputError):
        return ready
    mass, friction, gravity, _, center, scene, written = ready
    times = np.linspace(0.0, float(sum(s.duration for s in segments)), PATH_SAMPLES)
    try:
        run = run_path(
            scene,
            grasp,
            segments,
            times,
            friction=friction,
            center_of_mass=center,
            gravity=gravity,
            safety=options.safety,
            torsion=grasp.torsion,
        )
    except ValueError as exc:
        return _compile_error(grasp, exc)
    if run.unstable is not None:
        return _unstable(grasp, f"path '{options.path}' at {run.unstable.where}", run.unstable)
    return PathSimulated(grasp, options.path, mass, friction, run, options, written)


def write_mjcf(scene: Scene, path: str) -> None:
    """The scene's MJCF at ``path``, its meshes beside it (``python -m mujoco.viewer --mjcf PATH``)."""
    folder = os.path.dirname(os.path.abspath(path))
    for name, data in scene.assets.items():
        with open(os.path.join(folder, name), "wb") as out:
            out.write(data)
    with open(path, "w", encoding="utf-8") as out:
        out.write(scene.xml)


def _mjcf_name(path: str, k: int) -> str:
    """``--mjcf OUT.xml`` for the first scene written, ``OUT-2.xml``, ... for the next.

    >>> _mjcf_name("out.xml", 1), _mjcf_name("out.xml", 2)
    ('out.xml', 'out-2.xml')
    """
    if k == 1:
        return path
    stem, suffix = os.path.splitext(path)
    return f"{stem}-{k}{suffix}"


def _simulated_one(options: SimulateOptions, grasp: Grasp, numbers):
    """One grasp simulated, its scene numbered by ``numbers`` when it is written (``--mjcf``)."""
    written = []

    def scene_file() -> str:
        written.append(_mjcf_name(options.mjcf, next(numbers)))
        return written[-1]

    result = simulate_grasp(options, grasp, None if options.mjcf is None else scene_file)
    if isinstance(result, InputError):
        return NotSimulated(grasp, result, written[0] if written else None)
    return result


def simulate_inputs(
    job, inputs: Iterable, numbers=None
) -> Iterator[Simulated | PathSimulated | NotSimulated | InputError]:
    """Every grasp of ``inputs`` (paths or the errors of ``expand``) simulated, in order (an input that
    cannot be read: its :class:`InputError`; a grasp read but not simulated: :class:`NotSimulated`);
    ``numbers`` (an iterator, default from 1) numbers the scenes written for ``--mjcf``, so that they
    are ``OUT.xml``, ``OUT-2.xml``, ... without gaps."""
    numbers = itertools.count(1) if numbers is None else numbers
    for item in inputs:
        if isinstance(item, InputError):
            yield item
            continue
        for entry in read(item, job.max_bytes, job.reading):
            yield _simulated_one(job.options, entry, numbers) if isinstance(entry, Grasp) else entry


def _simulated(job, inputs: list, workers: int) -> Iterator[list]:
    """The items of each input (:func:`simulate_inputs`), a list per input in order: each input on one
    of ``workers`` forked processes when there are several (``--mjcf`` numbers its files in one)."""
    if job.options.mjcf is not None or pool_size(workers, len(inputs)) <= 1:
        numbers = itertools.count(1)
        for item in inputs:
            yield list(simulate_inputs(job, [item], numbers))
        return
    with Pool(lambda i: list(simulate_inputs(job, inputs[i : i + 1])), workers, in_flight=1) as pool:
        yield from pool.results(len(inputs))


def simulate_outputs(job, inputs: Iterable, w, workers: int = 1, tuning=None) -> Iterator[Output]:
    """The :class:`~grasptwist.run.outputs.Output` of each grasp simulated (a record each), and of
    each input done (the progress bar's unit)."""
    for items in _simulated(job, list(inputs), workers):
        for item in items:
            if isinstance(item, NotSimulated):  # read, but not simulated: counted by its code, not as an input failed
                rec = sr.not_simulated_record(error_record(item.error), item.grasp.name, item.scene)
                errors, warnings = diagnostics(rec)
                code = (NOT_SIMULATED, rec["error"]["code"])
                out = Output(encoded=[_encode(job, rec)], errors=errors, records=1, failed=1, degenerate={code: 1})
                yield out
                continue
            rec = error_record(item) if isinstance(item, InputError) else sr.simulate_record(item)
            errors, warnings = diagnostics(rec)
            out = Output(encoded=[_encode(job, rec)], errors=errors, warnings=warnings, records=1)
            out.count(rec)
            yield out
        yield Output(done=1)


def _encode(job, rec):
    if job.fmt == "table":
        return rec
    return sr.csv_line(rec) if job.fmt == "csv" else dumps(rec)


def _found_grasp(found, k: int) -> Grasp:
    """Grasp ``k`` that a search found, as a grasp file would give it (its hand at its joint positions)."""
    s = found.synthesis
    hand, positions = found.hand, None if s.joint_positions is None else s.joint_positions[k]
    if found.joints_at is not None:  # an inline hand: its joints moved to this grasp, positions 0 there
        hand = replace(
            hand, fingers=tuple(replace(f, screws=j[0], points=j[1]) for f, j in zip(hand.fingers, found.joints_at[k]))
        )
        positions = np.zeros(len(hand.joint_names))
    mass, center, gravity = found.hold if found.hold is not None else (None, None, None)
    return Grasp(
        f"{found.name}#{k + 1}",
        found.units,
        found.hand_file or found.file,  # a URDF hand's files are found from the file that names it
        0,
        found.contact_names,
        s.points[k],
        s.normals[k],
        found.wrist,
        (),
        found.line or 1,
        hand=hand,
        joint_positions=positions,
        friction=np.full(3, found.friction),
        torsion=None if found.torsion is None else np.full(3, found.torsion),
        mass=mass,
        center_of_mass=center,
        gravity=gravity,
        object=found.object,
        environment=found.environment,  # the fingers keep out of its table and boxes, as in simulate
    )


def _rows(synthesis, keep: np.ndarray):
    """The search's result with only the grasps ``keep`` (indices, best first kept so)."""
    taken = {
        name: None if getattr(synthesis, name) is None else getattr(synthesis, name)[keep]
        for name in ("points", "normals", "surface_distance", "total_normal_force", "closure_friction", "epsilon")
        + ("conditioning", "joint_positions", "reach_error", "tip_center")
    }
    return replace(synthesis, grips=tuple(synthesis.grips[k] for k in keep), **taken)


def held_only(found, options: SimulateOptions):
    """``found`` with only the grasps that hold in all six directions in MuJoCo, each kept grasp's
    :class:`~grasptwist.sim.hold.HoldTest` (``found.simulated``), and how many were dropped
    (``synthesize --simulate``); an object without a weight (no mass) has no load to test: all are kept."""
    if not len(found) or found.hold is None:
        return found, 0
    keep, tests = [], []
    for k in range(len(found)):
        sim = simulate_grasp(options, _found_grasp(found, k))
        if isinstance(sim, Simulated) and sim.test.held:
            keep.append(k)
            tests.append(sim.test)
    keep = np.array(keep, dtype=int)
    synthesis = _rows(found.synthesis, keep)
    if not len(keep):  # the search's record says why there is none
        message = f"none of the {len(found)} grasps found held in all six directions in MuJoCo (--simulate)"
        synthesis = replace(synthesis, failure=Failure(SIMULATED, message, math.nan, math.nan))
    kept = replace(found, synthesis=synthesis, simulated=tuple(tests))
    if found.joints_at is not None:
        kept = replace(kept, joints_at=tuple(found.joints_at[k] for k in keep))
    return kept, len(found) - len(keep)


def simulate(
    grasp: Grasp,
    *,
    mass: float | None = None,
    friction: float | None = None,
    table_height: float | None = None,
    duration: float = 1.0,
    tolerance: tuple[float, float] = (0.002, 2.0),
    safety: float = 1.25,
    mjcf: str | None = None,
) -> Simulated:
    """Run the six-direction hold test of one grasp in MuJoCo, as ``grasptwist simulate`` does.

    Parameters
    ----------
    grasp : Grasp
        With an object, as :func:`grasptwist.read_grasps` gives it: a URDF hand not yet on its
        contacts is placed first (:func:`grasptwist.place_grasp`, as every command places it), one
        placed already is taken as it is.
    mass, friction : float, optional
        Replace the grasp's (its object's mass, density or the file's ``mass``; its ``friction``).
    table_height : float, optional
        A table plane ``z = table_height`` under the object.
    duration : float
        Seconds each direction's load is applied.
    tolerance : (float, float)
        The distance (length units) and angle (degrees) within which the object counts as held.
    safety : float
        The grip's safety factor.
    mjcf : str, optional
        Write the scene there (MJCF, meshes beside it).

    Returns
    -------
    Simulated
        ``test.held``, and ``test.directions``: each direction's displacement, rotation
        (radians), MuJoCo's contact forces and the planned ones.

    Raises
    ------
    InputError
        A grasp it cannot simulate (``no-object``, ``no-mass``, ``no-friction``, ``scene-error``), a hand
        that cannot be put on its contacts (``contact-off-finger``, ``unreachable``, ``outside-limits``)
        or a simulation that diverged (``simulation-unstable``), or a distance tolerance not below the
        object's size (``tolerance-too-large``).
    ValueError
        A duration or tolerance out of bounds (``grasptwist.engine.hold_test.check_duration``,
        ``check_tolerance``), in the command line's words.
    """
    options = SimulateOptions(mass, friction, table_height, duration, *tolerance, safety)
    grasp = place_grasp(grasp)  # the one placement, as the command line reads every grasp
    if isinstance(grasp, InputError):
        raise grasp
    result = simulate_grasp(options, grasp, mjcf)
    if isinstance(result, InputError):
        raise result
    return result
