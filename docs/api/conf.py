"""Sphinx configuration of grasptwist's API reference (``docs/api/``), built from the docstrings.

Build: ``python -m sphinx -W -b html docs/api /tmp/api`` (tests/api/test_api.py does, offline).
Sphinx with numpydoc, the numpy docstring standard's own renderer, as numpy, scipy,
scikit-image and pytransform3d do; the alabaster theme ships with Sphinx.
"""

import ast
import importlib
import inspect

from sphinx.pycode import ModuleAnalyzer
from sphinx.util import logging

from grasptwist import __version__

project = "grasptwist"
author = "grasptwist developers"
copyright = "grasptwist developers"
version = release = __version__

extensions = ["sphinx.ext.autodoc", "numpydoc"]
exclude_patterns = ["_build"]
html_theme = "alabaster"

# the reference lists each public name once, by hand, in the order of its topic:
# no autosummary stubs (numpydoc would make a table of every class's members)
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
# names in "Returns" and "Parameters" types are plain text, not cross-references that
# could fail on numpy's own types
numpydoc_xref_param_type = False
autodoc_member_order = "bysource"
autodoc_typehints = "none"  # numpydoc's "Parameters" say the shapes; signatures stay short
add_module_names = False
# every cross-reference in a public docstring lands on a public name of this reference
nitpicky = True


def _defined_in(facade: str, name: str) -> str:
    """The module a public module takes ``name`` from: the core's ``_EXPORTS``, a facade's import."""
    module = importlib.import_module(facade)
    exports = getattr(module, "_EXPORTS", {})
    if name in exports:
        return importlib.util.resolve_name(exports[name], facade)
    for node in ast.parse(inspect.getsource(module)).body:
        if isinstance(node, ast.ImportFrom) and any((a.asname or a.name) == name for a in node.names):
            return importlib.util.resolve_name("." * node.level + (node.module or ""), facade.rpartition(".")[0])
    return facade


def _constant_docs(app, what, name, obj, options, lines):
    """A public constant's text is its ``#:`` comment where it is defined, not its type's docstring
    (autodoc looks for the comment in the public module, which only re-exports it)."""
    if what != "data":
        return
    facade, _, attr = name.rpartition(".")
    source = _defined_in(facade, attr)
    docs = ModuleAnalyzer.for_module(source).find_attr_docs().get(("", attr))
    if not docs:
        logging.getLogger(__name__).warning("%s: no '#:' comment above it in %s", name, source)
    lines[:] = list(docs or [])


def setup(app):
    app.connect("autodoc-process-docstring", _constant_docs)


# a public function or class without a docstring (GL08), or a "Parameters" entry that is no
# parameter (PR02: prose or a doctest read as one), fails the build.  The project's summaries
# start with a formula or a name in code, so numpydoc's capital-letter and period checks stay
# off; constants are documented by their `#:` comments, not by their type's docstring.
numpydoc_validation_checks = {"GL08", "PR02"}
numpydoc_validation_exclude = {r"\.[A-Z][A-Z_]+$"}
