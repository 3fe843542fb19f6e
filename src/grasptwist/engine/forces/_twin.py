r"""Twins of lane-form functions: the compiled grip's source run by numpy over all rows at once, and as
Python floats on one row.

A function in *lane form* keeps its rows in the last axis of its arrays (the lanes) and goes
through them in loops ``for ln in range(width):`` whose bodies are straight-line arithmetic on
the elements ``[..., ln]`` (numba compiles such a loop into vector code).  Its twin is the same
function with every such loop replaced by its body and ``ln`` by a full slice, so each statement
runs on all the rows at once, as numpy's batched code does.  A loop ``for m in every(K):``
(``every`` is ``range``, for a loop whose iterations are independent: each cone's or each
component's own) likewise runs over the whole axis at once, ``m`` a full slice too, so a
statement there is one numpy call on ``(K, rows)`` (or ``(K, k, rows)``); a loop over
``range`` stays a loop (a sum, a maximum).  Three rewrites keep a
scalar's meaning on whole rows:

- ``a if c else b`` becomes ``np.where(c, a, b)`` (both sides are computed, as a branch-free
  lane does);
- ``t op= e`` on a bare name becomes ``t = t op e`` (a scalar is rebound, never an array it
  was read from written through);
- ``ln`` anywhere (an index, or an argument of a helper that takes one lane) becomes
  ``slice(None)``.

A lane-form function has no ``if``, ``while``, ``and``, ``or`` or ``not`` (they decide one value,
not a row's each): logic is ``&``, ``|``, ``np.logical_not``, choices ``a if c else b``, and
:func:`twins` refuses the rest.  Functions called by a twin are the twins of the same set.

The *float twin* (:func:`floats`) is the same source for one row in Python floats, where numpy's
cost per call (a microsecond, on arrays of three numbers) would be all there is: the lane loops
run once, ``X[i, j, ln]`` becomes ``X[i][j]`` (the arrays nested lists of floats, the lane axis
gone; a lone lane index ``X[ln]`` becomes ``X[0]``, a list of one number, so a helper can still
write it), ``every`` becomes ``range``, and numpy's calls on one number their ``math`` or builtin
equivalents (:data:`SCALAR`).  :mod:`~grasptwist.engine.forces.one` runs it.

>>> import numpy as np
>>> def clipped(x, out, width):
...     for ln in range(width):
...         t = x[ln]
...         t *= 2
...         out[ln] = t if t < 3 else 3.0
>>> x, out = np.array([0.5, 1.0, 4.0]), np.zeros(3)
>>> twins([clipped])["clipped"](x, out, 3)
>>> out.tolist(), x.tolist()
([1.0, 2.0, 3.0], [0.5, 1.0, 4.0])
"""

from __future__ import annotations

import ast
import inspect
import math
import textwrap

import numpy as np

__all__ = ["twins", "floats", "float_workspace", "LANE", "EVERY", "SCALAR"]

#: The name of a lane loop's variable: ``for LANE in range(width):``.
LANE = "ln"

#: The name of the ``range`` whose loops run at once: ``for m in EVERY(K):`` (independent iterations).
EVERY = "every"

_REFUSED = (ast.If, ast.While, ast.BoolOp, ast.Break, ast.Continue)


