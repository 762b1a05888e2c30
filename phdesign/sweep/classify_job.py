r"""The ``classify`` job: the verdict of Propositions 3.1 to 3.4 and κ* at every gain.

At each point :func:`phdesign.symbolic.classify.classify` runs on the chunk's model with
:math:`L = \operatorname{diag}(l_1, \dots, l_q)`, each float gain read exactly through its
shortest decimal representation (``0.1`` is :math:`1/10`), so the verdict is exact.  The
figures are the ``verdict``, the ``best`` holding variant (``"3.4.4"``; empty when none
holds) and its ``kappa`` :math:`\kappa^*` as in the JSON of ``phdesign classify``
(missing when no variant holds or when :math:`\kappa^*` is unbounded: then ``best`` is
set).

Examples
--------
>>> from phdesign.models import load_builtin
>>> evaluate = prepare(load_builtin("wave"), (2,), {})
>>> evaluate((0.5,))  # 3.2.2: κ* = k/(1 + k²) = 0.4 for the damper k = 0.5
{'verdict': 'exponential', 'kappa': 0.4, 'best': '3.2.2'}
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

import sympy

from phdesign.symbolic.classify import classify
from phdesign.symbolic.expressions import exact_number
from phdesign.symbolic.observer import sensor_matrix

__all__ = ["prepare"]


def prepare(
    model: Any, sensors: tuple[int, ...] | None, options: Mapping[str, Any]
) -> Callable[[tuple[float, ...] | None], dict[str, Any]]:
    """Prepare the job's evaluator (see :mod:`phdesign.sweep.jobs`)."""
    if sensors is None:  # the description refuses this job without sensors
        raise ValueError("the classify job needs a sensor set")
    C_m = sensor_matrix(sensors, model.n_ports)

    def evaluate(gain: tuple[float, ...] | None) -> dict[str, Any]:
        entries = gain if gain is not None else (1.0,) * len(sensors)
        L = sympy.diag(*[exact_number(g, f"l{i + 1}") for i, g in enumerate(entries)])
        result = classify(model, C_m, L)
        best = result.best
        kappa = None if best is None else best.kappa_json()
        return {
            "verdict": result.verdict,
            "kappa": kappa if isinstance(kappa, float) else None,
            "best": "" if best is None else best.name,
        }

    return evaluate
