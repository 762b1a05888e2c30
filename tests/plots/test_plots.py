"""Plots are tested for what they draw (line data, labels, legends, markers), not pixels.

The synthetic simulation results below use closed-form time series, so every expected
array is the input itself or a one-line transformation of it (stated at each check).
"""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from phdesign import plots
from phdesign.core.errors import NumericError, OutputFileError
from phdesign.numeric.time.options import SimulationOptions
from phdesign.numeric.time.result import SimulationResult

T = np.linspace(0.0, 2.0, 41)
Z = np.linspace(0.0, 1.0, 11)


def make_result(observer: bool = True, displacement: bool = True) -> SimulationResult:
    """H = e^{-t}/2, Ĥ = (1 - e^{-t})/2, H̃ = e^{-3t}/4; w = z² cos t, ŵ = w (1 - e^{-t})."""
    w = np.outer(np.cos(T), Z**2)
    w_hat = w * (1 - np.exp(-T))[:, None]
    return SimulationResult(
        t=T,
        H=0.5 * np.exp(-T),
        H_hat=0.5 * (1 - np.exp(-T)) if observer else None,
        H_err=0.25 * np.exp(-3 * T) if observer else None,
        y=np.zeros((T.size, 2)),
        y_hat=np.zeros((T.size, 2)) if observer else None,
        output_labels=("y1", "y2"),
        method="galerkin",
        resolution=10,
        z_w=Z if displacement else None,
        w=w if displacement else None,
        w_hat=w_hat if (displacement and observer) else None,
    )


def legend_texts(ax) -> list[str]:
    return [t.get_text() for t in ax.get_legend().get_texts()]


def lines_by_label(ax) -> dict[str, object]:
    return {line.get_label(): line for line in ax.get_lines()}


# ----------------------------------------------------------------------------- energies
def test_hamiltonians_draw_the_three_energies_with_labels_and_a_log_panel():
    res = make_result()
    fig = plots.plot_hamiltonians(res)
    lin, log = fig.axes
    lines = lines_by_label(lin)
    np.testing.assert_array_equal(lines["H (plant)"].get_ydata(), res.H)
    np.testing.assert_array_equal(lines["Ĥ (observer)"].get_ydata(), res.H_hat)
    np.testing.assert_array_equal(lines["H̃ (estimation error)"].get_ydata(), res.H_err)
    assert lines["Ĥ (observer)"].get_linestyle() == "--"  # the paper's dashed estimate
    np.testing.assert_array_equal(lines["H (plant)"].get_xdata(), T)
    assert log.get_yscale() == "log"
    assert lin.get_yscale() == "linear"
    np.testing.assert_array_equal(
        lines_by_label(log)["H̃ (estimation error)"].get_ydata(), res.H_err
    )
    assert lin.get_xlabel() == "time t [s]"
    assert "energy [J]" in lin.get_ylabel()
    assert legend_texts(lin) == ["H (plant)", "Ĥ (observer)", "H̃ (estimation error)"]


def test_hamiltonians_without_observer_draw_only_the_plant():
    fig = plots.plot_hamiltonians(make_result(observer=False))
    assert [legend_texts(ax) for ax in fig.axes] == [["H (plant)"], ["H (plant)"]]


def test_hamiltonians_draw_on_given_axes():
    fig0, axes = plots.new_figure(1, 2)
    fig = plots.plot_hamiltonians(make_result(), axes)
    assert fig is fig0
    assert len(axes[0].get_lines()) == 3


def test_error_energy_is_normalized_per_design_with_reference_levels():
    a, b = make_result(), make_result()
    fig = plots.plot_error_energy({"design A": a, "design B": b})
    ax = fig.axes[0]
    lines = lines_by_label(ax)
    # H̃/H̃(0) = e^{-3t} for the synthetic result
    np.testing.assert_allclose(lines["design A"].get_ydata(), np.exp(-3 * T), rtol=1e-14)
    assert ax.get_yscale() == "log"
    assert legend_texts(ax) == ["design A", "design B", "level 0.01", "level 0.0001"]
    assert lines["level 0.01"].get_ydata()[0] == pytest.approx(1e-2)


def test_error_energy_refuses_a_zero_initial_error_and_missing_observer():
    res = make_result()
    zero = SimulationResult(**{**res.__dict__, "H_err": np.zeros(T.size)})
    with pytest.raises(NumericError, match="H̃\\(0\\) = 0"):
        plots.plot_error_energy({"zero": zero})
    with pytest.raises(NumericError, match="H_err"):
        plots.plot_error_energy([("plant only", make_result(observer=False))])
    with pytest.raises(NumericError, match="at least one"):
        plots.plot_error_energy({})


