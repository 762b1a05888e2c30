"""The design object and the flat namespace (issue 11), one validation for every command
and arguments checked by every public function (issue 12, items 7 and 8).

Expected values: the wave with the damper u_z(1) = -k u_t(1) has the exact abscissa
½ ln|(1 - k)/(1 + k)| (DESIGN-level closed form, also in
tests/numeric/spectrum/test_numeric_spectrum.py);
the string's Proposition 3.2 constant for sensor 2 and gain k is derived in
test_kappa_reads_the_same_everywhere.
"""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest
import sympy
from paths import ROOT

import phdesign as phd
from phdesign.cli import main
from phdesign.core.errors import (
    ArgumentError,
    ModelError,
    ModelFileError,
    NumericError,
    ObserverError,
    PhdesignError,
)
from phdesign.io import model_from_dict, read_model


def run(capsys, *argv):
    status = main(list(argv))
    out, err = capsys.readouterr()
    return status, out, err


@pytest.fixture(scope="module")
def wave():
    return phd.load("wave")


@pytest.fixture(scope="module")
def beam():
    return phd.load("euler-bernoulli")


# ----------------------------------------------------------------------------- namespace
def test_import_phdesign_and_plots_stay_light():
    probe = (
        "import sys, phdesign\n"
        "light = not any(m in sys.modules for m in ('sympy', 'numpy', 'matplotlib'))\n"
        "import phdesign.plots\n"
        "print(light, 'sympy' in sys.modules, 'matplotlib' in sys.modules)\n"
    )
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["True", "False", "False"]


def test_flat_namespace_names_every_entry_point():
    assert phd.Observer.__module__ == "phdesign.design.observer"
    assert phd.search_sensors is phd.symbolic.search.search_sensors
    assert {"load", "Observer", "classify", "port_inverse", "spectrum"} <= set(dir(phd))
    assert set(phd.__all__) <= set(dir(phd))
    # the names phdesign/__init__.py builds them with are not phdesign's (issue 28)
    assert not {"annotations", "importlib", "Any", "TYPE_CHECKING"} & set(dir(phd))
    with pytest.raises(AttributeError, match="no attribute 'nope'"):
        _ = phd.nope


def test_version_is_defined_once():
    import tomllib

    project = tomllib.loads((ROOT / "pyproject.toml").read_text())
    assert "version" not in project["project"]
    assert project["project"]["dynamic"] == ["version"]
    assert project["tool"]["setuptools"]["dynamic"]["version"] == {"attr": "phdesign.__version__"}


# ----------------------------------------------------------------------------- observer
def test_observer_forms_are_one_validation(wave, beam):
    by_index = phd.Observer(beam, sensors=[3, 4], gain=[0.1, 1])
    by_matrix = phd.Observer(
        beam, C_m=np.array([[0, 0, 1, 0], [0, 0, 0, 1]]), gain=np.diag([0.1, 1])
    )
    assert by_index == by_matrix  # exact: 0.1 is read as 1/10 both ways
    assert sympy.diag(sympy.Rational(1, 10), 1) == by_index.L
    assert phd.Observer(wave, sensors=2).L is None  # no gain yet: only tune() applies
    with pytest.raises(ObserverError, match="classify needs a gain"):
        phd.Observer(wave, sensors=2).classify()
    with pytest.raises(ObserverError, match=r"either sensors=.* or C_m=.*found both"):
        phd.Observer(wave, sensors=[2], C_m=[[0, 1]])
    with pytest.raises(ObserverError, match="output index 3 is out of range"):
        phd.Observer(wave, sensors=[3], gain=1)


def test_numeric_methods_refuse_a_symbolic_gain_and_say_what_to_do(wave):
    obs = phd.Observer(wave, sensors=[2], gain="symbolic")
    assert obs.classify().verdict == "exponential"  # exact, for every positive gain
    for method in (obs.spectrum, obs.simulate, lambda: obs.statespace("error")):
        with pytest.raises(ObserverError, match=r"needs numbers for L.*give numbers.*classify"):
            method()


