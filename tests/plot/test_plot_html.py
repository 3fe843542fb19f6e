"""The interactive HTML view (`plot -o FILE.html`): the figures embedded in the page, read back,
hold the engine's numbers; the command's files, options and errors."""

import json
import re
import sys

import numpy as np
import pytest
from typer.testing import CliRunner

from grasptwist import decompose_off_tangent, decompose_tangent
from grasptwist.cli import app
from grasptwist.engine.decompose import contact_velocities
from grasptwist.engine.path import follow
from grasptwist.engine.screws import cross, pitch
from grasptwist.io.grasp import load_grasps
from grasptwist.plot import read_figures, twist_figure
from places import GRASPS, TESTS

pytest.importorskip("plotly")


def run(*args):
    return CliRunner().invoke(app, [str(a) for a in args])


def traces(figure, name, visible_only=True):
    """The traces of a legend entry (line or marker traces, not cone heads) shown at first."""
    return [
        t
        for t in figure["data"]
        if t["name"] == name and t["type"] != "cone" and (not visible_only or t.get("visible", True) is not False)
    ]


def pieces(trace):
    """A line trace's pieces (separated by null) as ``(n, 2, 3)`` start and end points, with their hover texts."""
    xyz = np.array([trace["x"], trace["y"], trace["z"]], dtype=float).T  # null -> nan
    starts = [k for k in range(len(xyz) - 1) if not np.isnan(xyz[k, 0]) and (k == 0 or np.isnan(xyz[k - 1, 0]))]
    return np.array([[xyz[k], xyz[k + 1]] for k in starts]), [trace["hovertext"][k] for k in starts]


def number(text, key):
    return float(re.search(rf"{key} ([-+0-9.e]+)", text).group(1))


@pytest.fixture(scope="module")
def cylinder_page(tmp_path_factory):
    out = tmp_path_factory.mktemp("html") / "cylinder.html"
    r = run("plot", GRASPS / "cylinder.yaml", "--twist-name", "spin-z", "-o", out)
    assert r.exit_code == 0, r.output
    assert r.stdout == f"{out}\n"
    return out


def test_one_page_with_plotly_inside_the_twists_and_every_path(cylinder_page):
    text = cylinder_page.read_text("utf-8")
    assert "<script src=" not in text and "Plotly.newPlot" in text  # plotly.js is inside: opens offline
    grasp = load_grasps(GRASPS / "cylinder.yaml")[0]
    twists, *paths = read_figures(text)
    assert [len(p["frames"]) for p in paths] == [21] * len(grasp.paths)
    # the dropdown: one button per twist, the one asked for (--twist-name spin-z) active
    menu = twists["layout"]["updatemenus"][0]
    assert [b["label"] for b in menu["buttons"]] == [t.name for t in grasp.twists]
    assert menu["buttons"][menu["active"]]["label"] == "spin-z"
    assert twists["layout"]["scene"]["aspectmode"] == "cube"  # one framed cube for every twist
    names = {t["name"] for t in twists["data"] if t.get("visible", True) is not False}
    for name in (
        "contact",
        "wrist c",
        "surface normal",
        "plane of the contacts",
        "twist axis",
        "contact velocity T(p_i)",
        "off-tangent: Σ axis (line p_j p_k)",
        "off-tangent: Ψ axis (line c p_i)",
    ):
        assert name in names
    # the cylinder's normals all meet its axis: the tangent method is degenerate, and says why
    assert "tangent: degenerate — the three normal lines have rank &lt; 3" in twists["layout"]["title"]["text"]
    assert not any(n.startswith("tangent:") for n in names)


