"""Named regions given as small, safe boolean expressions of point coordinates.

An expression such as ``"abs(x) < 1e-9 or y > 0.5*Ly"`` is parsed with :mod:`ast`, checked
against a strict whitelist and compiled into a vectorised function of points (n, 3) that returns
a boolean mask (n,).  Nothing is ever passed to ``eval``.

Grammar
-------
names
    ``x``, ``y``, ``z``; ``r = sqrt(x**2 + y**2)``; ``rho = sqrt(x**2 + y**2 + z**2)``;
    ``theta = atan2(y, x)`` in (-pi, pi]; ``pi``; and the caller's ``constants``.
functions
    ``abs``, ``sqrt``, ``sin``, ``cos``, ``atan2(y, x)``, ``hypot(a, b)``, ``min(a, b, ...)``,
    ``max(a, b, ...)`` (element-wise).
operators
    ``+ - * / **``, unary ``-``; comparisons ``< <= > >= == !=`` (chains such as
    ``0 < x < 1`` allowed); ``and``, ``or``, ``not`` on comparisons.
equality
    ``a == b`` means ``|a - b| <= tol`` and ``a != b`` means ``|a - b| > tol``, with
    ``tol = atol`` if given, else ``1e-9 * length_scale``.  The same absolute tolerance applies
    whatever the compared quantities are (lengths in metres, angles in radians).
"""

from __future__ import annotations

import ast
import functools
import math
import operator
from collections.abc import Callable, Mapping

import numpy as np

from graspdef.errors import ProblemError

_VARIABLES: dict[str, Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray]] = {
    "x": lambda x, y, z: x,
    "y": lambda x, y, z: y,
    "z": lambda x, y, z: z,
    "r": lambda x, y, z: np.hypot(x, y),
    "rho": lambda x, y, z: np.sqrt(x * x + y * y + z * z),
    "theta": lambda x, y, z: np.arctan2(y, x),
}

# name -> (function, number of arguments; None means two or more)
_FUNCTIONS: dict[str, tuple[Callable[..., np.ndarray], int | None]] = {
    "abs": (np.abs, 1),
    "sqrt": (np.sqrt, 1),
    "sin": (np.sin, 1),
    "cos": (np.cos, 1),
    "atan2": (np.arctan2, 2),
    "hypot": (np.hypot, 2),
    "min": (lambda *a: functools.reduce(np.minimum, a), None),
    "max": (lambda *a: functools.reduce(np.maximum, a), None),
}

_ARITHMETIC = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul,
               ast.Div: operator.truediv, ast.Pow: operator.pow}
_ORDER = {ast.Lt: operator.lt, ast.LtE: operator.le, ast.Gt: operator.gt, ast.GtE: operator.ge}

Env = dict[str, np.ndarray]
Compiled = tuple[Callable[[Env], np.ndarray], bool]  # evaluator, whether it yields booleans


