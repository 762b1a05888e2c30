"""The checker is an independent implementation: it runs with flint, numpy and sympy blocked."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest
from paths import ROOT

pytest.importorskip("flint", reason="certificates need the extra 'certify' (python-flint)")

import phdesign as phd
from phdesign.models import load_builtin

BLOCKED = """
import sys
class Block:
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in ("flint", "numpy", "sympy", "scipy"):
            raise ImportError(f"{name} is blocked for the checker")
        return None
sys.meta_path.insert(0, Block())
from phdesign.proofcheck import check_file
failures = [f for path in sys.argv[1:] for f in check_file(path)]
loaded = sorted(m for m in sys.modules if m.split(".")[0] in ("flint", "numpy", "sympy"))
print(repr((failures, loaded)))
"""


def test_the_checker_verifies_proofs_with_flint_numpy_and_sympy_blocked(tmp_path):
    string = phd.Observer(load_builtin("wave-damper"), sensors=[1], gain=[2]).certify()
    beam = phd.Observer(load_builtin("euler-bernoulli"), sensors=[3, 4], gain=[0.1, 1])
    band = beam.certify(band=3)
    paths = []
    for name, cert in (("string", string), ("beam", band)):
        path = tmp_path / f"{name}.json"
        path.write_text(json.dumps(cert.to_dict()))
        paths.append(str(path))
    done = subprocess.run(
        [sys.executable, "-c", BLOCKED, *paths],
        capture_output=True,
        text=True,
        cwd=ROOT,
        env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"},
        check=False,
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == repr(([], []))