@pytest.mark.parametrize("twist_name", ["tip-over-edge", "slide-x"])
def test_the_screw_axes_are_the_engines_with_its_pitch_and_amplitudes(twist_name):
    grasp = load_grasps(GRASPS / "box-edge.yaml")[0]
    twist = next(t for t in grasp.twists if t.name == twist_name)
    figure = twist_figure(grasp, [twist])
    twist = twist.screw
    off = decompose_off_tangent(grasp.points, grasp.wrist, twist)
    tan = decompose_tangent(grasp.points, grasp.normals, twist)
    checks = [
        ("off-tangent: Σ axis (line p_j p_k)", off.sigma, off.x),
        ("off-tangent: Ψ axis (line c p_i)", off.psi, off.y),
        ("tangent: Θ axis (fixes p_i)", tan.theta, tan.alpha),
        ("tangent: Σ axis (line p_j p_k)", tan.sigma, tan.beta),
    ]
    for name, screws, amplitudes in checks:
        (trace,) = traces(figure, name)
        segments, hover = pieces(trace)
        assert len(segments) == 3
        for (start, end), text, screw, amplitude in zip(segments, hover, screws, amplitudes):
            direction = (end - start) / np.linalg.norm(end - start)
            w = screw[:3] / np.linalg.norm(screw[:3])
            assert abs(direction @ w) == pytest.approx(1, abs=1e-9), name
            # on the axis: the moment about the origin of the screw's line through `start`
            h = pitch(screw)
            assert cross(start, screw[:3]) + h * screw[:3] == pytest.approx(screw[3:], abs=1e-9), name
            assert number(text, "pitch") == pytest.approx(h, abs=1e-4)
            assert number(text, "amplitude") == pytest.approx(amplitude, rel=1e-3, abs=1e-12)


def test_the_contact_velocities_are_the_engines_at_one_scale(cylinder_page):
    grasp = load_grasps(GRASPS / "cylinder.yaml")[0]
    figure = read_figures(cylinder_page.read_text("utf-8"))[0]
    twist = next(t for t in grasp.twists if t.name == "spin-z").screw
    (trace,) = traces(figure, "contact velocity T(p_i)")
    arrows, _ = pieces(trace)
    velocity = contact_velocities(grasp.points, twist)
    assert arrows[:, 0] == pytest.approx(grasp.points, abs=1e-12)
    drawn = arrows[:, 1] - arrows[:, 0]
    scale = np.linalg.norm(drawn, axis=1) / np.linalg.norm(velocity, axis=1)
    assert scale == pytest.approx(np.full(3, scale[0]))
    assert drawn == pytest.approx(scale[0] * velocity, abs=1e-12)
    (contacts,) = traces(figure, "contact")
    assert contacts["text"] == list(grasp.contact_names)


def test_each_twist_button_shows_its_own_traces_only(cylinder_page):
    grasp = load_grasps(GRASPS / "cylinder.yaml")[0]
    figure = read_figures(cylinder_page.read_text("utf-8"))[0]
    buttons = figure["layout"]["updatemenus"][0]["buttons"]
    visible = [[v is not False for v in b["args"][0]["visible"]] for b in buttons]
    # the object is one trace shown with every twist; the rest come in blocks, a twist's each
    (shared,) = [n for n in range(len(figure["data"])) if all(v[n] for v in visible)]
    assert figure["data"][shared]["type"] == "mesh3d"
    others = [n for n in range(len(figure["data"])) if n != shared]
    end = 0
    for k, b in enumerate(buttons):  # each button shows the next block of the others, its twist's
        shown = [j for j, n in enumerate(others) if visible[k][n]]
        assert shown == list(range(end, shown[-1] + 1))
        end = shown[-1] + 1
        assert b["args"][1]["title.text"].startswith(f"cylinder — {grasp.twists[k].name}")
    assert end == len(others)


def test_the_animation_moves_the_contacts_as_follow_does_and_marks_degenerate_samples(cylinder_page):
    grasp = load_grasps(GRASPS / "cylinder.yaml")[0]
    path = next(p for p in grasp.paths if p.name == "turn-x")
    figures = read_figures(cylinder_page.read_text("utf-8"))
    figure = figures[1 + grasp.paths.index(path)]
    times = np.linspace(0, sum(s.duration for s in path.segments), 21)
    moved = follow(grasp.points, grasp.normals, grasp.wrist, path.segments, times).points
    contact = next(n for n, t in enumerate(figure["data"]) if t["name"] == "contact")
    for k, frame in enumerate(figure["frames"]):
        assert len(frame["data"]) == len(figure["data"])  # every frame the same traces
        shown = np.array([frame["data"][contact][c] for c in "xyz"]).T
        assert shown == pytest.approx(moved[k], abs=1e-9)
    labels = [s["label"] for s in figure["layout"]["sliders"][0]["steps"]]
    # turning about x carries the contacts' plane through the wrist at t = pi/2: off-tangent degenerate
    middle = int(np.argmin(np.abs(times - np.pi / 2)))
    assert labels[middle].startswith("✗")
    assert "off-tangent (wrist-coplanar)" in figure["frames"][middle]["layout"]["title"]["text"]
    assert [b["label"] for b in figure["layout"]["updatemenus"][0]["buttons"]] == ["▶ play", "❚❚ pause"]


