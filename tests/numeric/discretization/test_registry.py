"""The registry of discretization methods and their entries in the table of defaults.

A method is one class (registered by its name) and one entry of the table
(:mod:`phdesign.core.defaults`); the command line, the design objects, the sweep and
the spectrum read both, so a method registered here (Galerkin under another name) is
offered by ``phdesign spectrum --help`` and computes a spectrum, and a tolerance changed
in the table changes what the spectrum does.
"""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest
from numeric_models import BUILTINS, PAPER_SENSORS, numeric

from phdesign.cli import main
from phdesign.core.defaults import DEFAULTS, current, using
from phdesign.core.errors import NumericError
from phdesign.design.plant import Plant
from phdesign.models import load_builtin
from phdesign.numeric.discretization.base import Method, check_registered
from phdesign.numeric.discretization.galerkin import Galerkin, galerkin, resolve_basis
from phdesign.numeric.discretization.registry import discretize
from phdesign.numeric.spectrum.converged import default_resolutions, spectrum
from phdesign.numeric.spectrum.evaluator import AbscissaEvaluator
from phdesign.numeric.statespace import state_labels
from phdesign.sweep.jobs import get_job

TOY = "toy"  # no hyphen: the help wraps its lines at hyphens


@pytest.fixture
def toy():
    """Galerkin registered as a second method: one class and one entry of the table."""

    class Toy(Galerkin, name=TOY):
        @classmethod
        def build(cls, nm, resolution, basis):
            return dataclasses.replace(galerkin(nm, resolution, basis), method=cls.name)

    entry = dataclasses.replace(
        current().entry("galerkin"), name=TOY, summary="Galerkin again (a test's method)"
    )
    try:
        with using(current().with_method(entry)):
            yield Toy
    finally:
        Method.unregister(TOY)


@pytest.mark.parametrize("name", BUILTINS)
def test_discretize_and_spectrum_read_the_table(name):
    nm = numeric(name)
    row = current().discretization("galerkin", nm.order)
    d = discretize(nm)
    assert (d.method, d.resolution) == ("galerkin", row.resolution)
    assert d.info["basis"] == row.basis == resolve_basis(None, nm.order)
    assert default_resolutions(nm, "galerkin") == (row.spectrum_start, row.spectrum_max)
    # staggered FD needs mixed causality; a tip mass or a motor imposes the end's velocity,
    # so the string and beam that carry one have velocity inputs at both ends (galerkin only)
    if nm.order <= 2 and name not in ("string-tip-mass", "beam-tip-body", "string-motor"):
        fd = current().discretization("fd", nm.order)
        assert default_resolutions(nm, "fd") == (fd.spectrum_start, fd.spectrum_max)
        assert discretize(nm, "fd").resolution == fd.resolution


def test_the_builders_and_the_table_name_the_same_methods():
    assert Method.registered() == current().method_names == ("galerkin", "fd")
    check_registered()
    without_fd = dataclasses.replace(DEFAULTS, methods={"galerkin": DEFAULTS.entry("galerkin")})
    with pytest.raises(
        NumericError, match=r"the table of defaults has the methods \('galerkin',\)"
    ):
        check_registered(without_fd)
    ghost = dataclasses.replace(DEFAULTS.entry("galerkin"), name="ghost")
    unbuilt = pytest.raises(
        NumericError, match="no discretization method is registered as 'ghost'"
    )
    with using(DEFAULTS.with_method(ghost)), unbuilt:
        discretize(numeric("wave"), "ghost", 10)
    with pytest.raises(NumericError, match="registered already"):

        class Again(Method, name="galerkin"):
            pass


