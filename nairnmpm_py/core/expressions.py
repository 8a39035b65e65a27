"""Style-6 condition expressions as a cacheable Numba function plus runtime constants.

A scene's style-6 boundary conditions each carry a NairnMPM expression of t, x, y
and q (see ``conditions.expression_source``).  They become one generated module with
``condition_function(r, t, x, y, q, c)``, whose branch ``r`` is the expression of
record r, and a C-callable ``condition_cfunc`` around it.  The step kernels call
the cfunc through its address (``call_condition``, a runtime number in the
conditions bundle), never by name: the kernels' source, and with it their compiled
cache, is then the same for every expression, and a scene that differs from a
compiled one only in its expressions compiles just the small expression module
(about a second) instead of the step (a minute or more).  The indirect call costs a
few nanoseconds per evaluation, next to tens for a ``cos``.

Numba also caches that module by its source, so the numeric literals of the
expressions are *not* written into it: each becomes ``c[i]``, an entry of a float64
vector passed at run time.  Two scenes whose expressions differ only in their
numbers (say a loading rate entity substituted into ``function="&rate;*t^2"``) then
produce the same source and compile nothing at all.

What stays in the expression module's source, because it changes the code:

* the structure of each expression (operators, functions, variables, nesting);
* small integer exponents of a power (``t^2``, ``t**-3``: an integer literal, with
  or without a sign, of magnitude <= ``MAX_LITERAL_EXPONENT``), which Numba expands
  into multiplications instead of calling ``pow``;
* ``pi`` and ``e`` (as ``math.pi`` and ``math.e``);
* the record numbers.

A sign in front of a number is folded into its constant (``-3*t`` gives ``c[0]*t``
with ``c[0] = -3.0``), so an entity may change sign without a recompile.  Equal
numbers are deliberately *not* shared: whether two numbers happen to be equal must
not change the source.
"""
from __future__ import annotations

import ast

import numpy as np
from llvmlite import ir
from numba import types
from numba.extending import intrinsic

from .conditions import expression_source

# integer exponents of at most this magnitude stay literal (Numba: x*x*..., no pow)
MAX_LITERAL_EXPONENT = 8

# name of the constant vector in the generated source; an expression cannot use it,
# because expression_source only admits t, x, y, q, pi, e and the listed functions
CONSTANTS_NAME = "c"
MATH_ALIAS = "_math_fn"
NJIT_ALIAS = "_njit_fn"
CFUNC_ALIAS = "_cfunc_fn"
CARRAY_ALIAS = "_carray_fn"
# C signature of ``condition_cfunc``: (r, t, x, y, q, constants pointer, their count)
CFUNC_SIGNATURE = "float64(int64, float64, float64, float64, float64, CPointer(float64), int64)"
# math functions whose Numba result is an integer; the generated code makes it a float
INTEGER_FUNCTIONS = {"floor", "ceil"}
# the decorator of the generated function (see condition_module_source on inlining)
DECORATOR = f"@{NJIT_ALIAS}(cache=True, error_model='numpy')"


@intrinsic
def call_condition(typingctx, address, r, t, x, y, q, c):
    """``condition_cfunc(r, t, x, y, q, c)`` of the module whose cfunc is at
    ``address`` (an int64 from ``condition_functions``); ``c`` a float64 array."""
    sig = types.float64(types.int64, types.int64, types.float64, types.float64,
                        types.float64, types.float64, c)

    def codegen(context, builder, signature, args):
        address, r, t, x, y, q, c = args
        constants = context.make_array(signature.args[6])(context, builder, c)
        double, int64 = ir.DoubleType(), ir.IntType(64)
        fnty = ir.FunctionType(double, [int64, double, double, double, double,
                                        double.as_pointer(), int64])
        function = builder.inttoptr(address, fnty.as_pointer())
        return builder.call(function, [r, t, x, y, q, constants.data, constants.nitems])
    return sig, codegen


def _is_number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _signed_literal(node: ast.AST):
    """The number of a literal with any chain of unary signs (``3``, ``-3``, ``--3``,
    ``+3``), or None when ``node`` is not such a literal."""
    sign = 1
    while isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
        if isinstance(node.op, ast.USub):
            sign = -sign
        node = node.operand
    if isinstance(node, ast.Constant):
        if not _is_number(node.value):
            raise ValueError(f"{node.value!r} is not a real number")
        return node.value if sign > 0 else -node.value
    return None


