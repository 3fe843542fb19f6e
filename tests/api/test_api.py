"""The public API (docs/api/index.rst, ARCHITECTURE.md "The public API"): the core and one module per
topic, each public name in one place and in the API reference, options keyword-only, moved names
warning, the docs' examples importing only public names, and the reference building from the
docstrings without a warning."""

import ast
import doctest
import importlib
import inspect
import re
import subprocess
import sys

import pytest

import grasptwist as gt
from docs_blocks import ROOT, all_blocks
from layers import LAYERS

API = ROOT / "docs" / "api"

#: The public modules: the core and its topics (the last layer of test_layers.py, less the script).
PUBLIC = [m for m in LAYERS[-1] if m != "grasptwist.__main__"]
TOPICS = {m.rpartition(".")[2]: m for m in PUBLIC[1:]}


def module(name):
    return importlib.import_module(name)


def public_names():
    """``(module, name, object)`` of every name in every public module's ``__all__``."""
    return [(m, n, getattr(module(m), n)) for m in PUBLIC for n in module(m).__all__]


def test_the_core_has_a_module_per_topic():
    assert sorted(TOPICS) == ["dask", "forces", "hand", "objects", "path", "pictures", "screws"]
    assert sorted(TOPICS) == sorted(n for n in gt.__all__ if inspect.ismodule(getattr(gt, n)))
    for topic, name in TOPICS.items():
        assert getattr(gt, topic) is module(name)


def documented():
    """``module.name`` of every ``auto...`` directive of docs/api/*.rst, the modules of ``automodule``."""
    names = set()
    for page in sorted(API.glob("*.rst")):
        current = None
        for kind, target in re.findall(r"^\.\. (currentmodule|auto\w+):: ([\w.]+)", page.read_text(), re.M):
            if kind in ("currentmodule", "automodule"):
                current = target
            if kind != "currentmodule":
                names.add(target if kind == "automodule" or "." in target else f"{current}.{target}")
    return names


def test_every_public_name_is_in_the_api_reference_and_nothing_else_is():
    want = {m if inspect.ismodule(o) else f"{m}.{n}" for m, n, o in public_names()} | set(PUBLIC)
    have = documented()
    assert sorted(want - have) == [], "public but not in docs/api/*.rst"
    assert sorted(have - want) == [], "in docs/api/*.rst but not in a public module's __all__"


#: Names in two homes on purpose, by the core's rule (``_REEXPORTED``): issue 29 names the grip in the
#: core, a control loop's one call, as well as in its topic.
TWO_HOMES = [[f"grasptwist.{n}", f"grasptwist.{t}.{n}"] for n, t in gt._REEXPORTED.items()]


def test_each_public_function_and_class_has_one_home():
    homes = {}
    for m, n, o in public_names():
        if inspect.isfunction(o) or inspect.isclass(o):
            homes.setdefault(id(o), []).append(f"{m}.{n}")
    assert sorted(h for h in homes.values() if len(h) > 1) == sorted(TWO_HOMES)


def test_dir_of_the_core_shows_its_public_names_only():
    import grasptwist.cli  # noqa: F401 (binds the internal subpackages as the core's attributes)

    assert dir(gt) == sorted([*gt.__all__, "__version__"])
    assert "import_module" not in dir(gt) and "engine" not in dir(gt)
    with pytest.raises(AttributeError, match="module 'grasptwist' has no attribute 'nothing'"):
        gt.nothing  # noqa: B018


def home(place: str):
    """The module a dotted place under ``grasptwist`` is in, and its name there."""
    where, _, name = place.rpartition(".")
    return module(f"grasptwist.{where}" if where else "grasptwist"), name


@pytest.mark.parametrize("old", sorted(gt._MOVED))
def test_a_name_moved_or_dropped_warns_and_is_its_new_home(old):
    new, since, advice = gt._MOVED[old]
    words = f"use grasptwist\\.{re.escape(new)}" if advice is None else re.escape(f"it is internal now ({advice})")
    at, name = home(old)
    with pytest.warns(
        DeprecationWarning, match=rf"^grasptwist\.{re.escape(old)} is deprecated since {since}: {words}$"
    ):
        value = getattr(at, name)
    there, new_name = home(new)
    assert value is getattr(there, new_name)
    assert name not in at.__all__ and name not in dir(at)
    # a moved name's new place is public, a dropped one's is not
    assert (advice is None) == (there.__name__ in PUBLIC and new_name in there.__all__)


