r"""``Observer.export`` and ``phd.Loop``: the design object delegates, exactly, and stays lazy.

``obs.export(...)`` must return what :func:`phdesign.numeric.sampled.export.export_observer`
returns for the same numbers (the same matrices, bit for bit, and the same JSON), and
refuse bad arguments with phdesign's errors naming the argument.  The discretization's
mathematics (exactness, the averaged sampler's dissipativity, aliasing of point samples) is
tested in tests/test_sampled*.py against fine-step references; here one property that does
not go through the exporter: under the ``point`` sampler the continuous observer
:math:`\dot{\hat x} = A_o\hat x + B_o v` runs with :math:`v_k` held over the period, so
(Van Loan) :math:`[A\ B] = [I\ 0]\exp(\begin{bmatrix}A_o & B_o\\ 0 & 0\end{bmatrix} dt)`
for the continuous observer the export reports.
"""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest
from scipy.linalg import expm

import phdesign as phd
from phdesign.core.defaults import current
from phdesign.core.errors import ArgumentError, NumericError, ParameterError
from phdesign.design.loop import Loop
from phdesign.design.observer import Observer
from phdesign.models import load_builtin
from phdesign.numeric.sampled.export import export_observer

K = 0.5
DT = 1e-2


@pytest.fixture(scope="module")
def string():
    return phd.Observer(phd.load("wave"), sensors=[2], gain=K)


def test_export_is_the_export_function_exactly(string):
    mine = string.export(dt=DT, order=12)
    direct = export_observer(
        phd.to_numeric(phd.load("wave")),
        np.array([[0.0, 1.0]]),
        np.array([[K]]),
        dt=DT,
        order=12,
        model_name="wave",
    )
    assert type(mine) is type(direct)
    for name in ("A", "B", "C", "D", "energy_matrix"):
        assert np.array_equal(getattr(mine, name), getattr(direct, name)), name
    assert mine.to_dict() == direct.to_dict()
    assert str(mine) == str(direct)
    assert (mine.order, mine.inputs, mine.sampler) == (12, ("u1", "u2", "y2"), "average")


def test_export_with_verification_passes_the_initial_state_text(string):
    x0 = "x1: 0, x2: z - 0.5"
    mine = string.export(
        dt=DT, order=12, verify=True, x0=x0, t_end=1.0, plant_resolution=24, sampler="point"
    )
    nm = phd.to_numeric(phd.load("wave"))
    from phdesign.numeric.inputs import initial_state_function

    direct = export_observer(
        nm,
        np.array([[0.0, 1.0]]),
        np.array([[K]]),
        dt=DT,
        order=12,
        sampler="point",
        verify=True,
        x0=initial_state_function(x0, nm),
        x0_text=x0,
        t_end=1.0,
        plant_resolution=24,
        model_name="wave",
    )
    assert mine.to_dict() == direct.to_dict()
    assert mine.verification is not None
    assert mine.verification.x0 == x0


def test_point_sampled_update_is_the_held_continuous_observer(string):
    # [A B] = [I 0] expm([[A_o, B_o], [0, 0]] dt) (module docstring).  1e-12: two
    # evaluations of the exponential of a 15 x 15 matrix of norm < 1 in double precision.
    sampled = string.export(dt=DT, order=12, sampler="point", design="given")
    cont = sampled.continuous
    assert cont is not None
    n, m = cont.B.shape
    augmented = np.zeros((n + m, n + m))
    augmented[:n, :n], augmented[:n, n:] = cont.A, cont.B
    step = expm(augmented * DT)[:n]
    np.testing.assert_allclose(sampled.A, step[:, :n], atol=1e-12, rtol=0)
    np.testing.assert_allclose(sampled.B, step[:, n:], atol=1e-12, rtol=0)
    np.testing.assert_array_equal(sampled.C, cont.C)
    np.testing.assert_array_equal(sampled.D, cont.D)


