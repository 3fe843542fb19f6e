"""Reading hands from URDF: the hostile corpus (tests/corpus/urdf/expected.tsv),
generated hostile inputs (size, FIFO, symbolic links, nesting, UTF-16, network),
meshes never opened, and the chains read from a toy hand and the TriFinger Pro."""

import builtins
import os
import socket
import sys

import numpy as np
import pytest

from grasptwist import hand
from grasptwist.io import urdf as urdf_io
from grasptwist.model import InputError
from places import TESTS

yourdfpy = pytest.importorskip("yourdfpy")

FOLDER = TESTS / "corpus" / "urdf"
TOY = FOLDER / "hand.urdf"


def _rows():
    lines = [line for line in (FOLDER / "expected.tsv").read_text("utf-8").splitlines() if line and line[0] != "#"]
    header = lines[0].split("\t")
    return [dict(zip(header, line.split("\t"), strict=True)) for line in lines[1:]]


ROWS = _rows()


def test_the_table_covers_every_corpus_file_and_code():
    files = {p.name for p in FOLDER.iterdir()} - {"expected.tsv"}
    assert files <= {row["reference"] for row in ROWS}
    codes = {row["code"] for row in ROWS}
    assert codes >= {
        "forbidden-dtd", "urdf-syntax", "invalid-urdf", "unsupported-joint", "unknown-link", "read-error",
        "path-outside", "package-not-found", "unsupported-url",
    }  # fmt: skip


@pytest.mark.parametrize("row", ROWS, ids=[f"{r['reference']}:{r['tips']}" for r in ROWS])
def test_corpus(row):
    tips = row["tips"].split(",")
    if row["code"] == "-":
        h = hand.load_urdf_hand(row["reference"], tips, folder=FOLDER)
        assert [f.tip for f in h.fingers] == tips
        return
    with pytest.raises(InputError) as caught:
        hand.load_urdf_hand(row["reference"], tips, folder=FOLDER)
    error = caught.value
    assert error.code == row["code"], str(error)
    where = None if row["where"] == "-" else row["where"]
    got = None if error.line is None else f"{error.line}" + ("" if error.column is None else f":{error.column}")
    assert got == where, str(error)
    assert error.message and "\n" not in str(error)


# --------------------------------------------------------------------------
# Generated hostile inputs.


def test_size_cap_before_parsing(tmp_path):
    data = TOY.read_bytes()
    big = tmp_path / "big.urdf"
    big.write_bytes(data + b"<!--" + b"x" * (1 << 20) + b"-->\n")
    with pytest.raises(InputError, match="size limit of 1048576 bytes") as caught:
        hand.load_urdf_hand("big.urdf", ["a_tip"], folder=tmp_path)
    assert caught.value.code == "too-large"
    with pytest.raises(InputError) as caught:
        hand.load_urdf_hand(TOY, ["a_tip"], max_bytes=len(data) - 1)
    assert caught.value.code == "too-large"
    assert hand.load_urdf_hand(TOY, ["a_tip"], max_bytes=len(data)).joint_names == ("a_spread", "a_flex1", "a_flex2")


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs here")
def test_a_fifo_is_refused_without_blocking(tmp_path):
    os.mkfifo(tmp_path / "pipe.urdf")
    with pytest.raises(InputError, match="not a regular file") as caught:
        hand.load_urdf_hand("pipe.urdf", ["a_tip"], folder=tmp_path)
    assert caught.value.code == "read-error"


def test_symbolic_links_are_followed_before_the_folder_check(tmp_path):
    inside = tmp_path / "grasps"
    inside.mkdir()
    (inside / "toy.urdf").write_bytes(TOY.read_bytes())
    (inside / "alias.urdf").symlink_to(inside / "toy.urdf")
    (inside / "escape.urdf").symlink_to(TOY)
    assert hand.load_urdf_hand("alias.urdf", ["b_tip"], folder=inside).fingers[0].tip == "b_tip"
    with pytest.raises(InputError) as caught:
        hand.load_urdf_hand("escape.urdf", ["b_tip"], folder=inside)
    assert caught.value.code == "path-outside"


def test_deep_nesting_is_refused_by_the_parser_limits(tmp_path):
    (tmp_path / "deep.urdf").write_bytes(b'<robot name="x">' + b"<a>" * 20000 + b"</a>" * 20000 + b"</robot>")
    with pytest.raises(InputError) as caught:
        hand.load_urdf_hand("deep.urdf", ["a"], folder=tmp_path)
    assert caught.value.code == "urdf-syntax"
    assert "depth" in caught.value.message


def test_a_dtd_in_utf16_is_refused_and_fetches_nothing(tmp_path):
    # The prolog scan reads bytes as ASCII; in UTF-16 lxml's own declaration check
    # must refuse it, and its parser (network off, DTD loading off) must not connect.
    with socket.socket() as server:
        server.bind(("127.0.0.1", 0))
        server.listen(1)
        server.setblocking(False)
        port = server.getsockname()[1]
        text = f'<?xml version="1.0" encoding="UTF-16"?>\n<!DOCTYPE robot SYSTEM "http://127.0.0.1:{port}/r.dtd">\n<robot name="x"><link name="a"/></robot>\n'
        (tmp_path / "utf16.urdf").write_bytes(text.encode("utf-16"))
        with pytest.raises(InputError) as caught:
            hand.load_urdf_hand("utf16.urdf", ["a"], folder=tmp_path)
        assert caught.value.code == "forbidden-dtd"
        with pytest.raises(BlockingIOError, match="temporarily unavailable"):  # nobody connected
            server.accept()


