"""Sampled-data observers: exact discretization, exports that agree, atomic writes.

Expected values come from closed forms (exponentials of diagonalizable matrices, the mean
of an exponential), from an independent fine-step integration (scipy's DOP853 with a
Gauss-Legendre average of its dense output), and from an independent implementation of
the continuous observer (``phdesign.numeric.statespace.observer_statespace``).
"""

from __future__ import annotations

import dataclasses
import json
import runpy
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from phdesign.codegen import render_c, write_directory
from phdesign.core.errors import NumericError, OutputFileError
from phdesign.models import load_builtin
from phdesign.numeric.bridge import to_numeric
from phdesign.numeric.checks import check_sampling
from phdesign.numeric.discretization.registry import discretize
from phdesign.numeric.sampled.export import SampledObserver, export_observer
from phdesign.numeric.sampled.samplers import (
    ContinuousObserver,
    hold_discretization,
    sample_plant,
)
from phdesign.numeric.statespace import observer_statespace
from phdesign.numeric.time.options import SimulationOptions

BEAM_SENSORS = np.array([[0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]])
BEAM_GAIN = np.diag([0.1, 1.0])


def _diagonalizable(rng, n, eigenvalues):
    S = rng.standard_normal((n, n)) + 3 * np.eye(n)
    return S, S @ np.diag(eigenvalues) @ np.linalg.inv(S)


def test_hold_discretization_is_the_closed_form(rng):
    # A = S Λ S⁻¹: A_d = S e^{Λ dt} S⁻¹ and B_d = S (e^{Λ dt} - I) Λ⁻¹ S⁻¹ B, exactly
    lam = np.array([-0.5, -3.0, -40.0, -2.0])
    S, A = _diagonalizable(rng, 4, lam)
    B = rng.standard_normal((4, 2))
    dt = 0.03
    Ad, Bd = hold_discretization(A, B, dt)
    Si = np.linalg.inv(S)
    assert np.allclose(Ad, S @ np.diag(np.exp(lam * dt)) @ Si, rtol=0, atol=1e-13)
    exact_B = S @ np.diag((np.exp(lam * dt) - 1) / lam) @ Si @ B
    assert np.max(np.abs(Bd - exact_B)) <= 1e-13 * np.max(np.abs(exact_B))


def test_averaged_measurement_of_an_exponential_is_its_exact_mean(rng):
    # x' = Λ x in the eigenbasis: the mean of e^{λ s} over [0, dt] is (e^{λ dt} - 1)/(λ dt);
    # with u held, ∫∫ e^{λ r} dr ds / dt = ((e^{λ dt} - 1)/λ - dt)/(λ dt)
    lam = np.array([-1.0, -7.0, -0.2])
    S, F = _diagonalizable(rng, 3, lam)
    G = rng.standard_normal((3, 2))
    C = rng.standard_normal((2, 3))
    D = rng.standard_normal((2, 2))
    dt = 0.1
    s = sample_plant(F, G, C, D, dt, "average")
    Si = np.linalg.inv(S)
    mean_x = S @ np.diag((np.exp(lam * dt) - 1) / (lam * dt)) @ Si
    mean_u = S @ np.diag(((np.exp(lam * dt) - 1) / lam - dt) / (lam * dt)) @ Si @ G
    # round-off of one 8x8 exponential and a few products: 1e-13 on entries of order 1
    assert np.allclose(s.C_s, C @ mean_x, rtol=0, atol=1e-13)
    assert np.allclose(s.D_s, C @ mean_u + D, rtol=0, atol=1e-13)
    point = sample_plant(F, G, C, D, dt, "point")
    assert np.array_equal(point.C_s, C)
    assert np.array_equal(point.D_s, D)


