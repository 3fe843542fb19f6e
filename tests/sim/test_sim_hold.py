"""The six-direction hold test, run in MuJoCo itself: grasps that hold, grips that do not exist, slip
that the simulation sees, the scene's mass properties, a simulation that diverges."""

import math
import re
from dataclasses import replace

import numpy as np
import pytest

from grasptwist.engine.hold_test import DIRECTIONS
from grasptwist.engine.objects.geometry import mass_properties
from grasptwist.output.simulate_records import simulate_record
from grasptwist.run.options import SimulateOptions
from grasptwist.run.placement import read
from grasptwist.run.simulate import UNSTABLE, simulate_grasp
from grasptwist.sim.hold import hold_test, load_model
from grasptwist.sim.scene import build_scene
from places import GRASPS, TESTS

SHORT = 0.2  # seconds of simulated time per direction: the default run's tests stay short


def _grasp(name, k=0):
    return read(str(GRASPS / name))[k]


def _simulated(name, k=0, **options):
    return simulate_grasp(SimulateOptions(duration=SHORT, **options), _grasp(name, k))


def test_the_trifinger_holds_the_cube_and_mujoco_exerts_the_planned_grip():
    grasp = replace(_grasp("trifinger-cube.yaml"), environment=None)
    sim = simulate_grasp(SimulateOptions(duration=SHORT, mass=0.094, friction=1.0), grasp)
    assert sim.test.held and [d.name for d in sim.test.directions] == list(DIRECTIONS)
    load = 0.094 * 9.81
    assert sim.test.load == pytest.approx(load)
    for d in sim.test.directions:
        assert d.simulated and d.displacement < 5e-4 and d.rotation < math.radians(0.5)  # a quarter of the tolerances
        # each finger's contact force in MuJoCo is grasptwist's grip, squeezed so that every finger
        # presses at least half the load along its normal, within 5% of the load
        np.testing.assert_allclose(d.forces, d.planned, atol=0.05 * load)
        assert ((d.planned * grasp.normals).sum(axis=1) >= 0.5 * load - 1e-9).all()
    # on its table too, the file's (which carries none of the load)
    assert _simulated("trifinger-cube.yaml", mass=0.094, friction=1.0).test.held


def test_an_inline_hand_and_three_slid_fingertips_hold_too():
    hand = _simulated("three-finger-hand.yaml", mass=0.1, friction=0.8)
    ball = _simulated("sphere.yaml", 1, mass=0.1, friction=0.8)  # sphere-equator: no hand
    for sim in (hand, ball):
        assert sim.test.held, [(d.name, d.displacement) for d in sim.test.directions]


def test_a_ball_squeezed_hard_sideways_holds_with_its_drive_stiffened_to_the_grip(tmp_path):
    # sphere-equator's ball with the tips below its equator (a grasp synthesize returned for its weight):
    # sideways its grip pushes up to 36 N for a 0.98 N load; fingers that push F on a ball of radius r
    # roll it away unless their springs' tangential stiffness k exceeds F / r (the rotation's moment
    # grows by F r per radian, the springs' by k r^2).  With the drive stiff against the load alone it
    # rolled away in five directions (45-97 mm); stiffened to each direction's largest force, it holds
    text = (GRASPS / "sphere.yaml").read_text("utf-8").split("\n---")[0].split("contacts:")[0]
    contacts = """contacts:
  - {point: [0.0274471694, 0.0071187816, -0.0205176958], normal: [-0.7842048401, -0.2033937604, 0.5862198793]}
  - {point: [-0.0305279926, -0.0007110992, -0.0171036839], normal: [0.8722283613, 0.0203171206, 0.4886766829]}
  - {point: [0.0156566775, -0.0275191804, -0.0149185509], normal: [-0.4473336441, 0.786262296, 0.4262443112]}
"""
    (tmp_path / "ball.yaml").write_text(text + contacts, "utf-8")
    sim = simulate_grasp(SimulateOptions(duration=SHORT, mass=0.1, friction=0.8), read(str(tmp_path / "ball.yaml"))[0])
    assert max(np.linalg.norm(d.planned, axis=1).max() for d in sim.test.directions) > 20 * sim.test.load
    assert sim.test.held, [(d.name, d.displacement) for d in sim.test.directions]