def test_a_topic_s_unknown_name_is_an_attribute_error():
    with pytest.raises(AttributeError, match="module 'grasptwist.hand' has no attribute 'nothing'"):
        gt.hand.nothing  # noqa: B018


def test_a_name_is_re_exported_at_the_top_level_only_by_the_rule():
    # ARCHITECTURE.md, "The public API": a topic's name in the core too only when the core lists it (a whole
    # job's one call and its types); it is the topic's object, and the core names the topic as its home
    for name, topic in gt._REEXPORTED.items():
        assert name in gt.__all__ and name in module(TOPICS[topic]).__all__
        assert getattr(gt, name) is getattr(module(TOPICS[topic]), name)
    topics = {id(getattr(module(m), n)) for m in PUBLIC[1:] for n in module(m).__all__}
    twice = {n for n in gt.__all__ if not inspect.ismodule(getattr(gt, n)) and id(getattr(gt, n)) in topics}
    assert twice == set(gt._REEXPORTED)  # not gt.Status, a name of its own beside gt.forces.Status


def test_the_0_1_loader_path_warns_and_gives_the_core_loader():
    sys.modules.pop("grasptwist.io.grasp_file", None)
    with pytest.warns(
        DeprecationWarning, match=r"grasptwist\.io\.grasp_file is deprecated since 0\.4: .*gt\.load_grasps"
    ):
        shim = importlib.import_module("grasptwist.io.grasp_file")
    assert shim.load_grasps is gt.load_grasps and shim.GraspFileError is gt.InputError


def test_the_version_is_the_one_the_deprecations_and_the_package_say():
    import tomllib

    from typer.testing import CliRunner

    from grasptwist.cli import app

    with pytest.warns(DeprecationWarning) as said:
        gt.grasp_map  # noqa: B018
    since = re.search(r"deprecated since (\d+)\.(\d+)", str(said[0].message)).groups()
    version = tuple(int(n) for n in gt.__version__.split("."))
    assert version[:2] >= tuple(map(int, since))  # a release that deprecates is at least that release
    pyproject = tomllib.loads((ROOT / "pyproject.toml").read_text())
    assert pyproject["project"]["version"] == gt.__version__ == "0.6.0"
    r = CliRunner().invoke(app, ["--version"])
    assert (r.exit_code, r.stdout) == (0, "grasptwist 0.6.0\n")


#: Parameters with a default that are data, not options: they may be given by position.
DATA = {
    "grasptwist.status_message": {"culprit", "names"},
    "grasptwist.forces.status_message": {"culprit", "names"},
    "grasptwist.prepare": {"wrist"},
    "grasptwist.grasp_table": {"wrist", "twist", "names"},
    "grasptwist.forces.force_closure": {"friction"},
    "grasptwist.forces.hold_wrench": {"rotation", "position"},  # the object's pose
    "grasptwist.forces.cannot_hold": {"times"},
    "grasptwist.hand.finger_states": {"positions"},
    "grasptwist.hand.place": {"positions"},
    "grasptwist.hand.home_tips": {"points"},
    "grasptwist.hand.joint_screw": {"prismatic"},  # per joint, an array like the axes
    "grasptwist.path.degeneracies": {"times"},
    "grasptwist.screws.exp": {"t"},
    "grasptwist.pictures.scene": {"twist"},
    "grasptwist.pictures.grasp_scene": {"twist"},
    "grasptwist.pictures.plot_grasp": {"twist"},
    "grasptwist.pictures.twist_figure": {"twists"},
    "grasptwist.pictures.image_name": {"twist_name"},
    "grasptwist.dask.resolve_dataframe": {"twists"},
    "grasptwist.synthesize": {"friction"},  # a Grasp brings its own
}


def test_options_are_keyword_only():
    positional = []
    for m, n, o in public_names():
        if not inspect.isfunction(o):
            continue
        for p in inspect.signature(o).parameters.values():
            if p.default is not p.empty and p.kind != p.KEYWORD_ONLY and p.name not in DATA.get(f"{m}.{n}", ()):
                positional.append(f"{m}.{n}({p.name}=...)")
    assert positional == []