def compile_predicate(expr: str, name: str, *, constants: Mapping[str, float] | None = None,
                      length_scale: float = 1.0,
                      atol: float | None = None) -> Callable[[np.ndarray], np.ndarray]:
    """Compile a region expression into a vectorised point predicate.

    Parameters
    ----------
    expr : str
        Boolean expression in the grammar of this module's docstring, e.g.
        ``"abs(x) < 1e-9 or y > 0.5*Ly"``, ``"z == 0"``, ``"r < 0.1 and theta > 0"``.
    name : str
        Region name used in error messages.
    constants : mapping of str to float, optional
        Extra named constants (e.g. ``{"Ly": 0.2}``); must not reuse a built-in name.
    length_scale : float
        Characteristic length [m]; the default ``==`` tolerance is ``1e-9 * length_scale``.
    atol : float, optional
        Absolute tolerance of ``==`` and ``!=``, overriding ``1e-9 * length_scale``.

    Returns
    -------
    callable
        ``predicate(points)`` with points of shape (n, 3) [m] returning a bool array (n,).

    Raises
    ------
    ProblemError
        If the expression is not valid Python, uses anything outside the whitelist (naming the
        offending token), or is not a condition.
    """
    def fail(message: str):
        raise ProblemError(f"region {name!r}: {message} in {expr!r}")

    if not isinstance(expr, str):
        raise ProblemError(f"region {name!r}: expression must be a string, got {expr!r}")
    expr = expr.strip()

    tol = 1e-9 * float(length_scale) if atol is None else float(atol)
    values = {"pi": math.pi}
    for key, value in (constants or {}).items():
        if key in _VARIABLES or key in _FUNCTIONS or key == "pi" or not key.isidentifier():
            fail(f"constant name {key!r} is invalid or shadows a built-in name")
        try:
            values[key] = float(value)
        except (TypeError, ValueError):
            fail(f"constant {key!r} must be a number, got {value!r}")

    def source(node: ast.AST) -> str:
        return ast.get_source_segment(expr, node) or type(node).__name__

    def numeric(node: ast.AST) -> Callable[[Env], np.ndarray]:
        fn, is_bool = compile_node(node)
        if is_bool:
            fail(f"'{source(node)}' is a condition where a number is expected")
        return fn

    def condition(node: ast.AST) -> Callable[[Env], np.ndarray]:
        fn, is_bool = compile_node(node)
        if not is_bool:
            fail(f"'{source(node)}' is a number where a condition is expected")
        return fn

    def compile_node(node: ast.AST) -> Compiled:
        if isinstance(node, ast.Constant):
            if type(node.value) not in (int, float):
                fail(f"constant {source(node)} is not allowed")
            value = float(node.value)
            return (lambda env: value), False
        if isinstance(node, ast.Name):
            if node.id in _VARIABLES:
                key = node.id
                return (lambda env: env[key]), False
            if node.id in values:
                value = values[node.id]
                return (lambda env: value), False
            fail(f"unknown name '{node.id}'")
        if isinstance(node, ast.BinOp) and type(node.op) in _ARITHMETIC:
            op, left, right = _ARITHMETIC[type(node.op)], numeric(node.left), numeric(node.right)
            return (lambda env: op(left(env), right(env))), False
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub):
            operand = numeric(node.operand)
            return (lambda env: -operand(env)), False
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.Not):
            operand = condition(node.operand)
            return (lambda env: np.logical_not(operand(env))), True
        if isinstance(node, ast.BoolOp):
            combine = np.logical_and if isinstance(node.op, ast.And) else np.logical_or
            operands = [condition(v) for v in node.values]
            return (lambda env: functools.reduce(combine, (f(env) for f in operands))), True
        if isinstance(node, ast.Compare):
            return compile_compare(node), True
        if isinstance(node, ast.Call):
            return compile_call(node), False
        fail(f"'{source(node)}' is not allowed")

    def compile_compare(node: ast.Compare) -> Callable[[Env], np.ndarray]:
        terms = [numeric(node.left)] + [numeric(c) for c in node.comparators]
        tests = []
        for op in node.ops:
            if type(op) in _ORDER:
                tests.append(_ORDER[type(op)])
            elif isinstance(op, ast.Eq):
                tests.append(lambda a, b: np.abs(a - b) <= tol)
            elif isinstance(op, ast.NotEq):
                tests.append(lambda a, b: np.abs(a - b) > tol)
            else:
                fail(f"comparison '{source(node)}' is not allowed")

        def evaluate(env: Env) -> np.ndarray:
            vals = [t(env) for t in terms]
            return functools.reduce(np.logical_and,
                                    (test(a, b) for test, a, b in zip(tests, vals, vals[1:])))
        return evaluate

    def compile_call(node: ast.Call) -> Callable[[Env], np.ndarray]:
        if not isinstance(node.func, ast.Name):
            fail(f"'{source(node.func)}' is not allowed")
        if node.func.id not in _FUNCTIONS:
            fail(f"unknown function '{node.func.id}'")
        fn, n_args = _FUNCTIONS[node.func.id]
        if node.keywords or any(isinstance(a, ast.Starred) for a in node.args):
            fail(f"'{source(node)}': only positional arguments are allowed")
        if (len(node.args) != n_args) if n_args else (len(node.args) < 2):
            fail(f"'{node.func.id}' takes {n_args or 'at least 2'} argument(s), "
                 f"got {len(node.args)}")
        args = [numeric(a) for a in node.args]
        return lambda env: fn(*(a(env) for a in args))

    try:
        tree = ast.parse(expr, mode="eval")
    except (SyntaxError, ValueError) as exc:
        fail(f"syntax error: {getattr(exc, 'msg', exc)}")
    evaluate = condition(tree.body)
    used = sorted({n.id for n in ast.walk(tree) if isinstance(n, ast.Name)} & _VARIABLES.keys())

    def predicate(points: np.ndarray) -> np.ndarray:
        points = np.asarray(points, dtype=np.float64)
        if points.ndim != 2 or points.shape[1] != 3:
            raise ProblemError(f"region {name!r}: points must have shape (n, 3), "
                               f"got {points.shape}")
        x, y, z = points.T
        with np.errstate(all="ignore"):
            env = {key: _VARIABLES[key](x, y, z) for key in used}
            mask = evaluate(env)
        return np.broadcast_to(mask, (points.shape[0],)).copy()

    return predicate