def test_tune_returns_a_new_observer_carrying_the_report(wave):
    # damped wave: α(k) = ½ ln|(1 - k)/(1 + k)| tends to -∞ at k = 1, where the spectrum is
    # empty (extinction in finite time): the tuned gain is 1, reported as extinction with no
    # abscissa (issue 10 item 7), which beats any finite one such as the start ½ ln(1/3)
    obs = phd.Observer(wave, sensors=[2], gain=0.5)
    tuned = obs.tune(starts=1, resolution=12)  # a small pair: the optimum is a boundary one
    assert sympy.Matrix([[sympy.Rational(1, 2)]]) == obs.L
    assert obs.tuning is None
    assert tuned.C_m == obs.C_m
    assert np.array_equal(np.array(tuned.L.tolist(), dtype=float), tuned.tuning.gain)
    assert abs(float(tuned.L[0, 0]) - 1) < 1e-3
    assert tuned.tuning.status == "extinction"
    assert tuned.tuning.spectral_abscissa is None
    assert tuned.tuning.report.unbounded_below
    assert "tuned_abscissa" in repr(tuned)
    assert len(repr(tuned)) <= 300


def test_parameters_reach_classification_and_numbers(beam):
    # every plant mode of the undamped... damped beam has Re λ = -d/2 (DESIGN numbers)
    plant = phd.Plant(beam, parameters={"d": 0.5})
    assert plant.spectrum().spectral_abscissa == pytest.approx(-0.25, abs=1e-10)
    assert plant.design_model.parameter_defaults[sympy.Symbol("d", real=True)] == sympy.Rational(
        1, 2
    )


def test_initial_state_uses_the_parameters_of_the_numeric_model(wave):
    # issue 11 bug: rho = 4 gave x1(1) = 1; x1 = rho*z at z = 1 is 4
    from phdesign.numeric.bridge import to_numeric
    from phdesign.numeric.inputs import initial_state_function

    nm = to_numeric(wave, {"rho": 4})
    x0 = initial_state_function("x1: rho*z", nm, model=wave)
    assert x0(np.array([1.0]))[0, 0] == 4.0
    # e1 = 1 means x1 = rho e1 (H = diag(1/rho, T)): 4 again
    assert initial_state_function("e1: 1", nm)(np.array([1.0]))[0, 0] == 4.0


# ----------------------------------------------------------------------------- item 7
@pytest.mark.parametrize(
    "argv",
    [
        ("classify", "wave", "--cm", "[[0,0]]"),
        ("spectrum", "wave", "--cm", "[[0,0]]", "--gain", "1"),
        ("simulate", "wave", "--cm", "[[0,0]]", "--gain", "1", "--t-end", "0.1"),
        ("tune", "wave", "--cm", "[[0,0]]", "--starts", "1"),
    ],
)
def test_every_command_refuses_a_rank_deficient_C_m(capsys, argv):
    # issue 12 item 7: tune wave --cm '[[0,0]]' reported an "optimal, converged" gain
    status, out, err = run(capsys, *argv)
    assert status == 2
    assert out == ""
    assert "--cm must have full row rank (independent measurements); expected rank 1" in err


def test_numeric_functions_refuse_what_classify_refuses(wave):
    from phdesign.numeric.bridge import to_numeric
    from phdesign.numeric.spectrum.converged import spectrum
    from phdesign.numeric.time.options import SimulationOptions
    from phdesign.numeric.time.simulation import simulate
    from phdesign.numeric.tuning.search import tune

    nm = to_numeric(wave)
    singular = np.array([[0.0, 0.0]])
    for call in (
        lambda: spectrum(nm, singular, np.eye(1)),
        lambda: simulate(nm, singular, np.eye(1), options=SimulationOptions(t_end=0.1)),
        lambda: tune(nm, singular),
    ):
        with pytest.raises(ObserverError, match="full row rank"):
            call()
    with pytest.raises(ObserverError, match="L \\+ Lᵀ must be positive definite"):
        spectrum(nm, np.array([[0.0, 1.0]]), np.array([[-1.0]]))


