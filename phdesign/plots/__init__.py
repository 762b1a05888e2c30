r"""Plots for observer design: energies, deflections, outputs, spectra and gain maps.

A front end: every function draws data that a lower layer computed
(:class:`phdesign.numeric.time.result.SimulationResult`, eigenvalues from
:mod:`phdesign.numeric.spectrum.converged`, abscissas from :mod:`phdesign.numeric.tuning.search`)
and returns
the :class:`matplotlib.figure.Figure` it drew on.  Functions that draw one panel accept an
optional ``ax``; without it they make a new figure (:func:`new_figure`).  Result objects
draw themselves with these (``result.plot()``).

The modules, by subject: :mod:`~phdesign.plots.energy` (Hamiltonians),
:mod:`~phdesign.plots.deflection` (displacement, tip, outputs),
:mod:`~phdesign.plots.spectra` (eigenvalues, a spectrum report, a loop's spectrum,
abscissa against gain, gain maps), :mod:`~phdesign.plots.simulation` (the summary figure
of ``simulate --plot``), :mod:`~phdesign.plots.noise` (the noise report, speed against
noise), :mod:`~phdesign.plots.verification` (an exported observer against the continuous
one) and :mod:`~phdesign.plots.sweep` (gain maps and studies of a sweep).  No module
outside this package draws: a result's ``.plot()`` hands itself to one of these
functions in one line (python-control's ``TimeResponseData.plot``), and one place makes
the axes, titles the figure and writes the file (:func:`drawing`, :func:`save_figure`).
matplotlib is imported inside the functions and sympy not at all, so ``import
phdesign.plots`` stays light.  Figures are never pyplot's: in Jupyter a figure shows once,
as the value of a cell.

Units: the built-in models are written in SI units (unit density and stiffness), so time
is in s, position in m, deflection in m, energy in J and eigenvalues in 1/s.

The quantities drawn are the paper's (Section V):

.. math::

    H = \tfrac12 \int_a^b x^\top \mathcal H x \, dz, \quad
    \hat H = \tfrac12 \int_a^b \hat x^\top \mathcal H \hat x \, dz, \quad
    \tilde H = \tfrac12 \int_a^b \tilde x^\top \mathcal H \tilde x \, dz, \quad
    \tilde x = x - \hat x,

the deflection :math:`w(z, t)`, its estimate :math:`\hat w(z, t)` and the end-tip error
:math:`w(b, t) - \hat w(b, t)`.

Examples
--------
>>> import numpy as np
>>> fig = plot_spectrum(np.array([-1 + 2j, -1 - 2j, -0.1 + 90j]), np.array([True, True, False]))
>>> sorted(t.get_text() for t in fig.axes[0].get_legend().get_texts())[0]
'resolved (agree at two resolutions)'
"""

from __future__ import annotations

from phdesign.plots._figures import (
    check_plot_path,
    drawing,
    figure_bytes,
    literal,
    new_figure,
    save_figure,
)
from phdesign.plots.deflection import (
    plot_deflection,
    plot_deflection_panels,
    plot_outputs,
    plot_tip,
    plot_tip_error,
)
from phdesign.plots.energy import plot_error_energy, plot_hamiltonians
from phdesign.plots.simulation import plot_boundary_states, plot_simulation
from phdesign.plots.spectra import plot_abscissa_sweep, plot_gain_map, plot_spectrum

__all__ = [
    "check_plot_path",
    "drawing",
    "figure_bytes",
    "literal",
    "new_figure",
    "plot_abscissa_sweep",
    "plot_boundary_states",
    "plot_deflection",
    "plot_deflection_panels",
    "plot_error_energy",
    "plot_gain_map",
    "plot_hamiltonians",
    "plot_outputs",
    "plot_simulation",
    "plot_spectrum",
    "plot_tip",
    "plot_tip_error",
    "save_figure",
]