def _is_literal_exponent(node: ast.AST) -> bool:
    value = _signed_literal(node)
    return (isinstance(value, int) and not isinstance(value, bool)
            and abs(value) <= MAX_LITERAL_EXPONENT)


class _Parametrize(ast.NodeTransformer):
    """Numbers -> ``c[i]`` (appending to ``constants``), ``math`` -> its alias."""

    def __init__(self, constants: list[float]):
        self.constants = constants

    def _constant(self, value, like: ast.AST) -> ast.AST:
        index = len(self.constants)
        self.constants.append(float(value))
        node = ast.Subscript(ast.Name(CONSTANTS_NAME, ast.Load()), ast.Constant(index),
                             ast.Load())
        return ast.copy_location(node, like)

    def visit_BinOp(self, node: ast.BinOp) -> ast.AST:
        # left before right: constants are numbered in reading order
        node.left = self.visit(node.left)
        if not (isinstance(node.op, ast.Pow) and _is_literal_exponent(node.right)):
            node.right = self.visit(node.right)
        return node

    def visit_UnaryOp(self, node: ast.UnaryOp) -> ast.AST:
        value = _signed_literal(node)
        if value is not None:
            return self._constant(value, node)
        return self.generic_visit(node)

    def visit_Constant(self, node: ast.Constant) -> ast.AST:
        if not _is_number(node.value):
            raise ValueError(f"{node.value!r} is not a real number")
        return self._constant(node.value, node)

    def visit_Call(self, node: ast.Call) -> ast.AST:
        node = self.generic_visit(node)
        if isinstance(node.func, ast.Attribute) and node.func.attr in INTEGER_FUNCTIONS:
            # Numba's math.floor/ceil return int64: integer powers would then stay
            # integer (floor(t)^-1 == 0) and could overflow; Python's ints do neither
            return ast.copy_location(ast.Call(ast.Name("float", ast.Load()), [node], []), node)
        return node

    def visit_Name(self, node: ast.Name) -> ast.AST:
        if node.id == "math":   # expression_source's math.sin, math.pi, ...
            return ast.copy_location(ast.Name(MATH_ALIAS, node.ctx), node)
        return node


def parametrized_expression(text: str, constants: list[float]) -> str:
    """Python source of one NairnMPM expression with its numbers read from ``c``,
    appending their values to ``constants`` (indices continue from its length).

    Validation (ValueError, SyntaxError) is ``expression_source``'s, plus: every
    literal must be a real number."""
    tree = ast.parse(expression_source(text), mode="eval")
    tree = ast.fix_missing_locations(_Parametrize(constants).visit(tree))
    return ast.unparse(tree)


def condition_module_source(expressions: dict[int, str]) -> tuple[str, np.ndarray]:
    """(source, constants) of a module with ``condition_function(r, t, x, y, q, c)``
    and the kernels' entry ``condition_cfunc`` (signature ``CFUNC_SIGNATURE``).

    ``expressions`` maps record index -> NairnMPM expression.  The function returns
    the expression of record r, or 0.0 for any other r; the source depends only on
    the expressions' structure, not on their numbers.  ``constants`` (float64,
    C-contiguous, possibly empty) is the ``c`` to pass: numbered across the records in
    increasing record order, and within one in reading order.

    The expressions keep plain IEEE semantics (the kernels' ``fastmath`` does not
    reach them).  ``error_model='numpy'`` is the kernels': a division by zero gives
    inf or NaN, which the kernels' status check catches."""
    constants: list[float] = []
    lines = [f"import math as {MATH_ALIAS}",
             f"from numba import carray as {CARRAY_ALIAS}, cfunc as {CFUNC_ALIAS}, "
             f"njit as {NJIT_ALIAS}", "", "",
             DECORATOR,
             f"def condition_function(r, t, x, y, q, {CONSTANTS_NAME}):"]
    for r, text in sorted(expressions.items()):
        src = parametrized_expression(text, constants)
        lines.append(f"    if r == {int(r)}:")
        lines.append(f"        return {src}")
    lines += ["    return 0.0", "", "",
              f"@{CFUNC_ALIAS}('{CFUNC_SIGNATURE}', cache=True, error_model='numpy')",
              "def condition_cfunc(r, t, x, y, q, c, n):",
              f"    return condition_function(r, t, x, y, q, {CARRAY_ALIAS}(c, n))"]
    return "\n".join(lines) + "\n", np.array(constants, dtype=np.float64)