def test_sampled_plant_against_a_fine_step_reference(rng):
    # An independent integrator (DOP853, tight tolerances) over one period of the wave's
    # Galerkin plant, and the mean of y from a 40-point Gauss-Legendre rule on its dense
    # output; agreement to 1e-9 of the signal (the integrator's tolerance is 1e-12)
    d = discretize(to_numeric(load_builtin("wave")), "galerkin", 8)
    F = np.linalg.solve(d.E, d.J - d.R)
    G = np.linalg.solve(d.E, d.B)
    C, D = d.B.T, rng.standard_normal((2, 2))
    x0, u0 = rng.standard_normal(d.dim), rng.standard_normal(2)
    dt = 0.05
    sol = solve_ivp(
        lambda _t, x: F @ x + G @ u0,
        (0, dt),
        x0,
        method="DOP853",
        rtol=1e-12,
        atol=1e-14,
        dense_output=True,
    )
    nodes, weights = np.polynomial.legendre.leggauss(40)
    ts = 0.5 * dt * (nodes + 1)
    mean_y = 0.5 * sum(w * (C @ sol.sol(t) + D @ u0) for t, w in zip(ts, weights, strict=True))
    for sampler, expected in (("average", mean_y), ("point", C @ x0 + D @ u0)):
        s = sample_plant(F, G, C, D, dt, sampler)
        assert np.allclose(s.Phi @ x0 + s.Gamma @ u0, sol.y[:, -1], rtol=0, atol=1e-9)
        measured = s.C_s @ x0 + s.D_s @ u0
        assert np.max(np.abs(measured - expected)) <= 1e-9 * np.max(np.abs(expected))


def test_point_sampled_observer_is_the_continuous_one_with_held_input(rng):
    # 20 periods of the wave observer with a random held input v_k, integrated
    # independently period by period; the exported outputs are C x_k + D v_k (the averaged
    # sampler's observer is checked in tests/numeric/sampled/test_sampled_averaged.py)
    nm = to_numeric(load_builtin("wave"))
    obs = export_observer(
        nm,
        np.array([[0.0, 1.0]]),
        np.array([[0.5]]),
        dt=0.02,
        sampler="point",
        order=12,
        design="given",  # the given gain as is: the discretization under test
    )
    cont = obs.continuous
    V = rng.standard_normal((20, 3))
    x = np.zeros(obs.order)
    out = obs.run(V)
    for k, v in enumerate(V):
        # the integrator's tolerance (1e-12) on outputs of order 1 leaves ~1e-10
        expected = cont.C @ x + cont.D @ v
        assert np.max(np.abs(out[k] - expected)) <= 1e-9 * max(1.0, np.max(np.abs(expected)))
        sol = solve_ivp(
            lambda _t, z, v=v: cont.A @ z + cont.B @ v,
            (0, obs.dt),
            x,
            method="DOP853",
            rtol=1e-12,
            atol=1e-13,
        )
        x = sol.y[:, -1]
    x_disc = np.zeros(obs.order)
    for v in V:
        x_disc = obs.A @ x_disc + obs.B @ v
    assert np.max(np.abs(x_disc - x)) <= 1e-9 * max(1.0, np.max(np.abs(x)))


def test_continuous_observer_matches_the_independent_statespace_export(rng):
    # a feedthrough D = -Dᵀ ≠ 0 exercises the loop (I + K D)⁻¹ that no built-in model has
    d = discretize(to_numeric(load_builtin("euler-bernoulli")), "galerkin", 8)
    W = rng.standard_normal((4, 4))
    d = dataclasses.replace(d, D=0.3 * (W - W.T))
    ours = ContinuousObserver.from_discretization(d, BEAM_SENSORS, BEAM_GAIN, (1.0,))
    theirs = observer_statespace(d, BEAM_SENSORS, BEAM_GAIN)
    assert np.allclose(ours.A, theirs.A, rtol=0, atol=1e-10 * np.max(np.abs(theirs.A)))
    assert np.allclose(ours.B, theirs.B, rtol=0, atol=1e-10 * np.max(np.abs(theirs.B)))
    assert np.allclose(ours.C[:4], theirs.C[:4], rtol=0, atol=1e-12 * np.max(np.abs(theirs.C)))
    assert np.allclose(ours.D[:4], theirs.D[:4], rtol=0, atol=1e-12)
    assert ours.inputs == ("u1", "u2", "u3", "u4", "y3", "y4")
    assert ours.outputs == ("yhat1", "yhat2", "yhat3", "yhat4", "w(1)")


