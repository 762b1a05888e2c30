"""The spectrum above the resolved band (issue 22): branches, onsets and chain limits.

Every reference is computed here, independently of phdesign's discretizations: the
characteristic determinant of the Timoshenko beam in mpmath (the ODE in the efforts,
solved by ``mpmath.expm`` at 60 digits: near the thickness-shear cut-off the bending
branch's evanescent waves grow like e^104 over the steel beam, so 16 digits cancel to
nothing), the d'Alembert reflection at a damper, and the high-frequency characteristic
equation of two strings written by hand.
"""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest
from string_models import COUPLED_STRINGS, honest

from phdesign.cli import main
from phdesign.numeric.bridge import to_numeric
from phdesign.numeric.spectrum.converged import spectrum
from phdesign.symbolic.model import BCPHS

# -- the steel cantilever of the issue ------------------------------------------------
# 2 m long, 2 cm x 5 cm (bending about the strong axis: I = b h^3 / 12), E = 210 GPa,
# nu = 0.3 (G = E / (2 (1 + nu))), rho = 7850 kg/m^3, shear coefficient 5/6.
LENGTH, WIDTH, HEIGHT = 2.0, 0.02, 0.05
E_MOD, NU, RHO, KAPPA = 210e9, 0.3, 7850.0, 5 / 6
AREA, INERTIA = WIDTH * HEIGHT, WIDTH * HEIGHT**3 / 12
STEEL = {
    "K": KAPPA * E_MOD / (2 * (1 + NU)) * AREA,  # shear stiffness kappa G A, N
    "rho": RHO * AREA,  # mass per length, kg/m
    "EI": E_MOD * INERTIA,  # bending stiffness, N m^2
    "I_rho": RHO * INERTIA,  # rotary inertia per length, kg m
    "k1": 300.0,  # damper on the tip shear force, N s/m
    "k2": 3.0,  # damper on the tip moment, N m s
}
CUTOFF = math.sqrt(STEEL["K"] / STEEL["I_rho"])  # thickness-shear cut-off, 2.03e5 rad/s


def timoshenko(parameters, length="2", closed=(3, 4)):
    """Timoshenko beam clamped at 0 (u1 = u2 = 0), dampers closing the tip inputs ``closed``.

    x = (shear strain, momentum, angular strain, angular momentum), e = H x = (shear force,
    velocity, moment, angular velocity); the tip inputs are e1(L), e3(L) and the outputs
    their conjugates e2(L), e4(L), so u3 = -k1 y3 is the damper e1(L) = -k1 e2(L).
    """
    gains = {3: "k1", 4: "k2"}
    return BCPHS.define(
        name="steel timoshenko",
        interval=[0, length],
        order=1,
        state_names=["shear strain", "momentum", "angular strain", "angular momentum"],
        P={
            0: [[0, 0, 0, -1], [0, 0, 0, 0], [0, 0, 0, 0], [1, 0, 0, 0]],
            1: [[0, 1, 0, 0], [1, 0, 0, 0], [0, 0, 0, 1], [0, 0, 1, 0]],
        },
        H=[["K", 0, 0, 0], [0, "1/rho", 0, 0], [0, 0, "EI", 0], [0, 0, 0, "1/I_rho"]],
        parameters=parameters,
        inputs=["e2(0)", "e4(0)", f"e1({length})", f"e3({length})"],
        outputs=["-e1(0)", "-e3(0)", f"e2({length})", f"e4({length})"],
        feedback={
            "inputs": list(closed),
            "gain": [[gains[i] if i == j else 0 for j in closed] for i in closed],
        },
    )


def timoshenko_determinant(p, length, k1, k2, dps=60):
    """Delta(lambda) of lambda H^-1 e = P1 e' + P0 e, e2(0) = e4(0) = 0, tip dampers k1, k2.

    e(L) = exp(A(lambda) L) e(0) with A = P1^-1 (lambda H^-1 - P0) and e(0) = (a, 0, b, 0);
    the tip conditions e1(L) + k1 e2(L) = 0 and e3(L) + k2 e4(L) = 0 give a 2 x 2
    determinant (k = 0 leaves that end free).
    """
    with mpmath.workdps(dps):
        P1 = mpmath.matrix([[0, 1, 0, 0], [1, 0, 0, 0], [0, 0, 0, 1], [0, 0, 1, 0]])
        P0 = mpmath.matrix([[0, 0, 0, -1], [0, 0, 0, 0], [0, 0, 0, 0], [1, 0, 0, 0]])
        Hinv = mpmath.diag([1 / mpmath.mpf(p["K"]), p["rho"], 1 / mpmath.mpf(p["EI"]), p["I_rho"]])
        P1inv = mpmath.inverse(P1)

    def delta(lam):
        with mpmath.workdps(dps):
            Phi = mpmath.expm(P1inv * (lam * Hinv - P0) * length)
            rows = [[Phi[0, c] + k1 * Phi[1, c], Phi[2, c] + k2 * Phi[3, c]] for c in (0, 2)]
            return rows[0][0] * rows[1][1] - rows[0][1] * rows[1][0]

    return delta


