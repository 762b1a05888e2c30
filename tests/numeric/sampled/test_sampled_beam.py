"""The sampling trap on the paper's beam, and the order selection against closed forms.

The beam figures below were measured independently (an independent Legendre weak
Galerkin, by the issue's author): a continuous observer of degree 16 tracks a degree-48
plant from the paper's x0 (x1 = 0, x2 = z - 0.9) with a tip error of about 4e-6 at
t = 5 s; point samples every 1 ms leave about 2e-2, every 0.1 ms about 7e-5.
The wave's error spectrum is known exactly: with sensor 2 and gain k < 1 its eigenvalues
are ½ ln((1 - k)/(1 + k)) + i (m + ½) π.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from phdesign.core.errors import NumericError
from phdesign.models import load_builtin
from phdesign.numeric.bridge import to_numeric
from phdesign.numeric.discretization.registry import discretize
from phdesign.numeric.inputs import initial_state_function
from phdesign.numeric.sampled import reduction as reduction_module
from phdesign.numeric.sampled.export import export_observer, verify_observer
from phdesign.numeric.sampled.order import select_order
from phdesign.numeric.sampled.reduction import balanced_truncation
from phdesign.numeric.sampled.runs import run_against_continuous
from phdesign.numeric.sampled.samplers import ContinuousObserver

SENSORS = np.array([[0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]])
GAIN = np.diag([0.1, 1.0])


@pytest.fixture(scope="module")
def beam():
    model = load_builtin("euler-bernoulli")
    nm = to_numeric(model)
    plant = discretize(nm, "galerkin", 48)
    x0 = initial_state_function("x1: 0, x2: z - 0.9", nm, model=model)
    observer = ContinuousObserver.from_discretization(
        discretize(nm, "galerkin", 16), SENSORS, GAIN, (1.0,)
    )
    return nm, plant, observer, plant.project(x0)


@pytest.fixture(scope="module")
def runs(beam):
    _, plant, observer, e0 = beam
    cases = {"average 1 ms": ("average", 1e-3), "average 10 ms": ("average", 1e-2)}
    cases.update({"point 1 ms": ("point", 1e-3), "point 0.1 ms": ("point", 1e-4)})
    return {
        name: verify_observer(plant, observer, SENSORS, dt=dt, sampler=s, x0=e0, t_end=5.0)
        for name, (s, dt) in cases.items()
    }


def test_the_issue_measurements_are_reproduced(runs):
    # tip error |w(1) - ŵ(1)| at t = 5 s; the independent figures are given to one digit
    at_5 = {name: abs(float(v.error[-1, 0])) for name, v in runs.items()}
    continuous = abs(float(runs["point 1 ms"].continuous_error[-1, 0]))
    assert 3e-6 < continuous < 6e-6, continuous  # ~4e-6
    assert 1e-2 < at_5["point 1 ms"] < 3e-2, at_5  # ~2e-2
    assert 4e-5 < at_5["point 0.1 ms"] < 1.1e-4, at_5  # ~7e-5


def test_averaged_samples_at_1_ms_keep_the_continuous_accuracy(runs):
    v = runs["average 1 ms"]
    assert v.floor <= 2 * v.continuous_floor, (v.floor, v.continuous_floor)
    assert v.warnings == ()


def test_averaged_samples_at_10_ms_do_not_alias(runs):
    v = runs["average 10 ms"]
    assert v.floor <= 10 * v.continuous_floor, (v.floor, v.continuous_floor)
    assert v.warnings == ()


@pytest.mark.xfail(
    strict=True,
    reason="measured 2.04x (1.5x to 2.7x over each later second of a 10 s run), not the "
    "issue's 2x; the held-mean update gave 3.0x. Two causes, both of the 10 ms average "
    "itself: error modes above the 314 rad/s Nyquist frequency are damped only through "
    "their means, which nearly vanish near 2πj/dt (six pole pairs of the sampled error "
    "system decay at 0.14 to 0.82 1/s, where the continuous one has three Galerkin "
    "artefacts right of -2.5): 1.7x already on a plant equal to the observer's model; and "
    "the plant's modes the degree-16 model does not reproduce fold into the band, "
    "attenuated only by |sinc(ω dt / 2)|. The ratio grows with the observer's degree "
    "(1.30x at 12, 2.36x at 20, 2.65x at 24). With the plant's own model as the observer "
    "it is 6.8x (test_the_10_ms_gap_to_its_own_continuous_floor_is_the_periods_slow_decay): "
    "the part of the gap no order removes is the 10 ms average's slow modes",
)
def test_averaged_samples_at_10_ms_within_2x_of_the_continuous_observer(runs):
    v = runs["average 10 ms"]
    assert v.floor <= 2 * v.continuous_floor, (v.floor, v.continuous_floor)


def test_the_10_ms_gap_to_its_own_continuous_floor_is_the_periods_slow_decay(beam):
    # Why the 2x above cannot be reached by raising the order: the ratio to the observer's
    # OWN continuous floor grows with it (2.2, 2.4, 2.8, 3.7 at degrees 16, 20, 24, 32,
    # measured by an independent review): a higher order lowers the 10 ms floor (degree 16
    # 5.2e-5, degree 20 3.2e-5) but the continuous one faster, and the 10 ms floor levels
    # off near 2.7e-5. That part is the period's: let the observer run the plant's own
    # model (degree 48, nothing unmodeled to alias). The error then obeys the sampled error
    # recursion exactly (module docstring of sampled_discretization: e_{k+1} =
    # (Phi - Gamma M K C_s) e_k, the observer's own A). Measured: floor 2.68e-5 at T = 5 s
    # against 3.9e-6 continuous (6.8x); at T = 10 s, 1.68e-5 against 1.3e-9. The floor is
    # a transient: it falls like exp(sigma T), sigma the slowest decay rate ln|mu| / dt of
    # that recursion (-0.102 1/s; its next poles are -0.104 to -0.107 1/s, whose beats in
    # the envelope allow the 0.03 1/s tolerance; measured ln(0.627) / 5 = -0.093). These
    # are modes near multiples of 2 pi / dt (3753 to 7656 rad/s), damped only through
    # their interval means, at about their open-loop rate (max Re of E^-1 (J - R) is
    # -0.100); the continuous observer damps the same modes at -5.6 to -11. (Its own
    # unexcited Galerkin artefacts also sit near -0.100: the "-2.9" below is the converged
    # abscissa, not the continuous system's slowest rate.)
    _, plant, _, e0 = beam
    exact = ContinuousObserver.from_discretization(plant, SENSORS, GAIN, (1.0,))
    floors = {}
    for t_end in (5.0, 10.0):
        n = round(t_end / 1e-2)
        _, _, floors[t_end], _ = run_against_continuous(
            plant, exact, SENSORS, sampler="average", x0=e0, dt=1e-2, n_steps=n, stride=2
        )
    sampled_5, continuous_5 = floors[5.0]
    assert sampled_5 > 5 * continuous_5, floors
    mu = np.linalg.eigvals(exact.sampled(1e-2, "average").A)
    sigma = float(np.max(np.log(np.abs(mu)))) / 1e-2
    assert -0.2 < sigma < 0, sigma  # the slowest sampled mode, against the converged -2.9
    observed = math.log(floors[10.0][0] / sampled_5) / 5.0
    assert abs(observed - sigma) < 0.03, (observed, sigma)


def test_a_higher_order_at_10_ms_reaches_the_degree_16_continuous_floor(beam, runs):
    # The design answer the verification's hint gives ("a smaller dt or a higher order"):
    # averaged at 10 ms, a degree-20 observer (42 states, within the degree-48 plant's
    # half) reaches the degree-16 continuous observer's floor within 2x (measured 3.15e-5
    # against 2.54e-5, 1.24x), where the degree-16 one itself is at 2.04x.
    nm, plant, _, e0 = beam
    higher = ContinuousObserver.from_discretization(
        discretize(nm, "galerkin", 20), SENSORS, GAIN, (1.0,)
    )
    v = verify_observer(plant, higher, SENSORS, dt=1e-2, sampler="average", x0=e0, t_end=5.0)
    reference = runs["average 10 ms"].continuous_floor
    assert v.floor <= 2 * reference, (v.floor, reference)
    assert v.warnings == ()


def test_averaged_samples_at_10_ms_keep_the_continuous_accuracy_on_resolved_content(beam):
    # The paper's x0 restricted to the plant's first three modes (|λ| < 100 rad/s, below
    # the Nyquist frequency π/dt = 314 rad/s, and resolved by the degree-16 observer to
    # 1e-13): the observer's model predicts their means over each period exactly, so the
    # sampled error follows the model's error recursion, whose rightmost pole at 10 ms is
    # exp(λ dt) of the continuous one (λ = -2.911 ± 2.514i, the converged abscissa) to
    # 1e-5. The floors then agree: within 1.2x (measured 1.07x; comparing the held mean
    # with the observer's evolving output instead gave 8.6x).
    _, plant, observer, e0 = beam
    lam, modes = np.linalg.eig(np.linalg.solve(plant.E, plant.J - plant.R))
    keep = np.abs(lam) < 100.0
    assert np.count_nonzero(keep) == 6  # three conjugate pairs
    x0 = np.real(modes[:, keep] @ np.linalg.solve(modes, e0)[keep])
    v = verify_observer(plant, observer, SENSORS, dt=1e-2, sampler="average", x0=x0, t_end=5.0)
    assert v.floor <= 1.2 * v.continuous_floor, (v.floor, v.continuous_floor)


def test_point_samples_at_1_ms_trigger_the_aliasing_warning(runs):
    v = runs["point 1 ms"]
    assert v.floor > 100 * v.continuous_floor
    assert len(v.warnings) == 1
    assert "aliases the plant's high frequencies" in v.warnings[0]
    assert "use `sampler='average'`" in v.warnings[0]


def test_verification_needs_a_plant_twice_the_order(beam):
    nm, _, _, _ = beam
    small = discretize(nm, "galerkin", 30)  # 62 states < 2 x 34
    _, _, observer, _ = beam
    with pytest.raises(NumericError, match=r"at least 68 states; the plant .* has 62"):
        verify_observer(small, observer, SENSORS, dt=1e-3, sampler="average",
                        x0=np.zeros(62), t_end=1.0)  # fmt: skip


@pytest.fixture(scope="module")
def wave():
    nm = to_numeric(load_builtin("wave"))
    C_m, L = np.array([[0.0, 1.0]]), np.array([[0.5]])
    plant = discretize(nm, "galerkin", 48)
    e0 = plant.project(lambda z: np.stack([np.zeros_like(z), np.cos(np.pi * z / 2)], axis=1))
    return nm, C_m, L, plant, e0


def _exact_wave_poles(k, count):
    alpha = 0.5 * math.log((1 - k) / (1 + k))
    return np.array([alpha + 1j * s * (m + 0.5) * math.pi for m in range(count) for s in (1, -1)])


def test_order_selection_meets_its_targets_on_the_wave(wave):
    nm, C_m, L, plant, e0 = wave
    selection, observer = select_order(nm, C_m, L, plant=plant, x0=e0, t_end=5.0)
    exact = _exact_wave_poles(0.5, 3)  # the 6 rightmost eigenvalues (3 conjugate pairs)
    poles = np.linalg.eigvals(observer.A)
    gaps = [np.min(np.abs(poles - z)) / abs(z) for z in exact]
    assert max(gaps) <= selection.tol
    assert selection.floor <= selection.output_tol
    # minimal: the degree below misses a target
    below = [c for c in selection.candidates if c.degree == selection.degree - 1]
    assert below
    assert not below[0].passed
    # the Galerkin observer's unresolved modes sit right of the exact abscissa ½ ln(1/3)
    assert abs(selection.abscissa - 0.5 * math.log(1 / 3)) < 1e-8
    assert selection.spurious > 0
    assert selection.spurious_max_real > 0.5 * math.log(1 / 3)
    assert any("poles right of the converged abscissa" in w for w in selection.warnings)


def test_modal_reduction_keeps_only_exact_eigenvalues(wave):
    nm, C_m, L, plant, e0 = wave
    selection, observer = select_order(
        nm, C_m, L, plant=plant, x0=e0, t_end=5.0, reduction="modal"
    )
    poles = np.linalg.eigvals(observer.A)
    exact = _exact_wave_poles(0.5, poles.size)
    for z in poles:  # every pole is one of ½ ln(1/3) ± i (m + ½) π
        assert np.min(np.abs(exact - z)) <= 1e-6 * abs(z), z
    assert selection.spurious == 0
    assert selection.order == poles.size < selection.full_order
    assert any("unresolved modes" in line for line in selection.dropped)
    Q = observer.energy_matrix  # Vᵀ E V: the energy of the kept efforts
    assert np.allclose(Q, Q.T)
    assert np.min(np.linalg.eigvalsh(Q)) > 0


def test_balanced_truncation_obeys_the_twice_the_tail_bound(wave):
    # ‖G - G_r‖∞ ≤ 2 Σ_{i>r} σ_i (Glover); σ checked against gramians from scipy's
    # Lyapunov solver, an independent computation
    import scipy.linalg as sl

    pytest.importorskip("slycot", reason="balanced truncation needs slycot (extra 'reduce')")

    nm, C_m, L, *_ = wave
    observer = ContinuousObserver.from_discretization(discretize(nm, "galerkin", 6), C_m, L)
    _, sigma, reduce = balanced_truncation(observer)
    A, B, C = observer.A, observer.B, observer.C
    Wc = sl.solve_continuous_lyapunov(A, -B @ B.T)
    Wo = sl.solve_continuous_lyapunov(A.T, -C.T @ C)
    independent = np.sqrt(np.sort(np.abs(np.linalg.eigvals(Wc @ Wo)))[::-1])
    assert np.allclose(sigma, independent, rtol=1e-6, atol=1e-9 * sigma[0])
    for r in (4, 8):
        red = reduce(r)
        w = np.linspace(0.0, 60.0, 1201)
        err = max(
            np.linalg.norm(
                C @ np.linalg.solve(1j * x * np.eye(A.shape[0]) - A, B)
                - red.C @ np.linalg.solve(1j * x * np.eye(r) - red.A, red.B),
                2,
            )
            for x in w
        )
        assert err <= 2 * sigma[r:].sum() * (1 + 1e-8), (r, err, 2 * sigma[r:].sum())


def test_balanced_truncation_without_slycot_says_how_to_get_it(wave, monkeypatch):
    nm, C_m, L, *_ = wave
    observer = ContinuousObserver.from_discretization(discretize(nm, "galerkin", 6), C_m, L)
    monkeypatch.setattr(reduction_module, "_slycot_available", lambda: False)
    with pytest.raises(NumericError, match=r"needs slycot .* pip install slycot"):
        balanced_truncation(observer)


def test_export_default_order_on_the_beam_meets_the_targets(beam):
    nm, *_ = beam
    obs = export_observer(nm, SENSORS, GAIN, dt=1e-3)
    sel = obs.selection
    assert sel.order == 2 * (sel.degree + 1)
    assert sel.reduction == "none"
    assert sel.eigen_error <= sel.tol
    assert sel.floor <= sel.output_tol
    # the converged abscissa of design 2 (README, checked against the characteristic
    # determinant in tests/numeric/spectrum/test_numeric_spectrum.py)
    assert abs(sel.abscissa + 2.9106562986) < 1e-9
    assert "Galerkin degrees" in sel.dropped[0]
    assert len(repr(obs)) <= 300


def test_the_verification_says_when_its_plant_does_not_resolve_its_own_outputs():
    # FEEDTHROUGH (a wave with dampers at both ends): from the default initial state, which
    # violates the boundary conditions, the Galerkin plant's boundary traces keep an
    # unresolved part of the size of the signal (its top modes lose the boundary damping),
    # so the floor measures the plant. Raising the plant's degree by half moves its own
    # outputs by more than the continuous observer's floor (4.37 against 2.35, 20 states):
    # said. From x2 = sin(pi z), x1 = 0, which meets u = 0 (2 e1(0) = e2(1) = 0), they move
    # by 0.016 against a floor of 0.042: not said. The paper's beam: 0.07 of its floor.
    from numeric_models import FEEDTHROUGH

    from phdesign.numeric.sampled.plant_resolution import GAP_RATIO

    nm = to_numeric(FEEDTHROUGH)
    options = {"dt": 1e-2, "order": 20, "verify": True}
    exported = export_observer(nm, np.eye(2), np.diag([0.5, 2.0]), **options)
    rough = exported.verification
    assert rough.plant_gap > rough.continuous_floor
    assert any("does not resolve its own outputs" in w for w in rough.warnings)
    # and the order selection, which missed its floor target 1e-3, says why: the plant's
    # own outputs move by their whole peak (measured 1.0 of it) over the last fifth
    assert any("to the performance target" in w for w in exported.selection.warnings)
    smooth_x0 = initial_state_function("x1: 0, x2: sin(pi*z)", nm, model=FEEDTHROUGH)
    smooth = export_observer(nm, np.eye(2), np.diag([0.5, 2.0]), x0=smooth_x0, **options)
    v = smooth.verification
    assert v.plant_gap < GAP_RATIO * v.continuous_floor
    assert not any("does not resolve" in w for w in v.warnings)
    assert v.to_dict()["plant_gap"] == v.plant_gap


def test_a_verification_plant_at_the_largest_resolution_says_its_resolution_is_unchecked(wave):
    # the wave's largest Galerkin degree is 100 (spectrum_resolutions): no finer plant
    # exists to check the verification plant against, and the report must say so rather
    # than leave plant_gap None in silence
    nm, C_m, L, *_ = wave
    v = export_observer(nm, C_m, L, dt=1e-2, order=12, verify=True, plant_resolution=100)
    assert v.verification.plant_gap is None
    assert any("largest Galerkin resolution" in w for w in v.verification.warnings)