def test_the_data_parameters_above_are_positional_parameters_of_public_functions():
    # an entry goes when its parameter becomes keyword-only (as grip's safety with issue 29)
    functions = {f"{m}.{n}": o for m, n, o in public_names() if inspect.isfunction(o)}
    kinds = {k: {p.name: p.kind for p in inspect.signature(functions[k]).parameters.values()} for k in DATA}
    stale = [
        f"{k}({p})" for k, ps in DATA.items() for p in ps if kinds[k].get(p) != inspect.Parameter.POSITIONAL_OR_KEYWORD
    ]
    assert stale == []


def code_of(block):
    """A ``python`` block's code, or a ``pycon`` session's input lines."""
    if block.lang == "python":
        return block.text
    return "".join(e.source for e in doctest.DocTestParser().get_examples(block.text))


def grasptwist_names(code):
    """``(line, what)`` of every import of grasptwist and attribute of a public module in ``code``."""
    tree = ast.parse(code)
    bound = {}  # local name -> public module
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for a in node.names:
                if a.name.split(".")[0] == "grasptwist":
                    found.append((node.lineno, a.name))
                    bound[a.asname or a.name] = a.name
        elif isinstance(node, ast.ImportFrom) and (node.module or "").split(".")[0] == "grasptwist":
            for a in node.names:
                found.append((node.lineno, f"{node.module}.{a.name}"))
                if f"{node.module}.{a.name}" in PUBLIC:
                    bound[a.asname or a.name] = f"{node.module}.{a.name}"
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute):
            chain = [node.attr]
            value = node.value
            while isinstance(value, ast.Attribute):
                chain.insert(0, value.attr)
                value = value.value
            if isinstance(value, ast.Name) and value.id in bound:
                found.append((node.lineno, ".".join([bound[value.id], *chain])))
    return found


def is_public(dotted):
    """Whether ``grasptwist.a.b...`` names a public module, a name in one's ``__all__``, or an
    attribute of such a name (``gt.Status.OK``)."""
    parts = dotted.split(".")
    for k in range(len(parts), 0, -1):
        head = ".".join(parts[:k])
        if head in PUBLIC:
            return k == len(parts) or parts[k] in module(head).__all__
    return False


def test_an_import_of_an_internal_module_in_a_docs_example_is_found():
    code = (
        "import grasptwist as gt\nfrom grasptwist.engine.ik import hand_ik\nfrom grasptwist import forces\n"
        "gt.force_closure\nforces.force_closure\n"
    )
    assert [w for _, w in grasptwist_names(code) if not is_public(w)] == [
        "grasptwist.engine.ik.hand_ik",
        "grasptwist.force_closure",
    ]


def test_the_docs_examples_use_only_public_names():
    internal = []
    for block in all_blocks():
        if block.lang in ("python", "pycon"):
            internal += [
                f"{block.where}+{line - 1}: {what}"
                for line, what in grasptwist_names(code_of(block))
                if not is_public(what)
            ]
    assert internal == []


def test_the_public_docstrings_examples_use_only_public_names():
    # the reference shows them: a reader copies `from grasptwist.hand import Hand`, not the layer it lives in
    internal = []
    docs = [(m, module(m).__doc__) for m in PUBLIC]
    for m, n, o in public_names():
        if not inspect.ismodule(o):
            docs += [(f"{m}.{n}", inspect.getdoc(x)) for x in [o, *(members(o) if inspect.isclass(o) else [])]]
    for where, doc in docs:
        code = "".join(e.source for e in doctest.DocTestParser().get_examples(doc or ""))
        internal += [f"{where}: {what}" for _, what in grasptwist_names(code) if not is_public(what)]
    assert internal == []


def members(obj):
    """A public class's own public methods and properties (what ``:members:`` shows)."""
    return [
        v for k, v in vars(obj).items() if not k.startswith("_") and (inspect.isfunction(v) or isinstance(v, property))
    ]


