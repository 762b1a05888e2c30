"""Fuzzing: the expression parser and the model loader raise only documented errors.

CI runs the ``ci`` hypothesis profile (a few hundred examples per test); the nightly-style
run is ``HYPOTHESIS_PROFILE=nightly python -m pytest tests/test_fuzz.py`` (10,000 examples
per test). "Documented" means a subclass of :class:`phdesign.core.errors.PhdesignError`, which
are all ValueErrors: anything else (KeyError, RecursionError, sympy internals) is a bug.
"""

from __future__ import annotations

import contextlib
import copy
import os
import tomllib

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from phdesign.core.errors import PhdesignError
from phdesign.io import check_output_path, model_from_dict, model_from_toml
from phdesign.models import builtin_names, builtin_toml
from phdesign.symbolic.expressions import parse_scalar
from phdesign.symbolic.traces import parse_trace_expression

# Per-test budget: the profile's max_examples scaled up for these cheap targets in CI.
BUDGET = 10_000 if os.environ.get("HYPOTHESIS_PROFILE") == "nightly" else 300

# An alphabet that reaches deep into the grammar far more often than arbitrary unicode.
GRAMMAR_ALPHABET = "e123'()+-*/^. abzsqrtxpiE,_0"
TOKENS = [
    "e1",
    "e2",
    "e3",
    "(",
    ")",
    "'",
    "0",
    "1",
    "b",
    "a",
    "+",
    "-",
    "*",
    "/",
    "**",
    "^",
    "sqrt",
    "exp",
    "(0)",
    "(1)",
    "z",
    "d",
    "EI",
    "0.5",
    "1e-3",
    ".",
    ",",
    " ",
    "pi",
]


def _documented(call, *args, **kwargs):
    with contextlib.suppress(PhdesignError):
        call(*args, **kwargs)


@settings(max_examples=BUDGET)
@given(
    st.one_of(
        st.text(alphabet=GRAMMAR_ALPHABET, max_size=40),
        st.lists(st.sampled_from(TOKENS), max_size=25).map("".join),
        st.text(max_size=40),
    )
)
def test_fuzz_trace_parser(text):
    _documented(parse_trace_expression, text, (0, 1), 2, 2, ["d", "EI"])


@settings(max_examples=BUDGET)
@given(
    st.one_of(st.lists(st.sampled_from(TOKENS), max_size=25).map("".join), st.text(max_size=40))
)
def test_fuzz_scalar_parser(text):
    _documented(parse_scalar, text, ["d", "EI"])


