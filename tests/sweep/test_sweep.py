"""Design sweeps (issue 17): description, per-point jobs, storage, resume, CLI, plots.

Every run here is synchronous (in this process); the Dask schedulers are exercised in
``test_sweep_cluster.py``.  Expected numbers come from closed forms:

* string with the damper u_z(1) = -k u_t(1) (wave, sensor y2 = e1(1), gain k): spectral
  abscissa ½ ln|(1 - k)/(1 + k)|, no eigenvalue at all for k = 1 (extinction);
* the same string, Proposition 3.2 at z = 1: the error traces satisfy ẽ1(0) = 0 and
  ẽ2(1) = -k ẽ1(1), so LHS = ½ ỹ_m (2k) ỹ_m = k ẽ1(1)² and |ẽ(1)|² = (1 + k²) ẽ1(1)²:
  κ* = k / (1 + k²);
* cantilever beam with viscous damping d, u = 0: every mode has Re λ = -d/2;
* the beam's single sensors (README): y4 alone is exponential, y3 alone inconclusive.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

xr = pytest.importorskip("xarray", reason="install the sweep extra")
pytest.importorskip("zarr", reason="install the sweep extra")

from paths import ROOT  # noqa: E402
from sweep_support import BEAM_MAP, same_figures  # noqa: E402

import phdesign  # noqa: E402
from phdesign.cli import main  # noqa: E402
from phdesign.core.errors import OutputFileError, SweepError  # noqa: E402
from phdesign.models import load_builtin  # noqa: E402
from phdesign.sweep import describe, summarize  # noqa: E402
from phdesign.sweep.grids import parse_axis, parse_sensor_sets  # noqa: E402
from phdesign.sweep.plan import ChunkPlan  # noqa: E402

SYNC = {"scheduler": "synchronous", "progress": False}


# --------------------------------------------------------------------- description
def test_grids_are_exact_at_their_ends():
    assert parse_axis("l1", "0.1:10:3:log", "gain").values == (0.1, 1.0, 10.0)
    assert parse_axis("d", "0:0.4:3", "parameter").values == (0.0, 0.2, 0.4)
    assert parse_axis("l", "0.03,0.1,0.2", "gain").values == (0.03, 0.1, 0.2)
    assert parse_axis("d", "0.5:0.5:1", "parameter").values == (0.5,)
    assert parse_axis("l2", np.array([1, 2]), "gain").values == (1.0, 2.0)


@pytest.mark.parametrize(
    ("name", "spec", "kind", "message"),
    [
        ("l1", "", "gain", "empty"),
        ("l1", "3:0.01:40:log", "gain", "reversed"),
        ("d", "0.4:0:9", "parameter", "reversed"),
        ("l1", "0.1:3:0", "gain", "zero points"),
        ("l1", "0:3:10:log", "gain", "a log grid needs start > 0"),
        ("d", "-1:3:10:log", "parameter", "a log grid needs start > 0"),
        ("l1", "0.1:3:2.5", "gain", "whole number"),
        ("l1", "0.1:3:-2", "gain", "whole number"),
        ("l1", "0.1:3", "gain", "start:stop:count"),
        ("l1", "0.1:3:3:lin", "gain", "start:stop:count"),
        ("l1", "0.1:3:1", "gain", "one point needs start = stop"),
        ("l1", "0.3,0.1", "gain", "strictly increasing"),
        ("l1", "0.1,0.1", "gain", "strictly increasing"),
        ("l1", "-1:1:3", "gain", "gains must be positive"),
        ("l1", "nan:1:3", "gain", "finite"),
        ("l1", "a,b", "gain", "expected a number; found 'a'"),
        ("x", "0.1:1:3", "gain", "expected l1, l2"),
        ("l0", "0.1:1:3", "gain", "expected l1, l2"),
    ],
)
def test_malformed_grids_are_refused(name, spec, kind, message):
    with pytest.raises(SweepError, match=message):
        parse_axis(name, spec, kind)


def test_sensor_sets():
    sets = parse_sensor_sets("all", 4).values
    assert len(sets) == 2**4 - 1
    assert sets[:5] == ("1", "2", "3", "4", "1,2")
    assert parse_sensor_sets([(3, 4), (4,)], 4).values == ("3,4", "4")
    for bad, message in [("3,5", "out of range"), ("3;3", "given twice"), ("3,3", "repeats")]:
        with pytest.raises(SweepError, match=message):
            parse_sensor_sets(bad, 4)


def test_description_round_trip_fingerprint_and_difference():
    beam = load_builtin("euler-bernoulli")
    a = describe(beam, sensors=[3, 4], gain="0.1,1", grid={"l2": "0.5:2:4"})
    b = phdesign.sweep.SweepDescription.from_json(a.to_json())
    assert a == b
    assert hash(a) == hash(b)
    assert a.fingerprint == b.fingerprint
    c = describe(beam, sensors=[3, 4], gain="0.1,1", grid={"l2": "0.5:2:5"})
    assert c.fingerprint != a.fingerprint
    assert a.difference(c) == "axis l2: 0.5:2:4 against 0.5:2:5"
    d = describe(beam, sensors=[3, 4], gain="0.1,1", grid={"l2": "0.5:2:4"}, options={"tol": 1e-8})
    assert "options" in a.difference(d)
    # fixed entries and the axis entry combine into the diagonal of L
    assert a.gain_at((1,)) == (0.1, 1.0)
    every = describe(beam, sensors=[3, 4], grid={"l": "0.5:2:4"})
    assert every.gain_at((3,)) == (2.0, 2.0)


def test_description_refuses_what_the_model_lacks():
    wave = load_builtin("wave")
    with pytest.raises(SweepError, match=r"gain axis l2 is beyond the sensors \(1 sensor\)"):
        describe(wave, sensors=[2], grid={"l2": "0.1:1:3"})
    with pytest.raises(phdesign.PhdesignError, match="unknown parameter 'mass'"):
        describe(wave, sensors=[2], param_grid={"mass": "1:2:3"})
    with pytest.raises(phdesign.PhdesignError, match=r"rho = -1.0: .*positive definite"):
        describe(wave, param_grid={"rho": "-1:1:3"})
    with pytest.raises(SweepError, match="needs at least one axis"):
        describe(wave, sensors=[2])
    with pytest.raises(phdesign.PhdesignError, match="expected integer output indices"):
        describe(wave, sensors=[1.5], grid={"l1": "1:2:3"})
    assert describe(wave, sensors="2", grid={"l1": "1:2:3"}).sensors == (2,)
    assert describe(wave, sensors=np.array([2]), grid={"l1": "1:2:3"}).sensors == (2,)
    with pytest.raises(SweepError, match="job classify needs sensors"):
        describe(wave, job="classify", param_grid={"rho": "1:2:3"})
    with pytest.raises(SweepError, match="job classify has no option 'tol'"):
        describe(wave, job="classify", sensors=[2], grid={"l1": "1:2:3"}, options={"tol": 1e-3})


def test_chunks_cover_the_grid_once():
    for shape, size in [((7,), 3), ((3, 5, 4), 7), ((2, 20, 20), 48), ((4, 1), 100), ((5,), 1)]:
        plan = ChunkPlan.for_grid(shape, size)
        points = [p for i in range(plan.n_chunks) for p in plan.points(i)]
        assert len(points) == len(set(points)) == int(np.prod(shape))
        assert max(len(plan.points(i)) for i in range(plan.n_chunks)) <= size


# --------------------------------------------------------------------- per point
def test_wave_damper_sweep_matches_the_closed_form():
    k = (0.2, 0.5, 0.8, 1.0, 1.5, 3.0)
    ds = phdesign.sweep("wave", sensors=[2], grid={"l1": list(k)}, **SYNC)
    alpha = ds.spectral_abscissa.values
    kk = np.array(k)
    ok = kk != 1.0
    exact = 0.5 * np.log(np.abs((1 - kk[ok]) / (1 + kk[ok])))
    # tolerance: spectrum() converges the abscissa to 1e-10 (relative to max(1, |α|))
    np.testing.assert_allclose(alpha[ok], exact, rtol=0, atol=1e-9)
    assert ds.converged.values[ok].all()
    # k = 1: the matched damper empties the spectrum; no number is stored for it
    j = k.index(1.0)
    assert ds.unbounded_below.values[j]
    assert not ds.converged.values[j]
    assert np.isnan(alpha[j])
    assert np.isnan(ds.digits.values[j])


def test_damped_beam_parameter_study_matches_minus_d_over_two():
    ds = phdesign.sweep("euler-bernoulli", param_grid={"d": "0:0.4:5"}, **SYNC)
    d = ds.d.values
    np.testing.assert_allclose(ds.spectral_abscissa.values, -d / 2, rtol=0, atol=1e-9)
    assert ds.converged.values.all()
    assert ds.attrs["model"] == load_builtin("euler-bernoulli").name


def test_sweep_points_are_the_spectrum_command_s_numbers():
    """Each point equals spectrum() exactly: same matrices, same LAPACK calls, one thread.

    (0.3669, 0.1624) does not agree to 1e-10 at the first pair (20, 30): it goes to
    spectrum() itself; (0.1, 1) is answered from the prepared pair.
    """
    from threadpoolctl import threadpool_limits

    from phdesign.numeric.bridge import to_numeric
    from phdesign.numeric.spectrum.converged import spectrum
    from phdesign.sweep.spectrum_job import figures_of_report

    grid = {"l1": [0.1, 0.3669], "l2": [0.1624, 1.0]}
    ds = phdesign.sweep("euler-bernoulli", sensors=[3, 4], grid=grid, **SYNC)
    nm = to_numeric(load_builtin("euler-bernoulli"))
    C = np.array([[0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]])
    for i, l1 in enumerate(grid["l1"]):
        for j, l2 in enumerate(grid["l2"]):
            with threadpool_limits(limits=1):
                expected = figures_of_report(spectrum(nm, C, np.diag([l1, l2])))
            got = {name: ds[name].values[i, j].item() for name in expected}
            for name, value in expected.items():
                if value is None:
                    assert np.isnan(got[name]), name
                else:
                    assert got[name] == value, (l1, l2, name)


def test_classify_sweep_gives_the_damper_certificate():
    k = np.array([0.2, 0.5, 1.0, 3.0])
    ds = phdesign.sweep("wave", job="classify", sensors=[2], grid={"l1": list(k)}, **SYNC)
    assert ds.verdict.values.tolist() == ["exponential"] * 4
    assert ds.best.values.tolist() == ["3.2.2"] * 4
    # κ* = k/(1 + k²), computed exactly then rounded once: equal to the double nearest it
    np.testing.assert_allclose(ds.kappa.values, k / (1 + k**2), rtol=1e-15)


def test_sensor_set_axis_classifies_the_beam_s_single_sensors(tmp_path):
    ds = phdesign.sweep("euler-bernoulli", job="classify", sensor_sets="3,4;4;3", **SYNC)
    assert ds.sensors.values.tolist() == ["3,4", "4", "3"]
    assert ds.verdict.values.tolist() == ["exponential", "exponential", "inconclusive"]
    assert ds.best.values[2] == ""
    assert np.isnan(ds.kappa.values[2])
    # text figures and text coordinates survive Zarr, NetCDF and CSV
    for name in ("sets.zarr", "sets.nc"):
        phdesign.sweep(
            "euler-bernoulli",
            job="classify",
            sensor_sets="3,4;4;3",
            output=tmp_path / name,
            chunk_size=1,
            **SYNC,
        )
        same_figures(phdesign.sweep.open_sweep(tmp_path / name), ds)
    from phdesign.sweep.export import to_csv

    assert to_csv(ds).splitlines()[1] == '"3,4",exponential,0.5,3.4.3'


# --------------------------------------------------------------------- storage
def beam_map(**extra):
    return phdesign.sweep("euler-bernoulli", **{**BEAM_MAP, **SYNC, **extra})


@pytest.fixture(scope="module")
def beam_reference():
    return beam_map()


def test_zarr_csv_and_netcdf_hold_the_same_sweep(beam_reference, tmp_path):
    zarr_ds = beam_map(output=tmp_path / "m.zarr")
    same_figures(zarr_ds, beam_reference)
    assert zarr_ds.attrs["phdesign_sweep"] == beam_reference.attrs["phdesign_sweep"]
    assert json.loads(zarr_ds.attrs["phdesign_run"])["computed"] == 12 / 2
    assert (tmp_path / "m.zarr" / ".phdesign" / "complete.json").is_file()
    assert list(zarr_ds.dims)
    assert zarr_ds.spectral_abscissa.dims == ("d", "l1", "l2")

    beam_map(output=tmp_path / "m.nc")
    same_figures(phdesign.sweep.open_sweep(tmp_path / "m.nc"), beam_reference)

    beam_map(output=tmp_path / "m.csv")
    lines = (tmp_path / "m.csv").read_text().splitlines()
    assert lines[0] == ",".join(["d", "l1", "l2", *beam_reference.data_vars])
    assert len(lines) == 1 + 12
    first = dict(zip(lines[0].split(","), lines[1].split(","), strict=True))
    assert float(first["d"]) == 0.1
    assert float(first["l1"]) == 0.05
    assert float(first["l2"]) == 0.5
    assert float(first["spectral_abscissa"]) == beam_reference.spectral_abscissa.values[0, 0, 0]
    assert first["converged"] in ("true", "false")


def test_existing_outputs_are_never_replaced_without_force(beam_reference, tmp_path):
    store = tmp_path / "m.zarr"
    beam_map(output=store)
    before = {p: p.stat().st_mtime_ns for p in store.rglob("*")}
    with pytest.raises(OutputFileError, match="exists; resume the sweep it holds"):
        beam_map(output=store)
    other = {**BEAM_MAP["grid"], "l2": "0.5,3"}
    with pytest.raises(
        SweepError, match=r"holds a different sweep \(axis l2: 0.5,2 against 0.5,3\)"
    ):
        beam_map(output=store, resume=True, grid=other)
    with pytest.raises(SweepError, match="written in chunks of 2 points"):
        beam_map(output=store, resume=True, chunk_size=3)
    assert {p: p.stat().st_mtime_ns for p in store.rglob("*")} == before
    # a complete store resumes to itself without computing
    again = beam_map(output=store, resume=True)
    assert json.loads(again.attrs["phdesign_run"])["computed"] == 0
    same_figures(again, beam_reference)
    # --force replaces a store, never a folder that is not a Zarr store
    replaced = beam_map(output=store, force=True, grid=other)
    assert replaced.l2.values.tolist() == [0.5, 3.0]
    folder = tmp_path / "mine.zarr"
    folder.mkdir()
    (folder / "notes.txt").write_text("mine")
    with pytest.raises(OutputFileError, match="not a Zarr store; refusing to replace it"):
        beam_map(output=folder, force=True)
    assert (folder / "notes.txt").read_text() == "mine"


def test_a_killed_sweep_resumes_to_the_same_result(tmp_path):
    """SIGKILL a sweep after some chunks are stored; resume it; compare to a fresh run."""
    store = tmp_path / "map.zarr"
    grid = "l1=0.05:0.95:40"
    argv = [sys.executable, "-m", "phdesign", "sweep", "wave", "--sensors", "2", "--grid", grid]
    argv += ["--chunk-size", "1", "--scheduler", "synchronous", "--no-progress", "-o", str(store)]
    env = {**os.environ, "PYTHONPATH": str(ROOT), "OPENBLAS_NUM_THREADS": "1"}
    proc = subprocess.Popen(argv, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    markers = store / ".phdesign" / "chunks"

    def stored_markers() -> int:
        # a chunk's marker is its index; a kill can leave the temporary file of a marker
        # being written (.phd-*.tmp) beside them, which vouches for nothing
        return sum(1 for p in markers.iterdir() if p.name.isdigit()) if markers.is_dir() else 0

    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and proc.poll() is None:
        if stored_markers() >= 5:
            break
        time.sleep(0.002)
    proc.send_signal(signal.SIGKILL)
    _, err = proc.communicate()
    assert proc.returncode == -signal.SIGKILL, err.decode()
    stored = stored_markers()
    assert 5 <= stored < 40
    assert not (store / ".phdesign" / "complete.json").exists()
    with pytest.raises(SweepError, match="incomplete"):
        phdesign.sweep.open_sweep(store)

    kwargs = {"sensors": [2], "grid": {"l1": "0.05:0.95:40"}, **SYNC}
    resumed = phdesign.sweep("wave", output=store, resume=True, **kwargs)
    record = json.loads(resumed.attrs["phdesign_run"])
    assert (record["reused"], record["computed"]) == (stored, 40 - stored)
    same_figures(resumed, phdesign.sweep("wave", chunk_size=7, **kwargs))


def test_resuming_deletes_the_stale_half_written_markers_of_a_killed_sweep(tmp_path):
    # SIGKILL can land between staging a marker (.phd-XXXXXXXX.tmp) and linking it; the
    # resumed sweep deletes such a file once it is older than any live write could make
    # it (STALE_AFTER), keeps a young one (it may be a write in progress) and anything
    # not of the staging pattern, and recomputes exactly the chunks without a marker
    from phdesign.core.files import STALE_AFTER

    store = tmp_path / "map.zarr"
    kwargs = {"sensors": [2], "grid": {"l1": "0.1:0.9:6"}, "chunk_size": 1, **SYNC}
    first = phdesign.sweep("wave", output=store, **kwargs)
    chunks = store / ".phdesign" / "chunks"
    (store / ".phdesign" / "complete.json").unlink()
    for index in (2, 5):
        (chunks / f"{index:08d}").unlink()
    stale, young = chunks / ".phd-0123abcd.tmp", store / ".phdesign" / ".phd-89abcdef.tmp"
    other = chunks / ".phd-notmine.tmp"
    for path in (stale, young, other):
        path.write_bytes(b"")
    old = time.time() - 2 * STALE_AFTER
    os.utime(stale, (old, old))
    os.utime(other, (old, old))
    resumed = phdesign.sweep("wave", output=store, resume=True, **kwargs)
    record = json.loads(resumed.attrs["phdesign_run"])
    assert (record["reused"], record["computed"]) == (4, 2)
    assert not stale.exists()
    assert young.exists()
    assert other.exists()
    same_figures(resumed, first)


# --------------------------------------------------------------------- command line
def test_cli_sweep_json_summary_and_plot(tmp_path, capsys):
    out = tmp_path / "k.nc"
    argv = ["sweep", "wave", "--sensors", "2", "--grid", "l1=0.2:0.8:4", "--param-grid"]
    argv += ["rho=1,4", "--scheduler", "synchronous", "-o", str(out), "--json"]
    assert main(argv) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["points"] == 8
    assert [a["name"] for a in summary["axes"]] == ["rho", "l1"]
    converged = next(f for f in summary["figures"] if f["name"] == "converged")
    assert converged["true"] == 8
    alpha = next(f for f in summary["figures"] if f["name"] == "spectral_abscissa")
    # ρ w_tt = T w_zz, w(0) = 0, T w_z(1) = -k w_t(1): modes sinh(λ z / c) with
    # tanh(λ / c) = -Z / k, so α = (c/2) ln|(k - Z)/(k + Z)|, c = sqrt(T/ρ), Z = sqrt(ρ T)
    # (T = 1; ρ = 1 is the DESIGN.md formula).  The slowest point: k = 0.2 on ρ = 4.
    ds = phdesign.sweep.open_sweep(out)
    rho, k = np.meshgrid(ds.rho.values, ds.l1.values, indexing="ij")
    c, Z = np.sqrt(1 / rho), np.sqrt(rho)
    np.testing.assert_allclose(
        ds.spectral_abscissa.values, c / 2 * np.log(np.abs((k - Z) / (k + Z))), rtol=0, atol=1e-9
    )
    assert alpha["at_maximum"] == {"rho": 4.0, "l1": 0.2}
    assert abs(alpha["maximum"] - 0.25 * np.log(1.8 / 2.2)) < 1e-9
    assert main(["plot", str(out), "-o", str(tmp_path / "k.png"), "--select", "rho=4"]) == 0
    assert "wrote" in capsys.readouterr().out
    assert (tmp_path / "k.png").read_bytes()[:4] == b"\x89PNG"
    text = str(summarize(phdesign.sweep.open_sweep(out)))
    assert text.splitlines()[0] == "sweep: spectrum on wave (sensors 2; gain l1 (the grid's axis))"


def test_classify_and_the_sweep_package_import_no_dask():
    code = (
        "import sys, phdesign.sweep, phdesign.cli.sweep_command\n"
        "from phdesign.cli import main\n"
        "main(['classify', 'wave', '--sensors', '2', '--gain', '1'])\n"
        "print(sorted(m for m in ('dask', 'distributed', 'xarray', 'zarr') if m in sys.modules))"
    )
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert out.stdout.splitlines()[-1] == "[]"


def test_the_package_is_the_function():
    assert callable(phdesign.sweep)
    assert phdesign.sweep.sweep.__name__ == "sweep"


# --------------------------------------------------------------------- plots
def test_plots_mark_unconverged_points(beam_reference):
    from phdesign.plots.sweep import plot_sweep

    one = beam_reference.isel(d=1).copy(deep=True)
    one.converged.values[1, 0] = False  # as if (l1[1], l2[0]) had not converged
    fig = plot_sweep(one)  # a gain map: l1 across, l2 up, as in the README's gallery
    ax = fig.axes[0]
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("l1", "l2")
    assert ax.get_xscale() == "log"
    assert ax.get_yscale() == "linear"
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["not converged (1 point)"]
    marker = next(line for line in ax.get_lines() if line.get_marker() == "x")
    assert (marker.get_xdata().tolist(), marker.get_ydata().tolist()) == (
        [one.l1.values[1]],
        [one.l2.values[0]],
    )
    panels = plot_sweep(beam_reference)  # three axes: one map per value of d
    assert [a.get_title() for a in panels.axes if a.get_title()] == ["d = 0.1", "d = 0.3"]
    curve = plot_sweep(beam_reference, "digits", select={"d": 0.3, "l2": 2})
    assert curve.axes[0].get_xscale() == "log"  # l1 is a log grid
    assert curve.axes[0].get_lines()[0].get_xdata().tolist() == one.l1.values.tolist()
    with pytest.raises(SweepError, match="no figure 'kappa'"):
        plot_sweep(beam_reference, "kappa")
    with pytest.raises(SweepError, match="no axis 'rho'"):
        plot_sweep(beam_reference, select={"rho": 1})


def test_verdict_map_draws_categories():
    from phdesign.plots.sweep import plot_sweep

    ds = phdesign.sweep(
        "euler-bernoulli", job="classify", sensor_sets="4;3", grid={"l": "0.5,2"}, **SYNC
    )
    fig = plot_sweep(ds)  # one curve per sensor set over l
    assert fig.axes[0].get_xlabel() == "l"
    assert sorted(t.get_text() for t in fig.axes[0].get_legend().get_texts()) == [
        "sensors 3",
        "sensors 4",
    ]
