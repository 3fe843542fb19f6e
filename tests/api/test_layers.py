"""Imports go one way, down the layers of ARCHITECTURE.md, and never in a circle.

An ast walk over src/grasptwist: every ``import`` and ``from ... import``,
at module level or inside a function (a deferred import may keep start-up
fast or an optional dependency optional; it never hides a circle).
"""

import ast
import functools
import importlib.util
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from layers import LAYERS
from places import ROOT

SRC = ROOT / "src"
PACKAGE = SRC / "grasptwist"

#: Beyond the layers: pictures are drawn from the engine's geometry only; reading
#: files and writing records is the command line's (issue 22).  So are MuJoCo's scenes (issue 38).
FORBIDDEN = {
    "grasptwist.plot": ("grasptwist.io", "grasptwist.output", "grasptwist.results", "grasptwist.run"),
    "grasptwist.sim": ("grasptwist.io", "grasptwist.output", "grasptwist.results", "grasptwist.run"),
}

#: Facades only re-export: the public modules but the core, ``dask`` (which holds its own code) and the script.
FACADES = tuple(m for m in LAYERS[-1] if m not in ("grasptwist", "grasptwist.dask", "grasptwist.__main__"))


def module_name(path: Path) -> str:
    parts = path.relative_to(SRC).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


MODULES = {module_name(p): p for p in sorted(PACKAGE.rglob("*.py"))}


@functools.cache
def tree(name: str) -> ast.Module:
    """The module's source parsed, once per process: three parametrised tests read each module
    (its imports, its ``__all__``, its branches on a command's name), and parsing was most of their time."""
    path = MODULES[name]
    return ast.parse(path.read_text(), str(path))


@functools.cache
def nodes(name: str) -> tuple[ast.AST, ...]:
    """Every node of the module's tree (``ast.walk``), walked once for the imports and the branches."""
    return tuple(ast.walk(tree(name)))


@functools.cache
def imports(name: str) -> set[str]:
    """The package's modules ``name`` imports anywhere in its code (parsed once per process: a
    module's test parses its own file, not the whole package's)."""
    path = MODULES[name]
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = set()
    for node in nodes(name):
        if isinstance(node, ast.Import):
            found.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module
            # `from pkg import module` imports the module; `from module import name`, the module
            found.update(f"{target}.{a.name}" if f"{target}.{a.name}" in MODULES else target for a in node.names)
    return {m for m in found if m in MODULES and m != name}


@functools.cache
def graph() -> dict[str, set[str]]:
    """Each module's imports of the package's modules, parsed when a test first asks: at
    collection, every test worker would pay its 0.4 s (docs/reference/development.md, Test time)."""
    return {name: imports(name) for name in MODULES}


def group(name: str) -> tuple[int, str]:
    """The layer and group of a module: its longest matching group."""
    matches = [
        (len(g), k, g)
        for k, layer in enumerate(LAYERS)
        for g in layer
        if name == g or (name.startswith(g + ".") and g != "grasptwist")  # the package's own __init__: itself only
    ]
    assert matches, f"{name} is in no layer: add it to LAYERS"
    _, k, g = max(matches)
    return k, g


def test_the_walk_sees_deferred_and_relative_imports():
    # a deferred import inside a function, a relative `from . import module`, an absolute one
    assert "grasptwist.run.signals" in imports("grasptwist.__main__")
    assert "grasptwist.cli" in imports("grasptwist.__main__")
    assert "grasptwist.engine.kernels" in imports("grasptwist.engine.decompose")
    assert "grasptwist.output.parquet_writer" in imports("grasptwist.output.formats")
    assert group("grasptwist.engine.hands") == (1, "grasptwist.engine")
    assert group("grasptwist.hand") == (7, "grasptwist.hand")


@pytest.mark.parametrize("name", sorted(MODULES))
def test_imports_go_down_the_layers(name):
    layer, own = group(name)
    upward = []
    for target in sorted(imports(name)):
        their_layer, theirs = group(target)
        if theirs == own:
            continue
        if their_layer >= layer or theirs in FORBIDDEN.get(own, ()):
            upward.append(f"{target} ({theirs}, layer {their_layer})")
    assert not upward, f"{name} ({own}, layer {layer}) imports {', '.join(upward)}"


