"""The checker is an independent implementation: it runs with flint, numpy and sympy blocked."""

from __future__ import annotations

import json

import pytest
from checker_blocked import run_blocked

pytest.importorskip("flint", reason="certificates need the extra 'certify' (python-flint)")

import phdesign as phd
from phdesign.models import load_builtin


def test_the_checker_verifies_proofs_with_flint_numpy_and_sympy_blocked(tmp_path):
    string = phd.Observer(load_builtin("wave-damper"), sensors=[1], gain=[2]).certify()
    beam = phd.Observer(load_builtin("euler-bernoulli"), sensors=[3, 4], gain=[0.1, 1])
    band = beam.certify(band=3)
    paths = []
    for name, cert in (("string", string), ("beam", band)):
        path = tmp_path / f"{name}.json"
        path.write_text(json.dumps(cert.to_dict()))
        paths.append(str(path))
    done = run_blocked(paths)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == repr(([], []))