@pytest.mark.parametrize(
    ("dt", "sampler", "message"),
    [
        (0.0, "average", "dt must be a finite positive number of seconds; found 0.0"),
        (-1e-3, "average", "found -0.001"),
        (float("nan"), "point", "found nan"),
        (float("inf"), "point", "found inf"),
        ("1e-3", "point", "found '1e-3'"),
        (True, "point", "found True"),
        (1e-3, "spline", "unknown sampler 'spline'; expected one of average, point"),
    ],
)
def test_bad_sampling_is_refused(dt, sampler, message):
    with pytest.raises(NumericError, match=message.replace("(", r"\(")):
        check_sampling(dt, sampler)


@pytest.fixture(scope="module")
def beam_observer() -> SampledObserver:
    """The issue's beam observer: Legendre degree 16 (34 states), averaged at 1 ms."""
    nm = to_numeric(load_builtin("euler-bernoulli"))
    return export_observer(nm, BEAM_SENSORS, BEAM_GAIN, dt=1e-3, order=34)


def test_json_export_has_the_contract_keys(beam_observer, tmp_path):
    path = tmp_path / "observer.json"
    assert beam_observer.write(str(path), "json") == [str(path)]
    data = json.loads(path.read_text())
    assert set(data) == {
        "model", "dt", "sampler", "order", "A", "B", "C", "D", "inputs", "outputs", "x0",
        "energy_matrix", "verification", "order_selection",
        # issue 28: what each slot is, and the [feedback] renumbering (keys added)
        "input_descriptions", "output_descriptions", "renumbering",
        # issue 29: the gain design (which, why, the candidates' floors and noise)
        "design",
    }  # fmt: skip
    assert data["model"] == "euler-bernoulli"
    assert data["sampler"] == "average"
    assert data["dt"] == 1e-3
    assert data["order"] == 34
    assert data["verification"] is None
    assert data["inputs"] == ["u1", "u2", "u3", "u4", "y3", "y4"]
    assert data["outputs"] == ["yhat1", "yhat2", "yhat3", "yhat4", "w(1)"]
    # the beam's ports (DESIGN.md): u3 = e2(1), y3 = e1'(1), y4 = -e1(1); no [feedback]
    assert data["input_descriptions"][2:] == [
        "u3 = e2(1)",
        "u4 = e2'(1)",
        "y3 = e1'(1)",
        "y4 = -e1(1)",
    ]
    assert data["output_descriptions"][2] == "yhat3 = estimate of y3 = e1'(1)"
    assert data["output_descriptions"][4] == "w(1) = estimated displacement at z = 1"
    assert data["renumbering"] is None
    assert data["x0"] == [0.0] * 34
    Q = np.array(data["energy_matrix"])
    assert np.allclose(Q, Q.T)
    assert np.min(np.linalg.eigvalsh(Q)) > 0
    assert np.array(data["A"]).shape == (34, 34)
    assert np.array(data["D"]).shape == (5, 6)


def _run(A, B, C, D, V):
    x, out = np.zeros(A.shape[0]), []
    for v in V:
        out.append(C @ x + D @ v)
        x = A @ x + B @ v
    return np.array(out)


DRIVER = r"""
#include <stdio.h>
#include "observer.h"

int main(void)
{
    phd_observer obs;
    double v[PHD_OBSERVER_NV], out[PHD_OBSERVER_NOUT];
    int k, i, steps;
    if (scanf("%d", &steps) != 1) return 1;
    phd_observer_init(&obs);
    for (k = 0; k < steps; ++k) {
        for (i = 0; i < PHD_OBSERVER_NV; ++i) {
            if (scanf("%lf", &v[i]) != 1) return 1;
        }
        phd_observer_step(&obs, v, out);
        for (i = 0; i < PHD_OBSERVER_NOUT; ++i) {
            printf("%.17g%c", out[i], i + 1 < PHD_OBSERVER_NOUT ? ' ' : '\n');
        }
    }
    return 0;
}
"""


