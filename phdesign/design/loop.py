r"""The observer-based loop as a design object: actuate, feed back the estimate, ask.

.. math::

    u_a = -K \hat y_a,\ K + K^\top \succ 0, \qquad
    \hat u = u + C_m^\top L (y_m - \hat y_m), \qquad u_r = v \text{ (zero by default)} .

A notebook user describes the loop once and asks it questions::

    from phdesign.design.loop import Loop
    loop = Loop(beam, actuate=3, feedback=1, sensors=[4], gain=1)
    loop.classify()     # controlled plant, error system and loop verdicts (separation)
    loop.spectrum()     # converged spectrum of the assembled loop, and of its two blocks
    loop.simulate(x0="x1: 0, x2: z - 0.9", t_end=5)
    loop.tune()         # K on the controlled plant, L on the error system
    loop.statespace()   # control.StateSpace of plant + observer + feedback

The mathematics is in :mod:`phdesign.symbolic.control` (certificates and the separation
structure) and :mod:`phdesign.numeric.control.assembly` (the assembled loop).
:meth:`Loop.from_parts`
builds a loop from what an observer design holds (model, :math:`C_m`, :math:`L`,
parameter overrides).

Examples
--------
>>> from phdesign.models import load_builtin
>>> loop = Loop(load_builtin("euler-bernoulli"), actuate=4, feedback=1, sensors=[2], gain=1)
>>> loop.classify().verdict
'exponential'
>>> loop.actuate, loop.K, loop.source
((4,), Matrix([[1]]), 'estimate')
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace
from functools import cached_property
from typing import TYPE_CHECKING, Any

import sympy

from phdesign.core.checks import choice
from phdesign.core.defaults import current, method_or_default
from phdesign.core.errors import LoopError
from phdesign.core.progress import Progress, reports_progress
from phdesign.core.text import html_table
from phdesign.design.plant import Plant
from phdesign.symbolic.control import (
    FEEDBACK_SOURCES,
    LoopClassification,
    actuated_indices,
    check_collocated,
    check_measured,
    classify_loop,
    controlled_plant,
    feedback_gain,
)
from phdesign.symbolic.model import BCPHS

if TYPE_CHECKING:  # pragma: no cover - typing only
    from phdesign.numeric.bridge import NumericModel
    from phdesign.numeric.control.assembly import LoopSystem, NumericLoop
    from phdesign.numeric.control.simulation import LoopSimulation
    from phdesign.numeric.control.spectrum import LoopSpectrum
    from phdesign.numeric.control.tuning import LoopTuneResult
    from phdesign.numeric.time.options import SimulationOptions

__all__ = ["Loop"]


def _sensors(model: BCPHS, sensors: Any, C_m: Any) -> sympy.ImmutableMatrix:
    """Read the observer's sensors with the library's one reader (as an Observer does)."""
    from phdesign.symbolic.observer import measurement_matrix, sensor_matrix

    if (sensors is None) == (C_m is None):
        raise LoopError("give the observer's sensors (sensors=[4]) or C_m in full, not both")
    if C_m is not None:
        return measurement_matrix(C_m, model.n_ports)
    return sensor_matrix(sensors, model.n_ports)


def _plant(
    model: Any, parameters: Mapping[str, Any] | None, method: str | None, resolution: int | None
) -> Plant:
    """Return the loop's plant: the model given as a Plant, or one built from the model."""
    if isinstance(model, Plant):
        if parameters or method not in (None, current().method) or resolution is not None:
            raise LoopError("give parameters, method and resolution to the Plant, not twice")
        return model
    if not isinstance(model, BCPHS):
        raise LoopError(f"model must be a BCPHS; found {type(model).__name__}")
    method = choice(method_or_default(method), "method", current().method_names, LoopError)
    return Plant(model, {str(k): v for k, v in (parameters or {}).items()}, method, resolution)


def _observer_plant(observer: Any, parameters: Mapping[str, Any] | None) -> Plant:
    """Return the observer's plant, or a new one with further parameter overrides."""
    plant: Plant = observer.plant
    if not parameters:
        return plant
    overrides = {**plant.parameters, **{str(k): v for k, v in parameters.items()}}
    return Plant(plant.model, overrides, plant.method, plant.resolution)