class _Twin(ast.NodeTransformer):
    """The rewrites of the module's docstring, on one function's tree."""

    def __init__(self):
        self.sliced = set()  # the loop variables that stand for all their values at once

    def visit_For(self, node):
        name = node.target.id if isinstance(node.target, ast.Name) else None
        call = node.iter.func if isinstance(node.iter, ast.Call) else None
        every = EVERY in (getattr(call, "id", None), getattr(call, "attr", None))  # every(K) or ipm.every(K)
        if name == LANE or every:
            if every and len(node.iter.args) != 1:
                raise ValueError(f"{EVERY}(n) runs over a whole axis: one argument (line {node.lineno})")
            self.sliced.add(name)
            body = []
            for statement in node.body:
                done = self.visit(statement)
                body.extend(done if isinstance(done, list) else [done])
            self.sliced.discard(name)
            return body
        return self.generic_visit(node)

    def visit_Name(self, node):
        if node.id in self.sliced:
            return ast.copy_location(ast.Call(ast.Name("slice", ast.Load()), [ast.Constant(None)], []), node)
        return node

    def visit_Subscript(self, node):
        index = node.slice.elts if isinstance(node.slice, ast.Tuple) else [node.slice]
        index = [ast.Slice() if isinstance(e, ast.Name) and e.id in self.sliced else self.visit(e) for e in index]
        node.value = self.visit(node.value)
        node.slice = ast.Tuple(index, ast.Load()) if len(index) > 1 else index[0]
        return node

    def visit_AugAssign(self, node):
        node = self.generic_visit(node)
        if not isinstance(node.target, ast.Name):
            return node
        value = ast.BinOp(ast.Name(node.target.id, ast.Load()), node.op, node.value)
        return ast.copy_location(ast.Assign([ast.Name(node.target.id, ast.Store())], value), node)

    def visit_IfExp(self, node):
        node = self.generic_visit(node)
        where = ast.Attribute(ast.Name("_np", ast.Load()), "where", ast.Load())
        return ast.copy_location(ast.Call(where, [node.test, node.body, node.orelse], []), node)

    def generic_visit(self, node):
        if isinstance(node, _REFUSED) or (isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.Not)):
            raise ValueError(f"lane form has no {type(node).__name__} (line {node.lineno}): use &, |, a if c else b")
        return super().generic_visit(node)


#: numpy's names for one number's functions, and the float twin's (``not`` an operator); it refuses any other.
SCALAR = {
    "sqrt": "_sqrt",  # math's, bound in the twins' globals: no attribute to look up
    "isfinite": "_isfinite",
    "isnan": "_isnan",
    "isinf": "_isinf",
    "hypot": "_hypot",
    "inf": "_inf",
    "nan": "_nan",
    "minimum": "min",
    "maximum": "max",
    "abs": "abs",
    "logical_not": "not",
}


class _Float(ast.NodeTransformer):
    """The float twin's rewrites (:func:`floats`) on one function's tree."""

    def visit_For(self, node):
        name = node.target.id if isinstance(node.target, ast.Name) else None
        if name == LANE:
            body = []
            for statement in node.body:
                done = self.visit(statement)
                body.extend(done if isinstance(done, list) else [done])
            return body
        call = node.iter.func if isinstance(node.iter, ast.Call) else None
        if EVERY in (getattr(call, "id", None), getattr(call, "attr", None)):
            node.iter.func = ast.copy_location(ast.Name("range", ast.Load()), call)
        return self.generic_visit(node)

    def visit_Name(self, node):
        if node.id == LANE:  # a helper's lane argument, or a lone lane index: the one lane
            return ast.copy_location(ast.Constant(0), node)
        if node.id == "np":
            raise ValueError(f"the float twin has no numpy but its scalar calls (line {node.lineno})")
        return node

    def visit_Subscript(self, node):
        index = node.slice.elts if isinstance(node.slice, ast.Tuple) else [node.slice]
        if len(index) > 1 and isinstance(index[-1], ast.Name) and index[-1].id == LANE:
            index = index[:-1]  # X[i, j, ln] -> X[i][j]: a lane's elements are the lists' numbers
        if len(index) > 1 and any(isinstance(e, ast.Slice) for e in index):
            raise ValueError(f"the float twin's nested lists take no slice of an axis (line {node.lineno})")
        out = self.visit(node.value)
        for e in index:
            out = ast.copy_location(ast.Subscript(out, self.visit(e), node.ctx if e is index[-1] else ast.Load()), node)
        return out

    def visit_Attribute(self, node):
        if isinstance(node.value, ast.Name) and node.value.id == "np":
            if SCALAR.get(node.attr, "not") == "not":
                raise ValueError(f"the float twin has no np.{node.attr} (line {node.lineno})")
            return ast.copy_location(ast.parse(SCALAR[node.attr], mode="eval").body, node)
        return self.generic_visit(node)

    def visit_Call(self, node):
        f = node.func
        if isinstance(f, ast.Attribute) and getattr(f.value, "id", None) == "np" and f.attr == "logical_not":
            return ast.copy_location(ast.UnaryOp(ast.Not(), self.visit(node.args[0])), node)
        return self.generic_visit(node)

    def generic_visit(self, node):
        if isinstance(node, _REFUSED) or (isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.Not)):
            raise ValueError(f"lane form has no {type(node).__name__} (line {node.lineno}): use &, |, a if c else b")
        return super().generic_visit(node)


