"""Dissipativity invariants: what a NumericModel and a DiscretePHS refuse at construction.

Theory (the energy balance of phdesign.numeric.discretization.invariants): for a closed loop ũ =
−Kỹ of
E ê' = (J − R) ê + B u, y = Bᵀ ê + D u, an eigenpair gives
Re λ · x*Ex = −x*Rx − ỹ* sym(G) ỹ ≤ 0, which needs E ≻ 0, J = −Jᵀ, R ⪰ 0, D = −Dᵀ; for the
PDE, P0 + P0ᵀ ⪯ 0 on the interval and the plant's own dampers K + Kᵀ ⪰ 0.  The shift and
invert eigen stage and the drift rule (a positive real part is round-off) rest on them.
Each bad input below is a one-entry violation whose expected eigenvalue is computed by
hand in the comment; round-off far below RELATIVE_ROUNDOFF passes.  On the code before
these checks every row was accepted silently.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from phdesign.core.errors import ModelError, NumericError, ShapeError
from phdesign.models import load_builtin
from phdesign.numeric.bridge import PortFeedback, to_numeric
from phdesign.numeric.discretization.registry import discretize

BEAM = to_numeric(load_builtin("euler-bernoulli"))  # P0 = [[-d, 0], [0, 0]], d = 0.2
WAVE = to_numeric(load_builtin("wave"))  # lossless: R = 0
DISCRETE = discretize(BEAM, "galerkin", 8)
LOSSLESS = discretize(WAVE, "galerkin", 8)


def _unit(n: int, i: int, j: int) -> np.ndarray:
    M = np.zeros((n, n))
    M[i, j] = 1.0
    return M


def _bad_discretizations():
    n, m = DISCRETE.dim, DISCRETE.n_ports
    J, R, E = DISCRETE.J, DISCRETE.R, DISCRETE.E
    scale = float(np.max(np.abs(J)))
    return [
        # a symmetric part 1e-6 max|J| in J: max |J + J^T| = 2e-6 max|J|
        ("J", {"J": J + 1e-6 * scale * (_unit(n, 0, 1) + _unit(n, 1, 0))}, r"J must be skew"),
        # R - 2 e_0 e_0^T: its smallest eigenvalue is below -2 + max eig R < 0
        ("R", {"R": R - 2 * _unit(n, 0, 0)}, r"R must be positive semidefinite.*found smallest"),
        # -E is negative definite: its smallest eigenvalue is -lambda_max(E) < 0
        ("E", {"E": -E}, r"E must be symmetric positive definite; found smallest eigenvalue -"),
        ("E symmetric", {"E": E + 1e-3 * _unit(n, 0, 1)}, r"E must be symmetric; found max"),
        (
            "D",
            {"D": np.eye(m)},
            r"D must be skew-symmetric \(D\^T = -D\); found max \|D \+ D\^T\| = 2",
        ),
        ("J finite", {"J": J * np.nan}, r"J must be finite"),
        (
            "B shape",
            {"B": np.zeros((n, m + 1))},
            rf"B matrix; expected \({n}, {m}\) but found \({n}, {m + 1}\)",
        ),
    ]


@pytest.mark.parametrize(
    ("label", "fields", "pattern"),
    _bad_discretizations(),
    ids=lambda v: v if isinstance(v, str) else "",
)
def test_a_discretization_that_is_not_dissipative_is_refused(label, fields, pattern):
    with pytest.raises((NumericError, ShapeError), match=pattern) as info:
        dataclasses.replace(DISCRETE, **fields)
    assert isinstance(info.value, ValueError)


def test_round_off_in_the_invariants_is_accepted():
    n = DISCRETE.dim
    scale = float(np.max(np.abs(DISCRETE.J)))
    tiny = 1e-13  # far below the tolerance, RELATIVE_ROUNDOFF = 1e-10 of max|J|
    asym = tiny * scale * (_unit(n, 0, 1) + _unit(n, 1, 0))
    dataclasses.replace(DISCRETE, J=DISCRETE.J + asym)
    # a lossless R that is round-off only (entries +-1e-18) is measured against max|J|
    noise = 1e-18 * np.diag(np.where(np.arange(LOSSLESS.dim) % 2, 1.0, -1.0))
    dataclasses.replace(LOSSLESS, R=noise)
    # every built-in model and method passes at a few resolutions (the suite builds more)
    for name in ("wave", "timoshenko", "euler-bernoulli", "airy"):
        nm = to_numeric(load_builtin(name))
        for method, p in (("galerkin", 30), ("fd", 12)):
            if method == "fd" and nm.order > 2:
                continue
            discretize(nm, method, p)


def test_a_model_that_generates_energy_is_refused():
    # P0 = [[+0.3, 0], [0, 0]]: P0 + P0^T = diag(0.6, 0), largest eigenvalue 0.6
    P = (np.array([[0.3, 0.0], [0.0, 0.0]]), *BEAM.P[1:])
    with pytest.raises(
        ModelError, match=r"P0 \+ P0\^T must be negative semidefinite.*largest eigenvalue 0\.6$"
    ):
        dataclasses.replace(BEAM, P=P)

    # P0(z) = [[z - 1/2, 0], [0, 0]]: P0 + P0^T = 2 z - 1 > 0 for z > 1/2, largest at z = 1
    def P0(z):
        out = np.zeros((np.size(z), 2, 2))
        out[:, 0, 0] = np.ravel(z) - 0.5
        return out

    P_nan = (np.full((2, 2), np.nan), *BEAM.P[1:])
    with pytest.raises(
        ModelError, match=r"P0\(z\) \+ P0\(z\)\^T must be negative.*eigenvalue 1 at z = 1$"
    ):
        dataclasses.replace(BEAM, P=P_nan, P0=P0)

    # a damper that pumps energy in: u3 = -K y3 with K = -1, K + K^T = -2
    with pytest.raises(
        ModelError, match=r"feedback gain K \+ K\^T must be positive semidefinite.*-2$"
    ):
        dataclasses.replace(BEAM, feedback=PortFeedback((2,), np.array([[-1.0]])))


def test_a_skew_p0_evaluated_in_floating_point_is_round_off():
    # timoshenko's P0 is skew: P0 + P0^T = 0; a 1e-17 perturbation is round-off against
    # max|P0| = 1 (not against max|P0 + P0^T| = 2e-17, the size of the round-off itself)
    timoshenko = to_numeric(load_builtin("timoshenko"))
    P0 = timoshenko.P[0] + 1e-17 * _unit(4, 0, 0)
    dataclasses.replace(timoshenko, P=(P0, *timoshenko.P[1:]))
    from phdesign.numeric.discretization.invariants import require_semidefinite

    with pytest.raises(ModelError, match="P0"):
        require_semidefinite("P0 + P0^T", 1e-17 * _unit(4, 0, 0), negative=True, error=ModelError)


def test_a_model_whose_energy_is_not_positive_is_refused():
    # H(z) = diag(1, z - 1/2): its smallest eigenvalue is z - 1/2, most negative (-0.5) at z = 0
    def H(z):
        out = np.zeros((np.size(z), 2, 2))
        out[:, 0, 0] = 1.0
        out[:, 1, 1] = np.ravel(z) - 0.5
        return out

    with pytest.raises(
        ModelError,
        match=r"H\(z\) must be symmetric positive definite; found smallest eigenvalue -0\.5 "
        r"at z = 0$",
    ):
        dataclasses.replace(WAVE, H=H, H_constant=False)


def test_an_observer_gain_without_positive_symmetric_part_is_refused_with_its_eigenvalue():
    # L = [[1, 3], [-3, -1]] (both diagonal entries would not save it): L + Lᵀ = diag(2, -2),
    # smallest eigenvalue -2 by hand; L = [[1, 2], [2, 1]]: L + Lᵀ = [[2, 4], [4, 2]],
    # eigenvalues 2 ± 4, smallest -2 although the diagonal is positive
    from phdesign.core.errors import ObserverError
    from phdesign.numeric.discretization.phs import feedback_matrix

    C_m = np.eye(2)
    for L in ([[1.0, 3.0], [-3.0, -1.0]], [[1.0, 2.0], [2.0, 1.0]]):
        with pytest.raises(ObserverError, match=r"L \+ L\^T must be symmetric positive "
                           r"definite; found smallest eigenvalue -2$"):  # fmt: skip
            feedback_matrix(C_m, np.array(L), 2)
    K = feedback_matrix(C_m, np.array([[1.0, 5.0], [-5.0, 1.0]]), 2)  # sym(L) = I
    assert np.array_equal(K, [[1.0, 5.0], [-5.0, 1.0]])
