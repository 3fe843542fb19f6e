"""The ``hand:`` key of grasp files: both forms, every error located and coded,
and what a hand adds to records (joint rates, finger-cannot-follow, warnings)."""

import csv
import io
import json
import re
import shutil
import sys
from importlib.util import find_spec

import jsonschema
import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from grasptwist.cli import app
from grasptwist.io.grasp import grasp_schema, load_grasps
from grasptwist.run.placement import read_grasps  # the hand placed on its contacts, as every command reads it
from places import ROOT

CORPUS = ROOT / "tests" / "corpus" / "urdf"
TRIFINGER = ROOT / "grasps" / "trifinger-cube.yaml"

CONTACTS = """\
contacts:
  - {point: [1, 0, 0], normal: [-1, 0, 0]}
  - {point: [-1, 0.5, 0.3], normal: [1, 0, 0]}
  - {point: [0.2, -1, -0.4], normal: [0, 1, 0]}
"""


def finger(axes="[0, 0, 1]", extra=""):
    return f"""\
    - joints:
        - {{axis: {axes}, point: [2, 0, 0]{extra}}}
        - {{axis: [0, 1, 0], point: [2, 0, 1]}}
        - {{axis: [1, 0, 0], point: [2, 0, 2]}}
"""


def inline(*fingers):
    return CONTACTS + "hand:\n  fingers:\n" + "".join(fingers)


def errors(text, file="g.yaml"):
    out = read_grasps(text, file=file)
    return [(e.code, e.line, e.column, e.message) for e in out if not hasattr(e, "points")]


def one_error(text, **kw):
    (got,) = errors(text, **kw)
    return got


def test_inline_hand_defaults_and_prismatic_joints():
    text = inline(
        finger(),
        "    - name: index\n      joints:\n        - {name: slide, type: prismatic, axis: [0, 0, 3]}\n",
        finger(),
    )
    (g,) = read_grasps(text, file="g.yaml")
    assert [f.name for f in g.hand.fingers] == ["1", "index", "3"]
    assert g.hand.joint_names == ("1.1", "1.2", "1.3", "slide", "3.1", "3.2", "3.3")
    np.testing.assert_array_equal(g.hand.fingers[1].screws, [[0, 0, 0, 0, 0, 1.0]])  # normalised, (0; d)
    np.testing.assert_array_equal(g.hand.fingers[0].screws[0], [0, 0, 1.0, 0, -2.0, 0])  # (d; a x d)
    assert g.hand.fingers[0].joints[0].velocity_limit is None
    np.testing.assert_array_equal(g.joint_positions, np.zeros(7))


@pytest.mark.parametrize(
    ("text", "code", "line", "column", "match"),
    [
        (inline(finger(), finger()), "finger-count", 7, 5, r"hand\.fingers: expected exactly 3 fingers .* got 2"),
        (
            inline(finger(), finger(), finger().replace("- joints:", "- tip: x\n      joints:")),
            "conflicting-keys",
            15,
            12,
            r"hand\.fingers\[2\]\.tip: mixes the two forms",
        ),
        (
            inline(finger(), finger(extra=", type: spherical"), finger()),
            "unsupported-joint",
            12,
            53,
            r"hand\.fingers\[1\]\.joints\[0\]\.type: expected one of: revolute, prismatic, got 'spherical'",
        ),
        (inline(finger(), finger("[0, 0, 0]"), finger()), "zero-axis", 12, 18, r"joints\[0\]\.axis: a zero vector"),
        (
            inline(finger(), finger(extra=", velocity_limit: -1"), finger()),
            "invalid-limit",
            12,
            63,
            r"velocity_limit: must be positive, got -1",
        ),
        (
            inline(finger(), finger(), finger(extra=", name: 1.2")),
            "duplicate-name",
            16,
            53,
            r"duplicate joint name '1\.2' \(also hand\.fingers\[0\]\.joints\[1\]\)",
        ),
        (
            inline(finger(), "    - joints:\n        - {axis: [0, 0, 1]}\n", finger()),
            "missing-key",
            12,
            11,
            r"joints\[0\]\.point: a revolute joint needs a point",
        ),
        (
            inline(finger(), finger(), finger()).replace("hand:\n", "hand:\n  joint_positions: {a: 1}\n"),
            "conflicting-keys",
            6,
            20,
            r"hand\.joint_positions: only with 'urdf'",
        ),
        (CONTACTS + "hand: [1, 2, 3]\n", "not-a-mapping", 5, 7, r"hand: expected a mapping"),
        (CONTACTS + "hand:\n  fingres: []\n", "unknown-key", 6, 3, r"did you mean 'fingers'"),
    ],
    ids=lambda v: v if isinstance(v, str) and "\n" not in v and len(v) < 30 else "",
)
def test_inline_errors_are_located_and_coded(text, code, line, column, match):
    got = one_error(text)
    assert got[:3] == (code, line, column), got
    assert re.search(match, got[3]), got[3]