def polished(delta, lam, dps=60):
    """The root of ``delta`` that Muller's method reaches from ``lam``."""
    with mpmath.workdps(dps):
        return complex(mpmath.findroot(delta, mpmath.mpc(lam), solver="muller", tol=1e-40))


@pytest.fixture(scope="module")
def steel_plant():
    return spectrum(to_numeric(timoshenko(STEEL)))


def test_steel_beam_abscissa_is_the_least_damped_mode_past_the_cutoff(steel_plant):
    # Before: -39.6885 "converged, 14.7 digits" at resolutions 20, 30, from the bending
    # modes alone.  The thickness-shear branch starts at the cut-off sqrt(K / I_rho) and
    # its first modes are far less damped: the abscissa is a root of Delta near 1.02 x the
    # cut-off, to the digits claimed.
    rep = steel_plant
    assert rep.converged
    assert rep.kind == "attained"
    lead = rep.rightmost[0]
    root = polished(timoshenko_determinant(STEEL, LENGTH, STEEL["k1"], STEEL["k2"]), lead)
    assert abs(root - lead) < 1e-9 * abs(lead), (root, lead)
    assert honest(rep, root.real), (rep.spectral_abscissa - root.real, rep.digits)
    assert rep.digits >= 10
    assert CUTOFF < abs(root.imag) < 1.1 * CUTOFF
    assert root.real > -39.6885  # the value reported before lies 13x too far left
    # the principal part's families and their chains (checked by the next tests)
    assert rep.branches is not None
    assert rep.branches.onset == pytest.approx(CUTOFF, rel=1e-12)
    assert rep.complete_band >= 1.5 * CUTOFF


def test_steel_beam_error_system_with_a_tip_sensor_is_the_same_beam():
    # Shear damper in the plant, the tip moment external, the tip angular velocity y = e4(L)
    # measured with gain 3 N m s: the error system's boundary condition is the moment
    # damper's, so its spectrum is the plant's with both dampers (the previous test's root).
    nm = to_numeric(timoshenko(STEEL, closed=(3,)))
    rep = spectrum(nm, np.array([[0.0, 0.0, 1.0]]), np.array([[STEEL["k2"]]]))
    assert rep.converged
    root = polished(
        timoshenko_determinant(STEEL, LENGTH, STEEL["k1"], STEEL["k2"]), rep.rightmost[0]
    )
    assert honest(rep, root.real), (rep.spectral_abscissa - root.real, rep.digits)
    assert abs(root.imag) > CUTOFF


def test_shear_damper_alone_gives_no_decay_and_prints_zero(capsys, tmp_path):
    # The rotation family is clamped at 0 and moment-free at the tip: both reflections are
    # lossless, so its chains tend to Re = 0 (no uniform decay).  Reported as 0 (it was
    # -10.69 +- 11.9), converged, with the family named.
    nm = to_numeric(timoshenko(STEEL, closed=(3,)))
    rep = spectrum(nm)
    assert rep.spectral_abscissa == 0.0
    assert rep.no_decay
    assert rep.converged
    assert rep.kind == "limit"
    assert rep.uncertainty < 1e-8 * rep.rate_scale
    assert any("angular strain, angular momentum" in w for w in rep.warnings)
    assert "spectral abscissa: 0 ±" in str(rep)


