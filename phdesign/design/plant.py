r"""The numeric plumbing of a design: a model, its parameter overrides, its discretization.

:class:`Plant` is the model with its parameter overrides and discretization options, and
the numeric model it caches (the bridge runs once per plant).  Designs built on a plant
(:class:`~phdesign.design.observer.Observer`, an observer-based loop) share it.
:func:`numeric_matrix` turns an exact :math:`C_m` or :math:`L` into floats, refusing
symbols with a message that says what to do.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from functools import cached_property
from typing import TYPE_CHECKING, Any

import sympy

from phdesign.core.checks import choice, positive_int
from phdesign.core.defaults import current
from phdesign.core.errors import ArgumentError, ObserverError, ParameterError
from phdesign.core.progress import Progress, reports_progress
from phdesign.core.text import REPR_LIMIT, matrix_text, shorten
from phdesign.symbolic.model import BCPHS
from phdesign.symbolic.system import require_model

if TYPE_CHECKING:  # pragma: no cover - typing only
    import numpy as np

    from phdesign.numeric.bridge import NumericModel
    from phdesign.numeric.certified.certificate import Certificate
    from phdesign.numeric.discretization.phs import DiscretePHS
    from phdesign.numeric.noise.disturbance_report import GainReport
    from phdesign.numeric.spectrum.report import SpectrumReport
    from phdesign.numeric.time.options import SimulationOptions
    from phdesign.numeric.time.result import SimulationResult

__all__ = ["Plant", "numeric_matrix"]


def numeric_matrix(M: sympy.MatrixBase, name: str, what: str) -> np.ndarray:
    """Return an exact numeric matrix as floats; refuse symbols, saying what to do.

    Parameters
    ----------
    M : sympy matrix
        :math:`C_m` or :math:`L`.
    name : str
        Its name in messages.
    what : str
        The numeric computation that needs it (``"spectrum"``, ``"simulate"``).
    """
    import numpy as np

    if M.free_symbols:
        names = ", ".join(sorted(map(str, M.free_symbols)))
        raise ObserverError(
            f"{what} needs numbers for {name}; {name} = {matrix_text(M)} is symbolic ({names}): "
            "give numbers (`gain=[0.1, 1]`) or tune "
            "one; symbolic gains are for classify, which answers for all their positive values"
        )
    return np.array(M.evalf(17).tolist(), dtype=float)


@dataclass(frozen=True, repr=False)
class Plant:
    """A model with its parameter overrides and discretization: the numeric plumbing.

    Parameters
    ----------
    model : BCPHS
        The symbolic model (:func:`phdesign.load`).
    parameters : mapping of str to number, optional
        Overrides of the model's parameter defaults (``{"d": 0.5}``), used by the
        classification and by the numbers alike.
    method : str, optional
        A registered discretization (``"galerkin"``, ``"fd"``,
        :func:`phdesign.numeric.discretization.registry.discretize`); default: the table's
        (:mod:`phdesign.core.defaults`), remembered by the plant.
    resolution : int, optional
        Degree or nodes per group; for spectra, the first resolution of the refinement.

    Examples
    --------
    >>> from phdesign.models import load_builtin
    >>> plant = Plant(load_builtin("euler-bernoulli"), parameters={"d": 0.5})
    >>> plant.numeric.parameters["d"]
    0.5
    >>> round(plant.spectrum().spectral_abscissa, 10)  # every mode has Re λ = -d/2
    -0.25
    """

    model: BCPHS
    parameters: Mapping[str, Any] = field(default_factory=dict, hash=False)
    method: str | None = None
    resolution: int | None = None

    def __post_init__(self) -> None:
        require_model(self.model)
        if not isinstance(self.parameters, Mapping):
            raise ParameterError(
                "parameters must be a mapping of names to values such as {'d': 0.5}; found "
                f"{type(self.parameters).__name__}"
            )
        table = current()  # None: the default method, remembered by the plant
        method = table.method if self.method is None else self.method
        object.__setattr__(self, "method", choice(method, "method", table.method_names))
        if self.resolution is not None:
            positive_int(self.resolution, "resolution")
        object.__setattr__(self, "parameters", dict(self.parameters))
        self.design_model  # noqa: B018 - checks the overrides now, not at first use

    @cached_property
    def design_model(self) -> BCPHS:
        """The model with the parameter overrides as its defaults."""
        return self.model.with_parameters(self.parameters) if self.parameters else self.model

    @cached_property
    def numeric(self) -> NumericModel:
        """The numeric model (parameters substituted), made once."""
        from phdesign.numeric.bridge import to_numeric

        return to_numeric(self.model, self.parameters or None)

    def discrete(self, resolution: int | None = None) -> DiscretePHS:
        """Return the discretized plant at ``resolution`` (default: the plant's)."""
        from phdesign.numeric.discretization.registry import discretize

        return discretize(self.numeric, self.method, resolution or self.resolution)

    def initial_state(self, x0: str | Callable[[Any], Any] | None, name: str) -> Any:
        """Return an initial state as a function of z (text ``"x1: z - 0.9"`` is parsed)."""
        from phdesign.numeric.inputs import initial_state_function

        text = _text_or_function(x0, name, "'x1: 0, x2: z - 0.9'", "z")
        return x0 if text is None else initial_state_function(text, self.numeric)

    @reports_progress
    def spectrum(
        self,
        *,
        max_resolution: int | None = None,
        tol: float | None = None,
        count: int | None = None,
        progress: Progress | None = None,
    ) -> SpectrumReport:
        """Return the converged spectrum of the plant with u = 0.

        ``progress`` is called with one line of text at each stage of the refinement
        (:mod:`phdesign.core.progress`).
        """
        return self.closed_spectrum(
            None, None, max_resolution=max_resolution, tol=tol, count=count
        )

    @reports_progress
    def gain(
        self,
        C_m: np.ndarray | None = None,
        L: np.ndarray | None = None,
        *,
        intensity: Any = None,
        performance: Any = None,
        max_resolution: int | None = None,
        tol: float | None = None,
        optimal: bool = False,
        progress: Progress | None = None,
    ) -> GainReport:
        r"""Return the H∞ and H₂ norms from the disturbances to the performance outputs.

        Without ``C_m`` and ``L``, of the plant with its known inputs at zero, from the
        model's ``[disturbances]`` (:math:`B(z) w` and the unknown inputs) to its
        ``[performance]`` outputs (or ``performance``, in that grammar); with them, of
        the observer's estimation error, sensor noise of ``intensity`` included, and
        with ``optimal`` the Kalman–Bucy H₂ error and the H∞-optimal level γ* beside
        (:func:`phdesign.numeric.noise.disturbance.disturbance_gain`).  Each norm is
        converged under refinement or flagged.

        Examples
        --------
        >>> from phdesign.models import load_builtin
        >>> from phdesign.io import model_to_dict, model_from_dict
        >>> data = model_to_dict(load_builtin("wave-damper"))  # the damped-tip string
        >>> data["disturbances"] = {"B": [[1], [0]]}            # a uniform force
        >>> data["performance"] = {"outputs": ["integral(e1)"]}  # total momentum
        >>> report = Plant(model_from_dict(data)).gain()
        >>> round(report.hinf.value, 6), round(report.hinf.frequency, 3)  # PIETOOLS: "2"
        (0.841877, 1.665)
        """
        from phdesign.numeric.noise.disturbance import disturbance_gain

        return disturbance_gain(
            self.numeric,
            C_m,
            L,
            model=self.design_model,
            intensity=intensity,
            performance=performance,
            method=self.method,
            resolution=self.resolution,
            max_resolution=max_resolution,
            tol=tol,
            optimal=optimal,
        )

    def closed_spectrum(
        self,
        C_m: np.ndarray | None,
        L: np.ndarray | None,
        *,
        max_resolution: int | None = None,
        tol: float | None = None,
        count: int | None = None,
    ) -> SpectrumReport:
        r"""Return the converged spectrum with :math:`u = -C_m^\top L C_m y` (u = 0 without)."""
        from phdesign.numeric.spectrum.converged import spectrum

        return spectrum(
            self.numeric,
            C_m,
            L,
            method=self.method,
            resolution=self.resolution,
            max_resolution=max_resolution,
            tol=tol,
            count=count,
        )

    def certify(self, band: float | None = None, *, rate: bool = False) -> Certificate:
        r"""Prove the spectral abscissa of the plant with u = 0 (:mod:`phdesign.design.certify`).

        The whole plane for first-order systems with one travel time and :math:`P_0 = 0`,
        else the band :math:`|\operatorname{Im}\lambda| \le` ``band``.
        """
        from phdesign.design.certify import certify_design

        return certify_design(self, None, None, band, rate)

    @reports_progress
    def simulate(
        self,
        x0: str | Callable[[Any], Any] | None = None,
        *,
        u: str | Callable[[float], Any] | None = None,
        w: str | Callable[[float], Any] | None = None,
        options: SimulationOptions | None = None,
        progress: Progress | None = None,
        **settings: Any,
    ) -> SimulationResult:
        """Simulate the plant alone from ``x0`` (text or a function of z; zero by default).

        ``u``, ``w``, ``options``, ``progress`` and ``settings`` as for
        :meth:`phdesign.Observer.simulate` (``t_end=2``, ``scheme="midpoint"``,
        ``input_intensity=0.1``, ``disturbance_intensity=0.5`` ...); the noise is the only
        kind of run a plant without sensors has besides the plain one.
        """
        opts = self.simulation_options(options, **settings)
        return self.run(None, None, x0, u=u, w=w, options=opts)

    def simulation_options(
        self, options: SimulationOptions | None = None, **settings: Any
    ) -> SimulationOptions:
        """Return ``options`` with ``settings`` (fields by name) on this plant's discretization.

        Raises
        ------
        ArgumentError
            A setting that is not an option, or another method or resolution than the
            plant's (:meth:`~phdesign.numeric.time.options.SimulationOptions.discretized`).
        """
        from phdesign.numeric.time.options import SimulationOptions

        merged = SimulationOptions.merged(options, **settings)
        return merged.discretized(self.method, self.resolution, "Plant")

    def run(
        self,
        C_m: np.ndarray | None,
        L: np.ndarray | None,
        x0: str | Callable[[Any], Any] | None = None,
        *,
        xhat0: str | Callable[[Any], Any] | None = None,
        u: str | Callable[[float], Any] | None = None,
        w: str | Callable[[float], Any] | None = None,
        options: SimulationOptions | None = None,
        labels: Mapping[str, str] | None = None,
    ) -> SimulationResult:
        """Simulate the plant, with the observer of ``(C_m, L)`` when given.

        The one route of :meth:`simulate`, :meth:`phdesign.Observer.simulate` and
        ``phdesign simulate``: the kind of run the options ask for
        (:attr:`~phdesign.numeric.time.options.SimulationOptions.kind`) picks the
        simulator: :func:`~phdesign.numeric.sampled.simulation.simulate_sampled` for a
        sampled or lower-order observer, :func:`~phdesign.numeric.time.stochastic.simulate_noisy`
        for noise, else :func:`~phdesign.numeric.time.simulation.simulate`.  ``labels`` name
        the design in the result (presentation only: the plots' titles and the JSON).
        ``w`` drives the model's disturbance channels (``w1..wq``: the columns of
        ``[disturbances]`` B; ``u<j>``: the inputs marked unknown), as does
        ``disturbance_intensity`` (white) of the options: the observer knows neither.

        Raises
        ------
        ObserverError
            A sampled or lower-order observer asked for without sensors.
        ParameterError
            ``w`` on a model without disturbances, or a channel it does not have.
        """
        opts = self.simulation_options(options)
        inputs = {
            "x0": self.initial_state(x0, "x0"),
            "xhat0": self.initial_state(xhat0, "xhat0"),
            "u": self.input_signal(u, observed=C_m is not None),
            **self._disturbance_inputs(w, opts),
        }
        if opts.kind == "sampled":
            from phdesign.numeric.sampled.simulation import simulate_sampled

            if C_m is None or L is None:
                raise ObserverError(
                    "dt, sampler and observer_resolution act on the observer: give the sensors"
                )
            result = simulate_sampled(self.numeric, C_m, L, options=opts, **inputs)
        elif opts.kind == "noisy":
            from phdesign.numeric.time.stochastic import simulate_noisy

            result = simulate_noisy(self.numeric, C_m, L, options=opts, **inputs)
        else:
            from phdesign.numeric.time.simulation import simulate

            result = simulate(self.numeric, C_m, L, options=opts, **inputs)
        return self.labelled(result, **(labels or {}))

    def _disturbance_inputs(self, w: Any, opts: SimulationOptions) -> dict[str, Any]:
        """Return the simulator's ``w`` and ``disturbance`` B(z) (none: no disturbance)."""
        from phdesign.numeric.disturbance_inputs import disturbance_channels, disturbance_signal

        text = _text_or_function(w, "w", "'w1: sin(3*t)'", "t")
        signal = w if text is None else disturbance_signal(text, self.numeric, self.design_model)
        if signal is None and opts.disturbance_intensity is None:
            return {}
        channels = disturbance_channels(self.design_model, self.numeric)
        if channels is None:
            raise ParameterError(
                f"{'`w`' if signal is not None else 'disturbance_intensity'}: model "
                f"{self.model.name!r} has no disturbance channel: add a [disturbances] "
                "section with B (n x q), or mark external inputs unknown"
            )
        if opts.kind == "sampled":
            raise ObserverError(
                "a disturbance `w` runs with the continuous observer; dt, sampler and "
                "observer_resolution ask for a sampled one: give one or the other"
            )
        return {"w": signal, "disturbance": channels}

    def input_signal(
        self, u: str | Callable[[float], Any] | None, *, observed: bool = False
    ) -> Any:
        """Return plant inputs as a function of t (text ``"u2: sin(2*t)"`` is parsed).

        ``observed``: an observer runs too and copies these inputs, so text that drives an
        input marked unknown is refused (it is a disturbance: ``w``).
        """
        from phdesign.numeric.inputs import input_function

        text = _text_or_function(u, "u", "'u2: sin(2*t)'", "t")
        if observed:
            _refuse_unknown_inputs_in_u(text, self.model)
        return u if text is None else input_function(text, self.numeric, model=self.model)

    def labelled(self, result: SimulationResult, **labels: str) -> SimulationResult:
        """Return the result with the model's name (and the design's ``labels``) in its ``info``.

        Presentation only: the plots' titles and the JSON name what was simulated.
        """
        return replace(result, info={**result.info, "model": self.model.name, **labels})

    def __repr__(self) -> str:
        extra = f", parameters={self.parameters}" if self.parameters else ""
        text = f"Plant(model={self.model.name!r}{extra}, method={self.method!r})"
        return shorten(text, REPR_LIMIT)


def _refuse_unknown_inputs_in_u(u: Any, model: BCPHS) -> None:
    """Refuse ``u`` text that drives an input marked unknown, when an observer runs.

    The observer copies every input ``u`` gives it (û = u + C_mᵀL(y_m − ŷ_m)), so an
    unknown input driven through ``u`` would be known to it: such a signal is a
    disturbance, given through ``w`` (the same ``'u<j>: ...'`` text).
    """
    dist = model.disturbances
    if not isinstance(u, str) or dist is None or not dist.unknown:
        return
    named = [int(j) for j in re.findall(r"\bu(\d+)\s*:", u)]
    clash = [j for j in named if j in dist.unknown]
    if clash:
        j = clash[0]
        raise ParameterError(
            f"u{j} is marked unknown in [ports] (the observer does not know it), so `u` "
            f"cannot drive it in an observer's run; give it as a disturbance, through `w` "
            f"(the same 'u{j}: ...' text)"
        )


def _text_or_function(value: Any, name: str, example: str, variable: str) -> str | None:
    """Return ``value`` if it is text to parse, None if it is None or callable; else refuse."""
    if value is None or callable(value):
        return None
    if not isinstance(value, str):
        raise ArgumentError(
            f"{name} must be text such as {example} or a function of {variable}; found "
            f"{type(value).__name__}"
        )
    return value
