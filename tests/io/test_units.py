"""Units that cannot lie (issue 35, item 5): a grasp file's ``units`` weighs a density through the
unit's length, a mesh file in a unit of its own is scaled into the grasp file's, and a size that
looks like a unit mix-up is a warning."""

import numpy as np
import pytest

from grasptwist.engine.units import HAND_FIT, METRE_SPAN, hand_fit_warning, mesh_span_warning
from grasptwist.io.grasp import load_grasps, read_grasps
from small_meshes import cube_obj


def problems(text, file="g.yaml"):
    return [(e.code, e.line, e.column, e.message) for e in read_grasps(text, file=file) if not hasattr(e, "points")]


OBJECT_ONLY = "units: {units}\nobject:\n{object}\ncontacts:\n  - {{point: [{h}, 0, 0]}}\n  - {{point: [-{h}, 0, 0]}}\n  - {{point: [0, {h}, 0]}}\n"


def test_a_65_mm_cube_in_millimetres_at_700_kg_per_cubic_metre_weighs_0_1922_kg():
    text = OBJECT_ONLY.format(units="mm", object="  box: [65, 65, 65]\n  density: 700", h=32.5)
    (g,) = load_grasps(text, file="g.yaml")
    assert g.object.mass == pytest.approx(700 * 0.065**3, rel=1e-12)  # 0.1922 kg, not 1.9e8
    assert round(g.object.mass, 4) == 0.1922
    (hold,) = g.wrenches  # its weight in N, the moment in N mm (lengths stay in the file's unit)
    np.testing.assert_allclose(hold.wrench[:3], [0, 0, 9.81 * 700 * 0.065**3], rtol=1e-12)
    # the same cube in metres weighs the same
    text = OBJECT_ONLY.format(units="m", object="  box: [0.065, 0.065, 0.065]\n  density: 700", h=0.0325)
    (m,) = load_grasps(text, file="g.yaml")
    assert m.object.mass == pytest.approx(g.object.mass, rel=1e-12)


def test_a_mesh_in_millimetres_weighs_what_the_same_mesh_in_metres_does(tmp_path):
    cube_obj(tmp_path / "cube_mm.obj", 65.0)
    text = OBJECT_ONLY.format(units="mm", object="  mesh: cube_mm.obj\n  density: 700", h=32.5)
    (tmp_path / "g.yaml").write_text(text)
    (g,) = load_grasps(tmp_path / "g.yaml")
    assert round(g.object.mass, 4) == 0.1922 and g.warnings == ()


def test_a_mesh_file_in_its_own_unit_is_scaled_into_the_grasp_files(tmp_path):
    cube_obj(tmp_path / "cube_mm.obj", 65.0)
    text = OBJECT_ONLY.format(units="m", object="  mesh: {file: cube_mm.obj, units: mm}\n  density: 700", h=0.0325)
    (tmp_path / "g.yaml").write_text(text)
    (g,) = load_grasps(tmp_path / "g.yaml")
    extent = g.object.shape.vertices.max(axis=0) - g.object.shape.vertices.min(axis=0)
    np.testing.assert_allclose(extent, [0.065] * 3, rtol=1e-12)
    assert g.object.shape.scale.tolist() == [0.001]
    assert round(g.object.mass, 4) == 0.1922 and g.warnings == ()
    # a mesh in metres named in a millimetre file: scaled by 1000; its own scale as well
    cube_obj(tmp_path / "cube_m.obj", 0.065)
    text = OBJECT_ONLY.format(units="mm", object="  mesh: {file: cube_m.obj, units: m, scale: [1, 1, 2]}", h=32.5)
    (tmp_path / "g.yaml").write_text(text)
    (g,) = load_grasps(tmp_path / "g.yaml")
    extent = g.object.shape.vertices.max(axis=0) - g.object.shape.vertices.min(axis=0)
    np.testing.assert_allclose(extent, [65, 65, 130], rtol=1e-12)


def test_a_mesh_in_millimetres_read_in_metres_is_a_warning_that_asks(tmp_path):
    cube_obj(tmp_path / "cube_mm.obj", 65.0)
    text = OBJECT_ONLY.format(units="m", object="  mesh: cube_mm.obj", h=32.5)
    (tmp_path / "g.yaml").write_text(text)
    (g,) = load_grasps(tmp_path / "g.yaml")
    (said,) = g.warnings
    assert said.startswith("mesh-size-unlikely: the mesh spans 65 m: is it in millimetres?")
    # a file without units is in metres too; a 0.5 mm mesh is as unlikely
    cube_obj(tmp_path / "speck.obj", 0.0005)
    (tmp_path / "g.yaml").write_text(OBJECT_ONLY.format(units="m", object="  mesh: speck.obj", h=0.00025))
    (g,) = load_grasps(tmp_path / "g.yaml")
    assert g.warnings[0].startswith("mesh-size-unlikely: the mesh spans 0.0005 m: is its unit right?")


