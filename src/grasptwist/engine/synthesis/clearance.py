r"""The environment as the search sees it: contacts whose fingertip would not keep its clearance are never sampled.

A contact ``(p, n)`` touched by a fingertip sphere of radius ``r`` has the sphere's centre at
``c = p - r n``; the contact is *clear* when the sphere keeps the clearance :math:`c_\min`
from the table and the boxes (:func:`~grasptwist.engine.environment.sphere_distance`):

.. math:: \phi_E(p - r\,n) - r \ge c_\min .

A point contact (no hand) is the case ``r = 0``: the contact itself keeps the clearance.  A
face that rests on the table is never clear (its points are on the table, their spheres'
centres below it), nor is a strip as high as the radius and the clearance above it on the
faces beside.  With a hand, ``r`` is its least fingertip radius: each finger's own sphere is
checked again when the hand is put on the contacts (:mod:`~.reach`).
"""

from __future__ import annotations

import numpy as np

from ..environment import clearance_of, environment_distance, has_obstacles, sphere_distance
from .reach import hand_clearance

__all__ = ["clear_contacts", "clear_surface", "ClearTriples", "environment_search", "grasp_clearance"]


def clear_contacts(points, normals, environment, radius, clearance):
    """Which contacts are clear (module docstring): ``(..., 3)``, ``(..., 3)`` -> ``(...)`` bool.

    >>> from grasptwist.model import Environment
    >>> p = np.array([[0.03, 0, 0.0], [0.03, 0, 0.02], [0, 0, 0.0]])
    >>> n = np.array([[-1.0, 0, 0], [-1.0, 0, 0], [0, 0, 1.0]])  # two on a side, one on the resting face
    >>> clear_contacts(p, n, Environment(0.0), 0.01, 0.001).tolist()
    [False, True, False]
    """
    p, n = np.asarray(points, float), np.asarray(normals, float)
    return sphere_distance(p - radius * n, radius, environment)[0] >= clearance


class ClearTriples:
    """The search's constraint (``constraints``): ``(N, 3, 3), (N, 3, 3) -> (N,)`` every contact clear.

    It remembers how close the candidates it saw came (:attr:`best`: the largest over the triples of
    their contacts' least clearance, ``-inf`` before any), so that a search that no candidate
    passed names it, ``clearance``, with that distance and the clearance it needed.

    >>> from grasptwist.model import Environment
    >>> clear = ClearTriples(Environment(0.0), 0.0, 0.5)
    >>> p = np.array([[[0.1, 0, 0.2], [0, 0.1, 0.3], [0, 0, 0.4]]])
    >>> clear(p, -p).tolist(), clear.best, clear.needed
    ([False], 0.2, 0.5)
    """

    name = "clearance"

    def __init__(self, environment, radius, clearance):
        self.environment, self.radius, self.needed = environment, radius, clearance
        self.best = -np.inf

    def __call__(self, points, normals):
        p, n = np.asarray(points, float), np.asarray(normals, float)
        least = sphere_distance(p - self.radius * n, self.radius, self.environment)[0].min(axis=-1)
        self.best = max(self.best, float(least.max(initial=-np.inf)))
        return least >= self.needed


def clear_surface(surface, environment, radius, clearance):
    """A search's surface (``Surface``) whose samples are clear contacts, and whose projection
    marks a point that is not as one with no normal (``on_edge``), so that refinement never steps
    onto it.  Where no sample of a draw is clear, the draw is given whole: the constraint
    (:class:`ClearTriples`) then rejects its candidates.

    >>> from grasptwist.model import Environment, GraspObject, Shape
    >>> from grasptwist.engine.synthesis.problem import surface_of
    >>> cube = GraspObject(Shape("box", np.full(3, 0.065)), np.eye(4))  # its bottom face on z = -0.0325
    >>> s = clear_surface(surface_of(cube), Environment(-0.0325), 0.0, 0.001)
    >>> p, n = s.sample(600, np.random.default_rng(0))
    >>> len(p) < 600, bool((p[:, 2] >= -0.0315).all())
    (True, True)
    """

    def sample(count, rng):
        p, n = surface.sample(count, rng)
        keep = clear_contacts(p, n, environment, radius, clearance)
        return (p[keep], n[keep]) if keep.any() else (p, n)

    def project(points):
        p, n, d, on_edge = surface.project(points)
        return p, n, d, on_edge | ~clear_contacts(p, n, environment, radius, clearance)

    return surface._replace(sample=sample, project=project)


def environment_search(surface, environment, clearance, hand=None):
    """A search's surface and its further constraints with an environment: ``(surface, constraints)``.

    Contacts clear for the hand's least fingertip radius (a point without a hand) are sampled
    (:func:`clear_surface`) and required (:class:`ClearTriples`); without a table or a box, the
    surface as it is and no constraint.
    """
    if not has_obstacles(environment):
        return surface, ()
    room = clearance_of(environment) if clearance is None else float(clearance)
    radius = 0.0 if hand is None else float(np.min(hand.radii))
    return clear_surface(surface, environment, radius, room), (ClearTriples(environment, radius, room),)


def grasp_clearance(points, environment, hand=None, positions=None):
    """Each grasp's clearance: the least signed distance of any finger from the environment.

    With a hand (``HandReach``) every part of it at ``positions`` (:func:`~.reach.hand_clearance`),
    without one the contacts ``points (K, 3, 3)`` themselves; ``(K,)``, None without a table or a box.

    >>> from grasptwist.model import Environment
    >>> grasp_clearance(np.array([[[0, 0, 0.01], [0, 0, 0.02], [0, 0, 0.03]]]), Environment(0.0)).tolist()
    [0.01]
    """
    if not has_obstacles(environment):
        return None
    if hand is not None:
        return hand_clearance(hand, positions)
    return environment_distance(points, environment)[0].min(axis=-1)
