"""Fuzzing: the expression parser and the model loader raise only documented errors.

CI runs the ``ci`` hypothesis profile (a few hundred examples per test); the nightly-style
run is ``HYPOTHESIS_PROFILE=nightly python -m pytest tests/test_fuzz.py`` (10,000 examples
per test). "Documented" means a subclass of :class:`phdesign.errors.PhdesignError`, which
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

from phdesign.errors import PhdesignError
from phdesign.io import model_from_dict, model_from_toml
from phdesign.models import builtin_names, builtin_toml
from phdesign.symbolic.expressions import parse_scalar, parse_trace_expression

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
