r"""The ``spectrum`` job: converged spectral abscissa at every gain of a chunk.

Each point is exactly what :func:`phdesign.numeric.spectrum.converged.spectrum` reports at its
gain:
the same refinement of the resolution pair, the same drift test, choice of the abscissa
and convergence rule, so a stored abscissa carries the ``converged`` flag and the digits
that ``spectrum()`` gives, and no number that did not converge is stored as if it had.
Discretizing is most of a spectrum's cost on the beam (two Galerkin assemblies of ~20 ms
against ~7 ms of eigenvalues) and does not depend on the gain, so a chunk shares one
:class:`~phdesign.numeric.spectrum.refinement.Discretizations`: every resolution is
discretized once per chunk, whatever the number of gains, and each gain solves

.. math::

    (J - R - B (I + K D)^{-1} K B^\top)\, v = \lambda E v, \qquad K = C_m^\top L C_m,

at the resolutions its refinement visits.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from phdesign.core.defaults import method_or_default
from phdesign.numeric.bridge import NumericModel, to_numeric
from phdesign.numeric.spectrum.converged import spectrum
from phdesign.numeric.spectrum.refinement import Discretizations
from phdesign.numeric.spectrum.report import SpectrumReport

__all__ = [
    "ChunkSpectrum",
    "abscissa_evaluator",
    "check_options",
    "figures_of_report",
    "prepare",
    "sensor_rows",
]


def figures_of_report(report: SpectrumReport) -> dict[str, Any]:
    """Return the job's figures from a spectrum report (:mod:`phdesign.numeric.spectrum`)."""
    return {
        "spectral_abscissa": report.spectral_abscissa,
        "converged": report.converged,
        "digits": report.digits,
        "n_resolved": report.n_resolved,
        "unbounded_below": report.unbounded_below,
        "ill_conditioned": report.ill_conditioned,
    }


class ChunkSpectrum:
    """Spectrum figures at many gains of one model and sensor set, discretized once.

    Parameters
    ----------
    nm : NumericModel
    C_m : ndarray or None
        Sensor matrix (``None``: the plant with u = 0, gains ignored).
    method : str, optional
        A registered discretization; default: the table's (:mod:`phdesign.core.defaults`).
    resolution, max_resolution : int, optional
        As for :func:`~phdesign.numeric.spectrum.converged.spectrum`.
    tol : float, optional
        As for :func:`~phdesign.numeric.spectrum.converged.spectrum`.

    Examples
    --------
    >>> import numpy as np
    >>> from phdesign.models import load_builtin
    >>> evaluate = ChunkSpectrum(to_numeric(load_builtin("wave")), np.array([[0.0, 1.0]]))
    >>> figures = evaluate((0.5,))
    >>> bool(abs(figures["spectral_abscissa"] - 0.5 * np.log(1 / 3)) < 1e-12)  # ½ ln((1-k)/(1+k))
    True
    >>> figures["converged"]
    True
    """

    def __init__(
        self,
        nm: NumericModel,
        C_m: np.ndarray | None,
        *,
        method: str | None = None,
        resolution: int | None = None,
        max_resolution: int | None = None,
        tol: float | None = None,
    ) -> None:
        method = method_or_default(method)
        self.nm, self.C_m, self.method = nm, C_m, method
        self.resolution, self.max_resolution, self.tol = resolution, max_resolution, tol
        self.discretizations = Discretizations(nm, method)

    def __call__(self, gain: tuple[float, ...] | None) -> dict[str, Any]:
        """Return the figures at the gain ``diag(gain)`` (ignored without sensors)."""
        C_m, L = None, None
        if self.C_m is not None and gain is not None:
            C_m, L = self.C_m, np.diag(np.asarray(gain, dtype=float))
        report = spectrum(
            self.nm,
            C_m,
            L,
            method=self.method,
            resolution=self.resolution,
            max_resolution=self.max_resolution,
            tol=self.tol,
            discretizations=self.discretizations,
        )
        return figures_of_report(report)


def abscissa_evaluator(
    nm: NumericModel, C_m: np.ndarray | None, options: Mapping[str, Any]
) -> Callable[[tuple[float, ...] | None], dict[str, Any]]:
    """Prepare the spectrum figures of many gains for one model and sensor set."""
    return ChunkSpectrum(
        nm,
        C_m,
        method=options.get("method"),
        resolution=options.get("resolution"),
        max_resolution=options.get("max_resolution"),
        tol=options.get("tol"),
    )


def check_options(model: Any, options: Mapping[str, Any]) -> None:
    """Refuse resolutions over the discretization budget before the sweep starts.

    Every point would refuse them (:func:`phdesign.core.limits.check_discretization`, the check
    :func:`~phdesign.numeric.spectrum.converged.spectrum` makes); the model's size decides.
    """
    from phdesign.core.limits import check_discretization

    method = method_or_default(options.get("method"))
    check_discretization(model, method, options.get("resolution"), options.get("max_resolution"))


def prepare(
    model: Any, sensors: tuple[int, ...] | None, options: Mapping[str, Any]
) -> Callable[[tuple[float, ...] | None], dict[str, Any]]:
    """Prepare the job's evaluator (see :mod:`phdesign.sweep.jobs`)."""
    nm = to_numeric(model)
    return abscissa_evaluator(nm, sensor_rows(sensors, nm.n_ports), options)


def sensor_rows(sensors: tuple[int, ...] | None, ports: int) -> np.ndarray | None:
    """Return C_m of the unit rows that pick the (1-based) ``sensors`` (None: no sensors)."""
    if sensors is None:
        return None
    C_m = np.zeros((len(sensors), ports))
    C_m[np.arange(len(sensors)), np.asarray(sensors) - 1] = 1.0
    return C_m