def test_shear_chain_limit_matches_the_roots_of_the_determinant_at_high_frequency():
    # d'Alembert: a velocity wave meeting the tip damper k1 reflects with
    # r = (Z - k1)/(Z + k1), Z = sqrt(K rho) the shear impedance, and with -1 at the clamped
    # end; a round trip takes T = 2 L / c_s, c_s = sqrt(K / rho), so the shear chain is
    # lambda_j = (ln r + i (2j + 1) pi) / T and its real part tends to ln(r) / T = -19.11.
    c_s, Z = math.sqrt(STEEL["K"] / STEEL["rho"]), math.sqrt(STEEL["K"] * STEEL["rho"])
    T = 2 * LENGTH / c_s
    r = (Z - STEEL["k1"]) / (Z + STEEL["k1"])
    limit = math.log(r) / T
    rep = spectrum(to_numeric(timoshenko(STEEL)), max_resolution=30)  # no refinement needed
    shear = [b for b in rep.branches.limits if "shear strain" in b.label]
    assert len(shear) == 1
    assert shear[0].exact
    assert abs(shear[0].limit - limit) < 1e-12 * abs(limit) + shear[0].uncertainty
    # the true roots approach it: Re(lambda) - limit ~ omega^-2 above the cut-off
    delta = timoshenko_determinant(STEEL, LENGTH, STEEL["k1"], STEEL["k2"], dps=40)
    frequencies, gaps = [], []
    for omega in (1e7, 1e8, 1e9):
        j = round((omega * T / math.pi - 1) / 2)
        root = polished(delta, complex(limit, (2 * j + 1) * math.pi / T), dps=40)
        assert abs(root.real - limit) < 5.0, root  # a root of the shear chain, not rotation's
        frequencies.append(abs(root.imag))
        gaps.append(abs(root.real - limit))
    rate = np.polyfit(np.log(frequencies), np.log(gaps), 1)[0]
    message = f"Re - limit = {gaps} at |lambda| = {frequencies}: rate omega^{rate:.2f}"
    assert gaps[-1] < 1e-4 * abs(limit), message
    assert rate < -1.5, message


def test_slender_dimensionless_beam_refines_until_the_branch_is_seen():
    # K = rho = EI = 1, I_rho = 1e-4: shear speed 1, rotation speed 100 (the rate), cut-off
    # 100.  A light shear damper (1/64, impedance 1) and a moment damper (1/256, impedance
    # 1/100): the shear chains tend to 1/2 ln|(1 - 1/64)/(1 + 1/64)| = -0.01563 (round trip
    # 2) from below, the rotation chains to 50 ln|(1/100 - 1/256)/(1/100 + 1/256)| = -41.3.
    # Before: -0.00243 "attained", from unresolved shear modes kept inside the band of the
    # rotation modes; now the shear limit, every mode up to 1.5 x the cut-off resolved.
    k1, k2 = 1 / 64, 1 / 256
    params = {"K": 1, "rho": 1, "EI": 1, "I_rho": "1/10000", "k1": "1/64", "k2": "1/256"}
    rep = spectrum(to_numeric(timoshenko(params, length="1")))
    shear = 0.5 * math.log((1 - k1) / (1 + k1))
    rotation = 50 * math.log((0.01 - k2) / (0.01 + k2))
    assert rep.converged
    assert rep.kind == "limit"
    assert abs(rep.spectral_abscissa - shear) < 1e-11, rep.spectral_abscissa - shear
    limits = sorted(b.limit for b in rep.branches.limits)
    np.testing.assert_allclose(limits, [rotation, shear], rtol=1e-11)
    assert rep.complete_band >= 150
    # no root of Delta right of the limit among the resolved modes near the cut-off
    delta = timoshenko_determinant(params | {"I_rho": 1e-4}, 1, k1, k2, dps=40)
    near = [z for z in rep.eigenvalues[rep.resolved] if 80 < abs(z) < 150 and z.imag > 0]
    for z in near[:3]:
        root = polished(delta, z, dps=40)
        assert abs(root - z) < 1e-8 * abs(z)
        assert root.real < shear


def test_band_short_of_the_onset_is_a_lower_bound_not_a_number(capsys, tmp_path):
    # With the resolution capped at 60 the band stops at 6e4 rad/s, below the cut-off: the
    # report says so, names the families, prints the larger of the bending modes' abscissa
    # and the chains' limits as a lower bound, and keeps the unresolved eigenvalues right
    # of it (not "discarded").
    rep = spectrum(to_numeric(timoshenko(STEEL)), max_resolution=60)
    assert rep.kind == "lower bound"
    assert not rep.converged
    assert rep.digits is None
    assert rep.uncertainty is None
    assert rep.spectral_abscissa == pytest.approx(-19.1093653126, abs=1e-9)  # shear limit
    text = "\n".join(rep.warnings)
    assert "shear strain, momentum" in text
    assert "raise max_resolution" in text
    assert "not discarded" in text
    assert "frequencies, discarded" not in text
    assert ">= -19.1093653126" in str(rep)