# ----------------------------------------------------------------------------- deflection
@pytest.mark.parametrize(
    ("which", "expected"),
    [
        ("w", lambda r: r.w),
        ("w_hat", lambda r: r.w_hat),
        ("error", lambda r: r.w - r.w_hat),
    ],
)
def test_deflection_heat_map_holds_the_field_on_a_symmetric_scale(which, expected):
    res = make_result()
    fig = plots.plot_deflection(res, which)
    ax = fig.axes[0]
    mesh = ax.collections[0]
    # pcolormesh(t, z, field.T): rows are z, columns are t
    np.testing.assert_array_equal(
        np.asarray(mesh.get_array()).reshape(Z.size, T.size), expected(res).T
    )
    vmin, vmax = mesh.get_clim()
    assert vmin == -vmax
    assert vmax == pytest.approx(np.max(np.abs(expected(res))))
    assert ax.get_xlabel() == "time t [s]"
    assert ax.get_ylabel() == "position z [m]"
    assert fig.axes[1].get_ylabel().endswith("[m]")  # the colour bar says what and in which unit


def test_deflection_errors_name_what_is_missing():
    with pytest.raises(NumericError, match="no displacement"):
        plots.plot_deflection(make_result(displacement=False))
    with pytest.raises(NumericError, match="w_hat"):
        plots.plot_deflection(make_result(observer=False), "error")
    with pytest.raises(NumericError, match="unknown field 'v'"):
        plots.plot_deflection(make_result(), "v")


def test_deflection_panels_share_the_colour_scale_of_w_and_estimate():
    res = make_result()
    fig = plots.plot_deflection_panels(res)
    meshes = [ax.collections[0] for ax in fig.axes if ax.collections]
    assert meshes[0].get_clim() == meshes[1].get_clim()
    # max |w| = 1 (z = 1, t = 0) is larger than max |ŵ|
    assert meshes[0].get_clim()[1] == pytest.approx(1.0)


def test_tip_overlay_draws_true_and_estimated_end_tip():
    res = make_result()
    ax = plots.plot_tip(res).axes[0]
    lines = lines_by_label(ax)
    np.testing.assert_array_equal(lines["w(z = 1, t) (plant)"].get_ydata(), res.w[:, -1])
    np.testing.assert_array_equal(lines["ŵ(z = 1, t) (observer)"].get_ydata(), res.w_hat[:, -1])
    assert lines["ŵ(z = 1, t) (observer)"].get_linestyle() == "--"


def test_tip_error_of_several_designs():
    a, b = make_result(), make_result()
    ax = plots.plot_tip_error([("design 1", a), ("design 2", b)]).axes[0]
    lines = lines_by_label(ax)
    # w − ŵ at z = 1: cos(t) e^{-t}
    np.testing.assert_allclose(lines["design 1"].get_ydata(), np.cos(T) * np.exp(-T), atol=1e-15)
    assert legend_texts(ax) == ["design 1", "design 2"]
    assert ax.get_ylabel() == "w − ŵ at z = 1 [m]"


# ----------------------------------------------------------------------------- spectra
def test_spectrum_marks_resolved_and_unresolved_differently():
    lam = np.array([-1 + 2j, -1 - 2j, -0.5 + 80j, -0.5 - 80j, -3.0])
    mask = np.array([True, True, False, False, True])
    exact = np.array([-1 + 2j, -1 - 2j])
    ax = plots.plot_spectrum(lam, mask, abscissa=-1.0, exact=exact).axes[0]
    lines = lines_by_label(ax)
    resolved = lines["resolved (agree at two resolutions)"]
    unresolved = lines["unresolved (discretization artefacts)"]
    assert (resolved.get_marker(), unresolved.get_marker()) == ("o", "x")
    np.testing.assert_array_equal(resolved.get_xdata(), [-1, -1, -3])
    np.testing.assert_array_equal(unresolved.get_ydata(), [80, -80])
    assert lines["exact"].get_marker() == "+"
    assert lines["spectral abscissa α = -1"].get_xdata()[0] == -1.0
    assert ax.get_xlabel() == "Re λ [1/s]"
    assert ax.get_ylabel() == "Im λ [rad/s]"


def test_spectrum_accepts_indices_and_checks_the_mask_length():
    lam = np.array([-1.0, -2.0, -3.0])
    ax = plots.plot_spectrum(lam, np.array([2])).axes[0]
    np.testing.assert_array_equal(
        lines_by_label(ax)["resolved (agree at two resolutions)"].get_xdata(), [-3.0]
    )
    with pytest.raises(NumericError, match="expected 3"):
        plots.plot_spectrum(lam, np.array([True, False]))
    unmasked = plots.plot_spectrum(lam).axes[0]
    assert legend_texts(unmasked) == ["eigenvalues"]


def test_abscissa_sweep_overlays_the_exact_damped_wave_curve():
    k = np.array([0.2, 0.5, 2.0])
    alpha = 0.5 * np.log(np.abs((1 - k) / (1 + k)))  # the exact damped-wave abscissa

    def exact(x):
        return 0.5 * np.log(np.abs((1 - x) / (1 + x)))

    ax = plots.plot_abscissa_sweep(k, alpha, exact=exact, exact_label="exact").axes[0]
    lines = lines_by_label(ax)
    np.testing.assert_array_equal(lines["computed (resolved)"].get_ydata(), alpha)
    curve = lines["exact"]
    np.testing.assert_allclose(curve.get_ydata(), exact(np.asarray(curve.get_xdata())), rtol=1e-14)
    assert curve.get_xdata()[0] == 0.2
    assert curve.get_xdata()[-1] == 2.0
    with pytest.raises(NumericError, match="differ in shape"):
        plots.plot_abscissa_sweep(k, alpha[:2])


