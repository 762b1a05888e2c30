"""Numbers users can trust (issue 10, items 2, 3, 4, 8, 9): each case fails on the old code.

Every reference is derived in the test: a WKB high-frequency limit, the impedance-scaled
damped wave, the lossless (conservative) structure of a model, or a decoupling argument.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import scipy.linalg as sl
from string_models import COUPLED_STRINGS, SENSOR2, honest, string

from phdesign.cli import main
from phdesign.models import load_builtin
from phdesign.numeric.bridge import to_numeric
from phdesign.numeric.discretization.registry import discretize
from phdesign.numeric.spectrum.abscissa import MIN_MODES_ABOVE
from phdesign.numeric.spectrum.converged import spectrum
from phdesign.symbolic.model import BCPHS

# -- item 2: a supremum approached at high frequency -----------------------------------


def test_variable_string_abscissa_is_the_wkb_limit_that_no_mode_attains():
    # WKB: in a smooth medium high-frequency waves u ~ (rho T)^(-1/4) exp(i w (t -+ int dz/c))
    # travel without reflection (c = sqrt(T/rho), impedance Z = sqrt(rho T)).  At z = 1 the
    # damper T u_z = -k u_t reflects them with r = (Z(1) - k) / (Z(1) + k) (d'Alembert), at
    # z = 0 the fixed end with -1; a round trip takes tau = 2 int_0^1 dz / c and multiplies
    # the amplitude by |r|, so Re(lambda_m) -> ln|r| / tau as m -> oo.  Here rho = 1,
    # T = 1 + z: Z(1) = sqrt(2), tau = 4 (sqrt(2) - 1).  The real parts rise toward it
    # (measured: Re = limit - 0.0936/|lambda|^2), so no mode attains the supremum.  The
    # limit is derived from the principal part (numeric/spectrum/branches.py: the characteristic
    # speeds, the transport along them and the reflections of the closed boundary), so it
    # is known to round-off, not extrapolated from the band (it was, to 1e-7, before).
    k = 0.5
    limit = math.log((math.sqrt(2) - k) / (math.sqrt(2) + k)) / (4 * (math.sqrt(2) - 1))
    rep = spectrum(to_numeric(string("1 + z")), SENSOR2, np.array([[k]]))
    assert honest(rep, limit), (rep.spectral_abscissa - limit, rep.digits)
    assert rep.kind == "limit"
    assert rep.converged
    assert abs(rep.spectral_abscissa - limit) <= rep.uncertainty
    assert abs(rep.spectral_abscissa - limit) < 1e-12  # 65 Chebyshev points resolve T = 1 + z
    resolved = rep.eigenvalues[rep.resolved]
    assert np.all(resolved.real < limit)  # a limit that no mode attains
    assert any("root chains" in w and "no mode attains it" in w for w in rep.warnings)


def test_real_parts_tending_to_zero_mean_no_uniform_decay():
    # Timoshenko with the shear sensor y1 alone: the damper acts on the transverse wave; the
    # rotational wave is coupled to it by the zero-order P0 only, so at high frequency it
    # decouples and its modes lose the damping, Re(lambda) ~ -c/|lambda|^2 -> 0 (the
    # coupling enters at second order).  The supremum of the real parts is 0: no uniform
    # exponential decay, whatever a finite band of modes attains.
    # The supremum is derived from the principal part (numeric/spectrum/branches.py: with unit
    # parameters both speeds are 1, so the rotation through P0 stays in the transport of one
    # family, an orthogonal propagator; the damper on the shear force leaves a chain of
    # modulus 1 in the round trip): exactly 0, reported as 0 and converged, no longer an
    # unconverged extrapolation.
    rep = spectrum(to_numeric(load_builtin("timoshenko")), np.array([[1.0, 0, 0, 0]]), np.eye(1))
    assert honest(rep, 0.0), (rep.spectral_abscissa, rep.digits)
    assert rep.converged
    assert rep.kind == "limit"
    assert rep.spectral_abscissa == 0.0  # no decay: reported as 0, not a negative number
    assert rep.no_decay
    assert rep.uncertainty < 1e-12
    # the mechanism: the slowly damped family has Re(lambda) |lambda|^2 nearly constant
    # (a finer pair, whose band reaches beyond |lambda| = 30)
    wide = spectrum(
        to_numeric(load_builtin("timoshenko")),
        np.array([[1.0, 0, 0, 0]]),
        np.eye(1),
        resolution=60,
    )
    lam = wide.eigenvalues[wide.resolved]
    slow = lam[(np.abs(lam.real) < 1e-3) & (lam.imag > 30)]
    product = slow.real * np.abs(slow) ** 2
    assert slow.size >= 4
    np.testing.assert_allclose(product, product[-1], rtol=0.05)


def test_coupled_strings_with_one_damper_claim_no_false_digits():
    # The same decoupling for two strings of speeds 1 and sqrt(2) coupled at order zero with
    # a damper on the first: the second string's modes are damped only through the coupling,
    # which averages out at high frequency (the speeds differ): the supremum is 0.  Each
    # resolution pair used to report a different abscissa "converged to 11 digits".
    sensor = np.array([[0, 0, 1.0, 0]])
    # The limit 0 of the second string's chains is derived (its family's reflections are
    # lossless at both ends): the report is 0, converged, and names the family.
    rep = spectrum(to_numeric(COUPLED_STRINGS), sensor, np.array([[0.5]]), max_resolution=68)
    assert honest(rep, 0.0), (rep.spectral_abscissa, rep.digits)
    assert rep.converged
    assert rep.spectral_abscissa == 0.0
    assert rep.no_decay
    assert any("speed 1.41" in w for w in rep.warnings), rep.warnings


# -- item 3: one definition of the abscissa, printed consistently ----------------------


@pytest.mark.parametrize("resolution", [None, 30, 40])
def test_no_listed_eigenvalue_lies_right_of_the_abscissa(capsys, resolution):
    # The airy plant (u = 0, P0 = 0) is lossless: the energy is conserved, every eigenvalue
    # lies on the imaginary axis and the abscissa is exactly 0.  The printed abscissa must
    # be 0 within its printed accuracy and no listed eigenvalue may lie beyond it.
    argv = ["spectrum", "airy", "--json"]
    argv += [] if resolution is None else ["--resolution", str(resolution)]
    assert main(argv) == 0
    data = json.loads(capsys.readouterr().out)
    alpha = data["spectral_abscissa"]
    accuracy = 10.0 ** (-data["digits"]) * max(1.0, abs(alpha))
    assert abs(alpha) <= accuracy
    assert max(re for re, _ in data["rightmost"]) <= alpha + accuracy
    assert data["uncertainty"] >= max(re for re, _ in data["rightmost"]) - alpha


# -- item 4: enough resolved modes to see the rightmost ones --------------------------


def test_a_converged_report_has_modes_above_the_rightmost():
    # The rule: at least MIN_MODES_ABOVE resolved modes (upper half plane) at higher
    # frequency than the one that gives the abscissa.  Airy's first pair (8, 12) resolves
    # only the zero eigenvalue (e = z^2 - z spans the kernel: e''' = 0 with the three
    # boundary conditions); that cannot be "converged".
    nm = to_numeric(load_builtin("airy"))
    rep = spectrum(nm)
    assert rep.converged
    upper = rep.eigenvalues[rep.resolved & (rep.eigenvalues.imag > 0)]
    assert upper.size >= MIN_MODES_ABOVE
    capped = spectrum(nm, max_resolution=12)
    assert capped.resolutions == (8, 12)
    assert not capped.converged
    assert any("resolved modes lie above the rightmost" in w for w in capped.warnings)


# -- item 8: tolerances relative to the problem's own scales ---------------------------


def test_slow_string_abscissa_uses_its_own_time_scale():
    # rho = 1e8, T = 1e-8: speed c = sqrt(T/rho) = 1e-8, impedance Z = sqrt(rho T) = 1.  The
    # damper T u_z(1) = -k u_t(1) reflects with (Z - k)/(Z + k) once per round trip 2/c, so
    # every eigenvalue has Re = (c/2) ln|(Z - k)/(Z + k)| (k = 3: (1e-8/2) ln(1/2)).
    exact = 0.5e-8 * math.log(1 / 2)
    nm = to_numeric(load_builtin("wave"), {"rho": "1e8", "T": "1e-8"})
    rep = spectrum(nm, SENSOR2, np.array([[3.0]]))
    assert rep.converged
    assert honest(rep, exact)
    assert abs(rep.spectral_abscissa - exact) <= 1e-9 * abs(exact)
    assert not rep.ill_conditioned  # gaps are relative to the rate, not to 1


def test_a_very_long_string_keeps_its_digits():
    # On [0, 1e300] (unit speed and impedance) the abscissa of the damper k is
    # (1/(2 l)) ln|(1 - k)/(1 + k)| with l = 1e300, and the plant is lossless (abscissa 0).
    nm = to_numeric(string("1", b="1e300"))
    rep = spectrum(nm, SENSOR2, np.array([[0.5]]))
    exact = math.log(1 / 3) / 2e300
    assert rep.converged
    assert abs(rep.spectral_abscissa - exact) <= 1e-9 * abs(exact)
    plant = spectrum(nm)
    assert honest(plant, 0.0)
    assert plant.digits < 16  # never more digits than double precision holds


# -- item 9: "unbounded below" only on evidence ----------------------------------------


def test_an_unresolved_lossless_spectrum_is_not_called_extinct():
    # H11 = 2 + sin(300 z) and no damping: J is skew and R = 0, so the energy is conserved,
    # the spectrum lies on the imaginary axis and is infinite (no extinction).  The default
    # degrees (up to 102) cannot resolve 48 wavelengths of H: "not resolved", no number.
    model = BCPHS.define(
        name="wiggly string",
        interval=[0, 1],
        order=1,
        P={1: [[0, 1], [1, 0]]},
        H=[["2 + sin(300*z)", 0], [0, 1]],
        inputs=["e1(0)", "e2(1)"],
        outputs=["-e2(0)", "e1(1)"],
    )
    nm = to_numeric(model)
    d = discretize(nm, "galerkin", 30)
    lam = sl.eigvals(d.closed_matrix(), d.E)
    assert np.max(np.abs(lam.real)) <= 1e-10 * np.max(np.abs(lam))  # conservative
    rep = spectrum(nm)
    assert not rep.unbounded_below
    assert rep.spectral_abscissa is None
    assert rep.kind == "not resolved"
    assert "not resolved at these resolutions" in rep.warnings[0]


def test_extinction_needs_and_gives_evidence():
    # k = 1 is the matched damper: no reflection, the spectrum is empty (DESIGN.md); every
    # discrete eigenvalue leaves the disk |lambda| <= 5 s and decays faster than it turns.
    rep = spectrum(to_numeric(load_builtin("wave")), SENSOR2, np.array([[1.0]]))
    assert rep.unbounded_below
    assert rep.kind == "unbounded below"
    near = rep.eigenvalues[np.argmin(np.abs(rep.eigenvalues))]
    assert abs(near) > 5.0
    assert near.real < -0.5 * abs(near)


# -- the report object ----------------------------------------------------------------


@pytest.mark.parametrize("gain", ["0.5", "1"])
def test_report_prints_what_the_command_line_prints(capsys, gain):
    assert main(["spectrum", "wave", "--sensors", "2", "--gain", gain]) == 0
    out = capsys.readouterr().out
    rep = spectrum(to_numeric(load_builtin("wave")), SENSOR2, np.array([[float(gain)]]))
    assert out == str(rep) + "\n"
    assert len(repr(rep)) <= 300
    assert "<table>" in rep._repr_html_()
    text = json.dumps(rep.to_dict(), allow_nan=False)  # strict JSON, even with inf eigenvalues
    assert {"spectral_abscissa", "rightmost", "converged"} <= set(json.loads(text))
    assert len(rep.to_dict()["resolved"]) == rep.eigenvalues.size


def test_report_plots_its_eigenvalues():
    rep = spectrum(to_numeric(load_builtin("wave")), SENSOR2, np.array([[0.5]]))
    fig = rep.plot()
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert any("resolved" in label for label in labels)