# ----------------------------------------------------------------------------- item 8
def test_public_functions_name_their_arguments(wave, beam):
    from bad_inputs import BEAM

    from phdesign.numeric.bridge import to_numeric
    from phdesign.numeric.spectrum.converged import spectrum
    from phdesign.numeric.time.options import SimulationOptions
    from phdesign.numeric.time.simulation import simulate

    nm = to_numeric(wave)

    def string(**extra):
        return phd.BCPHS.define(
            name="s",
            interval=(0, 1),
            order=1,
            P={1: [[0, 1], [1, 0]]},
            H=[[1, 0], [0, 1]],
            inputs=["e1(0)", "e2(1)"],
            outputs=["-e2(0)", "e1(1)"],
            **extra,
        )

    cases = [
        (
            lambda: phd.derive_ports("wave"),
            ArgumentError,
            r"model: expected a BCPHS.*load\('wave'\)",
        ),
        (
            lambda: to_numeric(None),
            ArgumentError,
            r"model: expected a BCPHS model; found NoneType",
        ),
        (lambda: spectrum("wave"), ArgumentError, r"nm: expected a NumericModel"),
        (lambda: phd.classify(beam, "3,4", "1"), ObserverError, r"C_m: expected a matrix.*'3,4'"),
        (
            lambda: spectrum(nm, count=0),
            NumericError,
            r"count must be a positive integer; found 0",
        ),
        (lambda: spectrum(nm, tol=float("nan")), NumericError, r"tol must be a finite positive"),
        (
            lambda: simulate(nm, options=SimulationOptions(samples=2.5)),
            NumericError,
            r"samples must be an integer >= 2",
        ),
        (
            lambda: simulate(nm, x0=lambda z: np.full((np.size(z), 2), np.nan)),
            NumericError,
            r"x0 must be finite on \[0, 1\]; found nan in component 1 at z = 0",
        ),
        (lambda: simulate(nm, x0="x1: z"), ArgumentError, r"x0 must be a function of z"),
        (lambda: phd.gain_matrix("1", 0), ObserverError, r"q .* must be a positive integer"),
        (lambda: phd.search_sensors("wave"), ArgumentError, r"model: expected a BCPHS"),
        (lambda: phd.load(3), ArgumentError, r"source: expected a built-in model name"),
        (
            lambda: string(state_names=[1, 2]),
            ModelError,
            r"state label 1 must be non-empty text; found 1",
        ),
        (
            lambda: phd.Observer(wave, sensors=[2], gain=1).statespace("loop"),
            ObserverError,
            r"system must be one of 'plant', 'observer', 'error'",
        ),
        (
            lambda: phd.Observer(wave, sensors=[2], gain=1).statespace(modes="some"),
            ObserverError,
            r"modes must be one of 'all', 'resolved'; found 'some'",
        ),
        # issue 30: foreign errors (numpy's reshape, os, AttributeError) and a silent
        # reading of bytes as their code points (gain=b"1" was diag(49, 49))
        (
            lambda: simulate(
                nm, u=lambda t: [1], options=SimulationOptions(t_end=0.1, samples=3, resolution=4)
            ),
            ArgumentError,
            r"u\(t\) must return 2 numbers \(one per input\); found 1 at t = 0",
        ),
        (
            lambda: simulate(
                nm,
                u=lambda t: [np.nan, 0],
                options=SimulationOptions(t_end=0.1, samples=3, resolution=4),
            ),
            NumericError,
            r"u\(t\) must be finite; found nan in input u1 at t = 0",
        ),
        (lambda: read_model(None), ArgumentError, r"path: expected a file name .*NoneType"),
        (lambda: read_model(0), ArgumentError, r"path: expected a file name .*found int 0"),
        (
            lambda: model_from_dict({**BEAM, "matrices": {**BEAM["matrices"], 2: [[1]]}}),
            ModelFileError,
            r"the keys of \[matrices\] must be names \(text\); found 2",
        ),
        (
            lambda: string(displacement=(1, 1)),
            ArgumentError,
            r"displacement must be a Displacement\(component=i, integrations=k\) of two "
            r"integers; found tuple \(1, 1\)",
        ),
        (lambda: phd.classify(wave, [[0, 1]], b"1"), ObserverError, r"gain is bytes b'1'"),
        (
            lambda: phd.classify(wave, [b"\x00\x01"], 1),
            ObserverError,
            r"C_m: row 1 is bytes b'\\x00\\x01'; expected numbers",
        ),
        (
            lambda: phd.gain_matrix(np.array([b"1"]), 1),
            ObserverError,
            r"gain: row 1 is bytes",
        ),
    ]
    for call, error, message in cases:
        with pytest.raises(error, match=message) as info:
            call()
        assert isinstance(info.value, PhdesignError)


