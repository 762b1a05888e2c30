"""The one registry of per-method defaults (numeric/discretization/defaults.py) is in force."""

from __future__ import annotations

import dataclasses

import pytest
from numeric_models import BUILTINS, numeric

from phdesign.core.errors import NumericError
from phdesign.numeric.discretization.defaults import (
    FD,
    GALERKIN,
    defaults_for,
    spectrum_resolutions,
)
from phdesign.numeric.discretization.galerkin import resolve_basis
from phdesign.numeric.discretization.registry import discretize
from phdesign.numeric.spectrum.converged import default_resolutions


@pytest.mark.parametrize("name", BUILTINS)
def test_discretize_and_spectrum_read_the_registry(name):
    nm = numeric(name)
    row = defaults_for("galerkin", nm.order)
    d = discretize(nm)
    assert d.resolution == row.resolution
    assert d.info["basis"] == row.basis == resolve_basis(None, nm.order)
    # spectrum.default_resolutions (spectrum's own copy until it reads the registry)
    assert default_resolutions(nm, "galerkin") == spectrum_resolutions(nm.order, "galerkin")
    if nm.order <= 2:
        assert default_resolutions(nm, "fd") == spectrum_resolutions(nm.order, "fd")
        assert discretize(nm, "fd").resolution == FD[nm.order].resolution


def test_registry_is_frozen_and_says_what_it_does_not_know():
    with pytest.raises(dataclasses.FrozenInstanceError):
        GALERKIN[1].resolution = 10  # type: ignore[misc]
    with pytest.raises(TypeError):
        GALERKIN[4] = GALERKIN[3]  # type: ignore[index]
    assert defaults_for("galerkin", 7) == GALERKIN[3]
    assert spectrum_resolutions(3, "galerkin", "legendre") == (8, 48)
    with pytest.raises(NumericError, match="unknown discretization method 'chebyshev'"):
        defaults_for("chebyshev", 1)
    with pytest.raises(NumericError, match="basis applies to method='galerkin' only"):
        discretize(numeric("wave"), "fd", 10, basis="scaled")