def test_incommensurate_strings_coupled_at_the_boundary_take_the_supremum_over_phases():
    # Two strings (speeds 1 and sqrt 2, impedances 1 and sqrt 2), fixed at 0, and a full
    # gain L on both tip velocities: f = -L v at z = 1.  With velocity waves v = a + b
    # (a incoming, b outgoing) and f = Z (a - b) (Z = diag(1, sqrt 2)), b = R a with
    # R = (Z + L)^-1 (Z - L); the fixed ends reflect with -1 after the round trips
    # 2 / c_j.  So, at high frequency, det(I + D R) = 0 with D = diag(e^(-2 lambda / c_j)).
    # The travel times are incommensurate: the real parts' closure is the set of sigma for
    # which det(I + diag(x1 e^(i t1), x2 e^(i t2)) R) = 0 for some phases, x_j = e^(-2 sigma
    # / c_j) (Avellar and Hale).  For fixed t2 that is linear in e^(i t1):
    # |1 + x2 e^(i t2) R22| = x1 |R11 + x2 e^(i t2) det R|; its largest root sigma, maximized
    # over t2, is the supremum.
    L = np.array([[0.5, 0.3], [0.3, 0.5]])
    Z = np.diag([1.0, math.sqrt(2)])
    R = np.linalg.solve(Z + L, Z - L)
    c = np.array([1.0, math.sqrt(2)])

    def gap(sigma, t2):  # arrays: sigma (S, 1), t2 (1, P)
        x1, x2 = np.exp(-2 * sigma / c[0]), np.exp(-2 * sigma / c[1])
        w = x2 * np.exp(1j * t2)
        return np.abs(1 + w * R[1, 1]) - x1 * np.abs(R[0, 0] + w * np.linalg.det(R))

    def largest(t2):  # the largest sign change of gap in sigma, bisected, for each phase
        grid = np.linspace(0.0, -3.0, 601)[:, None]
        values = gap(grid, t2[None, :])
        first = np.argmax(values[1:] * values[:1] <= 0, axis=0)  # from sigma = 0 down
        lo, hi = grid[first + 1, 0], grid[first, 0]
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            same = gap(mid[None, :], t2[None, :])[0] * values[0] > 0  # hi's side
            lo, hi = np.where(same, lo, mid), np.where(same, mid, hi)
        return 0.5 * (lo + hi)

    phases = np.linspace(0, 2 * np.pi, 721)
    best = phases[int(np.argmax(largest(phases)))]
    supremum = float(np.max(largest(np.linspace(best - 0.01, best + 0.01, 2001))))
    rep = spectrum(to_numeric(COUPLED_STRINGS), np.array([[0, 0, 1.0, 0], [0, 0, 0, 1.0]]), L)
    limits = [b for b in rep.branches.limits if math.isfinite(b.limit)]
    assert len(limits) == 1
    assert not limits[0].exact
    assert abs(limits[0].limit - supremum) < 1e-6, (limits[0].limit, supremum)
    assert rep.spectral_abscissa >= limits[0].limit - limits[0].uncertainty


# -- the built-in models: the same numbers as before the change ---------------------
# (phdesign at commit 2d51833, before the branches; each equals its closed form where one
# exists: the wave's 1/2 ln|(1 - k)/(1 + k)|, the beam's -d/2)
GOLDEN = [
    ("wave", None, None, 1.1102230246251565e-16),
    ("wave", [2], [0.5], -0.5493061443340548),
    ("wave", [2], [3.0], -0.3465735902799745),
    ("wave", [1, 2], [0.3, 0.7], -1.1768201318971667),
    ("wave-damper", None, None, -0.5493061443340548),
    ("wave-damper", [1], [0.4], -0.9729550745276592),
    ("timoshenko", None, None, -2.220446049250313e-16),
    ("timoshenko", [3, 4], [1, 1], -0.7791193346988186),
    ("timoshenko", [1, 2, 3, 4], [1, 1, 1, 1], -2.6094646755621813),
    ("euler-bernoulli", None, None, -0.10000000000000075),
    ("euler-bernoulli", [3, 4], [0.1, 1], -2.910656298631452),
    ("euler-bernoulli", [4], [1], -2.065959052307099),
    ("euler-bernoulli", [1, 2, 3, 4], [1, 1, 1, 1], -2.0557072130212406),
    ("airy", None, None, -2.220446049250313e-16),
    ("airy", [1], [1], -2.9998721418776007),
    ("airy", [1, 2, 3], [1, 1, 1], -1.9939275371795402),
    ("beam-tip-damper", None, None, -1.968905403434897),
    ("beam-tip-damper", [3], [1.0], -0.81968311803992),
]