def test_the_table_is_read_only_and_says_what_it_does_not_know():
    galerkin_rows = DEFAULTS.entry("galerkin")
    with pytest.raises(dataclasses.FrozenInstanceError):
        galerkin_rows.at(1).resolution = 10  # type: ignore[misc]
    with pytest.raises(TypeError):
        galerkin_rows.rows[4] = galerkin_rows.at(3)  # type: ignore[index]
    assert galerkin_rows.at(7) == galerkin_rows.rows[3]
    # the plain Legendre basis refines as far as the scaled one (no cap of its own)
    assert spectrum(numeric("airy"), np.eye(3), np.eye(3), basis="legendre").converged
    with pytest.raises(
        NumericError, match="method must be one of 'galerkin', 'fd'; found 'chebyshev'"
    ):
        discretize(numeric("wave"), "chebyshev", 10)
    with pytest.raises(NumericError, match="basis: method 'fd' has no bases"):
        discretize(numeric("wave"), "fd", 10, basis="scaled")
    with pytest.raises(NumericError, match="basis: method 'fd' has no bases"):
        spectrum(numeric("wave"), method="fd", basis="scaled")


def test_a_registered_method_is_offered_and_computes(toy, capsys):
    with pytest.raises(SystemExit):
        main(["spectrum", "--help"])
    help_text = capsys.readouterr().out
    assert f"{{galerkin,fd,{TOY}}}" in help_text
    assert "Galerkin again" in help_text
    argv = ["spectrum", "wave", "--sensors", "2", "--gain", "0.5", "--json"]
    assert main([*argv, "--method", TOY]) == 0
    found = json.loads(capsys.readouterr().out)
    assert main(argv) == 0
    reference = json.loads(capsys.readouterr().out)
    assert (found["method"], reference["method"]) == (TOY, "galerkin")
    assert found["spectral_abscissa"] == reference["spectral_abscissa"]  # 1/2 ln(1/3)
    assert Plant(load_builtin("wave"), method=TOY).discrete().method == TOY
    assert TOY in get_job("spectrum").option_values({"method": TOY}).values()


def test_an_unregistered_method_is_refused(capsys):
    # the toy of the test above is gone with its fixture
    assert main(["spectrum", "wave", "--method", TOY]) == 2
    assert "invalid choice" in capsys.readouterr().err
    with pytest.raises(NumericError, match="method must be one of"):
        discretize(numeric("wave"), TOY, 10)


def test_a_changed_tolerance_changes_the_spectrum():
    # the beam (N = 2) with sensors 3, 4: 15 eigenvalues agree to the drift 1e-6 at
    # (20, 30); a drift tolerance of 0.1 in the table's N = 2 row lets 21 count as resolved
    # (23 pass the relative test; the pair -11.01 ± 1139.4i drifts by 10.3, 5 % of the
    # spacing 202 to its neighbour, where a chance match cannot be told from the same mode:
    # the drift test's spacing rule, numeric/spectrum/drift.py, does not count it)
    beam, wave = numeric("euler-bernoulli"), numeric("wave")
    L, C_wave, k = np.diag([0.1, 1.0]), np.array([[0.0, 1.0]]), np.array([[0.5]])
    before = spectrum(beam, PAPER_SENSORS, L)
    wave_before = spectrum(wave, C_wave, k)
    loose = current().entry("galerkin").with_row(2, resolved_rtol=0.1)
    with using(current().with_method(loose)):
        after = spectrum(beam, PAPER_SENSORS, L)
        wave_after = spectrum(wave, C_wave, k)  # its N = 1 row is unchanged
        evaluator = AbscissaEvaluator(beam, PAPER_SENSORS, (20, 30))
    assert (before.resolutions, before.n_resolved) == ((20, 30), 15)
    assert (after.resolutions, after.n_resolved) == ((20, 30), 21)
    assert wave_after.n_resolved == wave_before.n_resolved
    assert evaluator.rtol_resolved == 0.1
    assert spectrum(beam, PAPER_SENSORS, L).n_resolved == 15  # the table is back


@pytest.mark.parametrize("method", ["galerkin", "fd"])
def test_every_method_names_the_coordinates_of_its_states(method):
    # state_labels reads info["coordinates"], whatever the method (no method-only branch)
    d = discretize(numeric("timoshenko"), method, 12)
    labels = state_labels(d)
    assert len(d.info["coordinates"]) == len(labels) == d.dim
    expected = {
        "galerkin": ["e1[0]", "e1[1]", "e1[2]"],  # component-major, degree 0..12
        "fd": ["e2[0]", "e4[0]", "e2[1]"],  # the groups (2, 4), (1, 3), node-major
    }
    assert labels[:3] == expected[method]
