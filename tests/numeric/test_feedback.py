"""Boundary feedback in the plant ([feedback]): closed ports, propositions, numbers.

Expected values come from hand derivations written next to each check, from the exact
damped-wave formula of DESIGN.md, and from a characteristic determinant solved in mpmath.
"""

from __future__ import annotations

import mpmath
import numpy as np
import pytest
import scipy.linalg as sl
import sympy
from hypothesis import given, settings
from hypothesis import strategies as st

from phdesign.core.errors import ModelError
from phdesign.io import model_from_toml, model_to_toml
from phdesign.models import load_builtin
from phdesign.numeric.bridge import to_numeric
from phdesign.numeric.discretization.galerkin import galerkin
from phdesign.numeric.discretization.registry import discretize
from phdesign.numeric.inputs import initial_state_function
from phdesign.numeric.spectrum.converged import spectrum
from phdesign.numeric.statespace import plant_statespace
from phdesign.numeric.time.options import SimulationOptions
from phdesign.numeric.time.simulation import simulate
from phdesign.symbolic.classify import classify
from phdesign.symbolic.closing import close_inputs, closed_ports
from phdesign.symbolic.model import BCPHS
from phdesign.symbolic.observer import gain_matrix, sensor_matrix
from phdesign.symbolic.ports import derive_ports, q_matrix
from phdesign.symbolic.search import search_sensors

K_STRING = 0.5  # the default damper of the built-in wave-damper


def test_damped_string_plant_abscissa_is_exact_through_spectrum():
    """DESIGN.md: u_z(1) = -k u_t(1), u(0) = 0 has abscissa 1/2 ln|(1 - k)/(1 + k)|."""
    report = spectrum(to_numeric(load_builtin("wave-damper")))  # the plant: no sensors
    exact = 0.5 * np.log(abs((1 - K_STRING) / (1 + K_STRING)))
    assert report.converged
    assert abs(report.spectral_abscissa - exact) < 1e-10
    # the eigenvalues themselves: exact + i (m + 1/2) pi for k < 1 (DESIGN.md)
    top = sorted(report.rightmost, key=lambda z: abs(z.imag))[:2]
    assert all(abs(z - complex(exact, np.copysign(np.pi / 2, z.imag))) < 1e-10 for z in top)


def test_closing_an_input_of_the_wave_gives_the_built_in_damped_string():
    damped = close_inputs(load_builtin("wave"), [2], [["1/2"]])
    builtin = load_builtin("wave-damper")
    assert damped.feedback.inputs == (2,)
    assert damped.n_ports == 1
    defaults = builtin.parameter_defaults  # k = 1/2
    assert closed_ports(damped).boundary == closed_ports(builtin).boundary.xreplace(defaults)
    # closing the last external input as well: K block-diagonal over the open indices
    both = close_inputs(damped, [1], [[2]])
    assert both.feedback.inputs == (2, 1)
    assert both.n_ports == 0
    assert both.feedback.gain == sympy.diag(sympy.Rational(1, 2), 2)
    with pytest.raises(ModelError, match="inputs\\[1\\] = 2 is not an external input"):
        close_inputs(damped, [2], [[1]])


def test_closed_plant_energy_balance_on_the_admissible_traces():
    r"""½ vᵀ diag(Q, -Q) v = u_rᵀ y_r - y_cᵀ K y_c for every v with (U_c + K Y_c) v = 0.

    The traces are parametrized by free symbols (u_r, y): v = T⁻¹(u; y) with u_c = -K y_c.
    """
    beam = load_builtin("beam-tip-damper")
    ports, closed = derive_ports(beam), closed_ports(beam)
    k = sympy.Symbol("k", real=True)
    y = sympy.Matrix(sympy.symbols("y1:5", real=True))
    u = sympy.Matrix([*sympy.symbols("u1:4", real=True), -k * y[3]])  # u4 = -k y4
    v = sympy.Matrix.vstack(ports.U, ports.Y).inv() * sympy.Matrix.vstack(u, y)
    assert sympy.simplify(closed.boundary * v) == sympy.zeros(1, 1)
    Q = q_matrix(beam.P, 2)
    power = (v.T * sympy.diag(Q, -Q) * v)[0] / 2
    balance = sum(u[i] * y[i] for i in range(3)) - k * y[3] ** 2
    assert sympy.expand(power - balance) == 0


