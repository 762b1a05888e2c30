r"""The exported observer: a discrete-time system for a controller, and its reports.

:class:`SampledObserver` is what :func:`phdesign.numeric.sampled.export.export_observer`
returns (the timing, the signals and the energy are described there): the matrices, the
order selection, the gain design (:mod:`phdesign.numeric.sampled.gain_design`) and the
verification, with ``str()`` the command's text, ``to_dict()`` its JSON and ``write()`` the
files.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from phdesign.core.checks import EXPORT_FORMATS
from phdesign.core.errors import NumericError
from phdesign.core.text import html_table
from phdesign.numeric.sampled.gain_design import GainDesign
from phdesign.numeric.sampled.samplers import ContinuousObserver
from phdesign.numeric.sampled.selection import OrderSelection
from phdesign.numeric.sampled.verification import Verification
from phdesign.numeric.signals import signal_lines

__all__ = ["FORMATS", "SampledObserver"]

#: Export formats of :meth:`SampledObserver.write`.
FORMATS = EXPORT_FORMATS


def _matrix(a: np.ndarray) -> list[list[float]]:
    return [[float(x) for x in row] for row in np.atleast_2d(a)]


@dataclass(frozen=True)
class SampledObserver:
    """A discrete-time observer ready for a controller (module docstring).

    Attributes
    ----------
    model : str
    dt : float
        Sampling period in seconds.
    sampler : {"average", "point"}
    A, B, C, D : ndarray
        ``x[k+1] = A x[k] + B v[k]``, ``out[k] = C x[k] + D v[k]``.
    inputs, outputs : tuple of str
        Names of v (plant inputs u1.., then the measured outputs) and of the outputs.
    energy_matrix : ndarray
        Q of the observer's energy ½ x̂ᵀ Q x̂.
    selection : OrderSelection
        How the order was chosen and what was dropped.
    verification : Verification or None
    continuous : ContinuousObserver
        The continuous observer of the given gain and this order (the reference
        :math:`F_c` of the verification; ``point`` steps it with its input held, ``average``
        runs its model as a sampled-data observer).
    design : GainDesign or None
        Which gain the matrices run, the candidates compared and why
        (:mod:`phdesign.numeric.sampled.gain_design`).
    notes : tuple of str
        Warnings of the export itself (the point sampler's aliasing).
    """

    model: str
    dt: float
    sampler: str
    A: np.ndarray = field(repr=False)
    B: np.ndarray = field(repr=False)
    C: np.ndarray = field(repr=False)
    D: np.ndarray = field(repr=False)
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    energy_matrix: np.ndarray = field(repr=False)
    selection: OrderSelection = field(repr=False)
    verification: Verification | None = field(default=None, repr=False)
    continuous: ContinuousObserver | None = field(default=None, repr=False, compare=False)
    design: GainDesign | None = field(default=None, repr=False, compare=False)
    notes: tuple[str, ...] = ()

    @property
    def order(self) -> int:
        """Number of states N."""
        return int(self.A.shape[0])

    @property
    def x0(self) -> np.ndarray:
        """The initial state: zeros."""
        return np.zeros(self.order)

    def descriptions(self) -> tuple[tuple[str, ...], tuple[str, ...]]:
        """Return what each input and output is (``y3 = e1'(1)``), else their names."""
        c = self.continuous
        if c is None or not c.input_descriptions:
            return self.inputs, self.outputs
        return c.input_descriptions, c.output_descriptions

    @property
    def renumbering(self) -> str | None:
        """How a ``[feedback]`` closure renumbered the ports (:mod:`phdesign.numeric.signals`)."""
        from phdesign.numeric.signals import renumbering

        return None if self.continuous is None else renumbering(self.continuous.discrete.model)

    @property
    def warnings(self) -> tuple[str, ...]:
        """Warnings of the export, the order selection, the design and the verification."""
        extra = () if self.verification is None else self.verification.warnings
        return self.notes + self.selection.warnings + self._design_warnings() + extra

    def _design_warnings(self) -> tuple[str, ...]:
        """Return the warning of a requested design that failed its verification."""
        d = self.design
        if d is None or d.requested == "auto" or d.selected.failure is None:
            return ()
        return (f"the {d.chosen} design failed verification: {d.selected.failure}",)

    def step(self, x: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """One step: returns ``(x[k+1], out[k])`` from ``x[k]`` and ``v[k]``."""
        return self.A @ x + self.B @ v, self.C @ x + self.D @ v

    def run(self, V: np.ndarray, x0: np.ndarray | None = None) -> np.ndarray:
        """Return the outputs ``(nk, n_outputs)`` for inputs ``V`` of shape ``(nk, n_inputs)``."""
        V = np.atleast_2d(np.asarray(V, dtype=float))
        x = self.x0 if x0 is None else np.asarray(x0, dtype=float)
        out = np.empty((V.shape[0], len(self.outputs)))
        for k, v in enumerate(V):
            x, out[k] = self.step(x, v)
        return out

    def signal_names(self) -> tuple[tuple[str, ...], tuple[str, ...]]:
        """Return the inputs' and outputs' names as python-control takes them.

        python-control refuses '.' in a signal name: ``w(0.5)`` is ``w(0p5)`` there
        (:func:`~phdesign.numeric.statespace.control_signal_name`).
        """
        from phdesign.numeric.statespace import control_signal_name

        return (
            tuple(control_signal_name(name) for name in self.inputs),
            tuple(control_signal_name(name) for name in self.outputs),
        )

    def statespace(self) -> Any:
        """``control.StateSpace(A, B, C, D, dt)`` with the signal names (:meth:`signal_names`)."""
        import control

        inputs, outputs = self.signal_names()
        return control.ss(
            self.A,
            self.B,
            self.C,
            self.D,
            self.dt,
            inputs=list(inputs),
            outputs=list(outputs),
            states=[f"xhat{i + 1}" for i in range(self.order)],
            name="observer",
        )

    def to_dict(self) -> dict[str, Any]:
        """Return the JSON export (strict JSON).

        Keys: model, dt, sampler, order, A, B, C, D, inputs, outputs, x0, energy_matrix,
        verification (null when not run), order_selection and design (the gain design:
        which, why, each candidate's floors over the verification set and noise price,
        null without one); input_descriptions and
        output_descriptions say what each signal is (:meth:`descriptions`), renumbering
        how a ``[feedback]`` closure renumbered the ports (null without one).
        """
        inputs, outputs = self.descriptions()
        return {
            "model": self.model,
            "dt": self.dt,
            "sampler": self.sampler,
            "order": self.order,
            "A": _matrix(self.A),
            "B": _matrix(self.B),
            "C": _matrix(self.C),
            "D": _matrix(self.D),
            "inputs": list(self.inputs),
            "outputs": list(self.outputs),
            "x0": self.x0.tolist(),
            "energy_matrix": _matrix(self.energy_matrix),
            "verification": None if self.verification is None else self.verification.to_dict(),
            "order_selection": self.selection.to_dict(),
            "design": None if self.design is None else self.design.to_dict(),
            "input_descriptions": list(inputs),
            "output_descriptions": list(outputs),
            "renumbering": self.renumbering,
        }

    def write(self, path: str, format: str = "json", force: bool = False) -> list[str]:
        """Write the observer as ``format`` (:data:`FORMATS`) to ``path``; returns the files.

        ``json``, ``npz`` and ``statespace`` (a Python module that rebuilds the
        ``control.StateSpace``) write one file; ``c`` writes a folder holding
        ``observer.h``, ``observer.c`` and the marker ``.phdesign-export``, all files or
        none. ``force`` replaces a file, or a folder phdesign wrote and nothing else
        (:mod:`phdesign.codegen.folder`).
        """
        from phdesign.codegen import write_observer

        return write_observer(self, path, format, force=force)

    def __repr__(self) -> str:
        return (
            f"SampledObserver(model={self.model!r}, order={self.order}, dt={self.dt:g}, "
            f"sampler={self.sampler!r}, inputs={len(self.inputs)}, outputs={len(self.outputs)})"
        )

    def __str__(self) -> str:
        how = "mean over each period" if self.sampler == "average" else "point samples"
        sel, slow = self.selection, ""
        if sel.spurious and sel.abscissa is not None and sel.spurious_max_real is not None:
            slow = (
                f" ({sel.spurious} unresolved poles slower than the abscissa {sel.abscissa:.3g}: "
                f"max Re {sel.spurious_max_real:.3g}; `reduction='modal'` drops them)"
            )
        lines = [
            f"observer for {self.model}: {self.order} states{slow}, dt = {self.dt:g} s, "
            f"sampler {self.sampler} ({how})",
            *signal_lines(*self.descriptions(), self.renumbering),
            str(self.selection),
        ]
        if self.design is not None:
            lines.append(str(self.design))
        if self.verification is not None:
            lines.append(str(self.verification))
        lines += [
            f"warning: {w}" for w in self.notes + self.selection.warnings + self._design_warnings()
        ]
        return "\n".join(lines)

    def _repr_html_(self) -> str:
        rows = [
            ("model", self.model),
            (
                "order",
                f"{self.order} (degree {self.selection.degree}, {self.selection.reduction})",
            ),
            ("dt, sampler", f"{self.dt:g} s, {self.sampler}"),
            ("design", "given gain" if self.design is None else self.design.chosen),
            ("inputs", ", ".join(self.inputs)),
            ("outputs", ", ".join(self.outputs)),
        ]
        if self.verification is not None:
            v = self.verification
            rows.append(("error floor", f"{v.floor:.3g} (continuous {v.continuous_floor:.3g})"))
        return html_table((), rows)

    def plot(self, ax: Any = None) -> Any:
        """Draw the verification run (needs ``verify=True``); returns the axes."""
        if self.verification is None:
            raise NumericError("this observer was exported without verification: verify=True")
        return self.verification.plot(ax)
