"""Dirichlet-type inputs at both ends: the weak Galerkin's spurious unobservable modes.

When a component has all its boundary traces among the inputs, the top Legendre modes of
that component are invisible to the weak form: on the code before this fix they gave an
eigenvalue 0 (or -d with viscous damping, ±i for two Timoshenko components coupled by
P0) at every degree, with zero output, that no feedback moves and the drift test calls
resolved.  The continuum has no such mode (zero u and y means zero traces, and zero
Cauchy data forces e = 0).  Every expected eigenvalue below is a root of the
characteristic determinant Δ(λ) = det((U + K Y)(Φ(1); I)) solved in mpmath
(tests/characteristic.py), or an exact closed form.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sl
from characteristic import characteristic_determinant, root_ratio, zero_multiplicity
from dirichlet_models import beam, every_combination, string, timoshenko
from numeric_models import numeric

from phdesign.core.errors import NumericError
from phdesign.numeric.bridge import to_numeric
from phdesign.numeric.discretization.galerkin import galerkin
from phdesign.numeric.discretization.registry import discretize, feedback_matrix
from phdesign.numeric.inputs import initial_state_function
from phdesign.numeric.spectrum.converged import spectrum
from phdesign.numeric.spectrum.drift import match_resolved
from phdesign.numeric.time.options import SimulationOptions
from phdesign.numeric.time.simulation import simulate

COMBINATIONS = every_combination()


def _resolved(nm, K, p):
    """Eigenvalues at 1.5 p that agree with degree p (the spectrum's drift rule, 1e-6)."""
    coarse, fine = (
        sl.eigvals(d.closed_matrix(K), d.E)
        for d in (discretize(nm, "galerkin", r) for r in (p, int(1.5 * p)))
    )
    idx, _ = match_resolved(fine, coarse, 1e-6)
    return fine[idx]


def test_string_with_velocity_inputs_at_both_ends_has_the_exact_abscissa():
    # Inputs e1(0), e1(1) (velocities), outputs -e2(0), e2(1); sensor 2, gain k: the error
    # system is the string fixed at 0 with e1(1) = -k e2(1), a damper of constant 1/k, so
    # alpha = 1/2 ln|(1/k - 1)/(1/k + 1)| = 1/2 ln|(1 - k)/(1 + k)|: 1/2 ln(1/3) at k = 1/2
    # and extinction at k = 1 (DESIGN.md's damped wave).  Before: -5e-26 "converged".
    nm = to_numeric(string((0, 0)))
    C = np.array([[0.0, 1.0]])
    report = spectrum(nm, C, np.array([[0.5]]))
    assert report.converged
    assert abs(report.spectral_abscissa - 0.5 * np.log(1 / 3)) < 1e-10
    assert spectrum(nm, C, np.array([[1.0]])).unbounded_below
    assert discretize(nm, "galerkin", 20).spurious_removed == 1


@pytest.mark.parametrize(("label", "model"), COMBINATIONS, ids=[c[0] for c in COMBINATIONS])
def test_every_dirichlet_combination_matches_the_characteristic_determinant(label, model):
    # (1) The loop u = -0.7 y on every output: its rightmost resolved eigenvalue (the
    # error system's abscissa) must be a root of Delta: |Delta| there is below 1 % of
    # |Delta| at distance 1e-4 max(1, |lambda|) (a root within eps gives (eps/r)^m, a
    # non-root 1 + O(r)).  Before the fix it was the artefact 0, -d or +-i, not a root.
    # (2) The plant (u = 0): its number of zero eigenvalues equals the order of the
    # zero of Delta at 0 (extra zeros before the fix: 4 for the clamped-clamped beam).
    nm = to_numeric(model)
    p = 14 if nm.order == 3 else 16
    K = 0.7 * np.eye(nm.n_ports)
    lam = _resolved(nm, K, p)
    top = lam[np.argmax(lam.real - 1e-9 * np.abs(lam.imag))]
    ratio = root_ratio(characteristic_determinant(nm, K), top, 1e-4 * max(1.0, abs(top)))
    assert ratio < 1e-2, (label, top, ratio)
    multiplicity = zero_multiplicity(characteristic_determinant(nm))
    for degree in (p, p + 1):  # both parities (airy's artefacts depend on it)
        d = discretize(nm, "galerkin", degree)
        zeros = int(np.sum(np.abs(sl.eigvals(d.J - d.R, d.E)) < 1e-8))
        assert zeros == multiplicity, (label, degree, zeros)


def test_clamped_clamped_beam_plant_has_eigenvalue_zero_exactly_twice():
    # w = w' = 0 at both ends (inputs e1, e1' at both ends): the moment e2 = c0 + c1 z is
    # a steady state (two conserved moments of the curvature), so 0 is a double root of
    # Delta; the weak Galerkin added span{P_p, P_(p-1)} of e1: 4 zeros before the fix.
    nm = to_numeric(beam((0, 0, 1, 1)))
    assert zero_multiplicity(characteristic_determinant(nm)) == 2
    for p in (16, 24, 25):
        d = discretize(nm, "galerkin", p)
        lam = sl.eigvals(d.J - d.R, d.E)
        assert np.sum(np.abs(lam) < 1e-8) == 2
        assert d.spurious_removed == 2


def test_damped_clamped_beam_loses_its_spurious_eigenvalue_minus_d():
    # With viscous damping d on e1 the invisible top modes of e1 decay at exactly -d
    # (R = d E on them): not a root of Delta, and before the fix it sat in every loop.
    nm = to_numeric(beam((0, 0, 1, 1), "1/5"))
    delta = characteristic_determinant(nm, 0.7 * np.eye(4))
    assert root_ratio(delta, complex(-0.2, 0), 1e-4) > 0.5
    lam = _resolved(nm, 0.7 * np.eye(4), 16)
    assert np.min(np.abs(lam + 0.2)) > 1e-3


def test_genuine_zero_eigenvalues_are_kept():
    # The string with velocity inputs at both ends has a constant strain at rest (a
    # simple root 0 of Delta, with nonzero output); airy's plant has e = z - z^2 (e''' = 0,
    # e(0) = e(1) = 0, e'(0) + e'(1) = 0).  Airy at odd degree also had a spurious kernel
    # (a combination of P_p and P_(p-2) with e''(0) = e''(1) = 0 and e'(0) = e'(1)): two
    # zeros there before the fix.
    for nm in (to_numeric(string((0, 0))), numeric("airy")):
        assert zero_multiplicity(characteristic_determinant(nm)) == 1
        for p in (12, 13, 20, 21):
            d = discretize(nm, "galerkin", p)
            lam = sl.eigvals(d.J - d.R, d.E)
            assert np.sum(np.abs(lam) < 1e-8) == 1, (nm.name, p)


@pytest.mark.parametrize("name", ["wave", "timoshenko", "euler-bernoulli", "airy"])
def test_nothing_is_removed_where_nothing_is_spurious(name):
    # The built-ins have no component with all traces as inputs: nothing to remove, except
    # airy at odd degree p.  There the top three Legendre modes span the orthogonal
    # complement of e''' over the polynomials; the odd ones (p, p - 2) have e'(0) = e'(1)
    # (so the output (e'(0) - e'(1))/sqrt(2) vanishes) and one combination of them has
    # e''(1) = e''(0) = 0: one spurious mode at odd p, none at even p.
    nm = numeric(name)
    for p in range(10, 16):
        removed = discretize(nm, "galerkin", p).spurious_removed
        assert removed == (p % 2 if name == "airy" else 0), (name, p)


def test_the_restriction_keeps_every_other_eigenvalue_and_the_transfer_function():
    # The removed subspace O is invariant under every loop and lies in ker B^T, so the
    # loop matrix is block triangular in (O, its E-orthogonal complement): the restricted
    # spectrum is the full one less the artefacts, for any K, and B^T (sE - A)^-1 B is
    # unchanged.  Timoshenko with e1 and e4 Dirichlet at both ends: artefacts at +-i
    # (P0 couples the two invisible top modes); H = diag(2, 1, 1, 3) so E is not I.
    nm = to_numeric(
        timoshenko((0, 1, 0, 1), H=[[2, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 3]])
    )
    full = galerkin(nm, 12, remove_spurious=False)
    cut = galerkin(nm, 12)
    assert cut.spurious_removed == 2
    assert cut.dim == full.dim - 2
    K = feedback_matrix(
        np.array([[1.0, 0, 0, 0], [0, 0, 0, 1.0]]), np.array([[0.3, 0.1], [-0.1, 2.0]]), 4
    )
    lam_full = sl.eigvals(full.closed_matrix(K), full.E)
    lam_cut = sl.eigvals(cut.closed_matrix(K), cut.E)
    # the two artefacts: +-i sqrt(H11 H44) = +-i sqrt(6) (a' = -H44 b, b' = H11 a)
    extra = lam_full[np.argsort(np.min(np.abs(lam_full[:, None] - lam_cut[None, :]), axis=1))[-2:]]
    np.testing.assert_allclose(np.sort(extra.imag), [-np.sqrt(6), np.sqrt(6)], atol=1e-10)
    np.testing.assert_allclose(extra.real, 0.0, atol=1e-10)
    gap = np.min(np.abs(lam_cut[:, None] - lam_full[None, :]), axis=1)
    assert np.max(gap / np.maximum(1.0, np.abs(lam_cut))) < 1e-10
    for s in (0.5, 2.0 + 3.0j):
        tf = [d.B.T @ np.linalg.solve(s * d.E - d.closed_matrix(K), d.B) for d in (full, cut)]
        np.testing.assert_allclose(tf[1], tf[0], rtol=1e-10, atol=1e-12)
    structure = cut.check_structure()
    assert structure["J_skew"] < 1e-15
    assert structure["E_min_eig"] > 0


def test_the_removal_also_works_for_a_varying_hamiltonian():
    # With H(z) varying the artefact at +-i moves (an exactly unobservable pair near
    # +-1.0246i for this H, Hautus residual ||B^T v|| / ||v||_E ~ 1e-14) and the frozen-H
    # subspace is removed: afterwards no eigenvector is unobservable (smallest residual
    # ~1.3, the first physical mode).
    H = [["1 + z/2", 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, "1/(1 + z/3)"]]
    nm = to_numeric(timoshenko((0, 1, 0, 1), H=H))

    def hautus(d):
        _, v = sl.eig(d.J - d.R, d.E)
        energy = np.sqrt(np.abs(np.einsum("ij,ij->j", v.conj(), d.E @ v)))
        return np.min(np.linalg.norm(d.B.T @ v, axis=0) / energy)

    assert hautus(galerkin(nm, 20, remove_spurious=False)) < 1e-10
    assert hautus(galerkin(nm, 20)) > 0.1


def test_simulated_error_energy_no_longer_stalls():
    # String with velocity inputs at both ends, sensor 2, gain 1/2: the error string is
    # fixed at 0 (reflection -1) and ends in a damper of constant 2 at 1 (reflection
    # (1 - 2)/(1 + 2) = -1/3).  By d'Alembert every part of the error has met the damper
    # exactly m times at t = 2m, so H_err(2m) = 9^-m H_err(0) exactly.  The initial error
    # x1 = sqrt(z) has slowly decaying Legendre coefficients; its share in the spurious
    # kernel never decayed, and H_err stalled near 2e-9 of H_err(0) (500x off at t = 24).
    model = string((0, 0))
    nm = to_numeric(model)
    x0 = initial_state_function("x1: sqrt(z)", nm, model=model)
    r = simulate(
        nm,
        np.array([[0.0, 1.0]]),
        np.array([[0.5]]),
        x0=x0,
        options=SimulationOptions(t_end=24.0, samples=13),
    )
    exact = 9.0 ** -np.arange(13)
    # the kink of sqrt(z) at 0 limits the degree-40 projection to ~1 % (measured 1.2 %)
    np.testing.assert_allclose(r.H_err / r.H_err[0], exact, rtol=0.05)


def test_staggered_fd_refuses_inputs_at_both_ends_of_a_component():
    # The staggered grid imposes each component's input at one end only; a component with
    # inputs at both ends has no place on it: a clear refusal, never a wrong answer.
    for _label, model in COMBINATIONS:
        nm = to_numeric(model)
        if nm.order <= 2:
            with pytest.raises(NumericError, match="mixed causality"):
                discretize(nm, "fd", 20)