def test_no_import_circles():
    circles = []
    state = {}  # name -> 1 on the current path, 2 done

    def visit(name, path):
        state[name] = 1
        for target in sorted(graph()[name]):
            if state.get(target) == 1:
                circles.append(" -> ".join(path[path.index(target) :] + [target]))
            elif target not in state:
                visit(target, path + [target])
        state[name] = 2

    for name in sorted(MODULES):
        if name not in state:
            visit(name, [name])
    assert not circles, "import circles:\n" + "\n".join(circles)


def test_the_loader_only_reads():
    # a hand is put on its contacts (inverse kinematics) by the run layer, not while parsing (issue 28)
    solving = {"grasptwist.engine.ik", "grasptwist.engine.tracking"}
    assert not {
        name: imported & solving
        for name, imported in graph().items()
        if name.startswith("grasptwist.io") and imported & solving
    }


@pytest.mark.parametrize("name", FACADES)
def test_facades_only_re_export(name):
    for node in tree(name).body:
        docstring = isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant)
        targets = [t.id for t in node.targets if isinstance(t, ast.Name)] if isinstance(node, ast.Assign) else []
        # __all__, and __getattr__: its moved names' deprecated aliases (grasptwist/_moved.py)
        hook = targets == ["__getattr__"] and ast.unparse(node.value) == "topic_getattr(__name__)"
        assert docstring or targets == ["__all__"] or hook or isinstance(node, ast.ImportFrom), (
            f"{name}:{node.lineno}: not a re-export"
        )


@pytest.mark.parametrize("name", FACADES)
def test_a_topic_imports_nothing_that_runs_the_command_line(name):
    # ARCHITECTURE.md, "The public API": what runs run/ (gt.place_grasp, gt.synthesize, ...) is the core's (issue 39)
    assert not {m for m in imports(name) if m.startswith(("grasptwist.run", "grasptwist.cli"))}


@pytest.mark.parametrize(
    "name", [n for n, p in MODULES.items() if p.name != "__init__.py" and not p.name.startswith("_")]
)
def test_every_module_says_what_is_public(name):
    # the public API is grasptwist's _EXPORTS; each module marks its own public names
    assert any(
        isinstance(node, ast.Assign) and any(isinstance(t, ast.Name) and t.id == "__all__" for t in node.targets)
        for node in tree(name).body
    ), f"{name} has no __all__"


#: Where commands and their families are named: the registry (issue 28).
REGISTRY = "grasptwist.run.families"


def _command_names() -> set[str]:
    """The registry's command names, read from its source (no import: this file only reads)."""
    names = set()
    for node in nodes(REGISTRY):
        if isinstance(node, ast.Call) and getattr(node.func, "id", None) == "Command":
            first = node.args[0] if node.args else next((k.value for k in node.keywords if k.arg == "name"), None)
            if isinstance(first, ast.Constant) and isinstance(first.value, str):
                names.add(first.value)
    return names


COMMAND_NAMES = _command_names()


def branches_on_a_name(walked) -> list[tuple[int, str]]:
    """``(line, text)`` of each comparison with a command's name (``kind == "forces"``,
    ``job.kind != "resolve"``, ``kind in ("basis", "check")``) and each mapping keyed by commands
    (``{"resolve": TableWriter, "basis": ...}``; one such key is a name that is also a function's),
    among ``walked``, the nodes of a tree (``ast.walk``'s)."""

    def named(node) -> bool:
        if isinstance(node, ast.Constant):
            return node.value in COMMAND_NAMES
        if isinstance(node, ast.Tuple | ast.List | ast.Set):
            return any(named(e) for e in node.elts)
        return False

    found = []
    for node in walked:
        if isinstance(node, ast.Compare) and any(named(c) for c in (node.left, *node.comparators)):
            found.append((node.lineno, ast.unparse(node)))
        elif isinstance(node, ast.Dict) and sum(k is not None and named(k) for k in node.keys) > 1:
            found.append((node.lineno, ast.unparse(node)[:60]))
    return found


