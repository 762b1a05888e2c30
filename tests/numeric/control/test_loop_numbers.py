"""Numbers of the observer-based loop: assembled spectrum, separation, simulation, export.

Independent references: characteristic determinants of the beam solved in mpmath (derived
in the docstrings), the union of the blocks' spectra computed by the library's
``spectrum`` (a different code path: the discretization closed by ``closed_matrix``), the
physical power flows of plant and error (written here from the port maps, not from the
assembled matrix), and ``simulate`` of the controlled plant and of the observer.
"""

from __future__ import annotations

import json

import mpmath
import numpy as np
import pytest
import scipy.linalg as sl
from characteristic import beam_determinant

from phdesign.core.errors import LoopError
from phdesign.design.loop import Loop
from phdesign.models import load_builtin
from phdesign.numeric.bridge import NumericModel, constant_H, to_numeric
from phdesign.numeric.control.assembly import NumericLoop, assemble
from phdesign.numeric.control.simulation import simulate_loop
from phdesign.numeric.control.spectrum import loop_spectrum
from phdesign.numeric.control.tuning import tune_loop
from phdesign.numeric.discretization.phs import DiscretePHS
from phdesign.numeric.discretization.registry import discretize
from phdesign.numeric.inputs import initial_state_function
from phdesign.numeric.time.options import SimulationOptions
from phdesign.numeric.time.simulation import simulate
from phdesign.symbolic.closing import close_inputs

BEAM = load_builtin("euler-bernoulli")


def _roots_from_the_undamped_cantilever(**gains):
    """Follow each undamped cantilever mode iω, ω = β², to a root of the damped determinant."""
    betas = (1.8751040687, 4.6940911330, 7.8547574382, 10.9955407349, 14.1371683910)
    roots = []
    with mpmath.workdps(30):
        for b in betas:
            f = lambda x: beam_determinant(x, **gains)  # noqa: E731
            root = mpmath.findroot(f, 1j * b * b - 0.3, tol=1e-40, verify=False)
            assert abs(f(root)) < 1e-20  # a root, to far below double precision
            roots.append(complex(root))
    return roots


def test_estimated_tip_rotation_damps_the_undamped_beam_that_only_its_tip_velocity_sees():
    """d = 0, u3 = -ŷ3 (tip torque from the estimated rotation rate), only y4 measured.

    y4 is not collocated with u3, so no measured output can be fed to u3; the estimate can.
    The controlled plant u3 = -y3 against its determinant, the error system (ũ4 = -l ỹ4)
    against its own, and the assembled loop's abscissa = the max of the two.
    """
    loop = Loop(BEAM, actuate=3, feedback=1, sensors=[4], gain=1, parameters={"d": 0})
    with pytest.raises(LoopError, match="y4 = -e1\\(1\\) is not collocated with the actuated"):
        Loop(BEAM, actuate=3, sensors=[4], feedback_outputs=4)  # u3 = -k y4: no damper
    with pytest.raises(LoopError, match="is not measured by these sensors"):
        Loop(BEAM, actuate=3, sensors=[4], feedback_source="measured")  # y3 is not measured
    report = loop.spectrum(count=10)
    assert report.converged
    assert report.plant.converged
    assert report.error.converged
    plant_roots = _roots_from_the_undamped_cantilever(torque=1.0)
    error_roots = _roots_from_the_undamped_cantilever(shear=1.0)
    alpha_plant = max(r.real for r in plant_roots)
    alpha_error = max(r.real for r in error_roots)
    # every root is an eigenvalue of the loop's converged spectrum, and the top ones agree
    assert abs(report.plant_abscissa - alpha_plant) < 1e-10
    assert abs(report.error_abscissa - alpha_error) < 1e-10
    assert alpha_plant < -0.7
    assert alpha_error < alpha_plant
    # the loop's abscissa to its resolved digits (the coupling K ỹ3 costs a few digits)
    tolerance = 10 * 10 ** (-report.digits) * max(1.0, abs(report.spectral_abscissa))
    assert abs(report.spectral_abscissa - max(alpha_plant, alpha_error)) < max(tolerance, 1e-10)
    # every determinant root right of the last reported loop eigenvalue is reported
    last = min(z.real for z in report.rightmost)
    for z in plant_roots + error_roots:
        if z.real > last + 1e-9:
            assert min(abs(w - z) for w in report.rightmost) < 1e-9 * abs(z), z
    assert report.origin[0] == "plant"