urdf_only = pytest.mark.skipif(find_spec("yourdfpy") is None, reason="needs the urdf extra")


def trifinger_text(**changes):
    doc = yaml.safe_load(TRIFINGER.read_text("utf-8"))
    doc.update(changes)
    return yaml.safe_dump(doc, sort_keys=False)


@urdf_only
def test_urdf_form_gives_the_hand_at_its_seed_with_its_tip_radius():
    """The bundled file gives no joint positions (the run solves them) and no tip radius: the
    URDF's tip collision mesh (a 10 mm hemisphere about the tip link's origin) gives it."""
    (g,) = load_grasps(TRIFINGER)  # as read, not yet placed
    assert g.hand.root == "base_link" and g.hand.source.startswith("package://")
    assert [f.tip for f in g.hand.fingers] == ["finger_tip_link_0", "finger_tip_link_120", "finger_tip_link_240"]
    assert not g.placement.given and (g.joint_positions == 0).all()
    assert [f.tip_radius for f in g.hand.fingers] == [0.01] * 3


@urdf_only
def test_a_tip_radius_per_finger_wins_over_the_hands_and_the_urdfs():
    doc = yaml.safe_load(TRIFINGER.read_text("utf-8"))
    doc["hand"]["tip_radius"] = 0.005
    doc["hand"]["fingers"][1]["tip_radius"] = 0
    (g,) = read_grasps(yaml.safe_dump(doc, sort_keys=False), file=str(TRIFINGER))
    assert [f.tip_radius for f in g.hand.fingers] == [0.005, 0.0, 0.005]


def test_an_inline_hand_takes_a_tip_radius():
    text = inline(finger(), finger(), finger()).replace("hand:\n", "hand:\n  tip_radius: 0.25\n", 1)
    (g,) = read_grasps(text, file="g.yaml")
    assert [f.tip_radius for f in g.hand.fingers] == [0.25] * 3


@pytest.mark.parametrize(
    ("value", "code", "match"),
    [("-0.01", "invalid-radius", r"^hand.tip_radius: must be 0 or more, got -0.01$"), ("big", "not-a-number", "")],
)
def test_a_bad_tip_radius_is_located(value, code, match):
    text = inline(finger(), finger(), finger()).replace("hand:\n", f"hand:\n  tip_radius: {value}\n", 1)
    line = text.splitlines().index(f"  tip_radius: {value}") + 1
    got = one_error(text)
    assert got[:3] == (code, line, 15), got
    assert re.search(match, got[3]), got[3]


@urdf_only
def test_contact_off_finger():
    doc = yaml.safe_load(TRIFINGER.read_text("utf-8"))
    doc["contacts"][1]["point"] = [0.5, -0.5, 0.5]  # half a metre away: the hand's frame mistaken
    doc["hand"]["joint_positions"] = {"finger_base_to_upper_joint_0": 0.0}  # given: checked, not solved
    del doc["object"]  # which would call it contact-off-surface first
    code, line, column, message = one_error(yaml.safe_dump(doc, sort_keys=False))
    assert code == "contact-off-finger"
    assert message.startswith("hand.fingers[1].tip: contact 2 is ")
    assert "farther than the finger is long" in message and "root frame" in message
    assert line is not None and column is not None


