"""The options of the wrench, path, synthesis and simulation families, apart from the twist
rows' (:mod:`.options`, which re-exports them: their one home for callers) so that a
``resolve`` defines none of them at start-up (bench/startup.py).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from ..model import Wrench

__all__ = ["ForceOptions", "FollowOptions", "SynthesisOptions", "SimulateOptions"]


@dataclass(frozen=True)
class ForceOptions:
    """The wrench family's options: what ``grasptwist forces`` asks of every row beyond its inputs.

    ``wrenches`` (``--wrench``) replace each grasp's own, ``friction``
    (``--friction``) its friction; ``safety``, ``quality`` and ``cone_edges``
    go to the engine; ``torsion`` (``--contact soft --torsion E``), every
    contact's torsional radius: soft-finger contacts for the grip, :data:`POINT_CONTACTS` (``--contact
    point``) every contact a point, None the files' contacts (``model: soft``, else point).
    """

    wrenches: tuple[Wrench, ...] | None = None
    friction: float | None = None
    safety: float = 1.0
    quality: bool = False
    cone_edges: int = 8
    torsion: float | None = None

    def rows_per_grasp(self) -> int:
        """Rows each grasp of a data set gives: one per wrench of the command line, else its own (or none)."""
        return len(self.wrenches) if self.wrenches else 1


@dataclass(frozen=True)
class FollowOptions:
    """The path family's options: what ``follow`` was asked beyond what every command shares.

    Attributes
    ----------
    method : str
        A ``--method`` value.
    path : str or None
        Follow only the paths of this name.
    segments : tuple of Segment or None
        The command line's path, replacing the files'.
    samples : int or None
        Samples per path, evenly spaced, both ends included.
    dt : float or None
        Time step between samples instead (the path's end is a sample too).
    bases : bool
        Keep the basis screws (formats that show them; :func:`follow_outputs` sets it from the format).
    """

    method: str = "both"
    path: str | None = None
    segments: tuple | None = None
    samples: int | None = None
    dt: float | None = None
    bases: bool = True


@dataclass(frozen=True)
class SynthesisOptions:
    """The synthesis family's options: what ``grasptwist synthesize`` searches for, and how long.

    ``friction`` (``--friction``), ``mass`` (``--mass``: the object's weight, at its centre of
    mass, is the wrench ``hold``) and ``wrenches`` (``--wrench``) replace a grasp file's;
    ``count`` (``-n``) grasps are wanted, at least ``min_spacing`` apart; ``candidates`` and
    ``seconds`` bound the search; ``grasp_file`` (``-o FILE.yaml``) receives the grasps found;
    ``tip_radius`` (``--tip-radius``) replaces every fingertip's radius of the hand (the file's, or
    the job's ``hand``: ``--hand``, read from ``hand_file``); ``units`` (``--units``) is the length
    unit of the mesh files given directly (a grasp file says its own); ``span_bodies``
    (``--span-bodies``) lets a grasp's contacts lie on different bodies of a mesh; ``position_error``,
    ``friction_error`` and ``perturbations`` (``--position-error``, ...) make each grasp's robustness;
    ``loads`` (``--loads``: ``six``, a grip for the hold test's six loads beside the weight, or
    ``weight``); ``simulate`` (``--simulate``) keeps only the grasps that hold in all six directions in
    MuJoCo (:func:`grasptwist.run.simulate.held_only`).
    The rest go to :func:`grasptwist.engine.synthesis.search.search`.
    """

    count: int = 5
    friction: float | None = None
    mass: float | None = None
    wrenches: tuple[Wrench, ...] | None = None
    safety: float = 1.0
    objective: str = "robust"
    method: str = "both"
    min_conditioning: float | None = None  # None: the engine's (engine.synthesis.scores.MIN_CONDITIONING)
    min_spacing: float | None = None
    quality: bool = False
    seed: int = 0
    candidates: int = 20000
    seconds: float | None = 60.0
    grasp_file: str | None = None
    tip_radius: float | None = None
    hand_file: str | None = None
    units: str | None = None
    span_bodies: bool = False
    position_error: float | None = None
    friction_error: float = 0.2
    perturbations: int = 64
    torsion: float | None = None  # --contact soft --torsion E: every contact soft; 0: point; None: the file's
    loads: str = "six"  # engine.hold_test.LOADS

    simulate: SimulateOptions | None = None

    def __post_init__(self):
        # the options the search never sees as such (they change the object and the hand), checked as
        # the command line checks them, for every way in (grasptwist.dask passes them as keywords)
        from ..engine.hold_test import check_loads
        from ..engine.synthesis.checks import check_mass, check_tip_radius

        check_mass(self.mass)
        check_tip_radius(self.tip_radius)
        check_loads(self.loads)


@dataclass(frozen=True)
class SimulateOptions:
    """The simulation family's options: what ``grasptwist simulate`` runs in MuJoCo, and how.

    ``mass`` (``--mass``) and ``friction`` (``--friction``) replace the file's; ``table``
    (``--table Z``) puts a table plane at height ``Z``; ``duration`` (``--duration``) is the
    time each direction's load is applied; ``distance_tol`` and ``angle_tol`` (``--tolerance
    D,DEG``, degrees) how far the object may move and turn and still be held; ``safety``
    (``--safety``) the grip's safety factor; ``mjcf`` (``--mjcf OUT.xml``) where the scene is
    written; ``path`` (``--path NAME``) a path (or twist) to execute instead of the hold test.
    """

    mass: float | None = None
    friction: float | None = None
    table: float | None = None
    duration: float = 1.0
    distance_tol: float = 0.002
    angle_tol: float = 2.0
    safety: float = 1.25
    mjcf: str | None = None
    path: str | None = None

    def __post_init__(self):
        # checked as the command line checks them, for every way in (grasptwist.simulate, synthesize)
        from ..engine.hold_test import check_duration, check_tolerance

        for name, check, values in (
            ("duration", check_duration, (self.duration,)),
            ("tolerance", check_tolerance, (self.distance_tol, self.angle_tol)),
        ):
            try:
                check(*values)
            except ValueError as exc:
                raise ValueError(f"{name}: {exc}") from None
