"""Noise, tuning and export of observers of coupled models (issue 26), against closed forms.

* Noise: the tip-mass string (rho = T = 1) measured at the mass's velocity, the noise fed
  back as a force on the mass. Dissipation (c + l on e_c) and noise (l sigma on the mass's
  momentum) enter through the same port, so the fluctuation-dissipation relation holds:
  the stationary density of dx = (J - R) grad H dt + s dW with s s^T = 2 theta R is
  exp(-H/theta), here theta = l^2 sigma^2 / (2 (c + l)). For the discretization (states
  x = E e, H = 1/2 x^T E^-1 x) the covariance is theta E and E[H] = theta dim / 2 exactly:
  equipartition, so E[H~] grows with the number of states and is infinite for the PDE.
* Tuning: the flexible arm (a Timoshenko beam on a hub, all parameters 1) with the two tip
  velocities measured. The error system's eigenvalues are the roots of a 2 x 2 determinant
  built from the spatial ODE e' = P1^-1 (lambda H^-1 - P0) e, solved in mpmath; at high
  frequency P0 is lower order, each wave family reflects at z = 1 with (1 - l)/(1 + l)
  (impedance 1) and with modulus 1 at z = 0 (w_t(0) = 0; the hub's velocity is a mass's:
  a wall at high frequency), so the chains' real parts tend to ln|(1 - l)/(1 + l)| / 2.
* Export: the sampled observer of the tip-mass string with the user's gain; its error
  eigenvalues are the roots of (m lam + c + l) sinh(lam) + cosh(lam) (the mass's damper
  and the injection add: tests/numeric/test_boundary_dynamics.py derives the equation).
"""

from __future__ import annotations

import json

import mpmath
import numpy as np
import pytest

import phdesign as phd
from phdesign.cli import main


@pytest.mark.slow  # four resolutions, each a Lyapunov solve and an L2-gain sweep (~4 s)
def test_noise_on_the_mass_velocity_is_equipartition(capsys):
    m, c, gain, sigma2 = 2.0, 0.5, 3.0, 0.7
    argv = ["noise", "string-tip-mass", "--sensors", "2", "--gain", "3", "--param", "m=2",
            "--param", "c=0.5", "--intensity", "0.7", "--resolution", "10", "--json",
            "--quiet"]  # fmt: skip
    assert main(argv) == 0
    energy = json.loads(capsys.readouterr().out)["error_energy"]
    theta = gain**2 * sigma2 / (2 * (c + gain))
    nm = phd.to_numeric(phd.load("string-tip-mass"), {"m": m, "c": c})
    dims = [phd.discretize(nm, "galerkin", p).dim for p in energy["resolutions"]]
    # field + mass states; a Lyapunov solve in double precision: 1e-10 relative leaves room
    # for its round-off
    np.testing.assert_allclose(energy["values"], theta * np.array(dims) / 2, rtol=1e-10)
    assert energy["diverges"]
    assert not energy["converged"]
    assert energy["value"] is None  # infinite for the PDE: never reported as a number
    # E[H~] ~ dim: the local exponent of the last pair is that of the state count
    (p1, p2), (n1, n2) = energy["resolutions"][-2:], dims[-2:]
    assert energy["growth"] == pytest.approx(np.log(n2 / n1) / np.log(p2 / p1), rel=1e-6)


def arm_determinant(l1, l2, I_hub=1):
    """The flexible arm's error system with dampers l1, l2 at z = 1 (module docstring).

    e = (shear force, w_t, moment, phi_t). At z = 0: e2(0) = 0 and the hub, phi_t(0) = e_c
    with I_hub lam e_c = e3(0); so e(0) = a (1, 0, 0, 0) + b (0, 0, I_hub lam, 1). At z = 1:
    e1 = -l1 e2 and e3 = -l2 e4 (u~ = -C^T L C y~ with y3 = e2(1), y4 = e4(1)).
    """
    P1 = mpmath.matrix([[0, 1, 0, 0], [1, 0, 0, 0], [0, 0, 0, 1], [0, 0, 1, 0]])
    P0 = mpmath.matrix([[0, 0, 0, -1], [0, 0, 0, 0], [0, 0, 0, 0], [1, 0, 0, 0]])

    def det(lam):
        Phi = mpmath.expm(P1 * (lam * mpmath.eye(4) - P0))  # P1^-1 = P1, H = I
        a = Phi * mpmath.matrix([1, 0, 0, 0])
        b = Phi * mpmath.matrix([0, 0, I_hub * lam, 1])
        return (a[0] + l1 * a[1]) * (b[2] + l2 * b[3]) - (b[0] + l1 * b[1]) * (a[2] + l2 * a[3])

    return det