def _definitions(functions):
    """The trees of ``functions`` (one module's, parsed once; a test's or a doctest's from its own source)."""
    source = inspect.getsource(inspect.getmodule(functions[0]))
    definitions = {node.name: node for node in ast.parse(source).body if isinstance(node, ast.FunctionDef)}
    for function in functions:
        definition = definitions.get(function.__name__)
        if definition is None:  # not at the module's top level (a test's, a doctest's): its own source
            definition = ast.parse(textwrap.dedent(inspect.getsource(function))).body[0]
        definition.decorator_list = []
        yield function, definition


def _made(functions, transformer, namespace, kind):
    """``{name: twin}``: each of ``functions`` rewritten by a fresh ``transformer()``, run in ``namespace``."""
    out = {}
    for function, definition in _definitions(functions):
        tree = ast.fix_missing_locations(transformer().visit(ast.Module([definition], [])))
        code = compile(tree, f"<{kind} twin of {function.__module__}.{function.__name__}>", "exec")
        exec(code, namespace)
        out[function.__name__] = namespace[function.__name__]
        out[function.__name__].__source__ = ast.unparse(tree)
    return out


def floats(functions):
    """``{name: float twin}`` of lane-form ``functions``: one row (width 1) in Python floats, on nested lists.

    The lane loops are removed (their bodies run once), ``X[i, j, ln]`` is ``X[i][j]`` (a lone
    lane index ``X[ln]``, and a helper's lane argument, is ``0``: ``X`` a list of one number),
    ``every(K)`` is ``range(K)``, and numpy's calls on one number are :data:`SCALAR`'s (refused:
    any other use of ``np``).  A choice ``a if c else b`` computes only its side, and a division
    by zero or the root of a negative number raises where numpy gives ``inf`` or NaN: the caller
    stops the row there, as the step that is not finite does.

    >>> def clipped(x, y, out, K, width):
    ...     for ln in range(width):
    ...         for m in every(K):
    ...             y[m, ln] = np.minimum(x[m, 0, ln], 1.0)
    ...         out[ln] = np.sqrt(y[0, ln]) if y[0, ln] > 0 else np.inf
    >>> twin = floats([clipped])["clipped"]
    >>> print(twin.__source__)
    def clipped(x, y, out, K, width):
        for m in range(K):
            y[m] = min(x[m][0], 1.0)
        out[0] = _sqrt(y[0]) if y[0] > 0 else _inf
    >>> y, out = [0.0, 0.0], [0.0]
    >>> twin([[4.0], [0.5]], y, out, 2, 1); y, out
    ([1.0, 0.5], [1.0])
    """
    scalar = {"_sqrt": math.sqrt, "_isfinite": math.isfinite, "_isnan": math.isnan, "_isinf": math.isinf}
    scalar |= {"_hypot": math.hypot, "_inf": math.inf, "_nan": math.nan}
    return _made(functions, _Float, dict(functions[0].__globals__, **scalar), "float")


def float_workspace(arrays):
    """Lane-form arrays of width 1 as the float twin's nested lists: the lane axis dropped (a ``(1,)`` array
    kept, a list of one number).

    >>> float_workspace((np.zeros((2, 1)), np.ones(1)))
    [[0.0, 0.0], [1.0]]
    """
    return [np.asarray(w)[..., 0].tolist() if np.ndim(w) > 1 else np.asarray(w).tolist() for w in arrays]


def twins(functions):
    """``{name: twin}`` of lane-form ``functions`` (module-level, sharing globals), calling each other's twins.

    >>> def double(x, width):
    ...     for ln in range(width):
    ...         x[ln] = 2 * x[ln] if x[ln] > 0 else x[ln]
    >>> x = np.array([1.0, -1.0])
    >>> twins([double])["double"](x, None)
    >>> x.tolist()
    [2.0, -1.0]
    """
    return _made(functions, _Twin, dict(functions[0].__globals__, _np=np), "numpy")