def test_the_plants_damper_enters_the_left_hand_side_of_the_propositions():
    r"""Wave with the damper at 1, one sensor at 0 (y1 = -e2(0)), gain l (symbolic).

    Error traces: e1(0) = l e2(0) (observer) and e2(1) = -k e1(1) (the plant's damper).
    LHS = l ỹ1² + k ỹ2² with ỹ2 = e1(1).  Proposition 3.2 at b: RHS = e1(1)² + e2(1)²
    = (1 + k²) ỹ2², so κ* = k/(1 + k²) = 2/5 at k = 1/2: it holds only through the
    plant's own dissipation, and on the undamped string the same sensor leaves e1(1) free.
    """
    l1 = gain_matrix("symbolic", 1)
    damped = classify(load_builtin("wave-damper"), sensor_matrix([1], 1), l1)
    at_b = damped.result("3.2", 2)
    assert at_b.holds
    assert at_b.kappa == sympy.Rational(2, 5)
    # at a: RHS = e1(0)² + e2(0)² = (1 + l²) ỹ1², LHS ≥ l ỹ1²: κ* = l/(1 + l²)
    (gain,) = l1.free_symbols
    assert sympy.simplify(damped.result("3.2", 1).kappa - gain / (1 + gain**2)) == 0
    undamped = classify(load_builtin("wave"), sensor_matrix([1], 2), gain_matrix("symbolic", 1))
    assert undamped.result("3.2", 2).holds is False
    # the witness: ỹ2 = e1(1) free (ũ2 = e2(1) = 0 without a sensor there)
    assert [t.label((0, 1)) for t in undamped.result("3.2", 2).free] == ["e1(1)"]


def test_beam_with_a_tip_damper_is_exponential_with_the_tip_rotation_sensor_alone():
    r"""Beam, damper u4 = -k y4 (e2'(1) = k e1(1)), sensor y3 = e1'(1) with gain l.

    Error traces: e1(0) = e1'(0) = 0, e2(1) = -l e1'(1), e2'(1) = k e1(1).  Proposition 3.4,
    variant 3 with x1 = (momentum): RHS = e1(1)² + e2(1)² + e1'(1)² + e1(0)²
    = e1(1)² + (1 + l²) e1'(1)², LHS = k e1(1)² + l e1'(1)², so κ* = min(k, l/(1 + l²)).
    The open beam with y3 alone is inconclusive (README): the damper makes the difference.
    """
    beam = load_builtin("beam-tip-damper")  # k = 1
    result = classify(beam, sensor_matrix([3], 3), gain_matrix("symbolic", 1))
    assert result.verdict == "exponential"
    (gain,) = result.L.free_symbols
    kappa = result.result("3.4", 3).kappa
    # min(1, l/(1 + l²)) = l/(1 + l²) for every l > 0 (1 - l/(1 + l²) = (l² - l + 1)/(1 + l²)
    # has no real root): the dominated branch is dropped, exactly
    assert kappa == gain / (1 + gain**2)
    # variant 2 of 3.1: min(1/2, l/(1 + l²)), and 1/2 - l/(1 + l²) = (l - 1)²/(2 (1 + l²)) ≥ 0
    assert result.result("3.1", 2).kappa == gain / (1 + gain**2)
    # variant 4 of 3.4: min(1/2, 1/l) changes branch at l = 2, so both stay
    assert result.result("3.4", 4).kappa == sympy.Min(sympy.Rational(1, 2), 1 / gain)
    open_beam = classify(load_builtin("euler-bernoulli"), sensor_matrix([3], 4), sympy.eye(1))
    assert open_beam.verdict == "inconclusive"


def test_a_singular_symmetric_part_of_K_leaves_a_direction_undamped():
    r"""Timoshenko, inputs 3 and 4 closed with K = [[1, 1], [-1, 0]]: K + Kᵀ = diag(2, 0).

    y4 = e4(1) is not dissipated (only a gyrator couples it), so on the error traces
    ỹ4 is free whatever the sensors at the other end; the sensor search (combinatorial)
    and the classifier (certificate) must agree on every subset.
    """
    timo = close_inputs(load_builtin("timoshenko"), [3, 4], [[1, 1], [-1, 0]])
    assert "K + K^T >= 0: exact" in " ".join(timo.checks)
    found = search_sensors(timo)
    for subset in found.subsets:
        L = sympy.eye(len(subset.sensors))
        direct = classify(timo, sensor_matrix(list(subset.sensors), 2), L)
        assert direct.verdict == subset.verdict, subset.sensors
        if subset.kappa is not None and direct.best is not None:
            assert direct.best.kappa_float == pytest.approx(subset.kappa, rel=1e-12)