#: Round-off the drift test cannot see (both resolutions share it). The blocks and the loop
#: are solved by the same shift and invert: on the beam below, against the mpmath root, the
#: plant's abscissa is off by 4.7e-15 and the loop's by 1.5e-13 (the QZ stage used before
#: left the plant 4.3e-12 off); 1e-12 keeps a margin of about 7 over the larger.
EIGEN_ROUNDOFF = 1e-12


def _assert_union(report, count):
    """Each rightmost loop eigenvalue is in the union of the blocks' converged spectra."""
    union = list(report.plant.rightmost) + list(report.error.rightmost)
    union += [w.conjugate() for w in union]  # real matrices: the lists cut pairs at the end
    scale = max(1.0, abs(report.spectral_abscissa))
    digits = min(report.digits, report.plant.digits, report.error.digits)
    tolerance = 10 * 10 ** (-digits) * scale + EIGEN_ROUNDOFF
    for z in report.rightmost:
        assert min(abs(w - z) for w in union) <= tolerance * max(1.0, abs(z)), z
    # and the rightmost of the union are all there: the loop does not lose an eigenvalue
    top = sorted(union, key=lambda w: (-round(w.real, 8), abs(w.imag)))[: count // 2]
    for w in top:
        assert min(abs(w - z) for z in report.rightmost) <= tolerance * max(1.0, abs(w)), w
    assert abs(report.separation_gap) <= tolerance
    assert report.triangular_residual < 1e-13


def test_assembled_spectrum_is_the_union_of_the_two_blocks_on_the_beam():
    nm = to_numeric(BEAM)  # d = 0.2
    loop = NumericLoop((2,), np.array([[0.5]]), np.array([[0, 0, 0, 1.0]]), np.array([[2.0]]))
    report = loop_spectrum(nm, loop, count=8)
    assert report.converged
    assert report.digits > 12
    _assert_union(report, 8)
    # the abscissa against the determinant with damping: mu^4 = -(lambda^2 + d lambda)
    with mpmath.workdps(30):
        guess = mpmath.mpc(report.spectral_abscissa, abs(report.rightmost[0].imag))
        root = mpmath.findroot(
            lambda x: beam_determinant(x, torque=0.5, damping=0.2), guess, tol=1e-40, verify=False
        )
        assert abs(beam_determinant(root, torque=0.5, damping=0.2)) < 1e-20
    assert abs(report.spectral_abscissa - float(root.real)) < 1e-12
    assert abs(report.plant_abscissa - float(root.real)) < EIGEN_ROUNDOFF


def test_assembled_spectrum_is_the_union_of_the_two_blocks_on_timoshenko():
    # tip shear force and moment from the estimated tip velocities, the tip velocities measured
    nm = to_numeric(load_builtin("timoshenko"))
    C_m = np.eye(4)[[2, 3]]
    loop = NumericLoop((2, 3), np.diag([0.5, 2.0]), C_m, np.eye(2))
    report = loop_spectrum(nm, loop, count=8)
    assert report.converged
    assert report.origin[0] == "plant"  # the slower block (-0.5127 against -0.7791)
    _assert_union(report, 8)


def test_the_assembly_with_a_feedthrough_is_still_block_triangular():
    """A synthetic port-Hamiltonian system with D = -Dᵀ ≠ 0 (what finite differences give).

    Its loop spectrum must equal the eigenvalues of the two closed matrices that
    ``DiscretePHS.closed_matrix`` builds ((I + K D)⁻¹ K solved there, independently).
    """
    rng = np.random.default_rng(7)
    n, m = 12, 3
    M = rng.normal(size=(n, n))
    E = M @ M.T + n * np.eye(n)
    S = rng.normal(size=(n, n))
    Rf = rng.normal(size=(n, 2))
    D = np.array([[0.0, 0.4, -0.2], [-0.4, 0.0, 0.3], [0.2, -0.3, 0.0]])
    nm = NumericModel(
        "synthetic",
        (0.0, 1.0),
        1,
        3,
        (np.zeros((3, 3)), np.eye(3)),
        constant_H(np.eye(3)),
        np.zeros((3, 6)),
        np.zeros((3, 6)),
    )
    d = DiscretePHS(
        nm,
        "galerkin",
        1,
        E,
        S - S.T,
        Rf @ Rf.T,
        rng.normal(size=(n, m)),
        D,
        lambda z: z,
        lambda f: f,
    )
    K, C_m, L = np.array([[1.5]]), np.eye(3)[[0, 2]], np.diag([0.7, 2.0])
    system = assemble(d, NumericLoop((1,), K, C_m, L))
    assert system.triangular_residual < 1e-14
    lam = np.sort_complex(sl.eigvals(system.A, system.E))
    S_a = np.eye(m)[[1]]
    blocks = np.concatenate(
        [
            sl.eigvals(d.closed_matrix(S_a.T @ K @ S_a), E),
            sl.eigvals(d.closed_matrix(C_m.T @ L @ C_m), E),
        ]
    )
    for z in lam:
        assert np.min(np.abs(blocks - z)) < 1e-10 * max(1, abs(z))


def _physical_power(system):
    """Quadratic form of d/dt (H + H̃) in Z = (ê, ẽ), from the port maps alone (D = 0).

    Plant: -êᵀRê + uᵀy with y = Bᵀê, u_a = -K ŷ_a, ŷ = y - ỹ; error: -ẽᵀRẽ + ũᵀỹ with
    ũ = -C_mᵀ L C_m ỹ, ỹ = Bᵀẽ.
    """
    d, loop = system.discrete, system.loop
    n, m = d.dim, d.n_ports
    S_a = np.eye(m)[list(loop.actuated)]
    y = np.hstack([d.B.T, np.zeros((m, n))])
    y_err = np.hstack([np.zeros((m, n)), d.B.T])
    u = -S_a.T @ loop.K @ S_a @ (y - y_err)
    G = loop.C_m.T @ loop.L @ loop.C_m
    R = sl.block_diag(d.R, d.R)
    P = -R + 0.5 * (u.T @ y + y.T @ u) - y_err.T @ (0.5 * (G + G.T)) @ y_err
    return P


def _power_integral(F, P, dt):
    """Integral of exp(F^T s) P exp(F s) over [0, dt] (Van Loan), on dt/2^m doubled back.

    exp(-F^T dt) overflows for the stiff loop, so the block is taken on a step with
    |F| delta <= 1 and G(2 delta) = G(delta) + exp(F delta)^T G(delta) exp(F delta).
    """
    n = F.shape[0]
    doublings = max(0, int(np.ceil(np.log2(max(np.linalg.norm(F, 1) * dt, 1.0)))))
    delta = dt / 2**doublings
    block = np.zeros((2 * n, 2 * n))
    block[:n, :n], block[:n, n:], block[n:, n:] = -F.T, P, F
    ex = sl.expm(block * delta)
    Phi, G = ex[n:, n:], ex[n:, n:].T @ ex[:n, n:]
    for _ in range(doublings):
        G, Phi = G + Phi.T @ G @ Phi, Phi @ Phi
    return 0.5 * (G + G.T)


def test_the_loops_energy_balance_is_audited_exactly():
    """ΔH + ΔH̃ over each step = ∫ physical power (Van Loan), to round-off; plus the audits."""
    loop = Loop(BEAM, actuate=3, feedback=1, sensors=[4], gain=1, resolution=20)
    run = loop.simulate(x0="x1: 0, x2: z - 0.9", t_end=2.0, samples=81)
    # round-off of exact stepping; the torque damper's derivative trace makes the loop stiff
    # (‖E⁻¹A‖ Δt ~ 1e5 at degree 20): 1e-10 leaves a factor ~5 over what it shows
    assert run.info["energy_balance_residual_loop"] < 1e-10
    assert run.info["energy_balance_residual_error_system"] < 1e-12
    assert not run.warnings
    system = loop.assemble()
    A_Z, _ = system.error_coordinates()
    F = np.linalg.solve(system.E, A_Z)
    P = _physical_power(system)
    G = _power_integral(F, P, float(run.t[1] - run.t[0]))
    Z = np.hstack([run.states, run.states_err])
    change = np.einsum("ki,ij,kj->k", Z[:-1], G, Z[:-1])
    total = run.H + run.H_err
    # to the round-off the audit allows above (1e-10 of the energy), step by step
    np.testing.assert_allclose(np.diff(total), change, rtol=0, atol=1e-10 * total[0])
    assert np.max(np.abs(np.diff(total))) > 1e3 * 1e-10 * total[0]  # the test can see a change
    # the controller's law holds at every sample: u3 = -K ŷ3
    np.testing.assert_allclose(run.u[:, 2], -run.y_hat[:, 2], atol=1e-13)
    assert np.all(run.u[:, [0, 1, 3]] == 0)
    assert run.H[-1] < 0.05 * run.H[0]
    assert run.H_err[-1] < 1e-3 * run.H_err[0]


def test_the_loop_reproduces_the_controlled_plant_and_the_observer_error():
    nm = to_numeric(BEAM)
    x0 = initial_state_function("x1: 0, x2: z - 0.9", nm, model=BEAM)
    C_m, L, K = np.eye(4)[[2, 3]], np.diag([0.1, 1.0]), np.array([[2.0]])
    options = SimulationOptions(t_end=1.0, samples=21, resolution=16)
    measured = simulate_loop(nm, NumericLoop((2,), K, C_m, L, "measured"), x0=x0, options=options)
    closed_model = close_inputs(BEAM, [3], [[2]])
    closed = to_numeric(closed_model)
    x0_closed = initial_state_function("x1: 0, x2: z - 0.9", closed, model=closed_model)
    plant = simulate(closed, x0=x0_closed, options=options)
    np.testing.assert_allclose(measured.H, plant.H, rtol=1e-10)
    estimated = simulate_loop(nm, NumericLoop((2,), K, C_m, L), x0=x0, options=options)
    observer = simulate(nm, C_m, L, x0=x0, options=options)
    # the error system does not see u (the observer knows it): the same error energy
    np.testing.assert_allclose(estimated.H_err, observer.H_err, rtol=1e-9)
    assert not np.allclose(estimated.H, plant.H)  # the estimate is not the measurement


def test_the_loop_exports_to_python_control_with_named_signals():
    loop = Loop(BEAM, actuate=3, feedback=1, sensors=[4], gain=1, resolution=12)
    ss = loop.statespace()
    system = loop.assemble()
    assert ss.input_labels == ["u1", "u2", "u4"]
    assert ss.output_labels[:4] == ["y1", "y2", "y3", "y4"]
    assert ss.output_labels[-4:] == ["u1", "u2", "u3", "u4"]
    assert ss.state_labels[0] == "e1[0]"
    assert ss.state_labels[system.dim] == "hat_e1[0]"
    lam = sl.eigvals(system.A, system.E)
    for pole in ss.poles():  # the same pencil, through python-control's eigensolver
        assert np.min(np.abs(lam - pole)) <= 1e-8 * max(1.0, abs(pole))
    # the output u3 is the controller's law -K ŷ3, row by row
    np.testing.assert_allclose(ss.C[8 + 2], -ss.C[4 + 2], atol=1e-12)


def test_tuning_splits_by_separation_and_is_verified_on_the_assembled_loop():
    nm = to_numeric(BEAM, {"d": 0})
    start = NumericLoop((2,), np.array([[1.0]]), np.array([[0, 0, 0, 1.0]]), np.array([[1.0]]))
    result = tune_loop(nm, start, target="both", starts=1, maxiter=40)
    before = loop_spectrum(nm, start)
    assert result.plant is not None
    assert result.error is not None
    assert result.report.plant_abscissa <= before.plant_abscissa + 1e-9
    assert result.report.error_abscissa <= before.error_abscissa + 1e-9
    report = result.report
    assert report.converged
    expected = max(result.plant.spectral_abscissa, result.error.spectral_abscissa)
    assert abs(result.spectral_abscissa - expected) < 1e-8
    assert result.limited_by == "plant"
    payload = json.loads(json.dumps(result.to_dict()))
    assert payload["tuned"] == "both"
    assert payload["feedback"] == result.loop.K.tolist()


def test_results_print_as_the_command_line_and_stay_json():
    loop = Loop(BEAM, actuate=3, feedback=1, sensors=[4], gain=1, resolution=12)
    run = loop.simulate(t_end=0.5, samples=6, x0="x1: 0, x2: z")
    head = str(run).splitlines()[0].split(",")
    assert head[:5] == ["t", "H", "H_hat", "H_err", "y1"]
    assert head[-4:] == ["u1", "u2", "u3", "u4"]
    assert 0 < run.time_below(0.5) < 0.5  # a SimulationResult: its questions work
    assert len(repr(run)) <= 300
    assert "<table>" in run._repr_html_()
    assert json.loads(run.to_json())["actuated"] == [3]
    with pytest.raises(Exception, match="u3 is actuated by the feedback"):
        loop.simulate(u="u3: sin(t)", t_end=0.5, samples=6)
    free = loop.simulate(u="u4: 0.1*sin(t)", t_end=0.5, samples=6)
    assert "energy_balance_residual_loop" not in free.info  # not autonomous: not audited
    assert free.info["energy_balance_residual_error_system"] < 1e-12


def test_a_hand_built_numeric_loop_refuses_a_feedback_gain_without_positive_symmetric_part():
    # K = [[1, 3], [-3, -1]]: K + Kᵀ = diag(2, -2), smallest eigenvalue -2 (by hand); the
    # loop's dissipation -ỹᵀ sym(K) ỹ needs sym(K) ≻ 0, so assemble must refuse it as the
    # symbolic reader does, naming the matrix and the eigenvalue found
    d = discretize(to_numeric(BEAM), "galerkin", 8)
    C_m = np.array([[0, 0, 1.0, 0], [0, 0, 0, 1.0]])
    bad = NumericLoop((2, 3), np.array([[1.0, 3.0], [-3.0, -1.0]]), C_m, np.eye(2))
    with pytest.raises(LoopError, match=r"K \+ K\^T must be symmetric positive definite; found "
                       r"smallest eigenvalue -2"):  # fmt: skip
        assemble(d, bad)
    singular = NumericLoop((2,), np.zeros((1, 1)), C_m, np.eye(2))  # K = 0: open loop
    with pytest.raises(LoopError, match="smallest eigenvalue 0"):
        assemble(d, singular)
    skew_part = NumericLoop((2, 3), np.array([[1.0, 5.0], [-5.0, 1.0]]), C_m, np.eye(2))
    assert assemble(d, skew_part).A.shape == (2 * d.dim, 2 * d.dim)  # sym(K) = I is enough


def test_loop_tune_passes_on_a_tuning_that_located_no_optimum():
    # the error-system tuning of the wave with dampers at both ends has no optimum (its
    # abscissa falls without bound toward L = diag(0, 1): test_numeric_tune); the loop's
    # result must say so, not print the last gain as tuned without comment
    from numeric_models import FEEDTHROUGH

    nm = to_numeric(FEEDTHROUGH)
    loop = NumericLoop((0,), np.array([[1.0]]), np.eye(2), np.eye(2))
    result = tune_loop(nm, loop, target="gain", starts=1, maxiter=100)
    assert result.error is not None
    assert result.error.status == "descending"
    assert any(w.startswith("the tuned error system: no optimum located") for w in result.warnings)
    assert "no optimum located" in str(result)
