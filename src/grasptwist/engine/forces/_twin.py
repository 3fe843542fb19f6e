r"""numpy twins of lane-form functions: the compiled grip's source run over all rows at once.

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
import textwrap

import numpy as np

__all__ = ["twins", "LANE", "EVERY"]

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
    namespace = dict(functions[0].__globals__, _np=np)
    source = inspect.getsource(inspect.getmodule(functions[0]))  # one module: parsed once
    definitions = {node.name: node for node in ast.parse(source).body if isinstance(node, ast.FunctionDef)}
    out = {}
    for function in functions:
        definition = definitions.get(function.__name__)
        if definition is None:  # not at the module's top level (a test's, a doctest's): its own source
            definition = ast.parse(textwrap.dedent(inspect.getsource(function))).body[0]
        definition.decorator_list = []
        tree = ast.fix_missing_locations(_Twin().visit(ast.Module([definition], [])))
        exec(compile(tree, f"<numpy twin of {function.__module__}.{function.__name__}>", "exec"), namespace)
        out[function.__name__] = namespace[function.__name__]
    return out