@pytest.mark.parametrize("name", ["wave-damper", "beam-tip-damper"])
def test_sensor_search_agrees_with_classify_on_closed_plants(name):
    model = load_builtin(name)
    for subset in search_sensors(model).subsets:
        C_m = sensor_matrix(list(subset.sensors), model.n_ports)
        direct = classify(model, C_m, sympy.eye(len(subset.sensors)))
        assert direct.verdict == subset.verdict
        assert direct.best.kappa_float == pytest.approx(subset.kappa, rel=1e-12)


def test_beam_tip_damper_spectrum_matches_its_characteristic_determinant():
    r"""w_tt = -w_zzzz, w(0) = w'(0) = 0, w''(1) = 0, w'''(1) = k w_t(1) (unit parameters).

    w = φ(z) e^{λt}, μ⁴ = -λ², φ = A (cosh - cos)(μz) + B (sinh - sin)(μz) meets the
    clamped end; the tip conditions give the 2 x 2 determinant solved here in mpmath.
    """
    k = 1
    report = spectrum(to_numeric(load_builtin("beam-tip-damper")))
    assert report.converged

    def determinant(lam):
        mu = mpmath.sqrt(1j * lam)  # μ² = iλ, so μ⁴ = -λ²
        ch, sh, c, s = mpmath.cosh(mu), mpmath.sinh(mu), mpmath.cos(mu), mpmath.sin(mu)
        row1 = (ch + c, sh + s)  # φ''(1)/μ²
        row2 = (
            mu**3 * (sh - s) - k * lam * (ch - c),  # φ'''(1) - kλ φ(1)
            mu**3 * (ch + c) - k * lam * (sh - s),
        )
        return row1[0] * row2[1] - row1[1] * row2[0]

    with mpmath.workdps(30):
        for lam in report.rightmost[:4]:
            root = complex(mpmath.findroot(determinant, mpmath.mpc(lam)))
            assert abs(root - lam) < 1e-9 * max(1, abs(lam))


def test_beam_tip_damper_simulation_audits_the_damper_dissipation_exactly():
    r"""Energy balance of the closed beam (d = 0): ΔH over a step = -∫ k y4(t)² dt.

    Independently of the library's audit: with the open discretization's output map
    y4 = c ᵀ ê and the closed flow F = E⁻¹(J - R), the dissipated energy over a step is
    x_kᵀ G x_k with G = ∫_0^dt exp(Fᵀs) k c cᵀ exp(Fs) ds (Van Loan's block exponential).
    """
    beam = load_builtin("beam-tip-damper")
    nm = to_numeric(beam)
    degree = 24
    d = discretize(nm, "galerkin", degree)
    c = galerkin(nm, degree).B[:, 3]  # open port 4: y4 = cᵀ ê
    np.testing.assert_allclose(d.R, np.outer(c, c), atol=1e-12)  # k = 1, d = 0: R = k c cᵀ
    x0 = initial_state_function("x1: 0, x2: z - 0.9", nm, model=beam)
    t_end, samples = 2.0, 81
    run = simulate(nm, x0=x0, discrete=d, options=SimulationOptions(t_end=t_end, samples=samples))
    assert run.info["energy_balance_residual_plant"] < 1e-12
    assert not run.warnings
    F = np.linalg.solve(d.E, d.J - d.R)
    n, dt = F.shape[0], t_end / (samples - 1)
    block = np.zeros((2 * n, 2 * n))
    block[:n, :n], block[:n, n:], block[n:, n:] = -F.T, np.outer(c, c), F
    ex = sl.expm(block * dt)
    G = ex[n:, n:].T @ ex[:n, n:]
    dissipated = np.einsum("ki,ij,kj->k", run.states[:-1], G, run.states[:-1])
    np.testing.assert_allclose(-np.diff(run.H), dissipated, rtol=1e-9, atol=1e-13 * run.H[0])
    assert run.H[-1] < 0.01 * run.H[0]  # the damper takes the energy out


def test_exports_and_simulations_have_the_external_ports_only():
    nm = to_numeric(load_builtin("beam-tip-damper"))
    assert nm.n_ports == 3
    assert nm.output_labels == ("e2'(a)", "-e2(a)", "e1'(b)")
    d = discretize(nm, "fd", 20)
    assert d.n_ports == 3
    assert d.check_structure()["R_min_eig"] > -1e-12
    system = plant_statespace(discretize(nm, "galerkin", 12))
    assert system.ninputs == 3
    assert system.noutputs == 3