def test_a_hand_shows_its_fingers_and_joint_axes():
    from grasptwist.hand import finger_states

    grasp = load_grasps(GRASPS / "three-finger-hand.yaml")[0]
    figure = twist_figure(grasp)
    (links,) = traces(figure, "finger (joint to joint to tip)")
    segments, hover = pieces(links)
    states = finger_states(grasp.hand, grasp.joint_positions)
    joints = np.concatenate([s.points for s in states])
    ranges = np.array([figure["layout"]["scene"][f"{c}axis"]["range"] for c in "xyz"])
    centre, half = ranges.mean(axis=1), (ranges[0, 1] - ranges[0, 0]) / 2
    inside = np.all(np.abs(joints - centre) <= half, axis=1)
    ends = segments.reshape(-1, 3)
    for point in joints[inside]:  # every joint in the picture is on its finger's chain
        assert np.min(np.linalg.norm(ends - point, axis=1)) < 1e-9
    # the east finger's knuckle, 2 above its contact, lies beyond the picture: its chain is cut at the edge
    assert np.sum(~inside) == 2 and np.sum(np.isclose(np.max(np.abs(ends - centre), axis=1), half)) == 1
    assert set(hover) == {f"finger {name}" for name in grasp.contact_names}  # named as everywhere: by contact
    (axes,) = traces(figure, "finger joint axis")
    assert np.sum(inside) <= len(pieces(axes)[0]) <= len(grasp.hand.joint_names)


def test_js_beside_writes_it_once_and_a_folder_gets_one_page_per_grasp(tmp_path):
    folder = tmp_path / "in"
    folder.mkdir()
    for name in ("box-edge", "sphere"):
        (folder / f"{name}.yaml").write_text((GRASPS / f"{name}.yaml").read_text())
    r = run("plot", folder, "-o", tmp_path / "out", "--js-beside")
    assert r.exit_code == 0, r.output
    pages = sorted((tmp_path / "out").glob("*.html"))
    assert sorted(r.stdout.splitlines()) == [str(p) for p in pages]
    assert len(pages) == len(load_grasps(folder / "box-edge.yaml")) + len(load_grasps(folder / "sphere.yaml"))
    assert (tmp_path / "out" / "plotly.min.js").stat().st_size > 1_000_000
    for page in pages:
        text = page.read_text("utf-8")
        assert '<script src="plotly.min.js"></script>' in text and len(text) < 200_000


def test_errors(tmp_path, monkeypatch):
    out = tmp_path / "c.html"
    r = run("plot", GRASPS / "cylinder.yaml", "--path", "nowhere", "-o", out)
    assert r.exit_code == 1 and "has no path named 'nowhere' (its paths: 'turn-x'" in r.output
    assert len(read_figures(out.read_text("utf-8"))) == 1  # the twists are drawn all the same
    r = run("plot", GRASPS / "cylinder.yaml", "--js-beside", "-o", tmp_path / "c.png")
    assert r.exit_code == 2 and "--js-beside/--path" in r.output
    monkeypatch.setitem(sys.modules, "plotly", None)  # makes `import plotly` fail
    r = run("plot", GRASPS / "cylinder.yaml", "-o", out)
    assert r.exit_code == 1
    assert r.stderr.endswith(
        "needs plotly: pip install plotly (from a clone of grasptwist: pip install -e '.[html]')\n"
    )


def test_a_name_cannot_end_the_figures_script_element(tmp_path):
    source = (GRASPS / "box-edge.yaml").read_text().replace("name: ", "name: </script><b>x", 1)
    (tmp_path / "g.yaml").write_text(source)
    r = run("plot", tmp_path / "g.yaml", "-o", tmp_path / "g.html")
    assert r.exit_code == 0, r.output
    (figure,) = read_figures((tmp_path / "g.html").read_text("utf-8"))
    assert "</script><b>x" in figure["layout"]["title"]["text"].replace("&lt;", "<").replace("&gt;", ">")


HOSTILE_NAME = "<!--<script>"


def hostile_names_page(tmp_path):
    """A page of box-edge with its thumb named ``<!--<script>``, which once made an HTML parser
    take the rest of the page for script text (nothing drew)."""
    source = (GRASPS / "box-edge.yaml").read_text().replace("name: thumb", f"name: '{HOSTILE_NAME}'", 1)
    (tmp_path / "g.yaml").write_text(source)
    r = run("plot", tmp_path / "g.yaml", "-o", tmp_path / "g.html")
    assert r.exit_code == 0, r.output
    return tmp_path / "g.html"