def test_only_phdesign_errors_are_bad_input(monkeypatch, capsys):
    # issue 11 bug: an internal ValueError was printed as "bad input" and exit 2
    import phdesign.cli.model_commands as commands

    def broken(args):
        raise ValueError("an internal bug")

    monkeypatch.setattr(commands, "_models", broken)
    with pytest.raises(ValueError, match="an internal bug"):
        main(["models"])


# ----------------------------------------------------------------------------- printing
def test_results_print_what_the_command_line_prints(capsys, wave, beam):
    obs = phd.Observer(beam, sensors=[3, 4], gain=[0.1, 1])
    pairs = [
        (obs.classify(), ("classify", "euler-bernoulli", "--sensors", "3,4", "--gain", "0.1,1")),
        (phd.search_sensors(wave), ("classify", "wave", "--all-sensors")),
        (beam.ports, ("ports", "euler-bernoulli")),
        (beam, ("show", "euler-bernoulli")),
    ]
    for result, argv in pairs:
        status, out, _ = run(capsys, *argv)
        assert status == 0
        assert out == str(result) + "\n", argv
        assert len(repr(result)) <= 300
        assert result._repr_html_().startswith(("<table>", "<p>"))
    assert json.loads(run(capsys, "ports", "wave", "--json")[1]) == wave.ports.to_dict()
    status, out, _ = run(capsys, "classify", "wave", "--sensors", "2", "--json")
    assert json.loads(out) == json.loads(
        json.dumps(phd.Observer(wave, sensors=2, gain=1).classify().to_dict())
    )


def test_simulation_prints_its_csv_and_plots_a_titled_figure(capsys, wave):
    argv = ("simulate", "wave", "--sensors", "2", "--gain", "0.5", "--x0", "x2: sin(pi*z)")
    options = ("--t-end", "0.2", "--samples", "5", "--resolution", "8")
    status, out, err = run(capsys, *argv, *options)
    run_ = phd.Observer(wave, sensors=[2], gain=0.5, resolution=8).simulate(
        "x2: sin(pi*z)", t_end=0.2, samples=5
    )
    assert status == 0
    assert out == str(run_)
    assert err == ""
    assert len(repr(run_)) <= 300
    assert "<table>" in run_._repr_html_()
    fig = run_.plot()
    assert fig._suptitle.get_text() == "wave, sensors y2, L = diag(0.5), galerkin 8"
    # no --x0: the plant is at rest and every series is zero: say so; no --gain: L = I
    status, _, err = run(capsys, "simulate", "wave", "--sensors", "2", *options)
    assert status == 0
    assert "warning: no --gain given: the observer uses L = I" in err
    assert "warning: no --x0 given: the plant starts at rest" in err
    # at rest but driven by an input: the series are not zero, and nothing says they are
    status, _, err = run(capsys, "simulate", "wave", "--u", "u2: sin(2*t)", *options)
    assert status == 0
    assert "no --x0 given" not in err


def test_kappa_reads_the_same_everywhere(capsys, wave):
    # string, sensor y2 = e1(1), gain k = 0.5: the error BC is e2(1) = -k e1(1), so
    # ||e(1)||² = (1 + k²) e1(1)² and LHS = k e1(1)²: κ* = k/(1 + k²) = 0.4 exactly
    classification = phd.Observer(wave, sensors=[2], gain=0.5).classify()
    assert classification.result("3.2", 2).kappa == sympy.Rational(2, 5)
    table = str(classification)
    search = str(phd.search_sensors(wave, gain=0.5))
    assert "3.2   2   yes    0.4 " in table
    assert "holds with κ* = 0.4" in classification.result("3.2", 2).reason
    assert "\n2                        exponential   3.2.2   0.4\n" in search
    # N = 1: no rows of the order-2 propositions, one line says why
    assert "n/a" not in table
    assert "not applicable: Proposition 3.3 (stated for N = 2; N = 1)" in table


