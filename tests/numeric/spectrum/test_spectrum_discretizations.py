"""Discretizations shared by many spectra (a gain map): the same reports, and only their own.

The string with the damper of the observer (sensor y2, gain k < 1) has the error spectrum
½ ln((1 - k)/(1 + k)) + i (m + ½) π, so each report is checked against that closed form
as well as against the report computed without shared discretizations.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from phdesign.core.errors import NumericError
from phdesign.models import load_builtin
from phdesign.numeric.bridge import to_numeric
from phdesign.numeric.spectrum.converged import spectrum
from phdesign.numeric.spectrum.refinement import Discretizations

WAVE = to_numeric(load_builtin("wave"))
SENSOR = np.array([[0.0, 1.0]])


def test_shared_discretizations_give_the_same_reports_bit_for_bit():
    shared = Discretizations(WAVE, "galerkin")
    for k in (0.25, 0.5, 0.75):
        L = np.array([[k]])
        alone = spectrum(WAVE, SENSOR, L)
        together = spectrum(WAVE, SENSOR, L, discretizations=shared)
        assert together.to_dict() == alone.to_dict()
        # 1e-10: the spectrum's own tolerance relative to the rate 1 of the string
        assert abs(together.spectral_abscissa - 0.5 * math.log((1 - k) / (1 + k))) < 1e-10


def test_discretizations_of_another_model_or_method_are_refused():
    beam = to_numeric(load_builtin("euler-bernoulli"))
    L = np.array([[0.5]])
    with pytest.raises(NumericError, match=r"discretizations: expected those of this model"):
        spectrum(WAVE, SENSOR, L, discretizations=Discretizations(beam, "galerkin"))
    with pytest.raises(NumericError, match=r"found 'wave' by 'fd'"):  # galerkin asked
        spectrum(WAVE, SENSOR, L, discretizations=Discretizations(WAVE, "fd"))