@pytest.mark.slow  # a global search over the gains (625 points, then local searches)
def test_tuning_the_flexible_arm_against_its_characteristic_determinant():
    tuned = phd.Observer(phd.load("flexible-arm"), [2, 3]).tune(starts=2)
    result = tuned.tuning
    assert result.status == "optimum"
    l1, l2 = np.diag(result.gain)
    det = arm_determinant(l1, l2)
    report = result.report
    lam = report.eigenvalues[report.resolved]
    rightmost = lam[np.argsort(-lam.real)][:4]
    with mpmath.workdps(30):
        roots = [complex(mpmath.findroot(det, mpmath.mpc(z))) for z in rightmost]
    # the resolved eigenvalues are the determinant's roots (1e-10 of |lam|: converged
    # spectra are accurate to tol = 1e-10), and the abscissa is the rightmost of them
    for z, root in zip(rightmost, roots, strict=True):
        assert abs(z - root) < 1e-10 * abs(root), (z, root)
    assert result.spectral_abscissa == pytest.approx(max(r.real for r in roots), abs=1e-10)
    # above the band: the chains' limit is the reflection's, the larger of the two families'
    limit = max(np.log(abs((1 - g) / (1 + g))) / 2 for g in (l1, l2))
    assert max(b.limit for b in report.branches.limits) == pytest.approx(limit, abs=1e-8)
    assert limit < result.spectral_abscissa  # attained by a mode: a true optimum
    # better than the default gain L = I
    assert result.spectral_abscissa < phd.Observer(tuned.plant, [2, 3], gain=1).spectrum(
    ).spectral_abscissa - 0.1  # fmt: skip


def tip_mass_error_delta(m, c, gain):
    return lambda lam: (m * lam + c + gain) * mpmath.sinh(lam) + mpmath.cosh(lam)


def exported_gaps(obs, dt, delta):
    """Export with the user's gain; return the observer and the gaps of its slow modes."""
    exported = obs.export(dt=dt, design="given")
    mu = np.log(np.linalg.eigvals(exported.A).astype(complex)) / dt  # principal branch
    slow = mu[np.argsort(np.abs(mu))][:6]  # |Im mu| dt < 0.07: no branch ambiguity
    with mpmath.workdps(30):
        return exported, [abs(z - complex(mpmath.findroot(delta, mpmath.mpc(z)))) for z in slow]


@pytest.mark.slow  # two exports (order selection against a verification plant)
def test_the_exported_observer_carries_the_mass_and_its_spectrum(tmp_path):
    m, c, gain = 2.0, 0.5, 1.5
    obs = phd.Observer(phd.load("string-tip-mass"), [2], gain=gain, parameters={"m": m, "c": c})
    delta = tip_mass_error_delta(m, c, gain)
    exported, gaps = exported_gaps(obs, 0.01, delta)
    degree = exported.selection.degree
    d = phd.discretize(phd.to_numeric(phd.load("string-tip-mass"), {"m": m, "c": c}), "galerkin",
                       degree)  # fmt: skip
    field, boundary = d.info["boundary_states"]
    assert boundary == 1
    assert exported.A.shape == (field + boundary, field + boundary)
    # the averaging sampler perturbs the continuous error eigenvalues by O(dt^2): the gaps
    # to the exact roots are small and shrink by 4 when dt halves (3 to 5 allows the
    # Galerkin error, below 1e-9 for these modes, to blur the ratio)
    assert max(gaps) < 1e-4
    _, finer = exported_gaps(obs, 0.005, delta)
    ratios = np.array(gaps) / np.array(finer)
    assert np.all((ratios > 3) & (ratios < 5)), ratios
    # every format carries the same states: JSON's A and the C header's N
    exported.write(str(tmp_path / "obs.json"), "json")
    assert np.array(json.loads((tmp_path / "obs.json").read_text())["A"]).shape == (d.dim, d.dim)
    exported.write(str(tmp_path / "c"), "c")
    assert f"#define PHD_OBSERVER_N {d.dim} " in (tmp_path / "c" / "observer.h").read_text()


def test_verification_states_meet_the_static_part_of_a_boundary_system():
    # The Maxwell end at rest (e_c = 0) leaves u_p = -K y_p with K = d: e2(1) = -d e1(1).
    # A verification state has one component, so the condition forces e1(1) = 0 on e1's
    # states and e2(1) = 0 on e2's (without K, e1(1) would be left free: not in the domain).
    from string_models import string_with_maxwell_end

    from phdesign.numeric.sampled.state_set import boundary_states

    nm = phd.to_numeric(string_with_maxwell_end(d=3))
    states = boundary_states(nm)
    assert {s.text.split(" ")[0] for s in states} == {"e1", "e2"}
    for state in states:
        e = np.einsum("mij,mj->mi", nm.H_at(np.array([1.0])), state.function(np.array([1.0])))
        assert np.all(np.abs(e[0]) < 1e-12), (state.text, e)