def test_a_doctest_after_a_docstring_section_is_under_examples():
    # numpydoc reads a doctest below "Returns" or "Raises" as part of that section
    section = re.compile(r"^(Parameters|Returns|Raises|Attributes)\n-+$", re.M)
    strays = []
    for m, n, o in public_names():
        for thing in [o, *(members(o) if inspect.isclass(o) else [])]:
            doc = inspect.getdoc(thing) or ""
            if section.search(doc) and ">>>" in doc and not re.search(r"^Examples\n-+$", doc, re.M):
                strays.append(f"{m}.{n}" + ("" if thing is o else f" ({getattr(thing, '__name__', 'property')})"))
    assert strays == []


# --- the reference, built ----------------------------------------------------------------------


def documented_names():
    """``module.name`` of each ``.. autofunction::``/``autoclass``/... in the reference's pages, under its
    ``.. currentmodule::``, unless ``:no-index:`` (what the build gives an anchor to)."""
    directive = re.compile(r"^\.\. (currentmodule|auto\w+):: *([\w.]+).*\n((?:   .*\n)*)", re.M)
    found = set()
    for page in sorted(API.glob("*.rst")):
        current = None
        for kind, name, options in directive.findall(page.read_text("utf-8")):
            if kind == "currentmodule":
                current = name
            elif kind != "automodule" and ":no-index:" not in options:
                found.add(name if name.startswith("grasptwist.") else f"{current}.{name}")
    return found


def test_every_public_name_has_a_directive_in_the_reference():
    # the fast half of the build below (slow): a name added to an __all__ and to no page fails here
    documented = documented_names()
    want = {f"{m}.{n}" for m, n, o in public_names() if not inspect.ismodule(o)}
    second = {core for core, _ in TWO_HOMES}  # shown on the core page without an anchor of their own
    assert sorted(want - documented) == sorted(second)
    assert {topic for _, topic in TWO_HOMES} <= documented
    assert sorted(n for n in documented - want if not is_public(n)) == []


@pytest.mark.slow  # the Sphinx build, 4-6 s of CPU: docs/reference/development.md, Test time
def test_the_api_reference_builds_without_warnings_and_has_every_public_name(tmp_path):
    pytest.importorskip("sphinx", reason="the docs extra builds the API reference: pip install -e '.[docs]'")
    pytest.importorskip("numpydoc", reason="the docs extra builds the API reference: pip install -e '.[docs]'")
    out = tmp_path / "html"
    build = [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-j", "1", "-b", "html", str(API), str(out)]
    p = subprocess.run(build, capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stderr
    assert p.stderr == ""
    anchors = set()
    for page in out.glob("*.html"):
        anchors |= set(re.findall(r'<dt class="sig sig-object py" id="([\w.]+)"', page.read_text("utf-8")))
    want = {f"{m}.{n}" for m, n, o in public_names() if not inspect.ismodule(o)}
    second = {core for core, _ in TWO_HOMES}  # shown on the core page without an anchor of their own
    assert sorted(want - anchors) == sorted(second)
    assert {topic for _, topic in TWO_HOMES} <= anchors


@pytest.mark.slow  # over a second: docs/reference/development.md, Test time
def test_a_bad_docstring_shows_on_the_builds_stderr(tmp_path):
    """The build test can fail: numpydoc says of an unknown section on stderr, which the build test
    requires empty (it is a Python warning, which Sphinx's -W does not turn into an error)."""
    pytest.importorskip("sphinx", reason="the docs extra builds the API reference: pip install -e '.[docs]'")
    pytest.importorskip("numpydoc", reason="the docs extra builds the API reference: pip install -e '.[docs]'")
    (tmp_path / "bad.py").write_text('def f(x):\n    """Do.\n\n    Parametres\n    ----------\n    x : int\n    """\n')
    (tmp_path / "src").mkdir()
    (tmp_path / "src" / "conf.py").write_text('extensions = ["sphinx.ext.autodoc", "numpydoc"]\n')
    (tmp_path / "src" / "index.rst").write_text("Bad\n===\n\n.. autofunction:: bad.f\n")
    build = [sys.executable, "-m", "sphinx", "-W", "-q", "-b", "html", str(tmp_path / "src"), str(tmp_path / "out")]
    p = subprocess.run(build, capture_output=True, text=True, timeout=60, env={"PYTHONPATH": str(tmp_path), "PATH": ""})
    assert "Unknown section Parametres" in p.stderr
