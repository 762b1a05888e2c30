"""Issue 30: text from a model never reaches the generated sources unescaped.

A model name is any TOML string: comment openers and closers, newlines, ``#include``,
trigraphs (``??/`` is a backslash in C99), backslashes, quotes, non-ASCII. The generated
C must compile with ``gcc -std=c99 -Wall -Wextra -Werror -pedantic`` and the generated
Python module must run and build the same observer, its docstring reading the name back.
"""

from __future__ import annotations

import dataclasses
import runpy
import shutil
import subprocess

import numpy as np
import pytest
import tomli_w

from phdesign.cli import main
from phdesign.codegen import escaped, render_c, render_statespace
from phdesign.io import model_to_toml
from phdesign.models import load_builtin
from phdesign.numeric.bridge import to_numeric
from phdesign.numeric.sampled.export import SampledObserver, export_observer

pytest.importorskip("jinja2", reason="the C and statespace exports need the codegen extra")

HOSTILE = {
    "comments": "beam /* open */ close */ a/*b*/c */ int x; /* //",
    "ends": "/*/",
    "newlines": "one\ntwo\r\nthree\tfour */\n#define PHD_OBSERVER_N 0",
    "include": '#include <stdio.h>\n#error "x"',
    "trigraphs": "??/ ??= ??( ??) ??' ??< ??! ??> ??- ???/",
    "backslash": "C:\\path\\ to\\",
    "quotes": '""" \'\'\' " \' \\"""',
    "non-ASCII": "poutre d'Euler–Bernoulli, 漢字 😀 \u2028 \u202e \x00 \x1b[2J",
    "python": '""" + __import__("os").system("x") + """',
}


PEDANTIC = ("gcc", "-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-c")


@pytest.fixture(scope="module")
def observer() -> SampledObserver:
    nm = to_numeric(load_builtin("euler-bernoulli"))
    sensors, gain = np.eye(4)[[2, 3]], np.diag([0.1, 1.0])
    return export_observer(nm, sensors, gain, dt=1e-2, order=8, points=(0.5, 1.0))


def test_escaped_text_holds_no_comment_delimiter_trigraph_quote_or_control():
    for name in HOSTILE.values():
        text = escaped(name)
        assert text.isascii()
        assert text.isprintable()
        for bad in ("/*", "*/", "??", '"""', "\n", "\r"):
            assert bad not in text, (name, text)
        assert not text.startswith(("/", "*")), text
        assert not text.endswith(("/", "*", "\\")) or text.endswith("\\\\"), text
        # a Python string literal of the escaped text reads back the name
        assert eval(f'"""{text}"""') == name


@pytest.mark.skipif(shutil.which("gcc") is None, reason="no gcc on this machine")
def test_generated_c_compiles_pedantically_with_every_hostile_name(observer, tmp_path):
    for key, name in HOSTILE.items():
        folder = tmp_path / key.replace(" ", "_")
        folder.mkdir()
        for file, text in render_c(dataclasses.replace(observer, model=name)).items():
            (folder / file).write_text(text, encoding="utf-8")
        result = subprocess.run(
            [*PEDANTIC, "-Wtrigraphs", "observer.c", "-o", "observer.o"],
            cwd=folder, capture_output=True, text=True,
        )  # fmt: skip
        assert result.returncode == 0, f"{key}: {result.stderr}"
        for file, text in render_c(observer).items():  # the same directives as without
            assert _directives((folder / file).read_text()) == _directives(text), key


def _directives(source: str) -> list[str]:
    return [line for line in source.splitlines() if line.lstrip().startswith("#")]


def test_generated_python_runs_and_builds_the_same_observer_for_every_hostile_name(
    observer, tmp_path
):
    for key, name in HOSTILE.items():
        path = tmp_path / f"{key.replace(' ', '_').replace('-', '_')}.py"
        path.write_text(render_statespace(dataclasses.replace(observer, model=name), path.name))
        module = runpy.run_path(str(path))
        system = module["observer"]
        for matrix in "ABCD":
            assert np.array_equal(getattr(system, matrix), getattr(observer, matrix)), key
        assert system.dt == observer.dt
        assert f"Sampled-data observer for {name} as a python-control" in module["__doc__"], key


def test_a_hostile_model_file_name_exports_through_the_command_line(tmp_path, capsys):
    text = model_to_toml(load_builtin("wave"))
    name = HOSTILE["comments"] + HOSTILE["trigraphs"] + HOSTILE["quotes"]
    model = tmp_path / "m.toml"
    model.write_text(text.replace('name = "wave"', f"name = {tomli_w.dumps({'n': name})[4:]}"))
    argv = ["export", str(model), "--sensors", "2", "--gain", "1", "--dt", "1e-2"]
    for form, target in (("c", "c"), ("statespace", "o.py")):
        assert main([*argv, "--order", "6", "--format", form, "-o", str(tmp_path / target)]) == 0
    capsys.readouterr()
    assert name in runpy.run_path(str(tmp_path / "o.py"))["__doc__"]
    if shutil.which("gcc") is not None:
        subprocess.run([*PEDANTIC, "observer.c"], cwd=tmp_path / "c", check=True)


def test_every_exported_statespace_module_runs(observer, tmp_path):
    """``--at 0.5`` wrote a module that raised: python-control refuses '.' in names."""
    import control

    point = dataclasses.replace(observer, sampler="point")
    for index, variant in enumerate((observer, point)):
        path = tmp_path / f"o{index}.py"
        variant.write(str(path), "statespace")
        system = runpy.run_path(str(path))["observer"]
        assert system.output_labels == ["yhat1", "yhat2", "yhat3", "yhat4", "w(0p5)", "w(1)"]
        assert system.input_labels == ["u1", "u2", "u3", "u4", "y3", "y4"]
        same = variant.statespace()
        assert same.output_labels == system.output_labels
        response = control.forced_response(system, U=np.ones((6, 5)), X0=0).outputs
        assert np.allclose(response, control.forced_response(same, U=np.ones((6, 5))).outputs)
    # the JSON export keeps the model's own names
    assert observer.outputs[-2:] == ("w(0.5)", "w(1)")