def test_a_comment_and_script_opening_in_a_name_stay_in_the_figures_json(tmp_path):
    text = hostile_names_page(tmp_path).read_text("utf-8")
    (block,) = re.findall(r'<script type="application/json" id="figure-0-json">(.*?)</script>', text, flags=re.S)
    assert "<" not in block  # no "<!--", "<script" or "</" for the HTML parser to act on
    (figure,) = read_figures(text)
    assert any(HOSTILE_NAME in json.dumps(t, ensure_ascii=False) for t in figure["data"])  # the name as written


@pytest.mark.slow
def test_a_urdf_hands_meshes_are_posed_at_its_joint_positions_touching_the_contacts():
    pytest.importorskip("yourdfpy")
    pytest.importorskip("robot_properties_fingers")
    from grasptwist import place_grasp
    from grasptwist.io.urdf_meshes import hand_meshes
    from grasptwist.plot import grasp_page
    from grasptwist.plot.traces import MESH_NAME

    grasp = place_grasp(load_grasps(GRASPS / "trifinger-cube.yaml")[0])  # its joint positions solved
    meshes = hand_meshes(grasp.hand, grasp.joint_positions, folder=GRASPS)
    (section,) = grasp_page(grasp, meshes=meshes)  # no paths
    sections = [section]
    figure = sections[0][1]
    (mesh,) = [t for t in figure["data"] if t["name"] == MESH_NAME]
    vertices = np.array([mesh[c] for c in "xyz"]).T
    # each fingertip's sphere (radius 10 mm about the tip link's origin) touches its contact
    for contact in grasp.points:
        assert np.min(np.linalg.norm(vertices - contact, axis=1)) < 0.003
    # at the home configuration the tips are elsewhere: the joint positions are what poses them
    home = np.concatenate([v for v, _ in hand_meshes(grasp.hand, None)])
    assert max(np.min(np.linalg.norm(home - c, axis=1)) for c in grasp.points) > 0.01
    assert all(b["args"][0]["visible"][-1] is True for b in figure["layout"]["updatemenus"][0]["buttons"])


def test_a_mesh_outside_the_urdfs_folder_is_refused_and_the_chains_drawn_all_the_same(tmp_path):
    pytest.importorskip("yourdfpy")
    from grasptwist import hand
    from grasptwist.io.urdf_meshes import hand_meshes
    from grasptwist.model import InputError

    folder = TESTS / "corpus" / "urdf"
    toy = hand.load_urdf_hand("mesh-and-xinclude.urdf", ["a_tip", "b_tip"], folder=folder)  # a mesh at /etc/passwd
    with pytest.raises(InputError, match=r"^mesh-and-xinclude.urdf: mesh '/etc/passwd' resolves outside") as caught:
        hand_meshes(toy, folder=folder)
    assert (caught.value.code, caught.value.file) == ("path-outside", "mesh-and-xinclude.urdf")
    assert hand_meshes(hand.load_urdf_hand("hand.urdf", ["a_tip", "b_tip"], folder=folder), folder=folder) == []


def hand_with_mesh(folder, mesh: str):
    """The toy hand of the URDF tests with a visual mesh file ``mesh`` (in ``folder``) on one link."""
    from grasptwist import hand

    source = (TESTS / "corpus" / "urdf" / "hand.urdf").read_text()
    visual = f'<link name="a1"><visual><geometry><mesh filename="{mesh}"/></geometry></visual></link>'
    (folder / "h.urdf").write_text(source.replace('<link name="a1"/>', visual))
    return hand.load_urdf_hand("h.urdf", ["a_tip", "b_tip"], folder=folder)


MALFORMED_MESHES = {
    "bad.ply": b"ply\nformat binary_little_endian 1.0\nelement vertex 100\nproperty float x\nend_header\n\x00\x01",
    "bad.glb": b"glTF\x02\x00\x00\x00\x40\x00\x00\x00\x10\x00\x00\x00JSON{}xx",
    "bad.dae": b"<?xml version='1.0'?><COLLADA><library_geometries/></COLLADA>",
}


