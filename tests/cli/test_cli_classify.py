"""``phdesign classify``: JSON contract, readable table, bad input (exit 2, one line)."""

from __future__ import annotations

import json

from phdesign.cli import main


def run(capsys, *argv):
    status = main(list(argv))
    out, err = capsys.readouterr()
    return status, out, err


def test_json_contract_two_tip_sensors(capsys):
    status, out, err = run(
        capsys, "classify", "euler-bernoulli", "--sensors", "3,4", "--gain", "1,2", "--json"
    )
    assert status == 0
    assert err == ""
    data = json.loads(out)
    for key in (
        "model",
        "order",
        "size",
        "sensors",
        "gain",
        "partitioned",
        "results",
        "verdict",
    ):
        assert key in data
    assert (data["model"], data["order"], data["size"]) == ("euler-bernoulli", 2, 2)
    assert data["sensors"] == [[0, 0, 1, 0], [0, 0, 0, 1]]
    assert data["gain"] == [[1, 0], [0, 2]]
    assert data["partitioned"] is True
    assert data["verdict"] == "exponential"
    names = [(r["proposition"], r["variant"]) for r in data["results"]]
    assert names[:4] == [("3.1", 1), ("3.1", 2), ("3.2", 1), ("3.2", 2)]
    r34 = data["results"][10]
    # §IV-D corrected: κ* = min(l2, l1/(1 + l1^2)) = min(2, 1/2) = 1/2
    assert (r34["proposition"], r34["variant"], r34["holds"], r34["kappa"]) == (
        "3.4",
        3,
        True,
        0.5,
    )
    assert all({"proposition", "variant", "applicable", "holds", "kappa"} <= set(r) for r in
               data["results"])  # fmt: skip
    # not applicable (3.2 for N = 2): holds and kappa null
    assert data["results"][2]["applicable"] is False
    assert data["results"][2]["holds"] is None
    assert data["results"][2]["kappa"] is None


def test_symbolic_gain_json(capsys):
    status, out, _ = run(
        capsys, "classify", "euler-bernoulli", "--sensors", "3,4", "--gain", "symbolic", "--json"
    )
    assert status == 0
    data = json.loads(out)
    r34 = data["results"][10]
    assert r34["holds"] is True
    # DESIGN.md: kappa is null only when not applicable or unbounded; for symbolic gains it
    # is the exact expression (paper §IV-D, corrected: min(l2, l1/(1 + l1²)))
    assert r34["kappa"] == r34["kappa_exact"] == "Min(l2, l1/(l1**2 + 1))"
    failing = data["results"][4]  # 3.3 variant 1 fails: its witness makes the ratio 0
    assert (failing["proposition"], failing["holds"], failing["kappa"]) == ("3.3", False, 0.0)
    not_applicable = data["results"][2]  # 3.2 is for N = 1
    assert not_applicable["kappa"] is None
    assert r34["conditions"] == "holds for all positive l1, l2"


def test_cm_in_full_equals_sensors(capsys):
    _, by_sensors, _ = run(capsys, "classify", "wave", "--sensors", "2", "--json")
    _, by_cm, _ = run(capsys, "classify", "wave", "--cm", "[[0, 1]]", "--json")
    assert json.loads(by_sensors) == json.loads(by_cm)


def test_table(capsys):
    status, out, _ = run(capsys, "classify", "euler-bernoulli", "--sensors", "3,4")
    assert status == 0
    assert "Assumption 3.1 holds" in out
    assert "ẽ2(0) is left free by these sensors" in out
    assert out.strip().splitlines()[-1] == (
        "verdict: exponential (best: Proposition 3.4 variant 3)"
    )


def test_all_sensors(capsys):
    status, out, _ = run(capsys, "classify", "euler-bernoulli", "--all-sensors", "--json")
    assert status == 0
    data = json.loads(out)
    assert len(data["subsets"]) == 15
    assert data["minimal"]["exponential"] == [[2], [4]]  # derived in test_search.py
    status, out, _ = run(capsys, "classify", "wave", "--all-sensors")
    assert "minimal exponential sets: {1}, {2}" in out
