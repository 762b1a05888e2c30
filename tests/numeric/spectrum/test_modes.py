"""The modal table, the rightmost list's order, round-off real parts and the fd artefacts.

Expected values: the cantilever's natural frequencies ω_k = (β_k L)² √(EI/ρA) / L² with
β_k L the roots of 1 + cos x cosh x = 0 (found here by mpmath, not copied); the damped
beam ρA w_tt + d w_t + EI w'''' = 0, whose modes λ² ρA + d λ + EI β⁴ = 0 give
|λ| = ω_k and ζ_k = d / (2 ρA ω_k) (derived in the test below); the damped string's
λ_m = ½ ln((1 − k)/(1 + k)) + i(m + ½)π (DESIGN.md, exact); the roots of the beam's
characteristic determinant (``tests/characteristic.py``, mpmath).
"""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest
from characteristic import beam_determinant

import phdesign as phd
from phdesign.core.errors import NumericError
from phdesign.numeric.spectrum.drift import pair_spectrum
from phdesign.numeric.spectrum.eigen import roundoff_bound

#: A steel cantilever, 20 mm x 5 mm, 0.8 m: EI = E b h³/12, ρA = ρ b h.
STEEL_EI = 210e9 * 0.02 * 0.005**3 / 12  # 43.75 N m²
STEEL_RHO_A = 7850 * 0.02 * 0.005  # 0.785 kg/m
LENGTH = 0.8


def _cantilever(tmp_path, d: float):
    path = tmp_path / "steel.toml"
    path.write_text(
        'name = "steel cantilever"\n'
        f"interval = [0, {LENGTH}]\norder = 2\n"
        f"[parameters]\nrho = {STEEL_RHO_A!r}\nEI = {STEEL_EI!r}\nd = {d!r}\n"
        '[matrices]\nP0 = [["-d", 0], [0, 0]]\nP2 = [[0, -1], [1, 0]]\n'
        'H = [["1/rho", 0], [0, "EI"]]\n'
        "[ports]\n"
        f'inputs = ["e1(0)", "e1\'(0)", "e2({LENGTH})", "e2\'({LENGTH})"]\n'
        f'outputs = ["e2\'(0)", "-e2(0)", "e1\'({LENGTH})", "-e1({LENGTH})"]\n'
        '[units]\nt = "s"\nz = "m"\n'
    )
    return phd.load(str(path))


def _beta_l(count: int) -> list[float]:
    """Roots of 1 + cos x cosh x = 0 (the clamped-free beam), by mpmath from x ≈ (k − ½)π."""
    with mpmath.workdps(30):
        f = lambda x: 1 + mpmath.cos(x) * mpmath.cosh(x)  # noqa: E731
        return [float(mpmath.findroot(f, (k - 0.5) * math.pi)) for k in range(1, count + 1)]


def _omega(count: int) -> np.ndarray:
    c = math.sqrt(STEEL_EI / STEEL_RHO_A)
    return np.array([x**2 * c / LENGTH**2 for x in _beta_l(count)])


def test_undamped_steel_cantilever_modes_are_the_beam_frequencies(tmp_path):
    report = phd.Plant(_cantilever(tmp_path, 0.0)).spectrum()
    table = report.modes(count=5)
    found = np.array([m.natural_frequency for m in table.modes])
    exact = _omega(5)  # 1.8751² √(EI/ρA)/L² = 41.01 rad/s first
    assert np.allclose(found, exact, rtol=1e-9), (found, exact)
    assert all(m.damping_ratio == 0.0 and m.resolved and m.block == "plant" for m in table.modes)
    assert np.allclose([m.frequency_hz for m in table.modes], exact / (2 * math.pi), rtol=1e-9)
    assert table.units["angular_frequency"] == "rad/s"
    assert table.units["frequency"] == "Hz"
    # the rightmost list ties every real part (round-off) and so lists the lowest modes
    assert np.allclose(np.abs(np.asarray(report.rightmost[::2]).imag), exact[:3], rtol=1e-9)
    assert "Hz" in str(table)
    assert "41.0" in str(table)


def test_damped_cantilever_damping_ratio_is_the_hand_value(tmp_path):
    # ρA λ² + d λ + EI β⁴ = 0: λ = −d/(2ρA) ± i √(ω² − d²/(4ρA²)) with ω² = EI β⁴/ρA,
    # so |λ|² = d²/(4ρA²) + ω² − d²/(4ρA²) = ω² and ζ = −Re λ/|λ| = d/(2 ρA ω)
    d = 2.0
    table = phd.Plant(_cantilever(tmp_path, d)).spectrum().modes(count=4)
    exact = _omega(4)
    assert np.allclose([m.natural_frequency for m in table.modes], exact, rtol=1e-9)
    assert np.allclose([m.damping_ratio for m in table.modes], d / (2 * STEEL_RHO_A * exact))
    assert np.allclose([m.decay_rate for m in table.modes], d / (2 * STEEL_RHO_A), rtol=1e-9)
    damped = np.sqrt(exact**2 - (d / (2 * STEEL_RHO_A)) ** 2)
    assert np.allclose([m.damped_frequency for m in table.modes], damped, rtol=1e-9)


