"""The simulation figure of a coupled model shows the boundary states beside the field (issue 26).

Checked on what is drawn: the panel's lines carry the run's own boundary states
``x_c(t) = E_c e_c(t)`` and their estimates, which tests/numeric/time/test_boundary_start.py
checks against closed forms.
"""

from __future__ import annotations

import numpy as np
import pytest

import phdesign as phd
from phdesign.cli import main

pytest.importorskip("matplotlib")


def boundary_axis(fig):
    (ax,) = [a for a in fig.axes if a.get_title().startswith("boundary systems")]
    return ax


def test_the_figure_draws_the_mass_momentum_and_its_estimate():
    obs = phd.Observer(phd.load("string-tip-mass"), [2], gain=1)
    run = obs.simulate("x1: sin(pi*z), mass momentum: 0.5", xhat0="mass momentum: -0.25",
                       t_end=2, samples=21)  # fmt: skip
    # x_c is the mass's momentum m e_c, m = 1, e_c the run's last (appended) coordinate
    assert run.boundary_labels == ("mass momentum",)
    np.testing.assert_array_equal(run.x_c[:, 0], run.states[:, -1])
    np.testing.assert_array_equal(run.x_c_hat[:, 0], run.states_hat[:, -1])
    assert run.x_c[0, 0] == 0.5
    assert run.x_c_hat[0, 0] == -0.25
    fig = run.plot()
    ax = boundary_axis(fig)
    assert ax.get_title() == "boundary systems: states and estimates"
    plant, estimate = ax.get_lines()
    assert plant.get_label() == "mass momentum"
    assert estimate.get_label() == "mass momentum, estimate"
    np.testing.assert_array_equal(plant.get_xdata(), run.t)
    np.testing.assert_array_equal(plant.get_ydata(), run.x_c[:, 0])
    np.testing.assert_array_equal(estimate.get_ydata(), run.x_c_hat[:, 0])


def test_a_plant_run_of_the_motor_draws_both_motor_states(tmp_path):
    # two boundary states (winding flux Lw i, rotor momentum Jm u_t(0)); no observer: no
    # estimates, and the JSON carries the same series
    plant = phd.Plant(phd.load("string-motor"), {"Lw": 2, "Jm": 3})
    run = plant.simulate("winding flux: 1", t_end=1, samples=11)
    assert run.boundary_labels == ("winding flux", "rotor momentum")
    E_c = np.diag([2.0, 3.0])  # Q_c^-1 = diag(Lw, Jm)
    np.testing.assert_allclose(run.x_c, run.states[:, -2:] @ E_c, rtol=1e-15)
    lines = boundary_axis(run.plot()).get_lines()
    assert [line.get_label() for line in lines] == list(run.boundary_labels)
    for k, line in enumerate(lines):
        np.testing.assert_array_equal(line.get_ydata(), run.x_c[:, k])
    assert run.to_dict()["boundary_states"]["winding flux"][0] == 1.0
    assert "rotor momentum" in run.to_csv().splitlines()[0]


def test_simulate_plot_from_the_command_line(tmp_path):
    path = tmp_path / "run.png"
    argv = ["simulate", "string-tip-mass", "--sensors", "2", "--gain", "1",
            "--x0", "mass momentum: 1", "--t-end", "1", "--samples", "5", "--plot", str(path),
            "--quiet"]  # fmt: skip
    assert main(argv) == 0
    assert path.stat().st_size > 0