@urdf_only
def test_unknown_joint_position_is_located():
    doc = yaml.safe_load(TRIFINGER.read_text("utf-8"))
    doc["hand"]["joint_positions"] = {"no_such_joint": 1.0}
    code, _, _, message = one_error(yaml.safe_dump(doc, sort_keys=False))
    assert code == "unknown-joint"
    assert message.startswith("hand.joint_positions.no_such_joint: not a joint of the hand's fingers")


@urdf_only
def test_joints_in_a_urdf_hand_mix_the_forms():
    doc = yaml.safe_load(TRIFINGER.read_text("utf-8"))
    doc["hand"]["fingers"][0]["joints"] = []
    code, _, _, message = one_error(yaml.safe_dump(doc, sort_keys=False))
    assert (code, message.split(":")[0]) == ("conflicting-keys", "hand.fingers[0].joints")


@urdf_only
@pytest.mark.parametrize(
    ("reference", "tips", "code", "match"),
    [
        ("../outside.urdf", "a_tip", "path-outside", r"resolves outside"),
        ("mimic-joint.urdf", "a_tip", "unsupported-joint", r"mimic-joint\.urdf:\d+: joint .* is a mimic joint"),
        ("hand.urdf", "no_link", "unknown-link", r"no link named 'no_link'"),
        ("package://no_such_package_xyz/a.urdf", "a_tip", "package-not-found", r"no installed Python package"),
    ],
)
def test_urdf_errors_are_reported_at_the_urdf_key(tmp_path, reference, tips, code, match):
    shutil.copy(CORPUS / "hand.urdf", tmp_path / "hand.urdf")
    shutil.copy(CORPUS / "mimic-joint.urdf", tmp_path / "mimic-joint.urdf")
    fingers = "".join(f"    - {{tip: {tips}}}\n" for _ in range(3))
    path = tmp_path / "g.yaml"
    path.write_text(CONTACTS + f"hand:\n  urdf: {reference}\n  fingers:\n{fingers}", "utf-8")
    got = errors_of(path)
    assert got[:3] == (code, 6, 9), got
    assert got[3].startswith("hand.urdf: ")
    assert re.search(match, got[3]), got[3]


@urdf_only
def test_a_urdf_outside_the_folder_is_read_with_allow_outside(tmp_path):
    """--allow-outside (Reading.allow_outside) lifts the folder rule for a URDF as for a mesh."""
    inner = tmp_path / "grasps"
    inner.mkdir()
    shutil.copy(CORPUS / "hand.urdf", tmp_path / "hand.urdf")
    fingers = "".join("    - {tip: a_tip}\n" for _ in range(3))
    path = inner / "g.yaml"
    path.write_text(CONTACTS + f"hand:\n  urdf: ../hand.urdf\n  fingers:\n{fingers}", "utf-8")
    assert errors_of(path)[:3] == ("path-outside", 6, 9)
    result = CliRunner().invoke(app, ["resolve", str(path), "--allow-outside", "-f", "jsonl"])
    # read now: its three fingers on one tip link are refused, which only reading it can say
    assert json.loads(result.stdout)["error"]["code"] == "shared-joint" and "path-outside" not in result.stderr


def errors_of(path):
    (e,) = read_grasps(path)
    return e.code, e.line, e.column, e.message


def test_without_the_urdf_extra_the_bundled_trifinger_says_what_to_install(monkeypatch):
    monkeypatch.setitem(sys.modules, "yourdfpy", None)  # find_spec("yourdfpy") -> None, as when not installed
    result = CliRunner().invoke(app, ["resolve", str(TRIFINGER), "-f", "jsonl"])
    assert result.exit_code != 0
    assert "urdf-unavailable" in result.stderr and "pip install -e '.[urdf]'" in result.stderr
    assert "Traceback" not in result.stderr