def test_feedback_round_trips_and_is_refused_when_not_dissipative():
    beam = load_builtin("beam-tip-damper")
    assert model_from_toml(model_to_toml(beam)) == beam
    with pytest.raises(ModelError, match=r"K \+ K\^T must be positive semidefinite"):
        beam.with_parameters({"k": -1})
    with pytest.raises(
        ModelError, match=r"not an input of the model; expected an index in 1\.\.2"
    ):
        BCPHS.define(
            name="b",
            interval=(0, 1),
            order=1,
            P={1: [[0, 1], [1, 0]]},
            H=[[1, 0], [0, 1]],
            inputs=["e1(0)", "e2(1)"],
            feedback={"inputs": [0], "gain": [[1]]},
        )


@st.composite
def models_with_feedback_and_P0z(draw) -> BCPHS:
    """Strings and beams with random P0(z) <= 0, a random dissipative feedback and units.

    P0(z) = -diag(p + q z²) + s z [[0, 1], [-1, 0]] (p, q >= 0: exact check on [a, b]);
    K = A Aᵀ + S with S skew, so K + Kᵀ = 2 A Aᵀ >= 0 by construction.
    """
    order = draw(st.integers(1, 2))
    small = st.integers(-2, 2)
    p, q, s = draw(st.integers(0, 2)), draw(st.integers(0, 3)), draw(small)
    P0 = [[f"-({p} + {q}*z**2)", f"{s}*z"], [f"-{s}*z", f"-{p}"]]
    if order == 1:
        P = {0: P0, 1: [[0, 1], [1, 0]]}
        inputs = ["e1(0)", "e2(1)"]
    else:
        P = {0: P0, 2: [[0, -1], [1, 0]]}
        inputs = ["e1(0)", "e1'(0)", "e2(1)", "e2'(1)"]
    closed = draw(st.lists(st.integers(1, len(inputs)), min_size=1, max_size=2, unique=True))
    c = len(closed)
    A = sympy.Matrix(c, c, lambda i, j: draw(small))
    S = sympy.Matrix(c, c, lambda i, j: draw(small) if i < j else 0)
    K = A * A.T + S - S.T
    gain = [
        [str(x) if (i, j) != (0, 0) else f"{K[0, 0]} + k" for j, x in enumerate(row)]
        for i, row in enumerate(K.tolist())
    ]
    units = {"t": "s", "k": draw(st.sampled_from(["N*s/m", "kg/s", "1"]))}
    return BCPHS.define(
        name="random closed",
        interval=(0, 1),
        order=order,
        P=P,
        H=[["1 + z", 0], [0, 2]],
        parameters={"k": draw(st.sampled_from([0, 0.5, 3]))},
        inputs=inputs,
        outputs=draw(st.sampled_from(["conjugate", None])),
        feedback={"inputs": closed, "gain": gain},
        units=units,
    )


@settings(max_examples=10, deadline=None)
@given(models_with_feedback_and_P0z())
def test_models_with_feedback_and_P0z_round_trip_exactly(model):
    text = model_to_toml(model)
    again = model_from_toml(text)
    assert again == model
    assert again.units == model.units
    assert model_to_toml(again) == text
    assert all(value == 0 for value in closed_ports(again).identities.values())
    assert any("exact on [a, b]" in check for check in again.checks)


def test_closed_ports_print_short_and_refuse_what_is_not_a_model():
    closed = closed_ports(load_builtin("wave-damper"))
    assert repr(closed) == "ClosedPorts(closed=[2], gain=[[k]], max residual=0)"
    assert str(closed).startswith("feedback u_c = -K y_c on inputs [2], K = [[k]]")
    assert "e1(1)*k + e2(1) = 0" in closed._repr_html_()
    assert closed.to_dict()["boundary_conditions"] == ["e1(1)*k + e2(1) = 0"]
    with pytest.raises(ModelError, match="model must be a BCPHS; found str"):
        closed_ports("wave")
    with pytest.raises(ModelError, match="has no \\[feedback\\] section"):
        closed_ports(load_builtin("wave"))
    with pytest.raises(ModelError, match="model must be a BCPHS"):
        close_inputs(None, [1], [[1]])
