"""Every command's JSON output on the built-in models, against the golden files.

The files were recorded before the package moved into its pipeline folders
(``tests/golden_cases.py --record``): moving code must not move a number.
"""

from __future__ import annotations

import json

import pytest
from golden_cases import CASES, HERE, differences, run


@pytest.mark.parametrize("name", sorted(CASES))
def test_command_output_is_unchanged(name):
    golden = json.loads((HERE / f"{name}.json").read_text())
    found = run(CASES[name])
    problems = differences(golden, found)
    assert not problems, "\n".join(problems[:20])


def test_the_comparison_can_fail():
    # a number moved by 1e-10, a verdict changed, a key lost: each is reported
    golden = {"a": [1.0, 2.0], "verdict": "exponential", "b": {"c": 3.0}}
    found = {"a": [1.0, 2.0 + 1e-10], "verdict": "asymptotic", "b": {}}
    assert len(differences(golden, found)) == 3
    assert differences(golden, golden) == []