def test_damped_string_error_modes_are_exact():
    # wave (inputs at both ends), sensor 2, gain k: λ_m = ½ ln((1−k)/(1+k)) + i(m+½)π
    k = 0.5
    obs = phd.Observer(phd.Plant(phd.load("wave")), 2, gain=[[k]])
    table = obs.spectrum().modes(count=4)
    alpha = 0.5 * math.log((1 - k) / (1 + k))
    lam = alpha + 1j * (np.arange(4) + 0.5) * math.pi
    assert np.allclose([m.natural_frequency for m in table.modes], np.abs(lam), rtol=1e-10)
    assert np.allclose([m.damping_ratio for m in table.modes], -alpha / np.abs(lam), rtol=1e-9)
    assert {m.block for m in table.modes} == {"error"}
    assert any("error system's modes" in n for n in table.notes())


def test_a_dense_spectrum_shifted_by_spacings_is_not_resolved():
    # coarse: −1 + i k²; fine: the low modes alike, the high ones three modes up plus 5 %
    # of a spacing: within rtol |λ| of *another* mode (the old test passed them)
    k = np.arange(1, 81)
    coarse = -1 + 1j * k.astype(float) ** 2
    fine = coarse.copy()
    high = k > 10
    up = k[high] + 3
    fine[high] = -1 + 1j * (up**2 + 0.05 * (2 * up + 1))
    pair = pair_spectrum(fine, coarse, resolutions=(4, 6), rtol=1e-2, scale=1.0)
    assert pair.resolved.tolist() == (~high).tolist()
    drift = np.abs(fine[high] - (-1 + 1j * up.astype(float) ** 2))
    assert np.all(drift <= 1e-2 * np.abs(fine[high]))  # what the relative test alone allows


def test_a_double_eigenvalue_drifting_with_the_grid_is_still_resolved(monkeypatch):
    # two identical strings: every mode is double (copies 1e-15 apart).  A second-order
    # grid moves both copies alike by 1e-3 |λ| (below rtol = 1e-2): each copy's nearest
    # other eigenvalue is its twin, which is the same mode, so the spacing to reckon with
    # is the next mode's (2k + 1 away): the drift 1e-3 |−1 + i k²| stays under 1 % of it
    # for k = 1..5 (1.4e-3 < 0.03, ..., 2.5e-2 < 0.11).  The rule must not judge the twins
    # by the 1e-15 between them (with the twin as neighbour nothing would be resolved).
    import phdesign.numeric.spectrum.drift as drift_module

    k = np.repeat(np.arange(1.0, 6.0), 2)
    exact = -1 + 1j * k**2 + np.tile([0.0, 1e-15], 5)
    coarse = exact * (1 + 1e-3)
    pair = pair_spectrum(exact, coarse, resolutions=(4, 6), rtol=1e-2, scale=1.0)
    drift = np.abs(exact - coarse)
    with monkeypatch.context() as patch:
        patch.setattr(drift_module, "SEPARATION", np.inf)  # the relative test alone
        alone = pair_spectrum(exact, coarse, resolutions=(4, 6), rtol=1e-2, scale=1.0)
    assert np.all(drift <= 1e-2 * (2 * k + 1))
    expected = alone.resolved
    assert pair.resolved.tolist() == expected.tolist()
    assert pair.resolved[:2].any()  # k = 1 (the first twin at least, as before the rule)
    assert pair.resolved[2:4].any()  # k = 2


def test_fd_beam_lists_no_artefact_and_every_resolved_mode():
    # the case: before, −14.805 ± 37845.7i was listed and −7.62 ± 23.9i omitted
    obs = phd.Observer(
        phd.Plant(phd.load("euler-bernoulli"), method="fd"), [3, 4], gain=[[0.1, 0], [0, 1]]
    )
    report = obs.spectrum(count=14)
    lam = report.eigenvalues[report.resolved]
    f = lambda z: beam_determinant(z, torque=0.1, shear=1.0, damping=0.2)  # noqa: E731
    with mpmath.workdps(30):
        roots = [complex(mpmath.findroot(f, mpmath.mpc(z.real, z.imag))) for z in lam]
    # every resolved fd eigenvalue is a root of the characteristic determinant: the drift
    # test bounds the change between resolutions p and 1.5p by rtol = 1 %; for an error
    # C h (first order: the real mode −37.7 converges so) the change is C h/2 at the finer
    # grid, so its error is at most twice that: 2 %.  The artefact was ten spacings off.
    assert np.all(np.abs(lam - np.array(roots)) <= 2e-2 * np.abs(lam)), (lam, roots)
    listed = np.asarray(report.rightmost)
    for exact in (-7.588 + 23.964j, -9.770 + 70.210j):  # the determinant's roots, to 4 digits
        assert np.min(np.abs(listed - exact)) < 0.05 * abs(exact)
    assert np.max(np.abs(listed)) < 1e3


def test_positive_real_parts_of_airy_are_round_off():
    # the airy plant is lossless: every exact real part is 0
    report = phd.Plant(phd.load("airy")).spectrum()
    lam = report.eigenvalues
    pos = np.flatnonzero(np.isfinite(lam) & (lam.real > 0))
    assert pos.size
    bound = roundoff_bound(lam[pos], report.condition_all[pos], report.rate_scale, lam.size)
    assert np.all(lam.real[pos] <= bound)
    text = " ".join(report.warnings)
    assert "within round-off" in text
    assert "not an instability" in text


@pytest.mark.parametrize("count", [0, -1, 1.5, "2"])
def test_modes_count_is_checked(count):
    report = phd.Plant(phd.load("wave")).spectrum()
    with pytest.raises(NumericError, match="count must be a positive integer"):
        report.modes(count=count)
