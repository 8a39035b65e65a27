"""Style-6 expressions compiled with their numbers as runtime constants
(nairnmpm_py.core.expressions): expressions that differ only in their numbers give
the same Numba source (hence one compiled, cached kernel), and the generated
function agrees with the Python evaluation of the expression."""
from __future__ import annotations

import ast
import importlib.util
import itertools
import math
import sys

import numpy as np
import pytest

from nairnmpm_py.core.conditions import EXPRESSION_FUNCTIONS, evaluate_expression
from numba import njit

from nairnmpm_py.core.expressions import (MAX_LITERAL_EXPONENT, call_condition,
                                          condition_module_source)

RTOL = 1e-14

# every function of the language, unary minus, nested parentheses, integer and
# non-integer powers, scientific notation, x, y, q, pi and e
EXPRESSIONS = [
    "2.5*t^2",
    "-3*t + 4",
    "-(t - 0.25)^3 + -t",
    "((t + 1)*(x - 2.5))/((y + 0.5)*(1 + (q - 0.1)*(2 - (t + 0.3))))",
    "sin(pi*t/2) + cos(2*pi*x) - tan(0.3*q)",
    "asin(0.5*t) + acos(-0.4*t) + atan(3*y)",
    "sinh(t)*cosh(-0.5*x) + tanh(2*y)",
    "exp(-t/0.3) + log(1 + x) + log10(2.5e2*t)",
    "sqrt(abs(x - 3)) + floor(10*t) + ceil(-2.5*y)",
    "floor(4 + t)^-1 + ceil(t)^2 + floor(3.5*x)^3",
    "t^1.5 + x^-2 + y**0.5 + 2^t + t^2.0",
    "t^8 + t^9 + x^-8 + (1 + t)^-9 + t^0",
    "1e-3*x + 2.5E+2*y - 6.02e23*1e-24*q + .5 + 3.",
    "e^(-t) + pi*e - e*x",
    "--2*t + +3*x - -q + -(-(1.5))*y",
    "-2^2 + (-2)^2 + -t^2 + (-t)^2",
    "cos(q)*x - sin(q)*y",
    "7",
    "t",
]
POINTS = [(t, x, y, q) for t, x, y, q in itertools.product(
    (0.1, 0.37, 0.9), (0.7, 1.9), (0.3, 1.2), (-0.25, 0.0, 0.4))]


def _load(folder, source: str, name: str):
    """Import ``source`` as a real module (Numba's cache=True needs a file)."""
    path = folder / f"{name}.py"
    path.write_text(source)
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


def _close(got: float, want: float) -> bool:
    return got == want or abs(got - want) <= RTOL * abs(want)


@pytest.fixture(scope="module")
def compiled_module(tmp_path_factory):
    expressions = dict(enumerate(EXPRESSIONS))
    source, constants = condition_module_source(expressions)
    module = _load(tmp_path_factory.mktemp("expr"), source, "expr_constants_all")
    return expressions, constants, module


@pytest.fixture(scope="module")
def compiled(compiled_module):
    expressions, constants, module = compiled_module
    return expressions, constants, module.condition_function


def test_all_functions_are_covered():
    used = set()
    for text in EXPRESSIONS:
        tree = ast.parse(text.replace("^", "**"), mode="eval")
        used |= {n.func.id for n in ast.walk(tree) if isinstance(n, ast.Call)}
    assert EXPRESSION_FUNCTIONS <= used, EXPRESSION_FUNCTIONS - used


def test_generated_function_matches_python(compiled):
    expressions, constants, fn = compiled
    for (r, text), (t, x, y, q) in itertools.product(expressions.items(), POINTS):
        want = evaluate_expression(text, t, x, y, q)
        got = fn(r, t, x, y, q, constants)
        assert _close(got, want), (text, (t, x, y, q), got, want)


def test_unknown_record_is_zero(compiled):
    _, constants, fn = compiled
    for r in (-1, len(EXPRESSIONS), 99):
        assert fn(r, 0.5, 1.0, 2.0, 0.3, constants) == 0.0


@njit
def _through_address(address, r, t, x, y, q, c):
    return call_condition(address, r, t, x, y, q, c)


