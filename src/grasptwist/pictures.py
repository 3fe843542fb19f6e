"""Pictures of a grasp: a scene as plain data, drawn by matplotlib or as an interactive 3D page.

A scene (:func:`scene` from arrays, :func:`grasp_scene` from a loaded grasp) is
what gets drawn, in numbers: markers, line pieces (screw axes), arrows (twists,
velocities, forces), patches (tangent planes, cones), the object's mesh and the
fingertip spheres, framed on the contacts, object and fingertips (:func:`framed`);
:func:`grasps_scene` draws several grasps of one object together.  :func:`render` draws
it with matplotlib (the extra ``grasptwist[plot]``); :func:`twist_figure` and
:func:`grasp_page` make plotly.js figures as plain dicts, :func:`write_page`
writes them as one HTML page (the extra ``grasptwist[html]``).

>>> import numpy as np
>>> from grasptwist import pictures
>>> points = np.array([[1, 0, 0], [-0.5, 0.866, 0], [-0.5, -0.866, 0]])
>>> s = pictures.scene(points, -points, [0, 0, 1], [0, 0, 1, 0, 0, 0], method="off-tangent")
>>> len(s.of_kind("contact")), s.method
(3, 'off-tangent')
>>> print(s.title)
grasp: T = (0, 0, 1; 0, 0, 0)
off-tangent: x = (0, 0, 0)   y = (-0.471, -0.471, -0.471)

The code is in ``grasptwist.plot`` (internal).
"""

from .plot.figures import grasps_figure, twist_figure
from .plot.html import MissingPlotly, grasp_page, read_figures, write_page
from .plot.render import MissingMatplotlib, image_name, plot_grasp, render, render_grasps
from .plot.scene import (
    GRASP_COLOURS,
    KINDS,
    METHODS,
    REACH,
    Arrow,
    LinePiece,
    Marker,
    Mesh,
    Patch,
    Scene,
    Sphere,
    framed,
    grasp_scene,
    grasps_scene,
    scene,
)

__all__ = [
    "scene",
    "grasp_scene",
    "grasps_scene",
    "Scene",
    "Marker",
    "LinePiece",
    "Arrow",
    "Patch",
    "Mesh",
    "Sphere",
    "framed",
    "KINDS",
    "METHODS",
    "REACH",
    "GRASP_COLOURS",
    "render",
    "plot_grasp",
    "render_grasps",
    "image_name",
    "twist_figure",
    "grasps_figure",
    "grasp_page",
    "write_page",
    "read_figures",
    "MissingMatplotlib",
    "MissingPlotly",
]