def test_the_walk_finds_branches_on_a_command_name():
    assert {"resolve", "basis", "check", "follow", "forces"} <= COMMAND_NAMES
    code = (
        'if job.kind == "forces": pass\nx = kind != "resolve"\ny = k in ("basis", "x")\nw = {"check": 1, "basis": 2}\n'
    )
    assert [line for line, _ in branches_on_a_name(ast.walk(ast.parse(code)))] == [1, 2, 3, 4]
    assert not branches_on_a_name(
        ast.walk(ast.parse('f.kind == "fingers"\nCOMMANDS["forces"].formats\n{"resolve": ".api"}'))
    )


@pytest.mark.parametrize("name", sorted(n for n in MODULES if n != REGISTRY and group(n)[0] < len(LAYERS) - 1))
def test_no_layer_branches_on_a_command_name(name):
    # the public modules (the last group) name API functions, some called like a command (gt.resolve)
    # every layer loops over the registry (run/families.py); looking a command up there is fine;
    found = branches_on_a_name(nodes(name))
    assert not found, f"{name} branches on a command's name: " + "; ".join(f"line {n}: {t}" for n, t in found)


# --------------------------------------------------------------------------
# Issue 26.4: start-up pays for what the command and format in hand use (bench/startup.py times it)

#: Modules a one-file JSON ``resolve`` never needs: the force side, the hand's kinematics and
#: inverse kinematics, URDF reading, tables (rich) and pictures; on a primitive object, the
#: meshes' geometry and their winding-number solid; CSV rows; data sets; the hand's and the
#: environment's types, and the other families' options.
NOT_FOR_JSON_RESOLVE = (
    "grasptwist.engine.objects.mesh",
    "grasptwist.engine.objects.solid",
    "grasptwist.output.csv_rows",
    "csv",
    "grasptwist.io.dataset",
    "grasptwist.model.hands",
    "grasptwist.model.environment",
    "grasptwist.run.family_options",
    "grasptwist.engine.forces",
    "grasptwist.run.forces",
    "grasptwist.output.force_records",
    "grasptwist.engine.ik",
    "grasptwist.engine.kinematics",
    "grasptwist.engine.hands",
    "grasptwist.engine.path",
    "grasptwist.io.urdf",
    "grasptwist.output.table",
    "grasptwist.output.follow_table",
    "grasptwist.plot",
    "grasptwist.sim",
    "mujoco",
    "rich",
    "matplotlib",
    "scipy",
)

#: Runs ``grasptwist ARGS`` as the script does, one command line after another in one
#: process, printing after each the modules loaded so far (JSON, on stderr).
_IMPORTED = """
import json, sys
from grasptwist.__main__ import main
for args in json.loads(sys.argv[1]):
    sys.argv = ["grasptwist", *args]
    try:
        main()
    except SystemExit:
        pass
    sys.stderr.write("\\nMODULES " + json.dumps(sorted(sys.modules)) + "\\n")
"""


def _loaded(*command_lines) -> list[set[str]]:
    root = ROOT
    proc = subprocess.run(
        [sys.executable, "-c", _IMPORTED, json.dumps(command_lines)],
        capture_output=True, text=True, cwd=root, timeout=60, env={**os.environ, "NO_COLOR": "1"},
    )  # fmt: skip
    found = [set(json.loads(line[8:])) for line in proc.stderr.splitlines() if line.startswith("MODULES ")]
    assert len(found) == len(command_lines), proc.stderr
    return found


#: The most dataclasses the modules of a JSON resolve define.  Python compiles a dataclass's
#: methods from source as its module loads (0.5 ms each: 38 of them were a tenth of the start-up
#: over the import floor, bench/startup.py), so the registries that need none of it (columns,
#: formats, sections, families, output settings, tuning) are NamedTuples, a path's checks
#: (engine.segments) load without the path's engine and its results, and the hand's, the
#: environment's and the other families' options types live in modules of their own.
DATACLASSES_FOR_JSON_RESOLVE = 17


def _dataclasses(modules: set[str]) -> list[str]:
    """The dataclasses defined (not imported) by those of ``modules`` that are grasptwist's."""
    import dataclasses
    import importlib

    return sorted(
        f"{name}.{k}"
        for name in modules
        if name == "grasptwist" or name.startswith("grasptwist.")
        for k, v in vars(importlib.import_module(name)).items()
        if isinstance(v, type) and dataclasses.is_dataclass(v) and v.__module__ == name
    )


