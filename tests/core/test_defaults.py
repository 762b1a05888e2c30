"""The one table of defaults (phdesign.core.defaults) is the one in force.

Every signature says None for "the registered default" and every command builds its
options from the table, so a changed table put in force by ``using`` (never a global
setter) changes what the library and the command line do, and only inside its block.
"""

from __future__ import annotations

import threading
from dataclasses import FrozenInstanceError, replace

import pytest

from phdesign.cli import build_parser
from phdesign.core.defaults import DEFAULTS, Defaults, current, method_or_default, using
from phdesign.core.errors import ArgumentError, NumericError
from phdesign.design.observer import Observer
from phdesign.models import load_builtin

QUICK = replace(DEFAULTS, simulation=replace(DEFAULTS.simulation, t_end=1.0, samples=11))


def test_a_changed_simulation_default_reaches_the_library_and_the_command_line():
    wave = load_builtin("wave")
    observer = Observer(wave, sensors=[2], gain=0.5)
    assert observer.plant.simulate(x0="x1: 0, x2: z").t.size == 501
    with using(QUICK):
        run = observer.simulate(x0="x1: 0, x2: z")
        args = build_parser().parse_args(["simulate", "wave"])
        loop_args = build_parser().parse_args(["loop", "simulate", "wave", "--actuate", "2"])
    assert run.t.size == 11
    assert run.t[-1] == 1.0
    assert (args.t_end, args.samples, args.scheme, args.tol) == (1.0, 11, "expm", 1e-6)
    assert (loop_args.t_end, loop_args.samples) == (1.0, 11)
    args = build_parser().parse_args(["simulate", "wave"])
    assert (args.t_end, args.samples) == (5.0, 501)  # the registered table is back


def test_a_changed_default_method_and_count_reach_the_spectrum():
    fd = replace(DEFAULTS, method="fd", spectrum=replace(DEFAULTS.spectrum, count=2))
    with using(fd):
        report = Observer(load_builtin("wave"), sensors=[2], gain=0.5).spectrum()
        args = build_parser().parse_args(["spectrum", "wave"])
    assert (report.method, len(report.rightmost)) == ("fd", 2)
    assert (args.method, args.count) == ("fd", 2)
    assert method_or_default(None) == "galerkin"


def test_the_table_is_read_only_and_in_force_only_inside_its_block():
    with pytest.raises(FrozenInstanceError):
        DEFAULTS.simulation.samples = 11  # type: ignore[misc]
    with pytest.raises(TypeError):
        DEFAULTS.methods["toy"] = DEFAULTS.entry("galerkin")  # type: ignore[index]
    seen = []
    with using(QUICK):
        # another thread sees the registered table: using() is this thread's only
        worker = threading.Thread(target=lambda: seen.append(current().simulation.samples))
        worker.start()
        worker.join()
        with pytest.raises(RuntimeError), using(DEFAULTS):
            raise RuntimeError("a failure inside the block")
        assert current() is QUICK
    assert seen == [501]
    assert current() is DEFAULTS


def test_bad_tables_are_refused_by_name():
    refused = pytest.raises(ArgumentError, match="table must be a Defaults; found dict")
    with refused, using({"samples": 11}):  # type: ignore[arg-type]
        pass
    with pytest.raises(NumericError, match="the default method must be one of"):
        Defaults(method="chebyshev")
    with pytest.raises(TypeError, match="unexpected keyword argument 'resoluton'"):
        DEFAULTS.entry("galerkin").with_row(1, resoluton=10)
    assert DEFAULTS.describe("resolution") == "galerkin 40 (16 for N >= 3), fd 70"
    assert DEFAULTS.discretization("fd", 2).abscissa_tol == 1e-3