@pytest.mark.parametrize("name", MALFORMED_MESHES)
def test_a_malformed_mesh_is_an_input_error_naming_it(tmp_path, name):
    # 0.3: internal error (ValueError, JSONDecodeError, AttributeError from the mesh readers)
    pytest.importorskip("yourdfpy")
    from grasptwist.io.urdf_meshes import hand_meshes
    from grasptwist.model import InputError

    (tmp_path / name).write_bytes(MALFORMED_MESHES[name])
    # a PLY whose header declares more than its body holds is refused before the library parses it (issue 36)
    said, code = (
        (", line 3: the header declares 100 vertex", "invalid-mesh")
        if name == "bad.ply"
        else (": cannot read: ", "read-error")
    )
    with pytest.raises(InputError, match=rf"^h.urdf: mesh '{re.escape(name)}'{said}") as caught:
        hand_meshes(hand_with_mesh(tmp_path, name), folder=tmp_path)
    assert caught.value.code == code


def write_zeros(f, mib: int):
    for _ in range(mib):
        f.write(bytes(1 << 20))


@pytest.mark.parametrize("kind", ["zip", "gz", "bz2"])
def test_a_mesh_archive_that_inflates_past_the_cap_is_refused_before_it_is_inflated(tmp_path, kind, monkeypatch):
    # 0.3 passed a 6 MB zip inflating to 1.2 GB (the file's size was checked): 2.5 GB resident, 7.5 s
    pytest.importorskip("yourdfpy")
    import bz2
    import gzip
    import zipfile

    from grasptwist.io import urdf_meshes
    from grasptwist.model import InputError

    monkeypatch.setattr(urdf_meshes, "MAX_MESH_BYTES", 4 << 20)  # the rule, at a size quick to make
    path = tmp_path / {"zip": "m.zip", "gz": "m.stl.gz", "bz2": "m.stl.bz2"}[kind]
    if kind == "zip":
        with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as zf, zf.open("m.stl", "w") as f:
            write_zeros(f, 5)
    else:
        with (gzip if kind == "gz" else bz2).open(path, "wb") as f:
            write_zeros(f, 5)
    size = path.stat().st_size
    assert size < 50_000
    monkeypatch.setattr("trimesh.load", lambda *a, **k: pytest.fail("the mesh library was given the archive"))
    with pytest.raises(InputError, match=rf"^h.urdf: mesh '{path.name}': decodes to more than 4194304 bytes") as caught:
        urdf_meshes.hand_meshes(hand_with_mesh(tmp_path, path.name), folder=tmp_path)
    assert caught.value.code == "too-large" and caught.value.message.endswith(f"({size:,} compressed)")


def test_an_honest_zipped_mesh_is_read(tmp_path):
    pytest.importorskip("yourdfpy")
    import zipfile

    import trimesh

    from grasptwist.io.urdf_meshes import hand_meshes

    with zipfile.ZipFile(tmp_path / "box.zip", "w", zipfile.ZIP_DEFLATED) as zf:
        zf.writestr("box.stl", trimesh.creation.box().export(file_type="stl"))
    [(vertices, faces)] = hand_meshes(hand_with_mesh(tmp_path, "box.zip"), folder=tmp_path)
    assert vertices.shape == (8, 3) and faces.shape == (12, 3)


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_a_malformed_link_mesh_is_the_grasps_located_error_and_no_page(tmp_path):
    # the finger links are checked against the object and each other (issue 37), which needs their
    # meshes: one the mesh reader refuses (issue 36) is the grasp's error, located, not a crash
    pytest.importorskip("yourdfpy")
    from test_follow_hand import NORMALS, SPIN, _grasp, _turntable

    grasp = _grasp(tmp_path, _turntable([0.9, 0.6, 3.0]), NORMALS, SPIN)
    urdf = (tmp_path / "hand.urdf").read_text()
    visual = '<link name="f0_l0"><visual><geometry><mesh filename="bad.ply"/></geometry></visual></link>'
    (tmp_path / "hand.urdf").write_text(urdf.replace('<link name="f0_l0"/>', visual))
    (tmp_path / "bad.ply").write_bytes(MALFORMED_MESHES["bad.ply"])
    r = run("plot", grasp, "-o", tmp_path / "g.html")
    assert r.exit_code == 1 and "internal error" not in r.output and "Traceback" not in r.output, r.output
    # at the grasp file's urdf key, then the URDF's own file and <mesh> line, then the mesh's fault
    assert "g.yaml:7:9: error: invalid-mesh: hand.urdf: " in r.stderr and "hand.urdf:1: mesh 'bad.ply'" in r.stderr
    assert "mesh 'bad.ply', line 3: the header declares 100 vertex" in r.stderr