@pytest.mark.parametrize(("name", "sensors", "gain", "before"), GOLDEN)
def test_builtin_spectra_are_unchanged(name, sensors, gain, before):
    from phdesign.models import load_builtin

    nm = to_numeric(load_builtin(name))
    if sensors is None:
        rep = spectrum(nm)
    else:
        C = np.zeros((len(sensors), nm.n_ports))
        C[np.arange(len(sensors)), np.array(sensors) - 1] = 1.0
        rep = spectrum(nm, C, np.diag(gain))
    assert rep.converged
    # 1e-12: the same eigenvalues; a lossless plant's round-off real part is now printed 0
    assert abs(rep.spectral_abscissa - before) <= 1e-12 * max(1.0, abs(before))


def test_timoshenko_extrapolated_limit_is_now_derived():
    # Sensors 1 and 3 with L = diag(0.5, 2): the real parts rise toward a limit that no mode
    # attains.  Before, an extrapolation: -0.09918356 +- 5e-7, not converged; now the
    # chains' limit, inside that interval, to round-off.
    from phdesign.models import load_builtin

    C = np.array([[1.0, 0, 0, 0], [0, 0, 1.0, 0]])
    rep = spectrum(to_numeric(load_builtin("timoshenko")), C, np.diag([0.5, 2.0]))
    assert rep.converged
    assert rep.kind == "limit"
    assert abs(rep.spectral_abscissa + 0.09918356145240417) < 5.05e-7
    assert rep.uncertainty < 1e-12


def test_semisimple_double_zero_is_not_ill_conditioned():
    # The damped clamped-clamped beam: the moment e2 = c0 + c1 z is a steady state, so 0 is
    # a double eigenvalue with a full eigenspace (condition 1): close to its twin (gap 0)
    # but not sensitive; it used to be flagged "ill-conditioned ... few digits".
    from dirichlet_models import beam

    rep = spectrum(to_numeric(beam((0, 0, 1, 1), "1/5")))
    assert rep.spectral_abscissa == 0.0
    assert rep.condition_numbers[0] == pytest.approx(1.0)
    assert not rep.ill_conditioned
    assert not any("ill-conditioned" in w for w in rep.warnings)


def test_cli_json_carries_the_structure(capsys):
    assert main(["spectrum", "timoshenko", "--sensors", "3,4", "--gain", "1,1", "--json"]) == 0
    import json

    data = json.loads(capsys.readouterr().out)
    branches = data["branches"]
    assert branches["onset"] == pytest.approx(1.0)  # sqrt(K / I_rho) with unit parameters
    assert branches["analysed"]
    assert branches["limits"]
    assert data["complete_band"] >= branches["required_band"]