@settings(max_examples=BUDGET // 3)
@given(st.text(alphabet="[]=\"'\n abcdeinorstmpuxzP0123H.,-", max_size=200))
def test_fuzz_toml_text(text):
    _documented(model_from_toml, text)


_scalars = st.one_of(
    st.integers(-5, 5),
    st.floats(allow_nan=True, allow_infinity=True),
    st.booleans(),
    st.sampled_from(["e1(0)", "-e2(1)", "d", "z", "1/0", "0", "x", "e1''(0)", "", "[1]"]),
)
_values = st.recursive(
    _scalars,
    lambda inner: st.one_of(
        st.lists(inner, max_size=4),
        st.dictionaries(st.sampled_from(["P0", "P2", "H", "a"]), inner, max_size=3),
    ),
    max_leaves=12,
)
_paths = st.sampled_from(
    [
        ("order",),
        ("interval",),
        ("name",),
        ("states",),
        ("parameters", "d"),
        ("parameters", "rho"),
        ("matrices", "P0"),
        ("matrices", "P2"),
        ("matrices", "H"),
        ("matrices", "P1"),
        ("ports", "inputs"),
        ("ports", "outputs"),
        ("displacement",),
        ("ports",),
        ("matrices",),
    ]
)


@settings(max_examples=BUDGET // 3)
@given(
    st.sampled_from(builtin_names()), st.lists(st.tuples(_paths, _values), min_size=1, max_size=3)
)
def test_fuzz_structured_models(name, mutations):
    data = copy.deepcopy(tomllib.loads(builtin_toml(name)))
    for path, value in mutations:
        table = data
        for key in path[:-1]:
            if not isinstance(table.get(key), dict):
                table[key] = {}
            table = table[key]
        table[path[-1]] = value
    _documented(model_from_dict, data)


@pytest.mark.parametrize("name", builtin_names())
def test_fuzz_port_entries(name):
    """Replacing one port by each of a set of hostile strings never escapes the error family."""
    hostile = [
        "__import__('os')",
        "e1(0)" * 1000,
        "(" * 500,
        "e1(0)**99999999",
        "e1(1e999)",
        "e99999999999999999999(0)",
        "e1(0)/(e1(0)-e1(0))",
        "exp(1000000)*e1(0)",
        "\x00",
        "e1(0)\ne2(0)",
        "1e999999*e1(0)",
    ]
    data = tomllib.loads(builtin_toml(name))
    for text in hostile:
        mutated = copy.deepcopy(data)
        mutated["ports"]["inputs"][0] = text
        _documented(model_from_dict, mutated)


# --------------------------------------------------------------------------- library API
# Issue 12: strings and objects of the wrong type in every argument of every public
# function; only phdesign's errors may escape (or the call succeeds).
class _Opaque:
    """An object of no expected type, whose text would run code if anything evaluated it."""

    def __str__(self) -> str:
        return "__import__('os').getpid()"

    __repr__ = __str__


_INJECTIONS = [
    "__import__('os').system('false')",
    "lambda: 0",
    "exp(1e300)",
    "exp(exp(exp(5)))",
    "(z+1)**64**64",
    "1e999",
    "nan",
    "inf",
    "",
    "e1(0)",
    "((((((((((",
    "\x00",
    "E",
    "[[1, 0], [0, 1]]",
    "symbolic",
]
HOSTILE = st.one_of(
    st.sampled_from(_INJECTIONS),
    st.text(alphabet=GRAMMAR_ALPHABET, max_size=20),
    st.none(),
    st.booleans(),
    st.integers(-(10**30), 10**30),
    st.floats(allow_nan=True, allow_infinity=True),
    st.lists(st.sampled_from([0, 1, -1, "x", None, 0.5]), max_size=3),
    st.lists(st.lists(st.sampled_from([0, 1, "1/2", "x", None]), max_size=3), max_size=3),
    st.dictionaries(st.sampled_from(["rho", "T", "k", "x"]), st.integers(-2, 2), max_size=2),
    st.sampled_from([_Opaque(), b"bytes", object(), (), {}, 1j]),
)


def _targets():
    """(name, function, valid positional arguments, valid keyword arguments)."""
    import phdesign
    from phdesign.core import limits
    from phdesign.io import model_from_dict, model_to_toml
    from phdesign.symbolic import expressions, printing, traces
    from phdesign.symbolic.definiteness import check_definite

    wave = phdesign.load_builtin("wave")
    data = tomllib.loads(builtin_toml("wave"))
    define = {
        "name": "w",
        "interval": (0, 1),
        "order": 1,
        "P": {1: [[0, 1], [1, 0]]},
        "H": [[1, 0], [0, 1]],
        "inputs": ["e1(0)", "e2(1)"],
        "outputs": ["-e2(0)", "e1(1)"],
    }
    return [
        ("load_builtin", phdesign.load_builtin, ("wave",), {}),
        ("model_from_toml", phdesign.model_from_toml, (builtin_toml("wave"),), {}),
        ("model_from_dict", model_from_dict, (data,), {}),
        ("model_to_toml", model_to_toml, (wave,), {}),
        ("derive_ports", phdesign.derive_ports, (wave,), {}),
        ("BCPHS.define", phdesign.BCPHS.define, (), define),
        ("with_parameters", wave.with_parameters, ({"rho": 2},), {}),
        ("parse_scalar", expressions.parse_scalar, ("1/rho + z", ["rho"]), {}),
        ("parse_trace_expression", parse_trace_expression, ("-e2(0)", (0, 1), 1, 2), {}),
        ("format_expression", printing.format_expression, (Z_SYMBOL, (0, 1)), {}),
        ("exact_number", expressions.exact_number, ("0.5", "x"), {}),
        ("exact_matrix", expressions.exact_matrix, ([[1, 0]], "M"), {}),
        ("Trace.label", traces.Trace(1, 0, "a").label, ((0, 1),), {}),
        ("check_definite", check_definite, (MATRIX, "H", (0, 1)), {}),
        ("check_sensor_outputs", limits.check_sensor_outputs, (2,), {}),
        ("check_output_path", check_output_path, ("out.csv",), {}),
    ]


Z_SYMBOL = __import__("phdesign.symbolic.expressions", fromlist=["Z"]).Z
MATRIX = __import__("sympy").Matrix([[1, 0], [0, 2]])
TARGETS = _targets()


@pytest.mark.parametrize(
    ("name", "function", "args", "kwargs"), TARGETS, ids=[t[0] for t in TARGETS]
)
@settings(max_examples=BUDGET // 10)
@given(data=st.data())
def test_fuzz_library_api(name, function, args, kwargs, data):
    keys = [*range(len(args)), *kwargs]
    key = data.draw(st.sampled_from(keys), label="argument")
    value = data.draw(HOSTILE, label="value")
    call_args, call_kwargs = list(args), dict(kwargs)
    if isinstance(key, int):
        call_args[key] = value
    else:
        call_kwargs[key] = value
    with contextlib.suppress(PhdesignError):
        function(*call_args, **call_kwargs)


# Arguments of the wrong type for the library's sensor and gain readers (issue 12 item 8):
# each call must raise a phdesign error naming the argument, never a TypeError/ValueError
# of Python's; a huge q or n_outputs must be refused before anything is allocated.
FOREIGN = [
    ("measurement_matrix(None, 2)", "phdesign.symbolic.observer:measurement_matrix", (None, 2)),
    ("gain_matrix('1', 'x')", "phdesign.symbolic.observer:gain_matrix", ("1", "x")),
    ("gain_matrix(1, 10**12)", "phdesign.symbolic.observer:gain_matrix", (1, 10**12)),
    ("sensor_matrix('1', True)", "phdesign.symbolic.observer:sensor_matrix", ("1", True)),
    ("sensor_matrix(None, 2)", "phdesign.symbolic.observer:sensor_matrix", (None, 2)),
    ("sensor_matrix([1], 'x')", "phdesign.symbolic.observer:sensor_matrix", ([1], "x")),
    ("sensor_matrix([1], 10**12)", "phdesign.symbolic.observer:sensor_matrix", ([1], 10**12)),
]


@pytest.mark.parametrize(("label", "where", "args"), FOREIGN, ids=[f[0] for f in FOREIGN])
def test_observer_parsers_raise_only_phdesign_errors(label, where, args):
    import importlib

    module, name = where.split(":")
    function = getattr(importlib.import_module(module), name)
    with contextlib.suppress(PhdesignError):
        function(*args)