def test_a_direction_without_a_grip_is_reported_not_simulated():
    # at mu = 0.5 the three side contacts cannot carry the cube's weight sideways or up: no grip
    sim = _simulated("trifinger-cube.yaml", mass=0.094, friction=0.5)
    assert not sim.test.held
    for d in sim.test.directions:
        assert (d.simulated, d.held, d.grip_status) == (False, False, 20)  # cannot-hold
        assert math.isnan(d.displacement) and np.isnan(d.planned).all()


def test_a_grip_planned_with_more_friction_than_the_contacts_have_slips():
    g = _grasp("trifinger-cube.yaml")
    mass, load = 0.094, 0.094 * 9.81
    scene = build_scene(g, mass=mass, friction=np.full(3, 0.3), load=load, tolerance=0.002)
    com = mass_properties(replace(g.object, mass=mass)).center_of_mass
    test = hold_test(scene, g, center_of_mass=com, friction=np.full(3, 1.0), load=load, duration=SHORT)
    lift = test.directions[DIRECTIONS.index("+z")]
    assert lift.simulated and not lift.held and lift.displacement > 0.002


def test_the_objects_mass_centre_and_inertia_in_mujoco_are_the_solids():
    g = _grasp("trifinger-cube.yaml")
    scene = build_scene(g, mass=0.094, friction=np.ones(3), load=1.0, tolerance=0.002)
    model = load_model(scene)
    body = model.body("object")
    a = 0.065
    assert model.body_mass[body.id] == pytest.approx(0.094)
    np.testing.assert_allclose(model.body_inertia[body.id], [0.094 * 2 * a * a / 12] * 3, rtol=1e-12)
    np.testing.assert_allclose(model.body_pos[body.id], [0, 0, 0.0325], atol=1e-15)


def test_a_mesh_collides_as_convex_pieces_and_weighs_as_its_solid():
    trimesh = pytest.importorskip("trimesh")
    g = _grasp("bottle.yaml")
    shape = g.object.shape
    box = trimesh.creation.box((0.05, 0.05, 0.1))  # two pieces given: the object's own
    pieces = [(box.vertices + [0, 0, 0.05], box.faces), (box.vertices - [0, 0, 0.05], box.faces)]
    scene = build_scene(g, mass=0.5, friction=np.ones(3), load=1.0, tolerance=0.002, pieces=pieces)
    model = load_model(scene)
    assert [model.geom(k).name for k in range(model.ngeom) if model.geom_contype[k]][:3] == ["piece0", "piece1", "tip0"]
    solid = trimesh.Trimesh(shape.vertices, shape.faces)
    solid.density = 0.5 / solid.volume
    body = model.body("object").id
    assert model.body_mass[body] == pytest.approx(0.5)
    # the principal moments of inertia, about the centre: trimesh's of the same solid
    expected = np.sort(np.linalg.eigvalsh(solid.moment_inertia))
    np.testing.assert_allclose(np.sort(model.body_inertia[body]), expected, rtol=1e-4)


