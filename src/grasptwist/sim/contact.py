r"""Contact settings that make MuJoCo's friction Coulomb's, with the grasp file's ``mu``.

grasptwist's model is a point contact with Coulomb friction: a finger's force ``f`` at a
contact with unit normal ``n`` holds while ``|f - (f . n) n| <= mu f . n`` and slides
otherwise.  MuJoCo's contacts are soft and its friction cone is pyramidal unless told
otherwise; each setting below brings it to the model, and ``tests/sim/test_sim_contact.py``
holds the result: a block on a plane tilted just under ``atan(mu)`` stays, just over it
slides.

- ``condim = 3``: a point contact with tangential friction, no torsional or rolling
  friction (the paper's model; a fingertip rolls freely).
- ``condim = 4`` for a soft contact (a grasp file's ``model: soft``, torsional radius ``e``):
  MuJoCo adds torsional friction, its elliptic cone over the contact's force and its moment
  about the normal ``sqrt((f_t1 / mu_1)^2 + (f_t2 / mu_2)^2 + (tau_n / mu_spin)^2) <= f_n``
  (``mu_spin`` a length, the geom's second ``friction`` number).  grasptwist's soft cone
  ``|(f_t, tau_n / e)| <= mu f_n`` is that cone with ``mu_1 = mu_2 = mu`` and
  ``mu_spin = mu e`` (:func:`tip_friction`); rolling friction stays 0.
- ``cone = elliptic``: the cone ``|f_t| <= mu f_n`` itself, not a pyramid inside it
  (a pyramid's faces cut the cone by up to ``1 - cos(pi / 4)``, 29%, with four edges).
- ``impratio``: the ratio of the frictional to the normal constraints' impedance; large,
  so that friction does not give way softly before the cone's edge (MuJoCo's documentation
  recommends it for elliptic cones to curb slip).
- ``noslip_iterations``: a post-solve that removes the slip soft constraints leave inside
  the cone (Todorov's "noslip" solver): a contact inside its cone does not creep.
- ``solref = (timeconst, dampratio)`` and ``solimp``: stiff, critically damped contacts that
  sink a fraction of a millimetre (a soft contact would let the object sag under its load,
  which the hold test would count as movement).
- ``timestep``: 1 ms, a quarter of ``solref``'s time constant (MuJoCo asks for at least two steps).

Friction between two geoms is the larger of theirs, number by number, and their contact's
``condim`` the larger of theirs (MuJoCo's defaults), so the object's geoms carry none
(``0 0 0``: MuJoCo's default torsional and rolling friction, 0.005 and 0.0001, would otherwise
be the larger) and each fingertip carries its contact's (:func:`tip_friction`); the table
carries its own sliding friction, none other.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["ContactSettings", "CONTACT", "option_xml", "tip_friction", "SOFT_CONDIM"]


@dataclass(frozen=True)
class ContactSettings:
    """MuJoCo's options and contact parameters of every scene (the module docstring says why).

    >>> CONTACT.cone, CONTACT.condim
    ('elliptic', 3)
    """

    timestep: float = 0.001
    cone: str = "elliptic"
    impratio: float = 10.0
    noslip_iterations: int = 20
    solref: tuple[float, float] = (0.004, 1.0)
    solimp: tuple[float, float, float] = (0.99, 0.999, 0.001)
    condim: int = 3
    iterations: int = 100


#: The settings every scene uses.
CONTACT = ContactSettings()

#: MuJoCo's ``condim`` of a soft contact: tangential and torsional friction.
SOFT_CONDIM = 4


def tip_friction(mu, torsion=None, settings: ContactSettings = CONTACT) -> tuple[tuple[float, float, float], int]:
    """A fingertip's MuJoCo ``friction`` (sliding, torsional, rolling) and ``condim`` for a contact
    with Coulomb coefficient ``mu`` and torsional radius ``torsion`` (``e``, a length; None or 0: a
    point contact): ``(mu, mu e, 0)`` with ``condim`` 4 for a soft contact, so that MuJoCo's
    elliptic cone is ``|(f_t, tau_n / e)| <= mu f_n`` (module docstring); ``(mu, 0, 0)`` and
    ``settings.condim`` for a point contact.

    >>> tip_friction(0.5, 0.01), tip_friction(0.5)
    (((0.5, 0.005, 0.0), 4), ((0.5, 0.0, 0.0), 3))
    """
    e = 0.0 if torsion is None else float(torsion)
    if e > 0:
        return (float(mu), float(mu) * e, 0.0), SOFT_CONDIM
    return (float(mu), 0.0, 0.0), settings.condim


def _numbers(values) -> str:
    return " ".join(f"{float(v):.17g}" for v in values)


def option_xml(gravity, settings: ContactSettings = CONTACT) -> str:
    """The ``<option>`` and default ``<geom>`` elements of ``settings``, with ``gravity`` ``(3,)``.

    >>> print(option_xml([0, 0, -9.81]).splitlines()[0])
    <option timestep="0.001" gravity="0 0 -9.8100000000000005" cone="elliptic" impratio="10" noslip_iterations="20" iterations="100" integrator="implicitfast"/>
    """
    s = settings
    return (
        f'<option timestep="{s.timestep:g}" gravity="{_numbers(gravity)}" cone="{s.cone}" '
        f'impratio="{s.impratio:g}" noslip_iterations="{s.noslip_iterations}" iterations="{s.iterations}" '
        'integrator="implicitfast"/>\n'
        f'<default><geom condim="{s.condim}" solref="{_numbers(s.solref)}" solimp="{_numbers(s.solimp)}"/></default>'
    )
