"""Diagnosis: why a search found no grasp, in words and numbers (:class:`Failure`).

The tightest constraint any candidate reached (:data:`~.scores.CONSTRAINTS`, the archive's
``furthest``), and how close the best candidate came; ``budget`` when too few candidates were
scored to judge the object, ``verification`` when candidates passed every test but none was
verified (the certificate, the hand's forward kinematics, or the time).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .scores import CONSTRAINTS

__all__ = ["Failure", "FEW_CANDIDATES", "diagnose", "unverified"]

#: Fewer candidates than this, every one degenerate, say nothing of the object: the budget is the reason
#: (a chunk of ``k`` candidates draws its contacts from ``k`` surface points, all alike when ``k < 3``).
FEW_CANDIDATES = 100


class Failure(NamedTuple):
    """Why a search found no feasible grasp.

    Attributes
    ----------
    constraint : str
        The tightest constraint (:data:`~.scores.CONSTRAINTS`): the furthest any candidate got;
        ``budget`` when fewer than :data:`FEW_CANDIDATES` were scored, all degenerate (``best``:
        how many); ``verification`` when candidates passed every test but none was verified.
    message : str
        In words, with how close the best candidate came.
    best, needed : float
        That constraint's best value among the candidates and the value it needed
        (NaN where it has no number: the grip).
    """

    constraint: str
    message: str
    best: float
    needed: float


def diagnose(archive, scored, mu, min_conditioning, tol, constraints=()) -> Failure:
    """Why no candidate was feasible: the furthest constraint any reached, and how close the best came
    (a hand's constraints are reached only with a hand: after the grip a row without one is feasible)."""
    if archive.furthest == 0 and scored < FEW_CANDIDATES:
        return Failure(
            "budget",
            f"{scored} scored {'is' if scored == 1 else 'are'} too few to judge the object, none with three "
            f"distinct contacts off one line (allow {FEW_CANDIDATES} candidates or more)",
            float(scored),
            float(FEW_CANDIDATES),
        )
    if archive.furthest >= len(CONSTRAINTS):  # feasible, or spared as no better than the grasps kept
        return Failure(
            "verification",
            "candidates passed every test, but the exact grip's certificate (or the hand's forward "
            "kinematics) verified none",
            np.nan,
            np.nan,
        )
    name = CONSTRAINTS[archive.furthest]
    if name == "degenerate":
        return Failure(name, "every candidate's contacts were degenerate (coincident or collinear)", 0.0, tol)
    if name == "conditioning":
        best = archive.best_conditioning
        return Failure(
            name,
            f"no candidate's conditioning reached {min_conditioning:g} (the best: {best:.3g})",
            best,
            min_conditioning,
        )
    if name == "force_closure":
        best = archive.closest  # inf: no candidate is closure at any finite friction (a flat object's)
        words = f"the best needs friction {best:.3g}" if np.isfinite(best) else "none is at any finite friction"
        return Failure(name, f"no candidate is force closure at friction {mu:g} (friction / safety); {words}", best, mu)
    if name == "constraints":
        # a named constraint (the environment's clearance) that no candidate it saw passed is the one
        for c in constraints:
            if np.isfinite(getattr(c, "best", np.nan)) and c.best < c.needed:
                return Failure(
                    c.name,
                    f"no force-closure candidate keeps every fingertip (a contact, without a hand) {c.needed:g} "
                    f"from the environment (the best: {c.best:.3g})",
                    c.best,
                    c.needed,
                )
        return Failure(name, "no force-closure candidate passed the further constraints", np.nan, np.nan)
    if name == "fingertips":
        return Failure(
            name,
            "on every candidate some fingertip sphere would go into the object (concave there) or within the "
            "clearance of the environment",
            np.nan,
            np.nan,
        )
    if name == "reach":
        best = archive.best_miss.get(name, np.inf)
        return Failure(
            name,
            "the hand reaches no candidate's contacts within its joint limits"
            + (
                f": the best candidate leaves a fingertip {best:.3g} from where it must be" if np.isfinite(best) else ""
            ),
            best,
            0.0,
        )
    if name == "collision":
        best = archive.best_miss.get(name, np.inf)
        return Failure(
            name,
            "every grasp the hand reaches puts a finger link into the object or another finger, or within the "
            "clearance of the environment" + (f" (the least by {best:.3g})" if np.isfinite(best) else ""),
            best,
            np.nan,
        )
    return Failure(name, "no candidate's grip holds every wrench within the friction cones", np.nan, np.nan)


def unverified(count) -> Failure:
    """The failure of a search whose ``count`` grasps found were none verified before its time ran out.

    >>> unverified(2).constraint
    'verification'
    """
    return Failure(
        "verification",
        f"the time ran out before a grasp found was verified ({count} not verified: allow more seconds)",
        np.nan,
        np.nan,
    )