def test_kernels_get_the_same_values_through_the_cfunc_address(compiled_module):
    # the step kernels call the expressions only this way (a runtime address), so
    # their own source never depends on the expressions
    expressions, constants, module = compiled_module
    fn, address = module.condition_function, module.condition_cfunc.address
    for (r, text), (t, x, y, q) in itertools.product(expressions.items(), POINTS):
        got = _through_address(address, r, t, x, y, q, constants)
        assert got == fn(r, t, x, y, q, constants) or (math.isnan(got) and math.isnan(
            fn(r, t, x, y, q, constants))), (text, (t, x, y, q))
    assert _through_address(address, 99, 0.5, 1.0, 2.0, 0.3, constants) == 0.0


# --- the source depends on the structure only -------------------------------------

def _source(expressions):
    return condition_module_source(expressions)[0]


def test_same_source_for_different_numbers():
    a, ca = condition_module_source({0: "2.5*t^2"})
    b, cb = condition_module_source({0: "7*t^2"})
    assert a == b
    assert list(ca) == [2.5] and list(cb) == [7.0]
    assert _source({0: "-1.5*t**3"}) == _source({0: "4e-2*t^3"})


ENTITY_TEMPLATE = {
    0: "&a;*t^2 + &b;",
    2: "&c;*sin(&w;*t)*exp(-t/&tau;)",
    5: "x*&k; - &a;",
}
ENTITY_VALUES = [
    {"a": "2.5", "b": "0", "c": "1e-3", "w": "6.283", "tau": "0.3", "k": "4"},
    {"a": "-7", "b": "-1.5E2", "c": "3", "w": "0.5", "tau": "12", "k": "-0.25"},
]


def _substitute(values):
    out = {}
    for r, text in ENTITY_TEMPLATE.items():
        for name, value in values.items():
            text = text.replace(f"&{name};", value)
        out[r] = text
    return out


def test_entities_share_source_and_compiled_function(tmp_path):
    scenes = [_substitute(v) for v in ENTITY_VALUES]
    built = [condition_module_source(s) for s in scenes]
    assert built[0][0] == built[1][0]
    # numbered across records in record order, signs folded into the numbers
    assert list(built[1][1]) == [-7.0, -150.0, 3.0, 0.5, 12.0, -0.25, -7.0]
    fn = _load(tmp_path, built[0][0], "expr_constants_entities").condition_function
    for scene, (_, constants) in zip(scenes, built):
        for (r, text), (t, x, y, q) in itertools.product(scene.items(), POINTS):
            want = evaluate_expression(text, t, x, y, q)
            assert _close(fn(r, t, x, y, q, constants), want), (text, t, x, y, q)
    assert len(fn.signatures) == 1   # one compilation served both scenes


@pytest.mark.parametrize("a, b", [
    ("t^2", "t^3"),
    ("sin(t)", "cos(t)"),
    ("t^2", "t^2.5"),
    ("t^2", "t^-2"),
    ("2*t", "2*x"),
    ("2*t + 1", "2*(t + 1)"),
    ("-2^2", "(-2)^2"),
    ("pi*t", "3.14159*t"),
])
def test_different_structure_different_source(a, b):
    assert _source({0: a}) != _source({0: b})


def test_record_numbers_are_structure():
    assert _source({0: "t"}) != _source({1: "t"})


def test_constants_vector():
    _, c = condition_module_source({3: "2*t", 1: "5*t + 6"})
    assert c.dtype == np.float64 and c.flags.c_contiguous and list(c) == [5.0, 6.0, 2.0]
    assert condition_module_source({0: "t^2 + t^-3 + x^0"})[1].size == 0
    assert list(condition_module_source({0: f"t^{MAX_LITERAL_EXPONENT + 1}"})[1]) == [9.0]
    assert list(condition_module_source({0: "t^2.0"})[1]) == [2.0]
    assert list(condition_module_source({0: "-1e-3*t - 0.0"})[1]) == [-1e-3, 0.0]
    assert math.copysign(1.0, condition_module_source({0: "-0.0*t"})[1][0]) == -1.0
    source, c = condition_module_source({})
    assert c.size == 0 and "return 0.0" in source


@pytest.mark.parametrize("text", ["z*t", "open(t)", "t*(", "'a'*t", "1j*t", "True*t", "None"])
def test_invalid_expressions_are_rejected(text):
    with pytest.raises((ValueError, SyntaxError)):
        condition_module_source({0: text})
