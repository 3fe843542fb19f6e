"""Names of the public API that moved or went: each stays a deprecated alias for a release.

The core (``grasptwist/__init__.py``, its ``_MOVED``) and each topic module with a moved name (its
``__getattr__``, :func:`topic_getattr`) look old names up here: a ``DeprecationWarning`` naming
the new place, and the value.  Numpy is not imported here: the core stays light to import.
"""

import importlib
import warnings

__all__ = ["MOVED", "moved", "topic_getattr"]

#: Old public place (a core name, or ``topic.name``) -> ``(new place, since, advice)``: the new place
#: under ``grasptwist`` (a public one; for a dropped name the internal module it is read from, and
#: ``advice`` says what to use instead).
MOVED = {
    # 0.4: out of the core, into their topics
    "finger_jacobian": ("hand.finger_jacobian", "0.4", None),
    "joint_rates": ("hand.joint_rates", "0.4", None),
    "JointRates": ("hand.JointRates", "0.4", None),
    "force_closure": ("forces.force_closure", "0.4", None),
    "Closure": ("forces.Closure", "0.4", None),
    "manipulating_forces": ("forces.manipulating_forces", "0.4", None),
    "ManipulatingForces": ("forces.ManipulatingForces", "0.4", None),
    "squeeze_forces": ("forces.squeeze_forces", "0.4", None),
    "grasp_map": ("forces.grasp_map", "0.4", None),
    "ForceStatus": ("forces.Status", "0.4", None),
    "force_status_message": ("forces.status_message", "0.4", None),
    "check_wrench": ("forces.check_wrench", "0.4", None),
    "check_friction": ("forces.check_friction", "0.4", None),
    "check_safety": ("forces.check_safety", "0.4", None),
    # 0.6 (issue 39): one name for the error of every input, not only a grasp file's
    "GraspFileError": ("InputError", "0.6", None),
    # 0.6 (issue 39): grasptwist.hand imports no run/ module; a grasp file's hand placed and checked
    # as the command line does it is the core's, beside read_grasps
    "hand.place_grasp": ("place_grasp", "0.6", None),
    "hand.finger_collisions": ("finger_collisions", "0.6", None),
    "hand.hand_checks_along": ("hand_checks_along", "0.6", None),
    "hand.Collision": ("Collision", "0.6", None),
    "hand.Overlap": ("Overlap", "0.6", None),
    "hand.EnvironmentHit": ("EnvironmentHit", "0.6", None),
    # 0.6: dropped from grasptwist.hand, internal now
    "hand.place_hand": ("engine.ik.place_hand", "0.6", "use grasptwist.hand.place, the one placement"),
    "hand.with_collisions": ("run.collisions.with_collisions", "0.6", "grasptwist.place_grasp checks the fingers"),
    "hand.hand_constraints": ("run.collisions.hand_constraints", "0.6", "grasptwist.synthesize builds it"),
    "hand.HandPlacement": ("model.HandPlacement", "0.6", "a grasp's 'placement', read by grasptwist.place_grasp"),
    "hand.tip_poses": ("engine.hands.tip_poses", "0.6", "use grasptwist.hand.place"),
    "hand.sphere_radius": ("engine.fingertips.sphere_radius", "0.6", "a URDF's fingertip radius is read for you"),
    "hand.RANK_TOL": ("engine.kinematics.RANK_TOL", "0.6", "a tolerance of grasptwist.hand.joint_rates"),
    "hand.COLLISION_TOL": ("engine.collision.COLLISION_TOL", "0.6", "a tolerance of grasptwist.finger_collisions"),
}


def moved(old: str):
    """The value of the old name ``old`` (a key of :data:`MOVED`), with its ``DeprecationWarning``."""
    new, since, advice = MOVED[old]
    words = f"use grasptwist.{new}" if advice is None else f"it is internal now ({advice})"
    warnings.warn(f"grasptwist.{old} is deprecated since {since}: {words}", DeprecationWarning, stacklevel=3)
    module, _, name = new.rpartition(".")
    return getattr(importlib.import_module(f"grasptwist.{module}" if module else "grasptwist"), name)


def topic_getattr(module: str):
    """A topic module's ``__getattr__``: its moved names (``topic.name`` in :data:`MOVED`), else AttributeError."""
    topic = module.rpartition(".")[2]

    def __getattr__(name: str):
        if f"{topic}.{name}" in MOVED:
            return moved(f"{topic}.{name}")
        raise AttributeError(f"module {module!r} has no attribute {name!r}")

    return __getattr__