def test_the_span_and_fit_limits_are_the_documented_ones():
    low, high = METRE_SPAN
    assert mesh_span_warning(high, "m") is None and mesh_span_warning(high * 1.001, "m")
    assert mesh_span_warning(low, "m") is None and mesh_span_warning(low * 0.999, "m")
    assert mesh_span_warning(1e6, "px") is None  # a label that is no unit: nothing to judge by
    assert hand_fit_warning(HAND_FIT, 1.0, "m") is None and hand_fit_warning(HAND_FIT * 1.001, 1.0, "m")
    assert hand_fit_warning(1 / HAND_FIT, 1.0, "m") is None and hand_fit_warning(0.0999, 1.0, "m")


HAND = """\
hand:
  fingers:
    - joints: [{{axis: [0, 0, 1], point: [{r}, 0, {z}]}}, {{axis: [0, 1, 0], point: [{r}, 0, 0]}}]
    - joints: [{{axis: [0, 0, 1], point: [-{r}, 0, {z}]}}, {{axis: [0, 1, 0], point: [-{r}, 0, 0]}}]
    - joints: [{{axis: [0, 0, 1], point: [0, {r}, {z}]}}, {{axis: [1, 0, 0], point: [0, {r}, 0]}}]
"""


def test_an_object_ten_times_the_fingers_reach_is_a_warning_and_a_hand_sized_one_is_not():
    # fingers of reach 2 h + ... around a cube of edge 2 h: no warning
    fits = OBJECT_ONLY.format(units="m", object="  box: [2, 2, 2]", h=1) + HAND.format(r=2, z=2)
    (g,) = load_grasps(fits, file="g.yaml")
    assert g.warnings == ()
    # fingers of reach 1.5 on a cube of edge 200 (a millimetre object beside a hand in metres)
    big = OBJECT_ONLY.format(units="mm", object="  box: [200, 200, 200]", h=100) + HAND.format(r=100.5, z=1)
    (g,) = load_grasps(big, file="g.yaml")
    (said,) = g.warnings
    assert said.startswith("hand-size-mismatch: the object's largest extent (200 mm) is ")
    assert "times the fingers' reach (1.5 mm)" in said


def test_a_density_in_a_file_whose_units_are_no_length_is_located():
    text = OBJECT_ONLY.format(units="px", object="  box: [65, 65, 65]\n  density: 700", h=32.5)
    ((code, line, column, message),) = problems(text)
    assert (code, line, column) == ("unknown-units", 4, 12)
    assert message.startswith("object.density: a density is in kg/m^3: weighing the object needs the length")
    # a label alone, with nothing to weigh, stays a label
    (g,) = load_grasps(OBJECT_ONLY.format(units="px", object="  box: [65, 65, 65]", h=32.5), file="g.yaml")
    assert g.units == "px"


def test_a_mesh_unit_that_is_no_length_is_located(tmp_path):
    cube_obj(tmp_path / "c.obj", 65.0)
    text = OBJECT_ONLY.format(units="m", object="  mesh: {file: c.obj, units: parsec-ish}", h=32.5)
    assert problems(text, file=str(tmp_path / "g.yaml"))[0][:3] == ("unknown-units", 3, 30)
    text = OBJECT_ONLY.format(units="m", object="  mesh: {file: c.obj, scale: 2}\n  scale: 2", h=32.5)
    assert problems(text, file=str(tmp_path / "g.yaml"))[0][:3] == ("conflicting-keys", 4, 10)
    text = OBJECT_ONLY.format(units="m", object="  mesh: {units: mm}", h=32.5)
    assert problems(text, file=str(tmp_path / "g.yaml"))[0][:2] == ("missing-key", 3)


def test_a_file_unit_that_is_no_length_beside_a_mesh_unit_and_a_mass_that_underflows_are_located(tmp_path):
    cube_obj(tmp_path / "c.obj", 65.0)
    text = OBJECT_ONLY.format(units="px", object="  mesh: {file: c.obj, units: mm}", h=32.5)
    ((code, line, column, message),) = problems(text, file=str(tmp_path / "g.yaml"))
    assert (code, line, column) == ("unknown-units", 3, 30) and "the file's 'px' is none of" in message
    text = OBJECT_ONLY.format(units="m", object="  box: [1e-20, 1e-20, 1e-20]\n  density: 1e-300", h=5e-21)
    ((code, line, column, message),) = problems(text)
    assert (code, line, column) == ("invalid-mass", 4, 12) and "underflows" in message
