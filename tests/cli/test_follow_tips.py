"""``follow`` with fingertips of a radius: the TriFinger's spheres roll on the turning cube.

Spinning the cube of ``grasps/trifinger-cube.yaml`` by 0.5 rad about the vertical through
it, each fingertip sphere (10 mm, from the URDF) stays tangent to its face: every sample's
``tip_gap`` is zero to round-off, its ``tip_center`` is ``p(t) - r n(t)``, and ``tip_contact``
is the face's normal in the tip link's frame.  Welding the contact point to the tip link
instead (the behaviour before) leaves the spheres 1.2 mm inside the faces at the end.
"""

import json

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from grasptwist.cli import app
from grasptwist.engine.se3 import rotvec_to_matrix
from grasptwist.hand import finger_states
from grasptwist.path import Segment, track_finger
from grasptwist.run.placement import read_grasps
from places import GRASPS

pytest.importorskip("yourdfpy")
pytest.importorskip("robot_properties_fingers")


@pytest.fixture(scope="module")
def spun(tmp_path_factory):
    doc = yaml.safe_load((GRASPS / "trifinger-cube.yaml").read_text("utf-8"))
    doc["paths"] = [{"name": "turn", "segments": [{"angular": [0, 0, 0.5], "duration": 1.0}]}]
    path = tmp_path_factory.mktemp("tips") / "spin.yaml"
    path.write_text(yaml.safe_dump(doc, sort_keys=False), "utf-8")
    result = CliRunner().invoke(app, ["follow", str(path), "--samples", "3", "-f", "jsonl"])
    assert result.exit_code == 0, result.output
    (g,) = read_grasps(path)
    return g, [json.loads(line) for line in result.stdout.splitlines()][:-1]


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_each_sample_has_its_fingertips_tangent_to_the_turning_faces(spun):
    g, samples = spun
    assert len(samples) == 3
    for sample in samples:
        turn = rotvec_to_matrix([0, 0, 0.5 * sample["t"]])
        p, n = g.points @ turn.T, g.normals @ turn.T
        fingers = sample["hand"]["fingers"]
        assert [f["tip_radius"] for f in fingers] == [0.01] * 3
        np.testing.assert_allclose([f["tip_gap"] for f in fingers], 0.0, rtol=0, atol=1e-14)
        np.testing.assert_allclose([f["tip_center"] for f in fingers], p - 0.01 * n, rtol=0, atol=1e-14)
        q = np.array([x for f in fingers for x in f["joint_positions"]])
        turned = np.array([s.tip[:3, :3] for s in finger_states(g.hand, q)])
        want = np.einsum("fji,fj->fi", turned, n)  # the face's normal in each tip link's frame
        np.testing.assert_allclose([f["tip_contact"] for f in fingers], want, rtol=0, atol=1e-12)
    assert samples[-1]["t"] == 1.0


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_a_contact_welded_to_the_tip_would_sink_into_the_face(spun):
    """The regression: tracking the contact point fixed on the tip link (no rolling) puts the
    sphere of finger 0 1.27 mm into its face after the 0.5 rad turn."""
    g, _ = spun
    finger = g.hand.fingers[0]
    q0 = g.joint_positions[list(finger.joint_index)]
    welded = track_finger(
        finger.screws,
        finger.points,
        finger.tip_pose,
        q0,
        g.points[0],
        [Segment(1.0, twist=[0, 0, 0.5, 0, 0, 0])],
        [0.0, 1.0],
        steps=4,
    )
    (state,) = finger_states(g.hand, np.r_[welded.positions[-1], g.joint_positions[3:]])[:1]
    turn = rotvec_to_matrix([0, 0, 0.5])
    gap = (turn @ g.points[0] - state.tip[:3, 3]) @ (turn @ g.normals[0]) - 0.01
    assert gap == pytest.approx(-1.272e-3, abs=2e-6)
