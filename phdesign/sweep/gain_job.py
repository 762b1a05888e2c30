r"""The ``gain`` job: H∞ and H₂ norms from the disturbances to the performance outputs.

Each point is exactly what :func:`phdesign.numeric.noise.disturbance.disturbance_gain`
(``phdesign gain``, :meth:`phdesign.design.plant.Plant.gain`) reports: of the plant with
its known inputs at zero without sensors, else of the error of the observer
:math:`L = \operatorname{diag}(l_1, \dots, l_q)` (sensor noise of intensity ``intensity``
included, default 1), from the model's ``[disturbances]`` to its ``[performance]``
outputs, each norm refined until it converged or was flagged.  A norm that did not
converge is stored as missing (NaN) with its flag, never as a number; the discretizations
do not depend on the gain and are built once per chunk.

Examples
--------
>>> from phdesign.io import model_from_dict, model_to_dict
>>> from phdesign.models import load_builtin
>>> data = model_to_dict(load_builtin("wave-damper"))  # the damped-tip string, k = 1/2
>>> data["disturbances"] = {"B": [[1], [0]]}
>>> data["performance"] = {"outputs": ["integral(e1)"]}
>>> evaluate = prepare(model_from_dict(data), None, {})
>>> round(evaluate(None)["hinf"], 6)  # PIETOOLS' library comment says 2
0.841877
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from phdesign.numeric.bridge import to_numeric
from phdesign.numeric.discretization.registry import DiscretePHS
from phdesign.numeric.noise.disturbance import disturbance_gain
from phdesign.numeric.noise.disturbance_report import GainReport
from phdesign.sweep.spectrum_job import sensor_rows

__all__ = ["figures_of_report", "prepare"]


def figures_of_report(report: GainReport) -> dict[str, Any]:
    """Return the job's figures from a gain report (None: not converged)."""
    hinf = report.hinf
    return {
        "hinf": hinf.value,
        "hinf_converged": hinf.converged,
        "hinf_frequency": hinf.frequency if hinf.value is not None else None,
        "h2": report.h2.value,
        "h2_converged": report.h2.converged,
        "h2_diverges": report.h2.diverges,
        "steady_state": report.unstable is None,
    }


def prepare(
    model: Any, sensors: tuple[int, ...] | None, options: Mapping[str, Any]
) -> Callable[[tuple[float, ...] | None], dict[str, Any]]:
    """Prepare the job's evaluator (see :mod:`phdesign.sweep.jobs`)."""
    nm = to_numeric(model)
    C_m = sensor_rows(sensors, nm.n_ports)
    shared: dict[int, DiscretePHS] = {}

    def evaluate(gain: tuple[float, ...] | None) -> dict[str, Any]:
        observer = C_m is not None and gain is not None
        report = disturbance_gain(
            nm,
            C_m if observer else None,
            np.diag(np.asarray(gain, dtype=float)) if observer else None,
            model=model,
            intensity=options.get("intensity"),
            method=options.get("method"),
            resolution=options.get("resolution"),
            max_resolution=options.get("max_resolution"),
            tol=options.get("tol"),
            discretizations=shared,
        )
        return figures_of_report(report)

    return evaluate
