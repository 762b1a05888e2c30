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
from dataclasses import dataclass
from typing import Any

import numpy as np

from phdesign.core.errors import NumericError, ParameterError
from phdesign.numeric.bridge import NumericModel, _parameter_values
from phdesign.numeric.inputs import (
    Signals,
    exact_profile,
    input_function,
    substituted,
    trace_expression_row,
)

__all__ = [
    "DisturbanceChannels",
    "disturbance_channels",
    "disturbance_inputs",
    "disturbance_signal",
    "performance_terms",
]


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


@dataclass(frozen=True)
class DisturbanceChannels:
    r"""Where the disturbances enter a discretization: B's columns, then the unknown inputs.

    Channel ``w<k>`` is column k of :math:`B(z)` (:math:`B_d = \int \Psi^\top B\, dz`),
    channel ``u<j>`` the external input j marked unknown (column j of the discretization's
    B): the plant sees them, the observer does not, so both rows of a simulation
    (:mod:`phdesign.numeric.time.simulation`) are driven by :meth:`columns`.
    """

    B: Callable[[np.ndarray], np.ndarray] | None
    q: int
    unknown: tuple[int, ...]

    @property
    def names(self) -> tuple[str, ...]:
        """The channels' names: ``w1..wq``, then ``u<j>`` (1-based external inputs)."""
        return (*(f"w{k + 1}" for k in range(self.q)), *(f"u{j + 1}" for j in self.unknown))

    def columns(self, d: Any) -> np.ndarray:
        """Return the input columns ``[B_d, B[:, unknown]]`` on the discretization ``d``.

        Raises
        ------
        NumericError
            An unknown input feeds through into the outputs (D ≠ 0 there): the observer's
            measurements would see it, which the simulation does not model.
        """
        from phdesign.numeric.discretization.functionals import disturbance_matrix

        unknown = list(self.unknown)
        if unknown and np.any(d.D[:, unknown]):
            raise NumericError(
                "an unknown input feeds through into the outputs on this discretization "
                f"(D[:, u{unknown[0] + 1}] is not zero): use the galerkin method"
            )
        Bd = np.zeros((d.dim, 0)) if self.B is None else disturbance_matrix(d, self.B)
        return np.hstack([Bd, d.B[:, unknown]])


def disturbance_channels(model: Any, nm: NumericModel) -> DisturbanceChannels | None:
    """Return the model's disturbance channels (None: neither B nor unknown inputs)."""
    B, unknown = disturbance_inputs(model, nm)
    dist = getattr(model, "disturbances", None)
    q = 0 if dist is None else int(dist.q)
    return None if B is None and not unknown else DisturbanceChannels(B, q, unknown)


def disturbance_signal(
    text: str | None, nm: NumericModel, model: Any
) -> Callable[[float], np.ndarray] | None:
    """Parse disturbances ``'w1: sin(3*t)'`` into ``w(t)`` over the disturbance channels.

    The grammar of the inputs u (:func:`phdesign.numeric.inputs.input_function`); the
    channels are those of :class:`DisturbanceChannels` (``w1..wq``, then the unknown
    inputs ``u<j>``); channels not named are zero.

    Raises
    ------
    ParameterError
        The model has no disturbance channel, or a channel it does not have.
    """
    if text is None or not text.strip():
        return None
    channels = disturbance_channels(model, nm)
    if channels is None:
        raise ParameterError(
            f"`w`: model {nm.name!r} has no disturbance channel: add a [disturbances] "
            "section with B (n x q), or mark external inputs unknown ([ports] unknown = [j])"
        )
    kind = Signals("w", "disturbance", channels.names)
    return input_function(text, nm, model=model, channels=kind)
