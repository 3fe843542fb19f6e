"""The force side of the grasp: how hard each finger must press (issue 19).

- ``grasp_map``: the grasp map ``G``, Yoshikawa-Nagai's manipulating forces ``G^+ w``
  in closed form, the squeezes (internal forces) along the sides of the contact
  triangle, the status codes and the ``check_*`` validators;
- ``socp``: a batched primal-dual interior-point method over second-order cones of any size (no loop over grasps);
  its iteration is ``ipm``'s, written once in lane form, run by numpy as the twin ``_twin`` makes;
  ``one``: the same method for one row in Python floats (``ipm``'s float twin, which ``_twin`` makes too); ``kernel``: the whole grip of a row
  compiled by numba (the ``fast`` extra; ``ipm``'s iteration compiled), loaded through ``compiled`` at the first grip;
- ``cones``: the contact models as cones (frictionless, point, soft finger) and the grip over any
  mix of them (the rows with a soft contact, numpy only);
- ``grip``: the least total normal force that holds a wrench within the friction cones;
- ``hold``: holding a weight along an object path (gravity fixed in space): the grip at each
  pose, and the stretches where none exists;
- ``closure``: force closure, the least common friction that gives it, and the
  Ferrari-Canny ``epsilon``.

Conventions (docs/guide/forces.md): a wrench is ``(force; moment about the origin)``,
normals point into the object, a finger pushes (``f_i . n_i >= 0``), ``w = G f``.
"""