def test_meshes_and_includes_are_never_opened(monkeypatch):
    opened = []
    real_open, real_os_open = builtins.open, os.open
    monkeypatch.setattr(builtins, "open", lambda f, *a, **k: opened.append(os.fspath(f)) or real_open(f, *a, **k))
    monkeypatch.setattr(os, "open", lambda f, *a, **k: opened.append(os.fspath(f)) or real_os_open(f, *a, **k))
    h = hand.load_urdf_hand("mesh-and-xinclude.urdf", ["a_tip", "b_tip"], folder=FOLDER)
    assert len(h.joint_names) == 6
    assert opened == [str(FOLDER / "mesh-and-xinclude.urdf")]


def test_without_yourdfpy_the_error_says_what_to_install(monkeypatch):
    monkeypatch.setitem(sys.modules, "yourdfpy", None)  # find_spec("yourdfpy") -> None, as when not installed
    with pytest.raises(
        InputError, match=r"pip install yourdfpy \(from a clone of grasptwist: pip install -e '\.\[urdf\]'\)"
    ) as caught:
        hand.load_urdf_hand(TOY, ["a_tip"])
    assert caught.value.code == "urdf-unavailable"


def test_resolve_urdf():
    assert urdf_io.resolve_urdf("hand.urdf", FOLDER) == TOY.resolve()
    assert urdf_io.resolve_urdf(str(TOY)) == TOY.resolve()  # no folder: the caller's own path
    pro = urdf_io.resolve_urdf("package://robot_properties_fingers/urdf/pro/trifingerpro.urdf")
    assert pro.parts[-3:] == ("urdf", "pro", "trifingerpro.urdf") and pro.is_file()


# --------------------------------------------------------------------------
# What is read.


def test_toy_hand_joints_limits_and_lengths():
    h = hand.load_urdf_hand(TOY, ["a_tip", "b_tip"], names=["index", "thumb"])
    a, b = h.fingers
    assert (h.root, h.source, a.name, b.name) == ("palm", str(TOY), "index", "thumb")
    assert h.joint_names == ("a_spread", "a_flex1", "a_flex2", "b_spread", "b_slide", "b_flex")
    assert (a.joint_index, b.joint_index) == ((0, 1, 2), (3, 4, 5))
    described = [(j.name, j.type, j.velocity_limit, j.lower, j.upper, j.line) for j in a.joints + b.joints]
    assert described == [
        ("a_spread", "revolute", 2.0, -0.5, 0.5, 7),
        ("a_flex1", "revolute", 3.0, None, None, 12),  # continuous: no position limits
        ("a_flex2", "revolute", None, -1.5, 0.0, 17),  # velocity="0": no limit
        ("b_spread", "revolute", 2.0, -0.5, 0.5, 26),
        ("b_slide", "prismatic", 0.1, 0.0, 0.04, 31),
        ("b_flex", "revolute", 2.0, -1.0, 1.0, 36),
    ]
    assert np.allclose(b.screws[1], [0, 0, 0, 0, 0, -1.0])  # the slide points down, whatever the spread's yaw
    assert a.length == pytest.approx(0.02 + 0.06 + np.hypot(0.01, 0.05), rel=1e-12)
    assert b.length == pytest.approx(0.02 + 0.05 + 0.04 + 0.04, rel=1e-12)  # + the slide's travel
    assert not a.screws.flags.writeable


def test_toy_hand_forward_kinematics_matches_yourdfpy():
    # rpy origins, a continuous joint, a scaled axis and a prismatic joint
    h = hand.load_urdf_hand(TOY, ["a_tip", "b_tip"])
    robot = yourdfpy.URDF.load(str(TOY), load_meshes=False)
    q = np.random.default_rng(0).uniform(-0.5, 0.5, (3, 6))
    states = hand.finger_states(h, q)
    for k in range(3):
        robot.update_cfg(dict(zip(h.joint_names, q[k])))
        for finger, state in zip(h.fingers, states):
            assert np.allclose(state.tip[k], robot.get_transform(finger.tip), atol=1e-15)
    home = hand.finger_states(h)
    assert home[0].screws is h.fingers[0].screws


def test_trifinger_pro():
    tips = ["finger_tip_link_0", "finger_tip_link_120", "finger_tip_link_240"]
    h = hand.load_urdf_hand("package://robot_properties_fingers/urdf/pro/trifingerpro.urdf", tips)
    assert h.root == "base_link" and len(h.joint_names) == 9
    for finger, angle in zip(h.fingers, (0, 120, 240)):
        assert [j.name for j in finger.joints] == [
            f"finger_{part}_joint_{angle}" for part in ("base_to_upper", "upper_to_middle", "middle_to_lower")
        ]
        assert [(j.lower, j.upper, j.velocity_limit) for j in finger.joints] == [
            (-0.33, 1.0, 1000.0), (0.0, 1.57, 1000.0), (-2.7, 0.0, 1000.0)
        ]  # fmt: skip
        # at home the fingers hang straight down from the holder 0.29 m above the table
        assert np.allclose(finger.points[:, 2], [0.29, 0.29, 0.13], atol=1e-15)
        assert finger.tip_pose[2, 3] == pytest.approx(-0.03, abs=1e-15)
        assert finger.length == pytest.approx(
            np.hypot(0.01685, 0.0505) + np.hypot(0.05015, 0.16) + np.hypot(0.019, 0.16), rel=1e-12
        )
    positions = hand.joint_positions(h, {"finger_upper_to_middle_joint_120": 0.9})
    assert positions.tolist() == [0, 0, 0, 0, 0.9, 0, 0, 0, 0]
    with pytest.raises(ValueError, match="'elbow' is not a joint"):
        hand.joint_positions(h, {"elbow": 1.0})
    with pytest.raises(ValueError, match="names"):
        hand.load_urdf_hand(h.source, tips, names=["one"])