def test_proposition_34_rows_use_the_models_components(beam):
    # beam partition x1 = (momentum), x2 = (curvature): e₁'(b) of the paper is ẽ1'(1)
    result = phd.Observer(beam, sensors=[3, 4], gain=1).classify().result("3.4", 3)
    assert result.rhs == "‖ẽ(1)‖² + ‖ẽ1'(1)‖² + ‖ẽ1(0)‖²"
    symbolic = str(phd.search_sensors(beam, gain="symbolic"))
    assert "depends on L" in symbolic
    assert "—" not in symbolic.split("\n")[5]


def test_negative_gains_are_read_as_values(capsys):
    # argparse would take -1,1 for an option; the design's own check answers instead
    status, _, err = run(
        capsys, "classify", "euler-bernoulli", "--sensors", "3,4", "--gain", "-1,1"
    )
    assert status == 2
    assert "L + Lᵀ must be positive definite" in err


def test_spectrum_with_sensors_needs_a_gain(capsys):
    status, _, err = run(capsys, "spectrum", "wave", "--sensors", "2")
    assert status == 2
    assert "spectrum --sensors/--cm needs --gain" in err


def test_help_states_defaults_and_no_design_notes(capsys):
    for command in ("simulate", "tune", "spectrum", "classify"):
        with pytest.raises(SystemExit):
            main([command, "--help"])
        text = capsys.readouterr().out
        assert "DESIGN.md" not in text
        assert "default" in text
    with pytest.raises(SystemExit):
        main(["simulate", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    for default in ("final time; default: 5.0", "default: 501", "default: expm"):
        assert default in text
    assert "symbolic" not in text  # numeric commands do not advertise symbolic gains


# ----------------------------------------------------------------------------- plots
def test_plots_are_not_pyplots_and_energies_have_no_offset(wave):
    import matplotlib.pyplot as plt

    from phdesign import plots

    before = plt.get_fignums()
    run_ = phd.Plant(wave, resolution=8).simulate("x2: sin(pi*z)", t_end=0.5, samples=11)
    fig = plots.plot_hamiltonians(run_)
    assert plt.get_fignums() == before  # never shown twice by the inline backend
    linear = fig.axes[0]
    assert linear.get_ylim()[0] == 0.0  # energies from zero: a conserved H is flat
    formatter = linear.yaxis.get_major_formatter()
    assert formatter.get_useOffset() is False


def test_spectrum_legend_lists_only_what_is_in_view():
    from phdesign import plots

    lam = np.array([-1 + 2j, -1 - 2j, -0.1 + 90j])
    fig = plots.plot_spectrum(lam, np.array([True, True, False]), ylim=(-5, 5))
    texts = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert texts == ["resolved (agree at two resolutions)"]  # 90j is out of view


def test_library_raises_no_plain_value_errors(beam, monkeypatch):
    # issue 11 bug: plain ValueErrors outside the error family (classify's method, the
    # exact path of the certificate, the partition of Proposition 3.4)
    import phdesign.symbolic.certificate as certificate
    from phdesign.symbolic.propositions import VARIANTS

    with pytest.raises(ObserverError, match="method must be one of 'auto', 'exact', 'float'"):
        phd.classify(beam, phd.sensor_matrix([4], 4), 1, method="bogus")
    monkeypatch.setattr(certificate, "_exact_kappa", lambda poly: None)  # no closed form
    with pytest.raises(ObserverError, match="method='exact': no exact root"):
        phd.classify(beam, phd.sensor_matrix([4], 4), 1, method="exact")
    with pytest.raises(ObserverError, match="needs the partition"):
        VARIANTS[8].traces(order=2, size=2)


def test_atomic_write_refuses_what_is_neither_text_nor_bytes(tmp_path):
    """`atomic_write('x.out', 123)` wrote 123 zero bytes (bytes(123)) and raised nothing."""
    from phdesign.io import atomic_write

    for data in (123, None, 1.5, ["a"]):
        with pytest.raises(ArgumentError, match="text: expected text or bytes to write"):
            atomic_write(tmp_path / "x.out", data)
    assert list(tmp_path.iterdir()) == []
    atomic_write(tmp_path / "x.out", bytearray(b"kept"))
    assert (tmp_path / "x.out").read_bytes() == b"kept"
