r"""A model's disturbances and performance outputs read against its numeric model.

The crossing from the symbolic layer of the ``[disturbances]`` and ``[performance]``
sections (:mod:`phdesign.symbolic.disturbances`, :mod:`phdesign.symbolic.performance`):

* :func:`disturbance_inputs`: :math:`B(z)` as a vectorized profile and the unknown
  external inputs;
* :func:`performance_terms`: each performance output as numbers (its weight, trace row
  and points);
* :func:`disturbance_signal`: ``"w1: sin(3*t)"`` as :math:`w(t)` over B's columns, read by
  the parser of the inputs u (:func:`phdesign.numeric.inputs.input_function`).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from phdesign.core.errors import ParameterError
from phdesign.numeric.bridge import NumericModel, _parameter_values
from phdesign.numeric.inputs import (
    Signals,
    exact_profile,
    input_function,
    substituted,
    trace_expression_row,
)

__all__ = ["disturbance_count", "disturbance_inputs", "disturbance_signal", "performance_terms"]


def disturbance_inputs(model: Any, nm: NumericModel) -> tuple[Any, tuple[int, ...]]:
    r"""Return :math:`B(z)` as ``f(z) -> (m, n, q)`` (None without one) and the unknown inputs.

    The unknown inputs are 0-based indices into the external inputs (after the model's
    ``[feedback]``), as the discretizations number their columns of B.
    """
    from phdesign.symbolic.feedback import external_indices

    dist = getattr(model, "disturbances", None)
    if dist is None:
        return None, ()
    kept = external_indices(len(model.inputs), model.feedback)
    unknown = tuple(kept.index(j - 1) for j in dist.unknown)
    if not dist.q:
        return None, unknown
    entries = [x for row in dist.B.tolist() for x in row]
    return exact_profile(model, entries, (nm.size, dist.q), "disturbances B"), unknown


def performance_terms(model: Any, nm: NumericModel, outputs: Any = None) -> list[Any]:
    r"""Return each performance output as ``(name, weight, trace, points)`` with numbers.

    ``weight(z) -> (m, n)`` weighs the states, :math:`\int (H c + d)^	op x\, dz` for
    :math:`\int c^	op e + d^	op x` (None without an integral); ``trace`` is the row over
    ``v`` (None without traces); ``points`` are ``(field, point, coefficient)`` floats.
    ``outputs`` are text in the ``[performance]`` grammar (default: the model's outputs).
    """
    import sympy

    from phdesign.symbolic.performance import parse_performance

    items = model.performance
    if outputs is not None:
        fields = ["w"] * (model.displacement is not None) + [n for n, _ in model.fields]
        texts = [outputs] if isinstance(outputs, str) else outputs
        shape = (model.interval, model.order, model.size, model.parameter_names, fields)
        items = parse_performance(texts, *shape)
    out = []
    H = model.H
    for item in items:
        what = f"performance output {item.text!r}"
        weight = None
        if item.has_integral:
            c = H * sympy.Matrix(item.effort_weights) + sympy.Matrix(item.state_weights)
            weight = exact_profile(model, list(c), (nm.size,), what)
        trace = None
        if item.traces != 0:
            trace = trace_expression_row(item.traces, _parameter_values(model, None), nm, what)
        points = tuple(
            (field, float(point), float(substituted(model, c, what)))
            for field, point, c in item.points
        )
        out.append((item.text, weight, trace, points))
    return out


def disturbance_count(model: Any) -> int:
    """Return q, the number of columns of the model's ``[disturbances]`` B (0 without)."""
    dist = getattr(model, "disturbances", None)
    return 0 if dist is None else int(dist.q)


def disturbance_signal(
    text: str | None, nm: NumericModel, model: Any
) -> Callable[[float], np.ndarray] | None:
    """Parse disturbances ``'w1: sin(3*t)'`` into ``w(t) -> (q,)`` (B's columns ``w1..wq``).

    The grammar of the inputs u (:func:`phdesign.numeric.inputs.input_function`); channels
    not named are zero.

    Raises
    ------
    ParameterError
        The model has no ``[disturbances]`` B, or a channel it does not have.
    """
    if text is None or not text.strip():
        return None
    q = disturbance_count(model)
    if not q:
        raise ParameterError(
            f"`w`: model {nm.name!r} has no disturbance channel: add a [disturbances] "
            "section with B (n x q) to drive w1..wq"
        )
    channels = Signals("w", "disturbance", tuple(f"w{j + 1}" for j in range(q)))
    return input_function(text, nm, model=model, channels=channels)