def _among(modules: set[str], names) -> list[str]:
    return sorted(m for m in modules for n in names if m == n or m.startswith(n + "."))


def test_a_json_resolve_of_one_file_imports_no_force_hand_table_or_plot_module():
    json_run, forces_run, table_run, mesh_run = _loaded(
        ["resolve", "grasps/polyhedron.yaml", "--format", "json"],
        ["forces", "grasps/sphere.yaml", "--format", "json"],
        ["resolve", "grasps/three-finger-hand.yaml"],
        ["resolve", "grasps/bottle.yaml", "--format", "csv"],
    )
    assert "grasptwist.engine.decompose" in json_run and "orjson" in json_run  # it did run
    assert _among(json_run, NOT_FOR_JSON_RESOLVE) == []
    assert len(_dataclasses(json_run)) <= DATACLASSES_FOR_JSON_RESOLVE, _dataclasses(json_run)
    # the names are right: the commands that need these modules load them
    assert {"grasptwist.engine.forces.grip", "grasptwist.run.forces"} <= forces_run
    assert {"grasptwist.output.table", "rich", "grasptwist.engine.kinematics"} <= table_run
    assert {"grasptwist.engine.objects.solid", "grasptwist.output.csv_rows", "csv"} <= mesh_run


@pytest.mark.skipif(
    any(importlib.util.find_spec(m) is None for m in ("yourdfpy", "robot_properties_fingers")),
    reason="needs the TriFinger URDF",
)
def test_a_urdf_hand_is_read_and_searched_without_importing_trimesh_or_yourdfpy():
    # yourdfpy imports trimesh (scipy.optimize, networkx, ...): 0.43 s of issue 37's 4 s synthesis
    search = ["--friction", "0.8", "--mass", "0.1", "-n", "1", "--candidates", "20", "--perturbations", "1"]
    resolve_run, search_run = _loaded(
        ["resolve", "grasps/trifinger-cube.yaml", "-f", "json"],
        ["synthesize", "grasps/trifinger-cube.yaml", *search, "-f", "jsonl", "-q"],
    )
    assert "grasptwist.io.urdf_model" in resolve_run and "grasptwist.engine.collision" in search_run  # they did run
    assert _among(search_run, ("trimesh", "yourdfpy")) == []


#: Runs a JSON resolve as the script does, counting the cyclic collector's passes from the
#: command's start on, and says on stderr whether the collector is on and how much is frozen.
_COLLECTED = """
import functools, gc, sys
from grasptwist.__main__ import main
from grasptwist.cli import resolve

passes = []
body = resolve.resolve
@functools.wraps(body)
def counting(*args, **kwargs):  # the command's own work, the collector's passes during it
    gc.callbacks.append(lambda phase, info: phase == "start" and passes.append(info["generation"]))
    return body(*args, **kwargs)
resolve.resolve = counting
sys.argv = ["grasptwist", "resolve", "grasps/polyhedron.yaml", "--format", "json"]
try:
    main()
except SystemExit:
    pass
sys.stderr.write(f"\\nGC {gc.isenabled()} {gc.get_freeze_count()} {len(passes)}\\n")
"""


def test_the_script_freezes_the_start_up_s_objects_and_collects_the_run_s():
    proc = subprocess.run(
        [sys.executable, "-c", _COLLECTED], capture_output=True, text=True, cwd=ROOT, timeout=60
    )  # fmt: skip
    (line,) = [line for line in proc.stderr.splitlines() if line.startswith("GC ")]
    enabled, frozen, passes = line.split()[1:]
    # numpy's, typer's and grasptwist's tracked objects (about 29,000) are never gone through again; the
    # run's own are: the collector is on while the command works
    assert enabled == "True" and int(frozen) > 10_000 and int(passes) > 0, proc.stderr


def test_a_command_run_from_python_leaves_the_callers_collector_alone():
    """Only the script's start freezes: a notebook or a test calling grasptwist.cli.main keeps its heap in sight."""
    script = _COLLECTED.replace("from grasptwist.__main__ import main", "from grasptwist.cli import main")
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, cwd=ROOT, timeout=60)
    (line,) = [line for line in proc.stderr.splitlines() if line.startswith("GC ")]
    assert line.split()[1:3] == ["True", "0"], proc.stderr
