"""Each family's options (:mod:`.families`): what a command asks of its rows beyond what every
command shares, defaults being a command line without options.  Apart from the families'
compute so that a run loads only its own family's (a JSON ``resolve`` never imports the force
engine).  The twist rows' are defined here; the wrench, path, synthesis and simulation families'
in :mod:`.family_options`, imported from here on first use: Python compiles a dataclass's
methods as its module loads, and a ``resolve`` (bench/startup.py) needs none of theirs.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from ..model import Twist

#: The other families' options, defined in :mod:`.family_options` and imported from there on first use.
_ELSEWHERE = ("ForceOptions", "FollowOptions", "SynthesisOptions", "SimulateOptions")

__all__ = ["TwistOptions", *_ELSEWHERE, "NOT_SIMULATED", "POINT_CONTACTS"]

#: The options' ``torsion`` of ``--contact point``: every contact a point contact, a file's ``model: soft`` ones
#: too (None, without ``--contact``, takes the files' contacts as they are).
POINT_CONTACTS = 0.0


#: ``simulate``'s summary word for grasps read but not simulated, counted by code apart from those not
#: held (``3 records: 1 not held, 2 not simulated (2 no-mass), 0 inputs failed``).
NOT_SIMULATED = "not simulated"


@dataclass(frozen=True)
class TwistOptions:
    """The twist family's options: which twists each grasp's rows take, by which methods.

    ``twists`` (``--twist``) replace each grasp's own (``basis`` and ``check``
    fix them to :data:`ZERO_TWIST`: a row per grasp); ``twists_from``
    (``--twists-from``, a file or ``-``) gives them one per line instead;
    ``select`` (``--select``) picks the grasps' own by name.

    >>> TwistOptions().rows_per_grasp(), TwistOptions(twists=(None, None)).rows_per_grasp()
    (1, 2)
    """

    twists: tuple[Twist, ...] | None = None
    method: str = "both"
    twists_from: str | None = None
    select: tuple[str, ...] | None = None
    torsion: float | None = (
        None  # check's --contact: every contact soft for the closure, or a point (0); None: the files'
    )

    def rows_per_grasp(self) -> int:
        """Rows each grasp of a data set gives: one per twist of the command line, else its own."""
        return len(self.twists) if self.twists else 1


def __getattr__(name: str):
    if name in _ELSEWHERE:  # the other families' options, defined when first asked for
        from . import family_options

        return getattr(family_options, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