def test_beam_tip_damper_chains_tend_to_minus_two_k_over_rho_l():
    # w_tt = -w_zzzz (rho = EI = L = 1), clamped at 0, w''(1) = 0, w'''(1) = k w_t(1).  At
    # lambda = i beta^2 a wave b e^{-i beta z} meeting the tip returns as a e^{i beta z} plus
    # a boundary layer c e^{-beta (1 - z)}; the two tip conditions give
    # a / b = -(beta (1 + i) - 2 i k) / (beta (1 - i) - 2 i k), |a / b| = 1 - 2k/beta + O(beta^-2),
    # the clamped end is lossless, and a round trip takes 2 / c_g with c_g = 2 beta: so
    # Re lambda -> (-2k/beta)(2 beta)/2 = -2k.  The true roots (the 2 x 2 determinant of
    # test_feedback.py, in mpmath) approach it like beta^-2.
    from phdesign.models import load_builtin

    k = 1.0
    rep = spectrum(to_numeric(load_builtin("beam-tip-damper")))
    (limit,) = rep.branches.limits
    assert abs(limit.limit + 2 * k) <= max(limit.uncertainty, 1e-7), limit

    def determinant(lam):
        mu = mpmath.sqrt(1j * lam)
        ch, sh, c, s = mpmath.cosh(mu), mpmath.sinh(mu), mpmath.cos(mu), mpmath.sin(mu)
        row1 = (ch + c, sh + s)
        row2 = (
            mu**3 * (sh - s) - k * lam * (ch - c),
            mu**3 * (ch + c) - k * lam * (sh - s),
        )
        # mu ~ i beta: cos(mu) ~ cosh(beta) is the large factor; dividing by it keeps O(1)
        return (row1[0] * row2[1] - row1[1] * row2[0]) / (c**2 * mu**3)

    gaps, betas = [], []
    with mpmath.workdps(200):  # the terms ~ cosh(beta)^2 cancel: 2 beta / ln 10 digits lost
        for beta in (15.5 * math.pi, 30.5 * math.pi, 60.5 * math.pi):
            root = complex(mpmath.findroot(determinant, mpmath.mpc(-2 * k, beta**2)))
            betas.append(math.sqrt(abs(root.imag)))
            gaps.append(abs(root.real + 2 * k))
    rate = np.polyfit(np.log(betas), np.log(gaps), 1)[0]
    message = f"|Re + 2k| = {gaps} at beta = {betas}: rate beta^{rate:.2f}"
    assert gaps[-1] < 1e-3, message
    assert rate < -1.5, message
    assert rep.spectral_abscissa > limit.limit  # the low modes are the least damped here


def test_tune_on_a_steel_beam_optimizes_the_true_abscissa():
    # A 0.5 m bar of the same steel section (the same cut-off, four times fewer modes below
    # it, so that tuning fits the suite; benchmarks/branches.py tunes the 2 m beam).  The
    # tip angular velocity is measured; the gain damps the rotation family and, through the
    # bending modes, the low spectrum, but not the shear family's chains, whose limit
    # ln(r) / T (d'Alembert, T = 2 L / c_s: -76.44) no gain moves: the tuned abscissa is
    # that limit, not the bending branch's value that a band below the cut-off would give.
    from phdesign.numeric.tuning.search import tune

    nm = to_numeric(timoshenko(STEEL, length="1/2", closed=(3,)))
    result = tune(nm, np.array([[0.0, 0.0, 1.0]]))
    c_s, Z = math.sqrt(STEEL["K"] / STEEL["rho"]), math.sqrt(STEEL["K"] * STEEL["rho"])
    shear = math.log((Z - STEEL["k1"]) / (Z + STEEL["k1"])) / (2 * 0.5 / c_s)
    rep = result.report
    assert rep.converged
    assert rep.kind == "limit"
    assert abs(rep.spectral_abscissa - shear) < 1e-9 * abs(shear)
    bending = rep.eigenvalues[rep.resolved & (np.abs(rep.eigenvalues) < CUTOFF)]
    assert np.max(bending.real) < shear  # the bending branch alone would claim more
    # and the tuned gain's rightmost mode is a root of the determinant
    gain = float(np.asarray(result.gain)[0, 0])
    delta = timoshenko_determinant(STEEL, 0.5, STEEL["k1"], gain)
    lead = rep.rightmost[0]
    assert abs(polished(delta, lead) - lead) < 1e-9 * abs(lead)


def test_a_structure_not_derived_is_said():
    # a beam whose stiffness varies along z: the chains' limits of an N = 2 model are
    # derived for constant coefficients only, and the report says so (the uniform viscous
    # damping still gives every mode Re = -d/2 = -0.1, resolved and converged)
    beam = BCPHS.define(
        name="graded beam",
        interval=[0, 1],
        order=2,
        P={0: [["-1/5", 0], [0, 0]], 2: [[0, -1], [1, 0]]},
        H=[[1, 0], [0, "1 + z"]],
        inputs=["e1(0)", "e1'(0)", "e2(1)", "e2'(1)"],
        outputs=["e2'(0)", "-e2(0)", "e1'(1)", "-e1(1)"],
    )
    rep = spectrum(to_numeric(beam))
    assert rep.converged
    assert abs(rep.spectral_abscissa + 0.1) < 1e-9
    assert not rep.branches.analysed
    assert any(
        "are not derived (the chains' limits are derived for constant" in w for w in rep.warnings
    )