@pytest.fixture(scope="module", params=["auto", "passive", "kalman", "given"])
def designed_observer(request, beam_observer) -> SampledObserver:
    """The beam observer of each gain design (issue 29): every format must carry each."""
    if request.param == "auto":
        return beam_observer
    nm = to_numeric(load_builtin("euler-bernoulli"))
    obs = export_observer(nm, BEAM_SENSORS, BEAM_GAIN, dt=1e-3, order=34, design=request.param)
    assert obs.design is not None
    assert obs.design.chosen == request.param
    return obs


def test_every_export_gives_the_same_outputs_over_1000_steps(designed_observer, tmp_path, rng):
    pytest.importorskip("jinja2", reason="the C and statespace exports need the codegen extra")
    beam_observer = designed_observer
    V = rng.standard_normal((1000, len(beam_observer.inputs)))
    reference = beam_observer.run(V)
    scale = np.max(np.abs(reference))
    results = {}
    beam_observer.write(str(tmp_path / "o.json"), "json")
    data = json.loads((tmp_path / "o.json").read_text())
    results["json"] = _run(*(np.array(data[k]) for k in "ABCD"), V)
    beam_observer.write(str(tmp_path / "o.npz"), "npz")
    with np.load(tmp_path / "o.npz", allow_pickle=False) as z:
        results["npz"] = _run(z["A"], z["B"], z["C"], z["D"], V)
        assert list(z["inputs"]) == list(beam_observer.inputs)
        assert float(z["dt"]) == 1e-3
    beam_observer.write(str(tmp_path / "o.py"), "statespace")
    system = runpy.run_path(str(tmp_path / "o.py"))["observer"]
    assert system.dt == 1e-3
    assert system.input_labels == list(beam_observer.inputs)
    assert system.output_labels == list(beam_observer.outputs)
    import control

    results["statespace"] = control.forced_response(system, U=V.T, X0=0).outputs.T
    results["StateSpace()"] = control.forced_response(
        beam_observer.statespace(), U=V.T, X0=0
    ).outputs.T
    compiler = shutil.which("cc")
    if compiler is not None:
        results["c"] = _compiled_outputs(compiler, beam_observer, tmp_path, V)
    for name, out in results.items():
        assert out.shape == reference.shape, name
        error = np.max(np.abs(out - reference)) / scale
        assert error <= 1e-12, f"{name}: {error:.2g}"
    if compiler is None:
        pytest.skip("no C compiler (cc) on this machine: the C export was not compiled")


def _compiled_outputs(compiler, observer, tmp_path, V):
    folder = tmp_path / "c"
    observer.write(str(folder), "c")
    (folder / "driver.c").write_text(DRIVER)
    flags = ["-std=c99", "-Wall", "-Wextra", "-Werror", "-O2"]
    binary = folder / "driver"
    subprocess.run(
        [compiler, *flags, "observer.c", "driver.c", "-o", str(binary)],
        cwd=folder, check=True, capture_output=True,
    )  # fmt: skip
    text = f"{len(V)}\n" + "\n".join(" ".join(repr(float(x)) for x in v) for v in V)
    run = subprocess.run([str(binary)], input=text, capture_output=True, text=True, check=True)
    return np.array([[float(x) for x in line.split()] for line in run.stdout.splitlines()])