def test_export_uses_the_designs_parameters():
    beam = phd.load("euler-bernoulli")
    obs = phd.Observer(beam, sensors=[3, 4], gain=[0.1, 1], parameters={"d": 0.5})
    direct = export_observer(
        phd.to_numeric(beam, {"d": 0.5}),
        np.eye(4)[2:],
        np.diag([0.1, 1.0]),
        dt=1e-3,
        order=16,
        points=(0.5, 1.0),
        model_name=beam.name,
    )
    mine = obs.export(dt=1e-3, order=16, points=[0.5, 1.0])
    assert mine.to_dict() == direct.to_dict()
    assert mine.outputs[-2:] == ("w(0.5)", "w(1)")
    # one point may be given as a number
    assert obs.export(dt=1e-3, order=16, points=1.0).outputs[-1] == "w(1)"


BAD_EXPORT = [
    ({"dt": 0}, NumericError, r"^dt must be a finite positive number"),
    ({"dt": float("nan")}, NumericError, r"^dt must be a finite positive number"),
    ({"dt": "a"}, NumericError, r"^dt must be a finite positive number.*found 'a'"),
    ({"sampler": "zoh"}, NumericError, r"unknown sampler 'zoh'; expected one of average, point"),
    ({"order": 0}, NumericError, r"^order must be a positive integer"),
    ({"order": 2.5}, NumericError, r"^order must be a positive integer"),
    ({"order": 10**6}, NumericError, r"^order 1000000 needs a verification plant"),
    ({"reduction": "x"}, NumericError, r"unknown reduction 'x'"),
    ({"tol": -1}, NumericError, r"^tol must be a finite positive number; found -1"),
    ({"output_tol": 0}, NumericError, r"^output_tol must be a finite positive number"),
    ({"x0": 3}, ArgumentError, r"^x0 must be text .* found int"),
    ({"x0": "x7: 1"}, ParameterError, r"unknown component 'x7'"),
    ({"t_end": -1}, NumericError, r"^t_end must be a finite positive number"),
    ({"plant_resolution": 0}, NumericError, r"^plant_resolution must be at least"),
    ({"points": 0.5}, NumericError, r"^points: model 'wave' has no displacement"),
    ({"verify": "yes"}, ArgumentError, r"^verify must be True or False; found 'yes'"),
]


@pytest.mark.parametrize(("kwargs", "exc", "match"), BAD_EXPORT)
def test_export_refuses_bad_arguments_by_name(string, kwargs, exc, match):
    with pytest.raises(exc, match=match):
        string.export(**{"dt": DT, **kwargs})


@pytest.mark.parametrize(
    ("points", "match"),
    [(2.0, r"^points: expected numbers in \[0, 1\]; found 2"), ("a", r"^points: expected")],
)
def test_export_refuses_displacement_points_off_the_beam(points, match):
    obs = phd.Observer(phd.load("euler-bernoulli"), sensors=[3, 4], gain=[0.1, 1])
    with pytest.raises(NumericError, match=match):
        obs.export(dt=1e-3, points=points)


def test_export_options_are_keywords_and_typos_are_refused(string):
    with pytest.raises(TypeError):
        string.export(DT)  # type: ignore[misc]
    with pytest.raises(TypeError, match="samplr"):
        string.export(dt=DT, samplr="point")  # type: ignore[call-arg]


# ----------------------------------------------------------------------------- the loop
def test_loop_is_reachable_from_the_flat_namespace_and_takes_an_observer():
    beam = phd.load("euler-bernoulli")
    obs = phd.Observer(beam, sensors=[2], gain=1, parameters={"d": 0.5})
    assert phd.Loop is Loop
    from_observer = phd.Loop(obs, actuate=4, feedback=1)
    by_hand = Loop(beam, actuate=4, feedback=1, sensors=[2], gain=1, parameters={"d": 0.5})
    assert from_observer.to_dict() == by_hand.to_dict()
    assert from_observer.model.parameters == by_hand.model.parameters


def test_import_stays_light_and_the_new_names_load_on_first_use():
    probe = (
        "import sys, phdesign as phd\n"
        "heavy = ('sympy', 'numpy', 'scipy', 'control', 'matplotlib', 'phdesign.design.loop')\n"
        "print(any(m in sys.modules for m in heavy))\n"
        "phd.Loop, phd.NoiseReport, phd.Tradeoff, phd.SampledObserver\n"
        "print(any(m in sys.modules for m in ('control', 'matplotlib')))\n"
    )
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["False", "False"]
    assert {"Loop", "NoiseReport", "Tradeoff", "SampledObserver"} <= set(phd.__all__)