def test_gain_map_draws_the_grid_the_optimum_and_the_designs():
    l1 = np.array([0.01, 0.1, 1.0])
    l2 = np.array([0.1, 1.0])
    alpha = np.array([[-1.0, -2.0, np.nan], [-0.5, -3.0, -1.5]])
    fig = plots.plot_gain_map(
        l1, l2, alpha, optimum=(0.1, 1.0), optimum_abscissa=-3.0, designs={"paper": (0.1, 1.0)}
    )
    ax = fig.axes[0]
    data = ax.collections[0].get_array()
    np.testing.assert_array_equal(
        np.ma.getdata(data).reshape(2, 3)[~np.isnan(alpha)], alpha[~np.isnan(alpha)]
    )
    assert np.ma.getmaskarray(data).reshape(2, 3)[0, 2]  # the NaN cell is masked (grey)
    star = lines_by_label(ax)["tuned optimum (0.1, 1), α = -3"]
    assert star.get_marker() == "*"
    assert (star.get_xdata()[0], star.get_ydata()[0]) == (0.1, 1.0)
    assert [t.get_text() for t in ax.texts] == ["paper"]
    assert (ax.get_xscale(), ax.get_yscale()) == ("log", "log")
    assert fig.axes[1].get_ylabel() == "spectral abscissa α [1/s]"
    with pytest.raises(NumericError, match=r"\(2, 3\)"):
        plots.plot_gain_map(l1, l2, alpha.T)


# ----------------------------------------------------------------------------- CLI entry
def test_plot_simulation_writes_png_and_refuses_to_overwrite(tmp_path):
    path = tmp_path / "sim.png"
    fig = plots.plot_simulation(make_result(), path, title="beam")
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert fig.get_suptitle() == "beam"
    # 2 x 2 panels plus the heat map's colour bar
    assert len(fig.axes) == 5
    with pytest.raises(OutputFileError, match="exists"):
        plots.plot_simulation(make_result(), path)
    plots.plot_simulation(make_result(), path, force=True)
    with pytest.raises(OutputFileError, match="unknown image format 'xyz'"):
        plots.plot_simulation(make_result(), tmp_path / "sim.xyz")
    assert not (tmp_path / "sim.xyz").exists()


def test_plot_simulation_without_displacement_draws_the_outputs():
    # issue 11: a model without a displacement gets a y/ŷ panel and the output error
    res = make_result(displacement=False)
    fig = plots.plot_simulation(res)
    assert [ax.get_title() for ax in fig.axes] == [
        "Hamiltonians",
        "decay (log scale)",
        "boundary outputs (dashed: observer)",
        "output error",
    ]
    lines = lines_by_label(fig.axes[2])
    np.testing.assert_array_equal(lines["y1 = y1"].get_ydata(), res.y[:, 0])
    assert lines["ŷ2"].get_linestyle() == "--"


def test_plot_simulation_on_a_real_wave_simulation(tmp_path):
    from phdesign.models import load_builtin
    from phdesign.numeric.bridge import to_numeric
    from phdesign.numeric.inputs import initial_state_function
    from phdesign.numeric.time.simulation import simulate

    wave = load_builtin("wave")
    nm = to_numeric(wave)
    x0 = initial_state_function("x2: sin(pi*z)", nm, model=wave)
    res = simulate(
        nm,
        np.array([[0.0, 1.0]]),
        np.array([[0.5]]),
        x0=x0,
        options=SimulationOptions(t_end=1.0, samples=21),
    )
    fig = plots.plot_simulation(res, tmp_path / "wave.svg")
    assert (tmp_path / "wave.svg").read_text().lstrip().startswith("<?xml")
    lines = lines_by_label(fig.axes[0])
    np.testing.assert_array_equal(lines["H̃ (estimation error)"].get_ydata(), res.H_err)


def test_importing_plots_does_not_import_matplotlib():
    code = "import sys, phdesign.plots; print('matplotlib' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


@pytest.mark.parametrize(
    ("name", "exists", "force", "match"),
    [
        ("a.png", True, False, "exists; pass `force=True`"),
        ("a.txt", False, False, "unknown image format 'txt'"),
        ("a", False, False, "unknown image format ''"),
    ],
)
def test_check_plot_path_refuses_before_any_work(tmp_path, name, exists, force, match):
    path = tmp_path / name
    if exists:
        path.write_bytes(b"old")
    with pytest.raises(OutputFileError, match=match):
        plots.check_plot_path(path, force=force)


def test_check_plot_path_returns_the_format():
    assert plots.check_plot_path("figure.SVG") == "svg"