def test_the_schema_covers_both_forms():
    validator = jsonschema.Draft202012Validator(grasp_schema())
    good = yaml.safe_load(inline(finger(), finger(), finger()))
    validator.validate(good)
    mixed = yaml.safe_load(inline(finger(), finger(), finger()))
    mixed["hand"]["urdf"] = "x.urdf"
    assert not validator.is_valid(mixed)
    no_point = yaml.safe_load(inline(finger(), "    - joints:\n        - {axis: [0, 0, 1]}\n", finger()))
    assert not validator.is_valid(no_point)
    prismatic = yaml.safe_load(
        inline(finger(), "    - joints:\n        - {type: prismatic, axis: [0, 0, 1]}\n", finger())
    )
    validator.validate(prismatic)


# --------------------------------------------------------------------------
# What a hand adds to records.

PLANAR = """\
    - name: planar
      joints:  # three parallel axes: the tip moves in the plane y = 0 only
        - {axis: [0, 1, 0], point: [3, 0, 0]}
        - {axis: [0, 1, 0], point: [2, 0, 1]}
        - {axis: [0, 1, 0], point: [2, 0, 2]}
"""


def resolve(text, tmp_path, twist):
    path = tmp_path / "g.yaml"
    path.write_text(text + "wrist: [0, 0, 3]\n", "utf-8")
    result = CliRunner().invoke(app, ["resolve", str(path), "-f", "jsonl", "--twist", twist])
    return result, [json.loads(line) for line in result.stdout.splitlines()]


def test_a_planar_finger_cannot_follow_out_of_its_plane(tmp_path):
    # finger 1 touches (1, 0, 0); a spin about z moves it along y, out of its plane
    result, (rec,) = resolve(inline(PLANAR, finger(), finger()), tmp_path, "0,0,1,0,0,0")
    assert result.exit_code == 1
    assert rec["ok"] is False
    hand = rec["hand"]
    assert hand["ok"] is False
    assert hand["error"]["code"] == "finger-cannot-follow"
    assert hand["error"]["message"].startswith("finger 1 cannot follow its contact")
    assert hand["fingers"][0]["rank"] == 2 and hand["fingers"][0]["conditioning"] == 0.0
    assert hand["fingers"][0]["residual"] == pytest.approx(1.0)  # the whole velocity is out of reach
    assert "x" in rec["off_tangent"] and "alpha" in rec["tangent"]  # the decomposition stays
    assert "error: hand: finger-cannot-follow: finger 1 cannot follow" in result.stderr
    path = tmp_path / "g.yaml"
    out = CliRunner().invoke(app, ["resolve", str(path), "-f", "csv", "--twist", "0,0,1,0,0,0"]).stdout
    header, row = csv.reader(io.StringIO(out))
    assert row[header.index("hand_error")].startswith("finger-cannot-follow: finger 1 cannot follow")
    assert row[header.index("ok")] == "false" and row[header.index("qdot_planar_planar.1")] == ""


def test_a_planar_finger_follows_in_its_plane_with_a_warning(tmp_path):
    result, (rec,) = resolve(inline(PLANAR, finger(), finger()), tmp_path, "0,0,0,0,0,1")  # lift along z
    assert rec["hand"]["ok"] is True and rec["hand"]["fingers"][0]["residual"] < 1e-12
    assert rec["ok"] is True
    assert any("finger 1 is near a singularity (conditioning < 1e-12 < 0.001)" in w for w in rec["warnings"])
    assert "warning: hand: finger 1 is near a singularity" in result.stderr


def test_records_without_a_hand_have_no_hand_key(tmp_path):
    result, (rec,) = resolve(CONTACTS, tmp_path, "0,0,1,0,0,0")
    assert "hand" not in rec and "joint_rates" not in rec["off_tangent"]