@dataclass(frozen=True, init=False)
class Loop:
    r"""An observer-based boundary control loop (module docstring).

    Parameters
    ----------
    model : BCPHS, Plant or Observer
        The plant: a model, a :class:`~phdesign.design.plant.Plant` (its parameter
        overrides and discretization, shared with the designs built on it), or an
        :class:`~phdesign.design.observer.Observer`, whose plant, sensors and gain the loop
        takes (``phd.Loop(obs, actuate=3)``).
    actuate : int or sequence of int
        1-based indices into the model's external inputs.
    feedback : number, sequence, matrix or text
        :math:`K` (:func:`~phdesign.symbolic.control.feedback_gain`), default 1.
    sensors : int or sequence of int, optional
        The observer's measured outputs (1-based); or give ``C_m`` in full.
    gain : number, sequence or matrix
        The observer gain :math:`L` (default the identity), read as
        :func:`~phdesign.symbolic.observer.gain_matrix` reads it.
    C_m : matrix, optional
    feedback_source : {"estimate", "measured"}
        Feed back :math:`\hat y_a` (the loop) or the measured :math:`y_a` (to compare;
        only where :math:`y_a` is measured).
    feedback_outputs : int or sequence of int, optional
        The outputs fed back; they must be the collocated ones (the default).
    parameters : mapping, optional
        Parameter overrides (applied to the model).
    method : str, optional
        A registered discretization; default: the table's (:mod:`phdesign.core.defaults`).
    resolution : int, optional
        Discretization used by :meth:`simulate`, :meth:`statespace`, :meth:`assemble`, and
        the first resolution of :meth:`spectrum`'s refinement (unless it is given one).

    Attributes
    ----------
    plant : Plant
        The model, its overrides and discretization, and the cached numeric model.
    model : BCPHS
        The model with the parameter overrides as its defaults (``plant.design_model``).
    """

    plant: Plant
    actuate: tuple[int, ...]
    K: sympy.ImmutableMatrix
    C_m: sympy.ImmutableMatrix
    L: sympy.ImmutableMatrix
    source: str

    def __init__(
        self,
        model: Any,
        actuate: int | Sequence[int],
        feedback: Any = 1,
        sensors: int | Sequence[int] | None = None,
        gain: Any = 1,
        *,
        C_m: Any = None,
        feedback_source: str = "estimate",
        feedback_outputs: int | Sequence[int] | None = None,
        parameters: Mapping[str, Any] | None = None,
        method: str | None = None,
        resolution: int | None = None,
    ) -> None:
        from phdesign.design.observer import Observer
        from phdesign.symbolic.observer import ObserverDesign, gain_matrix

        if isinstance(model, Observer):  # phd.Loop(observer, actuate=..., feedback=...)
            if sensors is not None or C_m is not None:
                raise LoopError("the observer gives the sensors: drop sensors= and C_m=")
            if model.L is None:
                raise LoopError("the observer has no gain yet: give one (or tune it) first")
            plant, C_m, gain = _observer_plant(model, parameters), model.C_m, model.L
        else:
            plant = _plant(model, parameters, method, resolution)
        model = plant.design_model
        acts = actuated_indices(actuate, model)
        check_collocated(acts, feedback_outputs, model)
        choice(feedback_source, "feedback_source", FEEDBACK_SOURCES, LoopError)
        C = _sensors(model, sensors, C_m)
        design = ObserverDesign(model, C, gain_matrix(gain, C.rows))  # checks C_m and L
        if feedback_source == "measured":
            check_measured(acts, design.C_m, model)
        for name, value in (
            ("plant", plant),
            ("actuate", acts),
            ("K", feedback_gain(feedback, len(acts))),
            ("C_m", design.C_m),
            ("L", design.L),
            ("source", feedback_source),
        ):
            object.__setattr__(self, name, value)

    @property
    def model(self) -> BCPHS:
        """The model with the parameter overrides as its defaults."""
        return self.plant.design_model

    @property
    def method(self) -> str:
        """The discretization method (the plant's, resolved when it was built)."""
        return str(self.plant.method)

    @property
    def resolution(self) -> int | None:
        """The discretization's resolution (the plant's)."""
        return self.plant.resolution

    @classmethod
    def from_parts(
        cls,
        model: BCPHS,
        C_m: Any,
        L: Any,
        *,
        actuate: int | Sequence[int],
        feedback: Any = 1,
        feedback_source: str = "estimate",
        feedback_outputs: int | Sequence[int] | None = None,
        parameters: Mapping[str, Any] | None = None,
        method: str | None = None,
        resolution: int | None = None,
    ) -> Loop:
        """Build a loop from what an observer design holds: model, C_m, L, parameters."""
        return cls(
            model,
            actuate,
            feedback,
            gain=L,
            C_m=C_m,
            feedback_source=feedback_source,
            feedback_outputs=feedback_outputs,
            parameters=parameters,
            method=method,
            resolution=resolution,
        )

    def with_gains(self, feedback: Any = None, gain: Any = None) -> Loop:
        """Return the same loop with a new K and/or L (e.g. from :meth:`tune`), on its plant."""
        return Loop(
            self.plant,
            self.actuate,
            self.K if feedback is None else feedback,
            gain=self.L if gain is None else gain,
            C_m=self.C_m,
            feedback_source=self.source,
        )

    # ------------------------------------------------------------------ symbolic
    def controlled_plant(self) -> BCPHS:
        """Return the plant closed by :math:`u_a = -K y_a` (a BC-PHS, dissipative boundary)."""
        return controlled_plant(self.model, self.actuate, self.K)

    def classify(self, method: str = "auto") -> LoopClassification:
        """Certificates: the controlled plant, the error system and the loop's verdict."""
        return classify_loop(
            self.model, self.actuate, self.K, self.C_m, self.L, self.source, method
        )

    # ------------------------------------------------------------------ numeric
    @property
    def numeric_model(self) -> NumericModel:
        """The plant through the bridge (parameters substituted), made once by the plant."""
        return self.plant.numeric

    @cached_property
    def numeric(self) -> NumericLoop:
        """The loop's numbers (0-based actuated ports, K, C_m, L as floats)."""
        from phdesign.numeric.bridge import gain_to_numeric
        from phdesign.numeric.control.assembly import NumericLoop

        return NumericLoop(
            tuple(a - 1 for a in self.actuate),
            gain_to_numeric(self.K, "feedback K"),
            gain_to_numeric(self.C_m, "C_m"),
            gain_to_numeric(self.L, "L"),
            self.source,
        )

    def design_label(self) -> str:
        """``u3 = -K ŷ3, K = [[1]]; C_m = [[0, 0, 0, 1]], L = [[1]]`` (for reports, titles)."""
        feed = "ŷ" if self.source == "estimate" else "y"
        act = ",".join(f"u{a}" for a in self.actuate)
        out = ",".join(f"{feed}{a}" for a in self.actuate)
        return (
            f"{act} = -K {out}, K = {self.K.tolist()}; C_m = {self.C_m.tolist()}, "
            f"L = {self.L.tolist()}"
        )

    @reports_progress
    def spectrum(
        self,
        *,
        tol: float | None = None,
        count: int | None = None,
        resolution: int | None = None,
        max_resolution: int | None = None,
        progress: Progress | None = None,
    ) -> LoopSpectrum:
        """Return the loop's converged spectrum (:func:`.numeric.loop_spectrum.loop_spectrum`).

        ``resolution`` defaults to the loop's own (its refinement's first resolution);
        ``progress`` is called with one line of text at each stage
        (:mod:`phdesign.core.progress`).
        """
        from phdesign.numeric.control.spectrum import loop_spectrum

        return loop_spectrum(
            self.numeric_model,
            self.numeric,
            method=self.method,
            resolution=self.resolution if resolution is None else resolution,
            max_resolution=max_resolution,
            tol=tol,
            count=count,
            design=self.design_label(),
        )

    @reports_progress
    def simulate(
        self,
        *,
        x0: str | Callable[[Any], Any] | None = None,
        xhat0: str | Callable[[Any], Any] | None = None,
        u: str | Callable[[float], Any] | None = None,
        options: SimulationOptions | None = None,
        progress: Progress | None = None,
        **settings: Any,
    ) -> LoopSimulation:
        """Simulate the loop (:func:`~phdesign.numeric.control.simulation.simulate_loop`).

        ``x0``, ``xhat0`` and ``u`` may be text (``"x1: 0, x2: z - 0.9"``,
        ``"u1: sin(t)"``), read as on the command line, or callables.  ``options`` and
        ``settings`` (its fields by name: ``t_end``, ``samples``, ``scheme``, ``z_w``) say
        how to run (:class:`~phdesign.numeric.time.options.SimulationOptions`); the
        discretization is the loop's; ``progress`` as for :meth:`spectrum`.
        """
        from phdesign.numeric.control.simulation import simulate_loop
        from phdesign.numeric.inputs import initial_state_function, input_function
        from phdesign.numeric.time.options import SimulationOptions

        nm = self.numeric_model

        def state(value: Any) -> Any:
            return (
                initial_state_function(value, nm, model=self.model)
                if (value is None or isinstance(value, str))
                else value
            )

        inputs = (
            input_function(u, nm, model=self.model) if (u is None or isinstance(u, str)) else u
        )
        opts = SimulationOptions.merged(options, **settings)
        result = simulate_loop(
            nm,
            self.numeric,
            x0=state(x0),
            xhat0=state(xhat0),
            u=inputs,
            options=opts.discretized(self.method, self.resolution, "Loop"),
        )
        info = {**result.info, "model": self.model.name, "design": self.design_label()}
        return replace(result, info=info)  # the titles name the loop (presentation only)

    @reports_progress
    def tune(
        self,
        target: str = "both",
        *,
        full: bool = False,
        starts: int = 6,
        seed: int = 0,
        progress: Progress | None = None,
    ) -> LoopTuneResult:
        """Tune K, L or both on the loop's converged abscissa, by separation.

        ``loop.with_gains(result.loop.K, result.loop.L)`` is the tuned loop; ``progress``
        as for :meth:`spectrum`.
        """
        from phdesign.numeric.control.tuning import tune_loop

        return tune_loop(
            self.numeric_model, self.numeric, target=target, full=full, starts=starts, seed=seed
        )

    def assemble(self) -> LoopSystem:
        """Return the assembled loop matrices (:mod:`phdesign.numeric.control.assembly`)."""
        from phdesign.numeric.control.assembly import assemble

        return assemble(self.plant.discrete(), self.numeric)

    def statespace(self, name: str = "loop") -> Any:
        """Export the loop as ``control.StateSpace`` (:func:`.numeric.loop.loop_statespace`)."""
        from phdesign.numeric.control.assembly import loop_statespace

        return loop_statespace(self.assemble(), name)

    # ------------------------------------------------------------------ printing
    def to_dict(self) -> dict[str, Any]:
        """JSON-ready description of the design (exact entries as text)."""
        return {
            "model": self.model.name,
            "actuate": list(self.actuate),
            "feedback": [[str(x) for x in row] for row in self.K.tolist()],
            "sensors": [[str(x) for x in row] for row in self.C_m.tolist()],
            "gain": [[str(x) for x in row] for row in self.L.tolist()],
            "feedback_source": self.source,
            "method": self.method,
            "resolution": self.resolution,
        }

    def __repr__(self) -> str:
        return (
            f"Loop(model={self.model.name!r}, actuate={self.actuate}, "
            f"feedback={self.K.tolist()}, sensors={self.C_m.tolist()}, gain={self.L.tolist()}, "
            f"source={self.source!r})"
        )[:300]

    def __str__(self) -> str:
        return f"loop on {self.model.name}: {self.design_label()} ({self.source})"

    def _repr_html_(self) -> str:
        rows = [[key, value] for key, value in self.to_dict().items()]
        return html_table(["observer-based loop", ""], rows)