def test_a_simulation_that_diverges_is_a_record_naming_the_step(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # MuJoCo would log its warning to MUJOCO_LOG.TXT here
    g = _grasp("sphere.yaml", 1)
    options = SimulateOptions(mass=0.1, friction=0.8, duration=SHORT)
    # the slides' springs 1e7 times stiffer than their armature allows: explicit springs blow up
    scene = build_scene(g, mass=0.1, friction=np.full(3, 0.8), load=0.981, tolerance=0.002)
    bad = replace(scene, xml=re.sub(r'stiffness="[^"]+"', 'stiffness="1e9"', scene.xml))
    assert bad.xml != scene.xml
    test = hold_test(bad, g, center_of_mass=np.zeros(3), friction=np.full(3, 0.8), load=0.981, duration=SHORT)
    assert test.unstable is not None and not test.held
    assert test.unstable.where == "+x" and 0 < test.unstable.step <= round(SHORT / 0.001)
    assert options.duration == SHORT and UNSTABLE == "simulation-unstable"
    assert list(tmp_path.iterdir()) == []


def test_gt_simulate_runs_the_hold_test_and_raises_what_it_cannot_simulate():
    import grasptwist as gt

    grasp = _grasp("sphere.yaml", 1)  # sphere-equator: mass 1, friction 0.5
    sim = gt.simulate(grasp, mass=0.1, friction=0.8, duration=SHORT, tolerance=(0.002, 2.0))
    assert sim.test.held and sim.mass == 0.1 and sim.options.duration == SHORT
    with pytest.raises(gt.InputError) as err:
        gt.simulate(replace(grasp, object=None))
    assert err.value.code == "no-object"
    # the command line's bounds, in the same words
    with pytest.raises(ValueError, match=r"^duration: must be at least 0\.05 s \(50 time steps\)"):
        gt.simulate(grasp, mass=0.1, friction=0.8, duration=1e-9)
    with pytest.raises(ValueError, match=r"^tolerance: the angle must be in degrees, > 0 and at most 45, got 179"):
        gt.simulate(grasp, mass=0.1, friction=0.8, tolerance=(1e6, 179))
    with pytest.raises(gt.InputError) as err:
        gt.simulate(grasp, mass=0.1, friction=0.8, duration=SHORT, tolerance=(1e6, 2))
    assert err.value.code == "tolerance-too-large"


def _ball_on_the_table(mu, **environment):
    """sphere-equator's ball (radius 0.035) with its weight, the tips at its equator with friction ``mu``."""
    g = _grasp("sphere.yaml", 1)
    scene = build_scene(
        g, mass=0.1, friction=np.full(3, mu), load=0.981, tolerance=0.002, object_gravcomp=False, **environment
    )
    return scene, load_model(scene)


def _box_under_the_ball():
    from grasptwist.model import Obstacle

    pose = np.eye(4)
    pose[:3, :3] = [[0, -1, 0], [1, 0, 0], [0, 0, 1]]  # a quarter turn about z: its size is along its own axes
    pose[:3, 3] = [0.0, 0.0, -0.035 - 0.01]  # its top the ball's bottom
    return Obstacle(np.array([0.1, 0.12, 0.02]), pose)


def test_boxes_stand_in_the_scene_at_their_poses():
    _, model = _ball_on_the_table(0.8, boxes=[_box_under_the_ball()])
    geom = model.geom("box0")
    np.testing.assert_allclose(model.geom_size[geom.id], [0.05, 0.06, 0.01])
    np.testing.assert_allclose(model.geom_pos[geom.id], [0, 0, -0.045])
    np.testing.assert_allclose(abs(model.geom_quat[geom.id]), [0.5**0.5, 0, 0, 0.5**0.5], atol=1e-12)


@pytest.mark.parametrize("environment", [{"table_height": -0.035}, {"boxes": [_box_under_the_ball()]}])
def test_the_table_and_boxes_never_carry_the_object_it_falls_through_them(environment):
    # the ball resting on the table (or a box), the fingertips at its equator without friction (no
    # grip): it falls freely through the table, z = -g t^2 / 2, as if there were none
    import mujoco

    scene, model = _ball_on_the_table(0.0, **environment)
    data = mujoco.MjData(model)
    data.qpos[[model.jnt_qposadr[model.joint(j).id] for j in scene.joints]] = scene.positions
    mujoco.mj_step(model, data, nstep=100)  # 0.1 s
    z = data.body("object").xpos[2]
    assert z == pytest.approx(-9.81 * 0.1**2 / 2, rel=0.03)  # 49 mm below: through the table's plane
    names = {tuple(sorted((model.geom(c.geom1).name, model.geom(c.geom2).name))) for c in data.contact[: data.ncon]}
    assert not any("piece0" in pair and ("table" in pair or "box0" in pair) for pair in names)


def test_a_fingertip_pushed_onto_the_table_stands_on_it():
    # the environment is there for the hand: tip0 (radius 2% of the ball's size) pushed down by 20 N
    # stops on the table, its centre one radius above it (sinking 0.2 mm, a soft contact under 12 N;
    # without the table the push would take it 82 mm down)
    import mujoco

    scene, model = _ball_on_the_table(0.8, table_height=-0.035)
    data = mujoco.MjData(model)
    data.qfrc_applied[model.jnt_dofadr[model.joint("tip0_z").id]] = -20.0
    mujoco.mj_step(model, data, nstep=300)
    tip = model.geom("tip0").id
    assert data.geom_xpos[tip][2] == pytest.approx(-0.035 + scene.radii[0], abs=5e-4)


def test_the_trifinger_cube_holds_on_its_table_as_without_one():
    # the file's table under the cube carries none of it: at safety 1 and without a squeeze (a grip on the
    # cones' edge) the same directions slip with the table as without (before: 2 with it, 5 without)
    from grasptwist.run.simulate import _prepared

    grasp = _grasp("trifinger-cube.yaml")
    assert grasp.environment is not None and grasp.environment.table_height == 0
    options = SimulateOptions(duration=SHORT, mass=0.094, friction=1.0, safety=1.0)
    on, off = (
        hold_test(scene, g, center_of_mass=com, friction=mu, load=load, duration=SHORT, safety=1.0, squeeze=0.0)
        for g in (grasp, replace(grasp, environment=None))
        for _, mu, _, load, com, scene, _ in [_prepared(options, g, None, hold=True)]
    )
    assert [d.held for d in on.directions] == [d.held for d in off.directions] and not on.held
    moved = [[d.displacement for d in t.directions] for t in (on, off)]
    np.testing.assert_allclose(moved[0], moved[1], rtol=1e-6, atol=1e-9)


@pytest.mark.slow  # CoACD and trimesh's boolean union load in 2 s
def test_coacd_cuts_a_concave_mesh_into_convex_pieces_of_its_volume():
    trimesh = pytest.importorskip("trimesh")
    from grasptwist.sim.scene import convex_pieces

    bar = trimesh.creation.box((0.1, 0.02, 0.02))
    arm = trimesh.creation.box((0.02, 0.1, 0.02))
    arm.apply_translation((0.04, 0.04, 0))
    ell = bar.union(arm)  # an L: its convex hull would fill the corner (1.9 times its volume)
    pieces = [trimesh.Trimesh(v, f) for v, f in convex_pieces(ell.vertices, ell.faces)]
    assert len(pieces) == 2 and all(p.is_convex for p in pieces)
    assert sum(p.volume for p in pieces) == pytest.approx(ell.volume, rel=0.01)


def test_a_urdf_mujoco_cannot_read_is_its_reason_naming_the_urdf():
    from grasptwist.io.urdf_meshes import grasp_folder, urdf_files

    g = _grasp("trifinger-cube.yaml")
    text, meshes = urdf_files(g.hand, folder=grasp_folder(g))
    assert sorted(meshes)[:2] == ["center_axis_sim.stl", "int_sim.stl"]
    with pytest.raises(
        ValueError, match=r"MuJoCo cannot read the URDF package://robot_properties_fingers/.*prox-sim.stl"
    ):
        build_scene(g, mass=0.1, friction=np.ones(3), load=1.0, tolerance=0.002, urdf=(text, {}))  # no meshes


def test_a_grasp_files_environment_is_the_scenes_table_and_boxes_and_table_replaces_its_table(tmp_path):
    from grasptwist.run.simulate import _prepared

    text = (GRASPS / "sphere.yaml").read_text("utf-8").split("\n---")[0]
    env = "environment:\n  table: {height: -0.05}\n  boxes:\n    - {size: [0.02, 0.02, 0.02], pose: {position: [0.2, 0, 0]}}\n"
    (tmp_path / "g.yaml").write_text(text.rstrip() + "\n" + env, "utf-8")
    grasp = read(str(tmp_path / "g.yaml"))[0]
    for table, height in ((None, -0.05), (-0.07, -0.07)):
        *_, scene, _ = _prepared(SimulateOptions(mass=0.1, friction=0.8, table=table), grasp, None, hold=True)
        model = load_model(scene)
        assert model.geom_pos[model.geom("table").id][2] == pytest.approx(height, abs=1e-15)
        np.testing.assert_allclose(model.geom_pos[model.geom("box0").id], [0.2, 0, 0])


@pytest.mark.slow  # a search and eight short hold tests: a second
def test_held_only_keeps_the_grasps_that_hold_within_the_tolerance_and_counts_the_others():
    # synthesize --simulate's filter, held to a tolerance so strict (0.2 mm, then 20 um in 0.1 s) that
    # MuJoCo drops some of the 4 cylinder grasps the seeded search for the weight alone finds, then all
    # (searched for the six loads, all 4 hold within 0.2 mm)
    from grasptwist.run.families import COMMANDS
    from grasptwist.run.options import SynthesisOptions
    from grasptwist.run.pipeline import Job
    from grasptwist.run.simulate import SIMULATED, held_only
    from grasptwist.run.synthesize import Found, synthesize_inputs

    job = Job(
        command=COMMANDS["synthesize"],
        options=SynthesisOptions(count=4, friction=0.8, mass=0.1, candidates=400, loads="weight"),
    )
    (found,) = [x for x in synthesize_inputs(job, [str(GRASPS / "cylinder.yaml")]) if isinstance(x, Found)]
    assert len(found) == 4
    kept, dropped = held_only(found, SimulateOptions(duration=0.1, distance_tol=2e-4))
    assert 1 <= dropped < 4 and len(kept) == 4 - dropped == len(kept.simulated)
    for test in kept.simulated:
        assert test.held and max(d.displacement for d in test.directions) < 2e-4
    kept, dropped = held_only(found, SimulateOptions(duration=0.1, distance_tol=2e-5))
    assert (len(kept), dropped, kept.synthesis.failure.constraint) == (0, 4, SIMULATED)


# A rod pinched at its ends by two soft pads on a line 5 mm beside its centre, a third finger below that
# line: held along +z or -z, its weight's moment about the pads' line is the pads' torsion alone.
ROD = TESTS / "sim" / "soft-rod.yaml"


def test_soft_pads_hold_a_rod_by_their_torsion_which_mujoco_exerts_as_planned():
    from grasptwist.run.simulate import _prepared

    grasp = read(str(ROD))[0]
    options = SimulateOptions(duration=0.1)
    for torsion in (grasp.torsion, None):  # the scene's contacts soft (condim 4), or points (condim 3)
        _, mu, _, load, com, scene, _ = _prepared(options, replace(grasp, torsion=torsion), None, hold=True)
        model = load_model(scene)
        tips = [model.geom(f"tip{f}").id for f in range(3)]
        soft = torsion is not None  # the soft pads' MuJoCo friction (mu, mu e, 0), the point finger's (mu, 0, 0)
        assert model.geom_condim[tips].tolist() == ([4, 4, 3] if soft else [3, 3, 3])
        assert model.geom_friction[tips, :2].tolist() == [[0.5, 0.0025 if soft else 0]] * 2 + [[0.5, 0]]
    sim = simulate_grasp(options, grasp)  # as the command runs it: the soft scene, the soft grip
    soft = sim.test
    assert soft.held and max(math.degrees(d.rotation) for d in soft.directions) < 0.01  # 0.0006 deg at most
    for d in soft.directions[4:]:  # +z, -z: each pad's moment about its normal, 1.2 and 0.35 mN m
        assert d.torsion[:2] == pytest.approx(d.planned_torsion[:2], rel=0.06)  # MuJoCo's within 4%
        assert abs(d.planned_torsion[0]) > 3e-4 and d.torsion[2] == 0
    # the same torques with point contacts (MuJoCo's condim 3, as before soft contacts were simulated):
    # nothing resists the moment about the pads' line, and the rod turns (15 and 22 degrees in 0.1 s)
    point = hold_test(
        scene, grasp, center_of_mass=com, friction=mu, load=load, duration=0.1, safety=1.25, torsion=grasp.torsion
    )
    assert [d.held for d in point.directions] == [True] * 4 + [False] * 2
    assert min(math.degrees(d.rotation) for d in point.directions[4:]) > 5
    # the record says what was simulated
    rec = simulate_record(sim)
    assert rec["contact_model"] == "soft" and rec["torsion"] == [0.005, 0.005, 0.0] and rec["scene"] is None
    up = rec["directions"][4]
    assert up["contact_torsion"] == soft.directions[4].torsion.tolist() and len(up["planned_torsion"]) == 3