def test_generated_c_depends_on_string_h_only_and_never_allocates(beam_observer):
    pytest.importorskip("jinja2", reason="the C export needs the codegen extra")
    files = render_c(beam_observer)
    assert set(files) == {"observer.h", "observer.c"}
    includes = [
        line for text in files.values() for line in text.splitlines() if "#include" in line
    ]
    assert includes == ["#include <string.h>", '#include "observer.h"']
    for word in ("malloc", "calloc", "realloc", "free("):
        assert word not in files["observer.c"]
    header = files["observer.h"]
    assert "double x[PHD_OBSERVER_N];\n} phd_observer;" in header
    assert "#define PHD_OBSERVER_N 34 " in header
    assert "void phd_observer_init(phd_observer *obs);" in header
    assert "static const double phd_A[34][34]" in files["observer.c"]
    assert "/* out[4] = w(1) */" not in header
    assert " *   out[4] = w(1)" in header
    # 17 significant digits: every double reads back exactly
    row = files["observer.c"].split("phd_A[34][34] = {\n")[1].splitlines()[0]
    values = [float(x) for x in row.strip().strip("{").split("}")[0].split(",")]
    assert values == [float(x) for x in beam_observer.A[0]]


def test_c_export_folder_is_all_or_nothing(tmp_path, monkeypatch):
    target = tmp_path / "obs"
    calls = []
    original = Path.write_bytes

    def failing(self, data):
        calls.append(self.name)
        if len(calls) == 2:
            raise OSError(28, "No space left on device")
        return original(self, data)

    monkeypatch.setattr(Path, "write_bytes", failing)
    with pytest.raises(OutputFileError, match="No space left on device"):
        write_directory(target, {"a.h": "1", "a.c": "2"})
    monkeypatch.undo()
    assert list(tmp_path.iterdir()) == []  # neither the folder nor its staging copy
    write_directory(target, {"a.h": "old"})
    with pytest.raises(OutputFileError, match="exists; pass `force=True`"):
        write_directory(target, {"a.h": "new"})
    write_directory(target, {"a.h": "new", "a.c": "new"}, force=True)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["obs"]
    assert (target / "a.h").read_text() == "new"
    assert (target / "a.c").exists()


def test_a_sampling_period_is_at_most_the_run_and_the_periods_are_bounded():
    """Issue 30: ``dt = 1e300`` ended in numpy's LinAlgError, ``1e-300`` in an OverflowError."""
    from phdesign.numeric.sampled.simulation import simulate_sampled

    nm = to_numeric(load_builtin("wave"))
    design = (np.array([[0.0, 1.0]]), np.array([[0.5]]))
    with pytest.raises(NumericError, match=r"^`dt` = 1e\+300 s is longer than `t_end` = 5 s"):
        export_observer(nm, *design, dt=1e300, order=6)
    with pytest.raises(NumericError, match=r"^`t_end` / `dt` = 5e\+300 sampling periods"):
        export_observer(nm, *design, dt=1e-300, order=6, verify=True)
    with pytest.raises(NumericError, match=r"^`dt` = 10 s is longer than `t_end` = 5 s"):
        simulate_sampled(nm, *design, options=SimulationOptions(dt=10.0, resolution=6))
    with pytest.raises(NumericError, match=r"^`t_end` / `dt` = 5e\+300 sampling periods"):
        simulate_sampled(nm, *design, options=SimulationOptions(dt=1e-300, resolution=6))


def test_strict_export_raises_a_verification_error_naming_each_failed_check():
    # airy from the default x0 (every x_i = z - 0.9, which violates its boundary
    # conditions): the plant does not resolve its own outputs, the targets are missed
    from phdesign.core.errors import NumericError, VerificationError
    from phdesign.design.observer import Observer
    from phdesign.models import load_builtin

    observer = Observer(load_builtin("airy"), sensors=[1, 2, 3], gain=1)
    with pytest.raises(VerificationError, match=r"`strict=True`: the export failed") as info:
        observer.export(dt=1e-3, strict=True)
    assert isinstance(info.value, NumericError)
    assert isinstance(info.value, ValueError)
    text = str(info.value)
    assert "targets: rightmost eigenvalues to 1e-06" in text
    assert "plant resolution: the verification plant's outputs move by" in text
    with pytest.raises(TypeError, match="strict must be True or False; found 'yes'"):
        observer.export(dt=1e-3, strict="yes")
