"""The independent checker of the decay-rate proof (issue 25, part 3: the rate half).

A proof of the damped string (k = 1/2, true rate ln(3)/2, tests/numeric/certified) goes
through ``to_json`` and a JSON round trip, then is re-checked by
``phdesign.proofcheck.rate.check_rate``; every tampering below breaks one condition of
the derivation (phdesign.numeric.certified.rate) and must be reported.
"""

from __future__ import annotations

import ast
import copy
import json
from fractions import Fraction
from pathlib import Path

import pytest

from phdesign.proofcheck.rate import check_rate

pytest.importorskip("cvxpy", reason="making a proof needs the certify extra")

CHECKER = Path(__file__).parents[2] / "phdesign" / "proofcheck" / "rate.py"


@pytest.fixture(scope="module")
def section():
    from rate_models import closed

    from phdesign.models import load_builtin
    from phdesign.numeric.certified.rate import prove_decay_rate

    proof = prove_decay_rate(closed(load_builtin("wave"), [2], "2"), target=0.5)
    return json.loads(json.dumps(proof.to_json()))


def test_a_proof_passes_the_check(section):
    assert check_rate(section) == []
    assert Fraction(section["sigma"]) == Fraction(1, 2)


def test_a_raised_sigma_is_rejected(section):
    bad = copy.deepcopy(section)
    bad["sigma"] = "3/5"  # above the true rate ln(3)/2 = 0.5493
    found = check_rate(bad)
    assert any("pointwise" in f and "not negative definite" in f for f in found), found


def test_a_perturbed_pi_is_rejected(section):
    bad = copy.deepcopy(section)
    # Π₋ = [[p, q], [q, p]] for the string (Π₋P₁H symmetric); one diagonal entry moved
    bad["Pi_minus"][0][0] = str(Fraction(bad["Pi_minus"][0][0]) + 1)
    found = check_rate(bad)
    assert any("Pi_minus P1 H must be symmetric" in f for f in found), found


def test_a_tampered_inequality_matrix_is_rejected(section):
    bad = copy.deepcopy(section)
    boundary = next(q for q in bad["inequalities"] if q["name"] == "boundary")
    boundary["matrix"][0][0] = "-1/1"
    assert "rate: inequality 'boundary' is missing or differs from its data" in check_rate(bad)
    bad["inequalities"] = [q for q in bad["inequalities"] if q["name"] != "upper bound s=1"]
    assert any("'upper bound s=1' is missing" in f for f in check_rate(bad))


def test_a_wrong_mu_enclosure_and_a_small_m_are_rejected(section):
    bad = copy.deepcopy(section)
    above = Fraction(section["mu"][1]) + Fraction(1, 10)  # [mu_lo, mu_hi] holds ln(tau)
    bad["mu"] = [str(above), str(above + Fraction(1, 10))]
    assert any("mu = ln(tau)/(b - a) is not inside" in f for f in check_rate(bad))
    bad = copy.deepcopy(section)
    bad["M"] = "1/1"  # c2/c1 = tau² or so here, far above 1
    assert any("M² < c2/c1" in f for f in check_rate(bad))


def test_a_wrong_kernel_is_rejected(section):
    bad = copy.deepcopy(section)
    bad["kernel"][0][0] = str(Fraction(bad["kernel"][0][0]) + 1)
    assert any("boundary · kernel ≠ 0" in f for f in check_rate(bad))


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (lambda s: s.pop("H"), "missing key 'H'"),
        (lambda s: s.__setitem__("sigma", 0.5), "expected a 'p/q' string"),
        (lambda s: s.__setitem__("kernel", [["1/1"]]), "kernel must be 4 x 2"),
    ],
)
def test_a_malformed_section_is_a_message_not_a_traceback(section, change, message):
    bad = copy.deepcopy(section)
    change(bad)
    found = check_rate(bad)
    assert len(found) == 1, found
    assert message in found[0], found


def test_the_checker_imports_the_standard_library_only():
    tree = ast.parse(CHECKER.read_text(encoding="utf-8"))
    imported = {
        (node.module if isinstance(node, ast.ImportFrom) else alias.name).split(".")[0]
        for node in ast.walk(tree)
        if isinstance(node, ast.Import | ast.ImportFrom)
        for alias in node.names
    }
    assert imported <= {"__future__", "fractions", "typing"}, imported