def test_a_grasp_without_twists_is_drawn(tmp_path):
    # 0.3: internal error: RecursionError (no velocity arrow to share a scale with between the methods)
    source = (GRASPS / "box-edge.yaml").read_text()
    (tmp_path / "g.yaml").write_text(source[: source.index("twists:")])
    r = run("plot", tmp_path / "g.yaml", "-o", tmp_path / "g.html")
    assert r.exit_code == 0, r.output
    assert len(read_figures((tmp_path / "g.html").read_text("utf-8"))) == 1


def gltf(folder, buffer="m.bin", count=3, size=None):
    """A one-triangle glTF naming its buffer ``buffer`` (written beside it, ``size`` bytes: sparse
    past its 48 bytes of data), its positions accessor declaring ``count`` vertices."""
    import struct

    doc = {
        "asset": {"version": "2.0"},
        "buffers": [{"uri": buffer, "byteLength": 48}],
        "bufferViews": [{"buffer": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 12}],
        "accessors": [
            {
                "bufferView": 0,
                "componentType": 5126,
                "count": count,
                "type": "VEC3",
                "max": [1, 1, 0],
                "min": [0, 0, 0],
            },
            {"bufferView": 1, "componentType": 5125, "count": 3, "type": "SCALAR"},
        ],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "nodes": [{"mesh": 0}],
        "scenes": [{"nodes": [0]}],
        "scene": 0,
    }
    (folder / "m.gltf").write_text(json.dumps(doc))
    if "/" not in buffer:
        with open(folder / buffer, "wb") as f:
            f.write(struct.pack("<9f3I", 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 1, 2))
            f.truncate(size or 48)
    return "m.gltf"


@pytest.mark.parametrize(
    ("kind", "said"),
    [
        ("sparse-3-gib-buffer", "too-large: mesh 'm.gltf': reads 3,221,225,9"),
        ("accessor-of-10-9", "too-large: mesh 'm.gltf': declares accessors of 12,000,000,012 bytes"),
        ("buffer-outside", "path-outside: mesh 'm.gltf': '../m.bin' resolves outside"),
    ],
)
def test_a_gltf_is_measured_with_its_buffers_and_accessors_before_it_is_read(tmp_path, kind, said, monkeypatch):
    # issue 36: a .gltf naming a sparse 3 GB .bin was read whole (3.2 GB resident)
    pytest.importorskip("yourdfpy")
    from grasptwist.io.urdf_meshes import hand_meshes
    from grasptwist.model import InputError

    args = {
        "sparse-3-gib-buffer": {"size": 3 << 30},
        "accessor-of-10-9": {"count": 10**9},
        "buffer-outside": {"buffer": "../m.bin"},
    }[kind]
    name = gltf(tmp_path, **args)
    hand = hand_with_mesh(tmp_path, name)
    monkeypatch.setattr("trimesh.load", lambda *a, **k: pytest.fail("the mesh library was given the glTF"))
    with pytest.raises(InputError) as caught:
        hand_meshes(hand, folder=tmp_path)
    assert f"{caught.value.code}: {caught.value.message}".startswith(said), caught.value
    monkeypatch.undo()
    gltf(tmp_path)  # the same glTF, honest
    [(vertices, faces)] = hand_meshes(hand, folder=tmp_path)
    assert vertices.shape == (3, 3) and faces.tolist() == [[0, 1, 2]]  # posed with its link


def test_a_urdf_s_mesh_gets_an_object_mesh_s_caps_before_the_library_parses_it(tmp_path, monkeypatch):
    # issue 36: one polygon of millions of corners went past 0.5 GB; here just past the triangle cap
    pytest.importorskip("yourdfpy")
    from grasptwist.io.limits import MAX_TRIANGLES
    from grasptwist.io.urdf_meshes import hand_meshes
    from grasptwist.model import InputError

    corners = " ".join(str(1 + k % 4) for k in range(MAX_TRIANGLES + 3))
    (tmp_path / "p.obj").write_text(f"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf {corners}\n")
    hand = hand_with_mesh(tmp_path, "p.obj")
    monkeypatch.setattr("trimesh.load", lambda *a, **k: pytest.fail("the mesh library was given the OBJ"))
    with pytest.raises(
        InputError, match=r"^h.urdf: mesh 'p.obj', line 5: a polygon of more than 200,002 corners"
    ) as caught:
        hand_meshes(hand, folder=tmp_path)
    assert caught.value.code == "too-many-triangles"
