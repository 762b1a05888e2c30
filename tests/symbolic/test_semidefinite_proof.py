"""P0(z) + P0(z)ᵀ ⪯ 0 is proved between grid points, or refused: never accepted on samples.

The reviewer's bump (issue 13): P0 = [[exp(-1e9 (z - 0.50025)²) - 1/1000, 0], [0, 0]], so
P0 + P0ᵀ = diag(2 exp(-1e9 (z - 0.50025)²) - 1/500, 0), whose largest eigenvalue is
2 - 1/500 = 1.998 > 0 at z = 0.50025 (the exponent vanishes there) and -1/500 wherever
|z - 0.50025| > 1e-4 (the exponential is below e^-10).  0.50025 lies half-way between two
points of the 2001-point grid (spacing 5e-4, at 0.5 and 0.5005, where the bump is
e^-62.5): the grid cannot see it, and the earlier check (grid refined near its smallest
values, which are all -1/500 or 0) accepted the model.
"""

from __future__ import annotations

import pytest
import sympy

from phdesign.core.errors import ModelError
from phdesign.symbolic.definiteness import check_definite
from phdesign.symbolic.expressions import Z
from phdesign.symbolic.model import BCPHS

BUMP = "exp(-1000000000*(z - 0.50025)**2) - 1/1000"


def string_with(P0):
    """A unit string on [0, 1] with the distributed P0(z) (fixed at 0, free at 1)."""
    return BCPHS.define(
        name="string",
        interval=(0, 1),
        order=1,
        P={0: P0, 1: [[0, 1], [1, 0]]},
        H=[[1, 0], [0, 1]],
        inputs=["e1(0)", "e2(1)"],
        outputs=["-e2(0)", "e1(1)"],
    )


def negative_semidefinite(M):
    return check_definite(sympy.Matrix(M), "P0 + P0^T", (0, 1), sign=-1, strict=False)


def test_the_reviewers_bump_between_grid_points_is_refused_at_its_point():
    with pytest.raises(ModelError, match=r"largest eigenvalue 1\.998 at z = 0\.50025"):
        string_with([[BUMP, 0], [0, 0]])


def test_a_narrower_bump_off_the_cell_midpoints_is_found():
    # half-width 1/sqrt(1e11) ~ 3e-6 about 0.3000021 (the nearest grid point, 0.3, sees
    # e^-0.44 of it, a midpoint none); its top 2 - 1/500 is found by halving the cells the
    # interval bounds cannot close
    centre = sympy.Rational(3000021, 10**7)
    entry = 2 * sympy.exp(-(10**11) * (Z - centre) ** 2) - sympy.Rational(1, 500)
    with pytest.raises(ModelError, match=r"negative semidefinite on \[0, 1\]; found largest"):
        negative_semidefinite([[entry, 0], [0, 0]])


@pytest.mark.parametrize(
    ("M", "kernel"),
    [
        # damping on one component: the zero row is the constant kernel (0, 1)
        ([[-2 * sympy.exp(-Z), 0], [0, 0]], "(0, 1)"),
        # rank one, -e^z (1, 1)(1, 1)ᵀ: kernel (1, -1) verified exactly, e^z ∉ Q(z)
        ([[-sympy.exp(Z), -sympy.exp(Z)], [-sympy.exp(Z), -sympy.exp(Z)]], "(1, -1)"),
        # an eigenvalue that touches 0 at z = 0, 1/2, 1 while the other stays at -e^z:
        # Gershgorin's discs of the interval matrix close the cells there
        ([[-(sympy.sin(2 * sympy.pi * Z) ** 2), 0], [0, -sympy.exp(Z)]], None),
    ],
)
def test_semidefinite_matrices_are_proved_between_the_points(M, kernel):
    line = negative_semidefinite(M)
    assert "proved between the points by interval bounds" in line
    assert "count as 0" in line
    if kernel is None:
        assert "kernel" not in line
    else:
        assert f"constant kernel {kernel} set aside" in line


def test_a_touching_eigenvalue_that_moves_is_refused_not_sampled():
    """P0 + P0ᵀ = -v vᵀ, v = (e^z, sin z + 2): negative semidefinite (rank one), but its
    kernel (sin z + 2, -e^z) turns with z, so no constant kernel can be set aside and no
    interval bound separates the zero eigenvalue from the wrong side: undecided, refused."""
    v = sympy.Matrix([sympy.exp(Z), sympy.sin(Z) + 2])
    with pytest.raises(ModelError, match=r"could not be decided near z = \S+ within the budget"):
        negative_semidefinite(-v * v.T)


def test_the_model_records_how_its_P0_was_proved():
    string = string_with([["-exp(-z)", 0], [0, 0]])
    assert "proved between the points" in string.checks[1]
    assert "constant kernel (0, 1) set aside" in string.checks[1]