def test_the_library_the_design_object_and_the_cli_share_the_export_defaults():
    # one row of defaults (phdesign.core.defaults, its export row) serves the three entry
    # points: the signatures say None ("the registered default") and the command line
    # reads the row, so a change of policy there reaches every one of them
    import inspect
    from dataclasses import replace

    from phdesign.cli import build_parser
    from phdesign.core.defaults import DEFAULTS, current, using
    from phdesign.numeric.sampled.order import select_order

    expected = {"sampler": "average", "tol": 1e-6, "output_tol": 1e-3, "t_end": 5.0}
    assert {k: getattr(current().export, k) for k in expected} == expected
    for function in (export_observer, phd.Observer.export):
        parameters = inspect.signature(function).parameters
        assert {k: parameters[k].default for k in expected} == dict.fromkeys(expected), function
    parameters = inspect.signature(select_order).parameters
    assert (parameters["tol"].default, parameters["output_tol"].default) == (None, None)
    argv = ["export", "wave", "--sensors", "2", "--dt", "0.01", "--format", "json", "-o", "x.json"]
    args = build_parser().parse_args(argv)
    assert {k: getattr(args, k) for k in expected} == expected
    changed = {"sampler": "point", "tol": 1e-4, "output_tol": 1e-2, "t_end": 2.0}
    with using(replace(DEFAULTS, export=replace(DEFAULTS.export, **changed))):
        args = build_parser().parse_args(argv)
    assert {k: getattr(args, k) for k in expected} == changed


def test_the_symbolic_commands_never_load_the_numeric_layer():
    # the symbolic layer never imports the numeric one, and the command line builds every
    # subcommand's parser (export's defaults included) without it: classify and ports
    # start fast (benchmarks/cli_startup.py prints the same probe)
    probe = (
        "import contextlib, io, sys\n"
        "from phdesign.cli import main\n"
        "with contextlib.redirect_stdout(io.StringIO()):\n"
        "    main(sys.argv[1:])\n"
        "heavy = ('phdesign.numeric', 'scipy', 'control', 'matplotlib')\n"
        "print(sorted(m for m in heavy if m in sys.modules))\n"
    )
    for argv in (["ports", "euler-bernoulli", "--json"], ["classify", "wave", "--sensors", "2"]):
        out = subprocess.run(
            [sys.executable, "-c", probe, *argv], capture_output=True, text=True, check=True
        )
        assert out.stdout.strip() == "[]", (argv, out.stdout, out.stderr)


def test_observer_statespace_takes_modes_resolved_as_the_lower_level_exports_do():
    # wave, sensor 2, k = 1/2: the exact error eigenvalues are ½ ln|(1-k)/(1+k)| + i(m+½)π
    # (DESIGN.md); the resolved modal truncation keeps only poles that agree between p and
    # 1.5p to the drift rule's relative tolerance, so each lies that close to an exact one
    pytest.importorskip("control")
    obs = Observer(load_builtin("wave"), sensors=[2], gain=0.5)
    alpha = 0.5 * math.log(1 / 3)
    full, cut = obs.statespace("error", 24), obs.statespace("error", 24, modes="resolved")
    assert cut.nstates == len(cut.truncation.kept) < full.nstates
    rtol = current().discretization("galerkin", 1).resolved_rtol
    for pole in cut.poles():
        m = round(abs(pole.imag) / math.pi - 0.5)
        exact = complex(alpha, math.copysign((m + 0.5) * math.pi, pole.imag))
        assert abs(pole - exact) <= rtol * abs(pole), (pole, exact)
    assert np.max(full.poles().real) > alpha + 0.1  # the unresolved modes "all" keeps
    for system in ("plant", "observer"):
        reduced = obs.statespace(system, 24, modes="resolved")
        assert reduced.nstates < obs.statespace(system, 24).nstates
        assert reduced.state_labels[0] == "mode1"
